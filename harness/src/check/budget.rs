//! The wall-clock budget of one record: a check that runs past it ends as an `error` record
//! naming the budget — not a verdict on the model, which was not judged — instead of running
//! for minutes. The oracles' own budgets count evaluations, which a slow model (a child answering
//! through the protocol, an integrand the quadrature keeps refining) turns into minutes.
//!
//! How it is enforced: the runner (`run::run_plan`) runs each check under [`run_within`], which
//! sets the check's deadline for its thread; [`checkpoint`] — called where a check spends its
//! time on the model, before each request to an external child — unwinds the check once the
//! deadline has passed (with `resume_unwind`, so no panic message is printed, and before any
//! lock is taken, so nothing is poisoned). A check that ends past its budget without meeting a
//! checkpoint (an in-process model) is an error all the same, so what the record says depends
//! only on whether the check finished within its budget.
//!
//! Determinism: a record that finishes within its budget is the record of an unbudgeted run,
//! whatever the timing. A check's work can run on a thread that is itself running another check
//! (rayon lends blocked threads), where the checkpoint reads that other check's deadline; a
//! check unwound by a deadline not its own is run again ([`run_within`]), so another check's
//! budget never decides its record.

use crate::check::Profile;
use std::cell::Cell;
use std::time::{Duration, Instant};

/// The wall-clock budget of one record at `profile`: several times the longest a correct
/// model's record takes there through the protocol on a loaded 2-core machine (the pure-Python
/// dielectric's longest ci record took 26 s at load ≈ 12; thorough records draw 10⁸ samples).
pub fn record_budget(profile: Profile) -> Duration {
    Duration::from_secs(match profile {
        Profile::Ci => 120,
        Profile::Quick => 300,
        Profile::Standard => 900,
        Profile::Thorough => 3600,
    })
}

/// The message of the `error` record of a check that ran past its budget.
pub fn over_budget_message(budget: Duration, seconds: f64) -> String {
    format!(
        "{OVER_BUDGET}{} s ({seconds:.1} s; the profile's record budget, `--record-budget`): \
         no verdict on the model, whose record could not be finished in time",
        budget.as_secs_f64()
    )
}

/// Whether `verdict` is the error of a check that ran past its budget
/// ([`over_budget_message`]): such a record is not kept for `--resume`, which runs it again.
pub fn is_over_budget(verdict: &crate::record::Verdict) -> bool {
    matches!(verdict, crate::record::Verdict::Error { message } if message.starts_with(OVER_BUDGET))
}

/// How [`over_budget_message`] begins.
const OVER_BUDGET: &str = "not judged: the check ran past its wall-clock budget of ";

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
