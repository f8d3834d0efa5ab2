//! Kolmogorov–Smirnov test of the 1-D marginals of a normal sampler — of cos θ_m and of φ_m —
//! against the marginal CDFs of its pdf, tabulated by adaptive quadrature (ARCHITECTURE.md, "Checks
//! and records").
//!
//! Procedure:
//!
//! 1. **Samples.** `samples` normals are drawn with `u` from the same seeded streams as the
//!    chi-square test ([`stream`]`(seed, chunk)` per chunk of [`CHUNK`] sample indices, two
//!    [`crate::random::uniform`] draws per sample, generated in blocks), in parallel, concatenated in chunk order: the sample set
//!    does not depend on the thread count. A sample outside the closed upper hemisphere
//!    (non-finite, non-unit, below the horizon) is a sanity failure, as in the chi-square test.
//! 2. **The marginal.** For cos θ_m the test runs on θ_m = atan2(√(m_x² + m_y²), m_z) ∈ [0, π/2]
//!    (accurate near the pole, where cos θ is not): θ ↦ cos θ is strictly monotone, and the KS
//!    statistic sup |F_N − F| is invariant under strictly monotone maps of the variable, so it is
//!    the statistic of the cos θ marginal. For φ_m the test runs on atan2(m_y, m_x) ∈ [0, 2π)
//!    (the pole, m_x = m_y = 0, is φ = 0).
//! 3. **The exact CDF.** With dω = sin θ dθ dφ, the marginal densities are
//!
//!    ```text
//!    f_θ(θ) = sin θ ∫_0^{2π} pdf(θ, φ) dφ        F_θ(t) = ∫_0^t f_θ = P(θ_m ≤ t) = P(cos θ_m ≥ cos t)
//!    f_φ(φ) = ∫_0^{π/2} pdf(θ, φ) sin θ dθ       F_φ(p) = ∫_0^p f_φ
//!    ```
//!
//!    The inner integral is adaptive double-exponential quadrature with an error bound
//!    ([`crate::oracle::quadrature::integrate_pieces`]; cut where the lobe measured from the pdf
//!    varies — [`crate::oracle::lobe`]: log-spaced about its θ scales, about an off-axis mode
//!    and about the widest azimuth of an anisotropic lobe — and at the pdf's kinks). The outer integral is adaptive Simpson: each
//!    interval [a, b] is bisected until the two-halves Simpson sum S₂ and the one-interval S₁
//!    agree, |S₂ − S₁| ≤ its share of [`QUADRATURE_TOLERANCE`] (each initial interval an equal
//!    share, split by length within it; S₂'s error is ≈ |S₂ − S₁|/15, so
//!    the sum of |S₂ − S₁| bounds the cumulative error with a safety factor of 15), *and* the
//!    monotone cubic Hermite interpolant of F over [a, b] (values F(a), F(b), slopes f(a), f(b),
//!    Fritsch–Carlson limited) is within [`INTERPOLATION_TOLERANCE`] of the quadrature value at
//!    the midpoint. The accepted intervals' end points and midpoints are the table's knots (a
//!    few hundred to a few thousand), so the final knot spacing is half the one the interpolation
//!    was checked at, where the Hermite error (∝ h⁴) is 16 times smaller.
//! 4. **Its error bound**, stated in every result: Σ |S₂ − S₁| + Σ (b − a)·max inner error at
//!    the interval's nodes + max midpoint interpolation error. The test refuses to judge
//!    ([`Failure::TableInaccurate`]) unless this bound is below [`TABLE_FRACTION`] of the KS
//!    resolution 1/√N (it is typically ~1e-7, against 1/√N ≥ 3e-4 for N ≤ 10⁷). A total mass
//!    off from 1 by more than [`MASS_TOLERANCE`] is a sanity failure, as in the chi-square test;
//!    a smaller defect of the mass is left to the statistic (F is not renormalized).
//! 5. **Statistic and p-value.** D_N = max_i max(i/N − F(x₍ᵢ₎), F(x₍ᵢ₎) − (i − 1)/N) over the
//!    sorted samples; p = Q_KS(λ) with Stephens' λ = (√N + 0.12 + 0.11/√N)·D_N
//!    ([`kolmogorov_q`], [`ks_p_value`]). No well-kept crate provides the Kolmogorov
//!    distribution (statrs 0.18 does not), so its two classical series are summed here.

