//! Tabulated marginal CDFs of a density on the upper hemisphere (steps 3 and 4 of the
//! procedure in the module documentation of [`crate::oracle::ks`]).

use super::{LobeHints, Marginal, INITIAL_PER_PIECE, INNER_ACCURACY, INTERPOLATION_TOLERANCE};
use super::{
    KS_EVALUATION_BUDGET, MAX_DEPTH, MAX_SPANS, QUADRATURE_TOLERANCE, SIMPSON_NOISE_FLOOR,
};
use crate::oracle::lobe::{self, Lobe};
use crate::oracle::quadrature::integrate_pieces_many;
use crate::oracle::Estimate;
use crate::precision::Precision;
use mfh_reference::geometry::Vec3;
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
    /// Tabulates F(x) = ∫_{cuts\[0\]}^x f for the density `density` (each value an estimate with
    /// its error bound) with adaptive Simpson, starting from [`INITIAL_PER_PIECE`] equal
    /// intervals per piece between consecutive `cuts` (sorted, end points included).
    pub fn build(density: &(dyn Fn(f64) -> Estimate + Sync), cuts: &[f64]) -> Self {
        Self::build_batch(&|xs: &[f64]| xs.iter().map(|&x| density(x)).collect(), cuts)
    }

    /// [`CdfTable::build`] for a batch density (`density(xs)` returns the estimates at each of
    /// `xs`, in order): the refinement of every interval advances in waves, and each wave's new
    /// nodes are evaluated together, in chunks of [`NODES_PER_CALL`] spread over threads. The
    /// accepted intervals are those of one interval at a time (same tests, same arithmetic);
    /// only the cap [`MAX_SPANS`] counts the intervals of a wave instead of a depth-first stack.
    pub fn build_batch(density: &DensityBatch<'_>, cuts: &[f64]) -> Self {
        Self::build_batch_at(density, cuts, f64::EPSILON)
    }

    /// [`CdfTable::build_batch`] for a density whose values are rounded to `noise` relative
    /// (the pdf's precision): a span within [`SIMPSON_NOISE_FLOOR`] roundings of its mass is
    /// accepted.
    pub fn build_batch_at(density: &DensityBatch<'_>, cuts: &[f64], noise: f64) -> Self {
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
        let mut evaluations = 0u64;
        // The initial nodes: end points (shared by neighbours) and midpoints, each once.
        let mut xs: Vec<f64> = initial
            .iter()
            .flat_map(|&[a, b]| [a, 0.5 * (a + b), b])
            .collect();
        xs.sort_by(f64::total_cmp);
        xs.dedup_by(|x, y| x.to_bits() == y.to_bits());
        let nodes = evaluate(density, &xs, &mut evaluations);
        let node = |x: f64| {
            let i = xs.partition_point(|y| y.total_cmp(&x).is_lt());
            nodes[i]
        };
        let mut active: Vec<Span> = initial
            .iter()
            .enumerate()
            .map(|(interval, &[a, b])| Span {
                interval,
                a: node(a),
                m: node(0.5 * (a + b)),
                b: node(b),
                depth: 0,
            })
            .collect();
        let mut accepted: Vec<Vec<Piece>> = vec![Vec::new(); initial.len()];
        // Per initial interval: spans examined, and spans queued (this wave's and the next's).
        let mut examined = vec![0usize; initial.len()];
        let mut queued = vec![0usize; initial.len()];
        for s in &active {
            queued[s.interval] += 1;
        }
        while !active.is_empty() {
            if evaluations >= KS_EVALUATION_BUDGET {
                // Out of budget: the spans still open are accepted unrefined with an infinite
                // quadrature error, so that the table's bound says it was not resolved.
                for s in active.drain(..) {
                    let h = s.b.x - s.a.x;
                    let whole = h / 6.0 * (s.a.f + 4.0 * s.m.f + s.b.f);
                    accepted[s.interval].push(Piece {
                        a: s.a,
                        m: s.m,
                        b: s.b,
                        left: 0.5 * whole,
                        right: 0.5 * whole,
                        quadrature_error: f64::INFINITY,
                        interpolation_error: 0.0,
                        inner_error: h * s.a.error.max(s.m.error).max(s.b.error),
                        invalid: None,
                    });
                }
                break;
            }
            let xs: Vec<f64> = active
                .iter()
                .flat_map(|s| [0.5 * (s.a.x + s.m.x), 0.5 * (s.m.x + s.b.x)])
                .collect();
            let quarters = evaluate(density, &xs, &mut evaluations);
            let mut next = Vec::new();
            for (s, q) in active.iter().zip(quarters.chunks(2)) {
                let i = s.interval;
                examined[i] += 1;
                queued[i] -= 1;
                let [a, b] = initial[i];
                let capped = examined[i] + queued[i] >= MAX_SPANS;
                match judge(
                    s,
                    q[0],
                    q[1],
                    budget * (s.b.x - s.a.x) / (b - a).max(f64::MIN_POSITIVE),
                    SIMPSON_NOISE_FLOOR * noise,
                    capped,
                ) {
                    Judged::Accept(piece) => accepted[i].push(piece),
                    Judged::Split([left, right]) => {
                        queued[i] += 2;
                        next.extend([left, right]);
                    }
                }
            }
            active = next;
        }
        let mut pieces = Vec::new();
        for mut a in accepted {
            a.sort_by(|p, q| p.a.x.total_cmp(&q.a.x));
            pieces.extend(a);
        }
        Self::assemble(pieces, evaluations)
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

    /// F at each of the ascending `xs` (as `f64::total_cmp` sorts), passed to `f(i, F(xs[i]))`
    /// in order: the values of [`CdfTable::cdf`] bit for bit, the interval found by a walk
    /// along the knots instead of a binary search per value (the KS statistic evaluates F at
    /// every one of 2·10⁶ sorted samples).
    pub fn cdf_ascending(&self, xs: &[f64], mut f: impl FnMut(usize, f64)) {
        let n = self.knots.len();
        let mut i = match xs.first() {
            Some(&x) if n > 0 => self.knots.partition_point(|&k| k <= x).saturating_sub(1),
            _ => 0,
        };
        // The interval's limited slopes once per interval, not per value (the same bits:
        // `Segment::at` is `hermite`'s evaluation).
        let mut segment = (usize::MAX, Segment::default());
        for (j, &x) in xs.iter().enumerate() {
            if n < 2 || !(x > self.knots[0]) || x >= self.knots[n - 1] {
                f(j, self.cdf(x));
                continue;
            }
            while self.knots[i + 1] <= x {
                i += 1;
            }
            if segment.0 != i {
                segment = (i, self.segment(i));
            }
            f(j, segment.1.at(x));
        }
    }

    /// The interpolant on [knot i, knot i + 1].
    fn segment(&self, i: usize) -> Segment {
        Segment::new(
            [self.knots[i], self.knots[i + 1]],
            [self.cdf[i], self.cdf[i + 1]],
            [self.density[i], self.density[i + 1]],
        )
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
        self.segment(i).at(x)
    }
}

