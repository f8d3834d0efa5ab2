//! Kolmogorov–Smirnov test of the 1-D marginals of a normal sampler — of cos θ_m and of φ_m —
//! against the marginal CDFs of its pdf, tabulated by adaptive quadrature (DESIGN.md, "Checks
//! and records").
//!
//! Procedure:
//!
//! 1. **Samples.** `samples` normals are drawn with `u` from the same seeded streams as the
//!    chi-square test ([`stream`]`(seed, chunk)` per chunk of [`CHUNK`] sample indices, two
//!    [`uniform`] draws per sample), in parallel, concatenated in chunk order: the sample set
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
//!    ([`integrate_pieces`]; azimuth cut at the quadrants, polar angle cut at the lobe width
//!    × {10⁻³ … 10²} and at the pdf's kinks). The outer integral is adaptive Simpson: each
//!    interval [a, b] is bisected until the two-halves Simpson sum S₂ and the one-interval S₁
//!    agree, |S₂ − S₁| ≤ its share of [`QUADRATURE_TOLERANCE`] (S₂'s error is ≈ |S₂ − S₁|/15, so
//!    the sum of |S₂ − S₁| bounds the cumulative error with a safety factor of 15), *and* the
//!    monotone cubic Hermite interpolant of F over [a, b] (values F(a), F(b), slopes f(a), f(b),
//!    Fritsch–Carlson limited) is within [`INTERPOLATION_TOLERANCE`] of the quadrature value at
//!    the midpoint. The accepted intervals' end points and midpoints are the table's knots (a
//!    few hundred to a few thousand), so the final knot spacing is half the one the interpolation
//!    was checked at, where the Hermite error (∝ h⁴) is 16 times smaller.
//! 4. **Its error bound**, stated in every result: Σ |S₂ − S₁| + Σ (b − a)·max inner error at
//!    the interval's nodes + max midpoint interpolation error. The test refuses to judge
//!    ([`Failure::TableInaccurate`]) unless this bound is below [`TABLE_FRACTION`] of the KS
//!    resolution 1/√N (it is typically ~1e-9, against 1/√N ≥ 3e-4 for N ≤ 10⁷). A total mass
//!    off from 1 by more than [`MASS_TOLERANCE`] is a sanity failure, as in the chi-square test;
//!    a smaller defect of the mass is left to the statistic (F is not renormalized).
//! 5. **Statistic and p-value.** D_N = max_i max(i/N − F(x₍ᵢ₎), F(x₍ᵢ₎) − (i − 1)/N) over the
//!    sorted samples; p = Q_KS(λ) with Stephens' λ = (√N + 0.12 + 0.11/√N)·D_N
//!    ([`kolmogorov_q`], [`ks_p_value`]). No well-kept crate provides the Kolmogorov
//!    distribution (statrs 0.18 does not), so its two classical series are summed here.

use crate::oracle::chi2::{Verdict, CHUNK, MASS_TOLERANCE};
use crate::oracle::domain::{validate, DomainError};
use crate::oracle::quadrature::{integrate_pieces, Accuracy};
use crate::oracle::Estimate;
use crate::random::{stream, uniform};
use mfh_reference::geometry::{from_spherical, Vec3};
use mfh_reference::NormalSampler;
use rayon::prelude::*;
use std::f64::consts::{FRAC_PI_2, PI, TAU};
use std::time::Instant;

