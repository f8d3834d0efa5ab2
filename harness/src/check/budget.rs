//! The wall-clock budget of one record: a check that runs past it ends as an `error` record
//! naming the budget — not a verdict on the model, which was not judged — instead of running
//! for minutes. The oracles' own budgets count evaluations, which a slow model (a child answering
//! through the protocol, an integrand the quadrature keeps refining) turns into minutes.
//!
//! How it is enforced (`deadline.rs`, a leaf module that the oracles call too): the runner
//! (`run::run_plan`) runs each check under [`run_within`], which sets the check's deadline for
//! its thread; [`checkpoint`] — called where a check spends its time on the model: before each
//! request to an external child, at each step of the oracles' adaptive loops and in each chunk
//! of their parallel sample loops (which carry the deadline to the threads that run them) —
//! unwinds the check once the deadline has passed (with `resume_unwind`, so no panic message is printed, and before any
//! lock is taken, so nothing is poisoned). A check that ends past its budget without meeting a
//! checkpoint (an in-process model slow between two of them) is an error all the same, so what the record says depends
//! only on whether the check finished within its budget.
//!
//! Determinism: a record that finishes within its budget is the record of an unbudgeted run,
//! whatever the timing. A check's work can run on a thread that is itself running another check
//! (rayon lends blocked threads), where the checkpoint reads that other check's deadline; a
//! check unwound by a deadline not its own is run again ([`run_within`]), so another check's
//! budget never decides its record.

use crate::check::Profile;
pub use crate::deadline::{checkpoint, passed, run_within, stop, BudgetExceeded, Outcome};
use std::time::Duration;

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