/// A batch density: the estimates at each of `xs`, in order.
pub type DensityBatch<'a> = dyn Fn(&[f64]) -> Vec<Estimate> + Sync + 'a;

/// The nodes of one call of a batch density: a fixed number (not one per thread), so that the
/// calls' contents, and with them the table, do not depend on the thread count even for a
/// density whose batches are not evaluated element by element; 64 nodes of ~10² inner
/// evaluations each make requests of ~10⁴ directions for an external model.
pub const NODES_PER_CALL: usize = 64;

/// The density at each of `xs` as nodes, in chunks of [`NODES_PER_CALL`] over threads.
fn evaluate(density: &DensityBatch<'_>, xs: &[f64], evaluations: &mut u64) -> Vec<Node> {
    let chunks: Vec<Vec<Estimate>> = xs.par_chunks(NODES_PER_CALL).map(density).collect();
    let mut out = Vec::with_capacity(xs.len());
    for (e, &x) in chunks.into_iter().flatten().zip(xs) {
        *evaluations += e.evaluations;
        out.push(Node {
            x,
            f: e.value,
            error: e.error_bound,
        });
    }
    out
}

/// An interval [a, b] of the adaptive Simpson quadrature with its midpoint node, inside the
/// initial interval `interval`, `depth` bisections below it.
#[derive(Debug, Clone, Copy)]
struct Span {
    interval: usize,
    a: Node,
    m: Node,
    b: Node,
    depth: u32,
}

/// What [`judge`] decides for a span.
enum Judged {
    /// The span is accepted as this piece.
    Accept(Piece),
    /// The span's two halves, to refine.
    Split([Span; 2]),
}