mod kolmogorov;
mod table;

pub use kolmogorov::{kolmogorov_q, ks_p_value, stephens_lambda};
pub use table::{
    marginal_cdf, marginal_cdf_batch, marginal_cdf_lobe, marginal_cdf_lobe_batch,
    marginal_cdf_lobe_batch_at, CdfTable,
};

use crate::oracle::chi2::{BatchSampler, OutsideHemisphere, TestOutcome, CHUNK};
use crate::oracle::hemisphere_grid::{validate, DirectionError};
use crate::oracle::lobe::{self, Lobe};
use crate::oracle::quadrature::Accuracy;
use crate::precision::Precision;
use crate::random::stream;
use crate::tolerance::MASS_TOLERANCE;
use mfh_reference::geometry::Vec3;
use mfh_reference::trig;
use mfh_reference::NormalSampler;
use rayon::prelude::*;
use std::f64::consts::{FRAC_PI_2, TAU};
use std::time::Instant;

/// The summed |S₂ − S₁| the outer Simpson quadrature may reach over the whole table.
///
/// What the test needs: the table's error bound below [`TABLE_FRACTION`]/√N (3.2e-6 at the
/// thorough profile's N = 10⁷, 7e-6 at quick's 2·10⁶), where an error of the CDF moves D_N by at
/// most itself, against D_N's scale 1/√N ≥ 3.2e-4. 1e-7 here and in
/// [`INTERPOLATION_TOLERANCE`] keeps the bound (≈ 2e-7 with the inner errors) 15× below that
/// limit at N = 10⁷ (35× at 2·10⁶), and moves D_N by ≤ 6e-4 of its scale; it was 1e-9, 100×
/// tighter than needed, which cost ~3× the knots (Simpson's and the Hermite error ∝ h⁴: ×100
/// in tolerance is ×100^{1/4} ≈ 3.2 in spacing) and each knot an inner integral.
pub const QUADRATURE_TOLERANCE: f64 = 1e-7;
/// The largest interpolation error at an interval's midpoint the table accepts (see
/// [`QUADRATURE_TOLERANCE`] for the margin).
pub const INTERPOLATION_TOLERANCE: f64 = 1e-7;
/// The table's error bound must be below this fraction of the KS resolution 1/√N.
pub const TABLE_FRACTION: f64 = 0.01;
/// Accuracy of the inner integrals (the marginal densities at the knots).
pub const INNER_ACCURACY: Accuracy = Accuracy {
    relative: 1e-10,
    absolute: 1e-13,
    noise: f64::EPSILON,
};
/// The rounding floor of the outer Simpson quadrature, in units of the pdf's rounding
/// (`Precision::epsilon`): a span is accepted once |S₂ − S₁| and the interpolation error are
/// within this many roundings of its mass. For f64 it never binds (16 ε ≈ 3.6e-15 of a span's
/// mass against shares ≥ 1e-10); for a float32 pdf (16 ε₃₂ ≈ 1.9e-6 of the span's mass,
/// summing to ≤ 1.9e-6 of the CDF) it stops the bisection of rounding noise, which ran every
/// initial interval to [`MAX_SPANS`]. The table's error bound still sums the
/// accepted |S₂ − S₁|, so the bound stays honest and `TABLE_FRACTION` still judges it.
pub(crate) const SIMPSON_NOISE_FLOOR: f64 = 16.0;
/// The most density evaluations one KS table spends (the inner integrals included): 5·10⁷,
/// ~50× a smooth model's table at the `thorough` profile. Past it the spans still open are
/// accepted with an infinite error, so the test refuses to judge
/// ([`Failure::TableInaccurate`], an `error` record) instead of refining for ever: the table
/// of a D that oscillates faster than any span (GGX × (1 + ½ sin(10⁴ x))) ran for minutes.
pub const KS_EVALUATION_BUDGET: u64 = 50_000_000;
/// Initial intervals per piece between cuts, before adaptive bisection.
pub(crate) const INITIAL_PER_PIECE: usize = 8;
/// Bisections below an initial interval before it is accepted whatever its error.
pub(crate) const MAX_DEPTH: u32 = 30;
/// Intervals one initial interval may be refined into before the rest are accepted as they are
/// (their error still enters the bound).
pub(crate) const MAX_SPANS: usize = 1 << 12;

