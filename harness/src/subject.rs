//! The subject of an audit: a model seen only through its capability traits (mfh's reference
//! models and a renderer's own alike), the name records give it, and what is known of it —
//! its registry entry and spec for a reference model, the user's hints, and what the oracles
//! measure from D itself. Checks never ask a subject for a family name to decide what to do.

use mfh_reference::geometry::from_spherical;
use mfh_reference::registry::{self, FamilyInfo};
use mfh_reference::{Model, ModelSpec, Ndf, ParamError};
use serde_json::{json, Value};
use std::f64::consts::{FRAC_PI_2, PI};
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
    measured: OnceLock<Lobe>,
}

/// What the oracles know of a lobe.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lobe {
    /// The narrowest angular width over the azimuths (radians).
    pub width: f64,
    /// Whether D depends on the azimuth.
    pub anisotropic: bool,
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
            theta_kinks: (info.theta_kinks)(&spec),
            anisotropic: Some(spec_anisotropic(&spec)),
        };
        Self {
            model,
            label: serde_json::to_value(&spec).unwrap_or(Value::Null),
            reference: Some((spec, info)),
            hints,
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
        Arc::new(Self {
            model,
            label: json!({ "name": name }),
            reference: None,
            hints,
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

    /// The lobe: stated by hints where given, otherwise measured from D (once).
    pub fn lobe(&self) -> Lobe {
        let measured = || {
            *self
                .measured
                .get_or_init(|| measure_lobe(self.model.as_ref()))
        };
        Lobe {
            width: match self.hints.lobe_width {
                Some(w) if w > 0.0 && w.is_finite() => w,
                _ => measured().width,
            },
            anisotropic: match self.hints.anisotropic {
                Some(a) => a,
                None => measured().anisotropic,
            },
        }
    }

    /// The polar kinks of D (hinted; none for a model that states none).
    pub fn theta_kinks(&self) -> Vec<f64> {
        self.hints.theta_kinks.clone()
    }

    /// The exponent C of a Student-t slope marginal, where the registry knows it.
    pub fn tail_exponent(&self) -> Option<f64> {
        self.reference
            .as_ref()
            .and_then(|(s, i)| (i.tail_exponent)(s))
    }

    /// The mean slope (s̄x, s̄y): zero unless the registry says otherwise.
    pub fn mean_slope(&self) -> [f64; 2] {
        self.reference
            .as_ref()
            .map_or([0.0, 0.0], |(s, i)| (i.mean_slope)(s))
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

/// The lobe width a reference spec implies.
fn spec_width(spec: &ModelSpec) -> f64 {
    lobe_width(&serde_json::to_value(spec).unwrap_or(Value::Null))
}

/// The polar kinks of a spec given as JSON (registry), none if it does not parse.
pub fn theta_kinks(spec: &Value) -> Vec<f64> {
    serde_json::from_value::<ModelSpec>(spec.clone())
        .map(|s| (registry::info(&s).theta_kinks)(&s))
        .unwrap_or_default()
}

/// The lobe width a spec (JSON) implies: atan of the smallest roughness (or of the square root
/// of the smallest slope variance), 0.3 where the spec has no scale.
pub fn lobe_width(spec: &Value) -> f64 {
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

/// Measures the lobe from D alone: along 8 azimuths, the polar angle θ* where the projected
/// density D(θ, φ) cos θ sin θ peaks on a log-spaced grid from 1e-9 to π/2 (α/√3 for GGX,
/// α/√2 for Beckmann); the width is the smallest θ*, and the lobe is anisotropic when D at a
/// common θ differs between azimuths by more than 1e-9 relative. A few thousand evaluations.
pub fn measure_lobe(model: &dyn Ndf) -> Lobe {
    const N: usize = 400;
    let thetas: Vec<f64> = (0..N)
        .map(|i| 1e-9 * (FRAC_PI_2 / 1e-9).powf(i as f64 / (N - 1) as f64))
        .collect();
    let mut width = f64::INFINITY;
    let mut reference: Option<Vec<f64>> = None;
    let mut anisotropic = false;
    for k in 0..8 {
        let phi = k as f64 * PI / 4.0 + 0.1;
        let values: Vec<f64> = thetas
            .iter()
            .map(|&t| {
                let d = model.d(from_spherical(t.min(FRAC_PI_2 - 1e-9), phi));
                if d.is_finite() {
                    d
                } else {
                    0.0
                }
            })
            .collect();
        let best = thetas
            .iter()
            .zip(&values)
            .map(|(t, d)| (t, d * t.cos() * t.sin()))
            .fold(
                (0.3, 0.0),
                |acc, (t, v)| if v > acc.1 { (*t, v) } else { acc },
            );
        width = width.min(best.0);
        match &reference {
            None => reference = Some(values),
            Some(r) => {
                anisotropic |= r
                    .iter()
                    .zip(&values)
                    .any(|(a, b)| (a - b).abs() > 1e-9 * a.abs().max(b.abs()));
            }
        }
    }
    Lobe {
        width: if width.is_finite() { width } else { 0.3 },
        anisotropic,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_measured_lobe_follows_roughness_and_anisotropy() {
        for (spec, lo, hi, aniso) in [
            (r#"{"family":"ggx","alpha":0.3}"#, 0.1, 0.3, false),
            (r#"{"family":"ggx","alpha":1e-4}"#, 3e-5, 1e-4, false),
            (r#"{"family":"beckmann","alpha":1e-3}"#, 4e-4, 1e-3, false),
            (
                r#"{"family":"ggx","alpha_x":0.01,"alpha_y":1.0}"#,
                3e-3,
                1e-2,
                true,
            ),
        ] {
            let spec: ModelSpec = serde_json::from_str(spec).unwrap();
            let m = spec.build().unwrap();
            let lobe = measure_lobe(m.as_ref());
            assert!(lobe.width > lo && lobe.width < hi, "{spec:?}: {lobe:?}");
            assert_eq!(lobe.anisotropic, aniso, "{spec:?}");
        }
    }
}
