//! The power of the `ci` profile for a float32 model: GGX α = 0.3 computed in f32
//! arithmetic the way a renderer writes it (D, Λ, the normal sampler and its pdf: the model of
//! `harness/tests/float32.rs` without its visible-normal sampler, and with Λ written without
//! its cancellation near the normal, which an f64 build needs), declared `Precision::F32`, with
//! one distortion of size e:
//!
//! - `d`: D scaled by (1 + e) (pdf_wm keeps the true D);
//! - `pdf`: pdf_wm scaled by (1 + e);
//! - `exponent`: the sampled tan²θ/α² raised to 1 + e;
//! - `roughness`: the sampler draws from α(1 + e) (D and the pdf keep α).
//!
//! For each, the smallest e of {1e-4, 3e-4, 1e-3, 3e-3, 1e-2, 3e-2} whose `Audit::of(…)
//! .profile(Profile::Ci)` fails at every one of seeds 1, 2, 3, and the checks that failed. The
//! same for the model computed in f64 (declared f64), for comparison. The undistorted models
//! are audited first at the same seeds and must pass.
//!
//! ```text
//! cargo run --release -p mfh-harness --example power_f32 [-- f32|f64]
//! ```
//!
//! Prints a Markdown table (docs/gate.md, "What the ci profile catches in float32"), and every
//! run's failing checks on standard error.

use mfh_harness::{Audit, Precision, Profile};
use mfh_reference::{Ndf, NormalSampler, Smith, Vec3};
use std::collections::BTreeSet;

/// The distortions tried.
const ERRORS: [f64; 10] = [1e-6, 3e-6, 1e-5, 3e-5, 1e-4, 3e-4, 1e-3, 3e-3, 1e-2, 3e-2];
/// The audit seeds.
const SEEDS: [u64; 3] = [1, 2, 3];

/// Which quantity is distorted.
#[derive(Clone, Copy, PartialEq, Debug)]
enum Kind {
    None,
    D,
    Pdf,
    Exponent,
    Roughness,
}

impl Kind {
    fn name(self) -> &'static str {
        match self {
            Kind::None => "none",
            Kind::D => "D × (1 + e)",
            Kind::Pdf => "pdf_wm × (1 + e)",
            Kind::Exponent => "sampled tan²θ exponent 1 + e",
            Kind::Roughness => "sampler's α × (1 + e)",
        }
    }
}

/// GGX in arithmetic `$F` (f32 or f64), with one distortion.
macro_rules! ggx {
    ($name:ident, $F:ty, $guard:expr) => {
        struct $name {
            alpha: $F,
            kind: Kind,
            e: $F,
        }

        impl $name {
            fn d_in(&self, m: [$F; 3]) -> $F {
                if m[2] <= 0.0 {
                    return 0.0;
                }
                let cos2 = m[2] * m[2];
                let tan2 = (m[0] * m[0] + m[1] * m[1]).max(0.0) / cos2;
                if !tan2.is_finite() {
                    return 0.0;
                }
                let cos4 = cos2 * cos2;
                // pbrt-v4's guard in float32 (cos⁴θ underflows near grazing).
                if cos4 < $guard {
                    return 0.0;
                }
                let e = tan2 / (self.alpha * self.alpha);
                let pi = std::f64::consts::PI as $F;
                1.0 / (pi * self.alpha * self.alpha * cos4 * (1.0 + e) * (1.0 + e))
            }
            fn factor(&self, kind: Kind) -> $F {
                if self.kind == kind {
                    1.0 + self.e
                } else {
                    1.0
                }
            }
        }

        impl Ndf for $name {
            fn d(&self, m: Vec3) -> f64 {
                let m = [m[0] as $F, m[1] as $F, m[2] as $F];
                (self.d_in(m) * self.factor(Kind::D)) as f64
            }
            fn as_smith(&self) -> Option<&dyn Smith> {
                Some(self)
            }
            fn as_sampler(&self) -> Option<&dyn NormalSampler> {
                Some(self)
            }
        }

        impl Smith for $name {
            fn lambda(&self, w: Vec3) -> f64 {
                let w = [w[0] as $F, w[1] as $F, w[2] as $F];
                let tan2 = (w[0] * w[0] + w[1] * w[1]) / (w[2] * w[2]);
                if !tan2.is_finite() {
                    return f64::INFINITY;
                }
                // (√(1 + α²tan²θ) − 1)/2 without its cancellation near the normal.
                let t2 = self.alpha * self.alpha * tan2;
                let l = t2 / (2.0 * (1.0 + (1.0 + t2).sqrt()));
                (if w[2] < 0.0 { -1.0 - l } else { l }) as f64
            }
        }

        impl NormalSampler for $name {
            fn sample_wm(&self, u: [f64; 2]) -> Vec3 {
                let (u0, u1) = (u[0] as $F, u[1] as $F);
                let mut ratio = u0 / (1.0 - u0);
                if self.kind == Kind::Exponent {
                    ratio = ratio.powf(1.0 + self.e);
                }
                let a = self.alpha * self.factor(Kind::Roughness);
                let tan2 = a * a * ratio;
                let cos = 1.0 / (1.0 + tan2).sqrt();
                let sin = (1.0 - cos * cos).max(0.0).sqrt();
                let phi = 2.0 * (std::f64::consts::PI as $F) * u1;
                [
                    (sin * phi.cos()) as f64,
                    (sin * phi.sin()) as f64,
                    cos as f64,
                ]
            }
            fn pdf_wm(&self, m: Vec3) -> f64 {
                let m = [m[0] as $F, m[1] as $F, m[2] as $F];
                (self.d_in(m) * m[2].max(0.0) * self.factor(Kind::Pdf)) as f64
            }
        }
    };
}