/// One step of adaptive Simpson over a span (see the module documentation), with the nodes
/// q1, q3 at its quarter points and its `share` of the budget: the accepted piece, or the two
/// halves to refine. `capped`: accept whatever the error (the span cap is reached).
fn judge(s: &Span, q1: Node, q3: Node, share: f64, noise: f64, capped: bool) -> Judged {
    let (na, nm, nb) = (s.a, s.m, s.b);
    let h = nb.x - na.x;
    let whole = h / 6.0 * (na.f + 4.0 * nm.f + nb.f);
    let left = h / 12.0 * (na.f + 4.0 * q1.f + nm.f);
    let right = h / 12.0 * (nm.f + 4.0 * q3.f + nb.f);
    let quadrature_error = (left + right - whole).abs();
    let interpolated = hermite([na.x, nb.x], [0.0, left + right], [na.f, nb.f], nm.x);
    let interpolation_error = (interpolated - left).abs();
    // The rounding floor of the span's values (`SIMPSON_NOISE_FLOOR`).
    let floor = noise * (left.abs() + right.abs());
    let good = quadrature_error <= share.max(floor)
        && interpolation_error <= INTERPOLATION_TOLERANCE.max(floor);
    // An invalid density fails the test anyway: no point refining it.
    let invalid = [na, q1, nm, q3, nb]
        .iter()
        .find(|n| !(n.f.is_finite() && n.f >= 0.0))
        .map(|n| (n.x, n.f));
    if good || invalid.is_some() || s.depth >= MAX_DEPTH || capped {
        let inner = [na, q1, nm, q3, nb]
            .iter()
            .map(|n| n.error)
            .fold(0.0f64, f64::max);
        Judged::Accept(Piece {
            a: na,
            m: nm,
            b: nb,
            left,
            right,
            quadrature_error,
            interpolation_error,
            inner_error: h * inner,
            invalid,
        })
    } else {
        let half = |a, m, b| Span {
            interval: s.interval,
            a,
            m,
            b,
            depth: s.depth + 1,
        };
        Judged::Split([half(na, q1, nm), half(nm, q3, nb)])
    }
}

/// The monotone cubic Hermite interpolant through (x₀, F₀), (x₁, F₁) with slopes f₀, f₁ ≥ 0,
/// limited by Fritsch–Carlson (α² + β² ≤ 9 with α = f₀/Δ, β = f₁/Δ, Δ the secant slope), at x;
/// clamped to [F₀, F₁].
fn hermite(x: [f64; 2], f: [f64; 2], slope: [f64; 2], at: f64) -> f64 {
    Segment::new(x, f, slope).at(at)
}

/// [`hermite`]'s interpolant on one interval, its slopes limited once.
#[derive(Debug, Clone, Copy, Default)]
struct Segment {
    /// x₀ and h = x₁ − x₀.
    x0: f64,
    h: f64,
    /// F₀, F₁ and F₁ − F₀.
    f: [f64; 2],
    rise: f64,
    /// The limited slopes; `None` where the interval is empty or flat (the value is F₀).
    slopes: Option<[f64; 2]>,
}

