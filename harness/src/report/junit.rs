//! JUnit XML for CI systems: one test suite per check id, one test case per record; failures
//! and errors carry the measured error and tolerance, expected failures and skips are skipped
//! cases with their reason.
//!
//! A test case's name is the record's short readable name ([`super::text::test_name`]: check
//! id, model and case values), made unique within its suite by numbering repeats (`#2`, `#3`,
//! in record order, so the same report gives the same names); the full model and case are the
//! test case's properties `model` and `case` (JSON), with `seed` for a statistical check.

use crate::record::{CheckRecord, Verdict};
use crate::run::AuditReport;
use std::collections::{BTreeMap, HashMap, HashSet};

fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// A failing record's text ([`super::text::fields`], the layout every sink prints), one field
/// a line.
fn detail(r: &CheckRecord) -> String {
    super::text::fields(r)
        .iter()
        .map(|(label, text)| format!("{label}: {text}"))
        .collect::<Vec<_>>()
        .join("\n")
}

/// The test cases' names of one suite's records, in order: each record's
/// [`super::text::test_name`], a repeat numbered ` #2`, ` #3`, … (skipping a number whose
/// name is taken), so that every name of the suite is unique and the same records give the
/// same names.
fn testcase_names(records: &[&CheckRecord]) -> Vec<String> {
    let short: Vec<String> = records.iter().map(|r| super::text::test_name(r)).collect();
    let mut taken: HashSet<String> = short.iter().cloned().collect();
    let mut seen: HashMap<&str, usize> = HashMap::new();
    short
        .iter()
        .map(|name| {
            let n = seen.entry(name).or_insert(0);
            *n += 1;
            if *n == 1 {
                return name.clone();
            }
            loop {
                let numbered = format!("{name} #{n}");
                if taken.insert(numbered.clone()) {
                    return numbered;
                }
                *n += 1;
            }
        })
        .collect()
}

/// The full model and case of a record (JSON, as in report.json) and its seed, as the test
/// case's properties: what the short name leaves out.
fn properties(r: &CheckRecord) -> String {
    let mut out = String::from("      <properties>\n");
    for (name, value) in [("model", r.model.to_string()), ("case", r.case.to_string())]
        .into_iter()
        .chain(r.seed.map(|s| ("seed", s.to_string())))
    {
        out.push_str(&format!(
            "        <property name=\"{name}\" value=\"{}\"/>\n",
            escape(&value)
        ));
    }
    out.push_str("      </properties>\n");
    out
}

