//! `mfh eval` for reference BSDFs: the quantities `bsdf_eval`, `bsdf_pdf` and
//! `bsdf_sample` of a BSDF spec given as `"bsdf"` (a `mfh_reference::bsdf::BsdfSpec`, e.g.
//! `{"bsdf": "dielectric", "eta": 1.5, "ndf": {"family": "ggx", "alpha": 0.3}}`). These
//! queries carry no `"model"`.
//!
//! | quantity | arguments | answer |
//! |---|---|---|
//! | `bsdf_eval` | `wi`, `wo` | f(wi, wo) · \|cos θo\| |
//! | `bsdf_pdf` | `wi`, `wo` | the solid-angle density of `wo` sampled for `wi` |
//! | `bsdf_sample` | `wi`, `u` (three numbers in [0, 1)) | `{"wo": [x, y, z], "pdf": p, "weight": w}`; a failed sample answers `{"wo": null, "pdf": 0, "weight": 0}` |
//!
//! Directions are unit vectors `[x, y, z]` in the local frame (normal +z, pointing outside),
//! either hemisphere, pointing away from the surface (the conventions of
//! `mfh_reference::bsdf`).

use super::args::{no_route, number, numbers, EvalError, UNIT_TOLERANCE};
use mfh_reference::bsdf::{Bsdf, BsdfSpec};
use mfh_reference::geometry::{is_unit, Vec3};
use serde_json::{json, Map, Value};

/// The BSDF quantities this module answers.
pub const QUANTITIES: [&str; 3] = ["bsdf_eval", "bsdf_pdf", "bsdf_sample"];

/// The argument keys each BSDF quantity takes (besides `bsdf`, `quantity` and `route`); None
/// for a quantity this module does not answer.
pub fn arguments(quantity: &str) -> Option<&'static [&'static str]> {
    Some(match quantity {
        "bsdf_eval" | "bsdf_pdf" => &["wi", "wo"],
        "bsdf_sample" => &["wi", "u"],
        _ => return None,
    })
}

/// Answers `quantity` if it is a BSDF quantity (None otherwise), with the arguments in `q`.
pub fn evaluate(
    quantity: &str,
    q: &Map<String, Value>,
    route: Option<&str>,
) -> Option<Result<Value, EvalError>> {
    if !QUANTITIES.contains(&quantity) {
        return None;
    }
    Some(answer(quantity, q, route))
}

/// The BSDF of the query's `"bsdf"` spec; a `model` error naming the bad field otherwise.
fn bsdf(q: &Map<String, Value>) -> Result<std::sync::Arc<dyn Bsdf>, EvalError> {
    let value = q
        .get("bsdf")
        .ok_or_else(|| EvalError::Argument("missing \"bsdf\" (a BSDF spec)".into()))?;
    let spec: BsdfSpec = serde_json::from_value(value.clone()).map_err(|e| {
        EvalError::Model(format!(
            "bad bsdf spec: {}",
            crate::messages::json_error_message(&e)
        ))
    })?;
    spec.build()
        .map_err(|e| EvalError::Model(format!("bsdf.{}: {e}", e.field())))
}

/// The unit direction `q[key]`, finite and of unit length within [`UNIT_TOLERANCE`].
fn direction(q: &Map<String, Value>, key: &str) -> Result<Vec3, EvalError> {
    let v = q
        .get(key)
        .ok_or_else(|| EvalError::Argument(format!("missing \"{key}\" ([x, y, z])")))?;
    let a = numbers::<3>(v).ok_or_else(|| {
        EvalError::Argument(format!(
            "\"{key}\" must be [x, y, z], three finite numbers (got {v})"
        ))
    })?;
    if !a.iter().all(|x| x.is_finite()) {
        return Err(EvalError::Argument(format!(
            "\"{key}\" must be finite (got {a:?})"
        )));
    }
    if !is_unit(a, UNIT_TOLERANCE) {
        return Err(EvalError::Argument(format!(
            "\"{key}\" must be a unit vector (|‖{key}‖ − 1| ≤ {UNIT_TOLERANCE:e}; got {a:?})"
        )));
    }
    Ok(a)
}

