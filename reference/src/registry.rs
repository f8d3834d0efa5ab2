//! The family registry: everything the harness knows about a family of reference models, in one
//! place. Each family's own file declares its spec type (parameters, validation, construction:
//! [`FamilySpec`]) and its [`FamilyInfo`]; one line per family in the `registry!` list below
//! makes the [`ModelSpec`] enum, [`FAMILIES`] and [`info`] from them. Planners, tests, the default scene's coverage test, the
//! eval contract and the value-stability vectors iterate this registry, so no list of family
//! names is written anywhere else.

use serde::{Deserialize, Serialize};

use crate::spec::FamilySpec;

/// What the harness knows about one family of reference models.
#[derive(Debug, Clone, Copy)]
pub struct FamilyInfo {
    /// The family name, as in specs (`"family": "ggx"`).
    pub name: &'static str,
    /// The source documents (seed ids, the source documents, seeds 000–004) the family's closed forms come from.
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
    /// What the family's samplers cost, for balancing `mfh audit --shard` only.
    pub sampler_cost: SamplerCost,
    /// Whether the family tends to Beckmann as γ → ∞ (seed 001 §4), which the limit check
    /// measures.
    pub beckmann_limit: bool,
    /// Whether slope moments are part of the model itself (not only of Gaussian-slope
    /// filtering), so that they are always checked.
    pub intrinsic_moments: bool,
    /// The exponent C of the Student-t slope marginal (P2 ∝ (1 + q²/…)^(−C)), where the family
    /// has one: heavy tails (C near 3/2) need an oracle that does not integrate the tail.
    pub tail_exponent: fn(&ModelSpec) -> Option<f64>,
    /// The polar angles where D has kinks for every azimuth (piecewise-linear profiles), for
    /// quadrature cuts. A hint: oracles converge without it, only slower.
    pub theta_kinks: fn(&ModelSpec) -> Vec<f64>,
    /// The mean slope (s̄x, s̄y) of the slope distribution (non-zero only for Gaussian slopes
    /// with a mean, seed 002).
    pub mean_slope: fn(&ModelSpec) -> [f64; 2],
}

/// The measured cost of a family's samplers in an audit: wall-clock nanoseconds per sample of
/// its 10⁸-sample chi-square checks in the default scene's thorough audit (sampling and binning
/// on 2 cores while the audit runs other checks beside them; AMD EPYC Zen 4, 2026-12-02). Used
/// only to balance shards (`harness/src/shard.rs`): a wrong figure unbalances them, it cannot
/// change a record.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SamplerCost {
    /// `sample_wm` (`sampling.chi2`); 0 where the family has no normal sampler.
    pub normal_ns: f64,
    /// `sample_wm_visible` (`sampling.chi2_visible`); 0 where the family has none.
    pub visible_ns: f64,
}

/// No sampler.
pub const NO_SAMPLER: SamplerCost = SamplerCost {
    normal_ns: 0.0,
    visible_ns: 0.0,
};

/// No tail exponent.
pub fn no_tail(_: &ModelSpec) -> Option<f64> {
    None
}

/// No kinks.
pub fn no_kinks(_: &ModelSpec) -> Vec<f64> {
    Vec::new()
}

/// A zero mean slope.
pub fn zero_mean(_: &ModelSpec) -> [f64; 2] {
    [0.0, 0.0]
}

