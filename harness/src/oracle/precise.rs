//! The high-precision reference path: Smith Λ and D of Beckmann, GGX and STD, computed in
//! double-double arithmetic (≈ 106 bits) with tanh–sinh quadrature, each with an error bound
//! far below the 1e-15 relative at which it certifies a double-precision closed form.
//!
//! # What is computed
//!
//! Λ is the Smith integral of the slope marginal (document 001 eq 5, with P2 of eq 15):
//!
//! ```text
//! Λ(θ) = (1/μ) ∫_μ^∞ (q − μ) P2(q) dq,   μ = cot θ
//! Beckmann  P2(q) = e^{−q²/α²} / (α √π)
//! GGX       P2(q) = α² / (2 (α² + q²)^{3/2})                       (= Student, C = 2, s = α)
//! STD       P2(q) = N_C / s · (1 + (q/s)²)^{1/2 − C},  C = γ,  s = α √(γ − 1)
//!           N_C   = 1 / ∫_{−∞}^{∞} (1 + t²)^{1/2 − C} dt                (normalization)
//! ```
//!
//! The infinite range is mapped onto (0, 1] by the normalized first-moment tail
//! w(q) = ∫_q^∞ s P2(s) ds / ∫_μ^∞ s P2(s) ds, whose closed form is elementary. Then
//! dw = −q P2(q) dq / A′ and
//!
//! ```text
//! Λ = (A′/μ) ∫₀¹ (q(w) − μ) / q(w) dw
//! ```
//!
//! with a bounded integrand in [0, 1) and every algebraic or Gaussian tail absorbed into the
//! map (in standardized slopes x = μ/s, resp. a = μ/α):
//!
//! ```text
//! Student:  A′/μ = N_C (1 + x²)^{3/2 − C} / ((2C − 3) x),  t(w)² = (1 + x²) w^{−1/(C − 3/2)} − 1
//! Beckmann: A′/μ = e^{−a²} / (2 a √π),                     t(w)  = a + u, u² + 2au = −ln w
//! ```
//!
//! N_C is not taken from Γ: it is integrated too, with v = w^{1/(C−1)} in the Beta integral,
//! 1/N_C = (1/(C − 1)) ∫₀¹ (1 − w^{1/(C−1)})^{−1/2} dw. Every difference that could cancel
//! (t − x, 1 − w^m) is formed as expm1 / ln1p of the node's exact distance to its end point.
//!
//! D (document 001 eq 2, 10, and Table 1) is elementary and evaluated directly in double-double,
//! at the direction m/|m|.
//!
//! # Precision claim and how it is certified
//!
//! Each returned value carries `error_bound`, a bound on |value_dd − exact| made of
//! (1) the difference of the last two tanh–sinh levels (step h and 2h; the level is refined
//! until that difference is ≤ 1e-28 relative — double-exponential convergence makes the error
//! of the finer level of the order of the square of that difference, so this is pessimistic),
//! (2) the rounding of the quadrature sum, (n u + 200 u) Σ|terms|, u = 2⁻¹⁰⁴, and
//! (3) the rounding of the closed-form prefactors, (64 + |argument of exp|) u relative (the
//! argument reduction of exp loses |k| · 1e-32 absolute). A result whose relative bound
//! exceeds [`CERTIFIED_RELATIVE`] = 1e-24 is not returned (`PreciseError::NotCertified`).
//! The double-double primitives are unit-tested against exact identities
//! (`precise::double_double`), the quadrature against integrals known in closed form
//! (`precise::tanh_sinh`), and Λ against a second, plain substitution of the defining integral
//! and against N_C at the values of C where Γ is elementary (the tests of this module).
//! A certified value v certifies an f64 candidate y to relative accuracy r when
//! |y − v| + bound ≤ r |v| (`Certified::certifies`).
//!
//! Scope: isotropic models (`alpha`, or `alpha_x` = `alpha_y`), directions in the open upper
//! hemisphere for Λ (θ ∈ [0, π/2); Λ(−w) = −1 − Λ(w) below it is an identity, not a
//! closed form), STD for γ ∈ (3/2, 1e8] (Λ diverges at γ ≤ 3/2), and values that are normal
//! f64 numbers ≥ 1e-290 (smaller ones are `PreciseError::Underflow`, e.g. Beckmann Λ and D
//! where e^{−a²} underflows).

