//! Anisotropic spherical Gaussians (document 003, §3, after Xu et al. 2013): evaluation, the
//! integral over the sphere, the ASG × ASG product and the ASG–SG convolution.

use super::circular::bessel_i0_scaled;
use super::isotropic::Sg;
use super::quadrature::{integrate, integrate_directions, Lobe};
use super::{add, normalize, scale, unit_axis, UNIT_TOLERANCE};
use crate::error::{ParamError, QueryError};
use crate::geometry::{dot, Vec3};
use std::f64::consts::{FRAC_PI_2, PI};

/// Relative accuracy asked of the `_exact` (quadrature) routes.
const EXACT_REL: f64 = 1e-12;

/// An anisotropic spherical Gaussian in geometric form (document 003, §3.1):
///
/// ```text
/// G(v; [x, y, z], [λ, μ], c) = c · max(v·z, 0) · e^{−λ (v·x)² − μ (v·y)²}
/// ```
///
/// with lobe axis z, tangent x, bitangent y (an orthonormal frame), bandwidths λ, μ and
/// amplitude c. The factor max(v·z, 0) is the "smooth term". Domain: x, y, z unit and pairwise
/// orthogonal within 1e-9 (either handedness), λ, μ finite and ≥ 0, c finite. v should be a
/// unit vector.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Asg {
    x: Vec3,
    y: Vec3,
    z: Vec3,
    bandwidths: [f64; 2],
    amplitude: f64,
}

/// F(a) of the ASG integral (document 003, §3.2.1):
///
/// ```text
/// F(a) = ∫₀^{2π} e^{−a cos²φ} dφ = 2π e^{−a/2} I₀(a/2)
/// ```
///
/// Exact closed form (cos²φ = (1 + cos 2φ)/2 and the von Mises integral), where the document
/// suggests a table or a rational fit. Evaluated with the exponentially scaled I₀, so it does
/// not overflow for large a ≥ 0. Any real a.
pub fn f_function(a: f64) -> f64 {
    // e^{−a/2} I₀(a/2) = e^{−a/2 + |a|/2} · e^{−|a/2|} I₀(a/2).
    let shift = -0.5 * a + 0.5 * a.abs();
    2.0 * PI * shift.exp() * bessel_i0_scaled(0.5 * a)
}

fn param(name: &'static str, requirement: &'static str, value: f64) -> ParamError {
    ParamError::OutOfRange {
        name,
        requirement,
        value,
    }
}

impl Asg {
    /// A validated ASG: frame `x`, `y`, `z` (each normalized), bandwidths `[λ, μ]`, amplitude
    /// `c`.
    pub fn new(
        x: Vec3,
        y: Vec3,
        z: Vec3,
        bandwidths: [f64; 2],
        amplitude: f64,
    ) -> Result<Self, ParamError> {
        let x = unit_axis("x", x)?;
        let y = unit_axis("y", y)?;
        let z = unit_axis("z", z)?;
        for (name, d) in [("x·y", dot(x, y)), ("x·z", dot(x, z)), ("y·z", dot(y, z))] {
            if !(d.abs() <= UNIT_TOLERANCE) {
                return Err(param(
                    name,
                    "0: the frame must be orthonormal (within 1e-9)",
                    d,
                ));
            }
        }
        for (name, b) in [("lambda", bandwidths[0]), ("mu", bandwidths[1])] {
            if !(b >= 0.0 && b.is_finite()) {
                return Err(param(name, "finite and ≥ 0", b));
            }
        }
        if !amplitude.is_finite() {
            return Err(param("amplitude", "finite", amplitude));
        }
        Ok(Self {
            x,
            y,
            z,
            bandwidths,
            amplitude,
        })
    }

    /// The tangent x.
    pub fn x(&self) -> Vec3 {
        self.x
    }

    /// The bitangent y.
    pub fn y(&self) -> Vec3 {
        self.y
    }

    /// The lobe axis z.
    pub fn z(&self) -> Vec3 {
        self.z
    }

    /// The bandwidths [λ, μ] (along x and y).
    pub fn bandwidths(&self) -> [f64; 2] {
        self.bandwidths
    }

    /// The amplitude c.
    pub fn amplitude(&self) -> f64 {
        self.amplitude
    }

    /// G(v) = c · max(v·z, 0) · e^{−λ(v·x)² − μ(v·y)²} (document 003, §3.1).
    pub fn eval(&self, v: Vec3) -> f64 {
        let s = dot(v, self.z);
        if !(s > 0.0) {
            return 0.0;
        }
        let (a, b) = (dot(v, self.x), dot(v, self.y));
        self.amplitude * s * (-self.bandwidths[0] * a * a - self.bandwidths[1] * b * b).exp()
    }

