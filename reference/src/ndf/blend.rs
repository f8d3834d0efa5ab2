//! Eq 1 of seed 000 (Ribardière et al., "A Piecewise-Linear NDF") applied to two analytic
//! isotropic NDFs, e.g. GGX along x and Beckmann along y.

use crate::error::{ParamError, QueryError};
use crate::geometry::{from_spherical, Vec3};
use crate::model::{Model, Ndf, Smith};
use crate::ndf::piecewise_lambda::{both_hemispheres, lambda_exact, EXACT_REL};
use crate::spec::ModelSpec;

/// Interval ends for the Λ quadrature: the analytic profiles have no kinks, but narrow peaks
/// at small θ converge faster with a few fixed cuts.
const CUTS: [f64; 7] = [0.01, 0.03, 0.1, 0.3, 0.6, 1.0, 1.3];

/// The anisotropic blend of two normalized isotropic NDFs (seed 000, eq 1–3):
///
/// ```text
/// D(m) = (cos²φ D_x(θ) D_y(0) + sin²φ D_y(θ) D_x(0)) / c,   c = (D_x(0) + D_y(0)) / 2
/// D(m) = cos²φ D_x(θ) + sin²φ D_y(θ)                         if D_x(0) = D_y(0) = 0
/// ```
///
/// The document blends the analytic D_x, D_y directly here (§1.1, §1.2: "one could be defined
/// from GGX formulation and the second from Beckmann"); it discretizes to a piecewise-linear
/// profile only for its controllable NDF (`PiecewiseLinear`, `Profile::discretize`), which is
/// what makes its Smith derivation tractable. This model does the former: no discretization.
/// Smith Λ is by the exact route of `piecewise_lambda::lambda_exact` (adaptive quadrature of
/// the back-facing projected area, relative accuracy ~1e-13); the document gives no Λ for this
/// case ("Smith-Bourlier GAF derivation is not trivial"). No sampler: the θ-conditional cdf of
/// an analytic blend has no closed form.
///
/// Domain: both models isotropic (probed at construction: D(θ, φ) = D(θ, 0) to 1e-12) and
/// normalized (∫ D cos θ dω = 1, as every `Model` is), D(0) finite.
pub struct Blend {
    x: Box<dyn Model>,
    y: Box<dyn Model>,
    c: Option<f64>,
    kx: f64,
    ky: f64,
}

impl std::fmt::Debug for Blend {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Blend")
            .field("x", &self.x.spec())
            .field("y", &self.y.spec())
            .field("c", &self.c)
            .finish()
    }
}

impl Blend {
    /// A validated blend: D_x from `x`, D_y from `y` (both isotropic).
    pub fn new(x: Box<dyn Model>, y: Box<dyn Model>) -> Result<Self, ParamError> {
        check_isotropic("x", x.as_ref())?;
        check_isotropic("y", y.as_ref())?;
        let dx0 = x.d([0.0, 0.0, 1.0]);
        let dy0 = y.d([0.0, 0.0, 1.0]);
        for (name, v) in [("D_x(0)", dx0), ("D_y(0)", dy0)] {
            if !(v >= 0.0) || !v.is_finite() {
                return Err(ParamError::OutOfRange {
                    name,
                    requirement: "finite and ≥ 0",
                    value: v,
                });
            }
        }
        let (c, kx, ky) = if dx0 == 0.0 && dy0 == 0.0 {
            (None, 1.0, 1.0)
        } else {
            let c = 0.5 * (dx0 + dy0);
            (Some(c), dy0 / c, dx0 / c)
        };
        Ok(Self { x, y, c, kx, ky })
    }

    /// c of eq 3 (`None` in the zero case D_x(0) = D_y(0) = 0).
    pub fn c(&self) -> Option<f64> {
        self.c
    }

    /// The weights (k_x, k_y) = (D_y(0)/c, D_x(0)/c) of D = k_x cos²φ D_x + k_y sin²φ D_y.
    pub fn weights(&self) -> (f64, f64) {
        (self.kx, self.ky)
    }

    /// (k_x D_x(θ), k_y D_y(θ)).
    fn dxy(&self, theta: f64) -> (f64, f64) {
        let m = [theta.sin(), 0.0, theta.cos()];
        (self.kx * self.x.d(m), self.ky * self.y.d(m))
    }
}

/// Probes D(θ, φ) = D(θ, 0) at a few directions.
fn check_isotropic(axis: &'static str, model: &dyn Model) -> Result<(), ParamError> {
    for &theta in &[0.1, 0.5, 1.0, 1.4] {
        let d0 = model.d(from_spherical(theta, 0.0));
        for &phi in &[0.4, 0.9, 1.7, 2.6, 4.0] {
            let d = model.d(from_spherical(theta, phi));
            if !((d - d0).abs() <= 1e-12 * d0.abs().max(1e-300)) {
                return Err(ParamError::NotIsotropic {
                    axis,
                    family: model.family(),
                });
            }
        }
    }
    Ok(())
}

impl Ndf for Blend {
    fn d(&self, m: Vec3) -> f64 {
        if m[2] <= 0.0 {
            return 0.0;
        }
        let r2 = m[0] * m[0] + m[1] * m[1];
        let iso = [r2.sqrt(), 0.0, m[2]];
        let (c2, s2) = if r2 > 0.0 {
            (m[0] * m[0] / r2, m[1] * m[1] / r2)
        } else {
            (1.0, 0.0)
        };
        self.kx * c2 * self.x.d(iso) + self.ky * s2 * self.y.d(iso)
    }
}

impl Smith for Blend {
    /// The exact route: `piecewise_lambda::lambda_exact` with the analytic profiles.
    fn lambda(&self, w: Vec3) -> f64 {
        both_hemispheres(w, |t, c2| {
            lambda_exact(t, c2, &|th| self.dxy(th), &CUTS, EXACT_REL)
        })
    }

    fn lambda_routes(&self) -> Vec<&'static str> {
        vec!["exact"]
    }

    fn lambda_route(&self, w: Vec3, route: &str) -> Result<f64, QueryError> {
        match route {
            "exact" | "default" => Ok(self.lambda(w)),
            _ => Err(QueryError::Route {
                route: route.to_string(),
                reason: "blend Λ routes: exact".to_string(),
            }),
        }
    }
}

impl Model for Blend {
    fn spec(&self) -> ModelSpec {
        ModelSpec::Blend {
            x: Box::new(self.x.spec()),
            y: Box::new(self.y.spec()),
        }
    }

    fn family(&self) -> &'static str {
        "blend"
    }

    fn as_smith(&self) -> Option<&dyn Smith> {
        Some(self)
    }
}
