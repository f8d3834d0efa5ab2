//! Tabulated marginal CDFs of a density on the upper hemisphere (steps 3 and 4 of the
//! procedure in the module documentation of [`crate::oracle::ks`]).

use super::{LobeHints, Marginal, INITIAL_PER_PIECE, INNER_ACCURACY, INTERPOLATION_TOLERANCE};
use super::{MAX_DEPTH, MAX_SPANS, QUADRATURE_TOLERANCE};
use crate::oracle::lobe::{self, Lobe};
use crate::oracle::quadrature::integrate_pieces_batch;
use crate::oracle::Estimate;
use mfh_reference::geometry::{from_spherical, Vec3};
use rayon::prelude::*;
use std::f64::consts::FRAC_PI_2;

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
        // Each initial interval gets an equal share of the tolerance (the cuts are placed
        // log-spaced about the lobe, so each carries a comparable part of the mass; a share
        // by length would ask 1e-13 relative of the intervals of a lobe 1e-4 wide).
        let budget = QUADRATURE_TOLERANCE / initial.len().max(1) as f64;
        let evaluations = std::sync::atomic::AtomicU64::new(0);
        let pieces: Vec<Vec<Piece>> = initial
            .par_iter()
            .map(|&[a, b]| {
                let (pieces, spent) = refine(density, a, b, budget);
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
    budget: f64,
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
        let share = budget * h / (b - a).max(f64::MIN_POSITIVE);
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

/// Tabulates the CDF of a marginal of `pdf` (a density with respect to solid angle on the upper
/// hemisphere), measuring its lobe first (`hints.width` is only a hint).
pub fn marginal_cdf<P>(pdf: &P, marginal: Marginal, hints: &LobeHints<'_>) -> CdfTable
where
    P: Fn(Vec3) -> f64 + Sync + ?Sized,
{
    marginal_cdf_batch(&scalar_batch(pdf), marginal, hints)
}

/// A scalar density as a batch one (a loop).
fn scalar_batch<P>(pdf: &P) -> impl Fn(&[Vec3], &mut [f64]) + Sync + '_
where
    P: Fn(Vec3) -> f64 + Sync + ?Sized,
{
    move |m: &[Vec3], out: &mut [f64]| {
        for (o, &m) in out.iter_mut().zip(m) {
            *o = pdf(m);
        }
    }
}

/// [`marginal_cdf`] for a batch density (`pdf(m, out)` writes pdf(m[i]) into out[i]): the same
/// table bit for bit, each step of each inner integral one call of `pdf`.
pub fn marginal_cdf_batch(
    pdf: &(dyn Fn(&[Vec3], &mut [f64]) + Sync),
    marginal: Marginal,
    hints: &LobeHints<'_>,
) -> CdfTable {
    let options = lobe::Options {
        hint: Some(hints.width),
        seeds: &[],
    };
    let lobe = lobe::measure_with_batch(pdf, &options);
    let mut table = marginal_cdf_lobe_batch(pdf, marginal, &lobe, hints.theta_kinks);
    table.evaluations += lobe.evaluations;
    table
}

/// Tabulates the CDF of a marginal of `pdf`, with the polar cuts of `lobe`
/// ([`Lobe::polar_cuts`]) and `theta_kinks`, and its azimuthal cuts ([`Lobe::azimuth_cuts`]),
/// both for the outer table and for the inner integrals.
pub fn marginal_cdf_lobe<P>(
    pdf: &P,
    marginal: Marginal,
    lobe: &Lobe,
    theta_kinks: &[f64],
) -> CdfTable
where
    P: Fn(Vec3) -> f64 + Sync + ?Sized,
{
    marginal_cdf_lobe_batch(&scalar_batch(pdf), marginal, lobe, theta_kinks)
}

/// [`marginal_cdf_lobe`] for a batch density: the same table bit for bit.
pub fn marginal_cdf_lobe_batch(
    pdf: &(dyn Fn(&[Vec3], &mut [f64]) + Sync),
    marginal: Marginal,
    lobe: &Lobe,
    theta_kinks: &[f64],
) -> CdfTable {
    let mut polar = lobe.polar_cuts(FRAC_PI_2);
    polar.extend(
        theta_kinks
            .iter()
            .copied()
            .filter(|t| *t > 0.0 && *t < FRAC_PI_2),
    );
    polar.sort_by(f64::total_cmp);
    polar.dedup();
    let azimuth = lobe.azimuth_cuts();
    match marginal {
        Marginal::CosTheta => {
            let density = |theta: f64| {
                let s = theta.sin();
                if s == 0.0 {
                    return Estimate::default();
                }
                let e = integrate_pieces_batch(
                    &|phis: &[f64], out: &mut [f64]| {
                        let m: Vec<Vec3> =
                            phis.iter().map(|&phi| from_spherical(theta, phi)).collect();
                        pdf(&m, out)
                    },
                    &azimuth,
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
                integrate_pieces_batch(
                    &|thetas: &[f64], out: &mut [f64]| {
                        let m: Vec<Vec3> = thetas
                            .iter()
                            .map(|&theta| from_spherical(theta, phi))
                            .collect();
                        pdf(&m, out);
                        for (v, &theta) in out.iter_mut().zip(thetas) {
                            *v = if *v == 0.0 { 0.0 } else { *v * theta.sin() };
                        }
                    },
                    &polar,
                    INNER_ACCURACY,
                )
            };
            CdfTable::build(&density, &azimuth)
        }
    }
}
