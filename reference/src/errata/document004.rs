//! Document 004 (GTR, Dimov): printed forms that no route evaluates, as printed and corrected.

/// Document 004 §3.5's P2⁴(q) with the middle term `middle` of its numerator:
/// 3α⁶(8q⁴ + middle + 12q² + α⁴ + 2α² + 5) / (16(α⁴ + α² + 1)(q² + α²)^{7/2}).
fn p2_gamma4(alpha: f64, q: f64, middle: f64) -> f64 {
    let (a2, q2) = (alpha * alpha, q * q);
    let a4 = a2 * a2;
    3.0 * a4 * a2 * (8.0 * q2 * q2 + middle + 12.0 * q2 + a4 + 2.0 * a2 + 5.0)
        / (16.0 * (a4 + a2 + 1.0) * (q2 + a2).powf(3.5))
}

/// Document 004 §3.5's P2⁴ as printed, "4α²q2" read literally as 4α²·q·2 (ERRATA 004-E1: not even
/// in q, and off ∫ P22⁴ dp by percents).
pub fn p2_gamma4_printed(alpha: f64, q: f64) -> f64 {
    p2_gamma4(alpha, q, 4.0 * alpha * alpha * q * 2.0)
}

/// Document 004 §3.5's P2⁴ corrected: the middle term 4α²q².
pub fn p2_gamma4_corrected(alpha: f64, q: f64) -> f64 {
    p2_gamma4(alpha, q, 4.0 * alpha * alpha * q * q)
}
