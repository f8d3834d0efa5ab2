//! The deadline of the check a thread runs, and the checkpoints that stop the check once it has
//! passed (a leaf module: the oracles' loops call [`checkpoint`], the runner sets the deadline
//! through [`run_within`]; the budget itself and its record are `check/budget.rs`'s).
//!
//! A check's work that runs in parallel (rayon) reaches threads whose own deadline is another
//! check's or none: a parallel loop takes the deadline with [`current`] before it starts and
//! checks it in each chunk with [`check`], so that every thread working for the check stops
//! with it.

use std::cell::Cell;
use std::time::{Duration, Instant};

/// The payload a [`checkpoint`] unwinds with: the deadline that passed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BudgetExceeded {
    /// The deadline of the check whose budget ran out.
    pub deadline: Instant,
}

thread_local! {
    /// The deadline of the check this thread runs, if any.
    static DEADLINE: Cell<Option<Instant>> = const { Cell::new(None) };
}

/// Unwinds the running check if its deadline has passed (see the module doc); a no-op outside
/// a budgeted check. Call it holding no lock.
pub fn checkpoint() {
    if passed() {
        stop();
    }
}

/// Whether the running check's deadline has passed (a caller holding a lock releases it, then
/// calls [`stop`]).
pub fn passed() -> bool {
    DEADLINE
        .with(Cell::get)
        .is_some_and(|deadline| Instant::now() >= deadline)
}

/// Unwinds the running check, whose deadline has [`passed`].
pub fn stop() -> ! {
    let deadline = DEADLINE.with(Cell::get).unwrap_or_else(Instant::now);
    std::panic::resume_unwind(Box::new(BudgetExceeded { deadline }))
}

/// How a budgeted run ended.
#[derive(Debug)]
pub enum Outcome<R> {
    /// The check returned (within its budget or not: the caller compares its time).
    Done(R),
    /// It panicked (not at a checkpoint of its own deadline): the payload.
    Panicked(Box<dyn std::any::Any + Send>),
    /// A checkpoint stopped it once its own deadline had passed.
    OverBudget,
}

/// Runs `f` with the deadline `start + budget` set for this thread, catching its panics; a
/// run unwound by another check's deadline (its work lent to a thread running that check) is
/// run again, at most `RETRIES` times.
pub fn run_within<R>(budget: Option<Duration>, start: Instant, f: impl Fn() -> R) -> Outcome<R> {
    const RETRIES: usize = 8;
    let deadline = budget.and_then(|b| start.checked_add(b));
    let previous = DEADLINE.with(|d| d.replace(deadline));
    let mut outcome = Outcome::OverBudget;
    for _ in 0..=RETRIES {
        outcome = match std::panic::catch_unwind(std::panic::AssertUnwindSafe(&f)) {
            Ok(r) => Outcome::Done(r),
            Err(payload) => match payload.downcast_ref::<BudgetExceeded>() {
                Some(b) if Some(b.deadline) == deadline => Outcome::OverBudget,
                Some(_) => continue,
                None => Outcome::Panicked(payload),
            },
        };
        break;
    }
    DEADLINE.with(|d| d.set(previous));
    outcome
}

/// The deadline of the check this thread runs, for a parallel loop to carry to its workers
/// ([`check`]).
pub fn current() -> Option<Instant> {
    DEADLINE.with(Cell::get)
}

/// Unwinds the check whose deadline is `deadline` (taken with [`current`] on the check's
/// thread) once it has passed: the checkpoint of a parallel loop's chunk, on whatever thread
/// runs it.
pub fn check(deadline: Option<Instant>) {
    if let Some(deadline) = deadline {
        if Instant::now() >= deadline {
            std::panic::resume_unwind(Box::new(BudgetExceeded { deadline }))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_checkpoint_past_the_deadline_stops_the_run_and_a_foreign_one_is_run_again() {
        let start = Instant::now();
        // Within the budget: the result, untouched.
        let r = run_within(Some(Duration::from_secs(3600)), start, || {
            checkpoint();
            7
        });
        assert!(matches!(r, Outcome::Done(7)));
        // Past it: stopped at the checkpoint.
        let ran = std::sync::atomic::AtomicUsize::new(0);
        let r = run_within(Some(Duration::ZERO), start, || {
            ran.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
            checkpoint();
            unreachable!("stopped at the checkpoint")
        });
        assert!(matches!(r, Outcome::OverBudget));
        assert_eq!(ran.into_inner(), 1);
        // Unwound by another check's deadline: run again, and its own result kept.
        let tries = std::sync::atomic::AtomicUsize::new(0);
        let r = run_within(Some(Duration::from_secs(3600)), start, || {
            if tries.fetch_add(1, std::sync::atomic::Ordering::Relaxed) == 0 {
                std::panic::resume_unwind(Box::new(BudgetExceeded {
                    deadline: start - Duration::from_secs(1),
                }));
            }
            5
        });
        assert!(matches!(r, Outcome::Done(5)));
        assert_eq!(tries.into_inner(), 2);
        // Other panics are the caller's, and the thread's deadline is restored.
        let r = run_within(None, start, || -> () { panic!("boom") });
        assert!(matches!(r, Outcome::Panicked(_)));
        assert_eq!(DEADLINE.with(Cell::get), None);
        checkpoint();
    }
}
