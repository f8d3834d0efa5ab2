//! `mfh eval`: the JSON-lines contract for evaluating closed forms (ARCHITECTURE.md, "Evaluating
//! closed forms"). One query per line in, one answer per line out, in order.
//!
//! Non-finite numbers, which JSON cannot carry, are written as the strings `"inf"`, `"-inf"`
//! and `"nan"` (Λ at grazing incidence is +∞).

use crate::messages::{compact_numbers, json_error_message};
use mfh_reference::geometry::{from_spherical, is_unit, Vec3};
use mfh_reference::{Masking, Model, ModelSpec, ParamError, QueryError};
use serde_json::{json, Map, Value};
use std::io::{BufRead, Write};

/// How far from unit length a given direction vector may be.
pub const UNIT_TOLERANCE: f64 = 1e-9;

/// The error kinds an answer line can carry.
#[derive(Debug, Clone, PartialEq)]
pub enum EvalError {
    /// The line is not a JSON object.
    Parse(String),
    /// The model spec is malformed or its parameters are invalid.
    Model(String),
    /// An argument of the query is missing or outside its domain.
    Argument(String),
    /// The family has no meaning for this quantity.
    Unsupported(String),
    /// The requested route is unknown or does not apply.
    Route(String),
}

impl EvalError {
    /// The `kind` field of the error line.
    pub fn kind(&self) -> &'static str {
        match self {
            EvalError::Parse(_) => "parse",
            EvalError::Model(_) => "model",
            EvalError::Argument(_) => "argument",
            EvalError::Unsupported(_) => "unsupported",
            EvalError::Route(_) => "route",
        }
    }

    /// The human-readable message.
    pub fn message(&self) -> &str {
        match self {
            EvalError::Parse(m)
            | EvalError::Model(m)
            | EvalError::Argument(m)
            | EvalError::Unsupported(m)
            | EvalError::Route(m) => m,
        }
    }
}

impl From<ParamError> for EvalError {
    fn from(e: ParamError) -> Self {
        EvalError::Model(e.to_string())
    }
}

