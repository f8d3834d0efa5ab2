//! The subject of an audit: a model seen only through its capability traits (mfh's reference
//! models and a renderer's own alike), the name records give it, and what is known of it —
//! its registry entry and spec for a reference model, the user's hints, and what the oracles
//! measure from D itself. Checks never ask a subject for a family name to decide what to do.

pub mod bsdf;

use crate::oracle::lobe::{self, Lobe, Options};
use crate::oracle::smith_lambda::LambdaSubject;
use crate::precision::Precision;
use mfh_reference::family::{FamilyInfo, FamilySpec};
use mfh_reference::registry;
use mfh_reference::{Model, ModelSpec, Ndf, ParamError, Vec3};
use serde_json::{json, Value};
use std::sync::{Arc, OnceLock};

/// What a user may state about a model to speed the oracles up. Never needed for
/// correctness: without a hint, the harness measures.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Hints {
    /// The angular width of the lobe (radians, e.g. atan α of the narrower axis).
    pub lobe_width: Option<f64>,
    /// Polar angles where D has kinks for every azimuth (piecewise models), for quadrature cuts.
    pub theta_kinks: Vec<f64>,
    /// Whether D depends on the azimuth.
    pub anisotropic: Option<bool>,
}

/// The subject of an audit. Cheap to share: checks hold an `Arc<Subject>`.
pub struct Subject<'a> {
    /// The model, through its capabilities ([`Ndf`]'s `as_*` methods).
    pub model: Arc<dyn Ndf + 'a>,
    /// How records name the model: its spec for a reference model, `{"name": …}` otherwise.
    pub label: Value,
    /// The spec and registry entry of a reference model; None for a user's model.
    pub reference: Option<(ModelSpec, &'static FamilyInfo)>,
    /// What the user stated.
    pub hints: Hints,
    /// The precision the implementation computes in (declared; F64 for reference models):
    /// value tolerances and the oracles' rounding floors follow it.
    pub precision: Precision,
    /// Whether every evaluation crosses a process boundary (a child behind the external
    /// protocol): checks whose oracle accuracy is a cost trade-off may then use the looser of
    /// two stated tolerances that both keep their margin (each such check says which). A
    /// harness concern, so it is the subject's, not a method of the model's traits.
    pub remote: bool,
    measured: OnceLock<Lobe>,
}

impl std::fmt::Debug for Subject<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Subject")
            .field("label", &self.label)
            .field("hints", &self.hints)
            .finish()
    }
}

impl Subject<'static> {
    /// A reference model built from its spec.
    pub fn reference(spec: &ModelSpec) -> Result<Arc<Self>, ParamError> {
        let model: Arc<dyn Model> = Arc::from(spec.build()?);
        Ok(Arc::new(Self::of_reference(model, spec.clone())))
    }

    /// A reference model already built (its spec read back from it).
    pub fn from_model(model: Arc<dyn Model>) -> Arc<Self> {
        let spec = model.spec();
        Arc::new(Self::of_reference(model, spec))
    }
}

impl<'a> Subject<'a> {
    fn of_reference(model: Arc<dyn Ndf + 'a>, spec: ModelSpec) -> Self {
        let info = registry::info(&spec);
        let hints = Hints {
            lobe_width: Some(spec_width(&spec)),
            theta_kinks: spec.theta_kinks(),
            anisotropic: Some(spec_anisotropic(&spec)),
        };
        Self {
            model,
            label: serde_json::to_value(&spec).unwrap_or(Value::Null),
            reference: Some((spec, info)),
            hints,
            precision: Precision::F64,
            remote: false,
            measured: OnceLock::new(),
        }
    }
}

impl<'a> Subject<'a> {
    /// A reference model borrowed for `'a`.
    pub fn borrowed(model: &'a dyn Model) -> Self {
        Self::of_reference(Arc::new(model), model.spec())
    }

    /// A user's model, named `name` in the records.
    pub fn user(model: Arc<dyn Ndf + 'a>, name: &str, hints: Hints) -> Arc<Self> {
        Self::user_at(model, name, hints, Precision::F64)
    }

    /// A user's model that computes in `precision`.
    pub fn user_at(
        model: Arc<dyn Ndf + 'a>,
        name: &str,
        hints: Hints,
        precision: Precision,
    ) -> Arc<Self> {
        Self::user_model(model, name, hints, precision, false)
    }

    /// A user's model behind a process boundary ([`Subject::remote`]).
    pub fn remote_at(
        model: Arc<dyn Ndf + 'a>,
        name: &str,
        hints: Hints,
        precision: Precision,
    ) -> Arc<Self> {
        Self::user_model(model, name, hints, precision, true)
    }

    fn user_model(
        model: Arc<dyn Ndf + 'a>,
        name: &str,
        hints: Hints,
        precision: Precision,
        remote: bool,
    ) -> Arc<Self> {
        Arc::new(Self {
            model,
            label: json!({ "name": name }),
            reference: None,
            hints,
            precision,
            remote,
            measured: OnceLock::new(),
        })
    }

