//! `MFH_TRACE`: with it set (to anything), the commands that run checks print each check's
//! start and end on standard error — `start CHECK MODEL CASE` and `done 0.123s VERDICT CHECK
//! MODEL CASE` — and `mfh cost` each quantity's time. The library prints nothing: it tells
//! [`crate::run::RunControl::on_check`] of each start and finish, and these lines are made from
//! those events here.
//!
//! The lines are written from the worker threads with `eprintln!` (standard error, unlocked
//! between lines): the callback must be `'static`, so it cannot hold the command's borrowed
//! `stderr`, and a line must not wait on a lock the main thread holds.

use crate::run::{CheckEvent, CheckEventFn};
use std::sync::Arc;

/// Whether `MFH_TRACE` is set.
pub fn enabled() -> bool {
    std::env::var_os("MFH_TRACE").is_some()
}

/// Prints the trace line of a check's start or finish (nothing for the plan event).
pub fn print(event: &CheckEvent<'_>) {
    match event {
        CheckEvent::Plan { .. } => {}
        CheckEvent::Started { planned: p, .. } => {
            eprintln!("start {} {} {}", p.check, p.model, p.case);
        }
        CheckEvent::Finished {
            planned: p, record, ..
        } => {
            eprintln!(
                "done {:.3}s {} {} {} {}",
                record.cost.wall_seconds,
                record.verdict.name(),
                p.check,
                p.model,
                p.case
            );
        }
    }
}

/// A check-event callback that prints the trace lines, if `MFH_TRACE` is set (None otherwise):
/// for runs whose events nothing else listens to (`mfh selftest`).
pub fn events() -> Option<CheckEventFn> {
    enabled().then(|| CheckEventFn(Arc::new(|event: CheckEvent<'_>| print(&event))))
}
