//! Globally adaptive Gauss–Kronrod (G7/K15) quadrature over a list of break points, and the
//! G7/K15 nodes and weights every quadrature of the project shares.
//!
//! Why this lives in the reference crate: the "exact" and "slope_space" Smith Λ routes of the
//! piecewise-linear and blended NDFs (document 000, eq 10–13 and 30–32) have no closed form, so the
//! model itself must integrate. The crate may not depend on the `quadrature` crate (it is a
//! dev-dependency, kept for the independent test oracles), and the tests must stay independent
//! of the code they check: the tests integrate with `test_support` (double-exponential), the
//! models with this Gauss–Kronrod rule.
//!
//! The caller passes the kinks of the integrand as break points, so that every interval the
//! rule sees is smooth; intervals are bisected, largest error first (QUADPACK QAG style), until
//! the summed error estimate |K15 − G7| is below max(rel·|I|, abs).

/// Kronrod abscissae on [−1, 1] (non-negative half, descending); the odd-indexed ones are the
/// Gauss points (QUADPACK `qk15`).
pub const XGK: [f64; 8] = [
    0.991_455_371_120_812_6,
    0.949_107_912_342_758_5,
    0.864_864_423_359_769_1,
    0.741_531_185_599_394_4,
    0.586_087_235_467_691_1,
    0.405_845_151_377_397_2,
    0.207_784_955_007_898_5,
    0.0,
];

/// Kronrod weights, matching `XGK`.
pub const WGK: [f64; 8] = [
    0.022_935_322_010_529_22,
    0.063_092_092_629_978_55,
    0.104_790_010_322_250_2,
    0.140_653_259_715_525_9,
    0.169_004_726_639_267_9,
    0.190_350_578_064_785_4,
    0.204_432_940_075_298_9,
    0.209_482_141_084_727_8,
];

/// Gauss weights of the 7-point rule at `XGK[1]`, `XGK[3]`, `XGK[5]`, `XGK[7]`.
pub const WG: [f64; 4] = [
    0.129_484_966_168_869_7,
    0.279_705_391_489_276_7,
    0.381_830_050_505_118_9,
    0.417_959_183_673_469_4,
];

/// The result of an adaptive integration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Integral {
    /// The integral.
    pub value: f64,
    /// The summed |K15 − G7| error estimate of the accepted intervals.
    pub error: f64,
    /// Integrand evaluations spent.
    pub evaluations: usize,
}

/// One G7/K15 pass over [a, b]: (K15 value, |K15 − G7|).
fn gk15(f: &dyn Fn(f64) -> f64, a: f64, b: f64) -> (f64, f64) {
    let c = 0.5 * (a + b);
    let h = 0.5 * (b - a);
    let fc = f(c);
    let mut k = fc * WGK[7];
    let mut g = fc * WG[3];
    for j in 0..7 {
        let x = h * XGK[j];
        let s = f(c - x) + f(c + x);
        k += WGK[j] * s;
        if j % 2 == 1 {
            g += WG[j / 2] * s;
        }
    }
    (k * h, ((k - g) * h).abs())
}

/// ∫ f over `[breaks[0], breaks[last]]` with the integrand smooth between consecutive break
/// points (which must be non-decreasing; empty intervals are skipped). Stops when the error
/// estimate is ≤ max(rel·|I|, abs) or after `MAX_INTERVALS` intervals.
pub fn integrate(f: &dyn Fn(f64) -> f64, breaks: &[f64], rel: f64, abs: f64) -> Integral {
    const MAX_INTERVALS: usize = 4000;
    // (a, b, value, error)
    let mut pieces: Vec<(f64, f64, f64, f64)> = Vec::with_capacity(2 * breaks.len() + 16);
    for w in breaks.windows(2) {
        if w[1] > w[0] {
            let (v, e) = gk15(f, w[0], w[1]);
            pieces.push((w[0], w[1], v, e));
        }
    }
    let mut evaluations = 15 * pieces.len();
    loop {
        let value: f64 = pieces.iter().map(|p| p.2).sum();
        let error: f64 = pieces.iter().map(|p| p.3).sum();
        let done = !(error > (rel * value.abs()).max(abs)) || pieces.len() >= MAX_INTERVALS;
        // The worst interval, unless it can no longer be split in floating point.
        let worst = pieces
            .iter()
            .enumerate()
            .filter(|(_, p)| {
                let m = 0.5 * (p.0 + p.1);
                m > p.0 && m < p.1
            })
            .max_by(|x, y| x.1 .3.total_cmp(&y.1 .3))
            .map(|(i, _)| i);
        let Some(i) = worst.filter(|_| !done) else {
            return Integral {
                value,
                error,
                evaluations,
            };
        };
        let (a, b, _, _) = pieces[i];
        let m = 0.5 * (a + b);
        let (vl, el) = gk15(f, a, m);
        let (vr, er) = gk15(f, m, b);
        evaluations += 30;
        pieces[i] = (a, m, vl, el);
        pieces.push((m, b, vr, er));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exact_for_polynomials_and_accurate_for_smooth_functions() {
        // K15 integrates degree ≤ 22 exactly, G7 degree ≤ 13: x^13 has zero error estimate.
        let (v, e) = gk15(&|x| x.powi(13) + x.powi(12), 0.0, 1.0);
        assert!(
            (v - (1.0 / 14.0 + 1.0 / 13.0)).abs() < 1e-15 && e < 1e-15,
            "{v} {e}"
        );
        let (v, _) = gk15(&|x| x.powi(22), -1.0, 1.0);
        assert!((v - 2.0 / 23.0).abs() < 1e-15, "{v}");
        let r = integrate(&|x: f64| x.sin(), &[0.0, std::f64::consts::PI], 1e-14, 0.0);
        assert!((r.value - 2.0).abs() < 2e-15, "{r:?}");
        // A kink at a break point costs nothing; a √ end-point singularity is bisected.
        let r = integrate(&|x: f64| (x - 0.3).abs(), &[0.0, 0.3, 1.0], 1e-14, 0.0);
        assert!((r.value - (0.045 + 0.245)).abs() < 1e-15, "{r:?}");
        let r = integrate(&|x: f64| x.sqrt(), &[0.0, 1.0], 1e-12, 0.0);
        assert!((r.value - 2.0 / 3.0).abs() < 1e-12, "{r:?}");
    }
}
