//! A record as a person reads it, in every sink: the terminal summary, `assert_pass()`'s table,
//! JUnit's failure text and `report.html` all take a record's fields from here, so that a
//! quantity is named, carries its unit and is printed short (no Rust `Debug` forms, no
//! 309-digit integers for 1e308, no 17-digit JSON numbers) the same way everywhere.

use crate::record::{CheckRecord, Measured, Verdict};
use serde_json::Value;
use std::collections::BTreeMap;

/// Significant digits of a value or an oracle's value ([`num`]): enough to tell two values
/// that differ in the seventh digit, few enough to read; the measured error says the rest.
const VALUE_DIGITS: usize = 7;

/// A number as a person reads it: at most [`VALUE_DIGITS`] significant digits, trailing zeros
/// dropped; fixed notation from 10⁻³ to 10⁶, scientific outside (`1e308`, `6.67e-5`); `NaN`,
/// `∞` and `−∞` for the non-finite values.
pub fn num(x: f64) -> String {
    short(x, VALUE_DIGITS)
}

/// An error or a tolerance: two significant digits (`3.2e-16`, `0.05`).
pub fn err(x: f64) -> String {
    short(x, 2)
}

/// `x` with at most `digits` significant digits ([`num`]'s notation rules).
pub fn short(x: f64, digits: usize) -> String {
    if x.is_nan() {
        return "NaN".into();
    }
    if x.is_infinite() {
        return if x > 0.0 { "∞" } else { "−∞" }.into();
    }
    if x == 0.0 {
        return "0".into();
    }
    let digits = digits.max(1);
    // Round to `digits` significant digits first: the exponent is that of the rounded value
    // (9.9999999 rounds to 10).
    let sci = format!("{:.*e}", digits - 1, x);
    let (mantissa, exponent) = sci.split_once('e').unwrap_or((&sci, "0"));
    let exponent: i32 = exponent.parse().unwrap_or(0);
    if (-3..6).contains(&exponent) {
        let decimals = (digits as i32 - 1 - exponent).max(0) as usize;
        trim_zeros(&format!("{x:.decimals$}"))
    } else {
        format!("{}e{exponent}", trim_zeros(mantissa))
    }
}

/// `text` without trailing zeros after a decimal point (and without a bare point).
fn trim_zeros(text: &str) -> String {
    if text.contains('.') {
        text.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        text.to_string()
    }
}

/// Longest JSON array shown whole in a name; longer ones show their first values and a count.
const MAX_SHOWN_ITEMS: usize = 6;

/// A JSON value as a person reads it: numbers short ([`num`]), strings unquoted, long arrays
/// cut to their first values and a count.
pub fn json(v: &Value) -> String {
    match v {
        Value::Number(n) => match (n.as_i64(), n.as_u64(), n.as_f64()) {
            (Some(i), _, _) => i.to_string(),
            (_, Some(u), _) => u.to_string(),
            (_, _, Some(x)) => num(x),
            _ => n.to_string(),
        },
        Value::String(s) => s.clone(),
        Value::Array(items) => {
            let shown: Vec<String> = items.iter().take(MAX_SHOWN_ITEMS).map(json).collect();
            if items.len() > MAX_SHOWN_ITEMS {
                format!("[{}, … ({} values)]", shown.join(", "), items.len())
            } else {
                format!("[{}]", shown.join(", "))
            }
        }
        Value::Object(map) => format!(
            "{{{}}}",
            map.iter()
                .map(|(k, v)| format!("{k}: {}", json(v)))
                .collect::<Vec<_>>()
                .join(", ")
        ),
        Value::Bool(b) => b.to_string(),
        Value::Null => "null".into(),
    }
}

/// A short human name of a model spec: its kind (`family`, a reference BSDF's `bsdf`, or a
/// user model's `name`) then its other keys as `key=value` ([`json`]).
pub fn model_name(model: &Value) -> String {
    let Some(map) = model.as_object() else {
        return if model.is_null() {
            "(no model)".into()
        } else {
            json(model)
        };
    };
    let kind = ["family", "bsdf", "name"]
        .into_iter()
        .find(|k| map.get(*k).is_some_and(Value::is_string));
    let mut parts: Vec<String> = kind
        .and_then(|k| map.get(k))
        .map(json)
        .into_iter()
        .collect();
    for (k, v) in map.iter().filter(|(k, _)| Some(k.as_str()) != kind) {
        parts.push(format!("{k}={}", json(v)));
    }
    parts.join(" ")
}

