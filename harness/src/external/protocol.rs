//! The external protocol: JSON lines over a child's stdin / stdout (docs/external-protocol.md),
//! in two versions that differ only in how arrays travel.
//!
//! Every request is one line `{"v":V,"id":N,"op":"…", …arrays…}`; every answer is one line
//! carrying the same `id` and either the result (`values` or `m`) or `{"error":"…"}`. The
//! answer has exactly one item per item asked. NaN is refused as an answer (a protocol error
//! naming the item); infinity is allowed (Λ at grazing incidence).
//!
//! - **Version 1**: arrays are JSON arrays of directions (`[x,y,z]`) or uniform pairs
//!   (`[u1,u2]`). Non-finite numbers may be written as the bare tokens `Infinity`, `-Infinity`,
//!   `NaN` (what Python's `json.dumps` writes).
//! - **Version 2**: arrays are base64 (standard alphabet, padded) of little-endian IEEE-754
//!   f64, row-major (a direction is 3 numbers, a pair 2, a value 1), inside the same JSON line;
//!   requests also carry `"n"`, the number of items. Why base64 inside the line rather than a
//!   binary frame after a header line: the line framing, its length limit, the timeout and the
//!   error excerpts stay exactly those of version 1, and a child decodes an array with one
//!   library call (`np.frombuffer(base64.b64decode(s), '<f8')`, or `array('d', …)` in pure
//!   Python); the cost is 4/3 of the raw bytes, against ~20 bytes of text per number (and
//!   Python's float ↔ text conversion, which capped version 1 at ~1.5e5 samples/s). A version-2
//!   answer may also carry plain JSON arrays (small answers, hand-written children).
//!
//! Negotiation: mfh's `describe` request is a version-1 line that also carries
//! `"versions":[1,2]`; the child answers `"protocol":1` or `2`, and every later request uses
//! that version (a version-1 child needs no change).

use base64::Engine;
use mfh_reference::{Masking, Vec3};
use serde::{Deserialize, Serialize};
use serde_json::Value;
use std::marker::PhantomData;

/// The protocol versions this mfh speaks, oldest first (offered in `describe`).
pub const VERSIONS: [u32; 2] = [1, 2];

/// The newest protocol version this mfh speaks.
pub const PROTOCOL_VERSION: u32 = 2;

/// The base64 flavour of version 2: the standard alphabet with padding (Python's
/// `base64.b64encode`).
const BASE64: base64::engine::GeneralPurpose = base64::engine::general_purpose::STANDARD;

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

    /// The request's arrays: (field name, numbers row-major).
    fn arrays(&self) -> Vec<(&'static str, &[f64])> {
        match self {
            Request::Describe | Request::Shutdown => vec![],
            Request::D { m } | Request::PdfWm { m } => vec![("m", m.as_flattened())],
            Request::Lambda { w } => vec![("w", w.as_flattened())],
            Request::G1 { w, m } => vec![("w", w.as_flattened()), ("m", m.as_flattened())],
            Request::G2 { wo, wi, m, .. } => vec![
                ("wo", wo.as_flattened()),
                ("wi", wi.as_flattened()),
                ("m", m.as_flattened()),
            ],
            Request::SampleWm { u } => vec![("u", u.as_flattened())],
            Request::SampleWmVisible { wi, u } => {
                vec![("wi", wi.as_flattened()), ("u", u.as_flattened())]
            }
            Request::PdfWmVisible { wi, m } => {
                vec![("wi", wi.as_flattened()), ("m", m.as_flattened())]
            }
        }
    }

    /// The request as one line (without the newline) in protocol `version`, with its id.
    /// `describe` is always a version-1 line offering [`VERSIONS`].
    pub fn to_line(&self, id: u64, version: u32) -> String {
        #[derive(Serialize)]
        struct Envelope<'r, 'a> {
            v: u32,
            id: u64,
            #[serde(flatten)]
            request: &'r Request<'a>,
        }
        if let Request::Describe = self {
            return serde_json::json!({"v": 1, "id": id, "op": "describe", "versions": VERSIONS})
                .to_string();
        }
        if version < 2 {
            return serde_json::to_string(&Envelope {
                v: 1,
                id,
                request: self,
            })
            .expect("requests are plain numbers and strings");
        }
        let mut line = serde_json::Map::new();
        line.insert("v".into(), version.into());
        line.insert("id".into(), id.into());
        line.insert("op".into(), self.op().into());
        if !matches!(self, Request::Shutdown) {
            line.insert("n".into(), self.len().into());
        }
        for (name, numbers) in self.arrays() {
            line.insert(name.into(), encode(numbers).into());
        }
        if let Request::G2 { masking, .. } = self {
            let masking = serde_json::to_value(masking).expect("an enum of names");
            line.insert("masking".into(), masking);
        }
        Value::Object(line).to_string()
    }
}

