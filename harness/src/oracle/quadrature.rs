//! Adaptive 1-D quadrature with an error bound, and the nested hemisphere / sphere integrals
//! built on it: double-exponential (tanh–sinh) rules from the `quadrature` crate on each piece,
//! made globally adaptive by bisecting the piece with the largest error estimate.
//!
//! Why double-exponential here: the models' own numerical routes (GTR exact Λ, piecewise-linear
//! Λ) use Gauss–Kronrod (`mfh_reference::special::gauss_kronrod`); the oracle uses a different
//! rule family so that it shares no failure mode with them, and tanh–sinh is robust to the
//! integrable end-point singularities of heavy-tailed slope densities.

use super::double_exponential::{run_states, BatchFn, State, TaggedBatchFn};
use super::lobe::Lobe;
use super::Estimate;
use mfh_reference::trig::{sin_cos, sin_cos_block};
use mfh_reference::Vec3;
use std::cell::Cell;

/// The most pieces one integral splits into: past it the estimate is returned with its
/// (honest) error bound rather than bisecting for ever at round-off.
pub const MAX_PIECES: usize = 400;

/// The relative round-off floor of a target, in units of the integrand's rounding
/// ([`Accuracy::noise`]): 32 of them of the summed magnitudes of the pieces. For an f64
/// integrand 32 ulps; for a float32 implementation 32 ε₃₂ = 3.8e-6: below it, refinement of a
/// noisy integrand only trades one rounding error for another (a float32 GGX's normalization
/// passed 2·10⁸ evaluations chasing 1e-11).
const ROUNDOFF: f64 = 32.0;

/// How much rounding of the nodes themselves magnifies round-off on [lo, hi]: a node next to
/// an end point x is known only to ~ε|x|, so on a piece narrow next to its own position (the
/// sliver between a terminator and the horizon at normal incidence, θ ≈ π/2 over 1e-5) an
/// integrand that varies across the piece is resolved only to ~ε|x|/(hi − lo) relative.
fn node_noise(lo: f64, hi: f64) -> f64 {
    let width = (hi - lo).abs();
    if width > 0.0 {
        1.0 + 0.125 * lo.abs().max(hi.abs()) / width
    } else {
        1.0
    }
}

/// The most integrand evaluations one nested (2-D) quadrature spends ([`integrate_cap`] and
/// the hemisphere integrals on it, the Λ lune oracle): 10⁸, 5× the most a correct model is
/// known to need (the normalization of an anisotropic GGX α = 10⁻⁴ × 10⁻², 2.0·10⁷, in
/// `oracle::sweep_tests`), ~5 s of a closed-form D.
/// Past it the inner integrals are no longer computed and the estimate is NaN with an infinite
/// bound and `evaluations` ≥ the budget, which `check::compare` reports as an `error` naming
/// the budget: a piecewise-constant D's `smith.lambda_route` took 125 s per record without it.
pub const EVALUATION_BUDGET: u64 = 100_000_000;

/// The estimate of a nested quadrature that ran out of [`EVALUATION_BUDGET`].
pub fn exhausted(evaluations: u64) -> Estimate {
    Estimate {
        value: f64::NAN,
        error_bound: f64::INFINITY,
        evaluations: evaluations.max(EVALUATION_BUDGET),
    }
}

/// The accuracy asked of an integral: stop when the error bound is ≤ max(relative·|I|, absolute).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Accuracy {
    /// Relative target.
    pub relative: f64,
    /// Absolute floor.
    pub absolute: f64,
    /// The relative rounding of one evaluation of the integrand: f64's ε for mfh's own
    /// integrands, the declared precision's ε for an implementation's values (see
    /// [`Accuracy::at`]). No target is asked below [`ROUNDOFF`] of it.
    pub noise: f64,
}

impl Accuracy {
    /// A relative target with a negligible absolute floor, for an f64 integrand.
    pub fn relative(relative: f64) -> Self {
        Self {
            relative,
            absolute: 1e-300,
            noise: f64::EPSILON,
        }
    }

    /// This accuracy for an integrand computed in `precision`: its rounding floor is that
    /// precision's (the target itself is unchanged; where it is below the floor, the floor
    /// wins, and the estimate's error bound says what was reached).
    pub fn at(self, precision: crate::precision::Precision) -> Self {
        Self {
            noise: precision.epsilon(),
            ..self
        }
    }

    /// The relative rounding floor this accuracy stops at (of ∫|f|).
    pub fn floor(&self) -> f64 {
        ROUNDOFF * self.noise
    }

    /// The rounding floor for the record (`OracleValue::noise_floor`) where it is above the
    /// relative target, so that the oracle stops at it rather than at the target (an
    /// integrand in float32: 32 ε₃₂ = 3.8e-6 against targets of 1e-11); `None` where the
    /// target rules (every f64 integrand: its floor, 7e-15, is below every target asked).
    pub fn noise_floor(&self) -> Option<crate::record::NoiseFloor> {
        (self.floor() > self.relative).then_some(crate::record::NoiseFloor {
            noise: self.noise,
            floor: self.floor(),
        })
    }
}

