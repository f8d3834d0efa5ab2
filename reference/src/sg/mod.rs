//! Spherical Gaussians (SG), anisotropic spherical Gaussians (ASG) and circular Gaussians, after
//! document 003 (P. Khungurn, "Spherical Gaussian Technology", 2016), which surveys Wang et al. 2009
//! (SG shading), Xu et al. 2013 (ASG) and Iwasaki et al. 2012/2014 (circular Gaussians).
//!
//! Every approximation the document gives has a function for the document's route and an
//! `_exact` function that computes the same quantity by adaptive quadrature (the private
//! module `quadrature`, inside this crate so that `mfh eval` can answer `"route": "exact"`).
//! Where the printed document is wrong, `reference/ERRATA.md` says so and names the unit
//! test that shows it.

#[cfg(test)]
mod accuracy;
pub mod asg;
pub mod circular;
pub mod isotropic;
pub(crate) mod quadrature;

pub use asg::Asg;
pub use circular::CircularGaussian;
pub use isotropic::Sg;

use crate::geometry::{dot, Vec3};

/// How far from unit length (and from orthogonal) a given axis or frame may be.
pub const UNIT_TOLERANCE: f64 = 1e-9;

#[cfg(test)]
pub(crate) use crate::geometry::cross;

/// s·a.
#[inline]
pub(crate) fn scale(a: Vec3, s: f64) -> Vec3 {
    [a[0] * s, a[1] * s, a[2] * s]
}

/// a + b.
#[inline]
pub(crate) fn add(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// a − b.
#[inline]
pub(crate) fn sub(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// a / |a| (a must be non-zero).
#[inline]
pub(crate) fn normalize(a: Vec3) -> Vec3 {
    scale(a, 1.0 / dot(a, a).sqrt())
}

/// An orthonormal frame `[t, b, z]` whose third vector is the unit vector `z` (Duff et al.
/// 2017, "Building an orthonormal basis, revisited").
pub(crate) fn frame_around(z: Vec3) -> [Vec3; 3] {
    let sign = 1.0f64.copysign(z[2]);
    let a = -1.0 / (sign + z[2]);
    let b = z[0] * z[1] * a;
    let t = [1.0 + sign * z[0] * z[0] * a, sign * b, -sign * z[0]];
    let bt = [b, sign + z[1] * z[1] * a, -z[1]];
    [t, bt, z]
}

/// Checks that `v` is finite and unit within [`UNIT_TOLERANCE`], and returns it normalized.
pub(crate) fn unit_axis(name: &'static str, v: Vec3) -> Result<Vec3, crate::ParamError> {
    if !crate::geometry::is_unit(v, UNIT_TOLERANCE) {
        return Err(crate::ParamError::OutOfRange {
            name,
            requirement: "a finite unit vector (within 1e-9)",
            value: crate::geometry::length(v),
        });
    }
    Ok(normalize(v))
}

/// The independent oracle of this module's unit tests: `crate::test_support`'s
/// double-exponential quadrature, over pieces cut around the peaks, with an absolute floor from
/// a first coarse pass (without it, bisection of pieces where the integrand underflows would
/// never stop).
#[cfg(test)]
pub(crate) mod oracle {
    use crate::test_support::integrate;

    /// Breakpoints on [lo, hi]: lo, hi, c and `c ± w·4^k` inside.
    pub fn cuts(c: f64, w: f64, lo: f64, hi: f64) -> Vec<f64> {
        let mut v = vec![lo, hi];
        let mut d = w;
        while d < hi - lo {
            for x in [c - d, c + d] {
                if x > lo && x < hi {
                    v.push(x);
                }
            }
            d *= 4.0;
        }
        if c > lo && c < hi {
            v.push(c);
        }
        v.sort_by(f64::total_cmp);
        v.dedup();
        v
    }

    /// ∫ f over [cuts[0], cuts[last]], piece by piece, to relative accuracy ≈ `rel`.
    pub fn integrate_cut(f: &dyn Fn(f64) -> f64, cuts: &[f64], rel: f64) -> f64 {
        let magnitude: f64 = cuts
            .windows(2)
            .map(|w| integrate(f, w[0], w[1], 1e-6, 1e-300).0.abs())
            .sum();
        let abs = (rel * magnitude * 1e-3).max(1e-300);
        cuts.windows(2)
            .map(|w| integrate(f, w[0], w[1], rel, abs).0)
            .sum()
    }

    /// ∫ f(θ, φ) sin θ dφ dθ over θ ∈ [0, θmax], φ over a whole turn, with the polar angle
    /// measured from +z (`crate::geometry::from_spherical`), cut around a peak at
    /// (θp, φp) of angular width w; relative accuracy ≈ `rel`. With `mirror`, f is taken to be
    /// even about φp and only half a turn is integrated. The inner (φ) integrals are single
    /// double-exponential rules (the rule inside `test_support::integrate`) on pieces cut around
    /// the peak, where f is analytic and resolved; the outer one is adaptive.
    pub fn directions(
        f: &dyn Fn(f64, f64) -> f64,
        theta_max: f64,
        (theta_peak, phi_peak): (f64, f64),
        w: f64,
        rel: f64,
        mirror: bool,
    ) -> f64 {
        use std::f64::consts::PI;
        let theta_cuts = cuts(theta_peak.min(theta_max), w, 0.0, theta_max);
        let inner = |theta: f64, abs: f64| {
            let s = theta.sin();
            if s == 0.0 {
                return 0.0;
            }
            let pw = (w / s).min(1.0);
            let (lo, factor) = if mirror {
                (phi_peak, 2.0)
            } else {
                (phi_peak - PI, 1.0)
            };
            let phi_cuts = cuts(phi_peak, pw, lo, phi_peak + PI);
            let each = abs / (s * factor * phi_cuts.len() as f64);
            factor
                * s
                * phi_cuts
                    .windows(2)
                    .map(|c| {
                        quadrature::double_exponential::integrate(
                            |phi| f(theta, phi),
                            c[0],
                            c[1],
                            each,
                        )
                        .integral
                    })
                    .sum::<f64>()
        };
        let outer = |rel: f64, abs: f64| -> f64 {
            let inner_abs = abs / (2.0 * PI * theta_max) * 0.1;
            theta_cuts
                .windows(2)
                .map(|c| integrate(&|t| inner(t, inner_abs), c[0], c[1], rel, abs).0)
                .sum()
        };
        // A coarse first pass, against a guess from the peak's height, fixes the magnitude.
        let peak = f(theta_peak.min(theta_max), phi_peak).abs().max(1e-300);
        let rough = outer(1e-6, peak * w * w * 1e-9).abs();
        outer(rel, (rel * rough * 1e-2).max(1e-300))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_are_orthonormal() {
        for z in [
            [0.0, 0.0, 1.0],
            [0.0, 0.0, -1.0],
            normalize([1.0, -2.0, 0.3]),
            normalize([0.0, 1.0, -1e-12]),
        ] {
            let f = frame_around(z);
            for i in 0..3 {
                for j in 0..3 {
                    let expected = if i == j { 1.0 } else { 0.0 };
                    assert!((dot(f[i], f[j]) - expected).abs() < 1e-15);
                }
            }
            assert_eq!(f[2], z);
        }
    }
}
