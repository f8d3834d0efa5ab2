//! Globally adaptive Gauss–Kronrod (7, 15) quadrature on a finite interval, for closed forms that
//! are one-dimensional integrals with smooth, bounded integrands (GTR's Smith Λ and P2).
//!
//! Hand-written rather than taken from a crate: the reference crate may not depend on the
//! dev-only `quadrature` crate (that is the tests' independent oracle, and a closed form checked
//! against the same quadrature it is built on would prove little), and the rule is twenty lines
//! with the QUADPACK constants (kept with all their published digits, hence the
//! `excessive_precision` allowance). The error estimate is the raw |K15 − G7| of every segment (no
//! QUADPACK rescaling), which overestimates the error of the Kronrod value by orders of magnitude
//! on smooth integrands: the tolerance asked for is met with a wide margin.

/// Nodes of the 15-point Kronrod rule on [−1, 1] (non-negative half; QUADPACK `qk15`). The odd
/// indices 1, 3, 5 and the centre 7 are the 7-point Gauss nodes.
#[allow(clippy::excessive_precision)]
const XGK: [f64; 8] = [
    0.991_455_371_120_812_639_206_854_697_526_329,
    0.949_107_912_342_758_524_526_189_684_047_851,
    0.864_864_423_359_769_072_789_712_788_640_926,
    0.741_531_185_599_394_439_863_864_773_280_788,
    0.586_087_235_467_691_130_294_144_845_693_013,
    0.405_845_151_377_397_166_906_606_412_076_961,
    0.207_784_955_007_898_467_600_689_403_773_245,
    0.0,
];

/// Weights of the 15-point Kronrod rule (QUADPACK `qk15`).
#[allow(clippy::excessive_precision)]
const WGK: [f64; 8] = [
    0.022_935_322_010_529_224_963_732_008_058_970,
    0.063_092_092_629_978_553_290_700_663_189_204,
    0.104_790_010_322_250_183_839_876_322_541_518,
    0.140_653_259_715_525_918_745_189_590_510_238,
    0.169_004_726_639_267_902_826_583_426_598_550,
    0.190_350_578_064_785_409_913_256_402_421_014,
    0.204_432_940_075_298_892_414_161_999_234_649,
    0.209_482_141_084_727_828_012_999_174_891_714,
];

/// Weights of the 7-point Gauss rule at XGK[1], XGK[3], XGK[5], XGK[7].
#[allow(clippy::excessive_precision)]
const WG: [f64; 4] = [
    0.129_484_966_168_869_693_270_611_432_679_082,
    0.279_705_391_489_276_667_901_467_771_423_780,
    0.381_830_050_505_118_944_950_369_775_488_975,
    0.417_959_183_673_469_387_755_102_040_816_327,
];

/// The result of an adaptive integration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Quadrature {
    /// The integral (sum of the Kronrod values of all segments).
    pub value: f64,
    /// The error estimate: the sum of |K15 − G7| over all segments.
    pub error: f64,
    /// How many times the integrand was evaluated.
    pub evaluations: usize,
}

/// One application of the (7, 15) pair on [a, b]: (Kronrod value, |Kronrod − Gauss|).
pub fn gk15(f: &dyn Fn(f64) -> f64, a: f64, b: f64) -> (f64, f64) {
    let centre = 0.5 * (a + b);
    let half = 0.5 * (b - a);
    let fc = f(centre);
    let mut kronrod = WGK[7] * fc;
    let mut gauss = WG[3] * fc;
    for j in 0..7 {
        let dx = half * XGK[j];
        let pair = f(centre - dx) + f(centre + dx);
        kronrod += WGK[j] * pair;
        if j % 2 == 1 {
            gauss += WG[j / 2] * pair;
        }
    }
    (kronrod * half, ((kronrod - gauss) * half).abs())
}

#[derive(Clone, Copy)]
struct Segment {
    a: f64,
    b: f64,
    value: f64,
    error: f64,
}

