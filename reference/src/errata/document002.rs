//! Document 002 (Heitz et al., Gaussian slopes): the identities eq 52 and eq 53 as printed beside
//! their corrections (ERRATA.md document 002 #3, #4), at a point of the view frame of eq 47–50.
//! Errata #1 and #2 (eq 59, pseudocode lines 36–39) are routes of the model
//! (`equations_printed`, `pseudocode_printed`).

use crate::slopes::gaussian::GaussianSlopes;

/// The view-frame quantities of document 002 eq 47–50 at the slope (s_o, s_⊥) of the frame of
/// azimuth φ: p_s and its derivatives, the slope, and the moments of p_s in that frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ViewFramePoint {
    /// p_s(s) (eq 4–5).
    pub p: f64,
    /// ∂p_s/∂s_o (eq 49).
    pub dp_o: f64,
    /// ∂p_s/∂s_⊥ (eq 50).
    pub dp_perp: f64,
    /// s_o.
    pub s_o: f64,
    /// s_⊥.
    pub s_perp: f64,
    /// s̄_o, the mean along the view.
    pub mean_o: f64,
    /// s̄_⊥.
    pub mean_perp: f64,
    /// σ_o².
    pub var_o: f64,
    /// σ_⊥².
    pub var_perp: f64,
    /// c_o⊥.
    pub cov: f64,
}

impl ViewFramePoint {
    /// The quantities at (s_o, s_⊥) in the frame of azimuth `phi` of `model`.
    pub fn new(model: &GaussianSlopes, phi: f64, s_o: f64, s_perp: f64) -> Self {
        let r = model.rotated(phi);
        let (mean_o, mean_perp) = (r.mean[0], r.mean[1]);
        let (var_o, var_perp, cov) = (r.cov[0][0], r.cov[1][1], r.cov[0][1]);
        let det = var_o * var_perp - cov * cov;
        let (a, b, c) = (var_perp / det, -cov / det, var_o / det); // eq 48
        let (sn, cs) = phi.sin_cos();
        let p = model.ps([s_o * cs - s_perp * sn, s_o * sn + s_perp * cs]);
        ViewFramePoint {
            p,
            dp_o: (-a * (s_o - mean_o) - b * (s_perp - mean_perp)) * p,
            dp_perp: (-b * (s_o - mean_o) - c * (s_perp - mean_perp)) * p,
            s_o,
            s_perp,
            mean_o,
            mean_perp,
            var_o,
            var_perp,
            cov,
        }
    }
}

/// Document 002 eq 51, right as printed: s_o p_s = −c_o⊥ ∂p_s/∂s_⊥ − σ_o² ∂p_s/∂s_o + s̄_o p_s.
pub fn eq51(f: &ViewFramePoint) -> f64 {
    -f.cov * f.dp_perp - f.var_o * f.dp_o + f.mean_o * f.p
}

/// Document 002 eq 52 as printed: s_⊥ p_s = −σ_o² ∂p_s/∂s_⊥ + c_o⊥ ∂p_s/∂s_o + s̄_⊥ p_s (wrong
/// coefficients, ERRATA.md document 002 #3; eq 54 inherits them).
pub fn eq52_printed(f: &ViewFramePoint) -> f64 {
    -f.var_o * f.dp_perp + f.cov * f.dp_o + f.mean_perp * f.p
}

/// Document 002 eq 52 corrected: s_⊥ p_s = −σ_⊥² ∂p_s/∂s_⊥ − c_o⊥ ∂p_s/∂s_o + s̄_⊥ p_s.
pub fn eq52_corrected(f: &ViewFramePoint) -> f64 {
    -f.var_perp * f.dp_perp - f.cov * f.dp_o + f.mean_perp * f.p
}

/// The last term of document 002 eq 53 as printed, s̄_o p_s(s): it lacks the H(s) that multiplying
/// eq 51 by H gives (ERRATA.md document 002 #4; eq 54's s̄_⊥ p_s likewise).
pub fn eq53_last_term_printed(f: &ViewFramePoint) -> f64 {
    f.mean_o * f.p
}

/// The last term of document 002 eq 53 corrected, s̄_o p_s(s) H(s) with the visibility
/// H(s) = Heaviside(cos θ − s_o sin θ) at incidence θ.
pub fn eq53_last_term_corrected(f: &ViewFramePoint, theta: f64) -> f64 {
    let h = if theta.cos() - f.s_o * theta.sin() > 0.0 {
        1.0
    } else {
        0.0
    };
    f.mean_o * f.p * h
}