pub mod double_double;
pub mod tanh_sinh;

use super::Estimate;
use double_double::{DoubleDouble, UNIT_ROUNDOFF};
use mfh_reference::{ModelSpec, Vec3};
use tanh_sinh::integrate_unit;

/// The largest relative error bound a returned value may carry.
pub const CERTIFIED_RELATIVE: f64 = 1e-24;

/// The smallest magnitude certified: below, the trailing part of a double-double is
/// subnormal and its precision that of f64.
pub const SMALLEST_CERTIFIED: f64 = 1e-290;

/// The relative level difference at which a quadrature stops refining.
const LEVEL_TARGET: f64 = 1e-28;

/// The relative error assumed for one evaluation of an integrand (≈ 200 u: about ten
/// double-double operations, exp and ln1p of arguments of magnitude ≤ ~100).
const INTEGRAND_ERROR: f64 = 200.0 * UNIT_ROUNDOFF;

/// Why no certified value could be given.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PreciseError {
    /// The model is outside what this path covers.
    #[error("unsupported by the precise path: {0}")]
    Unsupported(String),
    /// A parameter is out of range.
    #[error("{name} = {value} is out of range: must be {requirement}")]
    Parameter {
        /// The parameter.
        name: &'static str,
        /// Its value.
        value: f64,
        /// The condition it broke.
        requirement: &'static str,
    },
    /// The direction is outside the domain of the quantity.
    #[error("direction {direction:?} is out of range: {requirement}")]
    Direction {
        /// The direction.
        direction: Vec3,
        /// The condition it broke.
        requirement: &'static str,
    },
    /// The value is below the normal range of double-double (|v| < 1e-290, where its trailing
    /// part would be subnormal), or underflows to 0.
    #[error("value {value:e} is below the range certified (1e-290)")]
    Underflow {
        /// The value (as computed).
        value: f64,
    },
    /// The error bound is not small enough.
    #[error("relative error bound {relative_bound:e} exceeds {CERTIFIED_RELATIVE:e}")]
    NotCertified {
        /// The bound reached.
        relative_bound: f64,
    },
}

/// A value with a certified bound on its error.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Certified {
    /// The f64 nearest `value_dd`.
    pub value: f64,
    /// The double-double value.
    pub value_dd: DoubleDouble,
    /// Bound on |value_dd − exact| (module docs, "Precision claim").
    pub error_bound: f64,
    /// Integrand evaluations spent.
    pub evaluations: u64,
}

impl Certified {
    /// A value known exactly.
    fn exact(value: DoubleDouble) -> Self {
        Self {
            value: value.to_f64(),
            value_dd: value,
            error_bound: 0.0,
            evaluations: 0,
        }
    }

    /// `value_dd` with a relative bound `relative`, checked against [`CERTIFIED_RELATIVE`].
    fn checked(value: DoubleDouble, relative: f64, evaluations: u64) -> Result<Self, PreciseError> {
        if value.hi().abs() < SMALLEST_CERTIFIED {
            return Err(PreciseError::Underflow { value: value.hi() });
        }
        if !(relative <= CERTIFIED_RELATIVE) || !value.is_finite() {
            return Err(PreciseError::NotCertified {
                relative_bound: relative,
            });
        }
        Ok(Self {
            value: value.to_f64(),
            value_dd: value,
            error_bound: relative * value.hi().abs(),
            evaluations,
        })
    }

    /// The bound relative to the value (0 for an exact 0).
    pub fn relative_bound(&self) -> f64 {
        if self.value_dd.hi() == 0.0 {
            self.error_bound
        } else {
            self.error_bound / self.value_dd.hi().abs()
        }
    }