/// ∫_a^b f over the pieces between consecutive `points` (sorted; the end points included), so
/// that kinks of f sit on piece boundaries.
///
/// Each piece starts with a cheap estimate that fixes the magnitude of the integral; every
/// piece is then refined to its share of the target, and, worst error first, bisected until
/// the summed error estimate meets the target or [`MAX_PIECES`] is reached. A refined piece's
/// error is checked against a second rule (see `estimate`), so that a double-exponential
/// estimate that stopped early cannot pass unseen.
pub fn integrate_pieces(f: &dyn Fn(f64) -> f64, points: &[f64], accuracy: Accuracy) -> Estimate {
    integrate_pieces_batch(&scalar_batch(f), points, accuracy)
}

/// A scalar integrand as a batch one (a loop).
fn scalar_batch<'f>(f: &'f dyn Fn(f64) -> f64) -> impl Fn(&[f64], &mut [f64]) + 'f {
    move |x: &[f64], out: &mut [f64]| {
        for (o, &x) in out.iter_mut().zip(x) {
            *o = f(x);
        }
    }
}

/// [`integrate_pieces`] for a batch integrand (`f(x, out)` writes f(x\[i\]) into out\[i\]): the
/// same nodes and arithmetic, so the same result bit for bit, but each step of the rule
/// evaluates its nodes in one call ([`integrate_pieces_many`]).
pub fn integrate_pieces_batch(f: &BatchFn<'_>, points: &[f64], accuracy: Accuracy) -> Estimate {
    let mut xs = Vec::new();
    integrate_pieces_many(
        &mut |tx: &[(usize, f64)], out: &mut [f64]| {
            xs.clear();
            xs.extend(tx.iter().map(|&(_, x)| x));
            f(&xs, out)
        },
        &[(points.to_vec(), accuracy)],
    )[0]
}

struct Piece {
    lo: f64,
    hi: f64,
    value: f64,
    error: f64,
    refined: bool,
    /// The rules behind the estimate: the first (cheap) whole-piece rule of an unrefined piece,
    /// the two half-piece rules of a refined one. A refinement's whole-piece rule resumes the
    /// rule already run on that piece ([`State::resume`]) instead of evaluating its levels
    /// again: bit for bit the rule run afresh when the new target is no looser than the old
    /// (a first rule's is infinite); otherwise (a half's target, re-derived from the running
    /// total when it is bisected, can grow a little) the same rule stopped at a level no
    /// coarser than afresh.
    rules: Vec<State>,
}

/// What one piecewise integral asks for next.
enum Step {
    /// The first (cheap) estimate of every piece.
    First(Vec<(f64, f64)>),
    /// Refined estimates of these parts `(lo, hi, share of the target, the rule already run on
    /// [lo, hi])`: three rules each.
    Refine(Vec<(f64, f64, f64, Option<State>)>),
    /// Finished.
    Done(Estimate),
}

/// The adaptive loop of [`integrate_pieces`] as a state machine, so that many integrals advance
/// in lockstep ([`integrate_pieces_many`]).
struct Pieces {
    pieces: Vec<Piece>,
    span: f64,
    accuracy: Accuracy,
    evaluations: u64,
    step: Step,
}

impl Pieces {
    fn new(points: &[f64], accuracy: Accuracy) -> Self {
        Self {
            pieces: Vec::new(),
            span: points.windows(2).map(|w| (w[1] - w[0]).abs()).sum(),
            accuracy,
            evaluations: 0,
            step: Step::First(
                points
                    .windows(2)
                    .filter(|w| w[1] > w[0])
                    .map(|w| (w[0], w[1]))
                    .collect(),
            ),
        }
    }

    /// The double-exponential rules the current step needs, tagged `tag`: a target is never
    /// below 1e-300 (a zero target would run every rule to its deepest level).
    fn rules(&self, tag: usize, out: &mut Vec<(usize, State)>) {
        let rule = |lo: f64, hi: f64, t: f64| (tag, State::new(lo, hi, t.max(1e-300)));
        match &self.step {
            Step::First(parts) => {
                out.extend(parts.iter().map(|&(lo, hi)| rule(lo, hi, f64::INFINITY)))
            }
            Step::Refine(parts) => {
                for (lo, hi, tol, done) in parts {
                    let (lo, hi, tol) = (*lo, *hi, *tol);
                    let mid = 0.5 * (lo + hi);
                    // The rule already run on [lo, hi], continued (`Piece::rules`).
                    let whole = match done {
                        Some(state) => (tag, state.clone().resume(tol.max(1e-300))),
                        None => rule(lo, hi, tol),
                    };
                    out.extend([whole, rule(lo, mid, 0.5 * tol), rule(mid, hi, 0.5 * tol)]);
                }
            }
            Step::Done(_) => {}
        }
    }