/// [`case_name`] cut to `max` characters (with "…").
pub fn case_name_cut(case: &Value, max: usize) -> String {
    let name = case_name(case);
    if name.chars().count() > max {
        name.chars().take(max.saturating_sub(1)).collect::<String>() + "…"
    } else {
        name
    }
}

/// A short human name of a case: `key value` pairs ([`json`]).
pub fn case_name(case: &Value) -> String {
    match case.as_object() {
        Some(map) => map
            .iter()
            .map(|(k, v)| format!("{k} {}", json(v)))
            .collect::<Vec<_>>()
            .join(", "),
        None => json(case),
    }
}

/// The title of a record (its plots, its failure heading): check, model and case.
pub fn record_title(record: &CheckRecord) -> String {
    format!(
        "{} · {} · {}",
        record.check,
        model_name(&record.model),
        case_name(&record.case)
    )
}

/// A record's name in a list of tests (JUnit's `<testcase name>`): the check id, then the
/// model's kind and the model's and the case's values as `key=value` words, numbers short
/// ([`json`]): `normalization.d ggx alpha=0.3 theta=0.5`. Nested values are flattened to
/// dotted keys (`lobes.0.family=ggx`); no braces or quotes, so that a CI page shows a name,
/// not JSON. Short numbers can make two records' names equal: a list that needs unique names
/// numbers the repeats (`report::junit`); the full case stays in the record.
pub fn test_name(record: &CheckRecord) -> String {
    let mut words = vec![record.check.clone()];
    if let Some(map) = record.model.as_object() {
        let kind = ["family", "bsdf", "name"]
            .into_iter()
            .find(|k| map.get(*k).is_some_and(Value::is_string));
        words.extend(kind.and_then(|k| map.get(k)).map(json));
        for (k, v) in map.iter().filter(|(k, _)| Some(k.as_str()) != kind) {
            flat_words(k, v, &mut words);
        }
    } else if !record.model.is_null() {
        flat_words("model", &record.model, &mut words);
    }
    match record.case.as_object() {
        Some(map) => map.iter().for_each(|(k, v)| flat_words(k, v, &mut words)),
        None if record.case.is_null() => {}
        None => flat_words("case", &record.case, &mut words),
    }
    words
        .join(" ")
        .chars()
        .map(|c| match c {
            '{' => '(',
            '}' => ')',
            '"' => '\'',
            c if c.is_control() => ' ',
            c => c,
        })
        .collect()
}

/// `key=value` words of a JSON value: scalars and arrays of scalars as one word ([`json`]),
/// objects and arrays holding objects or arrays flattened to `key.sub` and `key.index`.
fn flat_words(key: &str, value: &Value, out: &mut Vec<String>) {
    match value {
        Value::Object(map) => {
            for (k, v) in map {
                flat_words(&format!("{key}.{k}"), v, out);
            }
        }
        Value::Array(items) if items.iter().any(|v| v.is_object() || v.is_array()) => {
            for (i, v) in items.iter().enumerate() {
                flat_words(&format!("{key}.{i}"), v, out);
            }
        }
        v => out.push(format!("{key}={}", json(v))),
    }
}

/// `n` and the noun, singular or plural (`1 record`, `3 records`).
pub fn count(n: usize, singular: &str, plural: &str) -> String {
    format!("{n} {}", if n == 1 { singular } else { plural })
}

/// What a record's measured error counts.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum ErrorUnit {
    /// |value − oracle| / |oracle|.
    Relative,
    /// |value − oracle|.
    Absolute,
    /// Units in the last place (an absolute error in ulps).
    Ulps,
    /// |measured rate − expected rate|, a difference of exponents.
    Rate,
}