/// ∫ f over [breakpoints[0], breakpoints[last]], starting from the segments between
/// consecutive breakpoints (which must be increasing), bisecting the segment with the largest
/// error estimate until the total estimate is ≤ `rel_tol` · |value| (or ≤ `abs_tol`), or until
/// `max_segments` segments exist. Segments too short to bisect in f64 keep their estimate.
pub fn integrate(
    f: &dyn Fn(f64) -> f64,
    breakpoints: &[f64],
    rel_tol: f64,
    abs_tol: f64,
    max_segments: usize,
) -> Quadrature {
    let mut segments: Vec<Segment> = breakpoints
        .windows(2)
        .filter(|w| w[1] > w[0])
        .map(|w| {
            let (value, error) = gk15(f, w[0], w[1]);
            Segment {
                a: w[0],
                b: w[1],
                value,
                error,
            }
        })
        .collect();
    let mut evaluations = 15 * segments.len();
    // Segments that can no longer be bisected: their value and error are final.
    let mut frozen_value = 0.0;
    let mut frozen_error = 0.0;
    loop {
        let value: f64 = frozen_value + segments.iter().map(|s| s.value).sum::<f64>();
        let error: f64 = frozen_error + segments.iter().map(|s| s.error).sum::<f64>();
        let done = !(error > rel_tol * value.abs() && error > abs_tol);
        if done || segments.is_empty() || segments.len() >= max_segments || !error.is_finite() {
            return Quadrature {
                value,
                error,
                evaluations,
            };
        }
        let (worst, _) = segments.iter().enumerate().fold((0, -1.0), |acc, (i, s)| {
            if s.error > acc.1 {
                (i, s.error)
            } else {
                acc
            }
        });
        let s = segments.swap_remove(worst);
        let m = 0.5 * (s.a + s.b);
        if !(m > s.a && m < s.b) {
            frozen_value += s.value;
            frozen_error += s.error;
            continue;
        }
        for (a, b) in [(s.a, m), (m, s.b)] {
            let (value, error) = gk15(f, a, b);
            segments.push(Segment { a, b, value, error });
        }
        evaluations += 30;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rules_are_exact_for_polynomials_of_their_degree() {
        // K15 integrates x^k exactly for k ≤ 22, G7 for k ≤ 13: a wrong digit in any constant
        // shows here.
        for k in 0..=22 {
            let f = |x: f64| x.powi(k);
            let want = if k % 2 == 0 {
                2.0 / (k as f64 + 1.0)
            } else {
                0.0
            };
            let (kronrod, diff) = gk15(&f, -1.0, 1.0);
            assert!(
                (kronrod - want).abs() < 2e-16,
                "K15 x^{k}: {kronrod} vs {want}"
            );
            if k <= 13 {
                assert!(diff < 2e-16, "G7 x^{k}: |K − G| = {diff:e}");
            } else if k % 2 == 0 {
                assert!(diff > 1e-8, "G7 cannot be exact for x^{k}");
            }
        }
        let total: f64 = 2.0 * WGK[..7].iter().sum::<f64>() + WGK[7];
        assert!((total - 2.0).abs() < 1e-15);
    }

    #[test]
    fn adaptive_integration_resolves_peaks_and_end_point_behaviour() {
        // ∫_0^1 √x dx = 2/3 (derivative singular at 0); ∫_0^π/2 of a narrow Lorentzian.
        let q = integrate(&|x: f64| x.sqrt(), &[0.0, 1.0], 1e-14, 0.0, 500);
        assert!((q.value - 2.0 / 3.0).abs() < 1e-14, "{q:?}");
        let w: f64 = 1e-5;
        let f = |x: f64| w / (x * x + w * w);
        let q = integrate(&f, &[0.0, 1.0], 1e-14, 0.0, 2000);
        let want = (1.0 / w).atan();
        assert!(((q.value - want) / want).abs() < 1e-13, "{q:?} vs {want}");
        assert!(q.error < 1e-13 * want);
    }
}