    /// Takes the finished rules (in the order of `rules`) and decides the next step.
    fn advance(&mut self, rules: &[(usize, State)]) {
        let o: Vec<quadrature::Output> = rules.iter().map(|(_, s)| s.output()).collect();
        for o in &o {
            self.evaluations += u64::from(o.num_function_evaluations);
        }
        match &self.step {
            Step::First(parts) => self.pieces.extend(parts.iter().zip(&o).zip(rules).map(
                |((&(lo, hi), o), rule)| Piece {
                    lo,
                    hi,
                    value: o.integral,
                    error: o.error_estimate,
                    refined: false,
                    rules: vec![rule.1.clone()],
                },
            )),
            // A refined estimate is the sum over the two halves, and its error the larger of
            // their double-exponential estimates and the disagreement with the whole-piece
            // rule: the crate's own estimate can stop at a level where two successive levels
            // agree by accident (seen: a GGX Λ tail piece off by 2e-9 relative, reported as
            // 1e-17).
            Step::Refine(parts) => {
                self.pieces
                    .extend(parts.iter().zip(o.chunks(3)).zip(rules.chunks(3)).map(
                        |((&(lo, hi, ..), o), rules)| {
                            let (whole, left, right) = (o[0], o[1], o[2]);
                            let value = left.integral + right.integral;
                            Piece {
                                lo,
                                hi,
                                value,
                                error: (left.error_estimate + right.error_estimate)
                                    .max((whole.integral - value).abs()),
                                refined: true,
                                rules: vec![rules[1].1.clone(), rules[2].1.clone()],
                            }
                        },
                    ))
            }
            Step::Done(_) => return,
        }
        self.step = self.decide();
    }

    fn decide(&mut self) -> Step {
        let pieces = &mut self.pieces;
        let value: f64 = pieces.iter().map(|p| p.value).sum();
        let error: f64 = pieces.iter().map(|p| p.error).sum();
        let magnitude: f64 = pieces
            .iter()
            .map(|p| p.value.abs() * node_noise(p.lo, p.hi))
            .sum();
        // Never ask for less than the round-off of the sum: past it, bisection only trades one
        // rounding error for another (and used to run to MAX_PIECES on every inner integral of
        // a nested cubature).
        let target = (self.accuracy.relative * value.abs())
            .max(self.accuracy.absolute)
            .max(ROUNDOFF * self.accuracy.noise * magnitude);
        let unrefined = pieces.iter().position(|p| !p.refined);
        if unrefined.is_none() && (!(error > target) || pieces.len() >= MAX_PIECES) {
            return Step::Done(Estimate {
                value,
                error_bound: error,
                evaluations: self.evaluations,
            });
        }
        let worst = unrefined.unwrap_or_else(|| {
            pieces
                .iter()
                .enumerate()
                .max_by(|x, y| x.1.error.total_cmp(&y.1.error))
                .map(|(i, _)| i)
                .unwrap_or(0)
        });
        let mut piece = pieces.swap_remove(worst);
        // A piece's share of the target, but not below its own round-off (a double-exponential
        // rule asked for less runs to its deepest level for nothing).
        let floor =
            ROUNDOFF * self.accuracy.noise * piece.value.abs() * node_noise(piece.lo, piece.hi);
        let span = self.span;
        let share = |lo: f64, hi: f64| {
            ((0.5 * target * (hi - lo) / span.max(f64::MIN_POSITIVE))
                .max(floor * (hi - lo) / (piece.hi - piece.lo)))
            .max(1e-300)
        };
        let mut rules = std::mem::take(&mut piece.rules).into_iter();
        Step::Refine(if !piece.refined {
            vec![(piece.lo, piece.hi, share(piece.lo, piece.hi), rules.next())]
        } else {
            let mid = 0.5 * (piece.lo + piece.hi);
            vec![
                (piece.lo, mid, share(piece.lo, mid), rules.next()),
                (mid, piece.hi, share(mid, piece.hi), rules.next()),
            ]
        })
    }
}

