//! `mfh eval`: the JSON-lines contract for evaluating closed forms (ARCHITECTURE.md, "Evaluating
//! closed forms"). One query per line in, one answer per line out, in order.
//!
//! Non-finite numbers, which JSON cannot carry, are written as the strings `"inf"`, `"-inf"`
//! and `"nan"` (Λ at grazing incidence is +∞).

mod args;
pub mod bsdf;
mod ndf;
pub mod sg;

pub use args::{number, EvalError, UNIT_TOLERANCE};
pub use ndf::{arguments, QUANTITIES};

use crate::messages::{compact_numbers, json_error_message};
use args::check_keys;
use mfh_reference::ModelSpec;
use ndf::evaluate_quantity;
use serde_json::{json, Value};
use std::io::{BufRead, Write};

/// Counts of one `eval_stream` run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Summary {
    /// Queries answered (blank lines are skipped and not counted).
    pub answered: usize,
    /// Queries whose answer is an error line.
    pub failed: usize,
}

/// The longest accepted query line, 1 MiB: a query is a few hundred bytes (a piecewise-linear
/// profile with 10⁴ breakpoints is ≈ 400 KiB), so this bounds the memory of `mfh eval` to about
/// one such line whatever the input (`--input /dev/zero` has no line end at all).
pub const MAX_LINE_BYTES: usize = 1 << 20;

/// Why [`eval_stream`] stopped before the end of its input.
#[derive(Debug, thiserror::Error)]
pub enum StreamError {
    /// Reading the input or writing the answers failed.
    #[error("{0}")]
    Io(#[from] std::io::Error),
    /// A line exceeds [`MAX_LINE_BYTES`]; the run stops there (its error line is written).
    #[error(
        "line {line} is longer than the maximum query line length of {limit} bytes (1 MiB); \
         stopped reading there"
    )]
    LineTooLong {
        /// The 1-based line number.
        line: usize,
        /// The limit in bytes.
        limit: usize,
    },
}

/// One line read with [`read_bounded_line`].
enum Line {
    /// End of input.
    End,
    /// A complete line (without its line end) in the buffer.
    Complete,
    /// More than the limit without a line end; the buffer holds the first `limit` bytes.
    TooLong,
}

/// Reads one line into `buf` (cleared first), never holding more than `limit` bytes.
/// Hand-written: `BufRead::read_until` grows without bound, and `Read::take` would split an
/// over-long line into pieces that look like queries.
fn read_bounded_line(
    input: &mut dyn BufRead,
    buf: &mut Vec<u8>,
    limit: usize,
) -> std::io::Result<Line> {
    buf.clear();
    let mut any = false;
    loop {
        let chunk = match input.fill_buf() {
            Ok(c) => c,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            Err(e) => return Err(e),
        };
        if chunk.is_empty() {
            return Ok(if any { Line::Complete } else { Line::End });
        }
        any = true;
        let (take, done) = match chunk.iter().position(|&b| b == b'\n') {
            Some(i) => (i, true),
            None => (chunk.len(), false),
        };
        if buf.len() + take > limit {
            let room = limit - buf.len();
            buf.extend_from_slice(&chunk[..room]);
            input.consume(room);
            return Ok(Line::TooLong);
        }
        buf.extend_from_slice(&chunk[..take]);
        input.consume(if done { take + 1 } else { take });
        if done {
            return Ok(Line::Complete);
        }
    }
}