/// Which 1-D marginal of the sampled normals is tested.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Marginal {
    /// cos θ_m (tested as θ_m; the statistic is the same).
    CosTheta,
    /// φ_m ∈ [0, 2π).
    Phi,
}

impl Marginal {
    /// The name used in records and case descriptions.
    pub fn name(self) -> &'static str {
        match self {
            Marginal::CosTheta => "cos_theta",
            Marginal::Phi => "phi",
        }
    }

    /// The variable the test runs on, for a direction in the upper hemisphere: θ =
    /// atan2(√(m_x² + m_y²), m_z) or φ = atan2(m_y, m_x) ∈ [0, 2π), by `mfh_reference::trig`'s
    /// `atan2` (within 2 ulps of glibc's; [`Marginal::values`] computes the same bits a block at
    /// a time).
    #[inline]
    pub fn value(self, m: Vec3) -> f64 {
        match self {
            Marginal::CosTheta => trig::atan2(planar_radius(m), m[2]),
            Marginal::Phi => azimuth(m, trig::atan2(m[1], m[0])),
        }
    }

    /// `out[i]` = [`Marginal::value`]`(m[i])`, the arc tangents vectorized
    /// (`trig::atan2_block`): the KS test computes millions of them.
    ///
    /// # Panics
    /// If `m` and `out` differ in length.
    pub fn values(self, m: &[Vec3], out: &mut [f64]) {
        assert_eq!(m.len(), out.len(), "values: m and out differ in length");
        let (ys, xs): (Vec<f64>, Vec<f64>) = match self {
            Marginal::CosTheta => m.iter().map(|&m| (planar_radius(m), m[2])).unzip(),
            Marginal::Phi => m.iter().map(|m| (m[1], m[0])).unzip(),
        };
        trig::atan2_block(&ys, &xs, out);
        if self == Marginal::Phi {
            for (o, &m) in out.iter_mut().zip(m) {
                *o = azimuth(m, *o);
            }
        }
    }

    /// The range of the variable.
    pub fn range(self) -> [f64; 2] {
        match self {
            Marginal::CosTheta => [0.0, FRAC_PI_2],
            Marginal::Phi => [0.0, TAU],
        }
    }
}

/// √(m_x² + m_y²), through `hypot` only where the squares may underflow (a sum below 1e-290),
/// so that θ keeps its relative accuracy next to the pole.
#[inline]
fn planar_radius(m: Vec3) -> f64 {
    let planar = m[0] * m[0] + m[1] * m[1];
    if planar >= 1e-290 {
        planar.sqrt()
    } else {
        m[0].hypot(m[1])
    }
}

/// φ ∈ [0, 2π) of `m` from its arc tangent `phi` = atan2(m_y, m_x) ∈ [−π, π] (the pole is 0).
#[inline]
fn azimuth(m: Vec3, phi: f64) -> f64 {
    if m[0] == 0.0 && m[1] == 0.0 {
        0.0
    } else if phi >= 0.0 {
        phi
    } else if phi + TAU < TAU {
        phi + TAU
    } else {
        0.0 // φ = −1e-17 rounds to 2π: it is φ = 0 again.
    }
}

/// Where the pdf is peaked and where it has kinks, so that the quadrature resolves it (the
/// compatibility path: the width is now only a hint to [`lobe::measure_with`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LobeHints<'a> {
    /// The angular width of the lobe at the pole (radians), e.g. atan α: a hint only.
    pub width: f64,
    /// Polar angles (radians, inside (0, π/2)) where the pdf has kinks for every azimuth.
    pub theta_kinks: &'a [f64],
}