/// Several [`integrate_pieces`] at once, `problems[k] = (points, accuracy)` integrating f_k:
/// `f` receives `(k, x)` pairs and writes f_k(x). The integrals advance in lockstep — every
/// step of every adaptive loop, and every level of its double-exponential rules, is one call of
/// `f` for all of them — with each integral's arithmetic that of [`integrate_pieces`], so the
/// results are the same bit for bit. An external model (one round trip per call) pays a round
/// trip per step, not per node (nested integrals: the inner integrals of one outer step
/// together).
pub fn integrate_pieces_many(
    f: &mut TaggedBatchFn<'_>,
    problems: &[(Vec<f64>, Accuracy)],
) -> Vec<Estimate> {
    let mut states: Vec<Pieces> = problems.iter().map(|(p, a)| Pieces::new(p, *a)).collect();
    let (mut tagged, mut counts) = (Vec::new(), Vec::new());
    loop {
        crate::deadline::checkpoint();
        tagged.clear();
        counts.clear();
        let mut pending = false;
        for (k, s) in states.iter().enumerate() {
            if matches!(s.step, Step::Done(_)) {
                continue;
            }
            pending = true;
            let before = tagged.len();
            s.rules(k, &mut tagged);
            counts.push(tagged.len() - before);
        }
        if !pending {
            return states
                .iter()
                .map(|s| match s.step {
                    Step::Done(e) => e,
                    // Not reached: `pending` is false only when every state is done.
                    _ => Estimate {
                        value: f64::NAN,
                        ..Estimate::default()
                    },
                })
                .collect();
        }
        run_states(f, &mut tagged);
        let mut at = 0;
        for (s, n) in states
            .iter_mut()
            .filter(|s| !matches!(s.step, Step::Done(_)))
            .zip(counts.iter())
        {
            s.advance(&tagged[at..at + n]);
            at += n;
        }
    }
}

/// ∫_a^b f.
pub fn integrate(f: &dyn Fn(f64) -> f64, a: f64, b: f64, accuracy: Accuracy) -> Estimate {
    integrate_pieces(f, &[a, b], accuracy)
}

/// The exponent of the tail substitution t = a + scale·((1 − u)^{−M} − 1): algebraic tails down
/// to t^{−1 − 1/M} become bounded integrands.
const TAIL_POWER: f64 = 4.0;

/// ∫_a^∞ f, for an f that decays over a width `scale` past `a`: the substitution
/// t = a + scale·((1 − u)^{−4} − 1) with cuts at t − a = scale·{10⁻⁴ … 10⁸}, so that both a
/// narrow peak and a heavy algebraic tail are resolved.
///
/// One adaptive pass: its first step fixes the magnitude (`integrate_pieces`), and every target
/// is relative to the running total. (A rough pass to 1e-6 used to fix the magnitude first, for
/// an absolute floor of 5 % of the relative target: that floor never exceeds the relative target
/// once the running total is within 95 % of the integral, so it only loosened targets while a
/// first estimate was 20× too small, and cost ~40 % of every call.)
pub fn integrate_upper(f: &dyn Fn(f64) -> f64, a: f64, scale: f64, accuracy: Accuracy) -> Estimate {
    let m = TAIL_POWER;
    let g = |u: f64| {
        let one_minus = 1.0 - u;
        let stretch = one_minus.powf(-m);
        let t = a + scale * (stretch - 1.0);
        let v = f(t) * scale * m * stretch / one_minus;
        if t.is_finite() {
            v
        } else {
            0.0
        }
    };
    let mut cuts = vec![0.0];
    for v in [1e-4f64, 1e-2, 0.25, 1.0, 4.0, 16.0, 64.0, 1e3, 1e5, 1e8] {
        cuts.push(1.0 - (1.0 + v).powf(-1.0 / m));
    }
    cuts.push(1.0);
    integrate_pieces(&g, &cuts, accuracy)
}

/// ∫_{−∞}^{∞} f for an f centred near `center` with width `scale`.
pub fn integrate_line(
    f: &dyn Fn(f64) -> f64,
    center: f64,
    scale: f64,
    accuracy: Accuracy,
) -> Estimate {
    let right = integrate_upper(f, center, scale, accuracy);
    let left = integrate_upper(&|t| f(2.0 * center - t), center, scale, accuracy);
    Estimate {
        value: right.value + left.value,
        error_bound: right.error_bound + left.error_bound,
        evaluations: right.evaluations + left.evaluations,
    }
}

/// The direction at polar angle θ and azimuth φ about the frame (t, b, n), from (sin θ, cos θ)
/// and (sin φ, cos φ).
#[inline]
fn in_frame(frame: &[Vec3; 3], (st, ct): (f64, f64), (sp, cp): (f64, f64)) -> Vec3 {
    let [t, b, n] = frame;
    [
        st * cp * t[0] + st * sp * b[0] + ct * n[0],
        st * cp * t[1] + st * sp * b[1] + ct * n[1],
        st * cp * t[2] + st * sp * b[2] + ct * n[2],
    ]
}

/// An orthonormal frame (t, b, n) with n = `axis` (normalized).
pub fn frame_about(axis: Vec3) -> [Vec3; 3] {
    let len = (axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]).sqrt();
    let n = [axis[0] / len, axis[1] / len, axis[2] / len];
    // Duff et al. 2017, "Building an orthonormal basis, revisited".
    let sign = 1f64.copysign(n[2]);
    let a = -1.0 / (sign + n[2]);
    let b = n[0] * n[1] * a;
    let t = [1.0 + sign * n[0] * n[0] * a, sign * b, -sign * n[0]];
    let bb = [b, sign + n[1] * n[1] * a, -n[1]];
    [t, bb, n]
}