/// Declares the families: one line per family, `Variant(SpecType) => INFO`, where the spec type
/// and the [`FamilyInfo`] live in the family's own file. From this list the macro writes the
/// [`ModelSpec`] enum (serde-tagged by `family`, the variant name in snake_case), [`FAMILIES`],
/// [`info`], `ModelSpec::family_spec` and `From<SpecType> for ModelSpec`. Adding a family is its
/// file (its model, its spec type implementing [`FamilySpec`], its `INFO`) and one line here.
macro_rules! registry {
    ($($(#[$doc:meta])* $variant:ident($spec:ty) => $info:path),+ $(,)?) => {
        /// A model described as data, e.g. `{"family": "std", "gamma": 2.5, "alpha": 0.3}`
        /// (ARCHITECTURE.md, "Evaluating closed forms"). Unknown keys are errors. Each variant
        /// holds its family's spec type, declared in the family's file; the variants are the
        /// lines of the registry below.
        #[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
        #[serde(tag = "family", rename_all = "snake_case")]
        pub enum ModelSpec {
            $($(#[$doc])* $variant($spec),)+
        }

        impl ModelSpec {
            /// The family's own spec: its parameters, validation and construction.
            pub fn family_spec(&self) -> &dyn FamilySpec {
                match self {
                    $(ModelSpec::$variant(s) => s,)+
                }
            }
        }

        $(impl From<$spec> for ModelSpec {
            fn from(s: $spec) -> ModelSpec {
                ModelSpec::$variant(s)
            }
        })+

        /// Every family, in the order reports list them.
        pub const FAMILIES: [&FamilyInfo; [$(stringify!($variant)),+].len()] = [$(&$info),+];

        /// The registry entry of a spec's family.
        pub fn info(spec: &ModelSpec) -> &'static FamilyInfo {
            match spec {
                $(ModelSpec::$variant(_) => &$info,)+
            }
        }
    };
}

registry! {
    /// Beckmann (seed 001, Table 1, γ → ∞).
    Beckmann(crate::ndf::beckmann::BeckmannSpec) => crate::ndf::beckmann::INFO,
    /// GGX / Trowbridge–Reitz (seed 001, Table 1, γ = 2).
    Ggx(crate::ndf::ggx::GgxSpec) => crate::ndf::ggx::INFO,
    /// Student's t NDF, STD (seed 001, f = 1/(γ−1)); `gamma: "inf"` is Beckmann.
    Std(crate::ndf::student::StdSpec) => crate::ndf::student::STD_INFO,
    /// Hyper-Cauchy (seed 001, eq 8, f = 1).
    HyperCauchy(crate::ndf::student::HyperCauchySpec) => crate::ndf::student::HYPER_CAUCHY_INFO,
    /// The fixed-variance Student member (seed 001, eq 9, f = 1/(γ−2)); `gamma: "inf"` is
    /// Beckmann.
    StudentFixedVariance(crate::ndf::student::FixedVarianceSpec) => crate::ndf::student::FIXED_VARIANCE_INFO,
    /// The general isotropic family D^G(B, C) (seed 001, eq 1–2).
    StudentGeneral(crate::ndf::student::GeneralSpec) => crate::ndf::student::GENERAL_INFO,
    /// The piecewise-linear NDF (seed 000, eq 1–5).
    PiecewiseLinear(crate::ndf::piecewise::PiecewiseSpec) => crate::ndf::piecewise::INFO,
    /// Two isotropic models combined by eq 1 of seed 000.
    Blend(crate::ndf::blend::BlendSpec) => crate::ndf::blend::INFO,
    /// Generalized-Trowbridge-Reitz (Burley 2012; Smith G1 of seed 004), isotropic.
    Gtr(crate::ndf::gtr::GtrSpec) => crate::ndf::gtr::INFO,
    /// A Gaussian distribution of slopes N(s̄, Σ) (seed 002, eq 1; slope sign of eq 11).
    GaussianSlopes(crate::slopes::gaussian::GaussianSlopesSpec) => crate::slopes::gaussian::INFO,
}

/// The registry entry of a family name.
pub fn by_name(name: &str) -> Option<&'static FamilyInfo> {
    FAMILIES.iter().copied().find(|f| f.name == name)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every family's examples parse, build, and belong to the family that lists them; names
    /// are unique; every family has an example.
    #[test]
    fn the_registry_is_consistent() {
        let mut names = std::collections::BTreeSet::new();
        for f in FAMILIES {
            assert!(names.insert(f.name), "{} twice", f.name);
            assert!(!f.examples.is_empty(), "{} has no example", f.name);
            assert!(!f.documents.is_empty(), "{} cites no document", f.name);
            // A sampler cost where, and only where, the family has the sampler (shards are
            // balanced by it).
            let example: ModelSpec = serde_json::from_str(f.examples[0]).expect("example");
            let model = example.build().expect("example builds");
            for (has, ns, which) in [
                (
                    model.as_sampler().is_some(),
                    f.sampler_cost.normal_ns,
                    "normal",
                ),
                (
                    model.as_visible_sampler().is_some(),
                    f.sampler_cost.visible_ns,
                    "visible",
                ),
            ] {
                assert_eq!(has, ns > 0.0, "{}: {which} sampler cost {ns}", f.name);
            }
            for e in f
                .examples
                .iter()
                .chain(f.stress_specs.iter().map(|(_, s)| s))
            {
                let spec: ModelSpec = serde_json::from_str(e).expect(e);
                assert_eq!(spec.family(), f.name, "{e}");
                assert_eq!(info(&spec).name, f.name, "{e}");
                spec.build().unwrap_or_else(|err| panic!("{e}: {err}"));
            }
        }
    }
}
