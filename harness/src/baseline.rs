//! `--baseline old/report.json`: what got worse against a saved run. Records are matched by
//! (check, model, case); a record regresses when
//! - it failed (fail or error) where the baseline's passed or failed as expected;
//! - its measured error grew by more than [`ERROR_GROWTH`]: new > factor · max(old,
//!   [`ERROR_FLOOR`]) (a NaN/∞ error where the baseline's was finite counts);
//! - its cost rose by more than [`COST_GROWTH`]: wall time new > factor · max(old,
//!   [`COST_FLOOR_SECONDS`]), or samples or oracle evaluations new > factor · old.
//!
//! Checks only in one of the two runs are counted, not regressions (the plan changed).

use crate::record::CheckRecord;
use crate::run::AuditReport;
use std::collections::BTreeMap;
use std::fmt::Write;

/// A measured error regresses when it grows by more than this factor: errors of the same code
/// on the same seed are identical, so ×2 is a change of formula or oracle, not noise.
pub const ERROR_GROWTH: f64 = 2.0;
/// Errors below this are rounding noise (a few ulps of 1) and never regress.
pub const ERROR_FLOOR: f64 = 1e-15;
/// A cost regresses when it rises by more than this factor: wall times on a shared machine
/// vary by up to ~2× between runs; ×3 is beyond that noise.
pub const COST_GROWTH: f64 = 3.0;
/// Wall times below this are timer and scheduling noise and never regress.
pub const COST_FLOOR_SECONDS: f64 = 0.05;

/// How one record got worse.
#[derive(Debug, Clone, PartialEq)]
pub enum Regression {
    /// It fails where the baseline did not.
    NowFailing {
        /// The baseline's verdict name.
        was: String,
        /// The new verdict name.
        now: String,
    },
    /// The measured error grew.
    ErrorGrew {
        /// The baseline's error.
        was: f64,
        /// The new error.
        now: f64,
    },
    /// The cost rose.
    CostRose {
        /// What (`wall_seconds`, `samples`, `evaluations`).
        what: &'static str,
        /// The baseline's.
        was: f64,
        /// The new.
        now: f64,
    },
}

/// The comparison of a run with its baseline.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Comparison {
    /// Records present in both.
    pub compared: usize,
    /// Records only in the new run.
    pub new_only: usize,
    /// Records only in the baseline.
    pub baseline_only: usize,
    /// Every regression: the record's `check model case` and how.
    pub regressions: Vec<(String, Regression)>,
}

fn key(r: &CheckRecord) -> String {
    format!("{} {} {}", r.check, r.model, r.case)
}

fn record_regressions(old: &CheckRecord, new: &CheckRecord) -> Vec<Regression> {
    let mut out = Vec::new();
    if new.verdict.is_failure() && !old.verdict.is_failure() {
        out.push(Regression::NowFailing {
            was: old.verdict.name().to_string(),
            now: new.verdict.name().to_string(),
        });
    }
    if let (Some(was), Some(now)) = (
        old.measured.and_then(|m| m.error()),
        new.measured.and_then(|m| m.error()),
    ) {
        let grew = if was.is_finite() {
            !now.is_finite() || now > ERROR_GROWTH * was.max(ERROR_FLOOR)
        } else {
            false
        };
        if grew {
            out.push(Regression::ErrorGrew { was, now });
        }
    }
    let (o, n) = (old.cost, new.cost);
    if n.wall_seconds > COST_GROWTH * o.wall_seconds.max(COST_FLOOR_SECONDS) {
        out.push(Regression::CostRose {
            what: "wall_seconds",
            was: o.wall_seconds,
            now: n.wall_seconds,
        });
    }
    for (what, was, now) in [
        ("samples", o.samples, n.samples),
        ("evaluations", o.evaluations, n.evaluations),
    ] {
        if now as f64 > COST_GROWTH * was as f64 && now > 0 {
            out.push(Regression::CostRose {
                what,
                was: was as f64,
                now: now as f64,
            });
        }
    }
    out
}

/// Compares a run with its baseline.
pub fn compare(baseline: &AuditReport, run: &AuditReport) -> Comparison {
    let old: BTreeMap<String, &CheckRecord> =
        baseline.records.iter().map(|r| (key(r), r)).collect();
    let mut c = Comparison::default();
    let mut matched = 0;
    for r in &run.records {
        let k = key(r);
        match old.get(&k) {
            Some(o) => {
                matched += 1;
                for reg in record_regressions(o, r) {
                    c.regressions.push((k.clone(), reg));
                }
            }
            None => c.new_only += 1,
        }
    }
    c.compared = matched;
    c.baseline_only = baseline.records.len().saturating_sub(matched);
    c
}

/// A human summary of the comparison (at most `max` regressions listed).
pub fn render(c: &Comparison, baseline: &str, max: usize) -> String {
    let mut o = String::new();
    let _ = writeln!(
        o,
        "baseline {baseline}: {} records compared, {} new, {} gone; {} regression(s) (error ×{ERROR_GROWTH}, cost ×{COST_GROWTH} above {COST_FLOOR_SECONDS} s)",
        c.compared,
        c.new_only,
        c.baseline_only,
        c.regressions.len()
    );
    for (k, r) in c.regressions.iter().take(max) {
        let what = match r {
            Regression::NowFailing { was, now } => format!("now {now} (was {was})"),
            Regression::ErrorGrew { was, now } => format!("error {was:.3e} → {now:.3e}"),
            Regression::CostRose { what, was, now } => format!("{what} {was:.3e} → {now:.3e}"),
        };
        let _ = writeln!(o, "  {k}: {what}");
    }
    if c.regressions.len() > max {
        let _ = writeln!(o, "  … and {} more", c.regressions.len() - max);
    }
    o
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::record::{Cost, Measured, Verdict};
    use serde_json::json;

    fn rec(error: f64, seconds: f64, verdict: Verdict) -> CheckRecord {
        let mut r = CheckRecord::new("smith.lambda_route", json!({"family": "ggx"}), json!(1), "");
        r.measured = Some(Measured::Relative { error });
        r.cost = Cost {
            wall_seconds: seconds,
            evaluations: 100,
            samples: 0,
        };
        r.verdict = verdict;
        r
    }

    #[test]
    fn growth_beyond_the_factors_regresses_and_noise_does_not() {
        let old = rec(1e-12, 0.01, Verdict::Pass);
        assert!(record_regressions(&old, &rec(1.9e-12, 0.04, Verdict::Pass)).is_empty());
        assert!(record_regressions(
            &rec(0.0, 0.0, Verdict::Pass),
            &rec(9e-16, 0.1, Verdict::Pass)
        )
        .is_empty());
        let r = record_regressions(&old, &rec(2.1e-12, 0.2, Verdict::Fail));
        assert_eq!(r.len(), 3, "{r:?}");
        assert!(matches!(r[0], Regression::NowFailing { .. }));
        assert!(matches!(r[1], Regression::ErrorGrew { .. }));
        assert!(matches!(
            r[2],
            Regression::CostRose {
                what: "wall_seconds",
                ..
            }
        ));
        let r = record_regressions(&old, &rec(f64::NAN, 0.01, Verdict::Pass));
        assert!(matches!(r[..], [Regression::ErrorGrew { .. }]), "{r:?}");
    }
}