/// Answers every line of `input` on `output`; blank lines are skipped. A line that is not
/// valid UTF-8 answers a `parse` error and the later lines are answered; a line longer than
/// [`MAX_LINE_BYTES`] answers a `parse` error and ends the run ([`StreamError::LineTooLong`]).
pub fn eval_stream(
    input: &mut dyn BufRead,
    output: &mut dyn Write,
) -> Result<Summary, StreamError> {
    let mut summary = Summary::default();
    let mut buf = Vec::new();
    let mut number = 0;
    loop {
        number += 1;
        let answer = match read_bounded_line(input, &mut buf, MAX_LINE_BYTES)? {
            Line::End => break,
            Line::TooLong => {
                let e = StreamError::LineTooLong {
                    line: number,
                    limit: MAX_LINE_BYTES,
                };
                writeln!(output, "{}", error_answer(&EvalError::Parse(e.to_string())))?;
                output.flush()?;
                return Err(e);
            }
            Line::Complete => match std::str::from_utf8(&buf) {
                Ok(line) if line.trim().is_empty() => continue,
                Ok(line) => answer_line(line),
                Err(e) => error_answer(&EvalError::Parse(format!(
                    "line {number} is not valid UTF-8 (invalid byte at offset {})",
                    e.valid_up_to()
                ))),
            },
        };
        summary.answered += 1;
        if answer.get("error").is_some() {
            summary.failed += 1;
        }
        writeln!(output, "{answer}")?;
    }
    output.flush()?;
    Ok(summary)
}

/// The longest error message written (a message quotes the offending value, which may be long).
pub const MAX_MESSAGE_CHARS: usize = 400;

/// The error line of `e`, its message with long numbers compacted and cut to
/// [`MAX_MESSAGE_CHARS`].
fn error_answer(e: &EvalError) -> Value {
    let mut message = compact_numbers(e.message());
    if message.chars().count() > MAX_MESSAGE_CHARS {
        message = message.chars().take(MAX_MESSAGE_CHARS).collect::<String>() + "…";
    }
    json!({ "error": { "kind": e.kind(), "message": message } })
}

/// The answer to one query line: `{"value": …}` or `{"error": {"kind": …, "message": …}}`.
pub fn answer_line(line: &str) -> Value {
    match evaluate(line) {
        Ok(value) => json!({ "value": value }),
        Err(e) => error_answer(&e),
    }
}

/// Evaluates one query line.
pub fn evaluate(line: &str) -> Result<Value, EvalError> {
    let query: Value = serde_json::from_str(line)
        .map_err(|e| EvalError::Parse(format!("not JSON: {}", json_error_message(&e))))?;
    let obj = query
        .as_object()
        .ok_or_else(|| EvalError::Parse("a query must be a JSON object".into()))?;
    // Spherical-Gaussian quantities (document 003) take no "model": see [`sg`]; nor do the BSDF
    // quantities, which take a "bsdf" spec: see [`bsdf`].
    if let Some(quantity) = obj.get("quantity").and_then(Value::as_str) {
        if let Some(known) = bsdf::arguments(quantity) {
            check_keys(obj, quantity, &["bsdf", "quantity", "route"], known)?;
        } else if let Some(known) = sg::arguments(quantity) {
            check_keys(obj, quantity, &["quantity", "route"], known)?;
        } else if let Some(known) = arguments(quantity) {
            check_keys(obj, quantity, &["model", "quantity", "route"], known)?;
        }
        let route = obj.get("route").and_then(Value::as_str);
        if let Some(answer) = sg::evaluate(quantity, obj, route) {
            return answer;
        }
        if let Some(answer) = bsdf::evaluate(quantity, obj, route) {
            return answer;
        }
    }
    let spec_value = obj
        .get("model")
        .ok_or_else(|| EvalError::Argument("missing \"model\"".into()))?;
    let spec: ModelSpec = serde_json::from_value(spec_value.clone())
        .map_err(|e| EvalError::Model(format!("bad model spec: {}", json_error_message(&e))))?;
    let model = spec.build()?;
    let quantity = obj
        .get("quantity")
        .and_then(Value::as_str)
        .ok_or_else(|| EvalError::Argument("missing \"quantity\" (a string)".into()))?;
    let route = match obj.get("route") {
        None | Some(Value::Null) => None,
        Some(Value::String(r)) => Some(r.as_str()),
        Some(_) => return Err(EvalError::Argument("\"route\" must be a string".into())),
    };
    evaluate_quantity(model.as_ref(), quantity, obj, route)
}

/// Test helpers shared by the unit tests of every `eval` module.
#[cfg(test)]
pub(crate) mod testing {
    use super::answer_line;
    use serde_json::Value;