    /// The document's approximation of the integral over the sphere (document 003, §3.2.1, Xu et
    /// al. 2013), with λ ≥ μ (the bandwidths are swapped otherwise):
    ///
    /// ```text
    /// ∫_{S²} G(v) dv ≈ c [ π/√(λμ) − e^{−μ}/(2λ) (F(ν) + (ν/μ) F(ν + ν/μ)) ],   ν = λ − μ
    /// ```
    ///
    /// The document prints "=", but this is an approximation (ERRATA.md, E3): the exact
    /// integral is c ∫₀^{2π} (1 − e^{−k(φ)})/(2k(φ)) dφ, k = λ cos²φ + μ sin²φ, and the form
    /// replaces 1/k by (1/λ)(1 + (ν/μ) e^{−(ν/μ) cos²φ}), exact at φ = π/2 only. It is exact
    /// for λ = μ. The document states no error; measured (test `integral_error_measured`,
    /// bandwidths 1e-3 … 1e4): max relative error 4.24 % for μ ≥ 1 (at λ = 2, μ = 1), 1.03e-4
    /// for μ ≥ 5; it diverges as μ → 0 with λ > μ (error ×41 at λ = 0.01, μ = 1e-3). Domain:
    /// λ, μ > 0 (an error otherwise).
    pub fn integral(&self) -> Result<f64, QueryError> {
        let [a, b] = self.bandwidths;
        let (l, m) = if a >= b { (a, b) } else { (b, a) };
        if !(m > 0.0) {
            return Err(QueryError::Argument(
                "the document's ASG integral needs both bandwidths > 0".into(),
            ));
        }
        let nu = l - m;
        let r = nu / m;
        let tail = (-m).exp() / (2.0 * l) * (f_function(nu) + r * f_function(nu + r));
        Ok(self.amplitude * (PI / (l * m).sqrt() - tail))
    }

    /// The document's large-bandwidth approximation of the integral (document 003, §3.2.1: "if
    /// λ, μ > 5, the terms involving F become small"):
    ///
    /// ```text
    /// ∫_{S²} G(v) dv ≈ c π / √(λμ)
    /// ```
    ///
    /// Measured (test `integral_error_measured`): relative error ≤ 0.68 % for λ, μ ≥ 5 (the
    /// worst case is λ = μ = 5, where it is e^{−5}). Domain: λ, μ > 0.
    pub fn integral_large_bandwidth(&self) -> Result<f64, QueryError> {
        let [l, m] = self.bandwidths;
        if !(l > 0.0 && m > 0.0) {
            return Err(QueryError::Argument(
                "π/√(λμ) needs both bandwidths > 0".into(),
            ));
        }
        Ok(self.amplitude * PI / (l * m).sqrt())
    }

    /// The integral over the sphere, exactly: the integral over cos θ done in closed form,
    /// then adaptive quadrature over φ (relative accuracy ≈ 1e-13):
    ///
    /// ```text
    /// ∫_{S²} G(v) dv = c ∫₀^{2π} (1 − e^{−k(φ)}) / (2 k(φ)) dφ,   k(φ) = λ cos²φ + μ sin²φ
    /// ```
    ///
    /// (with t = cos θ: ∫₀¹ t e^{−(1 − t²) k} dt = (1 − e^{−k})/(2k)). Every λ, μ ≥ 0.
    pub fn integral_exact(&self) -> f64 {
        let [l, m] = self.bandwidths;
        let h = |phi: f64| {
            let (s, c) = phi.sin_cos();
            let k = l * c * c + m * s * s;
            if k == 0.0 {
                0.5
            } else {
                -(-k).exp_m1() / (2.0 * k)
            }
        };
        // The integrand is peaked where k is smallest (φ = π/2 if λ > μ, else 0), with width
        // √((1 + min)/(1 + max)).
        let w = ((1.0 + l.min(m)) / (1.0 + l.max(m))).sqrt();
        let mut breaks = vec![0.0, FRAC_PI_2];
        let mut d = w;
        while d < FRAC_PI_2 {
            breaks.push(d);
            breaks.push(FRAC_PI_2 - d);
            d *= 3.0;
        }
        breaks.sort_by(f64::total_cmp);
        breaks.dedup();
        4.0 * self.amplitude * integrate(&h, &breaks, 1e-14, 0.0).value
    }

    /// The quadratic form matrix A = λ x xᵀ + μ y yᵀ of the algebraic form
    /// G(v) = c max(v·z, 0) e^{−vᵀAv}.
    fn matrix(&self) -> [[f64; 3]; 3] {
        let [l, m] = self.bandwidths;
        let mut a = [[0.0; 3]; 3];
        for (i, row) in a.iter_mut().enumerate() {
            for (j, e) in row.iter_mut().enumerate() {
                *e = l * self.x[i] * self.x[j] + m * self.y[i] * self.y[j];
            }
        }
        a
    }

