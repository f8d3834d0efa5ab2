//! The one way a check is planned: [`Check`] names it (id, model, case, source, why, covers,
//! statistical or not) and [`Check::run`] turns a body into a [`PlannedCheck`] whose runner
//! creates the record, seeds it when the check draws random numbers, times it, sets its
//! coverage, and turns a capability the model lacks ([`need`]) into a typed `error` verdict —
//! the boilerplate every check would otherwise repeat.

use super::{PlannedCheck, RunContext};
use crate::record::{CheckRecord, Verdict};
use serde_json::Value;

/// A capability a model lacks (a check planned for it cannot run): the record gets an `error`
/// verdict that names it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Missing(pub &'static str);

/// The capability `capability`, or [`Missing`] naming `what` (e.g. "a normal sampler").
pub fn need<T>(capability: Option<T>, what: &'static str) -> Result<T, Missing> {
    capability.ok_or(Missing(what))
}

/// What a body returns: `Ok` once it has filled the record, or the capability it lacked.
pub type Outcome = Result<(), Missing>;

/// A check being planned: everything its record and its plan entry share.
#[derive(Debug, Clone)]
pub struct Check {
    check: String,
    model: Value,
    case: Value,
    source: String,
    why: String,
    covers: Vec<String>,
    statistical: bool,
    seeded: bool,
}

impl Check {
    /// The check `check` (id `family.property`) of `model` (its spec, or null) at `case`,
    /// citing `source` (document and equation).
    pub fn new(check: &str, model: Value, case: Value, source: &str) -> Self {
        Self {
            check: check.to_string(),
            model,
            case,
            source: source.to_string(),
            why: String::new(),
            covers: Vec::new(),
            statistical: false,
            seeded: false,
        }
    }

    /// Why the planner planned it.
    pub fn why(mut self, why: impl Into<String>) -> Self {
        self.why = why.into();
        self
    }

    /// The closed forms it exercises (`family/quantity/route`), in the plan and the record.
    pub fn covers(mut self, covers: Vec<String>) -> Self {
        self.covers = covers;
        self
    }

    /// A statistical check: it takes a share of the audit's α, and its record carries its seed.
    pub fn statistical(mut self) -> Self {
        self.statistical = true;
        self.seeded = true;
        self
    }

    /// Its record carries the seed of its random stream (set by [`Check::statistical`]; alone
    /// for a check that draws random numbers but decides without a p-value).
    pub fn seeded(mut self) -> Self {
        self.seeded = true;
        self
    }

    /// The planned check whose runner creates the record (id, model, case, source, coverage,
    /// seed), lets `body` fill it, turns a [`Missing`] capability into an `error` verdict, and
    /// adds the wall time to the record's cost.
    pub fn run<'a>(
        self,
        body: impl Fn(&mut CheckRecord, &RunContext) -> Outcome + Send + Sync + 'a,
    ) -> PlannedCheck<'a> {
        let Check {
            check,
            model,
            case,
            source,
            why,
            covers,
            statistical,
            seeded,
        } = self;
        let (check_run, model_run, case_run, covers_run) =
            (check.clone(), model.clone(), case.clone(), covers.clone());
        PlannedCheck {
            check,
            model,
            case,
            why,
            covers,
            statistical,
            run: Box::new(move |ctx| {
                let t = std::time::Instant::now();
                let mut r =
                    CheckRecord::new(&check_run, model_run.clone(), case_run.clone(), &source);
                r.covers = covers_run.clone();
                if seeded {
                    r.seed = Some(ctx.seed);
                }
                if let Err(Missing(what)) = body(&mut r, ctx) {
                    r.verdict = Verdict::Error {
                        message: format!("the model has no {what}"),
                    };
                }
                r.cost.wall_seconds += t.elapsed().as_secs_f64();
                r
            }),
        }
    }

    /// The planned check whose record is `skipped` for `reason` (a check the scene calls for
    /// but the model cannot support), with no coverage.
    pub fn skipped<'a>(self, reason: String) -> PlannedCheck<'a> {
        self.covers(Vec::new()).run(move |r, _| {
            r.verdict = Verdict::Skipped {
                reason: reason.clone(),
            };
            Ok(())
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn ctx() -> RunContext {
        RunContext { seed: 42 }
    }

    #[test]
    fn the_record_carries_what_the_plan_says() {
        let p = Check::new("x.y", json!({"family": "ggx"}), json!({"theta": 1}), "eq 1")
            .why("because")
            .covers(vec!["ggx/d/default".into()])
            .statistical()
            .run(|r, _| {
                r.verdict = Verdict::Pass;
                Ok(())
            });
        assert!(p.statistical);
        assert_eq!((p.check.as_str(), p.why.as_str()), ("x.y", "because"));
        let r = (p.run)(&ctx());
        assert_eq!((r.check.as_str(), r.source.as_str()), ("x.y", "eq 1"));
        assert_eq!((&r.model, &r.case), (&p.model, &p.case));
        assert_eq!(r.covers, p.covers);
        assert_eq!(r.seed, Some(42));
        assert_eq!(r.verdict, Verdict::Pass);
        assert!(r.cost.wall_seconds >= 0.0);
        // Not statistical, not seeded: no seed in the record.
        let p = Check::new("x.z", Value::Null, json!({}), "").run(|_, _| Ok(()));
        assert!(!p.statistical);
        assert_eq!((p.run)(&ctx()).seed, None);
    }

    #[test]
    fn a_missing_capability_is_an_error_verdict_and_skips_say_why() {
        let p = Check::new("x.y", Value::Null, json!({}), "").run(|r, _| {
            r.verdict = Verdict::Pass;
            need(None::<&()>, "normal sampler")?;
            Ok(())
        });
        assert_eq!(
            (p.run)(&ctx()).verdict,
            Verdict::Error {
                message: "the model has no normal sampler".into()
            }
        );
        let p = Check::new("x.y", Value::Null, json!({}), "").skipped("no sampler".into());
        assert_eq!(
            (p.run)(&ctx()).verdict,
            Verdict::Skipped {
                reason: "no sampler".into()
            }
        );
    }
}
