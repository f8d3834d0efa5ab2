//! The capabilities a model's type implements, found by the compiler rather than declared a
//! second time. Rust cannot ask at run time whether a `&dyn Ndf` also implements `Smith`, so
//! `Audit::of` sees only what `Ndf`'s `as_*` methods declare: a type that implements `Smith`
//! but leaves `as_smith` at its default `None` would be audited on D alone, its Λ never looked
//! at. [`crate::audit!`] finds every capability trait the type implements at the call site
//! (autoref specialization: for a concrete type the method resolution below picks the impl that
//! requires the trait where the type has it, the fallback otherwise) and wires it in
//! ([`Wired`]), so the audit runs the checks of everything the type implements.
//!
//! ```
//! use mfh_harness::{audit, Profile};
//! use mfh_harness::model::{Ndf, NormalSampler, Vec3};
//!
//! // A GGX with a sampler, and no `as_*` declaration: `audit!` finds and audits the sampler.
//! struct MyGgx;
//! impl Ndf for MyGgx {
//!     fn d(&self, m: Vec3) -> f64 {
//!         let (a2, c2) = (0.09, m[2] * m[2]);
//!         if m[2] <= 0.0 { return 0.0; }
//!         let t = c2 * (a2 - 1.0) + 1.0;
//!         a2 / (std::f64::consts::PI * t * t)
//!     }
//! }
//! impl NormalSampler for MyGgx {
//!     fn sample_wm(&self, u: [f64; 2]) -> Vec3 {
//!         let phi = 2.0 * std::f64::consts::PI * u[0];
//!         let r = 0.3 * (u[1] / (1.0 - u[1])).sqrt();
//!         let n = (1.0 + r * r).sqrt();
//!         [r * phi.cos() / n, r * phi.sin() / n, 1.0 / n]
//!     }
//! }
//! let m = MyGgx;
//! let report = audit!(m).profile(Profile::Ci).run();
//! assert!(report.passed());
//! assert!(report.records_of("sampling.chi2").count() > 0);
//! ```

use mfh_reference::{Ndf, NormalSampler, SlopeDistribution, Smith, VisibleNormalSampler};
use serde::Serialize;

/// The capability traits a model's type implements, as [`crate::audit!`] detected them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
pub struct Implemented {
    /// `Smith`.
    pub smith: bool,
    /// `NormalSampler`.
    pub sampler: bool,
    /// `VisibleNormalSampler`.
    pub visible_sampler: bool,
    /// `SlopeDistribution`.
    pub slopes: bool,
}

/// The capabilities a model declares through its `as_*` methods: (name, trait, declared).
pub fn declared(model: &dyn Ndf) -> [(&'static str, &'static str, bool); 4] {
    [
        ("smith", "Smith", model.as_smith().is_some()),
        ("sampler", "NormalSampler", model.as_sampler().is_some()),
        (
            "visible_sampler",
            "VisibleNormalSampler",
            model.as_visible_sampler().is_some(),
        ),
        ("slopes", "SlopeDistribution", model.as_slopes().is_some()),
    ]
}

impl Implemented {
    /// Whether capability `name` (as [`declared`] names it) is implemented.
    pub fn has(&self, name: &str) -> bool {
        match name {
            "smith" => self.smith,
            "sampler" => self.sampler,
            "visible_sampler" => self.visible_sampler,
            "slopes" => self.slopes,
            _ => false,
        }
    }
}

/// The probe the detection resolves methods on (used by [`crate::audit!`] only).
#[doc(hidden)]
pub struct Probe<'a, T>(pub &'a T);

// Each detector is a pair of traits with one method of the same name: the first is
// implemented for `Probe<T>` where `T` has the capability and answers the model as that trait
// object; the second for `&Probe<T>`, always, and answers `None`. Calling the method on
// `&probe` picks the first where it applies (no autoref needed) and the second otherwise.
macro_rules! detector {
    ($yes:ident, $no:ident, $method:ident, $bound:ident) => {
        #[doc(hidden)]
        pub trait $yes<'a> {
            fn $method(&self) -> Option<&'a (dyn $bound + Send + Sync)>;
        }
        impl<'a, T: $bound + Send + Sync + 'a> $yes<'a> for Probe<'a, T> {
            fn $method(&self) -> Option<&'a (dyn $bound + Send + Sync)> {
                Some(self.0)
            }
        }
        #[doc(hidden)]
        pub trait $no<'a> {
            fn $method(&self) -> Option<&'a (dyn $bound + Send + Sync)>;
        }
        impl<'a, T> $no<'a> for &Probe<'a, T> {
            fn $method(&self) -> Option<&'a (dyn $bound + Send + Sync)> {
                None
            }
        }
    };
}