    /// The document's approximation of the product of two ASGs (document 003, §3.2.2):
    ///
    /// ```text
    /// G₁(v) G₂(v) = S(v; z₁) S(v; z₂) e^{−vᵀ(A₁ + A₂)v}
    ///             ≈ S(z₃; z₁) S(z₃; z₂) · max(v·z₃, 0) e^{−vᵀA₃v}
    /// A₃ = A₁ + A₂,  z₃ its eigenvector of smallest eigenvalue e₀ (signed towards z₁ + z₂)
    /// ```
    ///
    /// returned in geometric form: frame [u₁, u₂, z₃] (the other eigenvectors), bandwidths
    /// [e₁ − e₀, e₂ − e₀], amplitude c₁c₂ S(z₃; z₁, z₂) e^{−e₀} (vᵀA₃v = e₀ + (e₁ − e₀)(v·u₁)² +
    /// (e₂ − e₀)(v·u₂)² on the unit sphere). The approximation freezes the ratio
    /// S(v; z₁) S(v; z₂) / S(v; z₃) at v = z₃; the document states no error. Measured (test
    /// `product_is_the_document_form_and_its_error_is_measured`, bandwidths (b, 0.3b) ×
    /// (0.5b, 2b), axes up to 0.5 rad apart): max |approx − exact| relative to the exact
    /// product's peak 0.19 at b = 1, 0.040 at b = 10, 8.0e-3 at b = 100, 2.1e-3 at b = 1000.
    /// An error if the product vanishes identically (z₃ on or behind the horizon of z₁ or
    /// z₂).
    pub fn product(&self, other: &Asg) -> Result<Asg, QueryError> {
        let (a1, a2) = (self.matrix(), other.matrix());
        let mut a3 = [[0.0; 3]; 3];
        for i in 0..3 {
            for j in 0..3 {
                a3[i][j] = a1[i][j] + a2[i][j];
            }
        }
        let (values, vectors) = symmetric_eigen(a3);
        let mut z3 = vectors[0];
        if dot(z3, add(self.z, other.z)) < 0.0 {
            z3 = scale(z3, -1.0);
        }
        let s = dot(z3, self.z).max(0.0) * dot(z3, other.z).max(0.0);
        if !(s > 0.0) {
            return Err(QueryError::Argument(
                "the product's axis z₃ is on or behind the horizon of z₁ or z₂".into(),
            ));
        }
        Asg::new(
            vectors[1],
            vectors[2],
            z3,
            [
                (values[1] - values[0]).max(0.0),
                (values[2] - values[0]).max(0.0),
            ],
            self.amplitude * other.amplitude * s * (-values[0]).exp(),
        )
        .map_err(|e| QueryError::Argument(e.to_string()))
    }

    /// The exact product G₁(v) G₂(v): what [`Asg::product`] approximates.
    pub fn product_exact(&self, other: &Asg, v: Vec3) -> f64 {
        self.eval(v) * other.eval(v)
    }

    /// The document's approximation of the convolution of the ASG with an SG (document 003,
    /// §3.2.3, Xu et al. 2013). With the SG written G_iso(v; p, ν) = e^{2ν(v·p − 1)} (so
    /// ν = half the [`Sg`] sharpness) and amplitude a:
    ///
    /// ```text
    /// C(p) = ∫_{S²} G(v) a G_iso(v; p, ν) dv
    ///      ≈ a c max(p·z, 0) e^{−λν/(λ+ν) (p·x)² − μν/(μ+ν) (p·y)²} π / √((λ + ν)(μ + ν))
    /// ```
    ///
    /// An approximation: the smooth term is frozen at p, ‖v − p‖² is linearized about z, and
    /// the remaining Gaussian integral is taken as π/√((λ+ν)(μ+ν)), which is its value over the
    /// hemisphere v·z ≥ 0 (the document writes ∫ over S², which is twice that: ERRATA.md,
    /// E4). The document claims an L2 error below 0.2 % for λ, μ > 3 and below 2.8 % for
    /// λ, μ > 1. Measured as the relative L2 error over the SG axis p ∈ S², the claims fail
    /// unless the SG is sharp; the error falls roughly as 1/ν, and only slowly with λ, μ:
    /// 4.6 % at λ = μ = 3, ν = 10; 0.53 % at ν = 100; 39 % at λ = μ = 1.5, ν = 1 (ERRATA.md,
    /// E5; tests `convolution_l2_error_claim_*`). Domain: (λ + ν)(μ + ν) > 0.
    pub fn convolve_sg(&self, sg: &Sg) -> Result<f64, QueryError> {
        let [l, m] = self.bandwidths;
        let nu = 0.5 * sg.sharpness();
        if !((l + nu) * (m + nu) > 0.0) {
            return Err(QueryError::Argument(
                "the convolution approximation needs (λ + ν)(μ + ν) > 0".into(),
            ));
        }
        let p = sg.axis();
        let s = dot(p, self.z);
        if !(s > 0.0) {
            return Ok(0.0);
        }
        let (px, py) = (dot(p, self.x), dot(p, self.y));
        let ratio = |a: f64| {
            if a + nu == 0.0 {
                0.0
            } else {
                a * nu / (a + nu)
            }
        };
        let exponent = -ratio(l) * px * px - ratio(m) * py * py;
        Ok(
            sg.amplitude() * self.amplitude * s * exponent.exp() * PI
                / ((l + nu) * (m + nu)).sqrt(),
        )
    }

