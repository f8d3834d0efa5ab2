//! Document 000 (piecewise-linear NDF): the derivation lines of eq 20 and eq 25 as printed and
//! corrected, eq 27/28's arccos as printed and guarded, and Algorithms 1–2 transcribed as
//! printed (tolerance 1e-5, `while true`) with an iteration bound so that the instability can
//! be shown without hanging.
//!
//! Units are the document's: D(θ, φ) = (cos²φ D_x(θ) D_y(0) + sin²φ D_y(θ) D_x(0)) / c with
//! c = (D_x(0) + D_y(0))/2 (eq 1–3); D_x, D_y are the profiles of the model (normalized
//! isotropic NDFs, eq 4–5).

use crate::ndf::piecewise::PiecewiseLinear;
use std::f64::consts::{FRAC_PI_2, PI, TAU};

/// The result of an iterative algorithm run with an iteration bound.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bounded {
    /// The last iterate.
    pub value: f64,
    /// Iterations run.
    pub iterations: usize,
    /// Whether the printed exit (`|value| < 1e-5`) was reached.
    pub converged: bool,
}

/// The printed tolerance of Algorithms 1 and 2 (`if |value| < 1e-5 then break`).
pub const PRINTED_TOLERANCE: f64 = 1e-5;

/// Document 000 eq 8 as printed, read as the cdf of θ_m (ERRATA.md document 000 E1): it integrates
/// φ over [0, 2π], so it is the marginal cdf of θ, ∫₀^θ (k_x D_x + k_y D_y) cos t sin t dt
/// normalized to 1 at π/2 (∫₀^{2π} cos²φ dφ = ∫₀^{2π} sin²φ dφ = π), not the conditional cdf
/// of θ given φ_m that Algorithm 2 inverts. Equal weights on cos²φ and sin²φ are the
/// conditional's at φ = π/4, so the model's exact segment sums evaluate it. The corrected form
/// (eq 9 with 2π/c) is the model's conditional, [`PiecewiseLinear::cdf_theta`].
pub fn eq8_theta_cdf_printed(m: &PiecewiseLinear, theta: f64) -> f64 {
    m.cdf_theta(theta, std::f64::consts::FRAC_PI_4)
}

/// Document 000 Algorithm 1 (φ_m by Newton's method in a quadrant bracket), line by line as
/// printed, stopped after `max_iterations` (the printed loop is `while true`). With
/// D_x(0) = D_y(0) = 0 the factor (D_y(0) − D_x(0))/(D_y(0) + D_x(0)) of line 18 is 0/0:
/// `value` is NaN, the exit test never holds, and the loop never ends.
pub fn algorithm1_printed(dx0: f64, dy0: f64, xi1: f64, max_iterations: usize) -> Bounded {
    let (mut a, mut c) = if xi1 >= 0.75 {
        (1.5 * PI, TAU)
    } else if xi1 >= 0.5 {
        (PI, 1.5 * PI)
    } else if xi1 >= 0.25 {
        (FRAC_PI_2, PI)
    } else {
        (0.0, FRAC_PI_2)
    };
    let mut phi = xi1 * TAU;
    let kappa = (dy0 - dx0) / (dy0 + dx0);
    for iteration in 1..=max_iterations {
        if !(phi >= a && phi <= c) {
            phi = 0.5 * (a + c);
        }
        let value = (phi / TAU + kappa / (4.0 * PI) * (2.0 * phi).sin()) - xi1;
        if value.abs() < PRINTED_TOLERANCE {
            return Bounded {
                value: phi,
                iterations: iteration,
                converged: true,
            };
        }
        if value > 0.0 {
            c = phi;
        } else {
            a = phi;
        }
        let derivative = 1.0 / TAU + kappa / TAU * (2.0 * phi).cos();
        phi -= value / derivative;
    }
    Bounded {
        value: phi,
        iterations: max_iterations,
        converged: false,
    }
}

