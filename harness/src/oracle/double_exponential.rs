//! The double-exponential (tanh–sinh) rule of the `quadrature` crate (0.1.2, BSD-2-Clause, a
//! port of John D. Cook's "Fast Numerical Integration"), re-implemented so that each level's
//! nodes are evaluated in one batch, and several integrals advance in lockstep.
//!
//! Why a copy rather than the crate: the crate calls the integrand one node at a time, and an
//! external model (a child process, `crate::external`) pays one round trip per call. This
//! version performs the crate's arithmetic operation for operation (same nodes, same weights,
//! same summation order, same stopping rule), so its results are bit-identical to
//! `quadrature::double_exponential::integrate` (the test below compares them on many
//! integrands and tolerances); only the grouping of the evaluations differs.

/// A batch integrand: writes f(x\[i\]) into out\[i\] for every i.
pub type BatchFn<'a> = dyn Fn(&[f64], &mut [f64]) + 'a;

/// The levels of the rule: (weight, abscissa) pairs on [−1, 1], positive abscissas only; each
/// level halves the step of the trapezoid rule in t (copied from the crate's `constants.rs`,
/// values computed with Mathematica by the crate's author).
#[allow(clippy::excessive_precision, clippy::unreadable_literal)]
const WEIGHTS: [&[(f64, f64)]; 7] = include!("double_exponential_weights.in");

/// One integral in progress.
#[derive(Debug, Clone)]
pub(super) struct State {
    c: f64,
    d: f64,
    target: f64,
    level: usize,
    integral: f64,
    current_delta: f64,
    error_estimate: f64,
    evaluations: u32,
    /// Evaluations reported before a [`State::resume`] (not counted again).
    counted: u32,
    done: bool,
}

impl State {
    pub(super) fn new(a: f64, b: f64, target_absolute_error: f64) -> Self {
        let c = 0.5 * (b - a);
        Self {
            c,
            d: 0.5 * (a + b),
            target: 0.25 * target_absolute_error / c,
            level: 0,
            integral: 0.0,
            current_delta: f64::MAX,
            error_estimate: f64::MAX,
            evaluations: 1,
            counted: 0,
            done: false,
        }
    }

    /// The rule continued to a new target: a finished rule resumes where it stopped, re-judging
    /// its last level against `target_absolute_error`. The stopping test is the only place the
    /// target enters, and a rule stops at the first level that passes it, so a rule run to a
    /// looser target and resumed takes the same levels, nodes and sums as one run to the new
    /// target from the start: the same output bit for bit, without evaluating the first levels
    /// twice (the test below compares them). Only the evaluations are counted once.
    pub(super) fn resume(mut self, target_absolute_error: f64) -> Self {
        self.counted = self.evaluations;
        self.target = 0.25 * target_absolute_error / self.c;
        if self.done {
            // The stopping test of `advance` at the level where the rule stopped (that level was
            // past the first 13 evaluations: `advance` never stops before).
            self.done = self.level == WEIGHTS.len()
                || self.current_delta == 0.0
                || self.error_estimate < self.target;
        }
        self
    }

    /// The points of the next step: f(0) with the first two levels (always evaluated: the
    /// stopping rule needs three levels), then one level per step.
    fn push_nodes(&self, xs: &mut Vec<f64>) {
        let map = |x: f64| self.c * x + self.d;
        let levels = if self.level == 0 {
            xs.push(map(0.0));
            0..2
        } else {
            self.level..self.level + 1
        };
        for level in levels {
            for &(_, x) in WEIGHTS[level] {
                xs.push(map(x));
                xs.push(map(-x));
            }
        }
    }