/// The sample point `"u": [u0, u1, u2]` in [0, 1)³ (`u0` chooses the lobe).
fn unit_cube(q: &Map<String, Value>) -> Result<[f64; 3], EvalError> {
    let v = q
        .get("u")
        .ok_or_else(|| EvalError::Argument("missing \"u\" ([u0, u1, u2])".into()))?;
    let u = numbers::<3>(v).ok_or_else(|| {
        EvalError::Argument(format!(
            "\"u\" must be [u0, u1, u2], three numbers (got {v})"
        ))
    })?;
    if let Some((i, x)) = u.iter().enumerate().find(|(_, x)| !(0.0..1.0).contains(*x)) {
        return Err(EvalError::Argument(format!(
            "\"u\"[{i}] must lie in [0, 1) (got {x})"
        )));
    }
    Ok(u)
}

fn answer(quantity: &str, q: &Map<String, Value>, route: Option<&str>) -> Result<Value, EvalError> {
    if let Some(r) = q.get("route") {
        if !(r.is_string() || r.is_null()) {
            return Err(EvalError::Argument("\"route\" must be a string".into()));
        }
    }
    no_route(route, quantity)?;
    let b = bsdf(q)?;
    let wi = direction(q, "wi")?;
    match quantity {
        "bsdf_eval" => Ok(number(b.eval(wi, direction(q, "wo")?))),
        "bsdf_pdf" => Ok(number(b.pdf(wi, direction(q, "wo")?))),
        _ => Ok(match b.sample(wi, unit_cube(q)?) {
            Some(s) => json!({
                "wo": s.wo.iter().map(|c| number(*c)).collect::<Vec<_>>(),
                "pdf": number(s.pdf),
                "weight": number(s.weight),
            }),
            None => json!({ "wo": Value::Null, "pdf": 0.0, "weight": 0.0 }),
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::super::testing::{error_kind, value};
    use super::*;

    const GLASS: &str = r#"{"bsdf":"dielectric","eta":1.5,"ndf":{"family":"ggx","alpha":0.3}}"#;
    const METAL: &str = r#"{"bsdf":"conductor","n":0.2,"k":3.0,"fresnel":"schlick","ndf":{"family":"beckmann","alpha":0.2}}"#;

    fn build(spec: &str) -> std::sync::Arc<dyn Bsdf> {
        serde_json::from_str::<BsdfSpec>(spec)
            .unwrap()
            .build()
            .unwrap()
    }

    fn message(line: &str) -> String {
        let a = super::super::answer_line(line);
        a["error"]["message"]
            .as_str()
            .unwrap_or_default()
            .to_string()
    }

    #[test]
    fn eval_pdf_and_sample_answer_the_library() {
        let wi = [0.6, 0.0, 0.8];
        let wo = [-0.4, 0.0, -0.916_515_138_991_168];
        for spec in [GLASS, METAL] {
            let b = build(spec);
            for (q, want) in [("bsdf_eval", b.eval(wi, wo)), ("bsdf_pdf", b.pdf(wi, wo))] {
                let got = value(&format!(
                    r#"{{"bsdf":{spec},"quantity":"{q}","wi":[0.6,0,0.8],"wo":{wo:?}}}"#
                ));
                assert_eq!(
                    got.as_f64().unwrap().to_bits(),
                    want.to_bits(),
                    "{spec} {q}"
                );
            }
            let got = value(&format!(
                r#"{{"bsdf":{spec},"quantity":"bsdf_sample","wi":[0.6,0,0.8],"u":[0.7,0.3,0.6]}}"#
            ));
            let want = b.sample(wi, [0.7, 0.3, 0.6]).unwrap();
            for k in 0..3 {
                assert_eq!(got["wo"][k].as_f64().unwrap(), want.wo[k]);
            }
            assert_eq!(got["pdf"].as_f64().unwrap(), want.pdf);
            assert_eq!(got["weight"].as_f64().unwrap(), want.weight);
        }
        // The dielectric transmits: some wo below the horizon has a positive value.
        let b = build(GLASS);
        assert!(b.eval(wi, wo) > 0.0 && b.pdf(wi, wo) > 0.0);
    }

    #[test]
    fn a_failed_sample_answers_pdf_and_weight_zero() {
        // A conductor seen from below reflects nothing: every sample fails.
        let got = value(&format!(
            r#"{{"bsdf":{METAL},"quantity":"bsdf_sample","wi":[0,0,-1],"u":[0.5,0.5,0.5]}}"#
        ));
        assert_eq!(got, json!({"wo": null, "pdf": 0.0, "weight": 0.0}));
    }

    #[test]
    fn errors_name_the_field_and_the_limit() {
        for (line, kind, needle) in [
            (
                r#"{"bsdf":{"bsdf":"dielectric","eta":20,"ndf":{"family":"ggx","alpha":0.3}},"quantity":"bsdf_eval","wi":[0,0,1],"wo":[0,0,1]}"#.to_string(),
                "model",
                "eta",
            ),
            (
                r#"{"bsdf":{"bsdf":"plastic"},"quantity":"bsdf_eval","wi":[0,0,1],"wo":[0,0,1]}"#.to_string(),
                "model",
                "plastic",
            ),
            (
                r#"{"bsdf":{"bsdf":"conductor","n":0.2,"k":3,"ndf":{"family":"ggx","alpha":-1}},"quantity":"bsdf_pdf","wi":[0,0,1],"wo":[0,0,1]}"#.to_string(),
                "model",
                "ndf",
            ),
            (
                format!(r#"{{"bsdf":{GLASS},"quantity":"bsdf_eval","wi":[0,0,2],"wo":[0,0,1]}}"#),
                "argument",
                "\"wi\" must be a unit vector",
            ),
            (
                format!(r#"{{"bsdf":{GLASS},"quantity":"bsdf_eval","wi":[0,0,1],"wo":[0,"nan",1]}}"#),
                "argument",
                "\"wo\"",
            ),
            (
                format!(r#"{{"bsdf":{GLASS},"quantity":"bsdf_eval","wi":[0,0,1]}}"#),
                "argument",
                "missing \"wo\"",
            ),
            (
                format!(r#"{{"bsdf":{GLASS},"quantity":"bsdf_sample","wi":[0,0,1],"u":[0.5,1.0,0.2]}}"#),
                "argument",
                "\"u\"[1] must lie in [0, 1)",
            ),
            (
                format!(r#"{{"bsdf":{GLASS},"quantity":"bsdf_sample","wi":[0,0,1],"u":[0.5,0.2]}}"#),
                "argument",
                "\"u\" must be [u0, u1, u2]",
            ),
            (
                format!(r#"{{"bsdf":{GLASS},"quantity":"bsdf_sample","wi":[0,0,1],"u":[0.5,0.2,0.1],"wo":[0,0,1]}}"#),
                "argument",
                "unknown key \"wo\"",
            ),
            (
                format!(r#"{{"bsdf":{GLASS},"quantity":"bsdf_pdf","wi":[0,0,1],"wo":[0,0,1],"route":"x"}}"#),
                "route",
                "single route",
            ),
            (
                r#"{"quantity":"bsdf_pdf","wi":[0,0,1],"wo":[0,0,1]}"#.to_string(),
                "argument",
                "missing \"bsdf\"",
            ),
        ] {
            assert_eq!(error_kind(&line), kind, "{line}");
            let m = message(&line);
            assert!(m.contains(needle), "{line}: {m}");
        }
    }

    #[test]
    fn every_quantity_has_its_argument_keys() {
        for q in QUANTITIES {
            assert!(arguments(q).is_some(), "{q}");
        }
        assert!(arguments("d").is_none());
    }
}