impl Default for LobeHints<'_> {
    fn default() -> Self {
        Self {
            width: 0.3,
            theta_kinks: &[],
        }
    }
}

/// The parameters of one KS test.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KsConfig {
    /// The number of samples N.
    pub samples: u64,
    /// The seed of the random streams.
    pub seed: u64,
    /// The significance level: the test fails when p < `alpha`.
    pub alpha: f64,
}

/// Why a KS test failed, or could not judge.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Failure {
    /// Samples lie outside the upper hemisphere.
    #[error(transparent)]
    OutsideHemisphere(OutsideHemisphere),
    /// The marginal density is negative or not finite somewhere.
    #[error("marginal density {value} at {at}")]
    InvalidDensity {
        /// Where (θ or φ, radians).
        at: f64,
        /// The density there.
        value: f64,
    },
    /// The pdf does not integrate to 1.
    #[error("pdf mass {mass} differs from 1 by more than {tolerance}")]
    MassOff {
        /// The integrated mass.
        mass: f64,
        /// The allowed difference.
        tolerance: f64,
    },
    /// The CDF table is not accurate enough for the number of samples: no verdict.
    #[error(
        "CDF table error bound {error_bound:.2e} above {limit:.2e} ({TABLE_FRACTION} of 1/√N){}",
        if error_bound.is_infinite() {
            format!(
                ": the table's evaluation budget ({KS_EVALUATION_BUDGET} evaluations, \
                 KS_EVALUATION_BUDGET) ran out"
            )
        } else {
            String::new()
        }
    )]
    TableInaccurate {
        /// The table's error bound.
        error_bound: f64,
        /// What it had to be below.
        limit: f64,
    },
    /// Fewer than one sample: nothing to test.
    #[error("no samples")]
    NoSamples,
    /// The marginal differs from the pdf's.
    #[error("p-value {p_value:.3e} below α = {alpha:.3e}")]
    Rejected {
        /// The p-value.
        p_value: f64,
        /// The level.
        alpha: f64,
    },
}

/// The result of a KS test.
#[derive(Debug, Clone, PartialEq)]
pub struct KsResult {
    /// The marginal tested.
    pub marginal: Marginal,
    /// D_N (NaN after a sanity failure).
    pub statistic: f64,
    /// Stephens' λ = (√N + 0.12 + 0.11/√N)·D_N.
    pub lambda: f64,
    /// Q_KS(λ) (0 after a sanity failure).
    pub p_value: f64,
    /// The level the verdict was taken at.
    pub alpha: f64,
    /// The value of the variable (θ or φ, radians) where D_N is attained.
    pub at: f64,
    /// Samples drawn.
    pub samples: u64,
    /// The seed of the random streams.
    pub seed: u64,
    /// Pass or fail.
    pub verdict: TestOutcome,
    /// Why it failed, if it did.
    pub reason: Option<Failure>,
    /// Knots of the CDF table.
    pub knots: usize,
    /// The table's error bound (absolute, in probability).
    pub table_error_bound: f64,
    /// The integrated pdf mass (the table's last value).
    pub pdf_mass: f64,
    /// Pdf evaluations spent on the table.
    pub evaluations: u64,
    /// Wall time of sampling and sorting, seconds.
    pub sampling_seconds: f64,
    /// Wall time of the CDF table, seconds.
    pub table_seconds: f64,
}

/// The drawn values of a marginal, or the samples outside the upper hemisphere.
struct Drawn {
    values: Vec<f64>,
    outside: u64,
    first_outside: Option<(u64, DirectionError)>,
}