    /// Consumes the values of `push_nodes`' points, in order.
    fn advance(&mut self, values: &[f64]) {
        let g = |v: f64| if v.is_finite() { v } else { 0.0 };
        let mut values = values.iter().map(|&v| g(v));
        let levels = if self.level == 0 {
            self.integral = 2.0 * std::f64::consts::FRAC_PI_2 * values.next().unwrap_or(0.0);
            0..2
        } else {
            self.level..self.level + 1
        };
        for level in levels {
            let weight = WEIGHTS[level];
            let new_contribution = weight
                .iter()
                .map(|&(w, _)| {
                    let plus = values.next().unwrap_or(0.0);
                    let minus = values.next().unwrap_or(0.0);
                    w * (plus + minus)
                })
                .fold(0.0, |sum, x| sum + x);
            self.evaluations += 2 * weight.len() as u32;
            let previous_delta_ln = self.current_delta.ln();
            self.current_delta = (0.5 * self.integral - new_contribution).abs();
            self.integral = 0.5 * self.integral + new_contribution;
            self.level = level + 1;
            if self.evaluations <= 13 {
                continue;
            }
            if self.current_delta == 0.0 {
                self.error_estimate = 0.0;
                self.done = true;
                return;
            }
            let r = self.current_delta.ln() / previous_delta_ln;
            self.error_estimate = if r > 1.9 && r < 2.1 {
                self.current_delta * self.current_delta
            } else {
                self.current_delta
            };
            if self.error_estimate < self.target {
                self.done = true;
                return;
            }
        }
        if self.level == WEIGHTS.len() {
            self.done = true;
        }
    }

    pub(super) fn output(&self) -> quadrature::Output {
        quadrature::Output {
            num_function_evaluations: self.evaluations - self.counted,
            error_estimate: self.c * self.error_estimate,
            integral: self.c * self.integral,
        }
    }
}

/// ∫ f over each interval `(a, b)` to its absolute target, all advancing in lockstep: each step
/// evaluates the next level of every unfinished integral in one call of `f`. The outputs equal
/// `quadrature::double_exponential::integrate(f, a, b, target)` bit for bit, interval by
/// interval.
pub fn integrate_many(f: &BatchFn<'_>, intervals: &[(f64, f64, f64)]) -> Vec<quadrature::Output> {
    let tagged: Vec<_> = intervals.iter().map(|&(a, b, t)| (0, a, b, t)).collect();
    let mut xs = Vec::new();
    integrate_many_tagged(
        &mut |tx: &[(usize, f64)], out: &mut [f64]| {
            xs_of(tx, &mut xs);
            f(&xs, out)
        },
        &tagged,
    )
}

fn xs_of(tx: &[(usize, f64)], xs: &mut Vec<f64>) {
    xs.clear();
    xs.extend(tx.iter().map(|&(_, x)| x));
}

/// A batch integrand of several integrals at once: `f(points, out)` writes f_tag(x) into out\[i\]
/// for each `(tag, x)` of `points`.
pub type TaggedBatchFn<'a> = dyn FnMut(&[(usize, f64)], &mut [f64]) + 'a;

/// [`integrate_many`] for intervals of different integrands: each interval `(tag, a, b,
/// target)` integrates f_tag, and `f` receives `(tag, x)` pairs.
pub fn integrate_many_tagged(
    f: &mut TaggedBatchFn<'_>,
    intervals: &[(usize, f64, f64, f64)],
) -> Vec<quadrature::Output> {
    let mut states: Vec<(usize, State)> = intervals
        .iter()
        .map(|&(tag, a, b, t)| (tag, State::new(a, b, t)))
        .collect();
    run_states(f, &mut states);
    states.iter().map(|(_, s)| s.output()).collect()
}

/// Runs every `(tag, state)` to its end in lockstep (the loop of [`integrate_many_tagged`]),
/// states built by [`State::new`] or resumed by [`State::resume`].
pub(super) fn run_states(f: &mut TaggedBatchFn<'_>, states: &mut [(usize, State)]) {
    let (mut xs, mut points, mut values, mut counts) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    loop {
        crate::deadline::checkpoint();
        points.clear();
        counts.clear();
        for (tag, s) in states.iter().filter(|s| !s.1.done) {
            xs.clear();
            s.push_nodes(&mut xs);
            counts.push(xs.len());
            points.extend(xs.iter().map(|&x| (*tag, x)));
        }
        if points.is_empty() {
            return;
        }
        values.clear();
        values.resize(points.len(), 0.0);
        f(&points, &mut values);
        let mut at = 0;
        for ((_, s), n) in states.iter_mut().filter(|s| !s.1.done).zip(counts.iter()) {
            s.advance(&values[at..at + n]);
            at += n;
        }
    }
}