ggx!(Ggx32, f32, 1e-16);
ggx!(Ggx64, f64, f64::MIN_POSITIVE);

/// The checks that did not pass (fail, error, unexpected pass) of one audit.
fn audit(kind: Kind, e: f64, single: bool, seed: u64) -> BTreeSet<String> {
    let report = if single {
        let m = Ggx32 {
            alpha: 0.3,
            kind,
            e: e as f32,
        };
        Audit::of(&m)
            .precision(Precision::F32)
            .profile(Profile::Ci)
            .seed(seed)
            .run()
    } else {
        let m = Ggx64 {
            alpha: 0.3,
            kind,
            e,
        };
        Audit::of(&m).profile(Profile::Ci).seed(seed).run()
    };
    report
        .records
        .iter()
        .filter(|r| r.verdict.is_failure())
        .map(|r| r.check.clone())
        .collect()
}

/// The smallest e of [`ERRORS`] at which every seed's audit has a failing check that
/// `counts` accepts, and the checks that failed there (at any seed).
fn smallest(runs: &[(f64, Vec<BTreeSet<String>>)], counts: &dyn Fn(&str) -> bool) -> String {
    for (e, per_seed) in runs {
        if per_seed.iter().all(|f| f.iter().any(|c| counts(c))) {
            let by: BTreeSet<&str> = per_seed
                .iter()
                .flatten()
                .map(|c| c.as_str())
                .filter(|c| counts(c))
                .collect();
            return format!("{e:e} ({})", by.into_iter().collect::<Vec<_>>().join(", "));
        }
    }
    "none ≤ 3e-2".into()
}

fn main() {
    println!(
        "| precision | distortion | smallest e caught at seeds 1, 2, 3 (by) | by chi-square or KS alone |"
    );
    println!("|---|---|---|---|");
    // `f32`, `f64` or both (the default).
    let only = std::env::args().nth(1);
    let precisions: Vec<bool> = [true, false]
        .into_iter()
        .filter(|&single| match only.as_deref() {
            Some("f32") => single,
            Some("f64") => !single,
            _ => true,
        })
        .collect();
    for single in precisions {
        let precision = if single { "f32" } else { "f64" };
        for seed in SEEDS {
            let failed = audit(Kind::None, 0.0, single, seed);
            eprintln!("{precision} control seed {seed}: failing {failed:?}");
            assert!(
                failed.is_empty(),
                "the undistorted {precision} model fails: {failed:?}"
            );
        }
        for kind in [Kind::D, Kind::Pdf, Kind::Exponent, Kind::Roughness] {
            let runs: Vec<(f64, Vec<BTreeSet<String>>)> = ERRORS
                .iter()
                .map(|&e| {
                    let per_seed: Vec<BTreeSet<String>> =
                        SEEDS.iter().map(|&s| audit(kind, e, single, s)).collect();
                    eprintln!("{precision} {kind:?} e = {e:e}: {per_seed:?}");
                    (e, per_seed)
                })
                .collect();
            let any = smallest(&runs, &|_| true);
            let statistical = smallest(&runs, &|c| {
                c == "sampling.chi2" || c == "sampling.ks_marginals"
            });
            println!("| {precision} | {} | {any} | {statistical} |", kind.name());
        }
    }
}