/// Algorithm 1 with the guard the reference uses (`PiecewiseLinear::new`): in the zero case
/// D_x(0) = D_y(0) = 0 the blend weights are k_x = k_y = 1, so κ = 0 and φ is uniform
/// (φ = 2πξ₁ solves the cdf exactly at the first iterate).
pub fn algorithm1_corrected(dx0: f64, dy0: f64, xi1: f64, max_iterations: usize) -> Bounded {
    if dx0 == 0.0 && dy0 == 0.0 {
        return algorithm1_printed(1.0, 1.0, xi1, max_iterations);
    }
    algorithm1_printed(dx0, dy0, xi1, max_iterations)
}

/// ∫_{t0}^{t1} (aθ + b) cos θ sin θ dθ = (1/8)(2(at0 + b) cos 2t0 − 2(at1 + b) cos 2t1
/// + a(sin 2t1 − sin 2t0)) (document 000, the display before Algorithm 2, and eq 23).
pub fn segment_cos_sin_doc(a: f64, b: f64, t0: f64, t1: f64) -> f64 {
    (2.0 * (a * t0 + b) * (2.0 * t0).cos() - 2.0 * (a * t1 + b) * (2.0 * t1).cos()
        + a * ((2.0 * t1).sin() - (2.0 * t0).sin()))
        / 8.0
}

/// ∫_{t0}^{t1} (aθ + b) sin²θ dθ = (1/8)(a cos 2t0 − a cos 2t1 + 2(t1 − t0)(2b + a(t0 + t1))
/// + 2(b + at0) sin 2t0 − 2(b + at1) sin 2t1) (document 000 eq 15, one segment).
pub fn segment_sin2_doc(a: f64, b: f64, t0: f64, t1: f64) -> f64 {
    (a * (2.0 * t0).cos() - a * (2.0 * t1).cos()
        + 2.0 * (t1 - t0) * (2.0 * b + a * (t0 + t1))
        + 2.0 * (b + a * t0) * (2.0 * t0).sin()
        - 2.0 * (b + a * t1) * (2.0 * t1).sin())
        / 8.0
}

/// Eq 23's partial segment ∫_{θ_k}^{E} (aθ + b) sin²θ dθ (E = π/2 − θ_o) written with
/// `cos2` where −cos 2E belongs (eq 15 at t1 = E).
fn eq23_partial_segment(a: f64, b: f64, theta_k: f64, theta_o: f64, cos2: f64) -> f64 {
    let e = FRAC_PI_2 - theta_o;
    (a * ((2.0 * theta_k).cos() + cos2)
        + 2.0 * (e - theta_k) * (a * (theta_k + e) + 2.0 * b)
        + 2.0 * (a * theta_k + b) * (2.0 * theta_k).sin()
        - 2.0 * (a * e + b) * (2.0 * theta_o).sin())
        / 8.0
}

/// Eq 23's y line as printed: the partial segment with cos 2φ_o where cos 2θ_o belongs
/// (ERRATA 000-E5; wrong whenever φ_o ≠ θ_o).
pub fn eq23_partial_segment_printed(a: f64, b: f64, theta_k: f64, theta_o: f64, phi_o: f64) -> f64 {
    eq23_partial_segment(a, b, theta_k, theta_o, (2.0 * phi_o).cos())
}

/// Eq 23's partial segment corrected: cos 2θ_o (= −cos 2E).
pub fn eq23_partial_segment_corrected(a: f64, b: f64, theta_k: f64, theta_o: f64) -> f64 {
    eq23_partial_segment(a, b, theta_k, theta_o, (2.0 * theta_o).cos())
}

/// Eq 34's Λ as printed when its display is read as eq 16's I₁ (= I₁₁ + cos θ_o/2, ERRATA
/// 000-E11): (I₁ + I₂¹ + I₂²)/cos θ_o − ½, ½ too large. `i11`, `i2_1`, `i2_2` are eq 34's
/// terms (`piecewise_lambda::domain_split`).
pub fn eq34_lambda_printed(theta_o: f64, i11: f64, i2_1: f64, i2_2: f64) -> f64 {
    let i1 = i11 + 0.5 * theta_o.cos();
    (i1 + i2_1 + i2_2) / theta_o.cos() - 0.5
}

/// Eq 34's Λ corrected: the display is I₁₁, (I₁₁ + I₂¹ + I₂²)/cos θ_o − ½.
pub fn eq34_lambda_corrected(theta_o: f64, i11: f64, i2_1: f64, i2_2: f64) -> f64 {
    (i11 + i2_1 + i2_2) / theta_o.cos() - 0.5
}