/// Renders the report as JUnit XML.
pub fn render(report: &AuditReport) -> String {
    let mut suites: BTreeMap<&str, Vec<&CheckRecord>> = BTreeMap::new();
    for r in &report.records {
        suites.entry(r.check.as_str()).or_default().push(r);
    }
    let mut out = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    let failures = report
        .records
        .iter()
        .filter(|r| matches!(r.verdict, Verdict::Fail | Verdict::UnexpectedPass { .. }))
        .count();
    let errors = report
        .records
        .iter()
        .filter(|r| matches!(r.verdict, Verdict::Error { .. }))
        .count();
    out.push_str(&format!(
        "<testsuites name=\"mfh audit: {}\" tests=\"{}\" failures=\"{failures}\" errors=\"{errors}\" time=\"{:.3}\">\n",
        escape(&report.scene),
        report.records.len(),
        report.summary.wall_seconds
    ));
    for (check, records) in suites {
        let f = records
            .iter()
            .filter(|r| matches!(r.verdict, Verdict::Fail | Verdict::UnexpectedPass { .. }))
            .count();
        let e = records
            .iter()
            .filter(|r| matches!(r.verdict, Verdict::Error { .. }))
            .count();
        let s = records
            .iter()
            .filter(|r| {
                matches!(
                    r.verdict,
                    Verdict::Skipped { .. } | Verdict::ExpectedFailure { .. }
                )
            })
            .count();
        out.push_str(&format!(
            "  <testsuite name=\"{}\" tests=\"{}\" failures=\"{f}\" errors=\"{e}\" skipped=\"{s}\">\n",
            escape(check),
            records.len()
        ));
        for (r, name) in records.iter().zip(testcase_names(&records)) {
            out.push_str(&format!(
                "    <testcase classname=\"{}\" name=\"{}\" time=\"{:.6}\">\n",
                escape(check),
                escape(&name),
                r.cost.wall_seconds
            ));
            out.push_str(&properties(r));
            match &r.verdict {
                Verdict::Pass => {}
                Verdict::Fail => out.push_str(&format!(
                    "      <failure message=\"{}\">{}</failure>\n",
                    escape(&super::text::measured_against(r)),
                    escape(&detail(r))
                )),
                Verdict::Error { message } => {
                    out.push_str(&format!("      <error message=\"{}\"/>\n", escape(message)))
                }
                Verdict::UnexpectedPass { reason } => out.push_str(&format!(
                    "      <failure message=\"unexpected pass: {}\">{}</failure>\n",
                    escape(reason),
                    escape(&detail(r))
                )),
                Verdict::ExpectedFailure { reason } => out.push_str(&format!(
                    "      <skipped message=\"expected failure: {}\"/>\n",
                    escape(reason)
                )),
                Verdict::Skipped { reason } => out.push_str(&format!(
                    "      <skipped message=\"{}\"/>\n",
                    escape(reason)
                )),
            }
            out.push_str("    </testcase>\n");
        }
        out.push_str("  </testsuite>\n");
    }
    out.push_str("</testsuites>\n");
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::check::Profile;
    use serde_json::{json, Value};

    fn report(records: Vec<CheckRecord>) -> AuditReport {
        AuditReport {
            schema_version: crate::record::SCHEMA_VERSION,
            mfh_version: "0",
            scene: "test".into(),
            profile: Profile::Quick,
            seed: 1,
            command: "mfh audit".into(),
            summary: crate::run::summarize(&records, (0, 0.0), 0.0),
            records,
            not_audited: Vec::new(),
        }
    }

    /// Every test case has a short readable name, unique within its suite, and keeps its full
    /// model and case as properties; records equal but for the 8th digit of θ, identical
    /// records and a name that looks like a numbered repeat all get names of their own.
    #[test]
    fn testcase_names_are_readable_unique_and_keep_the_case() {
        let ggx = json!({"family": "ggx", "alpha": 0.30000000000000004});
        let blend = json!({"family": "blend", "weight": 0.5,
            "lobes": [{"family": "ggx", "alpha": 0.1}, {"family": "beckmann", "alpha": 0.4}]});
        let mut records = vec![
            CheckRecord::new("normalization.d", ggx.clone(), json!({"theta": 0.5}), "s"),
            CheckRecord::new("normalization.d", ggx.clone(), json!({"theta": 0.5}), "s"),
            CheckRecord::new(
                "normalization.d",
                ggx.clone(),
                json!({"theta": 0.500000001}),
                "s",
            ),
            CheckRecord::new("normalization.d", blend, json!({"u": [0.1, 0.2]}), "s"),
            CheckRecord::new(
                "sg.product",
                Value::Null,
                json!({"sg": {"axis": [0.0, 0.0, 1.0], "sharpness": 2.0}, "name": "a\"b{c}"}),
                "s",
            ),
        ];
        // A name that looks like a numbered repeat of the first.
        records.push(CheckRecord::new(
            "normalization.d",
            json!({"family": "ggx alpha=0.3 theta=0.5 #2"}),
            Value::Null,
            "s",
        ));
        records[1].seed = Some(7);
        records[2].verdict = Verdict::Fail;
        let names: Vec<String> = testcase_names(&records.iter().collect::<Vec<_>>());
        assert_eq!(names[0], "normalization.d ggx alpha=0.3 theta=0.5");
        assert_eq!(names[1], "normalization.d ggx alpha=0.3 theta=0.5 #3");
        assert_eq!(names[2], "normalization.d ggx alpha=0.3 theta=0.5 #4");
        assert_eq!(
            names[3],
            "normalization.d blend lobes.0.alpha=0.1 lobes.0.family=ggx lobes.1.alpha=0.4 \
             lobes.1.family=beckmann weight=0.5 u=[0.1, 0.2]"
        );
        assert_eq!(
            names[4],
            "sg.product name=a'b(c) sg.axis=[0, 0, 1] sg.sharpness=2"
        );
        assert_eq!(names[5], "normalization.d ggx alpha=0.3 theta=0.5 #2");

        let xml = render(&report(records.clone()));
        let testcases: Vec<&str> = xml
            .lines()
            .filter(|l| l.trim_start().starts_with("<testcase "))
            .collect();
        assert_eq!(testcases.len(), records.len());
        let mut by_suite: HashSet<(String, String)> = HashSet::new();
        for line in &testcases {
            let attr = |key: &str| {
                let start = line.find(&format!(" {key}=\"")).unwrap() + key.len() + 3;
                line[start..][..line[start..].find('"').unwrap()].to_string()
            };
            let name = attr("name");
            assert!(!name.contains(['{', '}']), "{name}");
            assert!(!name.contains("&quot;") && name.len() < 200, "{name}");
            assert!(
                by_suite.insert((attr("classname"), name.clone())),
                "{name} twice"
            );
        }
        // The full case, with every digit, and the seed are the properties.
        assert!(xml.contains(r#"<property name="case" value="{&quot;theta&quot;:0.500000001}"/>"#));
        assert!(xml.contains(r#"<property name="seed" value="7"/>"#));
        assert!(xml.contains(
            r#"<property name="model" value="{&quot;alpha&quot;:0.30000000000000004,&quot;family&quot;:&quot;ggx&quot;}"/>"#
        ));
        assert_eq!(xml.matches("<properties>").count(), records.len());
        assert_eq!(xml.matches("</testcase>").count(), records.len());
        assert_eq!(xml.matches("<failure ").count(), 1);
    }
}