/// Numbers as version 2 sends them: base64 of little-endian f64.
pub fn encode(numbers: &[f64]) -> String {
    let mut bytes = Vec::with_capacity(8 * numbers.len());
    for x in numbers {
        bytes.extend_from_slice(&x.to_le_bytes());
    }
    BASE64.encode(bytes)
}

/// The child's answer to `describe`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Description {
    /// The protocol version the child chose among [`VERSIONS`]; later requests use it.
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
        if !VERSIONS.contains(&self.protocol) {
            return Err(format!(
                "protocol version {} is not supported (mfh speaks versions {VERSIONS:?})",
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
    pub values: Option<Wire<Number>>,
    /// Sampled directions.
    #[serde(default)]
    pub m: Option<Wire<[Number; 3]>>,
    /// The child's own error message.
    #[serde(default)]
    pub error: Option<String>,
}

/// An answer's array as it came: a JSON array (version 1, or a small version-2 answer) or a
/// base64 string of little-endian f64 (version 2). Deserialized by hand for the same reason
/// as [`Number`]: `untagged` would buffer the whole array before trying each form.
#[derive(Debug, Clone)]
pub enum Wire<T> {
    /// A JSON array of items.
    Json(Vec<T>),
    /// Base64 of little-endian f64, row-major.
    Base64(String),
}

/// An item of an answer array: its numbers, in order.
pub trait Item {
    /// Numbers per item (1 for a value, 3 for a direction).
    const WIDTH: usize;
    /// Appends the item's numbers to `out`.
    fn push_to(self, out: &mut Vec<f64>);
}

impl Item for Number {
    const WIDTH: usize = 1;
    fn push_to(self, out: &mut Vec<f64>) {
        out.push(self.value());
    }
}

impl Item for [Number; 3] {
    const WIDTH: usize = 3;
    fn push_to(self, out: &mut Vec<f64>) {
        out.extend(self.map(Number::value));
    }
}

impl<T: Item> Wire<T> {
    /// The array's numbers, row-major ([`Item::WIDTH`] per item). Base64 is refused in
    /// protocol version 1; invalid base64, or a byte count that is not a whole number of items,
    /// is an error saying so.
    pub fn numbers(self, version: u32) -> Result<Vec<f64>, String> {
        match self {
            Wire::Json(items) => {
                let mut out = Vec::with_capacity(items.len() * T::WIDTH);
                for item in items {
                    item.push_to(&mut out);
                }
                Ok(out)
            }
            Wire::Base64(_) if version < 2 => Err(
                "a string where protocol version 1 wants a JSON array (base64 arrays are \
                 version 2: answer \"protocol\":2 to describe)"
                    .into(),
            ),
            Wire::Base64(text) => {
                let bytes = BASE64.decode(text.as_bytes()).map_err(|e| {
                    let start: String = text.chars().take(40).collect();
                    format!("invalid base64 ({e}) in {start:?} ({} bytes)", text.len())
                })?;
                let item_bytes = 8 * T::WIDTH;
                if bytes.len() % item_bytes != 0 {
                    return Err(format!(
                        "{} bytes of base64-decoded data, not a whole number of items of {} \
                         little-endian f64 ({item_bytes} bytes each)",
                        bytes.len(),
                        T::WIDTH
                    ));
                }
                Ok(bytes
                    .chunks_exact(8)
                    .map(|b| f64::from_le_bytes(b.try_into().expect("chunks of 8")))
                    .collect())
            }
        }
    }
}

impl<'de, T: Deserialize<'de>> Deserialize<'de> for Wire<T> {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct Visitor<T>(PhantomData<T>);
        impl<'de, T: Deserialize<'de>> serde::de::Visitor<'de> for Visitor<T> {
            type Value = Wire<T>;
            fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str("a JSON array, or a base64 string of little-endian f64")
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(
                self,
                mut seq: A,
            ) -> Result<Wire<T>, A::Error> {
                // The line is at most MAX_LINE_BYTES long, so is this vector.
                let mut items = Vec::new();
                while let Some(item) = seq.next_element()? {
                    items.push(item);
                }
                Ok(Wire::Json(items))
            }
            fn visit_str<E: serde::de::Error>(self, v: &str) -> Result<Wire<T>, E> {
                Ok(Wire::Base64(v.to_owned()))
            }
            fn visit_string<E: serde::de::Error>(self, v: String) -> Result<Wire<T>, E> {
                Ok(Wire::Base64(v))
            }
        }
        deserializer.deserialize_any(Visitor(PhantomData))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn requests_are_versioned_lines_with_ids() {
        let m = [[0.0, 0.0, 1.0], [0.6, 0.0, 0.8]];
        let line = Request::D { m: &m }.to_line(7, 1);
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
        .to_line(1, 1);
        assert!(line.contains(r#""masking":"height_correlated""#), "{line}");
        // describe is a version-1 line whatever the version, and offers both.
        for version in VERSIONS {
            let v: Value = serde_json::from_str(&Request::Describe.to_line(0, version)).unwrap();
            assert_eq!(v["op"], "describe");
            assert_eq!(v["v"], 1);
            assert_eq!(v["versions"], serde_json::json!([1, 2]));
        }
    }

    /// Version 2: the arrays are base64 of little-endian f64, row-major, with the item count;
    /// the bytes are checked against a hand-written expectation (1.0 = 0x3FF0…, -2.5 = 0xC004…).
    #[test]
    fn version_2_arrays_are_base64_little_endian_f64() {
        let u = [[1.0, -2.5], [0.0, f64::INFINITY]];
        let line = Request::SampleWm { u: &u }.to_line(3, 2);
        let v: Value = serde_json::from_str(&line).unwrap();
        assert_eq!((v["v"].as_u64(), v["id"].as_u64()), (Some(2), Some(3)));
        assert_eq!(
            (v["op"].as_str(), v["n"].as_u64()),
            (Some("sample_wm"), Some(2))
        );
        let bytes = BASE64.decode(v["u"].as_str().unwrap()).unwrap();
        let mut want = vec![0, 0, 0, 0, 0, 0, 0xF0, 0x3F, 0, 0, 0, 0, 0, 0, 0x04, 0xC0];
        want.extend([0; 8]);
        want.extend([0, 0, 0, 0, 0, 0, 0xF0, 0x7F]);
        assert_eq!(bytes, want);
        let w = [[0.6, 0.0, 0.8]];
        let line = Request::G2 {
            wo: &w,
            wi: &w,
            m: &w,
            masking: Masking::Uncorrelated,
        }
        .to_line(4, 2);
        let v: Value = serde_json::from_str(&line).unwrap();
        assert_eq!(v["masking"], "uncorrelated");
        for k in ["wo", "wi", "m"] {
            assert_eq!(v[k].as_str().unwrap(), encode(&[0.6, 0.0, 0.8]), "{k}");
        }
        assert!(Request::Shutdown
            .to_line(5, 2)
            .contains(r#""op":"shutdown""#));
        // The example line of docs/external-protocol.md: u = (0.25, 0.5).
        let line = Request::SampleWm { u: &[[0.25, 0.5]] }.to_line(3, 2);
        assert!(line.contains(r#""u":"AAAAAAAA0D8AAAAAAADgPw==""#), "{line}");
    }

    /// Answers: base64 arrays decode in version 2 (also JSON arrays), are refused in version 1,
    /// and invalid base64 or a ragged byte count is an error naming what is wrong.
    #[test]
    fn version_2_answers_decode_and_bad_ones_are_named() {
        let dirs = [0.6, 0.0, 0.8, 0.0, 0.0, 1.0];
        let line = format!(r#"{{"id":1,"m":"{}"}}"#, encode(&dirs));
        let a: Answer = serde_json::from_str(&line).unwrap();
        assert_eq!(a.m.clone().unwrap().numbers(2).unwrap(), dirs);
        assert!(a.m.unwrap().numbers(1).unwrap_err().contains("version 1"));
        let a: Answer = serde_json::from_str(r#"{"id":1,"values":[1.5,2]}"#).unwrap();
        assert_eq!(a.values.unwrap().numbers(2).unwrap(), [1.5, 2.0]);
        let a: Answer = serde_json::from_str(r#"{"id":1,"values":"not base64!"}"#).unwrap();
        let e = a.values.unwrap().numbers(2).unwrap_err();
        assert!(e.contains("invalid base64"), "{e}");
        // Two values are 16 bytes: not a whole number of 24-byte directions.
        let line = format!(r#"{{"id":1,"m":"{}"}}"#, encode(&[1.0, 2.0]));
        let a: Answer = serde_json::from_str(&line).unwrap();
        let e = a.m.unwrap().numbers(2).unwrap_err();
        assert!(e.contains("16 bytes") && e.contains("24 bytes"), "{e}");
    }

    #[test]
    fn python_non_finite_tokens_are_read_and_strings_left_alone() {
        let line = r#"{"id":1,"values":[1.5,Infinity,-Infinity,NaN],"error":"NaN Infinity"}"#;
        let a: Answer = serde_json::from_str(&quote_non_finite(line)).unwrap();
        let v = a.values.unwrap().numbers(1).unwrap();
        assert_eq!(v[0], 1.5);
        assert_eq!(v[1], f64::INFINITY);
        assert_eq!(v[2], f64::NEG_INFINITY);
        assert!(v[3].is_nan());
        assert_eq!(a.error.as_deref(), Some("NaN Infinity"));
        // Integers are numbers; other strings are not.
        let a: Answer = serde_json::from_str(r#"{"id":2,"values":[0,-3,1e308]}"#).unwrap();
        let v = a.values.unwrap().numbers(1).unwrap();
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
        assert!(d(&["d"], 2).validate().is_ok());
        assert!(d(&["d"], 3).validate().unwrap_err().contains("version 3"));
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
