//! What each family's samplers cost, for balancing `mfh audit --shard` only
//! ([`super::estimated_cost`]): the registry's measured figure for a reference family
//! ([`mfh_reference::family::FamilyInfo::sampler_cost`], declared with the rest of the family
//! in its file), an assumed one for a family the registry does not know.

pub use mfh_reference::family::SamplerCost;

/// The sampler cost assumed for a family the registry does not know (a user's model): that
/// of the Student family's closed-form samplers, ~50 ns a sample.
pub const UNKNOWN_SAMPLER: SamplerCost = SamplerCost {
    normal_ns: 50.0,
    visible_ns: 50.0,
};

/// The measured cost of `family`'s samplers (its registry entry), or [`UNKNOWN_SAMPLER`] for a
/// family the registry does not know.
pub fn for_family(family: &str) -> SamplerCost {
    mfh_reference::registry::by_name(family).map_or(UNKNOWN_SAMPLER, |f| f.sampler_cost)
}

#[cfg(test)]
mod tests {
    use super::*;
    use mfh_reference::registry::FAMILIES;

    /// Every registry family is costed by its own entry (the registry's test checks that the
    /// entry has a cost where, and only where, the family has the sampler); a family the
    /// registry does not know by the assumed cost.
    #[test]
    fn a_registry_family_is_costed_by_its_entry() {
        for f in FAMILIES {
            assert_eq!(for_family(f.name), f.sampler_cost, "{}", f.name);
        }
        assert_eq!(for_family("ggx").normal_ns, 11.0);
        assert_eq!(for_family("my_renderer_ggx"), UNKNOWN_SAMPLER);
    }
}