detector!(HasSmith, LacksSmith, detect_smith, Smith);
detector!(HasSampler, LacksSampler, detect_sampler, NormalSampler);
detector!(
    HasVisibleSampler,
    LacksVisibleSampler,
    detect_visible_sampler,
    VisibleNormalSampler
);
detector!(HasSlopes, LacksSlopes, detect_slopes, SlopeDistribution);

/// The capability traits [`crate::audit!`] found a model's type to implement, as trait objects
/// of the model itself, ready to be wired.
#[doc(hidden)]
#[derive(Clone, Copy)]
pub struct Found<'a> {
    /// `Smith`, where implemented.
    pub smith: Option<&'a (dyn Smith + Send + Sync)>,
    /// `NormalSampler`, where implemented.
    pub sampler: Option<&'a (dyn NormalSampler + Send + Sync)>,
    /// `VisibleNormalSampler`, where implemented.
    pub visible_sampler: Option<&'a (dyn VisibleNormalSampler + Send + Sync)>,
    /// `SlopeDistribution`, where implemented.
    pub slopes: Option<&'a (dyn SlopeDistribution + Send + Sync)>,
}

impl Found<'_> {
    /// Which traits were found.
    pub fn implemented(&self) -> Implemented {
        Implemented {
            smith: self.smith.is_some(),
            sampler: self.sampler.is_some(),
            visible_sampler: self.visible_sampler.is_some(),
            slopes: self.slopes.is_some(),
        }
    }
}

/// A model with the capabilities [`crate::audit!`] found wired in: each `as_*` answers what the
/// model declares, else the trait its type implements. Every value (D, Λ, the samplers) is
/// still the model's own: the trait objects point at the model.
pub struct Wired<'a, M: ?Sized> {
    model: &'a M,
    found: Found<'a>,
}

impl<'a, M: Ndf + ?Sized> Wired<'a, M> {
    /// `model` with `found` wired in.
    pub fn new(model: &'a M, found: Found<'a>) -> Self {
        Self { model, found }
    }
}

impl<M: Ndf + ?Sized> Ndf for Wired<'_, M> {
    fn d(&self, m: mfh_reference::Vec3) -> f64 {
        self.model.d(m)
    }
    fn d_batch(&self, m: &[mfh_reference::Vec3], out: &mut [f64]) {
        self.model.d_batch(m, out)
    }
    fn as_smith(&self) -> Option<&dyn Smith> {
        self.model
            .as_smith()
            .or(self.found.smith.map(|x| x as &dyn Smith))
    }
    fn as_sampler(&self) -> Option<&dyn NormalSampler> {
        self.model
            .as_sampler()
            .or(self.found.sampler.map(|x| x as &dyn NormalSampler))
    }
    fn as_visible_sampler(&self) -> Option<&dyn VisibleNormalSampler> {
        self.model.as_visible_sampler().or(self
            .found
            .visible_sampler
            .map(|x| x as &dyn VisibleNormalSampler))
    }
    fn as_slopes(&self) -> Option<&dyn SlopeDistribution> {
        self.model
            .as_slopes()
            .or(self.found.slopes.map(|x| x as &dyn SlopeDistribution))
    }
    fn as_visible_moments(&self) -> Option<&dyn mfh_reference::model::VisibleSlopeMoments> {
        self.model.as_visible_moments()
    }
}

/// The gate for a renderer's own model: `Audit::of(&model)` with every capability trait the
/// model's type implements found by the compiler and wired in, so that nothing has to be
/// declared through `Ndf`'s `as_*` methods ([`crate::audit::capabilities`]). The
/// `audit.capabilities` record lists what was found and audited. `model` is a place (a
/// variable or a field) of a concrete type.
#[macro_export]
macro_rules! audit {
    ($model:expr) => {{
        #[allow(unused_imports)]
        use $crate::audit::capabilities::{
            HasSampler as _, HasSlopes as _, HasSmith as _, HasVisibleSampler as _,
            LacksSampler as _, LacksSlopes as _, LacksSmith as _, LacksVisibleSampler as _,
        };
        let model = &$model;
        let probe = $crate::audit::capabilities::Probe(model);
        let found = $crate::audit::capabilities::Found {
            smith: (&probe).detect_smith(),
            sampler: (&probe).detect_sampler(),
            visible_sampler: (&probe).detect_visible_sampler(),
            slopes: (&probe).detect_slopes(),
        };
        $crate::Audit::of_found(model, found)
    }};
}
