//! The visible-slope moments of Gaussian slopes (document 002, D_s): the closed forms against
//! numerical cubature with n × n points, the trade a renderer that filters slopes makes.
//!
//! - Routes: the model's closed form (eq 42–46 in the stable form of
//!   `GaussianSlopes::visible_moments`), the document's pseudocode with its erratum corrected,
//!   the equations as printed (eq 59's sign of E₁; ERRATA.md document 002), and tensor Gauss–Hermite
//!   cubature of the defining integrals with n ∈ {4, 8, 16, 32, 64} points per axis.
//! - Reference: `oracle::visible_moments::visible_moments_oracle`, adaptive cubature of the
//!   definition D_s ∝ p_s(s)(w_z − s·w_xy)⁺ to relative 1e-11 (never one of the routes).
//! - Inputs: three slope distributions (isotropic, anisotropic and correlated with a mean
//!   offset, strongly correlated) seen from θ ∈ {0.3, 0.8, 1.2, 1.45, 1.55} at φ = 0.4; each
//!   input is one component of the five (mean x, mean y, var x, var y, cov xy), so one
//!   evaluation of a route computes the whole moment set.

use super::{Candidate, Sweep};
use crate::check::ds::{components, units};
use crate::oracle::visible_moments::visible_moments_oracle;
use mfh_reference::geometry::from_spherical;
use mfh_reference::slopes::gaussian::GaussianSlopes;
use mfh_reference::slopes::pseudocode::Transcription;
use std::rc::Rc;

/// The slope distributions (mean, covariance).
pub const CASES: [([f64; 2], [[f64; 2]; 2]); 3] = [
    ([0.0, 0.0], [[0.09, 0.0], [0.0, 0.09]]),
    ([0.1, -0.05], [[0.04, 0.01], [0.01, 0.09]]),
    ([0.05, 0.02], [[0.16, 0.15], [0.15, 0.16]]),
];

/// The incidence angles.
pub const THETAS: [f64; 5] = [0.3, 0.8, 1.2, 1.45, 1.55];

/// The view azimuth.
pub const PHI: f64 = 0.4;

/// Points per axis of the Gauss–Hermite routes.
pub const POINTS: [usize; 5] = [4, 8, 16, 32, 64];

const COMPONENTS: usize = 5;

/// A route: the five components of the moments of a slope distribution seen from a direction.
type Route = Rc<dyn Fn(&GaussianSlopes, [f64; 3]) -> [f64; COMPONENTS]>;

/// Nodes and weights of the n-point Gauss–Hermite rule for the standard normal,
/// E[f(Z)] ≈ Σ wᵢ f(zᵢ), by the Golub–Welsch eigenproblem of the Jacobi matrix of the
/// probabilists' Hermite polynomials (off-diagonal √k; weights = first eigenvector
/// components squared). Written here rather than taken from `gauss-quad` (whose rule is for
/// the weight e^{−x²}) to add no dependency for one knob of `mfh cost`: nalgebra, already in
/// the tree through statrs, does the numerical work.
pub fn gauss_hermite_normal(n: usize) -> (Vec<f64>, Vec<f64>) {
    let jacobi = nalgebra::DMatrix::from_fn(n, n, |i, j| {
        if i + 1 == j || j + 1 == i {
            (i.max(j) as f64).sqrt()
        } else {
            0.0
        }
    });
    let eigen = nalgebra::SymmetricEigen::new(jacobi);
    let mut rule: Vec<(f64, f64)> = (0..n)
        .map(|i| (eigen.eigenvalues[i], eigen.eigenvectors[(0, i)].powi(2)))
        .collect();
    rule.sort_by(|a, b| a.0.total_cmp(&b.0));
    rule.into_iter().unzip()
}

/// The moments of D_s by the tensor Gauss–Hermite rule `(nodes, weights)` over the Gaussian
/// slope distribution N(mean, cov) (Cholesky factor), weighted by (w_z − s·w_xy)⁺; the
/// covariance about the computed mean (two passes); in the order of `check::ds::components`.
fn cubature_moments(
    rule: &(Vec<f64>, Vec<f64>),
    mean: [f64; 2],
    cov: [[f64; 2]; 2],
    w: [f64; 3],
) -> [f64; COMPONENTS] {
    let (nodes, weights) = rule;
    let l11 = cov[0][0].sqrt();
    let l21 = cov[0][1] / l11;
    let l22 = (cov[1][1] - l21 * l21).max(0.0).sqrt();
    let points = || {
        nodes.iter().zip(weights).flat_map(move |(&z1, &w1)| {
            nodes.iter().zip(weights).map(move |(&z2, &w2)| {
                let s = [mean[0] + l11 * z1, mean[1] + l21 * z1 + l22 * z2];
                let weight = w1 * w2 * (w[2] - s[0] * w[0] - s[1] * w[1]).max(0.0);
                (s, weight)
            })
        })
    };
    let (mut n, mut sx, mut sy) = (0.0, 0.0, 0.0);
    for (s, k) in points() {
        n += k;
        sx += k * s[0];
        sy += k * s[1];
    }
    let m = [sx / n, sy / n];
    let (mut xx, mut xy, mut yy) = (0.0, 0.0, 0.0);
    for (s, k) in points() {
        let d = [s[0] - m[0], s[1] - m[1]];
        xx += k * d[0] * d[0];
        xy += k * d[0] * d[1];
        yy += k * d[1] * d[1];
    }
    [m[0], m[1], xx / n, yy / n, xy / n]
}