    /// |candidate − exact| / |exact| at most: the measured difference plus the bound.
    pub fn relative_error_of(&self, candidate: f64) -> f64 {
        let difference = (DoubleDouble::from(candidate) - self.value_dd).hi().abs();
        let scale = self.value_dd.hi().abs();
        if scale == 0.0 {
            difference + self.error_bound
        } else {
            (difference + self.error_bound) / scale
        }
    }

    /// Whether `candidate` is certified to be within `relative` of the exact value.
    pub fn certifies(&self, candidate: f64, relative: f64) -> bool {
        self.relative_error_of(candidate) <= relative
    }

    /// As an [`Estimate`] of the oracles' common shape (the bound widened by the rounding to
    /// f64).
    pub fn estimate(&self) -> Estimate {
        let rounding = (DoubleDouble::from(self.value) - self.value_dd).hi().abs();
        Estimate {
            value: self.value,
            error_bound: self.error_bound + rounding,
            evaluations: self.evaluations,
        }
    }
}

/// The families the precise path covers.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Family {
    /// Beckmann (document 001, Table 1, γ → ∞).
    Beckmann,
    /// GGX (document 001, Table 1, γ = 2).
    Ggx,
    /// STD with shape γ (document 001, §1.1: C = γ, s = α √(γ − 1)).
    Std {
        /// The shape γ ∈ (1, 1e8] (Λ needs γ > 3/2).
        gamma: f64,
    },
}

/// An isotropic model of a covered family, evaluated in double-double.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PreciseModel {
    family: Family,
    alpha: f64,
}

/// The Student view of a model: exponent C and scale s.
#[derive(Debug, Clone, Copy)]
struct StudentShape {
    c: f64,
    s: DoubleDouble,
}

impl PreciseModel {
    /// A validated model: α finite and > 0, γ ∈ (1, 1e8].
    pub fn new(family: Family, alpha: f64) -> Result<Self, PreciseError> {
        if !(alpha > 0.0 && alpha.is_finite()) {
            return Err(PreciseError::Parameter {
                name: "alpha",
                value: alpha,
                requirement: "finite and > 0",
            });
        }
        if let Family::Std { gamma } = family {
            if !(gamma > 1.0 && gamma <= 1e8) {
                return Err(PreciseError::Parameter {
                    name: "gamma",
                    value: gamma,
                    requirement: "> 1 and ≤ 1e8",
                });
            }
        }
        Ok(Self { family, alpha })
    }

    /// The model a spec describes, if it is an isotropic Beckmann, GGX or STD
    /// (`gamma: "inf"` is Beckmann).
    pub fn from_spec(spec: &ModelSpec) -> Result<Self, PreciseError> {
        let isotropic = |alpha: Option<f64>, ax: Option<f64>, ay: Option<f64>| match (alpha, ax, ay)
        {
            (Some(a), None, None) => Ok(a),
            (None, Some(x), Some(y)) if x == y => Ok(x),
            _ => Err(PreciseError::Unsupported(
                "anisotropic or incomplete roughness".to_string(),
            )),
        };
        match *spec {
            ModelSpec::Beckmann(mfh_reference::ndf::beckmann::BeckmannSpec {
                alpha,
                alpha_x,
                alpha_y,
            }) => Self::new(Family::Beckmann, isotropic(alpha, alpha_x, alpha_y)?),
            ModelSpec::Ggx(mfh_reference::ndf::ggx::GgxSpec {
                alpha,
                alpha_x,
                alpha_y,
            }) => Self::new(Family::Ggx, isotropic(alpha, alpha_x, alpha_y)?),
            ModelSpec::Std(mfh_reference::ndf::student::StdSpec {
                gamma,
                alpha,
                alpha_x,
                alpha_y,
            }) => {
                let family = if gamma == f64::INFINITY {
                    Family::Beckmann
                } else {
                    Family::Std { gamma }
                };
                Self::new(family, isotropic(alpha, alpha_x, alpha_y)?)
            }
            _ => Err(PreciseError::Unsupported(format!(
                "family {}",
                spec.family()
            ))),
        }
    }