impl ErrorUnit {
    /// The unit as a column heading or a suffix: `relative`, `absolute`, `ulps`, `Δ rate`.
    pub fn name(self) -> &'static str {
        match self {
            ErrorUnit::Relative => "relative",
            ErrorUnit::Absolute => "absolute",
            ErrorUnit::Ulps => "ulps",
            ErrorUnit::Rate => "Δ rate",
        }
    }

    /// An error in this unit: ulps as a count, the others with two significant digits.
    pub fn show(self, error: f64) -> String {
        match self {
            ErrorUnit::Ulps if error == 1.0 => "1 ulp".into(),
            ErrorUnit::Ulps => format!("{} ulps", short(error, 3)),
            other => format!("{} {}", err(error), other.name()),
        }
    }
}

/// The unit of a record's measured error (None for a p-value or nothing measured). An absolute
/// error counts ulps where the tolerance says so: the batch-sampler tolerances measure the
/// distance between two samplers' outputs in ulps and open their reason with "ulps" (the
/// record schema has no unit field; a test below holds the tolerances to that wording).
pub fn error_unit(r: &CheckRecord) -> Option<ErrorUnit> {
    Some(match r.measured? {
        Measured::Relative { .. } => ErrorUnit::Relative,
        Measured::Absolute { .. } if in_ulps(r) => ErrorUnit::Ulps,
        Measured::Absolute { .. } => ErrorUnit::Absolute,
        Measured::Rate { .. } => ErrorUnit::Rate,
        Measured::PValue { .. } => return None,
    })
}

fn in_ulps(r: &CheckRecord) -> bool {
    case_unit(r) == Some("ulp")
        || r.tolerance
            .as_ref()
            .is_some_and(|t| t.reason.starts_with("ulps"))
}

/// The unit a check states in its case (`"unit": "ulp"`, `"unit": "σ²/16"`: the error is a
/// multiple of it), if any.
pub fn case_unit(r: &CheckRecord) -> Option<&str> {
    r.case.get("unit").and_then(Value::as_str)
}

/// " (in units of σ²/16)" where the case states a unit other than ulps, else nothing.
fn scaled(r: &CheckRecord) -> String {
    match case_unit(r) {
        Some(unit) if unit != "ulp" => format!(" (in units of {unit})"),
        _ => String::new(),
    }
}

/// The measured discrepancy as one line, its quantity named: `relative error 3.2e-16`,
/// `2 ulps`, `p = 0 < α = 6.7e-5 (statistic 271890.8, 1023 dof)`, `rate −1.02 (expected −1)`,
/// `not measured`.
pub fn measured(r: &CheckRecord) -> String {
    let Some(m) = r.measured else {
        return "not measured".into();
    };
    match m {
        Measured::Absolute { error } | Measured::Relative { error } => {
            let unit = error_unit(r).unwrap_or(ErrorUnit::Absolute);
            match unit {
                ErrorUnit::Ulps => format!("error {}", unit.show(error)),
                _ => format!("{} error {}{}", unit.name(), err(error), scaled(r)),
            }
        }
        Measured::PValue {
            p,
            statistic,
            dof,
            alpha,
        } => {
            let sign = if p < alpha { "<" } else { "≥" };
            let stat = if dof > 0 {
                format!("statistic {}, {dof} dof", num(statistic))
            } else {
                format!("statistic {}", num(statistic))
            };
            format!("p = {} {sign} α = {} ({stat})", err(p), err(alpha))
        }
        Measured::Rate { exponent, expected } => format!(
            "rate {} (expected {}, |difference| {})",
            short(exponent, 4),
            num(expected),
            err((exponent - expected).abs())
        ),
    }
}

/// The tolerance a record was judged against, in the unit of its error: `closed_form =
/// 1e-10 relative`, `batch_sampler = 4 ulps`, `α = 6.7e-5` for a p-value.
pub fn tolerance(r: &CheckRecord) -> Option<String> {
    let t = r.tolerance.as_ref()?;
    Some(match error_unit(r) {
        Some(unit) => format!("{} = {}", t.name, unit.show(t.value)),
        None => format!("{} = {}", t.name, err(t.value)),
    })
}

/// The measured discrepancy against the tolerance, as one line: `relative error 3.2e-16
/// against closed_form = 1e-10 relative`.
pub fn measured_against(r: &CheckRecord) -> String {
    let text = match (r.measured.is_some(), tolerance(r)) {
        (true, Some(t)) if !matches!(r.measured, Some(Measured::PValue { .. })) => {
            format!("{} against {t}", measured(r))
        }
        _ => measured(r),
    };
    match &r.region {
        Some(region) => format!("{text}; {}", region.text),
        None => text,
    }
}