/// The segment integral of the text after eq 9 on segment `k` ([θ_k, θ_{k+1}] of
/// `breakpoints`) at azimuth φ, ∫ (A θ + B) cos θ sin θ dθ with A^aniso = w_x a^x + w_y a^y and
/// B^aniso as printed: w_x b^x + w_y b^x (w_x = k_x cos²φ, w_y = k_y sin²φ; ERRATA 000-E2: the
/// x profile's b twice).
pub fn b_aniso_segment_printed(m: &PiecewiseLinear, phi: f64, k: usize) -> f64 {
    b_aniso_segment(m, phi, k, true)
}

/// The segment integral with B^aniso corrected (Algorithm 2, line 2): w_x b^x + w_y b^y, the
/// mass of D cos θ on the segment at φ.
pub fn b_aniso_segment_corrected(m: &PiecewiseLinear, phi: f64, k: usize) -> f64 {
    b_aniso_segment(m, phi, k, false)
}

fn b_aniso_segment(m: &PiecewiseLinear, phi: f64, k: usize, printed: bool) -> f64 {
    let (t0, t1) = (m.breakpoints()[k], m.breakpoints()[k + 1]);
    let (kx, ky) = m.weights();
    let (wx, wy) = (kx * phi.cos().powi(2), ky * phi.sin().powi(2));
    let (ax, bx) = line(&|t| m.d_x(t), t0, t1);
    let (ay, by) = line(&|t| m.d_y(t), t0, t1);
    let b = wx * bx + wy * if printed { bx } else { by };
    segment_cos_sin_doc(wx * ax + wy * ay, b, t0, t1)
}

/// The line (a, b) of a profile on [t0, t1] (eq 4).
fn line(d: &dyn Fn(f64) -> f64, t0: f64, t1: f64) -> (f64, f64) {
    let a = (d(t1) - d(t0)) / (t1 - t0);
    (a, d(t0) - a * t0)
}

/// ∫₀^E of a profile against `seg` by the segments of the model (eq 15, 23).
fn partial(
    m: &PiecewiseLinear,
    d: &dyn Fn(f64) -> f64,
    e: f64,
    seg: fn(f64, f64, f64, f64) -> f64,
) -> f64 {
    m.breakpoints()
        .windows(2)
        .filter(|w| w[0] < e)
        .map(|w| {
            let (a, b) = line(d, w[0], w[1]);
            seg(a, b, w[0], w[1].min(e))
        })
        .sum()
}

/// The document's (D_x(0), D_y(0), c) for the model.
fn doc_constants(m: &PiecewiseLinear) -> (f64, f64, f64) {
    let (dx0, dy0) = (m.d_x(0.0), m.d_y(0.0));
    (dx0, dy0, 0.5 * (dx0 + dy0))
}

/// I₂¹ (document 000 eq 19, first integral: θ_m ∈ [0, E], E = π/2 − θ_o, the back half of the
/// azimuths) by the last lines of eq 20 as printed: the D_x line with cos θ_o where sin θ_o
/// belongs, the D_y line with cos θ_o D_y(0) where sin θ_o D_x(0) belongs (eq 20 prints each
/// of these lines twice, once with sin θ_o for the D_x one; the first occurrences are taken);
/// the cos θ_o terms as eq 21 has them.
pub fn i21_eq20_printed(m: &PiecewiseLinear, theta_o: f64, phi_o: f64) -> f64 {
    i21(m, theta_o, phi_o, true)
}

/// I₂¹ by eq 22 (the corrected eq 20): sin θ_o D_y(0)(−3 − cos 2φ_o)/(3c) ∫₀^E D_x sin²
/// + sin θ_o D_x(0)(−3 + cos 2φ_o)/(3c) ∫₀^E D_y sin² + cos θ_o π/(2c)(D_y(0) ∫₀^E D_x cos sin
/// + D_x(0) ∫₀^E D_y cos sin).
pub fn i21_eq20_corrected(m: &PiecewiseLinear, theta_o: f64, phi_o: f64) -> f64 {
    i21(m, theta_o, phi_o, false)
}