    /// The family.
    pub fn family(&self) -> Family {
        self.family
    }

    /// The roughness α.
    pub fn alpha(&self) -> f64 {
        self.alpha
    }

    /// The spec of this model (isotropic `alpha`).
    pub fn spec(&self) -> ModelSpec {
        let alpha = Some(self.alpha);
        match self.family {
            Family::Beckmann => ModelSpec::Beckmann(mfh_reference::ndf::beckmann::BeckmannSpec {
                alpha,
                alpha_x: None,
                alpha_y: None,
            }),
            Family::Ggx => ModelSpec::Ggx(mfh_reference::ndf::ggx::GgxSpec {
                alpha,
                alpha_x: None,
                alpha_y: None,
            }),
            Family::Std { gamma } => ModelSpec::Std(mfh_reference::ndf::student::StdSpec {
                gamma,
                alpha,
                alpha_x: None,
                alpha_y: None,
            }),
        }
    }

    /// C and s of a Student member (GGX is C = 2, s = α); `None` for Beckmann.
    fn student_shape(&self) -> Option<StudentShape> {
        let alpha = DoubleDouble::from(self.alpha);
        match self.family {
            Family::Beckmann => None,
            Family::Ggx => Some(StudentShape { c: 2.0, s: alpha }),
            Family::Std { gamma } => Some(StudentShape {
                c: gamma,
                s: alpha * (DoubleDouble::from(gamma) - DoubleDouble::ONE).sqrt(),
            }),
        }
    }

    /// Smith Λ(w) for w in the upper hemisphere (document 001 eq 5): 0 at normal incidence, an
    /// error at or below the horizon.
    pub fn lambda(&self, w: Vec3) -> Result<Certified, PreciseError> {
        let mu = cotangent(w)?;
        let Some(mu) = mu else {
            return Ok(Certified::exact(DoubleDouble::ZERO));
        };
        match self.student_shape() {
            None => Ok(beckmann_lambda(mu / DoubleDouble::from(self.alpha))?),
            Some(shape) => {
                if !(shape.c > 1.5) {
                    return Err(PreciseError::Parameter {
                        name: "gamma",
                        value: shape.c,
                        requirement: "> 3/2 for Λ (the slope mean diverges below)",
                    });
                }
                student_lambda(shape.c, mu / shape.s)
            }
        }
    }

    /// κ = |d ln Λ / d ln μ| at w: how much a relative perturbation of cot θ (e.g. the
    /// rounding of w_z / √(w_x² + w_y²) in f64) moves Λ relatively. Any f64 evaluation of Λ
    /// from w carries an error of the order of κ ε. By a central difference of certified
    /// values, relative step 1e-9 (error ≈ κ · 1e-18 + 1e-15).
    pub fn lambda_condition(&self, w: Vec3) -> Result<f64, PreciseError> {
        let Some(mu) = cotangent(w)? else {
            return Ok(0.0);
        };
        let step = 1e-9;
        let lambda_at = |scale: f64| -> Result<DoubleDouble, PreciseError> {
            let mu = mu * DoubleDouble::from(scale);
            Ok(match self.student_shape() {
                None => beckmann_lambda(mu / DoubleDouble::from(self.alpha))?.value_dd,
                Some(shape) => student_lambda(shape.c, mu / shape.s)?.value_dd,
            })
        };
        let centre = self.lambda(w)?.value_dd;
        let difference = lambda_at(1.0 + step)? - lambda_at(1.0 - step)?;
        Ok((difference / centre).hi().abs() / (2.0 * step))
    }

