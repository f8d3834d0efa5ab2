//! The external protocol, version 1: JSON lines over a child's stdin / stdout (README,
//! "Audit an implementation in any language").
//!
//! Every request is one line `{"v":1,"id":N,"op":"…", …arrays…}`; every answer is one line
//! carrying the same `id` and either the result (`values` or `m`) or `{"error":"…"}`. Batched
//! requests carry arrays of directions (`[x,y,z]`) or uniform pairs (`[u1,u2]`); the answer has
//! exactly one item per item asked. Non-finite numbers may be written as the bare tokens
//! `Infinity`, `-Infinity`, `NaN` (what Python's `json.dumps` writes); NaN is refused as an
//! answer (a protocol error naming the item), infinity is allowed (Λ at grazing incidence).

use mfh_reference::{Masking, Vec3};
use serde::{Deserialize, Serialize};
use serde_json::Value;

/// The protocol version this mfh speaks.
pub const PROTOCOL_VERSION: u32 = 1;

/// The capabilities a child may declare in its `describe` answer.
pub const CAPABILITIES: [&str; 8] = [
    "d",
    "lambda",
    "g1",
    "g2",
    "sample_wm",
    "pdf_wm",
    "sample_wm_visible",
    "pdf_wm_visible",
];

/// A request to the child (serialized with `"op"` as the tag).
#[derive(Debug, Clone, Serialize)]
#[serde(tag = "op", rename_all = "snake_case")]
pub enum Request<'a> {
    /// Which protocol version, capabilities and parameters the child has.
    Describe,
    /// D(m) for each `m`.
    D {
        /// Microfacet normals.
        m: &'a [Vec3],
    },
    /// Λ(w) for each `w`.
    Lambda {
        /// Directions.
        w: &'a [Vec3],
    },
    /// G1(w, m) for each pair.
    G1 {
        /// Directions.
        w: &'a [Vec3],
        /// Microfacet normals.
        m: &'a [Vec3],
    },
    /// G2(wo, wi, m) for each triple, in the given form.
    G2 {
        /// Outgoing directions.
        wo: &'a [Vec3],
        /// Incident directions.
        wi: &'a [Vec3],
        /// Microfacet normals.
        m: &'a [Vec3],
        /// `uncorrelated` or `height_correlated`.
        masking: Masking,
    },
    /// A normal for each uniform pair.
    SampleWm {
        /// Uniform pairs in [0, 1)².
        u: &'a [[f64; 2]],
    },
    /// The density of `sample_wm` at each `m`.
    PdfWm {
        /// Microfacet normals.
        m: &'a [Vec3],
    },
    /// A visible normal for each (wi, u).
    SampleWmVisible {
        /// Incident directions (w_z > 0).
        wi: &'a [Vec3],
        /// Uniform pairs in [0, 1)².
        u: &'a [[f64; 2]],
    },
    /// The density of `sample_wm_visible` for each (wi, m).
    PdfWmVisible {
        /// Incident directions.
        wi: &'a [Vec3],
        /// Microfacet normals.
        m: &'a [Vec3],
    },
    /// The child should exit (no answer expected).
    Shutdown,
}

impl Request<'_> {
    /// The operation name, as on the wire.
    pub fn op(&self) -> &'static str {
        match self {
            Request::Describe => "describe",
            Request::D { .. } => "d",
            Request::Lambda { .. } => "lambda",
            Request::G1 { .. } => "g1",
            Request::G2 { .. } => "g2",
            Request::SampleWm { .. } => "sample_wm",
            Request::PdfWm { .. } => "pdf_wm",
            Request::SampleWmVisible { .. } => "sample_wm_visible",
            Request::PdfWmVisible { .. } => "pdf_wm_visible",
            Request::Shutdown => "shutdown",
        }
    }

    /// The number of items asked (0 for describe and shutdown).
    pub fn len(&self) -> usize {
        match self {
            Request::Describe | Request::Shutdown => 0,
            Request::D { m } | Request::PdfWm { m } => m.len(),
            Request::Lambda { w } | Request::G1 { w, .. } => w.len(),
            Request::G2 { m, .. } | Request::PdfWmVisible { m, .. } => m.len(),
            Request::SampleWm { u } | Request::SampleWmVisible { u, .. } => u.len(),
        }
    }

    /// Whether the request asks for no items.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The request as one line (without the newline), with its version and id.
    pub fn to_line(&self, id: u64) -> String {
        #[derive(Serialize)]
        struct Envelope<'r, 'a> {
            v: u32,
            id: u64,
            #[serde(flatten)]
            request: &'r Request<'a>,
        }
        serde_json::to_string(&Envelope {
            v: PROTOCOL_VERSION,
            id,
            request: self,
        })
        .expect("requests are plain numbers and strings")
    }
}

