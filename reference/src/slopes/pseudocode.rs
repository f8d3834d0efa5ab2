//! The D_s pseudocode of document 002 (§6, lines 1–56) ported line by line: as printed, with each
//! erratum corrected, and with the equations' E₁ (eq 59) in place of the pseudocode's. Kept to
//! show what the printed forms compute; the model's default route is `gaussian::visible_moments`.

use crate::model::VisibleMoments;
use libm::erfc;
use std::f64::consts::PI;

/// Which version of the source's formulas to evaluate (see reference/ERRATA.md).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Transcription {
    /// Pseudocode lines 1–56 exactly as printed (lines 36–39 misplace a bracket).
    PseudocodePrinted,
    /// The pseudocode with lines 36–39 corrected to eq 68; otherwise as printed.
    PseudocodeCorrected,
    /// Eq 59–69 as printed: E₁ = −σ_o/√(2π) exp(…) (eq 59), I_{s_o s_⊥²} by eq 68.
    EquationsPrinted,
}

/// Document 002, pseudocode lines 8–55, transcribed (variable names kept).
///
/// ```text
/// E1 = √(σ_o²/2π) exp(−(cot θ − s̄_o)²/(2σ_o²))        (line 23; eq 59 prints −σ_o/√(2π) …)
/// E2 = 1 − ½ erfc((cot θ − s̄_o)/√(2σ_o²))              (line 24, eq 60)
/// I, I_o, I_⊥, I_o², I_⊥², I_o⊥, I_o²⊥, I_o⊥², I_o³    (lines 27–40, eq 61–69)
/// N = −sin θ I_o + cos θ I;  moments by eq 25–29, 39–41;  back to (x, y) by eq 42–46
/// ```
///
/// Domain: 0 < θ ≤ π/2 and σ_o² > 0. At θ = 0 the printed code computes cot θ = ∞ and
/// returns NaN (∞ · 0 in lines 30–40). Accuracy of the corrected transcription (unit tests):
/// ≤ 1e-13 while z₀ = (cot θ − s̄_o)/σ_o ≥ −2, ~1e-11 at z₀ = −4, 2e-3 at z₀ = −6 and no
/// digits (or NaN) below z₀ ≈ −8, where E2 = 1 − ½ erfc(…) and N cancel (a mean facet facing
/// away at grazing incidence); for near-singular Σ the smallest variance of D_s loses
/// relative accuracy like ~3e-16 / (variance ratio) in eq 8–10, 39–41 and 44–46.
#[allow(clippy::too_many_arguments)]
pub fn d_s(
    ps_sx0: f64,
    ps_sy0: f64,
    ps_varx: f64,
    ps_vary: f64,
    ps_cxy: f64,
    theta: f64,
    phi: f64,
    transcription: Transcription,
) -> VisibleMoments {
    // pre-computations
    let cos_theta = theta.cos();
    let sin_theta = theta.sin();
    let cot_theta = cos_theta / sin_theta;
    let cos_phi = phi.cos();
    let sin_phi = phi.sin();

    // rotate p_s statistics to view-oriented basis
    let ps_para0 = ps_sx0 * cos_phi + ps_sy0 * sin_phi;
    let ps_ortho0 = -ps_sx0 * sin_phi + ps_sy0 * cos_phi;
    let ps_varpara = ps_varx * cos_phi * cos_phi
        + ps_vary * sin_phi * sin_phi
        + 2.0 * ps_cxy * cos_phi * sin_phi;
    let ps_varortho = ps_varx * sin_phi * sin_phi + ps_vary * cos_phi * cos_phi
        - 2.0 * ps_cxy * cos_phi * sin_phi;
    let ps_cparaortho =
        (ps_vary - ps_varx) * cos_phi * sin_phi + ps_cxy * (cos_phi * cos_phi - sin_phi * sin_phi);

    // compute E1 and E2
    let e1_magnitude = (0.5 * ps_varpara / PI).sqrt()
        * (-0.5 * (cot_theta - ps_para0) * (cot_theta - ps_para0) / ps_varpara).exp();
    let e1 = match transcription {
        Transcription::EquationsPrinted => -e1_magnitude,
        _ => e1_magnitude,
    };
    let e2 = 1.0 - 0.5 * erfc((cot_theta - ps_para0) / (2.0 * ps_varpara).sqrt());

    // compute Integrals I
    let i = e2;
    let i_para = -e1 + ps_para0 * e2;
    let i_ortho = -ps_cparaortho / ps_varpara * e1 + ps_ortho0 * e2;
    let i_para2 = -cot_theta * e1 + ps_varpara * e2 + ps_para0 * i_para;
    let i_ortho2 = -ps_cparaortho / ps_varpara
        * (ps_ortho0 + ps_cparaortho / ps_varpara * (cot_theta - ps_para0))
        * e1
        + ps_varortho * e2
        + ps_ortho0 * i_ortho;
    let i_para_ortho =
        -ps_cparaortho / ps_varpara * cot_theta * e1 + ps_cparaortho * e2 + ps_ortho0 * i_para;
    let i_para2_ortho = -ps_cparaortho / ps_varpara * cot_theta * cot_theta * e1
        + 2.0 * ps_cparaortho * i_para
        + ps_ortho0 * i_para2;
    let conditional = (ps_varpara * ps_varortho - ps_cparaortho * ps_cparaortho) / ps_varpara;
    let shift = ps_ortho0 + ps_cparaortho / ps_varpara * (cot_theta - ps_para0);
    let i_para_ortho2 = match transcription {
        // Lines 36–39 as printed: −(det)/σ_o² + (…)² E1 + …
        Transcription::PseudocodePrinted => {
            -conditional + shift * shift * e1 + ps_para0 * i_ortho2 + 2.0 * ps_cparaortho * i_ortho
        }
        // Eq 68: −(det/σ_o² + (…)²) E1 + …
        _ => {
            -(conditional + shift * shift) * e1
                + ps_para0 * i_ortho2
                + 2.0 * ps_cparaortho * i_ortho
        }
    };
    let i_para3 = 2.0 * ps_varpara * i_para - cot_theta * cot_theta * e1 + ps_para0 * i_para2;

    // compute D_s in view-oriented basis
    let n = -sin_theta * i_para + cos_theta * i;
    let ds_para0 = (-sin_theta * i_para2 + cos_theta * i_para) / n;
    let ds_ortho0 = (-sin_theta * i_para_ortho + cos_theta * i_ortho) / n;
    let ds_varpara = (-sin_theta * i_para3 + cos_theta * i_para2) / n - ds_para0 * ds_para0;
    let ds_varortho =
        (-sin_theta * i_para_ortho2 + cos_theta * i_ortho2) / n - ds_ortho0 * ds_ortho0;
    let ds_cparaortho =
        (-sin_theta * i_para2_ortho + cos_theta * i_para_ortho) / n - ds_para0 * ds_ortho0;

    // rotate D_s statistics to canonic basis
    let ds_sx0 = ds_para0 * cos_phi - ds_ortho0 * sin_phi;
    let ds_sy0 = ds_para0 * sin_phi + ds_ortho0 * cos_phi;
    let ds_varx = ds_varpara * cos_phi * cos_phi + ds_varortho * sin_phi * sin_phi
        - 2.0 * ds_cparaortho * cos_phi * sin_phi;
    let ds_vary = ds_varpara * sin_phi * sin_phi
        + ds_varortho * cos_phi * cos_phi
        + 2.0 * ds_cparaortho * cos_phi * sin_phi;
    let ds_cxy = (ds_varpara - ds_varortho) * cos_phi * sin_phi
        + ds_cparaortho * (cos_phi * cos_phi - sin_phi * sin_phi);
    VisibleMoments {
        mean: [ds_sx0, ds_sy0],
        cov: [[ds_varx, ds_cxy], [ds_cxy, ds_vary]],
    }
}