    /// κ = |d ln D / d ln tan²θ| at m (D's sensitivity to the rounding of tan²θ): t/α² for
    /// Beckmann, 2 (t/α²)/(1 + t/α²) for GGX, C (t/s²)/(1 + t/s²) for STD, t = tan²θ.
    pub fn d_condition(&self, m: Vec3) -> f64 {
        if !(m[2] > 0.0) {
            return 0.0;
        }
        let tan2 = (m[0] * m[0] + m[1] * m[1]) / (m[2] * m[2]);
        match self.student_shape() {
            None => tan2 / (self.alpha * self.alpha),
            Some(StudentShape { c, s }) => {
                let r = tan2 / s.square().hi();
                c * r / (1.0 + r)
            }
        }
    }

    /// D(m) (document 001 eq 2, 10; Table 1), at the unit direction m/|m|; 0 below the horizon.
    pub fn d(&self, m: Vec3) -> Result<Certified, PreciseError> {
        if !m.iter().all(|v| v.is_finite()) || m == [0.0; 3] {
            return Err(PreciseError::Direction {
                direction: m,
                requirement: "finite and non-zero",
            });
        }
        if m[2] <= 0.0 {
            return Ok(Certified::exact(DoubleDouble::ZERO));
        }
        let [x, y, z] = m.map(DoubleDouble::from);
        let r2 = x.square() + y.square();
        let z2 = z.square();
        let cos4 = (z2 / (r2 + z2)).square();
        let tan2 = r2 / z2;
        let alpha2 = DoubleDouble::from(self.alpha).square();
        let pi_alpha2_cos4 = DoubleDouble::PI * alpha2 * cos4;
        let (value, argument) = match self.student_shape() {
            None => {
                let argument = tan2 / alpha2;
                ((-argument).exp() / pi_alpha2_cos4, argument.hi())
            }
            Some(StudentShape { c, s }) => {
                let s2 = s.square();
                let log = (tan2 / s2).ln1p() * DoubleDouble::from(-c);
                let norm = DoubleDouble::from(c - 1.0) / (DoubleDouble::PI * s2 * cos4);
                (norm * log.exp(), log.hi())
            }
        };
        let relative = (64.0 + argument.abs()) * UNIT_ROUNDOFF;
        Certified::checked(value, relative, 1)
    }
}

/// μ = cot θ = w_z / √(w_x² + w_y²) in double-double from the f64 components given; `None`
/// at normal incidence (Λ = 0).
fn cotangent(w: Vec3) -> Result<Option<DoubleDouble>, PreciseError> {
    if !w.iter().all(|v| v.is_finite()) || !(w[2] > 0.0) {
        return Err(PreciseError::Direction {
            direction: w,
            requirement: "finite, in the open upper hemisphere (w_z > 0)",
        });
    }
    let [x, y, z] = w.map(DoubleDouble::from);
    let r = (x.square() + y.square()).sqrt();
    if r.hi() == 0.0 {
        return Ok(None);
    }
    Ok(Some(z / r))
}

/// ln w from a node (w, 1 − w): ln w directly away from 1, ln1p(−(1 − w)) next to it.
fn ln_of_node(w: DoubleDouble, complement: DoubleDouble) -> DoubleDouble {
    if w.hi() < 0.5 {
        w.ln()
    } else {
        (-complement).ln1p()
    }
}

/// N_C = Γ(C − ½)/(√π Γ(C − 1)) of document 001 eq 15, from its definition as a normalization:
/// 1/N_C = ∫ (1 + t²)^{½ − C} dt = B(C − 1, ½) = (1/(C − 1)) ∫₀¹ (1 − w^m)^{−½} dw,
/// m = 1/(C − 1), C ∈ (1, 1e8].
pub fn student_norm(c: f64) -> Result<Certified, PreciseError> {
    if !(c > 1.0 && c <= 1e8) {
        return Err(PreciseError::Parameter {
            name: "C",
            value: c,
            requirement: "> 1 and ≤ 1e8",
        });
    }
    let m = DoubleDouble::ONE / DoubleDouble::from(c - 1.0);
    let integrand = |w: DoubleDouble, complement: DoubleDouble| {
        let one_minus = -(m * ln_of_node(w, complement)).expm1();
        DoubleDouble::ONE / one_minus.sqrt()
    };
    let q = integrate_unit(&integrand, LEVEL_TARGET, INTEGRAND_ERROR);
    let value = DoubleDouble::from(c - 1.0) / q.value;
    let relative = q.error / q.value.hi().abs() + 8.0 * UNIT_ROUNDOFF;
    Certified::checked(value, relative, q.evaluations)
}

