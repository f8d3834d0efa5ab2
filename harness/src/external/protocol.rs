//! The external protocol: JSON lines over a child's stdin / stdout (docs/external-protocol.md),
//! in two versions that differ only in how arrays travel.
//!
//! Every request is one line `{"v":V,"id":N,"op":"…", …arrays…}`; every answer is one line
//! carrying the same `id` and either the result (`values` or `m`) or `{"error":"…"}`. The
//! answer has exactly one item per item asked. Infinity is allowed (Λ at grazing incidence);
//! NaN is read as NaN (a defect of the model, not of the protocol: `model.rs` lists it by
//! array and item, and the checks judge it as a Rust model's).
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
use mfh_reference::bsdf::Transport;
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
pub const CAPABILITIES: [&str; 11] = [
    "d",
    "lambda",
    "g1",
    "g2",
    "sample_wm",
    "pdf_wm",
    "sample_wm_visible",
    "pdf_wm_visible",
    "bsdf_eval",
    "bsdf_pdf",
    "bsdf_sample",
];

/// The capabilities of an NDF (the first of them, `d`, required by the others).
pub const NDF_CAPABILITIES: [&str; 8] = [
    "d",
    "lambda",
    "g1",
    "g2",
    "sample_wm",
    "pdf_wm",
    "sample_wm_visible",
    "pdf_wm_visible",
];