/// Draws `samples` normals with `sample` (seeded streams per chunk, as the chi-square test;
/// each chunk's uniforms in one call) and returns the marginal's values in sample order.
fn draw_batch(sample: &BatchSampler<'_>, marginal: Marginal, samples: u64, seed: u64) -> Drawn {
    let deadline = crate::deadline::current();
    let chunks: Vec<Drawn> = (0..samples.div_ceil(CHUNK))
        .into_par_iter()
        .map(|chunk| {
            crate::deadline::check(deadline);
            let mut rng = stream(seed, chunk);
            let (start, end) = (chunk * CHUNK, ((chunk + 1) * CHUNK).min(samples));
            let mut d = Drawn {
                values: Vec::with_capacity((end - start) as usize),
                outside: 0,
                first_outside: None,
            };
            // In one block: the pairs of `uniform` calls, generated in bulk.
            let mut u = vec![[0.0; 2]; (end - start) as usize];
            rng.fill_pairs(&mut u);
            let mut normals = vec![[0.0; 3]; u.len()];
            sample(&u, &mut normals);
            let mut values = vec![0.0; u.len()];
            marginal.values(&normals, &mut values);
            for ((index, m), value) in (start..end).zip(normals).zip(values) {
                match validate(m) {
                    Ok(_) => d.values.push(value),
                    Err(error) => {
                        d.outside += 1;
                        d.first_outside.get_or_insert((index, error));
                    }
                }
            }
            d
        })
        .collect();
    let mut all = Drawn {
        values: Vec::with_capacity(samples as usize),
        outside: 0,
        first_outside: None,
    };
    for d in chunks {
        all.values.extend_from_slice(&d.values);
        all.outside += d.outside;
        if all.first_outside.is_none() {
            all.first_outside = d.first_outside;
        }
    }
    all
}

/// D_N of sorted values against `cdf`, and the value where it is attained (the first, in
/// order, of equal maxima).
pub fn ks_statistic(sorted: &[f64], cdf: &(dyn Fn(f64) -> f64 + Sync)) -> (f64, f64) {
    let n = sorted.len() as f64;
    let best = sorted
        .par_iter()
        .enumerate()
        .map(|(i, &x)| {
            let f = cdf(x);
            ((i as f64 + 1.0) / n - f).max(f - i as f64 / n)
        })
        .enumerate()
        .reduce(|| (usize::MAX, f64::NEG_INFINITY), first_largest);
    located(best, sorted)
}

/// Of two (index, distance) candidates, the larger distance; of equal ones, the first index
/// (so that the statistic's location does not depend on how the work was split).
fn first_largest(p: (usize, f64), q: (usize, f64)) -> (usize, f64) {
    if q.1 > p.1 || (q.1 == p.1 && q.0 < p.0) {
        q
    } else {
        p
    }
}

/// (D_N, the sorted value where it is reached) of the best candidate; NaN where there is none.
fn located(best: (usize, f64), sorted: &[f64]) -> (f64, f64) {
    match best {
        (i, d) if i < sorted.len() => (d, sorted[i]),
        _ => (f64::NAN, f64::NAN),
    }
}

/// [`ks_statistic`] against a CDF table: the same (D_N, where), F evaluated by walks along the
/// table ([`CdfTable::cdf_ascending`]) over chunks of the sorted values in parallel, the
/// first of equal maxima kept as there.
pub fn ks_statistic_table(sorted: &[f64], table: &CdfTable) -> (f64, f64) {
    const CHUNK_VALUES: usize = 1 << 14;
    let n = sorted.len() as f64;
    let best = sorted
        .par_chunks(CHUNK_VALUES)
        .enumerate()
        .map(|(c, chunk)| {
            let start = c * CHUNK_VALUES;
            let mut best = (usize::MAX, f64::NEG_INFINITY);
            table.cdf_ascending(chunk, |j, f| {
                let i = start + j;
                let d = ((i as f64 + 1.0) / n - f).max(f - i as f64 / n);
                // Strictly greater: the first of equal maxima in order (NaN never wins).
                if d > best.1 || (d == best.1 && best.0 == usize::MAX) {
                    best = (i, d);
                }
            });
            best
        })
        .reduce(|| (usize::MAX, f64::NEG_INFINITY), first_largest);
    located(best, sorted)
}

