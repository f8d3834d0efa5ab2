//! The arguments of `mfh eval` queries, shared by the NDF quantities ([`super::ndf`]) and the
//! SG/ASG ones ([`super::sg`]): the error kinds, the JSON number convention, and the parsing of
//! numbers, unit vectors and directions, each error naming the key and its limit.

use mfh_reference::geometry::{from_spherical, is_unit, Vec3};
use mfh_reference::{ParamError, QueryError};
use serde_json::{json, Map, Value};

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

pub(crate) fn no_route(route: Option<&str>, quantity: &str) -> Result<(), EvalError> {
    match route {
        None | Some("default") => Ok(()),
        Some(r) => Err(EvalError::Route(format!(
            "route {r:?} is not available: {quantity} has a single route"
        ))),
    }
}

/// `v` as an array of exactly `N` numbers, or None (the callers name the key in their error).
pub(crate) fn numbers<const N: usize>(v: &Value) -> Option<[f64; N]> {
    let a = v.as_array().filter(|a| a.len() == N)?;
    let mut out = [0.0; N];
    for (o, x) in out.iter_mut().zip(a) {
        *o = x.as_f64()?;
    }
    Some(out)
}

/// The sample point `"u": [u1, u2]` in [0, 1)².
pub(crate) fn unit_square(q: &Map<String, Value>) -> Result<[f64; 2], EvalError> {
    let u = q
        .get("u")
        .and_then(numbers::<2>)
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
pub(crate) fn visible_incidence(q: &Map<String, Value>) -> Result<Vec3, EvalError> {
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

pub(crate) fn finite(q: &Map<String, Value>, key: &str) -> Result<f64, EvalError> {
    optional_finite(q, key)?.ok_or_else(|| EvalError::Argument(format!("missing \"{key}\"")))
}

/// `q[key]` as a finite number, `None` when absent; an [`EvalError::Argument`] naming the key
/// otherwise.
pub(crate) fn optional_finite(q: &Map<String, Value>, key: &str) -> Result<Option<f64>, EvalError> {
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

pub(crate) fn optional_vector(
    q: &Map<String, Value>,
    key: &str,
) -> Result<Option<Vec3>, EvalError> {
    let Some(v) = q.get(key) else {
        return Ok(None);
    };
    let a = numbers::<3>(v)
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
pub(crate) fn direction(q: &Map<String, Value>, key: &str) -> Result<Vec3, EvalError> {
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
