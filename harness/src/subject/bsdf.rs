//! The subject of a BSDF audit: a BSDF seen only through the [`Bsdf`] capability (mfh's
//! reference BSDFs and a renderer's own alike), the name records give it, its spec when it is
//! a reference BSDF, and its own NDF when it offers one. Checks ask it for nothing else.

use crate::precision::Precision;
use mfh_reference::bsdf::{BsdfSpec, Sampling};
use mfh_reference::{Bsdf, Masking, Ndf};
use serde_json::{json, Value};
use std::sync::Arc;

/// The microfacet distribution a BSDF says it is built on (a child offering both a BSDF and
/// an NDF, `Audit::of_bsdf(…).ndf(…)`, a reference BSDF's `ndf`), with what the BSDF declares
/// of its use: the checks compare the BSDF with Walter's eq 20/21 built from this D and Λ
/// (`bsdf.ndf_consistency`).
#[derive(Clone)]
pub struct OwnNdf<'a> {
    /// The NDF (its `d` and, for the comparison, its Smith Λ).
    pub ndf: Arc<dyn Ndf + 'a>,
    /// The G2 form the BSDF declares; None: not declared (the check finds the one that fits).
    pub masking: Option<Masking>,
    /// Whether the BSDF declares that it samples this NDF's visible normals at wi⁺ and, if it
    /// transmits, chooses reflection with probability F(wi·m) (Walter §5.3).
    pub visible_normals: bool,
}

/// The subject of a BSDF audit. Cheap to share: checks hold an `Arc<BsdfSubject>`.
pub struct BsdfSubject<'a> {
    /// The BSDF.
    pub bsdf: Arc<dyn Bsdf + 'a>,
    /// How records name it: its spec for a reference BSDF, `{"name": …}` otherwise.
    pub label: Value,
    /// The spec of a reference BSDF; None for a user's.
    pub reference: Option<BsdfSpec>,
    /// The NDF the BSDF is built on, when it offers one.
    pub own_ndf: Option<OwnNdf<'a>>,
    /// The arithmetic the BSDF computes in: its value tolerances are budgeted in that
    /// format's ε (`tolerance::Tolerance::at`). f64 for the reference BSDFs.
    pub precision: Precision,
}

impl std::fmt::Debug for BsdfSubject<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("BsdfSubject")
            .field("label", &self.label)
            .field("precision", &self.precision)
            .finish()
    }
}

impl BsdfSubject<'static> {
    /// A reference BSDF built from its spec.
    pub fn reference(spec: &BsdfSpec) -> Result<Arc<Self>, mfh_reference::bsdf::BsdfError> {
        let bsdf = spec.build()?;
        let (masking, sampling) = match spec {
            BsdfSpec::Conductor(s) => (s.masking, s.sampling),
            BsdfSpec::Dielectric(s) => (s.masking, s.sampling),
        };
        let ndf: Arc<dyn Ndf> = Arc::new(spec.ndf().build()?);
        Ok(Arc::new(Self {
            bsdf,
            label: serde_json::to_value(spec).unwrap_or(Value::Null),
            reference: Some(spec.clone()),
            own_ndf: Some(OwnNdf {
                ndf,
                masking: Some(masking),
                visible_normals: sampling == Sampling::VisibleNormals,
            }),
            precision: Precision::F64,
        }))
    }
}

impl<'a> BsdfSubject<'a> {
    /// A user's BSDF computing in `precision`, named `name` in the records, built on
    /// `own_ndf` when it says so.
    pub fn user(
        bsdf: Arc<dyn Bsdf + 'a>,
        name: &str,
        own_ndf: Option<OwnNdf<'a>>,
        precision: Precision,
    ) -> Arc<Self> {
        Arc::new(Self {
            bsdf,
            label: json!({ "name": name }),
            reference: None,
            own_ndf,
            precision,
        })
    }

    /// The family name for coverage ids: the reference BSDF's kind (`conductor`,
    /// `dielectric`), `user` otherwise.
    pub fn family(&self) -> &'static str {
        self.reference.as_ref().map_or("user", BsdfSpec::kind)
    }
}