/// Tests the marginal `marginal` of the sampler `sample` against that of the density `pdf`
/// (with respect to solid angle).
///
/// The lobe is measured from `pdf` ([`lobe::measure_with`], `hints.width` as the hint: it only
/// speeds the measurement up); [`ks_test_lobe`] takes a lobe measured once.
pub fn ks_test<S, P>(
    sample: &S,
    pdf: &P,
    marginal: Marginal,
    hints: &LobeHints<'_>,
    config: &KsConfig,
) -> KsResult
where
    S: Fn([f64; 2]) -> Vec3 + Sync + ?Sized,
    P: Fn(Vec3) -> f64 + Sync + ?Sized,
{
    let options = lobe::Options {
        hint: Some(hints.width),
        start_points: &[],
    };
    let lobe = lobe::measure_with(&|m| pdf(m), &options);
    ks_test_lobe(sample, pdf, marginal, &lobe, hints.theta_kinks, config)
}

/// [`ks_test`] with the CDF table cut where `lobe` varies and at `theta_kinks` (polar angles
/// where the pdf has kinks for every azimuth).
pub fn ks_test_lobe<S, P>(
    sample: &S,
    pdf: &P,
    marginal: Marginal,
    lobe: &Lobe,
    theta_kinks: &[f64],
    config: &KsConfig,
) -> KsResult
where
    S: Fn([f64; 2]) -> Vec3 + Sync + ?Sized,
    P: Fn(Vec3) -> f64 + Sync + ?Sized,
{
    ks_test_lobe_batch(
        &|u: &[[f64; 2]], m: &mut [Vec3]| {
            for (m, &u) in m.iter_mut().zip(u) {
                *m = sample(u);
            }
        },
        &|m: &[Vec3], out: &mut [f64]| {
            for (o, &m) in out.iter_mut().zip(m) {
                *o = pdf(m);
            }
        },
        marginal,
        lobe,
        theta_kinks,
        config,
    )
}

/// A KS test's result with what it judged: the sorted marginal values it drew and the model's
/// CDF table, so that a plot of the two shows the test without drawing the samples again.
#[derive(Debug, Clone)]
pub struct KsKept {
    /// The result.
    pub result: KsResult,
    /// The drawn marginal values, sorted (samples outside the upper hemisphere are not among them).
    pub sorted: Vec<f64>,
    /// The model's CDF table of the marginal.
    pub table: CdfTable,
}

/// [`ks_test_lobe`] with a batch sampler and a batch density (an external model: a round trip
/// per chunk of samples and per step of each table integral): the same result.
pub fn ks_test_lobe_batch(
    sample: &BatchSampler<'_>,
    pdf: &(dyn Fn(&[Vec3], &mut [f64]) + Sync),
    marginal: Marginal,
    lobe: &Lobe,
    theta_kinks: &[f64],
    config: &KsConfig,
) -> KsResult {
    ks_test_lobe_batch_kept(sample, pdf, marginal, lobe, theta_kinks, config).result
}

/// [`ks_test_lobe_batch`], keeping the sorted samples and the CDF table ([`KsKept`]).
pub fn ks_test_lobe_batch_kept(
    sample: &BatchSampler<'_>,
    pdf: &(dyn Fn(&[Vec3], &mut [f64]) + Sync),
    marginal: Marginal,
    lobe: &Lobe,
    theta_kinks: &[f64],
    config: &KsConfig,
) -> KsKept {
    ks_test_lobe_batch_kept_at(
        sample,
        pdf,
        marginal,
        lobe,
        theta_kinks,
        config,
        Precision::F64,
    )
}