fn i21(m: &PiecewiseLinear, theta_o: f64, phi_o: f64, printed: bool) -> f64 {
    let (dx0, dy0, c) = doc_constants(m);
    let (so, co) = theta_o.sin_cos();
    let c2 = (2.0 * phi_o).cos();
    let e = FRAC_PI_2 - theta_o;
    let dx = |t: f64| m.d_x(t);
    let dy = |t: f64| m.d_y(t);
    let ax = partial(m, &dx, e, segment_sin2_doc);
    let ay = partial(m, &dy, e, segment_sin2_doc);
    let tx = partial(m, &dx, e, segment_cos_sin_doc);
    let ty = partial(m, &dy, e, segment_cos_sin_doc);
    let (fx, fy, wy) = if printed {
        (co, co, dy0)
    } else {
        (so, so, dx0)
    };
    fx * dy0 * (-3.0 - c2) / (3.0 * c) * ax
        + fy * wy * (-3.0 + c2) / (3.0 * c) * ay
        + co * PI / (2.0 * c) * (dy0 * tx + dx0 * ty)
}

/// The cos θ_o part of I₂² (document 000 eq 25, last line) as printed: −(cos θ_o/4)(∫_{θ_{k+1}}^{π/2}
/// 2π D_x(θ) D_x(0) cos θ sin θ/c dθ + 2 ∫_E^{θ_{k+1}} 2π D_y D_x(0) cos θ sin θ/c dθ): D_x(θ)
/// where D_y(θ) belongs and the partial term written twice. (The remaining C-dependent part,
/// D_x(0)/c ∫ D_y cos sin (C − ½ sin 2C cos 2φ_o), is eq 27's and not included.)
pub fn i22_y_term_eq25_printed(m: &PiecewiseLinear, theta_o: f64) -> f64 {
    i22_y_term(m, theta_o, true)
}

/// The same term corrected (eq 26): −(cos θ_o/4) ∫_E^{π/2} 2π D_y(θ) D_x(0) cos θ sin θ/c dθ.
pub fn i22_y_term_eq25_corrected(m: &PiecewiseLinear, theta_o: f64) -> f64 {
    i22_y_term(m, theta_o, false)
}

fn i22_y_term(m: &PiecewiseLinear, theta_o: f64, printed: bool) -> f64 {
    let (dx0, _, c) = doc_constants(m);
    let co = theta_o.cos();
    let e = FRAC_PI_2 - theta_o;
    let b = m.breakpoints();
    let k1 = b.iter().copied().find(|&t| t > e).unwrap_or(FRAC_PI_2);
    let dx = |t: f64| m.d_x(t);
    let dy = |t: f64| m.d_y(t);
    let upper = |d: &dyn Fn(f64) -> f64, from: f64, to: f64| {
        partial(m, d, to, segment_cos_sin_doc) - partial(m, d, from, segment_cos_sin_doc)
    };
    let (outer, times) = if printed {
        (upper(&dx, k1, FRAC_PI_2), 2.0)
    } else {
        (upper(&dy, k1, FRAC_PI_2), 1.0)
    };
    -co / 4.0 * TAU * dx0 / c * (outer + times * upper(&dy, e, k1))
}

/// C = arccos(−1/(tan θ_o tan θ_m)) of document 000 eq 18 and 27–28 as printed: at θ_m = E =
/// π/2 − θ_o, where eq 28 evaluates it, the argument is −1 only in exact arithmetic; rounded,
/// it falls below −1 for most θ_o and C is NaN.
pub fn c_printed(theta_o: f64, theta_m: f64) -> f64 {
    (-1.0 / (theta_o.tan() * theta_m.tan())).acos()
}

/// C with the guard the reference uses (`piecewise_lambda::domain_split`): the argument
/// clamped to [−1, 1].
pub fn c_corrected(theta_o: f64, theta_m: f64) -> f64 {
    (-1.0 / (theta_o.tan() * theta_m.tan()))
        .clamp(-1.0, 1.0)
        .acos()
}

