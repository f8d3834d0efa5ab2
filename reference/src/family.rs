//! What a family of reference models provides, beside its model: how its spec type builds the
//! model and what follows from the spec's parameters ([`FamilySpec`]), and what the harness
//! knows about the family ([`FamilyInfo`], with its samplers' measured cost, [`SamplerCost`]).
//! Each family's file implements [`FamilySpec`] for its spec type (declared in `crate::spec`)
//! and attaches its facts to it as `SpecType::INFO`; the registry (`crate::registry`) reaches
//! both through the spec types of the one list of families. This file names no family, so the
//! families may name it.

use crate::error::ParamError;
use crate::model::{check_alpha, Model};

/// What every family's spec type does (each family's file implements it for its spec type; the
/// registry implements it for [`crate::ModelSpec`] by dispatching to the family's).
pub trait FamilySpec {
    /// Validates the parameters and builds the model.
    fn build(&self) -> Result<Box<dyn Model>, ParamError>;

    /// The parameter (name, value) that puts the model outside the domain of its Smith Λ, if
    /// any: for the Student-t members with γ ≤ 3/2 (and D^G(B, C) with C ≤ 3/2) the mean slope
    /// diverges and Λ = ∞ at every incidence (document 001 eq 18).
    fn smith_limit(&self) -> Option<(&'static str, f64)> {
        None
    }

    /// The exponent C of the Student-t slope marginal (P2 ∝ (1 + q²/…)^(−C)), where the family
    /// has one: heavy tails (C near 3/2) need an oracle that does not integrate the tail.
    fn tail_exponent(&self) -> Option<f64> {
        None
    }

    /// The polar angles where D has kinks for every azimuth (piecewise-linear profiles), for
    /// quadrature cuts. A hint: oracles converge without it, only slower.
    fn theta_kinks(&self) -> Vec<f64> {
        Vec::new()
    }

    /// The mean slope (s̄x, s̄y) of the slope distribution (non-zero only for Gaussian slopes
    /// with a mean, document 002).
    fn mean_slope(&self) -> [f64; 2] {
        [0.0, 0.0]
    }
}

/// What the harness knows about one family of reference models: facts about the family, the
/// same for every spec of it (what depends on the parameters is [`FamilySpec`]'s).
#[derive(Debug, Clone, Copy)]
pub struct FamilyInfo {
    /// The family name, as in specs (`"family": "ggx"`).
    pub name: &'static str,
    /// The source documents (seed ids, the source documents, documents 000–004) the family's closed forms come from.
    pub documents: &'static [&'static str],
    /// Where in the documents the family is defined.
    pub source: &'static str,
    /// The parameter domain, as accepted at construction.
    pub domain: &'static str,
    /// Example specs (JSON), isotropic and anisotropic where the family has both; the
    /// value-stability vectors and the eval contract iterate them.
    pub examples: &'static [&'static str],
    /// Roughness values at the ends of the domain for the stability checks (replacing the
    /// material's α), empty where the family has no α.
    pub stress_alpha: &'static [f64],
    /// Shape values γ at the ends of the domain for the stability checks, empty where the
    /// family has no γ.
    pub stress_gamma: &'static [f64],
    /// Whole specs at hard points of the domain (e.g. a near-singular covariance).
    pub stress_specs: &'static [(&'static str, &'static str)],
    /// Whether the default Λ is itself a numerical integral (its tolerance is the numerical
    /// route's, not the closed form's).
    pub lambda_numerical: bool,
    /// Whether `sample_wm` inverts a CDF numerically (an iteration with libm calls per sample,
    /// ~0.6 µs against 0.01–0.1 µs for the closed-form samplers): the KS checks take fewer
    /// samples.
    pub slow_sampler: bool,
    /// Whether the family tends to Beckmann as γ → ∞ (document 001 §4), which the limit check
    /// measures.
    pub beckmann_limit: bool,
    /// Whether slope moments are part of the model itself (not only of Gaussian-slope
    /// filtering), so that they are always checked.
    pub intrinsic_moments: bool,
    /// What its samplers cost per sample, measured ([`SamplerCost`]): a cost where, and only
    /// where, the model has the sampler (the registry's test).
    pub sampler_cost: SamplerCost,
}

/// The measured cost of a family's samplers in an audit: wall-clock nanoseconds per sample of
/// its 10⁸-sample chi-square checks in the default scene's thorough audit (sampling and binning
/// on 2 cores while the audit runs other checks beside them; AMD EPYC Zen 4, 2026-12-02). A
/// measurement of one machine, not mathematics: the harness uses it only to balance the shards
/// of `mfh audit --shard` (a wrong figure unbalances them, it cannot change a record). It sits
/// in the family's entry so that a family is described in one place.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SamplerCost {
    /// `sample_wm` (`sampling.chi2`); 0 where the family has no normal sampler.
    pub normal_ns: f64,
    /// `sample_wm_visible` (`sampling.chi2_visible`); 0 where the family has none.
    pub visible_ns: f64,
}

impl SamplerCost {
    /// A family without samplers.
    pub const NONE: SamplerCost = SamplerCost {
        normal_ns: 0.0,
        visible_ns: 0.0,
    };
}

/// Resolves `alpha` or (`alpha_x`, `alpha_y`) into validated per-axis roughness.
pub fn resolve_roughness(
    alpha: Option<f64>,
    alpha_x: Option<f64>,
    alpha_y: Option<f64>,
) -> Result<(f64, f64), ParamError> {
    match (alpha, alpha_x, alpha_y) {
        (Some(a), None, None) => {
            let a = check_alpha("alpha", a)?;
            Ok((a, a))
        }
        (None, Some(ax), Some(ay)) => {
            Ok((check_alpha("alpha_x", ax)?, check_alpha("alpha_y", ay)?))
        }
        _ => Err(ParamError::Combination(
            "give either alpha, or both alpha_x and alpha_y".to_string(),
        )),
    }
}

/// Per-axis roughness written back as a spec's fields: `alpha` when isotropic, otherwise
/// `alpha_x` and `alpha_y` (the inverse of [`resolve_roughness`]).
pub fn roughness_fields(alpha_x: f64, alpha_y: f64) -> (Option<f64>, Option<f64>, Option<f64>) {
    if alpha_x == alpha_y {
        (Some(alpha_x), None, None)
    } else {
        (None, Some(alpha_x), Some(alpha_y))
    }
}

/// The Smith limit of a Student-t shape parameter: Λ exists for `value` > 3/2 only.
pub fn student_smith_limit(field: &'static str, value: f64) -> Option<(&'static str, f64)> {
    (value <= 1.5).then_some((field, value))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bad_roughness_is_a_typed_error() {
        let e = resolve_roughness(Some(0.1), Some(0.2), None).unwrap_err();
        assert!(matches!(e, ParamError::Combination(_)));
        let e = resolve_roughness(Some(f64::NAN), None, None).unwrap_err();
        assert!(matches!(e, ParamError::AlphaNotPositive { .. }));
        let e = resolve_roughness(None, Some(0.1), Some(-1.0)).unwrap_err();
        assert!(matches!(
            e,
            ParamError::AlphaNotPositive {
                name: "alpha_y",
                ..
            }
        ));
        assert_eq!(roughness_fields(0.3, 0.3), (Some(0.3), None, None));
        assert_eq!(roughness_fields(0.1, 0.3), (None, Some(0.1), Some(0.3)));
    }
}