/// The value under test against the oracle: `0.1676628 against the oracle 0.1676628 ±
/// 1e-14 (error bound)`.
pub fn value_against_oracle(r: &CheckRecord) -> Option<String> {
    let oracle = r.oracle.map(|o| {
        format!(
            "the oracle {} ± {} ({})",
            num(o.value),
            err(o.uncertainty),
            o.kind.replace('_', " ")
        )
    });
    match (r.value, oracle) {
        (Some(v), Some(o)) => Some(format!("{} against {o}", num(v))),
        (Some(v), None) => Some(num(v)),
        (None, Some(o)) => Some(o),
        (None, None) => None,
    }
}

/// The verdict as text: `pass`, `FAIL`, `expected failure: …`, `ERROR: …`.
pub fn verdict(v: &Verdict) -> String {
    match v {
        Verdict::Pass => "pass".into(),
        Verdict::Fail => "FAIL".into(),
        Verdict::ExpectedFailure { reason } => format!("expected failure: {reason}"),
        Verdict::Skipped { reason } => format!("skipped: {reason}"),
        Verdict::Error { message } => format!("ERROR: {message}"),
        Verdict::UnexpectedPass { reason } => format!("UNEXPECTED PASS: {reason}"),
    }
}

/// A record's fields as (label, text) pairs, in reading order: case, value, oracle note,
/// measured, tolerance (with its reason), verdict, source. The one layout of a record that the
/// terminal, `assert_pass()`, JUnit and the HTML failures all print ([`block`] as text).
pub fn fields(r: &CheckRecord) -> Vec<(&'static str, String)> {
    let mut out = vec![("case", case_name(&r.case))];
    if let Some(v) = value_against_oracle(r) {
        out.push(("value", v));
    }
    if let Some(note) = r.oracle.and_then(|o| o.noise_note()) {
        out.push(("oracle", note));
    }
    if r.measured.is_some() {
        out.push(("measured", measured(r)));
    }
    if let Some(region) = &r.region {
        out.push(("region", region.text.clone()));
    }
    if let Some(t) = &r.tolerance {
        let shown = tolerance(r).unwrap_or_default();
        out.push(("tolerance", format!("{shown}: {}", t.reason)));
    }
    out.push(("verdict", verdict(&r.verdict)));
    if !r.source.is_empty() {
        out.push(("source", r.source.clone()));
    }
    out
}

/// A record as an indented block of text: a heading `✗ check  model` and its [`fields`],
/// one per line.
pub fn block(r: &CheckRecord, indent: &str) -> String {
    let mark = if r.verdict.is_failure() { "✗" } else { "·" };
    let mut out = format!("{indent}{mark} {}  {}\n", r.check, model_name(&r.model));
    for (label, text) in fields(r) {
        out.push_str(&format!("{indent}  {label:<9} {text}\n"));
    }
    out
}

/// The worst measured error of the passing records of each check id, one per unit (a check
/// may measure relative errors at some cases and absolute ones at others): check id → unit →
/// error. P-values have no error and are left out.
pub fn worst_passing(records: &[CheckRecord]) -> BTreeMap<&str, BTreeMap<ErrorUnit, f64>> {
    worst_by(records, |r| r.check.as_str())
}

/// [`worst_text`] of one check id, with the unit its cases state where they state one
/// (`1.1 relative (in units of σ²/16)`).
pub fn worst_text_of(
    records: &[CheckRecord],
    worst: &BTreeMap<&str, BTreeMap<ErrorUnit, f64>>,
    check: &str,
) -> String {
    let note = records
        .iter()
        .find(|r| r.check == check && r.verdict == Verdict::Pass)
        .map(scaled)
        .unwrap_or_default();
    worst_text(worst.get(check)) + &note
}