/// [`ks_test_lobe_batch_kept`] for a pdf computed in `precision`: the table's quadratures stop
/// at its rounding floor ([`marginal_cdf_lobe_batch_at`]).
pub fn ks_test_lobe_batch_kept_at(
    sample: &BatchSampler<'_>,
    pdf: &(dyn Fn(&[Vec3], &mut [f64]) + Sync),
    marginal: Marginal,
    lobe: &Lobe,
    theta_kinks: &[f64],
    config: &KsConfig,
    precision: Precision,
) -> KsKept {
    let t = Instant::now();
    let mut drawn = draw_batch(sample, marginal, config.samples, config.seed);
    let mut sampling_seconds = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let table = marginal_cdf_lobe_batch_at(pdf, marginal, lobe, theta_kinks, precision);
    let table_seconds = t.elapsed().as_secs_f64();
    let t = Instant::now();
    sort_values(&mut drawn.values);
    sampling_seconds += t.elapsed().as_secs_f64();
    let mut result = KsResult {
        marginal,
        statistic: f64::NAN,
        lambda: f64::NAN,
        p_value: 0.0,
        alpha: config.alpha,
        at: f64::NAN,
        samples: config.samples,
        seed: config.seed,
        verdict: TestOutcome::Fail,
        reason: None,
        knots: table.knots(),
        table_error_bound: table.error_bound(),
        pdf_mass: table.total(),
        evaluations: table.evaluations,
        sampling_seconds,
        table_seconds,
    };
    result.reason = sanity(&drawn, &table, config.samples);
    if result.reason.is_none() {
        judge(&mut result, &drawn.values, &table, config);
    }
    KsKept {
        result,
        sorted: drawn.values,
        table,
    }
}

/// Sorts `values` ascending in `f64::total_cmp`'s order. The marginals' values are ≥ +0 (θ and
/// φ), whose bit patterns as u64 sort as the numbers do: sorted as integers (a comparison a
/// cycle, where `total_cmp` transforms both operands each time; 2·10⁶ values were a quarter of
/// a KS test's time), the same order bit for bit; a value with its sign bit set (−0, say)
/// takes the comparison sort of `total_cmp`.
fn sort_values(values: &mut [f64]) {
    if values.iter().all(|v| v.is_sign_positive()) {
        let bits: &mut [u64] = bytemuck::cast_slice_mut(values);
        bits.par_sort_unstable();
    } else {
        values.par_sort_unstable_by(f64::total_cmp);
    }
}

/// D_N of the sorted `values` against `table`, λ, the p-value and the verdict.
fn judge(result: &mut KsResult, values: &[f64], table: &CdfTable, config: &KsConfig) {
    let (d, at) = ks_statistic_table(values, table);
    result.statistic = d;
    result.at = at;
    result.lambda = stephens_lambda(d, config.samples);
    result.p_value = kolmogorov_q(result.lambda);
    if result.p_value >= config.alpha {
        result.verdict = TestOutcome::Pass;
    } else {
        result.reason = Some(Failure::Rejected {
            p_value: result.p_value,
            alpha: config.alpha,
        });
    }
}

/// The failures that leave no statistic: samples outside the upper hemisphere, no samples, an invalid
/// density or mass, a table too coarse for N.
fn sanity(drawn: &Drawn, table: &CdfTable, samples: u64) -> Option<Failure> {
    if let Some((index, error)) = drawn.first_outside {
        return Some(Failure::OutsideHemisphere(OutsideHemisphere {
            index,
            error,
            count: drawn.outside,
        }));
    }
    if samples == 0 {
        return Some(Failure::NoSamples);
    }
    if let Some((at, value)) = table.invalid {
        return Some(Failure::InvalidDensity { at, value });
    }
    if !((table.total() - 1.0).abs() <= MASS_TOLERANCE) {
        return Some(Failure::MassOff {
            mass: table.total(),
            tolerance: MASS_TOLERANCE,
        });
    }
    let limit = TABLE_FRACTION / (samples as f64).sqrt();
    if !(table.error_bound() <= limit) {
        return Some(Failure::TableInaccurate {
            error_bound: table.error_bound(),
            limit,
        });
    }
    None
}

/// Tests a marginal of a model's `sample_wm` against its own `pdf_wm`.
pub fn ks_test_sampler(
    sampler: &dyn NormalSampler,
    marginal: Marginal,
    hints: &LobeHints<'_>,
    config: &KsConfig,
) -> KsResult {
    ks_test(
        &|u| sampler.sample_wm(u),
        &|m| sampler.pdf_wm(m),
        marginal,
        hints,
        config,
    )
}

#[cfg(test)]
mod tests;