/// The D_s sweep (see the module documentation).
pub fn sweep() -> Sweep<'static> {
    let models: Rc<Vec<GaussianSlopes>> = Rc::new(
        CASES
            .iter()
            .map(|&(mean, cov)| GaussianSlopes::new(mean, cov).expect("valid slope cases"))
            .collect(),
    );
    // Input i: case, angle, component.
    let input = |i: usize| {
        let point = i / COMPONENTS;
        (
            point / THETAS.len(),
            THETAS[point % THETAS.len()],
            i % COMPONENTS,
        )
    };
    let inputs = CASES.len() * THETAS.len() * COMPONENTS;
    let refs: Vec<[f64; COMPONENTS]> = (0..inputs / COMPONENTS)
        .map(|p| {
            let (c, theta, _) = input(p * COMPONENTS);
            let e = visible_moments_oracle(&models[c], theta, PHI).map(|e| e.value);
            // The oracle's order (mean x, mean y, var x, cov xy, var y) → the check's.
            [e[0], e[1], e[2], e[4], e[3]]
        })
        .collect();
    let route = |name: String, f: Route| {
        let m = models.clone();
        Candidate::total(name, move |i| {
            let (c, theta, k) = input(i);
            f(&m[c], from_spherical(theta, PHI))[k]
        })
    };
    let mut candidates = vec![
        route(
            "closed form (eq 42–46, stable)".into(),
            Rc::new(|g, w| components(&g.visible_moments(w))),
        ),
        route(
            "pseudocode, erratum corrected".into(),
            Rc::new(|g, w| {
                components(&g.visible_moments_transcribed(w, Transcription::PseudocodeCorrected))
            }),
        ),
        route(
            "equations as printed (eq 59)".into(),
            Rc::new(|g, w| {
                components(&g.visible_moments_transcribed(w, Transcription::EquationsPrinted))
            }),
        ),
    ];
    for n in POINTS {
        let rule = Rc::new(gauss_hermite_normal(n));
        candidates.push(route(
            format!("Gauss–Hermite cubature, {n} × {n} points"),
            Rc::new(move |g, w| cubature_moments(&rule, g.mean(), g.cov(), w)),
        ));
    }
    Sweep {
        name: "Gaussian visible-slope moments D_s (seed 002)".into(),
        reference: "adaptive cubature of the definition D_s ∝ p_s(s)(w_z − s·w_xy)⁺ \
                    (oracle::visible_moments, relative 1e-11)"
            .into(),
        error: "mean in units of max(|meanᵢ|, σᵢ), variances relative, covariance as a \
                correlation; max over the five components and the inputs"
            .into(),
        inputs_text: format!(
            "(mean, Σ) ∈ {{((0, 0), 0.09 I), ((0.1, −0.05), [[0.04, 0.01], [0.01, 0.09]]), \
             ((0.05, 0.02), [[0.16, 0.15], [0.15, 0.16]])}}, θ ∈ {THETAS:?}, φ = {PHI}"
        ),
        inputs,
        error_of: Box::new(move |i, v| {
            let (_, _, k) = input(i);
            let r = &refs[i / COMPONENTS];
            Some((v - r[k]).abs() / units(r)[k])
        }),
        candidates,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gauss_hermite_rule_integrates_normal_moments() {
        // E[Z^2k] = (2k − 1)!! exactly for polynomials of degree ≤ 2n − 1.
        let (z, w) = gauss_hermite_normal(8);
        let moment = |p: i32| z.iter().zip(&w).map(|(z, w)| w * z.powi(p)).sum::<f64>();
        assert!((moment(0) - 1.0).abs() < 1e-14);
        assert!(moment(1).abs() < 1e-14);
        assert!((moment(2) - 1.0).abs() < 1e-13);
        assert!((moment(4) - 3.0).abs() < 1e-12);
        assert!((moment(14) - 135_135.0).abs() / 135_135.0 < 1e-11);
    }

    #[test]
    fn closed_forms_agree_printed_fails_cubature_converges() {
        let q = super::super::measure(sweep(), None);
        let error = |name: &str| {
            q.routes
                .iter()
                .find(|r| r.route.starts_with(name))
                .and_then(|r| r.max_error)
                .unwrap_or(f64::INFINITY)
        };
        assert!(error("closed form") < 1e-9, "{q:?}");
        assert!(error("pseudocode") < 1e-9, "{q:?}");
        // The printed E₁ sign puts the means on the wrong side: far off.
        assert!(error("equations as printed") > 1e-2, "{q:?}");
        // The kink of (w_z − s·w_xy)⁺ limits Gauss–Hermite to algebraic convergence, but more
        // points must help.
        let (e4, e64) = (
            error("Gauss–Hermite cubature, 4 "),
            error("Gauss–Hermite cubature, 64 "),
        );
        assert!(e64 < e4 / 10.0, "4 points {e4:e}, 64 points {e64:e}");
    }
}