/// [`worst_passing`] by model family (the model's `family`, else the check id's first part),
/// rates left out; each with the record where it was measured.
pub fn worst_passing_by_family(
    records: &[CheckRecord],
) -> BTreeMap<String, BTreeMap<ErrorUnit, (f64, &CheckRecord)>> {
    let mut out: BTreeMap<String, BTreeMap<ErrorUnit, (f64, &CheckRecord)>> = BTreeMap::new();
    for r in records.iter().filter(|r| r.verdict == Verdict::Pass) {
        let (Some(unit), Some(e)) = (error_unit(r), r.measured.and_then(|m| m.error())) else {
            continue;
        };
        if unit == ErrorUnit::Rate {
            continue;
        }
        let family = r
            .model
            .get("family")
            .and_then(Value::as_str)
            .map(str::to_string)
            .unwrap_or_else(|| r.check.split('.').next().unwrap_or("").to_string());
        let w = out
            .entry(family)
            .or_default()
            .entry(unit)
            .or_insert((0.0, r));
        if e > w.0 {
            *w = (e, r);
        }
    }
    out
}

fn worst_by<'r>(
    records: &'r [CheckRecord],
    key: impl Fn(&'r CheckRecord) -> &'r str,
) -> BTreeMap<&'r str, BTreeMap<ErrorUnit, f64>> {
    let mut out: BTreeMap<&str, BTreeMap<ErrorUnit, f64>> = BTreeMap::new();
    for r in records.iter().filter(|r| r.verdict == Verdict::Pass) {
        if let (Some(unit), Some(e)) = (error_unit(r), r.measured.and_then(|m| m.error())) {
            let w = out.entry(key(r)).or_default().entry(unit).or_insert(0.0);
            *w = w.max(e);
        }
    }
    out
}