impl Segment {
    fn new(x: [f64; 2], f: [f64; 2], slope: [f64; 2]) -> Self {
        let h = x[1] - x[0];
        let rise = f[1] - f[0];
        let mut segment = Self {
            x0: x[0],
            h,
            f,
            rise,
            slopes: None,
        };
        if !(h > 0.0) || !(rise > 0.0) {
            return segment;
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
        segment.slopes = Some([d0, d1]);
        segment
    }

    /// The interpolant at `at`, clamped to [F₀, F₁].
    fn at(&self, at: f64) -> f64 {
        let Some([d0, d1]) = self.slopes else {
            return self.f[0];
        };
        let (h, f) = (self.h, self.f);
        let t = (at - self.x0) / h;
        let (t2, t3) = (t * t, t * t * t);
        let h01 = -2.0 * t3 + 3.0 * t2;
        let h10 = t3 - 2.0 * t2 + t;
        let h11 = t3 - t2;
        (f[0] + h01 * self.rise + h * (h10 * d0 + h11 * d1)).clamp(f[0], f[1])
    }
}

/// sin θ and cos θ as `from_spherical` computes them (cos θ snapped to 0 at the horizon), so
/// that a direction assembled from them and φ's sine and cosine is `from_spherical(θ, φ)` bit
/// for bit.
pub(super) fn polar_sin_cos(theta: f64) -> (f64, f64) {
    let (st, ct) = theta.sin_cos();
    if (theta - FRAC_PI_2).abs() < 1e-15 {
        (st, 0.0)
    } else {
        (st, ct)
    }
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

/// [`marginal_cdf`] for a batch density (`pdf(m, out)` writes pdf(m\[i\]) into out\[i\]): the same
/// table bit for bit, each step of each inner integral one call of `pdf`.
pub fn marginal_cdf_batch(
    pdf: &(dyn Fn(&[Vec3], &mut [f64]) + Sync),
    marginal: Marginal,
    hints: &LobeHints<'_>,
) -> CdfTable {
    let options = lobe::Options {
        hint: Some(hints.width),
        start_points: &[],
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
    marginal_cdf_lobe_batch_at(pdf, marginal, lobe, theta_kinks, Precision::F64)
}

/// [`marginal_cdf_lobe_batch`] for a pdf computed in `precision`: the inner integrals and the
/// outer Simpson stop at its rounding floor.
pub fn marginal_cdf_lobe_batch_at(
    pdf: &(dyn Fn(&[Vec3], &mut [f64]) + Sync),
    marginal: Marginal,
    lobe: &Lobe,
    theta_kinks: &[f64],
    precision: Precision,
) -> CdfTable {
    let inner_accuracy = INNER_ACCURACY.at(precision);
    let noise = precision.epsilon();
    let polar = lobe.polar_cuts_with(FRAC_PI_2, theta_kinks);
    let azimuth = lobe.azimuth_cuts();
    // The inner integrals of one wave of the table run in lockstep: one call of `pdf` per
    // step of all of them (an external model pays a round trip per step, not per knot), each
    // with the arithmetic of an integral alone.
    match marginal {
        Marginal::CosTheta => {
            let density = |thetas: &[f64]| {
                // θ with sin θ = 0 (the pole) has density 0 and no integral.
                let at: Vec<f64> = thetas.iter().copied().filter(|t| t.sin() != 0.0).collect();
                let problems: Vec<_> = at
                    .iter()
                    .map(|_| (azimuth.clone(), inner_accuracy))
                    .collect();
                // θ's sine and (snapped) cosine once per integral, not per node.
                let trig: Vec<(f64, f64)> = at.iter().map(|&t| polar_sin_cos(t)).collect();
                let mut m = Vec::new();
                let mut estimates = integrate_pieces_many(
                    &mut |tx: &[(usize, f64)], out: &mut [f64]| {
                        m.clear();
                        m.extend(tx.iter().map(|&(k, phi)| {
                            let ((st, ct), (sp, cp)) = (trig[k], phi.sin_cos());
                            [st * cp, st * sp, ct]
                        }));
                        pdf(&m, out)
                    },
                    &problems,
                )
                .into_iter();
                thetas
                    .iter()
                    .map(|theta| {
                        let s = theta.sin();
                        if s == 0.0 {
                            return Estimate::default();
                        }
                        let e = estimates.next().unwrap_or_default();
                        Estimate {
                            value: s * e.value,
                            error_bound: s * e.error_bound,
                            evaluations: e.evaluations,
                        }
                    })
                    .collect()
            };
            CdfTable::build_batch_at(&density, &polar, noise)
        }
        Marginal::Phi => {
            let density = |phis: &[f64]| {
                let problems: Vec<_> = phis
                    .iter()
                    .map(|_| (polar.clone(), inner_accuracy))
                    .collect();
                // φ's sine and cosine once per integral, not per node.
                let azimuthal: Vec<(f64, f64)> = phis.iter().map(|p| p.sin_cos()).collect();
                let mut m = Vec::new();
                integrate_pieces_many(
                    &mut |tx: &[(usize, f64)], out: &mut [f64]| {
                        m.clear();
                        m.extend(tx.iter().map(|&(k, theta)| {
                            let ((st, ct), (sp, cp)) = (polar_sin_cos(theta), azimuthal[k]);
                            [st * cp, st * sp, ct]
                        }));
                        pdf(&m, out);
                        for (v, &(_, theta)) in out.iter_mut().zip(tx) {
                            *v = if *v == 0.0 { 0.0 } else { *v * theta.sin() };
                        }
                    },
                    &problems,
                )
            };
            CdfTable::build_batch_at(&density, &azimuth, noise)
        }
    }
}
