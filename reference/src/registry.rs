//! The family registry: the list of families, from which planners, tests, the default scene's
//! coverage test, the eval contract and the value-stability vectors iterate them (so no list of
//! family names is written anywhere else). Each family's file declares its [`FamilyInfo`] and
//! implements [`FamilySpec`] for its spec type (declared in `crate::spec`); one line per family
//! in the `registry!` list below makes [`FAMILIES`], [`info`] and the dispatch of
//! [`ModelSpec`] to its family's [`FamilySpec`]. This file sits above the families: nothing a
//! family imports names it.

use crate::error::ParamError;
use crate::family::{FamilyInfo, FamilySpec};
use crate::model::Model;
use crate::spec::ModelSpec;

/// Declares the families: one line per family, `Variant => INFO`, where `Variant` is the
/// family's [`ModelSpec`] variant (its spec type implements [`FamilySpec`] in the family's
/// file) and `INFO` the family's [`FamilyInfo`]. From this list the macro writes [`FAMILIES`],
/// [`info`] and the dispatch of [`ModelSpec`]'s [`FamilySpec`] implementation. Adding a family
/// is its file (its model, `impl FamilySpec` for its spec type, its `INFO`), its spec type and
/// variant in `crate::spec`, and one line here.
macro_rules! registry {
    ($($variant:ident => $info:path),+ $(,)?) => {
        /// Every family, in the order reports list them.
        pub const FAMILIES: [&FamilyInfo; [$(stringify!($variant)),+].len()] = [$(&$info),+];

        /// The registry entry of a spec's family.
        pub fn info(spec: &ModelSpec) -> &'static FamilyInfo {
            match spec {
                $(ModelSpec::$variant(_) => &$info,)+
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

registry! {
    Beckmann => crate::ndf::beckmann::INFO,
    Ggx => crate::ndf::ggx::INFO,
    Std => crate::ndf::student::STD_INFO,
    HyperCauchy => crate::ndf::student::HYPER_CAUCHY_INFO,
    StudentFixedVariance => crate::ndf::student::FIXED_VARIANCE_INFO,
    StudentGeneral => crate::ndf::student::GENERAL_INFO,
    PiecewiseLinear => crate::ndf::piecewise::INFO,
    Blend => crate::ndf::blend::INFO,
    Gtr => crate::ndf::gtr::INFO,
    GaussianSlopes => crate::slopes::gaussian::INFO,
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
        }
    }
}