/// Worst errors of several units as one cell: `3.2e-16 relative; 2 ulps` (`—` for none).
pub fn worst_text(worst: Option<&BTreeMap<ErrorUnit, f64>>) -> String {
    match worst {
        Some(w) if !w.is_empty() => w
            .iter()
            .map(|(u, e)| u.show(*e))
            .collect::<Vec<_>>()
            .join("; "),
        _ => "—".into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::record::{AppliedTolerance, OracleValue};
    use serde_json::json;

    #[test]
    fn numbers_are_short() {
        let cases = [
            (0.0, "0"),
            (1e308, "1e308"),
            (-1e308, "-1e308"),
            (0.1676627924485398, "0.1676628"),
            (271890.8123, "271890.8"),
            (6.67e-5, "6.67e-5"),
            (1023.0, "1023"),
            (0.5, "0.5"),
            (9.99999999, "10"),
            (1e6, "1e6"),
            (123456.0, "123456"),
            (0.001, "0.001"),
            (f64::NAN, "NaN"),
            (f64::INFINITY, "∞"),
            (5e-324, "4.940656e-324"),
        ];
        for (x, want) in cases {
            assert_eq!(num(x), want, "{x:e}");
        }
        assert_eq!(err(3.2456e-16), "3.2e-16");
        assert_eq!(err(0.05), "0.05");
        assert_eq!(err(1e-10), "1e-10");
    }

    #[test]
    fn names_have_short_numbers_and_no_placeholder() {
        let m = json!({"name": "my_ggx", "alpha": 0.30000000000000004});
        assert_eq!(model_name(&m), "my_ggx alpha=0.3");
        assert_eq!(
            model_name(&json!({"family": "ggx", "alpha": 0.3})),
            "ggx alpha=0.3"
        );
        assert_eq!(model_name(&json!({"alpha": 0.3})), "alpha=0.3");
        let case = json!({"theta": 1.2345678901234567, "route": "2f1", "u": [1e308, 0.5]});
        assert_eq!(
            case_name(&case),
            "route 2f1, theta 1.234568, u [1e308, 0.5]"
        );
        let long = json!({"t": (0..10).collect::<Vec<_>>()});
        assert_eq!(case_name(&long), "t [0, 1, 2, 3, 4, 5, … (10 values)]");
        assert_eq!(count(1, "record", "records"), "1 record");
        assert_eq!(count(2, "record", "records"), "2 records");
    }

    fn record(measured: Measured, tolerance: (&'static str, f64, &'static str)) -> CheckRecord {
        let mut r = CheckRecord::new(
            "smith.lambda_route",
            json!({"family": "ggx", "alpha": 0.3}),
            json!({"theta": 0.5}),
            "seed 001 eq 16",
        );
        r.value = Some(0.1676627924485398);
        r.oracle = Some(OracleValue {
            value: 0.1676627924485398,
            uncertainty: 1e-14,
            kind: "error_bound",
            noise_floor: None,
        });
        r.measured = Some(measured);
        r.tolerance = Some(AppliedTolerance {
            name: tolerance.0,
            value: tolerance.1,
            reason: tolerance.2,
        });
        r.verdict = Verdict::Fail;
        r
    }

    /// The failure of the bug report: a p-value record reads as named quantities, no `Some(`,
    /// no `PValue {`, no 16-digit number.
    #[test]
    fn a_record_reads_as_named_quantities() {
        let r = record(
            Measured::PValue {
                p: 0.0,
                statistic: 271890.81234567,
                dof: 1023,
                alpha: 6.67e-5,
            },
            ("statistical_alpha", 6.67e-5, "family-wise α"),
        );
        let text = block(&r, "  ");
        for bad in ["Some(", "None", "PValue", "0.1676627924485398", "271890.81"] {
            assert!(!text.contains(bad), "{bad} in {text}");
        }
        for good in [
            "✗ smith.lambda_route  ggx alpha=0.3",
            "case      theta 0.5",
            "value     0.1676628 against the oracle 0.1676628 ± 1e-14 (error bound)",
            "measured  p = 0 < α = 6.7e-5 (statistic 271890.8, 1023 dof)",
            "verdict   FAIL",
            "source    seed 001 eq 16",
        ] {
            assert!(text.contains(good), "{good:?} not in\n{text}");
        }
    }

    #[test]
    fn errors_carry_their_units() {
        let rel = record(
            Measured::Relative { error: 3.24e-16 },
            ("closed_form", 1e-10, "two evaluations"),
        );
        assert_eq!(
            measured_against(&rel),
            "relative error 3.2e-16 against closed_form = 1e-10 relative"
        );
        let ulps = record(
            Measured::Absolute { error: 2.0 },
            (
                crate::tolerance::BATCH_SAMPLER.name,
                crate::tolerance::BATCH_SAMPLER.value,
                crate::tolerance::BATCH_SAMPLER.reason,
            ),
        );
        assert_eq!(
            measured_against(&ulps),
            "error 2 ulps against batch_sampler = 4 ulps"
        );
        let rate = record(
            Measured::Rate {
                exponent: -1.0213,
                expected: -1.0,
            },
            ("limit_rate", 0.05, "fit"),
        );
        assert_eq!(
            measured_against(&rate),
            "rate -1.021 (expected -1, |difference| 0.021) against limit_rate = 0.05 Δ rate"
        );
        let mut records = vec![rel.clone(), ulps.clone(), rel];
        for r in &mut records {
            r.verdict = Verdict::Pass;
        }
        records[2].measured = Some(Measured::Absolute { error: 1e-12 });
        records[2].tolerance = None;
        let worst = worst_passing(&records);
        assert_eq!(
            worst_text(worst.get("smith.lambda_route")),
            "3.2e-16 relative; 1e-12 absolute; 2 ulps"
        );
        assert_eq!(ErrorUnit::Ulps.show(1.0), "1 ulp");
        let mut scaled = records[0].clone();
        scaled.case = json!({"unit": "σ²/16"});
        assert_eq!(
            measured(&scaled),
            "relative error 3.2e-16 (in units of σ²/16)"
        );
    }

    /// The ulps rule reads the tolerance's reason: every tolerance of a batch sampler (the
    /// checks that count ulps) opens its reason with "ulps", and no other does.
    #[test]
    fn the_ulps_tolerances_say_so() {
        use crate::tolerance as t;
        let f32_rows = t::F32_TABLE.iter().map(|(_, tol)| tol);
        for tol in [&t::BATCH_SAMPLER, &t::BATCH_SAMPLER_REFERENCE]
            .into_iter()
            .chain(t::TABLE)
            .chain(f32_rows)
        {
            let batch = tol.name.starts_with("batch_sampler");
            assert_eq!(tol.reason.starts_with("ulps"), batch, "{}", tol.name);
        }
    }
}