    /// The convolution ∫ G(v) G_sg(v) dv by adaptive quadrature over the hemisphere v·z ≥ 0
    /// (relative accuracy ≈ 1e-12; ≈ `rel` with [`Asg::convolve_sg_exact_to`]): the exact
    /// counterpart of [`Asg::convolve_sg`].
    pub fn convolve_sg_exact(&self, sg: &Sg) -> f64 {
        self.convolve_sg_exact_to(sg, EXACT_REL)
    }

    /// [`Asg::convolve_sg_exact`] to the relative accuracy `rel` (for sweeps that need less).
    pub fn convolve_sg_exact_to(&self, sg: &Sg, rel: f64) -> f64 {
        let [l, m] = self.bandwidths;
        let ls = sg.sharpness();
        let frame = [self.x, self.y, self.z];
        let peak = self.product_peak(sg);
        let lobes = [
            Lobe::of_sharpness(self.z, l.max(m)),
            Lobe::of_sharpness(sg.axis(), ls),
            Lobe::of_sharpness(peak, l.max(m) + ls),
        ];
        integrate_directions(
            &|v| self.eval(v) * sg.eval(v),
            &frame,
            FRAC_PI_2,
            &lobes,
            rel,
        )
    }

    /// The maximum over the sphere of −λ(v·x)² − μ(v·y)² + λ_s v·p (the exponent of the
    /// ASG × SG integrand without the smooth term), from the secular equation
    /// v_i = b_i / (2(a_i + γ)), |v| = 1, γ > 0 (a = (λ, μ, 0), b = λ_s p in the ASG frame).
    pub(crate) fn product_peak(&self, sg: &Sg) -> Vec3 {
        let [l, m] = self.bandwidths;
        let ls = sg.sharpness();
        let p = sg.axis();
        let b = [
            ls * dot(p, self.x),
            ls * dot(p, self.y),
            ls * dot(p, self.z),
        ];
        let a = [l, m, 0.0];
        if !(ls > 0.0) {
            return self.z;
        }
        let v_of = |g: f64| -> Vec3 {
            let mut v = [0.0; 3];
            for i in 0..3 {
                let d = 2.0 * (a[i] + g);
                v[i] = if d == 0.0 { 0.0 } else { b[i] / d };
            }
            v
        };
        let (mut lo, mut hi) = (0.0f64, 0.5 * ls + l.max(m) + 1.0);
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            let v = v_of(mid);
            if dot(v, v) > 1.0 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let mut v = v_of(hi);
        let n2 = dot(v, v);
        if n2 < 1.0 {
            // The "hard case" (b_z = 0): fill up with the z component.
            v[2] = (1.0 - n2).sqrt();
        }
        let local = normalize(v);
        add(
            add(scale(self.x, local[0]), scale(self.y, local[1])),
            scale(self.z, local[2]),
        )
    }
}