/// Where to cut the polar and azimuthal integrals of a spherical integral.
#[derive(Clone, Copy)]
pub struct Cuts<'a> {
    /// Polar cut points (radians, inside the polar range) for a given azimuth: kinks of the
    /// integrand such as the terminator of ⟨w·m⟩⁺.
    pub theta: &'a dyn Fn(f64) -> Vec<f64>,
    /// Azimuthal cut points (radians, inside [0, 2π]).
    pub phi: &'a [f64],
}

/// ∫ f(ω) dω over the directions within polar angle `theta_max` of `axis` (π/2: a hemisphere;
/// π: the sphere). `width` is the angular width of a peak of f at the axis (e.g. α for an NDF,
/// 1/√λ for an SG): the polar integral is cut at width·{10⁻³ … 10²} so that the peak is
/// resolved whatever its width; `cuts` adds the integrand's own kinks.
pub fn integrate_cap(
    f: &dyn Fn(Vec3) -> f64,
    axis: Vec3,
    theta_max: f64,
    width: f64,
    cuts: Option<Cuts<'_>>,
    accuracy: Accuracy,
) -> Estimate {
    integrate_cap_batch(
        &scalar_directions(f),
        axis,
        theta_max,
        width,
        cuts,
        accuracy,
    )
}

/// [`integrate_cap`] for a batch integrand (`f(m, out)` writes f(m[i]) into out[i]): the same
/// value bit for bit, with the nodes of each step in one call.
fn integrate_cap_batch(
    f: &dyn Fn(&[Vec3], &mut [f64]),
    axis: Vec3,
    theta_max: f64,
    width: f64,
    cuts: Option<Cuts<'_>>,
    accuracy: Accuracy,
) -> Estimate {
    let frame = frame_about(axis);
    let (polar_cuts, phi_points) = width_cuts(width, theta_max);
    cap_polar(
        CapIntegrand::Directions(&frame, f),
        theta_max,
        &polar_cuts,
        &phi_points,
        cuts,
        accuracy,
    )
}

/// A scalar integrand of directions as a batch one (a loop).
fn scalar_directions<'f>(f: &'f dyn Fn(Vec3) -> f64) -> impl Fn(&[Vec3], &mut [f64]) + 'f {
    move |m: &[Vec3], out: &mut [f64]| {
        for (o, &m) in out.iter_mut().zip(m) {
            *o = f(m);
        }
    }
}

/// The cuts of a cap quadrature for an integrand of angular width `width` about the axis: polar
/// cuts at width·{10⁻³ … 10²} below `theta_max` (from 0), and the four quadrant azimuths.
fn width_cuts(width: f64, theta_max: f64) -> (Vec<f64>, [f64; 5]) {
    let mut polar_cuts = vec![0.0];
    for k in [1e-3, 1e-2, 0.1, 0.3, 1.0, 3.0, 10.0, 30.0, 100.0] {
        let t = width * k;
        if t > 0.0 && t < theta_max {
            polar_cuts.push(t);
        }
    }
    let tau = std::f64::consts::TAU;
    (polar_cuts, [0.0, 0.25 * tau, 0.5 * tau, 0.75 * tau, tau])
}

/// A batch integrand over a cap: writes f(θ\[i\], φ\[i\]) into out\[i\] for each `[θ, φ]`.
pub type PolarBatchFn<'a> = dyn Fn(&[[f64; 2]], &mut [f64]) + 'a;

/// What a cap quadrature integrates.
#[derive(Clone, Copy)]
enum CapIntegrand<'a> {
    /// f(θ, φ) of the cap's polar angles, a batch of `[θ, φ]` at a time.
    Polar(&'a PolarBatchFn<'a>),
    /// f(m) of the direction m = sin θ cos φ t + sin θ sin φ b + cos θ n in the frame
    /// (t, b, n), a batch of directions at a time.
    Directions(&'a [Vec3; 3], &'a dyn Fn(&[Vec3], &mut [f64])),
}

