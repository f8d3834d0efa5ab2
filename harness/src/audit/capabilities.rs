//! The capabilities a model's type implements, found by the compiler rather than declared a
//! second time: a type that implements `Smith` but whose `as_smith` returns `None` (the
//! default) would be audited on D alone, its Λ never looked at, and pass. [`crate::audit!`]
//! detects every capability trait the type implements at the call site (autoref
//! specialization: for a concrete type the method resolution below picks the impl that
//! requires the trait where the type has it, the fallback otherwise), and the audit turns an
//! implemented but undeclared capability into a failing `audit.capabilities` record.
//!
//! ```
//! use mfh_harness::{audit, Profile};
//! use mfh_reference::{Ndf, NormalSampler, Vec3};
//!
//! // A GGX whose sampler is implemented but not declared through `as_sampler`.
//! struct Forgetful;
//! impl Ndf for Forgetful {
//!     fn d(&self, m: Vec3) -> f64 {
//!         let (a2, c2) = (0.09, m[2] * m[2]);
//!         if m[2] <= 0.0 { return 0.0; }
//!         let t = c2 * (a2 - 1.0) + 1.0;
//!         a2 / (std::f64::consts::PI * t * t)
//!     }
//! }
//! impl NormalSampler for Forgetful {
//!     fn sample_wm(&self, u: [f64; 2]) -> Vec3 {
//!         let phi = 2.0 * std::f64::consts::PI * u[0];
//!         let r = 0.3 * (u[1] / (1.0 - u[1])).sqrt();
//!         let n = (1.0 + r * r).sqrt();
//!         [r * phi.cos() / n, r * phi.sin() / n, 1.0 / n]
//!     }
//! }
//! let m = Forgetful;
//! let report = audit!(m).profile(Profile::Ci).run();
//! assert_eq!(report.failed_checks(), ["audit.capabilities"]);
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

macro_rules! detector {
    ($yes:ident, $no:ident, $method:ident, $bound:path) => {
        #[doc(hidden)]
        pub trait $yes {
            fn $method(&self) -> bool {
                true
            }
        }
        impl<T: $bound> $yes for Probe<'_, T> {}
        #[doc(hidden)]
        pub trait $no {
            fn $method(&self) -> bool {
                false
            }
        }
        impl<T> $no for &Probe<'_, T> {}
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

/// `Audit::of(&model)` with the capability traits of the model's type detected by the
/// compiler ([`crate::audit::capabilities`]): a capability implemented but not declared through
/// its `as_*` method is a failing `audit.capabilities` record instead of a silently skipped
/// set of checks. `model` is a place (a variable or a field) of a concrete type.
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
        let implemented = $crate::audit::capabilities::Implemented {
            smith: (&probe).detect_smith(),
            sampler: (&probe).detect_sampler(),
            visible_sampler: (&probe).detect_visible_sampler(),
            slopes: (&probe).detect_slopes(),
        };
        $crate::Audit::of(model).implemented(implemented)
    }};
}
