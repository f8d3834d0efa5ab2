//! Time per evaluation: the median of repeated batches, with the spread (fastest and slowest
//! batch). Hand-timed with `std::time::Instant` rather than criterion because `mfh cost` is a
//! command that must finish in a stated time on a user's machine and report into its own
//! JSON: criterion is a benchmark driver (its own CLI, output folder and warm-up policy) and
//! stays in `harness/benches/`. Timings are machine- and load-dependent: callers print them in
//! a section marked so, and never compare them in tests.

use serde::{Deserialize, Serialize};
use std::hint::black_box;
use std::time::{Duration, Instant};

/// How long to time each candidate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Budget {
    /// Batches timed (the median of their per-evaluation times is reported); at least 1.
    pub batches: usize,
    /// A batch repeats the sweep until it lasts at least this long (one sweep at least).
    pub batch_time: Duration,
}

impl Budget {
    /// `mfh cost --quick`: 5 batches of ≥ 2 ms.
    pub const QUICK: Budget = Budget {
        batches: 5,
        batch_time: Duration::from_millis(2),
    };
    /// The full run: 11 batches of ≥ 20 ms.
    pub const FULL: Budget = Budget {
        batches: 11,
        batch_time: Duration::from_millis(20),
    };
}

/// The measured time per evaluation (seconds).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Timing {
    /// The median over batches of (batch time / evaluations in the batch).
    pub median: f64,
    /// The fastest batch, per evaluation.
    pub min: f64,
    /// The slowest batch, per evaluation.
    pub max: f64,
    /// Batches timed.
    pub batches: usize,
    /// Evaluations per batch.
    pub evaluations_per_batch: u64,
}

/// Times `sweep`, which performs `evaluations` evaluations per call and returns a value that is
/// kept alive (`black_box`) so that the work is not optimized away. One untimed call warms the
/// caches; the number of sweeps per batch is set from it so that a batch lasts about
/// `budget.batch_time`.
pub fn time_per_evaluation(
    sweep: &mut dyn FnMut() -> f64,
    evaluations: u64,
    budget: Budget,
) -> Timing {
    let evaluations = evaluations.max(1);
    let start = Instant::now();
    black_box(sweep());
    let once = start.elapsed().max(Duration::from_nanos(1));
    let sweeps = (budget.batch_time.as_secs_f64() / once.as_secs_f64())
        .ceil()
        .clamp(1.0, 1e7) as u64;
    let mut per_eval: Vec<f64> = (0..budget.batches.max(1))
        .map(|_| {
            let start = Instant::now();
            for _ in 0..sweeps {
                black_box(sweep());
            }
            start.elapsed().as_secs_f64() / (sweeps * evaluations) as f64
        })
        .collect();
    per_eval.sort_by(f64::total_cmp);
    Timing {
        median: per_eval[per_eval.len() / 2],
        min: per_eval[0],
        max: per_eval[per_eval.len() - 1],
        batches: per_eval.len(),
        evaluations_per_batch: sweeps * evaluations,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_median_lies_within_the_spread_and_scales_with_the_work() {
        let budget = Budget {
            batches: 5,
            batch_time: Duration::from_micros(500),
        };
        let work = |n: u64| {
            move || {
                let mut s = 0.0f64;
                for i in 0..n {
                    s += black_box(i as f64).sqrt();
                }
                s
            }
        };
        let small = time_per_evaluation(&mut work(100), 1, budget);
        let large = time_per_evaluation(&mut work(100_000), 1, budget);
        for t in [small, large] {
            assert!(t.min <= t.median && t.median <= t.max, "{t:?}");
            assert!(t.median > 0.0 && t.batches == 5, "{t:?}");
        }
        // 1000× the work: at least 50× the time even on a loaded machine.
        assert!(large.median > 50.0 * small.median, "{small:?} {large:?}");
    }
}