/// ∫ over the cap within `theta_max` of the frame's axis, with the polar cuts `polar_cuts`
/// (from 0, without `theta_max`) and the azimuthal cuts `phi_cuts` (from 0 to 2π), plus the
/// integrand's own `cuts`: the one nested quadrature every cap and hemisphere integral here
/// goes through. The inner (polar) integrals of one step of the outer (azimuthal) rule run in
/// lockstep ([`integrate_pieces_many`]), so each call of `f` carries the nodes of all of them,
/// each integral with the arithmetic of one alone (so a scalar integrand looped over a batch
/// gives the same value bit for bit; the summed inner error bounds may differ in the last
/// bits: they are added in another order). The sines and
/// cosines of the polar nodes (the Jacobian sin θ, and the directions) are computed a step at
/// a time by the vectorized [`sin_cos_block`], those of an inner integral's azimuth once per
/// integral: the trigonometry of glibc's scalar `sincos` per node was a quarter of an audit.
fn cap_polar(
    f: CapIntegrand<'_>,
    theta_max: f64,
    polar_cuts: &[f64],
    phi_cuts: &[f64],
    cuts: Option<Cuts<'_>>,
    accuracy: Accuracy,
) -> Estimate {
    let evaluations = Cell::new(0u64);
    let inner_error = Cell::new(0.0f64);
    // The inner integrals are asked for a little more than the outer one, but not below
    // round-off (the double-exponential error estimate cannot certify less than ~1e-15).
    let inner_accuracy = Accuracy {
        relative: (0.2 * accuracy.relative).max(2e-15),
        absolute: 0.05 * accuracy.absolute / std::f64::consts::TAU,
        noise: accuracy.noise,
    };
    // The outer integrand is the inner integrals, each rounded at its own floor: above f64,
    // the outer rule's floor is twice the integrand's (the inner estimates' noise, ≤ 32 noise
    // each, averages over the outer nodes to about the floor itself).
    let accuracy = if accuracy.noise > f64::EPSILON {
        Accuracy {
            noise: 2.0 * accuracy.noise,
            ..accuracy
        }
    } else {
        accuracy
    };
    let points_at = |phi: f64| {
        let mut points = polar_cuts.to_vec();
        if let Some(c) = cuts {
            points.extend(
                (c.theta)(phi)
                    .into_iter()
                    .filter(|t| *t > 0.0 && *t < theta_max),
            );
        }
        points.push(theta_max);
        points.sort_by(f64::total_cmp);
        points.dedup();
        points
    };
    let calls = Cell::new(0u64);
    let over_budget = Cell::new(false);
    let inner =
        |phis: &[f64], out: &mut [f64]| {
            if evaluations.get() >= EVALUATION_BUDGET {
                over_budget.set(true);
                out.fill(0.0);
                return;
            }
            calls.set(calls.get() + phis.len() as u64);
            let problems: Vec<(Vec<f64>, Accuracy)> = phis
                .iter()
                .map(|&phi| (points_at(phi), inner_accuracy))
                .collect();
            let azimuths: Vec<(f64, f64)> = phis.iter().map(|&phi| sin_cos(phi)).collect();
            let (mut tp, mut dirs) = (Vec::new(), Vec::new());
            let (mut thetas, mut st, mut ct) = (Vec::new(), Vec::new(), Vec::new());
            let estimates =
                integrate_pieces_many(
                    &mut |tx: &[(usize, f64)], values: &mut [f64]| {
                        thetas.clear();
                        thetas.extend(tx.iter().map(|&(_, theta)| theta));
                        st.resize(tx.len(), 0.0);
                        ct.resize(tx.len(), 0.0);
                        sin_cos_block(&thetas, &mut st, &mut ct);
                        match f {
                            CapIntegrand::Polar(f) => {
                                tp.clear();
                                tp.extend(tx.iter().map(|&(k, theta)| [theta, phis[k]]));
                                f(&tp, values);
                            }
                            CapIntegrand::Directions(frame, f) => {
                                dirs.clear();
                                dirs.extend(tx.iter().zip(&st).zip(&ct).map(
                                    |((&(k, _), &s), &c)| in_frame(frame, (s, c), azimuths[k]),
                                ));
                                f(&dirs, values);
                            }
                        }
                        for (v, &s) in values.iter_mut().zip(&st) {
                            *v = if *v == 0.0 { 0.0 } else { *v * s };
                        }
                    },
                    &problems,
                );
            for (o, e) in out.iter_mut().zip(estimates) {
                evaluations.set(evaluations.get() + e.evaluations);
                inner_error.set(inner_error.get() + e.error_bound.abs());
                *o = e.value;
            }
        };
    let tau = std::f64::consts::TAU;
    let mut phi_points: Vec<f64> = phi_cuts.to_vec();
    if let Some(c) = cuts {
        phi_points.extend(c.phi.iter().copied().filter(|p| *p > 0.0 && *p < tau));
    }
    phi_points.sort_by(f64::total_cmp);
    phi_points.dedup();
    let outer = integrate_pieces_batch(&inner, &phi_points, accuracy);
    // The outer estimate's error bound covers its own rule; each inner error enters the outer
    // sum with a weight of at most the largest outer weight, bounded here by the mean inner
    // error times the azimuthal range.
    if over_budget.get() {
        return exhausted(evaluations.get());
    }
    let mean_inner = inner_error.get() / (calls.get().max(1) as f64);
    Estimate {
        value: outer.value,
        error_bound: outer.error_bound + mean_inner * tau,
        evaluations: evaluations.get(),
    }
}