/// The capabilities of a BSDF: all three are needed for a BSDF audit.
pub const BSDF_CAPABILITIES: [&str; 3] = ["bsdf_eval", "bsdf_pdf", "bsdf_sample"];

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
    /// eval(wi, wo) = f(wi, wo)·|cos θo| of a BSDF for each pair.
    BsdfEval {
        /// The directions queried from (either hemisphere).
        wi: &'a [Vec3],
        /// The other directions.
        wo: &'a [Vec3],
    },
    /// The solid-angle density of `bsdf_sample`'s wo for each pair.
    BsdfPdf {
        /// The directions queried from.
        wi: &'a [Vec3],
        /// The other directions.
        wo: &'a [Vec3],
    },
    /// A sampled (wo, pdf, weight) for each (wi, u).
    BsdfSample {
        /// The directions queried from.
        wi: &'a [Vec3],
        /// Uniform triples in [0, 1)³ (u0 chooses the lobe, u1 and u2 the normal).
        u: &'a [[f64; 3]],
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
            Request::BsdfEval { .. } => "bsdf_eval",
            Request::BsdfPdf { .. } => "bsdf_pdf",
            Request::BsdfSample { .. } => "bsdf_sample",
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
            Request::BsdfEval { wo, .. } | Request::BsdfPdf { wo, .. } => wo.len(),
            Request::BsdfSample { u, .. } => u.len(),
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
            Request::BsdfEval { wi, wo } | Request::BsdfPdf { wi, wo } => {
                vec![("wi", wi.as_flattened()), ("wo", wo.as_flattened())]
            }
            Request::BsdfSample { wi, u } => {
                vec![("wi", wi.as_flattened()), ("u", u.as_flattened())]
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
    /// Its capabilities, among [`CAPABILITIES`]: an NDF's (`d` and what it allows), a
    /// BSDF's (`bsdf_eval`, `bsdf_pdf`, `bsdf_sample`), or both.
    pub capabilities: Vec<String>,
    /// Its parameters (any JSON object), for the report.
    #[serde(default)]
    pub parameters: Value,
    /// A BSDF's relative index η_inside/η_outside (absent: reflection only); checked by
    /// [`Description::validate`], read by [`Description::eta`].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub eta: Option<Value>,
    /// A BSDF's transport convention, `"importance"` or `"radiance"` (absent: radiance);
    /// checked by [`Description::validate`], read by [`Description::transport`].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub transport: Option<Value>,
    /// The G2 form of a BSDF that also offers its NDF (`d`, `lambda`): `"uncorrelated"` or
    /// `"height_correlated"` (absent: not declared); read by [`Description::masking`].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub masking: Option<Value>,
    /// How a BSDF that also offers its NDF samples: `"visible_normals"` (that NDF's visible
    /// normals at wi⁺, reflection chosen with probability F where it transmits), or any other
    /// name (not compared); read by [`Description::visible_normals`].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sampling: Option<Value>,
    /// The precision the implementation computes in, `"f64"` (absent: the default) or
    /// `"f32"`; checked by [`Description::validate`], read by [`Description::precision`].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub precision: Option<Value>,
    /// Whether a reflection-only BSDF reflects from below as from above (`true`; absent or
    /// `false`: black from below); checked by [`Description::validate`], read by
    /// [`Description::two_sided`].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub two_sided: Option<Value>,
    /// The reference sampler whose map u ↦ wo `bsdf_sample` reproduces (`"visible_normals"`,
    /// `"normals"` or `"pseudo_vnis"`; absent: its own map, whose directions for a given u are
    /// not compared); checked by [`Description::validate`], read by
    /// [`Description::reference_map`].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reference_map: Option<Value>,
}

impl Description {
    /// Whether the child declared capability `name`.
    pub fn has(&self, name: &str) -> bool {
        self.capabilities.iter().any(|c| c == name)
    }

    /// Whether the child offers a BSDF (it declared all of [`BSDF_CAPABILITIES`]; validation
    /// refuses a part of them).
    pub fn has_bsdf(&self) -> bool {
        BSDF_CAPABILITIES.iter().all(|c| self.has(c))
    }

    /// Whether the child offers an NDF (it declared `d`).
    pub fn has_ndf(&self) -> bool {
        self.has("d")
    }

    /// The BSDF's relative index (None: reflection only, or not a valid number: see
    /// [`Description::validate`]).
    pub fn eta(&self) -> Option<f64> {
        self.eta.as_ref().and_then(Value::as_f64)
    }

    /// The precision the implementation computes in (f64 when absent or invalid: see
    /// [`Description::validate`]).
    pub fn precision(&self) -> crate::precision::Precision {
        self.precision
            .as_ref()
            .and_then(Value::as_str)
            .and_then(|p| p.parse().ok())
            .unwrap_or_default()
    }

    /// The BSDF's declared G2 form (None when absent; see [`Description::validate`]).
    pub fn masking(&self) -> Option<Masking> {
        self.masking
            .as_ref()
            .and_then(|m| serde_json::from_value(m.clone()).ok())
    }

    /// Whether the BSDF declares visible-normal sampling of its NDF.
    pub fn visible_normals(&self) -> bool {
        self.sampling.as_ref().and_then(Value::as_str) == Some("visible_normals")
    }

    /// Whether the BSDF declared itself two-sided (false when absent or invalid: see
    /// [`Description::validate`]).
    pub fn two_sided(&self) -> bool {
        self.two_sided.as_ref().and_then(Value::as_bool) == Some(true)
    }

    /// The reference map the BSDF declared (None when absent or invalid: see
    /// [`Description::validate`]).
    pub fn reference_map(&self) -> Option<mfh_reference::bsdf::Sampling> {
        self.reference_map
            .as_ref()
            .and_then(|m| serde_json::from_value(m.clone()).ok())
    }

    /// The BSDF's transport convention (radiance when absent or invalid: see
    /// [`Description::validate`]).
    pub fn transport(&self) -> Transport {
        match self.transport.as_ref().and_then(Value::as_str) {
            Some("importance") => Transport::Importance,
            _ => Transport::Radiance,
        }
    }

    /// Checks the version, the capability list and the BSDF fields: every name must be known;
    /// the child offers an NDF (`d`), a BSDF (`bsdf_eval`, `bsdf_pdf`, `bsdf_sample`, all
    /// three), or both; the other NDF capabilities need `d`, `g1`/`g2` need `lambda`, `pdf_wm`
    /// needs `sample_wm`, visible sampling needs `lambda`; `bsdf_pdf` and `bsdf_sample` need
    /// `bsdf_eval`; `eta`, when given, is a finite number in [0.1, 10] at least 5e-5 away from
    /// 1; `transport`, when given, is `"importance"` or `"radiance"`; `masking`, when given,
    /// is `"uncorrelated"` or `"height_correlated"`; `two_sided`, when given, is a boolean, and
    /// `true` only without `eta`; `reference_map`, when given, names a reference sampler.
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
            ("g1", "lambda"),
            ("g2", "lambda"),
            ("pdf_wm", "sample_wm"),
            ("sample_wm_visible", "lambda"),
            ("pdf_wm_visible", "sample_wm_visible"),
            ("bsdf_pdf", "bsdf_eval"),
            ("bsdf_sample", "bsdf_eval"),
        ];
        let bsdf_declared = BSDF_CAPABILITIES.iter().any(|c| self.has(c));
        if !self.has("d") && !bsdf_declared {
            return Err(
                "capability \"d\" (an NDF) or \"bsdf_eval\", \"bsdf_pdf\" and \"bsdf_sample\" \
                 (a BSDF) is required"
                    .into(),
            );
        }
        if !self.has("d") {
            if let Some(c) = NDF_CAPABILITIES[1..].iter().find(|c| self.has(c)) {
                return Err(format!("capability {c:?} requires \"d\""));
            }
        }
        for (cap, need) in needs {
            if self.has(cap) && !self.has(need) {
                return Err(format!("capability {cap:?} requires {need:?}"));
            }
        }
        if bsdf_declared && !self.has_bsdf() {
            let missing: Vec<&str> = BSDF_CAPABILITIES
                .into_iter()
                .filter(|c| !self.has(c))
                .collect();
            return Err(format!(
                "a BSDF audit needs all of bsdf_eval, bsdf_pdf and bsdf_sample; missing: {}",
                missing.join(", ")
            ));
        }
        if let Some(eta) = &self.eta {
            let value = eta.as_f64().ok_or_else(|| {
                format!("\"eta\" is {eta}, not a number (η inside / η outside, in [0.1, 10])")
            })?;
            check_eta(value).map_err(|e| format!("\"eta\": {e}"))?;
        }
        if let Some(t) = &self.transport {
            if !matches!(t.as_str(), Some("importance" | "radiance")) {
                return Err(format!(
                    "\"transport\" is {t}; it must be \"importance\" or \"radiance\""
                ));
            }
        }
        if let Some(m) = &self.masking {
            if self.masking().is_none() {
                return Err(format!(
                    "\"masking\" is {m}; it must be \"uncorrelated\" or \"height_correlated\""
                ));
            }
        }
        if let Some(t) = &self.two_sided {
            match t.as_bool() {
                None => {
                    return Err(format!(
                        "\"two_sided\" is {t}; it must be true or false (a reflector that \
                         reflects from below as from above)"
                    ))
                }
                Some(true) if self.eta.is_some() => {
                    return Err(
                        "\"two_sided\": true is for a reflection-only BSDF; this one declares \
                         \"eta\" (a transmitting BSDF has both sides already)"
                            .into(),
                    )
                }
                _ => {}
            }
        }
        if let Some(m) = &self.reference_map {
            if self.reference_map().is_none() {
                return Err(format!(
                    "\"reference_map\" is {m}; it must be \"visible_normals\", \"normals\" or \
                     \"pseudo_vnis\" (the reference sampler whose map u ↦ wo bsdf_sample \
                     reproduces), or absent"
                ));
            }
        }
        if let Some(p) = &self.precision {
            let valid = p
                .as_str()
                .is_some_and(|p| p.parse::<crate::precision::Precision>().is_ok());
            if !valid {
                return Err(format!(
                    "\"precision\" is {p}; it must be \"f64\" (the default) or \"f32\""
                ));
            }
        }
        Ok(())
    }
}

