//! The subject of a BSDF audit: a BSDF seen only through the [`Bsdf`] capability (mfh's
//! reference BSDFs and a renderer's own alike), the name records give it, and its spec when it
//! is a reference BSDF. Checks ask it for nothing else.

use mfh_reference::bsdf::{Bsdf, BsdfSpec};
use serde_json::{json, Value};
use std::sync::Arc;

/// The subject of a BSDF audit. Cheap to share: checks hold an `Arc<BsdfSubject>`.
pub struct BsdfSubject<'a> {
    /// The BSDF.
    pub bsdf: Arc<dyn Bsdf + 'a>,
    /// How records name it: its spec for a reference BSDF, `{"name": …}` otherwise.
    pub label: Value,
    /// The spec of a reference BSDF; None for a user's.
    pub reference: Option<BsdfSpec>,
}

impl std::fmt::Debug for BsdfSubject<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("BsdfSubject")
            .field("label", &self.label)
            .finish()
    }
}

impl BsdfSubject<'static> {
    /// A reference BSDF built from its spec.
    pub fn reference(spec: &BsdfSpec) -> Result<Arc<Self>, mfh_reference::bsdf::BsdfError> {
        let bsdf = spec.build()?;
        Ok(Arc::new(Self {
            bsdf,
            label: serde_json::to_value(spec).unwrap_or(Value::Null),
            reference: Some(spec.clone()),
        }))
    }
}

impl<'a> BsdfSubject<'a> {
    /// A user's BSDF, named `name` in the records.
    pub fn user(bsdf: Arc<dyn Bsdf + 'a>, name: &str) -> Arc<Self> {
        Arc::new(Self {
            bsdf,
            label: json!({ "name": name }),
            reference: None,
        })
    }

    /// The family name for coverage ids: the reference BSDF's kind (`conductor`,
    /// `dielectric`), `user` otherwise.
    pub fn family(&self) -> &'static str {
        self.reference.as_ref().map_or("user", BsdfSpec::kind)
    }
}
