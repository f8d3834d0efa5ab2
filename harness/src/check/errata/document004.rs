//! Errata demonstrations of Document 004 (GTR, Dimov): each printed form and its correction against a
//! harness oracle (reference/ERRATA.md, section "Document 004").

use super::*;
use crate::oracle::gtr::{self, g1_gamma0};
use mfh_reference::errata::document004;

/// 004-E1: document 004 §3.5, P2⁴ with "4α²q2" read literally (8α²q) and as 4α²q², against
/// ∫ P22⁴(p, q) dp by harness quadrature (α = 0.3, q = 0.5).
fn e004_1() -> Result<Shown, String> {
    let (alpha, q) = (0.3f64, 0.5f64);
    let m = Gtr::new(4.0, alpha).map_err(|e| e.to_string())?;
    let slopes = m.as_slopes().ok_or("no slopes")?;
    let o = integrate_line(&|p| slopes.p22(p, q), 0.0, alpha, acc());
    Ok(Shown::new(
        document004::p2_gamma4_printed(alpha, q),
        document004::p2_gamma4_corrected(alpha, q),
        o,
        &ERRATUM,
    ))
}

/// 004-E2: document 004 §4 "all height fields converge to G1⁰ when μ → 1 and α → 0": at μ = 1,
/// α = 1e-4, γ = 2 the printed limit is G1⁰(1) = 0.83; the true limit is 1.
fn e004_2() -> Result<Shown, String> {
    // G1 = 1 − Λ + O(Λ²) with Λ ≈ 2.5e-9 here: Λ to 1e-2 relative bounds G1's error by
    // ~3e-11, far inside GTR_LIMIT's 1e-6 (Λ to 1e-9 cost 12.7·10⁶ evaluations, 6 s in the
    // audit).
    let o = gtr::g1_to(2.0, 1e-4, FRAC_PI_2 / 2.0, 1e-2);
    Ok(Shown::new(
        g1_gamma0(1.0),
        1.0,
        o,
        &crate::tolerance::GTR_LIMIT,
    ))
}

/// The demonstrations of this document's errata.
pub(super) fn demos() -> Vec<Demo> {
    let gtr = |g: f64, a: f64| json!({"family": "gtr", "gamma": g, "alpha": a});
    let d = Demo;
    vec![
        d(
            "004-E1",
            Concern::new(&["gtr"], &[Effect::Masking]),
            "seed 004 §3.5, P2⁴",
            vec![covers("gtr", "p22", "default")],
            gtr(4.0, 0.3),
            json!({"q": 0.5}),
            e004_1,
        ),
        d(
            "004-E2",
            Concern::new(&["gtr"], &[Effect::Masking]),
            "seed 004 §4",
            vec![],
            gtr(2.0, 1e-4),
            json!({"mu": 1.0}),
            e004_2,
        ),
    ]
}