/// ∫_a^b f to an absolute target: [`integrate_many`] for one interval.
pub fn integrate(
    f: &BatchFn<'_>,
    a: f64,
    b: f64,
    target_absolute_error: f64,
) -> quadrature::Output {
    integrate_many(f, &[(a, b, target_absolute_error)])[0]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Bit for bit the crate's results, on smooth, peaked, singular, kinked and discontinuous
    /// integrands, over many intervals and targets (so that every stopping branch is taken).
    #[test]
    fn bit_identical_to_the_quadrature_crate() {
        let integrands: [&dyn Fn(f64) -> f64; 7] = [
            &|x| x.exp(),
            &|x| 1.0 / (1e-4 + x * x),
            &|x| x.abs().sqrt().recip(),
            &|x| (x - 0.3).abs(),
            &|x| if x > 0.1 { 1.0 } else { 0.0 },
            &|x| (50.0 * x).sin() * x.cos(),
            &|_| 0.5,
        ];
        let mut compared = 0;
        for f in integrands {
            for (a, b) in [
                (-1.0, 1.0),
                (0.0, 1.0),
                (0.2, 3.5),
                (-2.0, -0.1),
                (1e-3, 2e-3),
            ] {
                for target in [1.0, 1e-3, 1e-8, 1e-13, 0.0, f64::INFINITY] {
                    let want = quadrature::double_exponential::integrate(f, a, b, target);
                    let scalar = |x: &[f64], out: &mut [f64]| {
                        for (o, &x) in out.iter_mut().zip(x) {
                            *o = f(x);
                        }
                    };
                    let got = integrate(&scalar, a, b, target);
                    assert_eq!(
                        got.integral.to_bits(),
                        want.integral.to_bits(),
                        "{a} {b} {target}"
                    );
                    assert_eq!(got.error_estimate.to_bits(), want.error_estimate.to_bits());
                    assert_eq!(got.num_function_evaluations, want.num_function_evaluations);
                    compared += 1;
                }
            }
        }
        // Several at once: each as if alone, and one call of f per level.
        let calls = std::cell::Cell::new(0);
        let f = |x: &[f64], out: &mut [f64]| {
            calls.set(calls.get() + 1);
            for (o, &x) in out.iter_mut().zip(x) {
                *o = 1.0 / (1e-2 + x * x);
            }
        };
        let intervals = [(-1.0, 1.0, 1e-12), (0.0, 2.0, 1e-3), (0.5, 0.6, 0.0)];
        let many = integrate_many(&f, &intervals);
        assert!(calls.get() <= 6, "{} calls", calls.get());
        for (&(a, b, t), got) in intervals.iter().zip(&many) {
            let want = quadrature::double_exponential::integrate(|x| 1.0 / (1e-2 + x * x), a, b, t);
            assert_eq!(got.integral.to_bits(), want.integral.to_bits());
        }
        assert_eq!(compared, 7 * 5 * 6);
    }

    /// A rule run to an infinite target and resumed to a finite one gives the output of the rule
    /// run to that target from the start, bit for bit, and counts only the new evaluations.
    #[test]
    fn a_resumed_rule_is_the_rule_run_to_its_new_target() {
        let integrands: [&dyn Fn(f64) -> f64; 6] = [
            &|x| x.exp(),
            &|x| 1.0 / (1e-4 + x * x),
            &|x| x.abs().sqrt().recip(),
            &|x| (x - 0.3).abs(),
            &|x| (50.0 * x).sin() * x.cos(),
            &|_| 0.5,
        ];
        for f in integrands {
            let mut scalar = |tx: &[(usize, f64)], out: &mut [f64]| {
                for (o, &(_, x)) in out.iter_mut().zip(tx) {
                    *o = f(x);
                }
            };
            for (a, b) in [(-1.0, 1.0), (0.2, 3.5), (1e-3, 2e-3)] {
                let mut first = [(0, State::new(a, b, f64::INFINITY))];
                run_states(&mut scalar, &mut first);
                for target in [1.0, 1e-3, 1e-8, 1e-13, 0.0] {
                    let want = quadrature::double_exponential::integrate(f, a, b, target);
                    let mut resumed = [(0, first[0].1.clone().resume(target))];
                    run_states(&mut scalar, &mut resumed);
                    let got = resumed[0].1.output();
                    assert_eq!(got.integral.to_bits(), want.integral.to_bits(), "{a} {b}");
                    assert_eq!(got.error_estimate.to_bits(), want.error_estimate.to_bits());
                    assert_eq!(
                        got.num_function_evaluations + first[0].1.output().num_function_evaluations,
                        want.num_function_evaluations
                    );
                }
            }
        }
    }
}
