//! The harness of the `mfh eval` contract tests (`eval_contract.rs`, `eval_contract_sg.rs`): one
//! in-process run of the CLI, its answer lines, and the bit-for-bit comparison of answers with
//! what the library returns.
// Each test crate that includes this module uses a part of it.
#![allow(dead_code)]

use mfh_harness::cli::run;
use serde_json::{json, Value};

/// One in-process run of `mfh`.
pub struct Run {
    pub status: i32,
    pub stdout: String,
    pub stderr: String,
}

/// Runs `mfh <args>` with `stdin` as standard input.
pub fn mfh(args: &[&str], stdin: &str) -> Run {
    let argv: Vec<&str> = std::iter::once("mfh").chain(args.iter().copied()).collect();
    let (mut out, mut err) = (Vec::new(), Vec::new());
    let status = run(argv, &mut stdin.as_bytes(), &mut out, &mut err);
    Run {
        status,
        stdout: String::from_utf8(out).expect("stdout is UTF-8"),
        stderr: String::from_utf8(err).expect("stderr is UTF-8"),
    }
}

/// The answer lines, each parsed (each must be one JSON object).
pub fn answers(r: &Run) -> Vec<Value> {
    r.stdout
        .lines()
        .map(|l| {
            let v: Value = serde_json::from_str(l).unwrap_or_else(|e| panic!("{l:?}: {e}"));
            assert!(v.is_object(), "answer {l} is not an object");
            v
        })
        .collect()
}

/// Query lines, one per line.
pub fn lines(queries: &[Value]) -> String {
    queries.iter().map(|q| format!("{q}\n")).collect()
}

/// What the library answers: a JSON value, or the kind of error the CLI must report.
pub type Expect = Result<Value, &'static str>;

/// A number as the contract writes it: finite numbers as JSON numbers, the rest as strings.
pub fn num(x: f64) -> Value {
    if x.is_nan() {
        json!("nan")
    } else if x == f64::INFINITY {
        json!("inf")
    } else if x == f64::NEG_INFINITY {
        json!("-inf")
    } else {
        json!(x)
    }
}

/// Equality of answers with numbers compared bit for bit (a JSON number written from an f64
/// parses back to the same f64).
pub fn same(a: &Value, b: &Value) -> bool {
    match (a, b) {
        (Value::Number(x), Value::Number(y)) => {
            x.as_f64().map(f64::to_bits) == y.as_f64().map(f64::to_bits)
        }
        (Value::Array(x), Value::Array(y)) => {
            x.len() == y.len() && x.iter().zip(y).all(|(x, y)| same(x, y))
        }
        (Value::Object(x), Value::Object(y)) => {
            x.len() == y.len() && x.iter().all(|(k, v)| y.get(k).is_some_and(|w| same(v, w)))
        }
        _ => a == b,
    }
}

/// Asserts that `answer` is what `expect` says, for the query `query`.
pub fn assert_answer(query: &Value, answer: &Value, expect: &Expect) {
    match expect {
        Ok(v) => assert!(
            same(answer, &json!({ "value": v })),
            "{query}\n  answered {answer}\n  library  {v}"
        ),
        Err(kind) => {
            assert_eq!(answer["error"]["kind"], *kind, "{query} answered {answer}");
            let message = answer["error"]["message"].as_str().unwrap_or("");
            assert!(!message.is_empty(), "{query}: error without message");
            assert_eq!(answer.as_object().map(|o| o.len()), Some(1), "{answer}");
        }
    }
}
