//! Statistical power of a profile: the smallest sampler distortion (the sampled tan²θ raised
//! to 1 + e, [`Defect::SamplerExponent`]) that the statistical checks (`sampling.chi2`,
//! `sampling.ks_marginals`) catch at every seed. Only those checks run, judged at the Šidák
//! level the full gate audit of the model would use (its number of statistical checks), with
//! the seeds the full audit derives for them: the verdicts are those of the full audit. (The
//! deterministic `sampling.pdf_jacobian` also sees this defect; power is about the tests whose
//! sample counts the profile sets.)

use super::mutant::{Defect, Mutated};
use crate::audit::Audit;
use crate::check::{sampling, Profile};
use crate::run::sidak_alpha;
use crate::run::{judge_at, run_plan, AuditOptions};
use crate::subject::Subject;
use crate::tolerance::STATISTICAL_ALPHA;
use mfh_reference::ModelSpec;
use serde::Serialize;
use serde_json::Value;
use std::sync::Arc;

/// The distortions tried: 0.25, 0.5, 1 and 2 %.
pub const DISTORTIONS: [f64; 4] = [0.0025, 0.005, 0.01, 0.02];

/// The samplers measured: (spec, the roughness the exponent is taken about).
pub const SAMPLERS: [(&str, f64); 5] = [
    (r#"{"family":"ggx","alpha":0.3}"#, 0.3),
    (r#"{"family":"beckmann","alpha":0.3}"#, 0.3),
    (r#"{"family":"std","gamma":2.5,"alpha":0.3}"#, 0.3),
    (
        r#"{"family":"hyper_cauchy","gamma":2.0,"alpha":0.25}"#,
        0.25,
    ),
    (r#"{"family":"gtr","gamma":2.5,"alpha":0.4}"#, 0.4),
];

/// One sampler at one distortion and seed.
#[derive(Debug, Clone, Serialize)]
pub struct PowerRun {
    /// The sampler's spec.
    pub model: Value,
    /// The distortion e.
    pub distortion: f64,
    /// The audit seed.
    pub seed: u64,
    /// The statistical checks that failed.
    pub killers: Vec<String>,
    /// The smallest p-value among them.
    pub min_p: f64,
    /// The Šidák level they were judged at.
    pub alpha: f64,
}

/// The detectable distortion of one sampler.
#[derive(Debug, Clone, Serialize)]
pub struct Detectable {
    /// The sampler's spec.
    pub model: Value,
    /// The smallest distortion of [`DISTORTIONS`] caught at every seed (None: none is).
    pub smallest: Option<f64>,
    /// Every run.
    pub runs: Vec<PowerRun>,
}

/// Measures the detectable distortion of each sampler of [`SAMPLERS`] at `profile` over
/// `seeds`.
pub fn measure(
    profile: Profile,
    seeds: &[u64],
    progress: Option<super::Progress<'_>>,
) -> Vec<Detectable> {
    let mut out = Vec::new();
    for (text, scale) in SAMPLERS {
        let Ok(spec) = serde_json::from_str::<ModelSpec>(text) else {
            continue;
        };
        let value = serde_json::to_value(&spec).unwrap_or(Value::Null);
        let mut runs = Vec::new();
        for e in DISTORTIONS {
            let Ok(m) = Mutated::new(&spec, Defect::SamplerExponent { scale, e }) else {
                continue;
            };
            let hints = super::hints_of(&value);
            // The full gate audit's number of statistical checks sets the level.
            let (full, _) = Audit::of(&m).hint(hints.clone()).profile(profile).plan();
            let k = full.iter().filter(|p| p.statistical).count();
            let alpha = sidak_alpha(STATISTICAL_ALPHA.value, k);
            // The name `Audit::of` gives the model by default (it seeds the checks).
            let name = std::any::type_name::<Mutated>();
            let subject = Subject::user(Arc::new(&m), name, hints);
            let plan: Vec<_> = sampling::plan(&subject, profile, "power")
                .into_iter()
                .filter(|p| p.check == "sampling.chi2" || p.check == "sampling.ks_marginals")
                .collect();
            for &seed in seeds {
                let options = AuditOptions {
                    profile,
                    seed,
                    out: None,
                    ..Default::default()
                };
                let (mut records, _, _) = run_plan(&plan, &options);
                judge_at(&mut records, alpha);
                let killers = super::killers(&records);
                let min_p = records
                    .iter()
                    .filter_map(|r| match r.measured {
                        Some(crate::record::Measured::PValue { p, .. }) => Some(p),
                        _ => None,
                    })
                    .fold(f64::INFINITY, f64::min);
                if let Some(f) = progress {
                    f(&format!(
                        "power {text} e = {e} seed {seed:#x}: min p = {min_p:.3e} at α = {alpha:.3e} {}",
                        if killers.is_empty() { "survived" } else { "caught" }
                    ));
                }
                runs.push(PowerRun {
                    model: value.clone(),
                    distortion: e,
                    seed,
                    killers,
                    min_p,
                    alpha,
                });
            }
        }
        let smallest = DISTORTIONS.iter().copied().find(|&e| {
            let at: Vec<_> = runs.iter().filter(|r| r.distortion == e).collect();
            !at.is_empty() && at.iter().all(|r| !r.killers.is_empty())
        });
        out.push(Detectable {
            model: value,
            smallest,
            runs,
        });
    }
    out
}