/// The child's answer to `describe`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Description {
    /// The protocol version the child speaks (must equal [`PROTOCOL_VERSION`]).
    pub protocol: u32,
    /// The implementation's name, for the report.
    #[serde(default)]
    pub name: Option<String>,
    /// Its capabilities, among [`CAPABILITIES`]; `d` is required.
    pub capabilities: Vec<String>,
    /// Its parameters (any JSON object), for the report.
    #[serde(default)]
    pub parameters: Value,
}

impl Description {
    /// Whether the child declared capability `name`.
    pub fn has(&self, name: &str) -> bool {
        self.capabilities.iter().any(|c| c == name)
    }

    /// Checks the version and the capability list: `d` is required, every name must be known,
    /// `g1`/`g2` need `lambda`, `pdf_wm` needs `sample_wm`, visible sampling needs `lambda`.
    pub fn validate(&self) -> Result<(), String> {
        if self.protocol != PROTOCOL_VERSION {
            return Err(format!(
                "protocol version {} is not supported (mfh speaks version {PROTOCOL_VERSION})",
                self.protocol
            ));
        }
        if let Some(bad) = self
            .capabilities
            .iter()
            .find(|c| !CAPABILITIES.contains(&c.as_str()))
        {
            return Err(format!(
                "unknown capability {bad:?} (known: {})",
                CAPABILITIES.join(", ")
            ));
        }
        let needs = [
            ("d", None),
            ("g1", Some("lambda")),
            ("g2", Some("lambda")),
            ("pdf_wm", Some("sample_wm")),
            ("sample_wm_visible", Some("lambda")),
            ("pdf_wm_visible", Some("sample_wm_visible")),
        ];
        if !self.has("d") {
            return Err("capability \"d\" is required".into());
        }
        for (cap, need) in needs {
            if let Some(need) = need {
                if self.has(cap) && !self.has(need) {
                    return Err(format!("capability {cap:?} requires {need:?}"));
                }
            }
        }
        Ok(())
    }
}

/// Rewrites the bare tokens `NaN`, `Infinity` and `-Infinity` (outside strings) as the strings
/// `"NaN"`, `"Infinity"`, `"-Infinity"`, so that a strict JSON parser reads Python's output.
pub fn quote_non_finite(line: &str) -> std::borrow::Cow<'_, str> {
    if !(line.contains("NaN") || line.contains("Infinity")) {
        return std::borrow::Cow::Borrowed(line);
    }
    let mut out = String::with_capacity(line.len() + 16);
    let mut in_string = false;
    let mut escaped = false;
    let mut rest = line;
    while let Some(c) = rest.chars().next() {
        if in_string {
            out.push(c);
            if escaped {
                escaped = false;
            } else if c == '\\' {
                escaped = true;
            } else if c == '"' {
                in_string = false;
            }
            rest = &rest[c.len_utf8()..];
            continue;
        }
        if c == '"' {
            in_string = true;
        }
        let token = ["-Infinity", "Infinity", "NaN"]
            .into_iter()
            .find(|t| rest.starts_with(t));
        if let Some(t) = token {
            out.push('"');
            out.push_str(t);
            out.push('"');
            rest = &rest[t.len()..];
        } else {
            out.push(c);
            rest = &rest[c.len_utf8()..];
        }
    }
    std::borrow::Cow::Owned(out)
}

/// A number of an answer: a JSON number or one of the strings `"NaN"`, `"Infinity"`,
/// `"-Infinity"`. Deserialized by hand: serde's `untagged` buffers every value and tries each
/// variant in turn, which made parsing an answer of 65 536 directions ~4× slower.
#[derive(Debug, Clone, Copy)]
pub enum Number {
    /// A JSON number.
    Finite(f64),
    /// A non-finite number written as a token.
    Token(NonFinite),
}

/// A non-finite number token.
#[derive(Debug, Clone, Copy, Deserialize)]
pub enum NonFinite {
    /// NaN.
    NaN,
    /// +∞.
    Infinity,
    /// −∞.
    #[serde(rename = "-Infinity")]
    NegInfinity,
}