/// Λ of the standardized Student slope distribution at the f64 argument x = μ/s > 0 (the
/// argument every f64 route of `student_lambda` takes), C ∈ (3/2, 1e8]: the reference of
/// `mfh cost`, which compares the routes at the same x so that the rounding of x is no one's
/// error.
pub fn student_lambda_standardized(c: f64, x: f64) -> Result<Certified, PreciseError> {
    if !(c > 1.5 && c <= 1e8) {
        return Err(PreciseError::Parameter {
            name: "C",
            value: c,
            requirement: "> 3/2 and ≤ 1e8",
        });
    }
    if !(x > 0.0 && x.is_finite()) {
        return Err(PreciseError::Parameter {
            name: "x",
            value: x,
            requirement: "finite and > 0",
        });
    }
    student_lambda(c, DoubleDouble::from(x))
}

/// Λ of the standardized Student slope distribution at x = μ/s > 0, C > 3/2 (module docs).
fn student_lambda(c: f64, x: DoubleDouble) -> Result<Certified, PreciseError> {
    let norm = student_norm(c)?;
    let one_plus_x2 = DoubleDouble::ONE + x.square();
    let k = DoubleDouble::ONE / DoubleDouble::from(c - 1.5);
    // g(w) = (t − x)/t with t² − x² = (1 + x²) E, E = w^{−k} − 1 = expm1(−k ln w).
    let integrand = |w: DoubleDouble, complement: DoubleDouble| {
        let e = one_plus_x2 * (-(k * ln_of_node(w, complement))).expm1();
        if !e.is_finite() {
            return DoubleDouble::ONE;
        }
        let t = (x.square() + e).sqrt();
        if e.hi() > 1e200 {
            return DoubleDouble::ONE - x / t;
        }
        e / (t * (t + x))
    };
    let q = integrate_unit(&integrand, LEVEL_TARGET, INTEGRAND_ERROR);
    // A′/μ = N_C (1 + x²)^{3/2 − C} / ((2C − 3) x); 2C − 3 is exact in f64 for C ≥ 1.5.
    let exponent = DoubleDouble::from(1.5 - c) * one_plus_x2.ln();
    let prefactor = norm.value_dd * exponent.exp() / (DoubleDouble::from(2.0 * c - 3.0) * x);
    let value = prefactor * q.value;
    let relative = q.error / q.value.hi().abs()
        + norm.relative_bound()
        + (64.0 + exponent.hi().abs()) * UNIT_ROUNDOFF;
    Certified::checked(value, relative, q.evaluations + norm.evaluations)
}

/// Λ of the standardized Beckmann slope distribution at a = μ/α > 0 (module docs):
/// Λ = e^{−a²}/(2a√π) ∫₀¹ u/(u + a) dw, u = y/(√(a² + y) + a), y = −ln w.
fn beckmann_lambda(a: DoubleDouble) -> Result<Certified, PreciseError> {
    let a2 = a.square();
    let integrand = |w: DoubleDouble, complement: DoubleDouble| {
        let y = -ln_of_node(w, complement);
        let u = y / ((a2 + y).sqrt() + a);
        u / (u + a)
    };
    let q = integrate_unit(&integrand, LEVEL_TARGET, INTEGRAND_ERROR);
    let prefactor = (-a2).exp() / (a.ldexp(1) * DoubleDouble::PI.sqrt());
    let value = prefactor * q.value;
    let relative = q.error / q.value.hi().abs() + (64.0 + a2.hi()) * UNIT_ROUNDOFF;
    Certified::checked(value, relative, q.evaluations)
}

#[cfg(test)]
mod tests;