/// Eigen-decomposition of a symmetric 3×3 matrix by cyclic Jacobi rotations: eigenvalues in
/// ascending order and their unit eigenvectors.
fn symmetric_eigen(mut a: [[f64; 3]; 3]) -> ([f64; 3], [Vec3; 3]) {
    let mut v = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    for _ in 0..64 {
        let off = a[0][1] * a[0][1] + a[0][2] * a[0][2] + a[1][2] * a[1][2];
        let diag = a[0][0] * a[0][0] + a[1][1] * a[1][1] + a[2][2] * a[2][2];
        if off <= 1e-34 * diag || off < f64::MIN_POSITIVE {
            break;
        }
        for (p, q) in [(0, 1), (0, 2), (1, 2)] {
            if a[p][q] == 0.0 {
                continue;
            }
            let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
            let t = if theta.abs() > 1e150 {
                0.5 / theta
            } else {
                theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt())
            };
            let c = 1.0 / (t * t + 1.0).sqrt();
            let s = t * c;
            for row in a.iter_mut() {
                let (kp, kq) = (row[p], row[q]);
                row[p] = c * kp - s * kq;
                row[q] = s * kp + c * kq;
            }
            let (row_p, row_q) = (a[p], a[q]);
            for k in 0..3 {
                a[p][k] = c * row_p[k] - s * row_q[k];
                a[q][k] = s * row_p[k] + c * row_q[k];
            }
            for row in v.iter_mut() {
                let (kp, kq) = (row[p], row[q]);
                row[p] = c * kp - s * kq;
                row[q] = s * kp + c * kq;
            }
        }
    }
    let mut order = [0usize, 1, 2];
    order.sort_by(|&i, &j| a[i][i].total_cmp(&a[j][j]));
    let values = order.map(|i| a[i][i]);
    let vectors = order.map(|i| normalize([v[0][i], v[1][i], v[2][i]]));
    (values, vectors)
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::geometry::from_spherical;
    use crate::sg::oracle::{cuts, directions, integrate_cut};
    use crate::sg::{cross, frame_around};
    use crate::test_support::rel_err;

    const BANDWIDTHS: [f64; 13] = [
        1e-3, 0.01, 0.1, 0.5, 1.0, 2.0, 3.0, 5.0, 10.0, 30.0, 100.0, 1e3, 1e4,
    ];

    pub(crate) fn asg_at(z: Vec3, twist: f64, l: f64, m: f64, c: f64) -> Asg {
        let f = frame_around(z);
        let (s, co) = twist.sin_cos();
        let x = add(scale(f[0], co), scale(f[1], s));
        let y = cross(z, x);
        Asg::new(x, y, z, [l, m], c).unwrap()
    }

    /// The independent oracle for the ASG integral: nested double-exponential quadrature over
    /// (θ, φ) of the ASG (λ ≥ μ) in its own frame, cut around the ridge at φ = π/2, over the
    /// half turn φ ∈ [π/2, 3π/2] (the integrand is even about π/2).
    pub(crate) fn integral_oracle(l: f64, m: f64) -> f64 {
        let w = 1.0 / (1.0 + l.max(m)).sqrt();
        let f = |theta: f64, phi: f64| {
            let (st, ct) = theta.sin_cos();
            let (sp, cp) = phi.sin_cos();
            ct * (-(l * cp * cp + m * sp * sp) * st * st).exp()
        };
        directions(&f, FRAC_PI_2, (0.0, FRAC_PI_2), w, 1e-11, true)
    }

    #[test]
    fn validation() {
        let (x, y, z) = ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]);
        assert!(Asg::new(x, y, z, [1.0, 2.0], 1.0).is_ok());
        assert!(Asg::new(y, x, z, [0.0, 0.0], -1.0).is_ok());
        assert!(Asg::new(x, normalize([0.0, 1.0, 1e-8]), z, [1.0, 2.0], 1.0).is_err());
        assert!(Asg::new(x, y, [0.0, 0.0, 1.1], [1.0, 2.0], 1.0).is_err());
        assert!(Asg::new(x, x, z, [1.0, 2.0], 1.0).is_err());
        assert!(Asg::new(x, y, z, [-1.0, 2.0], 1.0).is_err());
        assert!(Asg::new(x, y, z, [1.0, f64::NAN], 1.0).is_err());
        assert!(Asg::new(x, y, z, [f64::INFINITY, 1.0], 1.0).is_err());
        assert!(Asg::new(x, y, z, [1.0, 1.0], f64::NAN).is_err());
        assert!(Asg::new([f64::NAN, 0.0, 0.0], y, z, [1.0, 1.0], 1.0).is_err());
        let g = Asg::new(x, y, z, [1.0, 0.0], 1.0).unwrap();
        assert!(g.integral().is_err());
        assert!(g.integral_large_bandwidth().is_err());
    }

    #[test]
    fn eval_is_the_definition() {
        let g = asg_at(normalize([0.2, 0.3, 0.9]), 0.7, 3.0, 0.5, 2.0);
        let v = normalize([0.1, 0.5, 0.8]);
        let want = 2.0
            * dot(v, g.z())
            * (-3.0 * dot(v, g.x()).powi(2) - 0.5 * dot(v, g.y()).powi(2)).exp();
        assert!(rel_err(g.eval(v), want) < 1e-15);
        assert_eq!(g.eval(scale(g.z(), -1.0)), 0.0);
    }

    #[test]
    fn f_function_is_its_integral() {
        for a in [-3.0f64, 0.0, 1e-3, 1.0, 10.0, 1e3, 1e5] {
            let cut = cuts(FRAC_PI_2, 1.0 / (1.0 + a.abs()).sqrt(), 0.0, FRAC_PI_2);
            let q = 4.0 * integrate_cut(&|p: f64| (-a * p.cos().powi(2)).exp(), &cut, 1e-13);
            assert!(
                rel_err(f_function(a), q) < 1e-13,
                "a = {a}: {} vs {q}",
                f_function(a)
            );
        }
    }

    #[test]
    fn exact_integral_matches_quadrature() {
        for l in [1e-3, 1.0, 100.0, 1e4] {
            for m in [1e-3, 1.0, 100.0, 1e4].into_iter().filter(|&m| m <= l) {
                let g = asg_at(normalize([0.5, -0.5, 0.7]), 0.3, l, m, 1.5);
                let q = 1.5 * integral_oracle(l, m);
                let got = g.integral_exact();
                assert!(rel_err(got, q) < 1e-10, "λ = {l}, μ = {m}: {got} vs {q}");
            }
        }
        // λ = μ: the integral is π(1 − e^{−λ})/λ in closed form.
        let g = asg_at([0.0, 0.0, 1.0], 0.0, 2.0, 2.0, 1.0);
        assert!(rel_err(g.integral_exact(), PI * -(-2.0f64).exp_m1() / 2.0) < 1e-13);
    }

    #[test]
    fn integral_error_measured() {
        let mut worst = [0.0f64; 3]; // μ ≥ 1, μ ≥ 5, π/√(λμ) for λ, μ ≥ 5
        let mut worst_at = [(0.0, 0.0); 3];
        let mut worst_small = 0.0f64;
        for &l in &BANDWIDTHS {
            for &m in BANDWIDTHS.iter().filter(|&&m| m <= l) {
                let g = asg_at([0.0, 0.0, 1.0], 0.0, l, m, 1.0);
                let swapped = asg_at([0.0, 0.0, 1.0], 0.0, m, l, 1.0);
                let exact = g.integral_exact();
                let doc = g.integral().unwrap();
                assert!(rel_err(swapped.integral().unwrap(), doc) < 1e-15);
                let err = rel_err(doc, exact);
                if l == m {
                    assert!(err < 1e-12, "λ = μ = {l}: {err}");
                }
                worst_small = worst_small.max(err);
                for (k, floor) in [(0, 1.0), (1, 5.0)] {
                    if m >= floor && err > worst[k] {
                        worst[k] = err;
                        worst_at[k] = (l, m);
                    }
                }
                if m >= 5.0 {
                    let e = rel_err(g.integral_large_bandwidth().unwrap(), exact);
                    if e > worst[2] {
                        worst[2] = e;
                        worst_at[2] = (l, m);
                    }
                }
            }
        }
        eprintln!(
            "ASG integral (seed 003 §3.2.1): F-form max rel err {:.3e} at {:?} (μ ≥ 1), \
             {:.3e} at {:?} (μ ≥ 5), {worst_small:.3e} over all; π/√(λμ) {:.3e} at {:?} \
             (λ, μ ≥ 5)",
            worst[0], worst_at[0], worst[1], worst_at[1], worst[2], worst_at[2]
        );
        assert!(worst[0] < 0.0425 && worst[0] > 0.0423, "{worst:?}");
        assert!(worst[1] < 1.04e-4, "{worst:?}");
        assert!(worst[2] < 0.0068 && worst[2] > 0.0067, "{worst:?}");
        assert!(worst_small > 10.0);
        // ERRATA.md, E3: printed as an equality; it is not one for λ ≠ μ.
        let g = asg_at([0.0, 0.0, 1.0], 0.0, 2.0, 1.0, 1.0);
        assert!(rel_err(g.integral().unwrap(), g.integral_exact()) > 0.04);
    }

    #[test]
    fn product_is_the_document_form_and_its_error_is_measured() {
        let mut report = Vec::new();
        for (b, bound) in [
            (1.0, 0.193),
            (10.0, 0.0397),
            (100.0, 8.0e-3),
            (1e3, 2.08e-3),
        ] {
            let mut worst = 0.0f64;
            for beta in [0.0, 0.1, 0.5] {
                let g1 = asg_at([0.0, 0.0, 1.0], 0.0, b, 0.3 * b, 1.2);
                let g2 = asg_at(from_spherical(beta, 0.5), 1.0, 0.5 * b, 2.0 * b, 0.8);
                let p = g1.product(&g2).unwrap();
                // The exponent is exact: vᵀA₃v = e₀ + Σ (e_i − e₀)(v·u_i)², so at z₃ the
                // approximation equals the exact product.
                let z3 = p.z();
                assert!(rel_err(p.eval(z3), g1.product_exact(&g2, z3)) < 1e-10);
                let mut peak = 0.0f64;
                let mut err = 0.0f64;
                let w = 1.0 / b.sqrt();
                let f = frame_around(z3);
                for i in 0..=60 {
                    for j in 0..48 {
                        let theta = (6.0 * w * i as f64 / 60.0).min(FRAC_PI_2);
                        let phi = 2.0 * PI * j as f64 / 48.0;
                        let (st, ct) = theta.sin_cos();
                        let v = add(
                            add(scale(f[0], st * phi.cos()), scale(f[1], st * phi.sin())),
                            scale(f[2], ct),
                        );
                        let exact = g1.product_exact(&g2, v);
                        peak = peak.max(exact);
                        err = err.max((p.eval(v) - exact).abs());
                    }
                }
                worst = worst.max(err / peak);
            }
            report.push(format!("bandwidth {b}: {worst:.3e}"));
            assert!(worst < bound && worst > 0.9 * bound, "{b}: {worst}");
        }
        eprintln!("ASG product (seed 003 §3.2.2), max |approx − exact| / peak: {report:?}");
    }

    #[test]
    fn printed_convolution_gaussian_integral_is_over_the_hemisphere() {
        // ERRATA.md, E4: §3.2.3 approximates
        // ∫_{S²} e^{−(λ+ν)(v·x − a)² − (μ+ν)(v·y − b)²} dv ≈ π/√((λ+ν)(μ+ν)). The integrand does
        // not vanish on the lower hemisphere (no smooth term left), so over S² the integral is
        // twice that; π/√(…) is its value over v·z ≥ 0. Here a = b = 0, λ+ν = μ+ν = A.
        for a in [100.0, 1e4] {
            let f = |t: f64| 2.0 * PI * (-a * t.sin().powi(2)).exp() * t.sin();
            let w = 1.0 / (1.0f64 + a).sqrt();
            let mut cut = cuts(0.0, w, 0.0, FRAC_PI_2);
            cut.extend(cuts(PI, w, FRAC_PI_2, PI));
            cut.sort_by(f64::total_cmp);
            cut.dedup();
            let sphere = integrate_cut(&f, &cut, 1e-13);
            let hemisphere = integrate_cut(&f, &cuts(0.0, w, 0.0, FRAC_PI_2), 1e-13);
            let printed = PI / a;
            assert!(
                (sphere / printed - 2.0).abs() < 2.0 / a,
                "A = {a}: {}",
                sphere / printed
            );
            assert!((hemisphere / printed - 1.0).abs() < 1.0 / a);
        }
    }

    #[test]
    fn printed_asg_warp_axis_is_not_o() {
        // ERRATA.md, E9: §3.3.2 prints z_i = 2(o·z_h)z_h = o. The peak of
        // G_h(h(i)), h(i) = (i + o)/‖i + o‖, is where h(i) = z_h, i.e. at the mirror direction
        // z_i = 2(o·z_h)z_h − o, which is not o (unless o = z_h).
        let g = asg_at(normalize([0.1, 0.2, 1.0]), 0.4, 30.0, 5.0, 1.0);
        let o = normalize([0.5, -0.2, 0.8]);
        let half = |i: Vec3| normalize(add(i, o));
        let zh = g.z();
        let zi = add(scale(zh, 2.0 * dot(o, zh)), scale(o, -1.0));
        assert!(rel_err(g.eval(half(zi)), 1.0) < 1e-12);
        assert!(g.eval(half(o)) < 0.5, "{}", g.eval(half(o)));
        // And z_i is the maximum: nearby directions are lower.
        for d in [[1e-3, 0.0, 0.0], [0.0, 1e-3, 0.0], [0.0, 0.0, 1e-3]] {
            assert!(g.eval(half(normalize(add(zi, d)))) < 1.0);
        }
    }

    #[test]
    fn eigen_decomposition() {
        let a = [[2.0, -1.0, 0.3], [-1.0, 4.0, 0.7], [0.3, 0.7, 1.0]];
        let (values, vectors) = symmetric_eigen(a);
        assert!(values[0] <= values[1] && values[1] <= values[2]);
        for k in 0..3 {
            for i in 0..3 {
                let av: f64 = (0..3).map(|j| a[i][j] * vectors[k][j]).sum();
                assert!((av - values[k] * vectors[k][i]).abs() < 1e-13);
            }
        }
    }

    /// The relative L2 error over the SG axis p ∈ S² of the document's convolution
    /// approximation, ‖C_approx − C‖₂ / ‖C‖₂, for an ASG (λ, μ) and an SG e^{2ν(v·p − 1)}, on a
    /// product grid of 7-point Gauss rules (15-point Kronrod with `fine`) over the θ pieces and
    /// φ over a quadrant (by the ASG's symmetry), with the exact C(p) to relative accuracy 1e-7.
    fn convolution_l2_error(l: f64, m: f64, nu: f64, theta_pieces: &[f64], fine: bool) -> f64 {
        use crate::sg::quadrature::{gauss_rule, kronrod_rule};
        let rule = if fine { kronrod_rule } else { gauss_rule };
        let g = asg_at([0.0, 0.0, 1.0], 0.0, l, m, 1.0);
        let theta: Vec<(f64, f64)> = theta_pieces
            .windows(2)
            .flat_map(|c| rule(c[0], c[1]))
            .collect();
        let phi = rule(0.0, FRAC_PI_2);
        let (mut num, mut den) = (0.0, 0.0);
        for &(t, wt) in &theta {
            for &(p, wp) in &phi {
                let sg = Sg::new(from_spherical(t, p), 2.0 * nu, 1.0).unwrap();
                let exact = g.convolve_sg_exact_to(&sg, 1e-7);
                let approx = g.convolve_sg(&sg).unwrap();
                let w = wt * wp * t.sin();
                num += w * (approx - exact).powi(2);
                den += w * exact * exact;
            }
        }
        (num / den).sqrt()
    }

    // ERRATA.md, E5. Document 003 §3.2.3: "When λ, μ > 3, the L2-error is less than 0.2 %.
    // When λ, μ > 1, the error is bounded by 2.8 %." Measured as the relative L2 error over the
    // SG's axis p ∈ S² (`convolution_l2_error`), both claims fail unless the SG is sharp: the
    // error falls roughly as 1/ν.
    const THETA_PIECES: [f64; 4] = [0.0, 0.25 * PI, FRAC_PI_2, PI];

    #[test]
    fn convolution_l2_error_claim_for_bandwidths_above_3_fails() {
        let e_sharp = convolution_l2_error(3.5, 3.5, 100.0, &THETA_PIECES, false);
        let e_mid = convolution_l2_error(3.5, 3.5, 10.0, &THETA_PIECES, false);
        eprintln!(
            "ASG–SG convolution (seed 003 §3.2.3), relative L2 error over p, λ = μ = 3.5: \
             {e_mid:.3e} (ν = 10), {e_sharp:.3e} (ν = 100); claimed < 2e-3"
        );
        assert!(e_sharp > 0.002 && e_sharp < 0.01, "{e_sharp}");
        assert!(e_mid > 0.028 && e_mid < 0.06, "{e_mid}");
    }

    #[test]
    fn convolution_l2_error_claim_for_bandwidths_above_1_fails() {
        let e_broad = convolution_l2_error(1.5, 1.5, 1.0, &THETA_PIECES, false);
        eprintln!(
            "ASG–SG convolution (seed 003 §3.2.3), relative L2 error over p, λ = μ = 1.5, \
             ν = 1: {e_broad:.3e}; claimed < 2.8e-2"
        );
        assert!(e_broad > 0.3 && e_broad < 0.5, "{e_broad}");
    }

    #[test]
    #[cfg_attr(not(mfh_extensive), ignore = "extensive tier: set MFH_EXTENSIVE=1")]
    fn convolution_l2_error_sweep() {
        // The extensive tier: the whole grid behind ERRATA.md, E5.
        let pieces = [0.0, 0.25 * PI, FRAC_PI_2, 0.75 * PI, PI];
        // The bounds the measured sweep justifies (`Asg::convolve_sg`'s documentation,
        // ERRATA.md E5): 4.6 % at λ = μ = 3, ν = 10 and 0.53 % at ν = 100 (±25 %); every
        // error finite, and at ν = 100 below its value at ν = 1 (it falls roughly as 1/ν).
        let at = |l: f64, m: f64, nu: f64| convolution_l2_error(l, m, nu, &pieces, true);
        let e10 = at(3.0, 3.0, 10.0);
        assert!(
            (0.0345..=0.0575).contains(&e10),
            "λ = μ = 3, ν = 10: {e10:.3e}"
        );
        let e100 = at(3.0, 3.0, 100.0);
        assert!(
            (0.0040..=0.0066).contains(&e100),
            "λ = μ = 3, ν = 100: {e100:.3e}"
        );
        for (l, m) in [
            (1.0, 1.0),
            (3.0, 1.0),
            (3.0, 3.0),
            (10.0, 3.0),
            (10.0, 10.0),
            (30.0, 30.0),
        ] {
            let row: Vec<String> = [0.3, 1.0, 3.0, 10.0, 30.0, 100.0]
                .iter()
                .map(|&nu| {
                    let e = convolution_l2_error(l, m, nu, &pieces, true);
                    assert!(e.is_finite() && e >= 0.0, "λ = {l}, μ = {m}, ν = {nu}: {e}");
                    format!("ν = {nu}: {e:.2e}")
                })
                .collect();
            let (first, last) = (at(l, m, 1.0), at(l, m, 100.0));
            assert!(
                last < first,
                "λ = {l}, μ = {m}: ν = 100 {last:.2e} ≥ ν = 1 {first:.2e}"
            );
            eprintln!("λ = {l}, μ = {m}: {}", row.join(", "));
        }
    }

    /// The convolution's exact route against the oracle: nested double-exponential quadrature
    /// in the ASG frame, over the hemisphere, cut around the product's peak. Cases are
    /// (λ, μ, SG sharpness, angle of the SG axis from z).
    fn check_convolution_exact_route(cases: &[(f64, f64, f64, f64)]) {
        for &(l, m, ls, beta) in cases {
            let g = asg_at([0.0, 0.0, 1.0], 0.0, l, m, 1.0);
            let sg = Sg::new(from_spherical(beta, 0.9), ls, 1.0).unwrap();
            let peak = g.product_peak(&sg);
            let theta_peak = peak[2].clamp(-1.0, 1.0).acos().min(FRAC_PI_2);
            let phi_peak = peak[1].atan2(peak[0]);
            let w = 1.0 / (1.0 + l.max(m) + ls).sqrt();
            let q = directions(
                &|t, p| {
                    let v = from_spherical(t, p);
                    g.eval(v) * sg.eval(v)
                },
                FRAC_PI_2,
                (theta_peak, phi_peak),
                w,
                1e-11,
                false,
            );
            let got = g.convolve_sg_exact(&sg);
            assert!(rel_err(got, q) < 1e-10, "{l} {m} {ls} {beta}: {got} vs {q}");
        }
    }

    #[test]
    fn convolution_exact_route_matches_quadrature_broad() {
        check_convolution_exact_route(&[
            (1.0, 1.0, 1.0, 0.3),
            (1e-3, 5.0, 100.0, 1.0),
            (100.0, 3.0, 10.0, 0.2),
        ]);
    }

    #[test]
    fn convolution_exact_route_matches_quadrature_sharp() {
        check_convolution_exact_route(&[
            (1e4, 1e4, 1e4, 0.005),
            (1e4, 1.0, 2.0, 1.2),
            (10.0, 10.0, 1e4, 1.6),
        ]);
    }
}