impl<'de> Deserialize<'de> for Number {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct Visitor;
        impl serde::de::Visitor<'_> for Visitor {
            type Value = Number;
            fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str("a number, or \"NaN\", \"Infinity\" or \"-Infinity\"")
            }
            fn visit_f64<E: serde::de::Error>(self, v: f64) -> Result<Number, E> {
                Ok(Number::Finite(v))
            }
            fn visit_i64<E: serde::de::Error>(self, v: i64) -> Result<Number, E> {
                Ok(Number::Finite(v as f64))
            }
            fn visit_u64<E: serde::de::Error>(self, v: u64) -> Result<Number, E> {
                Ok(Number::Finite(v as f64))
            }
            fn visit_str<E: serde::de::Error>(self, v: &str) -> Result<Number, E> {
                match v {
                    "NaN" => Ok(Number::Token(NonFinite::NaN)),
                    "Infinity" => Ok(Number::Token(NonFinite::Infinity)),
                    "-Infinity" => Ok(Number::Token(NonFinite::NegInfinity)),
                    _ => Err(E::invalid_value(serde::de::Unexpected::Str(v), &self)),
                }
            }
        }
        deserializer.deserialize_any(Visitor)
    }
}

impl Number {
    /// The value as an f64.
    pub fn value(self) -> f64 {
        match self {
            Number::Finite(x) => x,
            Number::Token(NonFinite::NaN) => f64::NAN,
            Number::Token(NonFinite::Infinity) => f64::INFINITY,
            Number::Token(NonFinite::NegInfinity) => f64::NEG_INFINITY,
        }
    }
}

/// An answer line, before its arrays are checked against the request.
#[derive(Debug, Deserialize)]
pub struct Answer {
    /// The id of the request answered.
    pub id: Option<u64>,
    /// Scalar results.
    #[serde(default)]
    pub values: Option<Vec<Number>>,
    /// Sampled directions.
    #[serde(default)]
    pub m: Option<Vec<[Number; 3]>>,
    /// The child's own error message.
    #[serde(default)]
    pub error: Option<String>,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn requests_are_versioned_lines_with_ids() {
        let m = [[0.0, 0.0, 1.0], [0.6, 0.0, 0.8]];
        let line = Request::D { m: &m }.to_line(7);
        let v: Value = serde_json::from_str(&line).unwrap();
        assert_eq!(v["v"], 1);
        assert_eq!(v["id"], 7);
        assert_eq!(v["op"], "d");
        assert_eq!(v["m"][1][0], 0.6);
        let w = [[0.6, 0.0, 0.8]];
        let line = Request::G2 {
            wo: &w,
            wi: &w,
            m: &w,
            masking: Masking::HeightCorrelated,
        }
        .to_line(1);
        assert!(line.contains(r#""masking":"height_correlated""#), "{line}");
        assert!(Request::Describe.to_line(0).contains(r#""op":"describe""#));
    }

    #[test]
    fn python_non_finite_tokens_are_read_and_strings_left_alone() {
        let line = r#"{"id":1,"values":[1.5,Infinity,-Infinity,NaN],"error":"NaN Infinity"}"#;
        let a: Answer = serde_json::from_str(&quote_non_finite(line)).unwrap();
        let v: Vec<f64> = a.values.unwrap().into_iter().map(Number::value).collect();
        assert_eq!(v[0], 1.5);
        assert_eq!(v[1], f64::INFINITY);
        assert_eq!(v[2], f64::NEG_INFINITY);
        assert!(v[3].is_nan());
        assert_eq!(a.error.as_deref(), Some("NaN Infinity"));
        // Integers are numbers; other strings are not.
        let a: Answer = serde_json::from_str(r#"{"id":2,"values":[0,-3,1e308]}"#).unwrap();
        let v: Vec<f64> = a.values.unwrap().into_iter().map(Number::value).collect();
        assert_eq!(v, [0.0, -3.0, 1e308]);
        assert!(serde_json::from_str::<Answer>(r#"{"id":2,"values":["inf"]}"#).is_err());
    }

    #[test]
    fn descriptions_are_validated() {
        let d = |caps: &[&str], protocol| Description {
            protocol,
            name: None,
            capabilities: caps.iter().map(|s| s.to_string()).collect(),
            parameters: Value::Null,
        };
        assert!(d(&["d", "lambda", "g2"], 1).validate().is_ok());
        assert!(d(&["lambda"], 1).validate().unwrap_err().contains("\"d\""));
        assert!(d(&["d"], 2).validate().unwrap_err().contains("version 2"));
        assert!(d(&["d", "g1"], 1)
            .validate()
            .unwrap_err()
            .contains("lambda"));
        assert!(d(&["d", "sample"], 1)
            .validate()
            .unwrap_err()
            .contains("unknown"));
    }
}