/// ∫ f(m) dm over the upper hemisphere (n = +z), cut where the measured `lobe` varies (its
/// polar and azimuthal cuts, [`Lobe::polar_cuts`], [`Lobe::azimuth_cuts`]: its every scale, its
/// anisotropy and an off-axis mode, so that its peak is resolved however narrow):
/// normalization and furnace integrals of a lobe of any width.
pub fn integrate_hemisphere_lobe(
    f: &dyn Fn(Vec3) -> f64,
    lobe: &Lobe,
    cuts: Option<Cuts<'_>>,
    accuracy: Accuracy,
) -> Estimate {
    integrate_hemisphere_lobe_batch(&scalar_directions(f), lobe, cuts, accuracy)
}

/// [`integrate_hemisphere_lobe`] for a batch integrand (`f(m, out)` writes f(m\[i\]) into
/// out\[i\]): the same value bit for bit, with the nodes of each step in one call.
pub fn integrate_hemisphere_lobe_batch(
    f: &dyn Fn(&[Vec3], &mut [f64]),
    lobe: &Lobe,
    cuts: Option<Cuts<'_>>,
    accuracy: Accuracy,
) -> Estimate {
    let polar = lobe.polar_cuts(std::f64::consts::FRAC_PI_2);
    cap_polar(
        CapIntegrand::Directions(&IDENTITY, f),
        std::f64::consts::FRAC_PI_2,
        &polar[..polar.len() - 1],
        &lobe.azimuth_cuts(),
        cuts,
        accuracy,
    )
}

/// [`integrate_hemisphere`] for a batch integrand (`f(m, out)` writes f(m\[i\]) into out\[i\]):
/// the same value bit for bit, with the nodes of each step in one call.
pub fn integrate_hemisphere_batch(
    f: &dyn Fn(&[Vec3], &mut [f64]),
    width: f64,
    cuts: Option<Cuts<'_>>,
    accuracy: Accuracy,
) -> Estimate {
    integrate_cap_batch(
        f,
        [0.0, 0.0, 1.0],
        std::f64::consts::FRAC_PI_2,
        width,
        cuts,
        accuracy,
    )
}

/// ∫ over the upper hemisphere of an integrand given in the polar angles (θ, φ) about +z (φ
/// from +x), a batch of `[θ, φ]` pairs a call, cut as [`integrate_hemisphere`] cuts: for
/// integrands better computed from the angles than from the direction (e.g. w·m near its
/// zero, as R sin(θ_t − θ) without the cancellation of a Cartesian dot product).
pub fn integrate_hemisphere_polar_batch(
    f: &PolarBatchFn<'_>,
    width: f64,
    cuts: Option<Cuts<'_>>,
    accuracy: Accuracy,
) -> Estimate {
    let theta_max = std::f64::consts::FRAC_PI_2;
    let (polar_cuts, phi_points) = width_cuts(width, theta_max);
    cap_polar(
        CapIntegrand::Polar(f),
        theta_max,
        &polar_cuts,
        &phi_points,
        cuts,
        accuracy,
    )
}

/// The frame about +z.
const IDENTITY: [Vec3; 3] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