    /// The value of an answer line; panics on an error line.
    pub(crate) fn value(line: &str) -> Value {
        let a = answer_line(line);
        a.get("value")
            .cloned()
            .unwrap_or_else(|| panic!("expected a value for {line}, got {a}"))
    }

    /// The error kind of an answer line; panics on a value line.
    pub(crate) fn error_kind(line: &str) -> String {
        let a = answer_line(line);
        a["error"]["kind"]
            .as_str()
            .unwrap_or_else(|| panic!("expected an error for {line}, got {a}"))
            .to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::testing::{error_kind, value};
    use super::*;
    use mfh_reference::geometry::from_spherical;

    #[test]
    fn std_lambda_matches_library() {
        let v = value(
            r#"{"model":{"family":"std","gamma":2.5,"alpha":0.3},"quantity":"lambda","theta":1.2}"#,
        );
        let m = ModelSpec::Std(mfh_reference::ndf::student::StdSpec {
            gamma: 2.5,
            alpha: Some(0.3),
            alpha_x: None,
            alpha_y: None,
        })
        .build()
        .unwrap();
        let expected = m.as_smith().unwrap().lambda(from_spherical(1.2, 0.0));
        assert_eq!(v.as_f64().unwrap(), expected);
        assert!(expected > 0.0);
    }

    #[test]
    fn errors_have_kinds() {
        assert_eq!(error_kind("not json"), "parse");
        assert_eq!(error_kind("[1]"), "parse");
        assert_eq!(
            error_kind(r#"{"model":{"family":"ggx","alpha":-1},"quantity":"d","theta":0}"#),
            "model"
        );
        assert_eq!(
            error_kind(
                r#"{"model":{"family":"ggx","alpha":0.1,"beta":1},"quantity":"d","theta":0}"#
            ),
            "model"
        );
        assert_eq!(
            error_kind(r#"{"model":{"family":"ggx","alpha":0.1},"quantity":"d"}"#),
            "argument"
        );
        assert_eq!(
            error_kind(r#"{"model":{"family":"ggx","alpha":0.1},"quantity":"d","m":[0,0,2]}"#),
            "argument"
        );
        assert_eq!(
            error_kind(
                r#"{"model":{"family":"std","gamma":1.2,"alpha":0.1},"quantity":"lambda","theta":1}"#
            ),
            "unsupported"
        );
        assert_eq!(
            error_kind(
                r#"{"model":{"family":"std","gamma":2.7,"alpha":0.1},"quantity":"lambda","theta":1,"route":"integer"}"#
            ),
            "route"
        );
        assert_eq!(
            error_kind(
                r#"{"model":{"family":"std","gamma":2,"alpha":0.1},"quantity":"sample_wm","u":[0.5,1.0]}"#
            ),
            "argument"
        );
    }

    #[test]
    fn grazing_lambda_is_inf_string_and_moments_null() {
        let v = value(
            r#"{"model":{"family":"ggx","alpha":0.3},"quantity":"lambda","theta":1.5707963267948966}"#,
        );
        assert_eq!(v, json!("inf"));
        let v = value(r#"{"model":{"family":"ggx","alpha":0.3},"quantity":"slope_moment","k":1}"#);
        assert_eq!(v, Value::Null);
    }

    #[test]
    fn stream_answers_every_line_in_order() {
        let input = concat!(
            r#"{"model":{"family":"beckmann","alpha":0.5},"quantity":"d","theta":0}"#,
            "\n\nbroken\n",
            r#"{"model":{"family":"ggx","alpha_x":0.1,"alpha_y":0.4},"quantity":"sample_wm","u":[0.3,0.6]}"#,
            "\n"
        );
        let mut out = Vec::new();
        let s = eval_stream(&mut input.as_bytes(), &mut out).unwrap();
        assert_eq!(
            s,
            Summary {
                answered: 3,
                failed: 1
            }
        );
        let lines: Vec<Value> = String::from_utf8(out)
            .unwrap()
            .lines()
            .map(|l| serde_json::from_str(l).unwrap())
            .collect();
        assert_eq!(lines.len(), 3);
        let d0 = lines[0]["value"].as_f64().unwrap();
        assert!((d0 - 1.0 / (std::f64::consts::PI * 0.25)).abs() < 1e-15);
        assert_eq!(lines[1]["error"]["kind"], "parse");
        assert_eq!(lines[2]["value"].as_array().unwrap().len(), 3);
    }

    #[test]
    fn visible_normal_sampling_answers_the_library() {
        let ggx = r#"{"family":"ggx","alpha_x":0.2,"alpha_y":0.5}"#;
        let m = serde_json::from_str::<ModelSpec>(ggx)
            .unwrap()
            .build()
            .unwrap();
        let v = m.as_visible_sampler().unwrap();
        let wi = from_spherical(1.1, 0.4);
        let got = value(&format!(
            r#"{{"model":{ggx},"quantity":"sample_wm_visible","theta_i":1.1,"phi_i":0.4,"u":[0.3,0.7]}}"#
        ));
        let want = v.sample_wm_visible(wi, [0.3, 0.7]);
        for k in 0..3 {
            assert_eq!(got[k].as_f64().unwrap(), want[k]);
        }
        let got = value(&format!(
            r#"{{"model":{ggx},"quantity":"pdf_wm_visible","theta_i":1.1,"phi_i":0.4,"theta":0.3,"phi":1.0}}"#
        ));
        let want = v.pdf_wm_visible(wi, from_spherical(0.3, 1.0));
        assert_eq!(got.as_f64().unwrap(), want);
        assert!(want > 0.0);
        for (line, kind) in [
            (
                format!(r#"{{"model":{ggx},"quantity":"pdf_wm_visible","theta_i":1.6,"theta":0.3}}"#),
                "argument",
            ),
            (
                format!(r#"{{"model":{ggx},"quantity":"sample_wm_visible","theta_i":0.3}}"#),
                "argument",
            ),
            (
                r#"{"model":{"family":"std","gamma":3,"alpha":0.3},"quantity":"sample_wm_visible","theta_i":0.3,"u":[0.1,0.2]}"#.to_string(),
                "unsupported",
            ),
        ] {
            assert_eq!(error_kind(&line), kind, "{line}");
        }
    }

    #[test]
    fn visible_moments_of_gaussian_slopes() {
        let model =
            r#"{"family":"gaussian_slopes","mean":[0.2,-0.1],"cov":[[0.04,0.01],[0.01,0.09]]}"#;
        let v = value(&format!(
            r#"{{"model":{model},"quantity":"visible_moments","theta":1.2,"phi":0.5}}"#
        ));
        let built: ModelSpec = serde_json::from_str(model).unwrap();
        let built = built.build().unwrap();
        let expected = built
            .as_visible_moments()
            .unwrap()
            .visible_moments(from_spherical(1.2, 0.5))
            .unwrap();
        assert_eq!(v["mean"][1].as_f64().unwrap(), expected.mean[1]);
        assert_eq!(v["cov"][0][1].as_f64().unwrap(), expected.cov[0][1]);
        assert_eq!(v["cov"][1][1].as_f64().unwrap(), expected.cov[1][1]);
        let printed = value(&format!(
            r#"{{"model":{model},"quantity":"visible_moments","theta":1.2,"phi":0.5,"route":"pseudocode_printed"}}"#
        ));
        assert_ne!(printed["cov"], v["cov"]);
        assert_eq!(
            error_kind(&format!(
                r#"{{"model":{model},"quantity":"visible_moments","theta":2.0}}"#
            )),
            "argument"
        );
        assert_eq!(
            error_kind(&format!(
                r#"{{"model":{model},"quantity":"visible_moments","theta":1.0,"route":"x"}}"#
            )),
            "route"
        );
        assert_eq!(
            error_kind(
                r#"{"model":{"family":"ggx","alpha":0.3},"quantity":"visible_moments","theta":1.0}"#
            ),
            "unsupported"
        );
    }
}
