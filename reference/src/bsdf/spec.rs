//! Reference BSDFs described as data, validated with typed errors that name the field and the
//! limit, and built into `Arc<dyn Bsdf>`:
//!
//! ```text
//! {"bsdf": "dielectric", "eta": 1.5, "ndf": {"family": "ggx", "alpha": 0.3},
//!  "masking": "height_correlated", "sampling": "visible_normals", "transport": "radiance"}
//! {"bsdf": "conductor", "n": 0.18, "k": 3.42, "fresnel": "exact",
//!  "ndf": {"family": "beckmann", "alpha_x": 0.1, "alpha_y": 0.4},
//!  "masking": "uncorrelated", "sampling": "normals", "two_sided": true}
//! ```
//!
//! `ndf` is any model spec (`ModelSpec`) whose model has a Smith Λ. Defaults: `masking`
//! `height_correlated`, `sampling` `visible_normals`, `transport` `radiance`, `fresnel` `exact`,
//! `two_sided` `false` (a conductor only: [`super::TwoSided`]; a dielectric has both sides).
//! Serialization writes every field but `two_sided: false` (so that specs written before it
//! existed serialize as they did). Unknown keys are errors.

use std::sync::Arc;

use serde::{Deserialize, Serialize};

use super::conductor::Conductor;
use super::dielectric::Dielectric;
use super::error::BsdfError;
use super::fresnel::FresnelModel;
use super::microfacet::{Microfacet, Sampling};
use super::{Bsdf, Transport};
use crate::model::{Masking, Ndf};
use crate::ndf::student_vnis::PseudoVnis;
use crate::spec::ModelSpec;

fn height_correlated() -> Masking {
    Masking::HeightCorrelated
}

/// A reference BSDF described as data, tagged by `bsdf`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "bsdf", rename_all = "snake_case")]
pub enum BsdfSpec {
    /// `{"bsdf": "conductor", …}`: [`ConductorSpec`].
    Conductor(ConductorSpec),
    /// `{"bsdf": "dielectric", …}`: [`DielectricSpec`].
    Dielectric(DielectricSpec),
}

/// A rough conductor ([`Conductor`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ConductorSpec {
    /// Real part of the complex index, in [1e-3, 100].
    pub n: f64,
    /// Imaginary part (extinction), in [0, 100].
    pub k: f64,
    /// `exact` (default) or `schlick`.
    #[serde(default)]
    pub fresnel: FresnelModel,
    /// The NDF (a model spec with a Smith Λ).
    pub ndf: ModelSpec,
    /// `height_correlated` (default) or `uncorrelated`.
    #[serde(default = "height_correlated")]
    pub masking: Masking,
    /// `visible_normals` (default), `normals` or `pseudo_vnis`.
    #[serde(default)]
    pub sampling: Sampling,
    /// Whether it reflects from below as from above ([`super::TwoSided`]; default `false`:
    /// black from below).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub two_sided: bool,
}

/// A rough dielectric ([`Dielectric`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DielectricSpec {
    /// η = η_inside/η_outside, in [0.1, 10], |η − 1| ≥ 5e-5.
    pub eta: f64,
    /// The NDF (a model spec with a Smith Λ).
    pub ndf: ModelSpec,
    /// `height_correlated` (default) or `uncorrelated`.
    #[serde(default = "height_correlated")]
    pub masking: Masking,
    /// `visible_normals` (default), `normals` or `pseudo_vnis`.
    #[serde(default)]
    pub sampling: Sampling,
    /// `radiance` (default) or `importance`.
    #[serde(default)]
    pub transport: Transport,
}

/// The microfacet part of a spec: the NDF (with a Smith Λ) and its sampler.
fn microfacet(
    ndf: &ModelSpec,
    masking: Masking,
    sampling: Sampling,
) -> Result<Microfacet, BsdfError> {
    let family = ndf.family();
    if let Some(reason) = ndf.smith_limit() {
        return Err(BsdfError::NoSmith {
            family: family.to_string(),
            reason,
        });
    }
    if sampling == Sampling::PseudoVnis {
        return match ndf {
            ModelSpec::Std(s) if s.gamma.is_finite() => {
                let (ax, ay) = crate::family::resolve_roughness(s.alpha, s.alpha_x, s.alpha_y)?;
                Ok(Microfacet::pseudo_vnis(
                    PseudoVnis::new(s.gamma, ax, ay)?,
                    masking,
                ))
            }
            _ => Err(BsdfError::NoSampler {
                sampling: sampling.name(),
                family: family.to_string(),
                needs: "the std family with a finite gamma (seed 001 §7.2's pseudo-VNIS \
                        approximates the STD's visible normals; gamma \"inf\" is Beckmann: \
                        use visible_normals)",
            }),
        };
    }
    let model = ndf.build()?;
    let ndf: Arc<dyn Ndf> = Arc::new(model);
    Microfacet::new(ndf, family, masking, sampling)
}

impl BsdfSpec {
    /// `conductor` or `dielectric`.
    pub fn kind(&self) -> &'static str {
        match self {
            BsdfSpec::Conductor(_) => "conductor",
            BsdfSpec::Dielectric(_) => "dielectric",
        }
    }

    /// The NDF's spec.
    pub fn ndf(&self) -> &ModelSpec {
        match self {
            BsdfSpec::Conductor(s) => &s.ndf,
            BsdfSpec::Dielectric(s) => &s.ndf,
        }
    }

    /// The relative index of a transmitting BSDF (`None` for a conductor).
    pub fn eta(&self) -> Option<f64> {
        match self {
            BsdfSpec::Conductor(_) => None,
            BsdfSpec::Dielectric(s) => Some(s.eta),
        }
    }

    /// Whether the BSDF reflects from both sides (a two-sided conductor).
    pub fn two_sided(&self) -> bool {
        matches!(self, BsdfSpec::Conductor(s) if s.two_sided)
    }

    /// Validates every field (building the NDF): the first error, naming its field and limit.
    pub fn validate(&self) -> Result<(), BsdfError> {
        self.build().map(|_| ())
    }

    /// Validates and builds the BSDF.
    pub fn build(&self) -> Result<Arc<dyn Bsdf>, BsdfError> {
        Ok(match self {
            BsdfSpec::Conductor(s) => {
                // The numbers first, so that an error names the first bad field as written.
                super::conductor::check_nk(s.n, s.k)?;
                let mf = microfacet(&s.ndf, s.masking, s.sampling)?;
                let conductor = Conductor::new(s.n, s.k, s.fresnel, mf)?;
                if s.two_sided {
                    Arc::new(super::TwoSided(conductor))
                } else {
                    Arc::new(conductor)
                }
            }
            BsdfSpec::Dielectric(s) => {
                super::dielectric::check_eta(s.eta)?;
                let mf = microfacet(&s.ndf, s.masking, s.sampling)?;
                Arc::new(Dielectric::new(s.eta, mf, s.transport)?)
            }
        })
    }
}
