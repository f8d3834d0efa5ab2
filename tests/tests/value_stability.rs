//! Value-stability vectors: the closed forms did not drift. Every query of
//! `tests/data/value_stability.jsonl` is answered again and compared with the stored answer
//! (numbers to 1e-15 relative, error lines by kind); and the stored file is current: its
//! queries are exactly today's query set, and each of them still parses.
//!
//! After a deliberate change of a closed form: `cargo run -p mfh-tests --example
//! generate_value_stability`, review the diff, say why in the commit.

use mfh_harness::eval::{answer_line, evaluate, EvalError};
use mfh_tests::value_stability::{compare, data_path, header, queries, REGENERATE};
use serde_json::Value;

/// The header and the (query, answer) records of the stored file.
fn stored() -> (Value, Vec<(Value, Value)>) {
    let path = data_path();
    let text = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("cannot read {}: {e} (run {REGENERATE})", path.display()));
    let mut lines = text.lines().filter(|l| !l.trim().is_empty());
    let header: Value = serde_json::from_str(lines.next().expect("a header line")).unwrap();
    let records = lines
        .enumerate()
        .map(|(i, l)| {
            let v: Value =
                serde_json::from_str(l).unwrap_or_else(|e| panic!("line {}: not JSON: {e}", i + 2));
            (v["query"].clone(), v["answer"].clone())
        })
        .collect();
    (header, records)
}

#[test]
fn closed_forms_did_not_drift() {
    let (_, records) = stored();
    assert!(records.len() >= 100, "only {} vectors", records.len());
    let mut drifted = Vec::new();
    for (i, (query, answer)) in records.iter().enumerate() {
        let current = answer_line(&query.to_string());
        if let Err(e) = compare(answer, &current) {
            drifted.push(format!("line {}: {query}\n    {e}", i + 2));
        }
    }
    assert!(
        drifted.is_empty(),
        "{} of {} stored answers changed (if deliberate: {REGENERATE}):\n{}",
        drifted.len(),
        records.len(),
        drifted.join("\n")
    );
}

#[test]
fn stored_file_is_current() {
    let (head, records) = stored();
    let current = queries();
    assert_eq!(
        head,
        header(current.len()),
        "the header is stale: {REGENERATE}"
    );
    let stored_queries: Vec<&Value> = records.iter().map(|(q, _)| q).collect();
    assert_eq!(
        stored_queries.len(),
        current.len(),
        "the query set changed: {REGENERATE}"
    );
    for (i, (s, c)) in stored_queries.iter().zip(&current).enumerate() {
        assert_eq!(
            *s,
            c,
            "query {} differs from the query set: {REGENERATE}",
            i + 1
        );
    }
    // Every stored query still parses: a JSON object whose model spec still builds, unless
    // the stored answer itself says it did not.
    for (query, answer) in &records {
        let kind = answer["error"]["kind"].as_str();
        match evaluate(&query.to_string()) {
            Err(EvalError::Parse(m)) => panic!("{query} no longer parses: {m}"),
            Err(EvalError::Model(m)) if kind != Some("model") => {
                panic!("{query}: its model no longer builds: {m}")
            }
            _ => {}
        }
    }
}
