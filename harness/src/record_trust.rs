//! Taking a record read back from a file (`--resume`'s `report.jsonl`, `mfh merge`'s shard
//! reports), which anyone can edit: it must be the record of the planned check it is filed
//! under ([`identity_mismatch`]: its check, model and case are that check's), and its verdict is
//! re-judged from its own numbers ([`rejudge`], one rule for both readers).

use crate::check::PlannedCheck;
use crate::record::{CheckRecord, Verdict};
use serde::{Deserialize, Serialize};
use serde_json::Value;

/// What a planned check is: its id, model and case — what its seed, its `plan_key` and the
/// plan's fingerprint are computed from. A shard writes one per plan index it ran into
/// `shard.json`, so that `mfh merge` can check each record against the check planned at its
/// index.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Identity {
    /// The check id.
    pub check: String,
    /// The model spec.
    pub model: Value,
    /// The planned case.
    pub case: Value,
}

impl Identity {
    /// The identity of a planned check.
    pub fn of(planned: &PlannedCheck<'_>) -> Self {
        Self {
            check: planned.check.clone(),
            model: planned.model.clone(),
            case: planned.case.clone(),
        }
    }

    /// The line the plan fingerprint and the plan key hash: `check|model|case`, the model and
    /// case as compact JSON. (Only shards use it, and they are the CLI's.)
    #[cfg_attr(not(feature = "cli"), allow(dead_code))]
    pub fn line(&self) -> String {
        format!("{}|{}|{}", self.check, self.model, self.case)
    }
}

/// The one check id a check may record under another id than its planned one: a stressed Λ
/// route that refuses the case records the loss the refused formula would have had
/// (`check/route_stress.rs`). Every other record carries its planned id.
const REFINED_CHECK_IDS: [(&str, &str); 1] = [("smith.lambda_route", "smith.lambda_route_loss")];

/// Whether `case` (a record's) holds `planned`: equal, or — both objects — every planned key
/// present with its planned value (a check may add what it found to its case: the worst point,
/// a sanity failure, the oracle's mass; it never changes what it was planned at).
fn case_holds(case: &Value, planned: &Value) -> bool {
    match (case, planned) {
        (Value::Object(c), Value::Object(p)) => p.iter().all(|(k, v)| c.get(k) == Some(v)),
        _ => case == planned,
    }
}

/// Why `record` is not the record of the planned check `planned`, or None when it is: its
/// check id is the planned one (or its one refinement, [`REFINED_CHECK_IDS`]), its model the
/// planned model, and its case holds the planned case ([`case_holds`]).
pub fn identity_mismatch(planned: &Identity, record: &CheckRecord) -> Option<String> {
    let check_ok = record.check == planned.check
        || REFINED_CHECK_IDS.contains(&(planned.check.as_str(), record.check.as_str()));
    if !check_ok {
        return Some(format!(
            "its check is `{}`, the planned check's is `{}`",
            record.check, planned.check
        ));
    }
    if record.model != planned.model {
        return Some(format!(
            "its model is {}, the planned check's ({}) is {}",
            record.model, planned.check, planned.model
        ));
    }
    if !case_holds(&record.case, &planned.case) {
        return Some(format!(
            "its case {} does not hold the planned case {} of {}",
            record.case, planned.case, planned.check
        ));
    }
    None
}

/// Keeps a record's case holding its planned case: a check that replaced its case (with the
/// worst point it found, say) gets the planned keys it dropped back, so that every record can
/// be checked against its planned check when it is read back ([`identity_mismatch`]). A key
/// the check set to another value is left as the check set it.
pub fn keep_planned_case(case: &mut Value, planned: &Value) {
    if let (Value::Object(c), Value::Object(p)) = (&mut *case, planned) {
        for (k, v) in p {
            c.entry(k.clone()).or_insert_with(|| v.clone());
        }
    } else if case.is_null() {
        *case = planned.clone();
    }
}

/// Re-judges a record read back from a file: a verdict the rest of the record contradicts
/// ([`CheckRecord::contradiction`]) becomes `fail`; returns the line that says so (the stored
/// verdict and why). The caller says which record and where it came from.
pub fn rejudge(record: &mut CheckRecord) -> Option<String> {
    let why = record.contradiction()?;
    let line = format!(
        "stored verdict {} {why}; re-judged as fail",
        record.verdict.name(),
    );
    record.verdict = Verdict::Fail;
    Some(line)
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn planned() -> Identity {
        Identity {
            check: "bsdf.chi2".into(),
            model: json!({"family": "ggx", "alpha": 0.3}),
            case: json!({"theta": 0.5, "samples": 1000}),
        }
    }

    fn record_of(id: &Identity) -> CheckRecord {
        CheckRecord::new(&id.check, id.model.clone(), id.case.clone(), "")
    }

    #[test]
    fn a_record_is_its_planned_checks_with_added_findings_only() {
        let p = planned();
        let mut r = record_of(&p);
        assert_eq!(identity_mismatch(&p, &r), None);
        r.case["worst_at"] = json!({"theta": 0.1});
        assert_eq!(
            identity_mismatch(&p, &r),
            None,
            "a finding added to the case"
        );
        r.case["theta"] = json!(0.6);
        let why = identity_mismatch(&p, &r).unwrap();
        assert!(why.contains("does not hold the planned case"), "{why}");
        let mut r = record_of(&p);
        r.check = "bsdf.energy".into();
        let why = identity_mismatch(&p, &r).unwrap();
        assert!(
            why.contains("`bsdf.energy`") && why.contains("`bsdf.chi2`"),
            "{why}"
        );
        let mut r = record_of(&p);
        r.model["alpha"] = json!(0.31);
        assert!(identity_mismatch(&p, &r).unwrap().contains("its model"));
        // The one refinement of a check id, and only from its planned id.
        let route = Identity {
            check: "smith.lambda_route".into(),
            ..planned()
        };
        let mut r = record_of(&route);
        r.check = "smith.lambda_route_loss".into();
        assert_eq!(identity_mismatch(&route, &r), None);
        assert!(identity_mismatch(&planned(), &r).is_some());
    }

    #[test]
    fn a_replaced_case_gets_its_planned_keys_back() {
        let p = planned();
        let mut case = json!({"worst": "G1 > 1"});
        keep_planned_case(&mut case, &p.case);
        assert_eq!(
            case,
            json!({"theta": 0.5, "samples": 1000, "worst": "G1 > 1"})
        );
        let mut empty = json!({});
        keep_planned_case(&mut empty, &p.case);
        assert_eq!(empty, p.case);
    }
}