    /// The family name for coverage ids and the expected-failure table: the registry name of
    /// a reference model, `user` otherwise (no expected failure ever applies to a user's model).
    pub fn family(&self) -> &'static str {
        self.reference.as_ref().map_or("user", |(_, i)| i.name)
    }

    /// The registry entry, for a reference model.
    pub fn info(&self) -> Option<&'static FamilyInfo> {
        self.reference.as_ref().map(|(_, i)| *i)
    }

    /// The spec, for a reference model.
    pub fn spec(&self) -> Option<&ModelSpec> {
        self.reference.as_ref().map(|(s, _)| s)
    }

    /// The lobe, measured from D once ([`crate::oracle::lobe`]; a stated width only speeds the
    /// measurement up).
    pub fn lobe(&self) -> &Lobe {
        self.measured.get_or_init(|| {
            // D in batches (the survey grids in one call each: an external model's round
            // trips).
            lobe::measure_with_batch(
                &|m: &[Vec3], out: &mut [f64]| {
                    self.model.d_batch(m, out);
                    for (o, m) in out.iter_mut().zip(m) {
                        *o *= m[2];
                    }
                },
                &Options {
                    hint: self.hints.lobe_width,
                    ..Options::default()
                },
            )
        })
    }

    /// Whether D depends on the azimuth: as stated (or known from a reference spec); a user's
    /// model that states nothing is treated as anisotropic (checks then run at two azimuths).
    pub fn anisotropic(&self) -> bool {
        self.hints.anisotropic.unwrap_or(true)
    }

    /// The polar kinks of D (hinted; none for a model that states none).
    pub fn theta_kinks(&self) -> Vec<f64> {
        self.hints.theta_kinks.clone()
    }

    /// The exponent C of a Student-t slope marginal, where the registry knows it.
    pub fn tail_exponent(&self) -> Option<f64> {
        self.reference.as_ref().and_then(|(s, _)| s.tail_exponent())
    }

    /// The mean slope (s̄x, s̄y): zero unless the registry says otherwise.
    pub fn mean_slope(&self) -> [f64; 2] {
        self.reference
            .as_ref()
            .map_or([0.0, 0.0], |(s, _)| s.mean_slope())
    }

    /// Whether the default Λ is a numerical integral (registry); false for user models, whose
    /// Λ is held to the closed-form tolerance.
    pub fn lambda_numerical(&self) -> bool {
        self.info().is_some_and(|i| i.lambda_numerical)
    }

    /// Whether the sampler is slow (registry).
    pub fn slow_sampler(&self) -> bool {
        self.info().is_some_and(|i| i.slow_sampler)
    }
}

/// The Λ oracle's questions, answered from the registry, the hints and the measured lobe.
impl LambdaSubject for Subject<'_> {
    fn ndf(&self) -> &dyn Ndf {
        self.model.as_ref()
    }
    fn tail_exponent(&self) -> Option<f64> {
        Subject::tail_exponent(self)
    }
    fn lobe_width(&self) -> f64 {
        self.lobe().width()
    }
    fn theta_kinks(&self) -> Vec<f64> {
        Subject::theta_kinks(self)
    }
    fn precision(&self) -> Precision {
        self.precision
    }
}

/// The lobe width a reference spec implies (a hint for lobe measurement and quadrature): atan
/// of the smallest roughness (or of the square root of the smallest slope variance), 0.3 where
/// the spec has no scale.
pub fn spec_width(spec: &ModelSpec) -> f64 {
    lobe_width(&serde_json::to_value(spec).unwrap_or(Value::Null))
}

/// [`spec_width`] of the spec's JSON form.
fn lobe_width(spec: &Value) -> f64 {
    let get = |k: &str| spec.get(k).and_then(Value::as_f64);
    let mut w = f64::INFINITY;
    for k in ["alpha", "alpha_x", "alpha_y"] {
        if let Some(a) = get(k) {
            w = w.min(a);
        }
    }
    if let Some(cov) = spec.get("cov").and_then(Value::as_array) {
        for (i, row) in cov.iter().enumerate() {
            if let Some(v) = row.get(i).and_then(Value::as_f64) {
                w = w.min(v.abs().sqrt());
            }
        }
    }
    if w.is_finite() && w > 0.0 {
        w.atan()
    } else {
        0.3
    }
}

/// Whether a reference spec is anisotropic (per-axis roughness, a second profile, a blend of
/// two models, or Gaussian slopes, whose covariance and mean make them so in general).
fn spec_anisotropic(spec: &ModelSpec) -> bool {
    let spec = serde_json::to_value(spec).unwrap_or(Value::Null);
    let has = |k: &str| spec.get(k).is_some_and(|v| !v.is_null());
    has("alpha_x") || (has("y") && has("x")) || has("cov") || has("mean")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_measured_lobe_follows_roughness() {
        for (spec, lo, hi) in [
            // The θ where the mass per ln θ peaks: ≈ α for GGX and Beckmann at small α.
            (r#"{"family":"ggx","alpha":0.3}"#, 0.075, 0.9),
            (r#"{"family":"ggx","alpha":1e-4}"#, 2.5e-5, 3e-4),
            (r#"{"family":"beckmann","alpha":1e-3}"#, 2.5e-4, 3e-3),
        ] {
            let spec: ModelSpec = serde_json::from_str(spec).unwrap();
            let user = Subject::user(Arc::new(spec.build().unwrap()), "u", Hints::default());
            let w = user.lobe().width();
            assert!(w > lo && w < hi, "{spec:?}: {w}");
            assert!(user.anisotropic());
            assert!(!Subject::reference(&spec).unwrap().anisotropic());
        }
    }
}