/// ∫ f(m) dm over the upper hemisphere (n = +z), for an f peaked at the normal with width `width`.
pub fn integrate_hemisphere(
    f: &dyn Fn(Vec3) -> f64,
    width: f64,
    cuts: Option<Cuts<'_>>,
    accuracy: Accuracy,
) -> Estimate {
    // frame_about(+z) is the identity frame, so φ is measured from +x as the model boundary
    // defines it.
    integrate_cap(
        f,
        [0.0, 0.0, 1.0],
        std::f64::consts::FRAC_PI_2,
        width,
        cuts,
        accuracy,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn line_and_tail_integrals_with_error_bounds() {
        // ∫_0^∞ e^{−t} = 1; ∫ 1/(1+t²) over ℝ = π; a heavy tail ∫_1^∞ t^{−1.3} = 1/0.3.
        let e = integrate_upper(&|t| (-t).exp(), 0.0, 1.0, Accuracy::relative(1e-13));
        assert!((e.value - 1.0).abs() < 1e-13, "{e:?}");
        assert!(e.error_bound < 1e-12 && e.evaluations > 0);
        let e = integrate_line(
            &|t| 1.0 / (1.0 + t * t),
            0.0,
            1.0,
            Accuracy::relative(1e-12),
        );
        assert!((e.value - std::f64::consts::PI).abs() < 1e-11, "{e:?}");
        let e = integrate_upper(&|t| t.powf(-1.3), 1.0, 1.0, Accuracy::relative(1e-10));
        assert!((e.value - 1.0 / 0.3).abs() < 1e-8 * 3.4, "{e:?}");
        // An end-point singularity: ∫_0^1 t^{−½} = 2. The crate's tanh–sinh rule stops ~1e-23
        // short of the end point, so a t^{−½} singularity loses 2√1e-23 ≈ 1e-11 that its error
        // estimate does not see: substitute (as `integrate_upper` does) where it matters.
        let e = integrate(
            &|t: f64| 1.0 / t.sqrt(),
            0.0,
            1.0,
            Accuracy::relative(1e-12),
        );
        assert!((e.value - 2.0).abs() < 3e-11, "{e:?}");
        let e = integrate(&|s: f64| 2.0 * s / s, 0.0, 1.0, Accuracy::relative(1e-12));
        assert!((e.value - 2.0).abs() < 1e-13, "{e:?}");
    }

    #[test]
    fn hemisphere_and_sphere_integrals() {
        // ∫ cos θ over the hemisphere = π; a narrow lobe exp(−tan²θ/α²)/(πα²cos⁴θ)·cos θ = 1.
        let e = integrate_hemisphere(&|m| m[2], 1.0, None, Accuracy::relative(1e-12));
        assert!((e.value - std::f64::consts::PI).abs() < 1e-11, "{e:?}");
        let alpha: f64 = 1e-3;
        let beckmann = |m: Vec3| {
            // tan²θ from the components: 1 − cos²θ would cancel near the pole.
            let c2 = m[2] * m[2];
            let t2 = (m[0] * m[0] + m[1] * m[1]) / c2;
            (-t2 / (alpha * alpha)).exp() / (std::f64::consts::PI * alpha * alpha * c2 * c2) * m[2]
        };
        let e = integrate_hemisphere(&beckmann, alpha, None, Accuracy::relative(1e-11));
        assert!((e.value - 1.0).abs() < 1e-10, "{e:?}");
        // An SG of sharpness 1e4 about a tilted axis: ∫ = 2π(1 − e^{−2λ})/λ.
        let axis = [0.6, 0.0, 0.8];
        let lambda = 1e4;
        let sg =
            |v: Vec3| (lambda * (v[0] * axis[0] + v[1] * axis[1] + v[2] * axis[2] - 1.0)).exp();
        let e = integrate_cap(
            &sg,
            axis,
            std::f64::consts::PI,
            lambda.powf(-0.5),
            None,
            Accuracy::relative(1e-12),
        );
        let exact = std::f64::consts::TAU * (-(-2.0 * lambda).exp_m1()) / lambda;
        assert!(((e.value - exact) / exact).abs() < 1e-11, "{e:?}");
    }

    #[test]
    fn kinks_on_cut_points() {
        // ∫ ⟨w·m⟩⁺ over the hemisphere for w at θ = 1.2: the projected area (1 + Λ) cos θ of a
        // flat plane's hemisphere of normals = ∫ max(0, w·m) dm = π(1 + cos θ)/2 … checked by
        // the cut and uncut integrals agreeing, the cut one with far fewer evaluations.
        let w = mfh_reference::geometry::from_spherical(1.2, 0.0);
        let f = |m: Vec3| (w[0] * m[0] + w[1] * m[1] + w[2] * m[2]).max(0.0);
        let theta_cut = |phi: f64| {
            let c = phi.cos();
            if c < 0.0 {
                vec![(w[2] / (-c * w[0])).atan()]
            } else {
                vec![]
            }
        };
        let pi = std::f64::consts::PI;
        let phi_cuts = [0.5 * pi, 1.5 * pi];
        let cut = integrate_hemisphere(
            &f,
            1.0,
            Some(Cuts {
                theta: &theta_cut,
                phi: &phi_cuts,
            }),
            Accuracy::relative(1e-12),
        );
        let plain = integrate_hemisphere(&f, 1.0, None, Accuracy::relative(1e-12));
        assert!((cut.value - plain.value).abs() < 1e-9, "{cut:?} {plain:?}");
        assert!(cut.evaluations < plain.evaluations);
        // The closed value: ∫_H max(0, w·m) dm = π (1 + cos θ) / 2.
        let exact = pi * (1.0 + 1.2f64.cos()) / 2.0;
        assert!((cut.value - exact).abs() < 1e-11, "{cut:?} {exact}");
    }
}
#[cfg(test)]
mod regression {
    use super::*;

    /// A GGX (α = 0.1) Λ tail at θ = 0.5: the adaptive loop once accepted a piece 2e-9 off
    /// with a reported error of 1e-17 (7e-10 on the whole integral).
    #[test]
    fn an_early_double_exponential_stop_is_caught() {
        let (ax, mu) = (0.1f64, 1.0 / 0.5f64.tan());
        let p2 = |q: f64| ax * ax / (2.0 * (ax * ax + q * q).powf(1.5));
        let x = ax * ax / (mu * mu);
        let want = x / (1.0 + (1.0 + x).sqrt()) / 2.0;
        for scale in [0.01, 0.1, 1.0, 10.0] {
            let e = integrate_upper(&|q| (q - mu) * p2(q), mu, scale, Accuracy::relative(1e-12));
            let err = ((e.value / mu - want) / want).abs();
            assert!(err < 1e-12, "scale {scale}: {err:e} {e:?}");
        }
    }
}
