//! What each reference family's samplers cost, measured, for balancing `mfh audit --shard`
//! only ([`super::estimated_cost`]). Kept with the harness that uses them, not with the closed
//! forms: they are measurements of one machine, not mathematics.

/// The measured cost of a family's samplers in an audit: wall-clock nanoseconds per sample of
/// its 10⁸-sample chi-square checks in the default scene's thorough audit (sampling and binning
/// on 2 cores while the audit runs other checks beside them; AMD EPYC Zen 4, 2026-12-02). Used
/// only to balance shards: a wrong figure unbalances them, it cannot change a record.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SamplerCost {
    /// `sample_wm` (`sampling.chi2`); 0 where the family has no normal sampler.
    pub normal_ns: f64,
    /// `sample_wm_visible` (`sampling.chi2_visible`); 0 where the family has none.
    pub visible_ns: f64,
}

/// No sampler.
const NONE: SamplerCost = SamplerCost {
    normal_ns: 0.0,
    visible_ns: 0.0,
};

/// The costs by family name (the registry's names, `mfh_reference::registry::FAMILIES`; the
/// test below requires an entry for each, with a cost where and only where the family has the
/// sampler).
const MEASURED: &[(&str, SamplerCost)] = &[
    (
        "beckmann",
        SamplerCost {
            normal_ns: 23.0,
            visible_ns: 634.0,
        },
    ),
    (
        "ggx",
        SamplerCost {
            normal_ns: 11.0,
            visible_ns: 14.0,
        },
    ),
    (
        "std",
        SamplerCost {
            normal_ns: 44.6,
            visible_ns: 0.0,
        },
    ),
    (
        "hyper_cauchy",
        SamplerCost {
            normal_ns: 46.1,
            visible_ns: 0.0,
        },
    ),
    (
        "student_fixed_variance",
        SamplerCost {
            normal_ns: 42.3,
            visible_ns: 0.0,
        },
    ),
    (
        "student_general",
        SamplerCost {
            normal_ns: 43.3,
            visible_ns: 0.0,
        },
    ),
    (
        "piecewise_linear",
        SamplerCost {
            normal_ns: 568.0,
            visible_ns: 0.0,
        },
    ),
    ("blend", NONE),
    (
        "gtr",
        SamplerCost {
            normal_ns: 84.0,
            visible_ns: 0.0,
        },
    ),
    ("gaussian_slopes", NONE),
];

/// The sampler cost assumed for a family the registry does not know (a user's model): that
/// of the Student family's closed-form samplers, ~50 ns a sample.
pub const UNKNOWN_SAMPLER: SamplerCost = SamplerCost {
    normal_ns: 50.0,
    visible_ns: 50.0,
};

/// The measured cost of `family`'s samplers, or [`UNKNOWN_SAMPLER`] for a family the
/// registry does not know.
pub fn for_family(family: &str) -> SamplerCost {
    MEASURED
        .iter()
        .find(|(name, _)| *name == family)
        .map_or(UNKNOWN_SAMPLER, |(_, cost)| *cost)
}

#[cfg(test)]
mod tests {
    use super::*;
    use mfh_reference::registry::FAMILIES;
    use mfh_reference::ModelSpec;

    /// Every registry family has a measured cost, and a cost where, and only where, the
    /// family has the sampler (shards are balanced by it); no entry names another family.
    #[test]
    fn a_cost_where_and_only_where_the_family_has_the_sampler() {
        for f in FAMILIES {
            let cost = MEASURED
                .iter()
                .find(|(name, _)| *name == f.name)
                .map(|(_, c)| *c)
                .unwrap_or_else(|| panic!("{}: no measured sampler cost", f.name));
            let example: ModelSpec = serde_json::from_str(f.examples[0]).expect("example");
            let model = example.build().expect("example builds");
            for (has, ns, which) in [
                (model.as_sampler().is_some(), cost.normal_ns, "normal"),
                (
                    model.as_visible_sampler().is_some(),
                    cost.visible_ns,
                    "visible",
                ),
            ] {
                assert_eq!(has, ns > 0.0, "{}: {which} sampler cost {ns}", f.name);
            }
        }
        for (name, _) in MEASURED {
            assert!(
                FAMILIES.iter().any(|f| f.name == *name),
                "{name} is not a registry family"
            );
        }
        assert_eq!(for_family("my_renderer_ggx"), UNKNOWN_SAMPLER);
    }
}