/// A relative index checked against the reference dielectric's limits
/// ([`mfh_reference::bsdf::dielectric::ETA_MIN`] and its siblings).
fn check_eta(eta: f64) -> Result<f64, String> {
    use mfh_reference::bsdf::dielectric::{ETA_MAX, ETA_MIN, ETA_MIN_GAP};
    if !(ETA_MIN..=ETA_MAX).contains(&eta) {
        return Err(format!(
            "{eta} is outside [{ETA_MIN}, {ETA_MAX}] (η inside / η outside)"
        ));
    }
    if !((eta - 1.0).abs() >= ETA_MIN_GAP) {
        return Err(format!(
            "{eta} is less than {ETA_MIN_GAP:e} away from 1 (at η = 1 refraction is a delta, \
             wo = −wi, which no density-based check resolves)"
        ));
    }
    Ok(eta)
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
    /// Sampled BSDF directions (`bsdf_sample`).
    #[serde(default)]
    pub wo: Option<Wire<[Number; 3]>>,
    /// The densities of sampled BSDF directions (`bsdf_sample`; 0 for a failed sample).
    #[serde(default)]
    pub pdf: Option<Wire<Number>>,
    /// The weights eval/pdf of sampled BSDF directions (`bsdf_sample`; 0 for a failed sample).
    #[serde(default)]
    pub weight: Option<Wire<Number>>,
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
            eta: None,
            transport: None,
            masking: None,
            sampling: None,
            precision: None,
            two_sided: None,
            reference_map: None,
        };
        assert!(d(&["d", "lambda", "g2"], 1).validate().is_ok());
        // "precision": "f64" or "f32"; anything else is an error naming the field.
        use crate::precision::Precision;
        let at = |p: Value| Description {
            precision: Some(p),
            ..d(&["d"], 2)
        };
        assert_eq!(at(Value::from("f32")).precision(), Precision::F32);
        assert!(at(Value::from("f32")).validate().is_ok());
        assert_eq!(d(&["d"], 2).precision(), Precision::F64);
        for bad in [Value::from("float"), Value::from(32), Value::Null] {
            let e = at(bad).validate().unwrap_err();
            assert!(e.contains("\"precision\""), "{e}");
        }
        let parsed: Description =
            serde_json::from_str(r#"{"protocol":2,"capabilities":["d"],"precision":"f32"}"#)
                .unwrap();
        assert_eq!(parsed.precision(), Precision::F32);
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

    /// A child may offer a BSDF only (no `d`), an NDF only, or both; a BSDF needs all three
    /// capabilities; `eta` and `transport` are checked, and the error names the field.
    #[test]
    fn bsdf_descriptions_are_validated() {
        let d = |caps: &[&str], eta: Option<Value>, transport: Option<Value>| Description {
            protocol: 2,
            name: None,
            capabilities: caps.iter().map(|s| s.to_string()).collect(),
            parameters: Value::Null,
            eta,
            transport,
            masking: None,
            sampling: None,
            precision: None,
            two_sided: None,
            reference_map: None,
        };
        let bsdf = ["bsdf_eval", "bsdf_pdf", "bsdf_sample"];
        let ok = d(&bsdf, Some(1.5.into()), Some("importance".into()));
        assert!(ok.validate().is_ok());
        assert!(ok.has_bsdf() && !ok.has_ndf());
        assert_eq!(ok.eta(), Some(1.5));
        assert_eq!(ok.transport(), Transport::Importance);
        let both = d(&["d", "bsdf_eval", "bsdf_pdf", "bsdf_sample"], None, None);
        assert!(both.validate().is_ok() && both.has_bsdf() && both.has_ndf());
        assert_eq!((both.eta(), both.transport()), (None, Transport::Radiance));
        // A BSDF with its NDF may declare its G2 form and visible-normal sampling.
        assert_eq!((both.masking(), both.visible_normals()), (None, false));
        let declared = Description {
            masking: Some("uncorrelated".into()),
            sampling: Some("visible_normals".into()),
            ..both.clone()
        };
        assert!(declared.validate().is_ok());
        assert_eq!(declared.masking(), Some(Masking::Uncorrelated));
        assert!(declared.visible_normals());
        for bad in [Value::from("smith"), Value::from(1)] {
            let e = Description {
                masking: Some(bad),
                ..both.clone()
            }
            .validate()
            .unwrap_err();
            assert!(e.contains("\"masking\""), "{e}");
        }
        // A reflector may declare itself two-sided; a transmitting BSDF may not (it has both
        // sides); either may declare the reference map it reproduces.
        assert!(!both.two_sided() && both.reference_map().is_none());
        let two = Description {
            two_sided: Some(true.into()),
            reference_map: Some("normals".into()),
            ..both.clone()
        };
        assert!(two.validate().is_ok() && two.two_sided());
        assert_eq!(
            two.reference_map(),
            Some(mfh_reference::bsdf::Sampling::Normals)
        );
        for (bad, want) in [
            (
                Description {
                    two_sided: Some("yes".into()),
                    ..both.clone()
                },
                "\"two_sided\" is",
            ),
            (
                Description {
                    two_sided: Some(true.into()),
                    ..d(&bsdf, Some(1.5.into()), None)
                },
                "declares \"eta\"",
            ),
            (
                Description {
                    reference_map: Some("concentric".into()),
                    ..both.clone()
                },
                "\"reference_map\"",
            ),
        ] {
            let e = bad.validate().unwrap_err();
            assert!(e.contains(want), "{e}");
        }
        let e = d(&["bsdf_pdf"], None, None).validate().unwrap_err();
        assert!(e.contains("bsdf_eval"), "{e}");
        let e = d(&["bsdf_eval", "bsdf_pdf"], None, None)
            .validate()
            .unwrap_err();
        assert!(e.contains("missing: bsdf_sample"), "{e}");
        let e = d(
            &["lambda", "bsdf_eval", "bsdf_pdf", "bsdf_sample"],
            None,
            None,
        )
        .validate()
        .unwrap_err();
        assert!(e.contains("\"lambda\" requires \"d\""), "{e}");
        assert!(d(&[], None, None)
            .validate()
            .unwrap_err()
            .contains("bsdf_eval"));
        for (eta, want) in [
            (Value::from(1.00001), "5e-5"),
            (Value::from(11.0), "[0.1, 10]"),
            (Value::from(0.05), "[0.1, 10]"),
            (Value::from("1.5"), "not a number"),
        ] {
            let e = d(&bsdf, Some(eta.clone()), None).validate().unwrap_err();
            assert!(e.contains("\"eta\"") && e.contains(want), "{eta}: {e}");
        }
        let e = d(&bsdf, None, Some("photons".into()))
            .validate()
            .unwrap_err();
        assert!(e.contains("\"transport\""), "{e}");
    }

    /// The BSDF requests carry their arrays in both versions (u triples as 3 numbers an item).
    #[test]
    fn bsdf_requests_carry_their_arrays() {
        let w = [[0.6, 0.0, 0.8]];
        let u = [[0.25, 0.5, 0.75]];
        let v: Value =
            serde_json::from_str(&Request::BsdfSample { wi: &w, u: &u }.to_line(1, 1)).unwrap();
        assert_eq!(v["op"], "bsdf_sample");
        assert_eq!(v["u"], serde_json::json!([[0.25, 0.5, 0.75]]));
        let v: Value =
            serde_json::from_str(&Request::BsdfSample { wi: &w, u: &u }.to_line(2, 2)).unwrap();
        assert_eq!(v["n"], 1);
        assert_eq!(v["u"].as_str().unwrap(), encode(&[0.25, 0.5, 0.75]));
        assert_eq!(v["wi"].as_str().unwrap(), encode(&[0.6, 0.0, 0.8]));
        for (request, op) in [
            (Request::BsdfEval { wi: &w, wo: &w }, "bsdf_eval"),
            (Request::BsdfPdf { wi: &w, wo: &w }, "bsdf_pdf"),
        ] {
            let v: Value = serde_json::from_str(&request.to_line(3, 2)).unwrap();
            assert_eq!((v["op"].as_str(), v["n"].as_u64()), (Some(op), Some(1)));
            assert_eq!(v["wo"].as_str().unwrap(), encode(&[0.6, 0.0, 0.8]));
        }
        let line = format!(
            r#"{{"id":1,"wo":"{}","pdf":[0.5],"weight":[0.25]}}"#,
            encode(&[0.0, 0.0, -1.0])
        );
        let a: Answer = serde_json::from_str(&line).unwrap();
        assert_eq!(a.wo.unwrap().numbers(2).unwrap(), [0.0, 0.0, -1.0]);
        assert_eq!(a.pdf.unwrap().numbers(2).unwrap(), [0.5]);
        assert_eq!(a.weight.unwrap().numbers(2).unwrap(), [0.25]);
    }
}