/// The summed |S₂ − S₁| the outer Simpson quadrature may reach over the whole table.
pub const QUADRATURE_TOLERANCE: f64 = 1e-9;
/// The largest interpolation error at an interval's midpoint the table accepts.
pub const INTERPOLATION_TOLERANCE: f64 = 1e-9;
/// The table's error bound must be below this fraction of the KS resolution 1/√N.
pub const TABLE_FRACTION: f64 = 0.01;
/// Accuracy of the inner integrals (the marginal densities at the knots).
pub const INNER_ACCURACY: Accuracy = Accuracy {
    relative: 1e-10,
    absolute: 1e-13,
};
/// Initial intervals per piece between cuts, before adaptive bisection.
const INITIAL_PER_PIECE: usize = 8;
/// Bisections below an initial interval before it is accepted whatever its error.
const MAX_DEPTH: u32 = 30;
/// Intervals one initial interval may be refined into before the rest are accepted as they are
/// (their error still enters the bound).
const MAX_SPANS: usize = 1 << 12;

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

    /// The variable the test runs on, for a direction in the upper hemisphere.
    #[inline]
    pub fn value(self, m: Vec3) -> f64 {
        match self {
            Marginal::CosTheta => m[0].hypot(m[1]).atan2(m[2]),
            Marginal::Phi => {
                if m[0] == 0.0 && m[1] == 0.0 {
                    return 0.0;
                }
                let phi = m[1].atan2(m[0]);
                if phi >= 0.0 {
                    phi
                } else if phi + TAU < TAU {
                    phi + TAU
                } else {
                    0.0 // φ = −1e-17 rounds to 2π: it is φ = 0 again.
                }
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

/// Where the pdf is peaked and where it has kinks, so that the quadrature resolves it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LobeHints<'a> {
    /// The angular width of the lobe at the pole (radians), e.g. atan α.
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
    /// A sample lies outside the upper hemisphere; `index` is the first such sample.
    #[error("{count} samples outside the domain; the first, sample {index}: {error}")]
    OutsideDomain {
        /// Index of the first offending sample (in the seeded sequence).
        index: u64,
        /// What is wrong with it.
        error: DomainError,
        /// How many samples were outside.
        count: u64,
    },
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
        "CDF table error bound {error_bound:.2e} above {limit:.2e} ({TABLE_FRACTION} of 1/√N)"
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
    pub verdict: Verdict,
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

/// Q_KS(λ) = P(K > λ) = 2 Σ_{k≥1} (−1)^{k−1} e^{−2k²λ²}, the Kolmogorov distribution's upper
/// tail.
///
/// ```text
/// λ ≥ 1.18:  Q = 2 (x − x⁴ + x⁹ − x¹⁶),  x = e^{−2λ²} ≤ 0.062   (next term x²⁵ < 1e-30)
/// λ < 1.18:  Q = 1 − (√(2π)/λ) (y + y⁹ + y²⁵ + y⁴⁹ + y⁸¹),  y = e^{−π²/(8λ²)} ≤ 0.41
///            (the Jacobi-theta form of the CDF; next term y¹²¹ < 1e-46)
/// ```
///
/// Both truncations are below 1e-16 absolute where used (Numerical Recipes, 3rd ed., §6.14).
/// Q(λ ≤ 0) = 1; NaN gives NaN.
pub fn kolmogorov_q(lambda: f64) -> f64 {
    if lambda.is_nan() {
        return f64::NAN;
    }
    if lambda <= 0.0 {
        return 1.0;
    }
    if lambda < 1.18 {
        let y = (-PI * PI / (8.0 * lambda * lambda)).exp();
        let sum: f64 = [1, 9, 25, 49, 81].iter().map(|&k| y.powi(k)).sum();
        (1.0 - (TAU.sqrt() / lambda) * sum).clamp(0.0, 1.0)
    } else {
        let x = (-2.0 * lambda * lambda).exp();
        2.0 * (x - x.powi(4) + x.powi(9) - x.powi(16))
    }
}

/// Stephens' λ = (√N + 0.12 + 0.11/√N)·D: with it the asymptotic Q_KS(λ) is a close
/// approximation of the exact finite-N p-value of D_N (relative error well below 1 % for
/// N ≥ 5 in the upper tail; M. A. Stephens, J. R. Stat. Soc. B 32 (1970) 115–122).
pub fn stephens_lambda(d: f64, n: u64) -> f64 {
    let root = (n as f64).sqrt();
    (root + 0.12 + 0.11 / root) * d
}

/// The p-value of a KS statistic `d` from `n` samples: Q_KS(Stephens' λ).
pub fn ks_p_value(d: f64, n: u64) -> f64 {
    kolmogorov_q(stephens_lambda(d, n))
}

/// A tabulated CDF of a 1-D density: knots, the CDF and the density at each, interpolated
/// monotonically (cubic Hermite with Fritsch–Carlson limited slopes).
#[derive(Debug, Clone, PartialEq)]
pub struct CdfTable {
    knots: Vec<f64>,
    cdf: Vec<f64>,
    density: Vec<f64>,
    /// Σ |S₂ − S₁| of the outer Simpson quadrature.
    pub quadrature_error: f64,
    /// Σ (b − a)·max inner error: what the inner integrals' errors can do to F.
    pub inner_error: f64,
    /// The largest midpoint interpolation error found (at twice the final knot spacing).
    pub interpolation_error: f64,
    /// Pdf evaluations spent.
    pub evaluations: u64,
    /// The first knot where the density was negative or not finite, with its value.
    pub invalid: Option<(f64, f64)>,
}

/// One node of the outer quadrature: where, the density there and its error bound.
#[derive(Debug, Clone, Copy)]
struct Node {
    x: f64,
    f: f64,
    error: f64,
}

/// An accepted interval [a, b] with midpoint node m: masses of [a, m] and [m, b].
#[derive(Debug, Clone, Copy)]
struct Piece {
    a: Node,
    m: Node,
    b: Node,
    left: f64,
    right: f64,
    quadrature_error: f64,
    interpolation_error: f64,
    inner_error: f64,
    /// The first node of the five where the density is negative or not finite.
    invalid: Option<(f64, f64)>,
}

impl CdfTable {
    /// Tabulates F(x) = ∫_{cuts[0]}^x f for the density `density` (each value an estimate with
    /// its error bound) with adaptive Simpson, starting from [`INITIAL_PER_PIECE`] equal
    /// intervals per piece between consecutive `cuts` (sorted, end points included).
    pub fn build(density: &(dyn Fn(f64) -> Estimate + Sync), cuts: &[f64]) -> Self {
        let mut initial = Vec::new();
        for w in cuts.windows(2).filter(|w| w[1] > w[0]) {
            for k in 0..INITIAL_PER_PIECE {
                let t = |k: usize| w[0] + (w[1] - w[0]) * k as f64 / INITIAL_PER_PIECE as f64;
                initial.push([
                    t(k),
                    if k + 1 == INITIAL_PER_PIECE {
                        w[1]
                    } else {
                        t(k + 1)
                    },
                ]);
            }
        }
        let span = cuts.last().copied().unwrap_or(0.0) - cuts.first().copied().unwrap_or(0.0);
        let evaluations = std::sync::atomic::AtomicU64::new(0);
        let pieces: Vec<Vec<Piece>> = initial
            .par_iter()
            .map(|&[a, b]| {
                let (pieces, spent) = refine(density, a, b, span);
                evaluations.fetch_add(spent, std::sync::atomic::Ordering::Relaxed);
                pieces
            })
            .collect();
        Self::assemble(
            pieces.into_iter().flatten().collect(),
            evaluations.into_inner(),
        )
    }

    /// Knots, prefix sums and error totals from the accepted pieces (in order).
    fn assemble(pieces: Vec<Piece>, evaluations: u64) -> Self {
        let mut table = CdfTable {
            knots: Vec::with_capacity(2 * pieces.len() + 1),
            cdf: Vec::with_capacity(2 * pieces.len() + 1),
            density: Vec::with_capacity(2 * pieces.len() + 1),
            quadrature_error: 0.0,
            inner_error: 0.0,
            interpolation_error: 0.0,
            evaluations,
            invalid: None,
        };
        let mut total = 0.0;
        let mut last = None;
        for p in &pieces {
            if table.invalid.is_none() {
                table.invalid = p.invalid;
            }
            for (n, mass) in [(p.a, p.left), (p.m, p.right)] {
                table.knots.push(n.x);
                table.cdf.push(total);
                table.density.push(n.f);
                total += mass;
            }
            table.quadrature_error += p.quadrature_error;
            table.inner_error += p.inner_error;
            table.interpolation_error = table.interpolation_error.max(p.interpolation_error);
            last = Some(p);
        }
        if let Some(p) = last {
            table.knots.push(p.b.x);
            table.cdf.push(total);
            table.density.push(p.b.f);
        }
        if !total.is_finite() && table.invalid.is_none() {
            table.invalid = Some((f64::NAN, total));
        }
        table
    }

    /// The table's error bound: quadrature + inner integrals + interpolation.
    pub fn error_bound(&self) -> f64 {
        self.quadrature_error + self.inner_error + self.interpolation_error
    }

    /// The number of knots.
    pub fn knots(&self) -> usize {
        self.knots.len()
    }

    /// The total mass F(hi).
    pub fn total(&self) -> f64 {
        self.cdf.last().copied().unwrap_or(0.0)
    }

    /// F(x), clamped to the table's range.
    pub fn cdf(&self, x: f64) -> f64 {
        let n = self.knots.len();
        if n == 0 {
            return f64::NAN;
        }
        if !(x > self.knots[0]) {
            return self.cdf[0];
        }
        if x >= self.knots[n - 1] {
            return self.cdf[n - 1];
        }
        let i = self.knots.partition_point(|&k| k <= x) - 1;
        hermite(
            [self.knots[i], self.knots[i + 1]],
            [self.cdf[i], self.cdf[i + 1]],
            [self.density[i], self.density[i + 1]],
            x,
        )
    }
}

/// Adaptive Simpson over [a, b] (see the module documentation); returns the accepted pieces in
/// order and the pdf evaluations spent.
fn refine(
    density: &(dyn Fn(f64) -> Estimate + Sync),
    a: f64,
    b: f64,
    span: f64,
) -> (Vec<Piece>, u64) {
    let spent = std::cell::Cell::new(0u64);
    let eval = |x: f64| {
        let e = density(x);
        spent.set(spent.get() + e.evaluations);
        Node {
            x,
            f: e.value,
            error: e.error_bound,
        }
    };
    let mut out = Vec::new();
    let mut stack = vec![(eval(a), eval(0.5 * (a + b)), eval(b), 0u32)];
    let mut spans = 0usize;
    while let Some((na, nm, nb, depth)) = stack.pop() {
        spans += 1;
        let q1 = eval(0.5 * (na.x + nm.x));
        let q3 = eval(0.5 * (nm.x + nb.x));
        let h = nb.x - na.x;
        let whole = h / 6.0 * (na.f + 4.0 * nm.f + nb.f);
        let left = h / 12.0 * (na.f + 4.0 * q1.f + nm.f);
        let right = h / 12.0 * (nm.f + 4.0 * q3.f + nb.f);
        let quadrature_error = (left + right - whole).abs();
        let interpolated = hermite([na.x, nb.x], [0.0, left + right], [na.f, nb.f], nm.x);
        let interpolation_error = (interpolated - left).abs();
        let share = QUADRATURE_TOLERANCE * h / span.max(f64::MIN_POSITIVE);
        let good = quadrature_error <= share && interpolation_error <= INTERPOLATION_TOLERANCE;
        // An invalid density fails the test anyway: no point refining it.
        let invalid = [na, q1, nm, q3, nb]
            .iter()
            .find(|n| !(n.f.is_finite() && n.f >= 0.0))
            .map(|n| (n.x, n.f));
        let valid = invalid.is_none();
        if good || !valid || depth >= MAX_DEPTH || spans + stack.len() >= MAX_SPANS {
            let inner = [na, q1, nm, q3, nb]
                .iter()
                .map(|n| n.error)
                .fold(0.0f64, f64::max);
            out.push(Piece {
                a: na,
                m: nm,
                b: nb,
                left,
                right,
                quadrature_error,
                interpolation_error,
                inner_error: h * inner,
                invalid,
            });
        } else {
            stack.push((nm, q3, nb, depth + 1));
            stack.push((na, q1, nm, depth + 1));
        }
    }
    (out, spent.get())
}

/// The monotone cubic Hermite interpolant through (x₀, F₀), (x₁, F₁) with slopes f₀, f₁ ≥ 0,
/// limited by Fritsch–Carlson (α² + β² ≤ 9 with α = f₀/Δ, β = f₁/Δ, Δ the secant slope), at x;
/// clamped to [F₀, F₁].
fn hermite(x: [f64; 2], f: [f64; 2], slope: [f64; 2], at: f64) -> f64 {
    let h = x[1] - x[0];
    let rise = f[1] - f[0];
    if !(h > 0.0) || !(rise > 0.0) {
        return f[0];
    }
    let secant = rise / h;
    let (mut d0, mut d1) = (slope[0].max(0.0), slope[1].max(0.0));
    let (a, b) = (d0 / secant, d1 / secant);
    let r2 = a * a + b * b;
    if r2 > 9.0 {
        let tau = 3.0 / r2.sqrt();
        d0 = tau * a * secant;
        d1 = tau * b * secant;
    }
    let t = (at - x[0]) / h;
    let (t2, t3) = (t * t, t * t * t);
    let h01 = -2.0 * t3 + 3.0 * t2;
    let h10 = t3 - 2.0 * t2 + t;
    let h11 = t3 - t2;
    (f[0] + h01 * rise + h * (h10 * d0 + h11 * d1)).clamp(f[0], f[1])
}

/// The polar cuts of a lobe: 0, width × {10⁻³ … 10²}, the kinks, π/2.
fn polar_cuts(hints: &LobeHints<'_>) -> Vec<f64> {
    let mut cuts = vec![0.0, FRAC_PI_2];
    for k in [1e-3, 1e-2, 0.1, 0.3, 1.0, 3.0, 10.0, 30.0, 100.0] {
        let t = hints.width * k;
        if t > 0.0 && t < FRAC_PI_2 {
            cuts.push(t);
        }
    }
    cuts.extend(
        hints
            .theta_kinks
            .iter()
            .copied()
            .filter(|t| *t > 0.0 && *t < FRAC_PI_2),
    );
    cuts.sort_by(f64::total_cmp);
    cuts.dedup();
    cuts
}

/// The azimuthal cuts: the quadrants.
const AZIMUTH_CUTS: [f64; 5] = [0.0, 0.5 * PI, PI, 1.5 * PI, TAU];

/// Tabulates the CDF of a marginal of `pdf` (a density with respect to solid angle on the upper
/// hemisphere).
pub fn marginal_cdf<P>(pdf: &P, marginal: Marginal, hints: &LobeHints<'_>) -> CdfTable
where
    P: Fn(Vec3) -> f64 + Sync + ?Sized,
{
    let polar = polar_cuts(hints);
    match marginal {
        Marginal::CosTheta => {
            let density = |theta: f64| {
                let s = theta.sin();
                if s == 0.0 {
                    return Estimate::default();
                }
                let e = integrate_pieces(
                    &|phi| pdf(from_spherical(theta, phi)),
                    &AZIMUTH_CUTS,
                    INNER_ACCURACY,
                );
                Estimate {
                    value: s * e.value,
                    error_bound: s * e.error_bound,
                    evaluations: e.evaluations,
                }
            };
            CdfTable::build(&density, &polar)
        }
        Marginal::Phi => {
            let density = |phi: f64| {
                integrate_pieces(
                    &|theta| {
                        let v = pdf(from_spherical(theta, phi));
                        if v == 0.0 {
                            0.0
                        } else {
                            v * theta.sin()
                        }
                    },
                    &polar,
                    INNER_ACCURACY,
                )
            };
            CdfTable::build(&density, &AZIMUTH_CUTS)
        }
    }
}

/// The drawn values of a marginal, or the samples outside the domain.
struct Drawn {
    values: Vec<f64>,
    outside: u64,
    first_outside: Option<(u64, DomainError)>,
}

/// Draws `samples` normals with `sample` (seeded streams per chunk, as the chi-square test)
/// and returns the marginal's values in sample order.
fn draw<S>(sample: &S, marginal: Marginal, samples: u64, seed: u64) -> Drawn
where
    S: Fn([f64; 2]) -> Vec3 + Sync + ?Sized,
{
    let chunks: Vec<Drawn> = (0..samples.div_ceil(CHUNK))
        .into_par_iter()
        .map(|chunk| {
            let mut rng = stream(seed, chunk);
            let (start, end) = (chunk * CHUNK, ((chunk + 1) * CHUNK).min(samples));
            let mut d = Drawn {
                values: Vec::with_capacity((end - start) as usize),
                outside: 0,
                first_outside: None,
            };
            for index in start..end {
                let u = [uniform(&mut rng), uniform(&mut rng)];
                let m = sample(u);
                match validate(m) {
                    Ok(_) => d.values.push(marginal.value(m)),
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
        .reduce(
            || (usize::MAX, f64::NEG_INFINITY),
            |p, q| {
                if q.1 > p.1 || (q.1 == p.1 && q.0 < p.0) {
                    q
                } else {
                    p
                }
            },
        );
    match best {
        (i, d) if i < sorted.len() => (d, sorted[i]),
        _ => (f64::NAN, f64::NAN),
    }
}

/// Tests the marginal `marginal` of the sampler `sample` against that of the density `pdf`
/// (with respect to solid angle).
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
    let t = Instant::now();
    let mut drawn = draw(sample, marginal, config.samples, config.seed);
    drawn.values.par_sort_unstable_by(f64::total_cmp);
    let sampling_seconds = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let table = marginal_cdf(pdf, marginal, hints);
    let mut result = KsResult {
        marginal,
        statistic: f64::NAN,
        lambda: f64::NAN,
        p_value: 0.0,
        alpha: config.alpha,
        at: f64::NAN,
        samples: config.samples,
        seed: config.seed,
        verdict: Verdict::Fail,
        reason: None,
        knots: table.knots(),
        table_error_bound: table.error_bound(),
        pdf_mass: table.total(),
        evaluations: table.evaluations,
        sampling_seconds,
        table_seconds: t.elapsed().as_secs_f64(),
    };
    result.reason = sanity(&drawn, &table, config.samples);
    if result.reason.is_some() {
        return result;
    }
    let (d, at) = ks_statistic(&drawn.values, &|x| table.cdf(x));
    result.statistic = d;
    result.at = at;
    result.lambda = stephens_lambda(d, config.samples);
    result.p_value = kolmogorov_q(result.lambda);
    if result.p_value >= config.alpha {
        result.verdict = Verdict::Pass;
    } else {
        result.reason = Some(Failure::Rejected {
            p_value: result.p_value,
            alpha: config.alpha,
        });
    }
    result
}

/// The failures that leave no statistic: samples outside the domain, no samples, an invalid
/// density or mass, a table too coarse for N.
fn sanity(drawn: &Drawn, table: &CdfTable, samples: u64) -> Option<Failure> {
    if let Some((index, error)) = drawn.first_outside {
        return Some(Failure::OutsideDomain {
            index,
            error,
            count: drawn.outside,
        });
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
mod tests {
    use super::*;
    use mfh_reference::ndf::Ggx;
    use mfh_reference::{Model, ModelSpec};

    fn model(json: &str) -> Box<dyn Model> {
        serde_json::from_str::<ModelSpec>(json)
            .unwrap()
            .build()
            .unwrap()
    }

    fn config(samples: u64, seed: u64) -> KsConfig {
        KsConfig {
            samples,
            seed,
            alpha: 1e-4,
        }
    }

    fn hints(width: f64) -> LobeHints<'static> {
        LobeHints {
            width,
            theta_kinks: &[],
        }
    }

    fn report(name: &str, r: &KsResult) {
        eprintln!(
            "{name} {:?}: D = {:.3e}, λ = {:.3}, p = {:.4}, knots {}, table bound {:.1e}, \
             mass {:.12}, {} pdf evaluations, table {:.3} s, sampling {:.3} s",
            r.marginal,
            r.statistic,
            r.lambda,
            r.p_value,
            r.knots,
            r.table_error_bound,
            r.pdf_mass,
            r.evaluations,
            r.table_seconds,
            r.sampling_seconds
        );
    }

    #[test]
    fn ks_kolmogorov_distribution_values() {
        // P(K ≤ 1) = 0.730000328322645…; the critical values of K at 0.05, 0.01 and 0.001
        // (the 99-term series in double precision, solved by bisection).
        assert!((kolmogorov_q(1.0) - 0.269_999_671_677_354_56).abs() < 1e-14);
        for (lambda, p) in [
            (1.358_098_639_322_550_5, 0.05),
            (1.627_623_611_518_950_2, 0.01),
            (1.949_474_603_504_375, 0.001),
        ] {
            assert!((kolmogorov_q(lambda) / p - 1.0).abs() < 1e-9, "{lambda}");
        }
        // The two series agree across their switch point.
        let series_small = |l: f64| {
            let y = (-PI * PI / (8.0 * l * l)).exp();
            1.0 - (TAU.sqrt() / l) * [1, 9, 25, 49, 81].iter().map(|&k| y.powi(k)).sum::<f64>()
        };
        let series_large = |l: f64| {
            let x = (-2.0 * l * l).exp();
            2.0 * (1..=10)
                .map(|k: i32| f64::from(if k % 2 == 1 { 1 } else { -1 }) * x.powi(k * k))
                .sum::<f64>()
        };
        for l in [0.9, 1.1, 1.18, 1.3, 1.6] {
            assert!((series_small(l) - series_large(l)).abs() < 1e-15, "{l}");
        }
        assert_eq!(kolmogorov_q(0.0), 1.0);
        assert_eq!(kolmogorov_q(-1.0), 1.0);
        assert!(kolmogorov_q(f64::NAN).is_nan());
        assert!(kolmogorov_q(0.1) > 0.999_999_999);
        assert!(kolmogorov_q(10.0) < 1e-80 && kolmogorov_q(10.0) > 0.0);
        // Stephens' λ at N = 10⁶: ≈ √N·D.
        assert!((stephens_lambda(1e-3, 1_000_000) - 1.000_120_11).abs() < 1e-12);
    }

    #[test]
    fn ks_cdf_tables_match_closed_forms() {
        // Uniform on the hemisphere: F_θ = 1 − cos θ, F_φ = φ/2π.
        let uniform = |m: Vec3| if m[2] >= 0.0 { 1.0 / TAU } else { 0.0 };
        let t = marginal_cdf(&uniform, Marginal::CosTheta, &hints(0.3));
        let p = marginal_cdf(&uniform, Marginal::Phi, &hints(0.3));
        for x in [0.0, 1e-3, 0.1, 0.7, 1.2, 1.5, FRAC_PI_2] {
            assert!((t.cdf(x) - (1.0 - x.cos())).abs() < 1e-10, "{x}");
            assert!((p.cdf(4.0 * x) - 4.0 * x / TAU).abs() < 1e-10, "{x}");
        }
        // GGX: P(θ ≤ t) = tan²t / (α² + tan²t); anisotropic: P(φ ≤ p) = atan((α_x/α_y) tan p)/2π
        // on the first quadrant.
        for alpha in [0.3, 0.05] {
            let g = Ggx::new(alpha, alpha).unwrap();
            let t = marginal_cdf(&|m| g.pdf_wm(m), Marginal::CosTheta, &hints(alpha.atan()));
            let mut worst = 0.0f64;
            for i in 0..=1000 {
                let x = FRAC_PI_2 * f64::from(i) / 1000.0;
                let tan2 = x.tan().powi(2);
                let want = if i == 1000 {
                    1.0
                } else {
                    tan2 / (alpha * alpha + tan2)
                };
                worst = worst.max((t.cdf(x) - want).abs());
            }
            eprintln!(
                "GGX α = {alpha}: {} knots, bound {:.2e}, worst {worst:.2e}, {} evaluations",
                t.knots(),
                t.error_bound(),
                t.evaluations
            );
            assert!(worst < 1e-8 && worst <= t.error_bound().max(1e-12) * 10.0);
            assert!(t.error_bound() < 1e-7);
        }
        let g = Ggx::new(0.1, 0.4).unwrap();
        let p = marginal_cdf(&|m| g.pdf_wm(m), Marginal::Phi, &hints(0.1f64.atan()));
        for i in 0..=100 {
            let x = 0.5 * PI * f64::from(i) / 100.0;
            let want = if i == 100 {
                0.25
            } else {
                (0.25 * x.tan()).atan() / TAU
            };
            assert!((p.cdf(x) - want).abs() < 1e-8, "{x}: {} {want}", p.cdf(x));
        }
        assert!(p.error_bound() < 1e-7 && (p.total() - 1.0).abs() < 1e-9);
    }

    fn passes(json: &str, samples: u64) {
        let m = model(json);
        let s = m.as_sampler().unwrap();
        let spec = serde_json::to_value(m.spec()).unwrap();
        let width = crate::check::lobe_width(&spec);
        for marginal in [Marginal::CosTheta, Marginal::Phi] {
            let r = ks_test_sampler(s, marginal, &hints(width), &config(samples, 7));
            report(json, &r);
            assert_eq!(r.verdict, Verdict::Pass, "{:?}", r.reason);
            assert!(r.p_value > 1e-3, "{r:?}");
        }
    }

    #[test]
    fn ks_correct_samplers_pass() {
        passes(r#"{"family":"ggx","alpha":0.3}"#, 1_000_000);
        passes(r#"{"family":"ggx","alpha_x":0.1,"alpha_y":0.4}"#, 1_000_000);
        passes(r#"{"family":"beckmann","alpha":0.3}"#, 1_000_000);
    }

    #[test]
    fn ks_defects_of_one_percent_fail() {
        // The sampler of α·1.02 against the pdf of α: D ≈ 0.02·max 2F(1 − F) = 0.01.
        let sampler = Ggx::new(0.306, 0.306).unwrap();
        let pdf = Ggx::new(0.3, 0.3).unwrap();
        let h = hints(0.3f64.atan());
        let r = ks_test(
            &|u| sampler.sample_wm(u),
            &|m| pdf.pdf_wm(m),
            Marginal::CosTheta,
            &h,
            &config(1_000_000, 7),
        );
        report("α·1.02", &r);
        assert_eq!(r.verdict, Verdict::Fail);
        assert!(r.p_value < 1e-12, "{r:?}");
        assert!(matches!(r.reason, Some(Failure::Rejected { .. })));
        // φ = 2π·(1.01 u₁ mod 1) (GGX maps u₁ to the azimuth): 1 % of the azimuths wrapped
        // back onto [0, 0.02π].
        let g = Ggx::new(0.3, 0.3).unwrap();
        let stretched = |u: [f64; 2]| g.sample_wm([(1.01 * u[0]).fract(), u[1]]);
        let r = ks_test(
            &stretched,
            &|m| g.pdf_wm(m),
            Marginal::Phi,
            &h,
            &config(1_000_000, 7),
        );
        report("φ stretched 1 %", &r);
        assert!(r.p_value < 1e-12, "{r:?}");
        // The θ marginal of the φ defect is right: that test passes.
        let r = ks_test(
            &stretched,
            &|m| g.pdf_wm(m),
            Marginal::CosTheta,
            &h,
            &config(1_000_000, 7),
        );
        assert_eq!(r.verdict, Verdict::Pass, "{r:?}");
    }

    #[test]
    fn ks_sanity_failures() {
        let g = Ggx::new(0.3, 0.3).unwrap();
        let h = hints(0.3);
        let flipped = |u: [f64; 2]| {
            let m = g.sample_wm(u);
            if u[0] < 0.01 {
                [m[0], m[1], -m[2]]
            } else {
                m
            }
        };
        let r = ks_test(
            &flipped,
            &|m| g.pdf_wm(m),
            Marginal::Phi,
            &h,
            &config(10_000, 3),
        );
        assert!(matches!(
            r.reason,
            Some(Failure::OutsideDomain {
                error: DomainError::BelowHorizon(_),
                ..
            })
        ));
        let half = ks_test(
            &|u| g.sample_wm(u),
            &|m| 0.5 * g.pdf_wm(m),
            Marginal::CosTheta,
            &h,
            &config(10_000, 3),
        );
        assert!(
            matches!(half.reason, Some(Failure::MassOff { .. })),
            "{half:?}"
        );
        let negative = ks_test(
            &|u| g.sample_wm(u),
            &|m| -g.pdf_wm(m),
            Marginal::CosTheta,
            &h,
            &config(10_000, 3),
        );
        assert!(
            matches!(negative.reason, Some(Failure::InvalidDensity { .. })),
            "{negative:?}"
        );
        // The double-exponential rule reads a NaN integrand as 0: a NaN pdf has mass 0.
        let nan = ks_test(
            &|u| g.sample_wm(u),
            &|_| f64::NAN,
            Marginal::CosTheta,
            &h,
            &config(10_000, 3),
        );
        assert!(
            matches!(nan.reason, Some(Failure::MassOff { .. })),
            "{nan:?}"
        );
        assert_eq!(nan.verdict, Verdict::Fail);
    }

    #[test]
    fn ks_results_do_not_depend_on_thread_count() {
        let g = Ggx::new(0.1, 0.4).unwrap();
        let run = |threads| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| {
                    let mut r =
                        ks_test_sampler(&g, Marginal::Phi, &hints(0.1), &config(3 * CHUNK + 77, 5));
                    r.sampling_seconds = 0.0;
                    r.table_seconds = 0.0;
                    r
                })
        };
        let (one, two) = (run(1), run(2));
        assert_eq!(one, two);
        let other = ks_test_sampler(&g, Marginal::Phi, &hints(0.1), &config(3 * CHUNK + 77, 6));
        assert_ne!(one.statistic, other.statistic);
    }

    #[test]
    fn ks_p_values_of_a_correct_sampler_spread_over_seeds() {
        let g = Ggx::new(0.3, 0.3).unwrap();
        let h = hints(0.3f64.atan());
        let table = marginal_cdf(&|m| g.pdf_wm(m), Marginal::CosTheta, &h);
        let p: Vec<f64> = (0..12u64)
            .map(|seed| {
                let mut d = draw(&|u| g.sample_wm(u), Marginal::CosTheta, 50_000, seed);
                d.values.sort_unstable_by(f64::total_cmp);
                ks_p_value(ks_statistic(&d.values, &|x| table.cdf(x)).0, 50_000)
            })
            .collect();
        eprintln!("p-values over 12 seeds: {p:.3?}");
        let mean = p.iter().sum::<f64>() / p.len() as f64;
        assert!((0.25..0.75).contains(&mean), "{p:?}");
        assert!(p.iter().all(|&p| p > 1e-3), "{p:?}");
        assert!(
            p.iter().any(|&p| p < 0.5) && p.iter().any(|&p| p > 0.5),
            "{p:?}"
        );
    }
}
