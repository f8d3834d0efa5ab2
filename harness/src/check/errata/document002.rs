//! Errata demonstrations of Document 002 (Gaussian slopes, Heitz et al.): each printed form and its correction against a
//! harness oracle (reference/ERRATA.md, section "Document 002").

use super::*;
use crate::oracle::visible_moments::visible_moments_oracle;
use mfh_reference::errata::document002 as errata002;

const GS_MEAN: [f64; 2] = [1.0, 1.0];
const GS_COV: [[f64; 2]; 2] = [[1.0, 0.75], [0.75, 1.0]];

/// 002-1 and 002-2: the routes `equations_printed` (eq 59's E₁) and `pseudocode_printed` (lines
/// 36–39) against the corrected `pseudocode` and the cubature oracle, on σx² of D_s (Table 3,
/// row 4: s̄ = (1, 1), Σ = [[1, 0.75], [0.75, 1]], θ = 1.56, φ = −π/2 for 002-2; θ = 1.2, φ = 0
/// for 002-1).
fn visible_route(printed_route: &str, theta: f64, phi: f64) -> Result<Shown, String> {
    use mfh_reference::model::VisibleSlopeMoments;
    let gs = GaussianSlopes::new(GS_MEAN, GS_COV).map_err(|e| e.to_string())?;
    let w = from_spherical(theta, phi);
    let printed = gs
        .visible_moments_route(w, printed_route)
        .map_err(|e| e.to_string())?;
    let corrected = gs
        .visible_moments_route(w, "pseudocode")
        .map_err(|e| e.to_string())?;
    let o = visible_moments_oracle(&gs, theta, phi);
    Ok(Shown::new(
        printed.cov[0][0],
        corrected.cov[0][0],
        o[2],
        &ERRATUM_VISIBLE_MOMENTS,
    ))
}

fn e002_1() -> Result<Shown, String> {
    visible_route("equations_printed", 1.2, 0.0)
}

fn e002_2() -> Result<Shown, String> {
    visible_route("pseudocode_printed", 1.56, -FRAC_PI_2)
}

/// 002-3: document 002 eq 52, s_⊥ p_s = −σ_o² ∂p_s/∂s_⊥ + c_o⊥ ∂p_s/∂s_o + s̄_⊥ p_s (printed) against
/// −σ_⊥² ∂p_s/∂s_⊥ − c_o⊥ ∂p_s/∂s_o + s̄_⊥ p_s (`errata::document002`); oracle: the left side.
fn e002_3() -> Result<Shown, String> {
    let gs =
        GaussianSlopes::new([0.3, -0.2], [[0.5, 0.2], [0.2, 0.3]]).map_err(|e| e.to_string())?;
    let f = errata002::ViewFramePoint::new(&gs, 0.0, 0.7, 0.4);
    Ok(Shown::new(
        errata002::eq52_printed(&f),
        errata002::eq52_corrected(&f),
        exact(f.s_perp * gs.ps([0.7, 0.4])),
        &ERRATUM,
    ))
}

/// 002-4: document 002 eq 53 at a back-facing slope off the cut (H = 0 in a neighbourhood): the
/// left side s_o p_s H and every derivative term vanish; the printed last term s̄_o p_s does not.
fn e002_4() -> Result<Shown, String> {
    let gs =
        GaussianSlopes::new([0.3, -0.2], [[0.5, 0.2], [0.2, 0.3]]).map_err(|e| e.to_string())?;
    let theta = 1.0f64;
    let s = [1.0 / theta.tan() + 0.5, 0.1]; // s_o > cot θ: H = 0
    let h = if s[0] < 1.0 / theta.tan() { 1.0 } else { 0.0 };
    let f = errata002::ViewFramePoint::new(&gs, 0.0, s[0], s[1]);
    Ok(Shown::new(
        errata002::eq53_last_term_printed(&f),
        errata002::eq53_last_term_corrected(&f, theta),
        exact(s[0] * gs.ps(s) * h),
        &ERRATUM,
    ))
}

/// The demonstrations of this document's errata.
pub(super) fn demos() -> Vec<Demo> {
    let gs = json!({"family": "gaussian_slopes", "mean": GS_MEAN, "cov": GS_COV});
    let d = Demo;
    vec![
        d(
            "002-1",
            Concern::new(&[], &[Effect::GaussianSlopes]),
            "seed 002 eq 59 (pseudocode line 23)",
            vec![
                covers("gaussian_slopes", "visible_moments", "equations_printed"),
                covers("gaussian_slopes", "visible_moments", "pseudocode"),
            ],
            gs.clone(),
            json!({"theta": 1.2, "phi": 0.0, "route": "equations_printed", "quantity": "σx²(D_s)"}),
            e002_1,
        ),
        d(
            "002-2",
            Concern::new(&[], &[Effect::GaussianSlopes]),
            "seed 002 pseudocode lines 36–39 (eq 68), Table 3 row 4",
            vec![
                covers("gaussian_slopes", "visible_moments", "pseudocode_printed"),
                covers("gaussian_slopes", "visible_moments", "pseudocode"),
            ],
            gs,
            json!({"theta": 1.56, "phi": -FRAC_PI_2, "route": "pseudocode_printed", "quantity": "σx²(D_s)"}),
            e002_2,
        ),
        d(
            "002-3",
            Concern::new(&[], &[Effect::GaussianSlopes]),
            "seed 002 eq 52",
            vec![],
            json!({"family": "gaussian_slopes", "mean": [0.3, -0.2], "cov": [[0.5, 0.2], [0.2, 0.3]]}),
            json!({"s": [0.7, 0.4]}),
            e002_3,
        ),
        d(
            "002-4",
            Concern::new(&[], &[Effect::GaussianSlopes]),
            "seed 002 eq 53",
            vec![],
            json!({"family": "gaussian_slopes", "mean": [0.3, -0.2], "cov": [[0.5, 0.2], [0.2, 0.3]]}),
            json!({"theta": 1.0, "s_offset_past_cut": 0.5}),
            e002_4,
        ),
    ]
}