impl From<QueryError> for EvalError {
    fn from(e: QueryError) -> Self {
        match e {
            QueryError::Unsupported { .. } => EvalError::Unsupported(e.to_string()),
            QueryError::Route { .. } => EvalError::Route(e.to_string()),
            QueryError::Argument(_) => EvalError::Argument(e.to_string()),
        }
    }
}

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
    // Spherical-Gaussian quantities (seed 003) take no "model": see eval_sg.
    if let Some(quantity) = obj.get("quantity").and_then(Value::as_str) {
        if let Some(known) = crate::eval_sg::arguments(quantity) {
            check_keys(obj, quantity, &["quantity", "route"], known)?;
        } else if let Some(known) = arguments(quantity) {
            check_keys(obj, quantity, &["model", "quantity", "route"], known)?;
        }
        let route = obj.get("route").and_then(Value::as_str);
        if let Some(answer) = crate::eval_sg::evaluate(quantity, obj, route) {
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

fn unsupported(model: &dyn Model, quantity: &str) -> EvalError {
    if matches!(quantity, "lambda" | "g1" | "g2") {
        if let Some(why) = model.spec().smith_limit() {
            return EvalError::Unsupported(format!(
                "{} does not support {quantity}: {why}",
                model.family()
            ));
        }
    }
    QueryError::Unsupported {
        family: model.family().to_string(),
        quantity: quantity.to_string(),
    }
    .into()
}

/// The argument keys each model quantity takes (besides `model`, `quantity`, `route`); None
/// for an unknown quantity.
pub fn arguments(quantity: &str) -> Option<&'static [&'static str]> {
    Some(match quantity {
        "d" | "pdf_wm" => &["m", "theta", "phi"],
        "lambda" | "visible_moments" => &["w", "theta", "phi"],
        "g1" => &["w", "theta", "phi", "m"],
        "g2" => &[
            "wo", "theta_o", "phi_o", "wi", "theta_i", "phi_i", "m", "masking",
        ],
        "p22" => &["p", "q"],
        "p2" => &["q", "phi"],
        "slope_moment" => &["k", "phi"],
        "variance" => &["phi"],
        "excess_kurtosis" => &[],
        "sample_wm" => &["u"],
        "sample_wm_visible" => &["wi", "theta_i", "phi_i", "u"],
        "pdf_wm_visible" => &["wi", "theta_i", "phi_i", "m", "theta", "phi"],
        _ => return None,
    })
}

/// Rejects a key of `q` that is neither in `common` nor in `known`, naming it and the keys the
/// quantity takes: a misspelled optional key (`"ph"`) must not silently answer for its default.
pub(crate) fn check_keys(
    q: &Map<String, Value>,
    quantity: &str,
    common: &[&str],
    known: &[&str],
) -> Result<(), EvalError> {
    match q
        .keys()
        .find(|k| !common.contains(&k.as_str()) && !known.contains(&k.as_str()))
    {
        None => Ok(()),
        Some(k) => {
            let mut all: Vec<&str> = common.to_vec();
            all.extend_from_slice(known);
            let shown: String = k.chars().take(40).collect();
            Err(EvalError::Argument(format!(
                "unknown key {shown:?} for quantity {quantity} (known: {})",
                all.join(", ")
            )))
        }
    }
}

fn no_route(route: Option<&str>, quantity: &str) -> Result<(), EvalError> {
    match route {
        None | Some("default") => Ok(()),
        Some(r) => Err(EvalError::Route(format!(
            "route {r:?} is not available: {quantity} has a single route"
        ))),
    }
}

fn evaluate_quantity(
    model: &dyn Model,
    quantity: &str,
    q: &Map<String, Value>,
    route: Option<&str>,
) -> Result<Value, EvalError> {
    match quantity {
        "d" => {
            no_route(route, quantity)?;
            Ok(number(model.d(direction(q, "m")?)))
        }
        "lambda" => {
            let smith = model
                .as_smith()
                .ok_or_else(|| unsupported(model, quantity))?;
            let w = direction(q, "w")?;
            Ok(number(match route {
                None => smith.lambda(w),
                Some(r) => smith.lambda_route(w, r)?,
            }))
        }
        "g1" => {
            no_route(route, quantity)?;
            let smith = model
                .as_smith()
                .ok_or_else(|| unsupported(model, quantity))?;
            let w = direction(q, "w")?;
            let m = optional_vector(q, "m")?.unwrap_or([0.0, 0.0, 1.0]);
            Ok(number(smith.g1(w, m)))
        }
        "g2" => {
            no_route(route, quantity)?;
            let smith = model
                .as_smith()
                .ok_or_else(|| unsupported(model, quantity))?;
            let wo = direction(q, "wo")?;
            let wi = direction(q, "wi")?;
            let m = optional_vector(q, "m")?.unwrap_or([0.0, 0.0, 1.0]);
            let masking: Masking = match q.get("masking") {
                None => Masking::HeightCorrelated,
                Some(v) => serde_json::from_value(v.clone()).map_err(|_| {
                    EvalError::Argument(
                        "\"masking\" must be \"uncorrelated\" or \"height_correlated\"".into(),
                    )
                })?,
            };
            Ok(number(smith.g2(wo, wi, m, masking)))
        }
        "p22" => {
            no_route(route, quantity)?;
            let slopes = model
                .as_slopes()
                .ok_or_else(|| unsupported(model, quantity))?;
            Ok(number(slopes.p22(finite(q, "p")?, finite(q, "q")?)))
        }
        "p2" => {
            no_route(route, quantity)?;
            let slopes = model
                .as_slopes()
                .ok_or_else(|| unsupported(model, quantity))?;
            let phi = optional_finite(q, "phi")?.unwrap_or(0.0);
            Ok(number(slopes.p2(finite(q, "q")?, phi)))
        }
        "slope_moment" | "variance" | "excess_kurtosis" => {
            no_route(route, quantity)?;
            let slopes = model
                .as_slopes()
                .ok_or_else(|| unsupported(model, quantity))?;
            let phi = optional_finite(q, "phi")?.unwrap_or(0.0);
            let v = match quantity {
                "slope_moment" => {
                    let k = q.get("k").and_then(Value::as_u64).ok_or_else(|| {
                        EvalError::Argument("\"k\" must be a non-negative integer".into())
                    })?;
                    let k = u32::try_from(k)
                        .map_err(|_| EvalError::Argument("\"k\" is too large".into()))?;
                    slopes.slope_moment(k, phi)
                }
                "variance" => slopes.variance(phi),
                _ => slopes.excess_kurtosis(),
            };
            Ok(v.map(number).unwrap_or(Value::Null))
        }
        "sample_wm" => {
            no_route(route, quantity)?;
            let sampler = model
                .as_sampler()
                .ok_or_else(|| unsupported(model, quantity))?;
            let m = sampler.sample_wm(unit_square(q)?);
            Ok(Value::Array(m.iter().map(|c| number(*c)).collect()))
        }
        "sample_wm_visible" => {
            no_route(route, quantity)?;
            let sampler = model
                .as_visible_sampler()
                .ok_or_else(|| unsupported(model, quantity))?;
            let wi = visible_incidence(q)?;
            let m = sampler.sample_wm_visible(wi, unit_square(q)?);
            Ok(Value::Array(m.iter().map(|c| number(*c)).collect()))
        }
        "pdf_wm_visible" => {
            no_route(route, quantity)?;
            let sampler = model
                .as_visible_sampler()
                .ok_or_else(|| unsupported(model, quantity))?;
            let wi = visible_incidence(q)?;
            Ok(number(sampler.pdf_wm_visible(wi, direction(q, "m")?)))
        }
        "pdf_wm" => {
            no_route(route, quantity)?;
            let sampler = model
                .as_sampler()
                .ok_or_else(|| unsupported(model, quantity))?;
            Ok(number(sampler.pdf_wm(direction(q, "m")?)))
        }
        "visible_moments" => {
            let moments = model
                .as_visible_moments()
                .ok_or_else(|| unsupported(model, quantity))?;
            let w = direction(q, "w")?;
            let v = match route {
                None => moments.visible_moments(w)?,
                Some(r) => moments.visible_moments_route(w, r)?,
            };
            Ok(json!({
                "mean": [number(v.mean[0]), number(v.mean[1])],
                "cov": [
                    [number(v.cov[0][0]), number(v.cov[0][1])],
                    [number(v.cov[1][0]), number(v.cov[1][1])]
                ],
            }))
        }
        other => Err(EvalError::Argument(format!(
            "unknown quantity {other:?} (known: d, lambda, g1, g2, p22, p2, slope_moment, \
             variance, excess_kurtosis, sample_wm, pdf_wm, sample_wm_visible, pdf_wm_visible, \
             visible_moments, and the SG/ASG quantities)"
        ))),
    }
}

/// The sample point `"u": [u1, u2]` in [0, 1)².
fn unit_square(q: &Map<String, Value>) -> Result<[f64; 2], EvalError> {
    let u = q
        .get("u")
        .and_then(Value::as_array)
        .filter(|a| a.len() == 2)
        .and_then(|a| Some([a[0].as_f64()?, a[1].as_f64()?]))
        .ok_or_else(|| EvalError::Argument("\"u\" must be [u1, u2]".into()))?;
    if !u.iter().all(|x| (0.0..1.0).contains(x)) {
        return Err(EvalError::Argument(format!(
            "\"u\" must lie in [0, 1)² (got {u:?})"
        )));
    }
    Ok(u)
}

/// The incident direction of the visible-normal quantities (`"wi"`, or `"theta_i"` and
/// `"phi_i"`), which must lie strictly above the horizon.
fn visible_incidence(q: &Map<String, Value>) -> Result<Vec3, EvalError> {
    let wi = direction(q, "wi")?;
    if !mfh_reference::model::visible_domain(wi) {
        return Err(EvalError::Argument(format!(
            "the incident direction must lie strictly above the horizon (got {wi:?})"
        )));
    }
    Ok(wi)
}

/// A JSON number, or `"inf"`, `"-inf"`, `"nan"` for non-finite values.
pub fn number(x: f64) -> Value {
    if x.is_finite() {
        json!(x)
    } else if x.is_nan() {
        json!("nan")
    } else if x > 0.0 {
        json!("inf")
    } else {
        json!("-inf")
    }
}

fn finite(q: &Map<String, Value>, key: &str) -> Result<f64, EvalError> {
    optional_finite(q, key)?.ok_or_else(|| EvalError::Argument(format!("missing \"{key}\"")))
}

fn optional_finite(q: &Map<String, Value>, key: &str) -> Result<Option<f64>, EvalError> {
    match q.get(key) {
        None => Ok(None),
        Some(v) => match v.as_f64() {
            Some(x) if x.is_finite() => Ok(Some(x)),
            _ => Err(EvalError::Argument(format!(
                "\"{key}\" must be a finite number (got {v})"
            ))),
        },
    }
}

fn optional_vector(q: &Map<String, Value>, key: &str) -> Result<Option<Vec3>, EvalError> {
    let Some(v) = q.get(key) else {
        return Ok(None);
    };
    let a = v
        .as_array()
        .filter(|a| a.len() == 3)
        .and_then(|a| Some([a[0].as_f64()?, a[1].as_f64()?, a[2].as_f64()?]))
        .ok_or_else(|| EvalError::Argument(format!("\"{key}\" must be [x, y, z]")))?;
    if !is_unit(a, UNIT_TOLERANCE) {
        return Err(EvalError::Argument(format!(
            "\"{key}\" must be a unit vector (got {a:?})"
        )));
    }
    Ok(Some(a))
}

/// A direction given as the unit vector `key`, or as `theta` (and optional `phi`); for the
/// two-direction quantities the angles are `theta_o`/`phi_o` and `theta_i`/`phi_i`.
fn direction(q: &Map<String, Value>, key: &str) -> Result<Vec3, EvalError> {
    let (theta_key, phi_key) = match key {
        "wo" => ("theta_o", "phi_o"),
        "wi" => ("theta_i", "phi_i"),
        _ => ("theta", "phi"),
    };
    let vector = optional_vector(q, key)?;
    let theta = optional_finite(q, theta_key)?;
    match (vector, theta) {
        (Some(_), Some(_)) => Err(EvalError::Argument(format!(
            "give either \"{key}\" or \"{theta_key}\", not both"
        ))),
        (Some(v), None) => Ok(v),
        (None, Some(theta)) => {
            if !(0.0..=std::f64::consts::PI).contains(&theta) {
                return Err(EvalError::Argument(format!(
                    "\"{theta_key}\" must lie in [0, π] (got {theta})"
                )));
            }
            let phi = optional_finite(q, phi_key)?.unwrap_or(0.0);
            Ok(from_spherical(theta, phi))
        }
        (None, None) => Err(EvalError::Argument(format!(
            "missing direction: give \"{key}\" ([x, y, z]) or \"{theta_key}\" (and \"{phi_key}\")"
        ))),
    }
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
