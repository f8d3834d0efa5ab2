//! The family registry: what is known of every family, written from the one list of families
//! (`families!` in `crate::spec`, one entry per family naming its [`ModelSpec`] variant, spec
//! type and name). From that list the macro below writes [`FAMILIES`] (each family's
//! [`FamilyInfo`], which its file declares as `SpecType::INFO`: sources, examples, stress
//! values, flags and measured sampler cost), [`info`], and the dispatch of [`ModelSpec`] to its
//! family's [`FamilySpec`] (the constructor). Planners, tests, the default scene, the eval
//! contract, the shard balancer's sampler costs and the value-stability vectors iterate
//! [`FAMILIES`], so no list of family names is written anywhere else. This file sits above the
//! families and reaches them only through their spec types: nothing a family imports names it.

use crate::error::ParamError;
use crate::family::{FamilyInfo, FamilySpec};
use crate::model::Model;
// Every spec type, by the names the list gives them.
use crate::spec::*;

/// Writes the registry from the list of families (`families!` hands it over): [`FAMILIES`],
/// [`info`], the dispatch of [`ModelSpec`]'s [`FamilySpec`] implementation, and a check when
/// the crate compiles that each family's `SpecType::INFO` carries the entry's name.
macro_rules! registry {
    ($($(#[$doc:meta])* $variant:ident($spec:ty) = $name:literal),+ $(,)?) => {
        // The name in a family's `INFO` is its `family` key.
        $(const _: () = assert!(
            same_str(<$spec>::INFO.name, $name),
            concat!("the FamilyInfo of the spec type of \"", $name, "\" names another family")
        );)+

        /// Every family, in the order reports list them.
        pub const FAMILIES: [&FamilyInfo; [$($name),+].len()] = [$(&<$spec>::INFO),+];

        /// The registry entry of a spec's family.
        pub fn info(spec: &ModelSpec) -> &'static FamilyInfo {
            match spec {
                $(ModelSpec::$variant(_) => &<$spec>::INFO,)+
            }
        }

        /// The family's own spec inside a [`ModelSpec`]: its parameters, validation and
        /// construction.
        fn family_spec(spec: &ModelSpec) -> &dyn FamilySpec {
            match spec {
                $(ModelSpec::$variant(s) => s,)+
            }
        }
    };
}

families!(registry);

/// Whether two strings are equal, in a constant (the registry's check of the names).
const fn same_str(a: &str, b: &str) -> bool {
    let (a, b) = (a.as_bytes(), b.as_bytes());
    if a.len() != b.len() {
        return false;
    }
    let mut i = 0;
    while i < a.len() {
        if a[i] != b[i] {
            return false;
        }
        i += 1;
    }
    true
}

/// The registry entry of a family name.
pub fn by_name(name: &str) -> Option<&'static FamilyInfo> {
    FAMILIES.iter().copied().find(|f| f.name == name)
}

/// Any spec is its family's spec: what a composite family (the blend) needs of the specs it
/// holds, without naming the families.
impl FamilySpec for ModelSpec {
    fn build(&self) -> Result<Box<dyn Model>, ParamError> {
        family_spec(self).build()
    }

    fn smith_limit(&self) -> Option<(&'static str, f64)> {
        family_spec(self).smith_limit()
    }

    fn tail_exponent(&self) -> Option<f64> {
        family_spec(self).tail_exponent()
    }

    fn theta_kinks(&self) -> Vec<f64> {
        family_spec(self).theta_kinks()
    }

    fn mean_slope(&self) -> [f64; 2] {
        family_spec(self).mean_slope()
    }
}

impl ModelSpec {
    /// Validates the parameters and builds the model ([`FamilySpec::build`], callable without
    /// importing the trait).
    pub fn build(&self) -> Result<Box<dyn Model>, ParamError> {
        family_spec(self).build()
    }

    /// Why the model has no Smith Λ (and so no G1 or G2), if that follows from its parameters
    /// ([`FamilySpec::smith_limit`]). The message names the field and the limit.
    pub fn smith_limit(&self) -> Option<String> {
        let (field, value) = family_spec(self).smith_limit()?;
        Some(format!(
            "{} {field} = {value} has no Smith Λ: Λ diverges for {field} ≤ 3/2 (the mean \
             slope is infinite); masking needs {field} > 3/2",
            self.family()
        ))
    }
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
            // A measured sampler cost where, and only where, the family has the sampler
            // (the shard balancer prices its sampling checks by it).
            let example: ModelSpec = serde_json::from_str(f.examples[0]).expect("example");
            let model = example.build().expect("example builds");
            let cost = f.sampler_cost;
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
    }

    /// A family cannot be left out of the registry: every `FamilyInfo` declared in the crate's
    /// sources is an entry of [`FAMILIES`], and the lists the registry writes hold every entry
    /// ([`by_name`] finds it; each example parses to a [`ModelSpec`] variant whose [`info`] is
    /// the entry and which serializes under the entry's name). Every other list of families
    /// (the default scene, the eval contract, the value-stability vectors, the shard balancer's
    /// costs) iterates [`FAMILIES`] and has its own coverage test.
    #[test]
    fn every_declared_family_is_in_the_derived_lists() {
        let src = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
        let mut declared = Vec::new();
        // The declaration's form, not written here literally (this file would match it).
        let needle = format!(": {0} = {0} {{", "FamilyInfo");
        let mut dirs = vec![src];
        while let Some(dir) = dirs.pop() {
            for entry in std::fs::read_dir(&dir).expect("reads src") {
                let path = entry.expect("entry").path();
                if path.is_dir() {
                    dirs.push(path);
                    continue;
                }
                let text = std::fs::read_to_string(&path).expect("reads a source");
                for (at, _) in text.match_indices(needle.as_str()) {
                    let rest = &text[at..];
                    let name = rest
                        .split_once("name: \"")
                        .and_then(|(_, r)| r.split_once('"'))
                        .map(|(n, _)| n.to_string())
                        .unwrap_or_else(|| {
                            panic!("{}: a FamilyInfo without a name", path.display())
                        });
                    declared.push(name);
                }
            }
        }
        assert!(declared.len() >= FAMILIES.len(), "found {declared:?}");
        for name in &declared {
            assert!(
                by_name(name).is_some(),
                "the family {name} declares a FamilyInfo but has no registry entry"
            );
        }
        for f in FAMILIES {
            assert!(declared.iter().any(|n| n == f.name), "{}", f.name);
            assert_eq!(by_name(f.name).map(|b| b.name), Some(f.name));
            for e in f.examples {
                let spec: ModelSpec = serde_json::from_str(e).expect(e);
                assert_eq!(info(&spec).name, f.name, "{e}");
                let json = serde_json::to_value(&spec).expect("serializes");
                assert_eq!(json["family"], f.name, "{e}");
            }
        }
        assert!(by_name("my_renderer_ggx").is_none());
    }
}