/// Document 000 Algorithm 2 (θ_m given φ_m) line by line, with errata 000-E1–E3 corrected (the
/// normalization c for the printed b, b^y in B^aniso, the conditional cdf of eq 9) and the
/// printed exit `|value| < 1e-5` kept (`tolerance`; `value` is in the units of the
/// unnormalized segment integral ∫(A^aniso θ + B^aniso) cos θ sin θ dθ, not a probability),
/// stopped after `max_iterations`. Returns θ_m.
pub fn algorithm2_printed(
    m: &PiecewiseLinear,
    xi2: f64,
    phi: f64,
    tolerance: f64,
    max_iterations: usize,
) -> Bounded {
    let (dx0, dy0, c) = doc_constants(m);
    let (c2, s2) = (phi.cos().powi(2), phi.sin().powi(2));
    let b = m.breakpoints();
    // Segment lines and the unnormalized cdf at the breakpoints (eq 9: 2π/c · ∫ … ).
    let seg = |i: usize| {
        let (ax, bx) = line(&|t| m.d_x(t), b[i], b[i + 1]);
        let (ay, by) = line(&|t| m.d_y(t), b[i], b[i + 1]);
        (c2 * dy0 * ax + s2 * dx0 * ay, c2 * dy0 * bx + s2 * dx0 * by)
    };
    let mut cdf = vec![0.0; b.len()];
    for i in 0..b.len() - 1 {
        let (a, bb) = seg(i);
        cdf[i + 1] = cdf[i] + TAU / c * segment_cos_sin_doc(a, bb, b[i], b[i + 1]);
    }
    // Line 3 (with c for b): ξ'₂ = ξ₂ (D_y(0) cos²φ + D_x(0) sin²φ)/c.
    let xi = xi2 * (dy0 * c2 + dx0 * s2) / c;
    // "k + 1 the index of the minimum plausible θ_m": the segment whose cdf range holds ξ'₂.
    let k = (0..b.len() - 1)
        .find(|&i| cdf[i + 1] > xi)
        .unwrap_or(b.len() - 2);
    let (a_aniso, b_aniso) = seg(k);
    let cc = c * (xi - cdf[k]) / TAU; // line 4 (c for b)
    let (mut bmin, mut bmax) = (b[k], b[k + 1]);
    let slope = (cdf[k + 1] - cdf[k]) / (b[k + 1] - b[k]);
    let shift = cdf[k] - slope * b[k];
    let mut theta = (xi - shift) / slope;
    for iteration in 1..=max_iterations {
        if !(theta >= bmin && theta <= bmax) {
            theta = 0.5 * (bmin + bmax);
        }
        let value = segment_cos_sin_doc(a_aniso, b_aniso, b[k], theta) - cc;
        if value.abs() < tolerance {
            return Bounded {
                value: theta,
                iterations: iteration,
                converged: true,
            };
        }
        if value > 0.0 {
            bmax = theta;
        } else {
            bmin = theta;
        }
        let derivative = (a_aniso * theta + b_aniso) / 2.0 * (2.0 * theta).sin();
        theta -= value / derivative;
    }
    Bounded {
        value: theta,
        iterations: max_iterations,
        converged: false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ndf::angular_profile::AngularProfile;
    use crate::test_support::{integrate, rel_err};

    fn model() -> PiecewiseLinear {
        PiecewiseLinear::new(
            AngularProfile::uniform(vec![3.0, 2.2, 1.4, 0.9, 0.3, 0.05]),
            Some(AngularProfile::uniform(vec![1.0, 0.95, 0.7, 0.2, 0.02])),
        )
        .unwrap()
    }

    /// ∫∫ over θ_m ∈ [t0, t1], φ_m ∈ [φ_o + π/2, φ_o + 3π/2] of f(θ, φ) D sin θ, by nested
    /// quadrature with the breakpoints as cuts.
    fn back_half(
        m: &PiecewiseLinear,
        t0: f64,
        t1: f64,
        phi_o: f64,
        f: &dyn Fn(f64, f64) -> f64,
    ) -> f64 {
        let (dx0, dy0, c) = doc_constants(m);
        let mut cuts = vec![t0];
        cuts.extend(
            m.breakpoints()
                .iter()
                .copied()
                .filter(|&t| t > t0 && t < t1),
        );
        cuts.push(t1);
        cuts.windows(2)
            .map(|w| {
                integrate(
                    &|t: f64| {
                        integrate(
                            &|p: f64| {
                                let d = (p.cos().powi(2) * m.d_x(t) * dy0
                                    + p.sin().powi(2) * m.d_y(t) * dx0)
                                    / c;
                                f(t, p) * d * t.sin()
                            },
                            phi_o + FRAC_PI_2,
                            phi_o + 1.5 * PI,
                            1e-13,
                            0.0,
                        )
                        .0
                    },
                    w[0],
                    w[1],
                    1e-12,
                    0.0,
                )
                .0
            })
            .sum()
    }

    #[test]
    fn eq20_lines_have_cos_for_sin_and_dy0_for_dx0() {
        let m = model();
        for &(theta_o, phi_o) in &[(0.9f64, 0.3f64), (0.5, 1.1), (1.3, 2.0)] {
            let (so, co) = theta_o.sin_cos();
            let truth = back_half(&m, 0.0, FRAC_PI_2 - theta_o, phi_o, &|t, p| {
                so * t.sin() * (p - phi_o).cos() + co * t.cos()
            });
            let printed = i21_eq20_printed(&m, theta_o, phi_o);
            let corrected = i21_eq20_corrected(&m, theta_o, phi_o);
            assert!(rel_err(corrected, truth) < 1e-10, "{corrected} vs {truth}");
            assert!(rel_err(printed, truth) > 1e-2, "{printed} vs {truth}");
        }
    }

    #[test]
    fn eq25_last_line_has_dx_for_dy_and_a_repeated_term() {
        let m = model();
        let (dx0, _, c) = doc_constants(&m);
        for &theta_o in &[0.3f64, 0.9, 1.3] {
            let e = FRAC_PI_2 - theta_o;
            let co = theta_o.cos();
            // −(cos θ_o/4) ∫_E^{π/2} 2π D_y D_x(0) cos sin / c by quadrature.
            let truth = -co / 4.0 * TAU * dx0 / c
                * integrate(
                    &|t: f64| m.d_y(t) * t.cos() * t.sin(),
                    e,
                    FRAC_PI_2,
                    1e-13,
                    0.0,
                )
                .0;
            let printed = i22_y_term_eq25_printed(&m, theta_o);
            let corrected = i22_y_term_eq25_corrected(&m, theta_o);
            assert!(rel_err(corrected, truth) < 1e-8, "{corrected} vs {truth}");
            assert!(rel_err(printed, truth) > 1e-3, "{printed} vs {truth}");
        }
    }

    #[test]
    fn arccos_of_eq27_is_nan_at_e_for_most_directions_unless_clamped() {
        let n = 10_000;
        let nan = (1..n)
            .filter(|i| {
                let t = *i as f64 / n as f64 * FRAC_PI_2;
                c_printed(t, FRAC_PI_2 - t).is_nan()
            })
            .count();
        let fraction = nan as f64 / (n - 1) as f64;
        assert!(fraction > 0.5, "{fraction}");
        for i in 1..n {
            let t = i as f64 / n as f64 * FRAC_PI_2;
            let c = c_corrected(t, FRAC_PI_2 - t);
            // π − √(2δ) for an argument −1 + δ: δ is a few ulps × the conditioning of tan near π/2.
            assert!((c - PI).abs() < 1e-3, "θ_o = {t}: {c}");
        }
    }

    #[test]
    fn algorithm1_loops_forever_in_the_zero_case_unless_guarded() {
        let printed = algorithm1_printed(0.0, 0.0, 0.3, 10_000);
        assert!(!printed.converged && printed.value.is_nan(), "{printed:?}");
        let guarded = algorithm1_corrected(0.0, 0.0, 0.3, 10_000);
        assert!(guarded.converged && (guarded.value - 0.3 * TAU).abs() < 1e-12);
        let regular = algorithm1_printed(1.5, 0.5, 0.3, 10_000);
        assert!(regular.converged && regular.iterations < 10, "{regular:?}");
    }

    #[test]
    fn algorithm2_as_printed_inverts_the_conditional_cdf_to_its_tolerance() {
        let m = model();
        let (dx0, dy0, _) = doc_constants(&m);
        for &phi in &[0.4f64, 1.2] {
            let scale = TAU / (dy0 * phi.cos().powi(2) + dx0 * phi.sin().powi(2));
            for i in 0..50 {
                let xi = (i as f64 + 0.5) / 50.0;
                let r = algorithm2_printed(&m, xi, phi, PRINTED_TOLERANCE, 100);
                assert!(r.converged, "{r:?}");
                let err = (m.cdf_theta(r.value, phi) - xi).abs();
                // |value| < 1e-5 in units of the unnormalized integral: ≤ 1e-5 · 2π/… in
                // probability, with c in the document's normalization.
                assert!(
                    err <= PRINTED_TOLERANCE * scale + 1e-12,
                    "{err} > {}",
                    PRINTED_TOLERANCE * scale
                );
                let tight = algorithm2_printed(&m, xi, phi, 1e-15, 100);
                assert!((m.cdf_theta(tight.value, phi) - xi).abs() < 1e-12);
            }
        }
    }

    /// Chi-square detection of Algorithm 2's printed tolerance: u = F(θ(ξ)) for ξ on a
    /// midpoint grid of n values (2²⁰ for the numbers in ERRATA.md 000-E13, 2¹⁸ here) is histogrammed into K bins equiprobable under the true
    /// conditional cdf F (the reference's `cdf_theta`); p′ᵢ is the fraction in bin i. The
    /// chi-square statistic of N samples is noncentral with λ = N·K Σ (p′ᵢ − 1/K)², so the test
    /// at level α catches the bias (with probability ½) at N* = λ*/(K Σ (p′ᵢ − 1/K)²), λ* the
    /// noncentrality whose median reaches the critical value.
    fn detection_count(
        m: &PiecewiseLinear,
        phi: f64,
        tolerance: f64,
        k: usize,
        n: usize,
    ) -> (f64, f64, f64) {
        use statrs::distribution::{ChiSquared, ContinuousCDF};
        let mut counts = vec![0usize; k];
        let mut worst = 0.0f64;
        for j in 0..n {
            let xi = (j as f64 + 0.5) / n as f64;
            let r = algorithm2_printed(m, xi, phi, tolerance, 200);
            let u = m.cdf_theta(r.value, phi);
            worst = worst.max((u - xi).abs());
            counts[((u * k as f64) as usize).min(k - 1)] += 1;
        }
        let lambda1: f64 = counts
            .iter()
            .map(|&c| (c as f64 / n as f64 - 1.0 / k as f64).powi(2))
            .sum::<f64>()
            * k as f64;
        // The grid's own discretization: each bin's count is off by < 1 (|p′ − 1/K| < 1/n).
        let floor = k as f64 * k as f64 / (n as f64 * n as f64);
        let dof = (k - 1) as f64;
        let crit = ChiSquared::new(dof).unwrap().inverse_cdf(1.0 - 1e-3);
        // Median of the noncentral chi-square ≈ dof + λ − 2/3 (+ O(1/(dof + λ))).
        let lambda_star = crit - dof + 2.0 / 3.0;
        (lambda_star / lambda1, worst, lambda1 / floor)
    }

    #[test]
    fn algorithm2_printed_tolerance_bias_and_its_chi_square_detection() {
        let m = model();
        let phi = 0.4;
        for &k in &[16usize, 256] {
            let (n_printed, worst, above_floor) =
                detection_count(&m, phi, PRINTED_TOLERANCE, k, 1 << 18);
            println!(
                "φ = {phi}, K = {k}: printed 1e-5: max |F(θ) − ξ| = {worst:.2e}, caught at N ≈ \
                 {n_printed:.2e} (λ₁ = {above_floor:.1e} × grid floor)"
            );
            // |value| < 1e-5 in unnormalized units is up to 1e-5 · 2π/(D_y(0) cos²φ + D_x(0)
            // sin²φ) in probability (2.2e-4 at φ = 0.4 for this model).
            assert!(
                worst > 1e-6 && worst < 1e-5 * TAU / m.d_y(0.0).min(m.d_x(0.0)),
                "{worst}"
            );
            // Measured at 2²⁰: 8.1e7 (K = 16) and 2.1e6 (K = 256).
            assert!(above_floor > 10.0, "{above_floor}");
            assert!(n_printed > 5e5 && n_printed < 1e9, "{n_printed}");
        }
    }
}
