//! Running one chi-square test of a model's sampler, as `mfh chi2` asks for it: the request
//! (validated against stated limits, with typed errors naming the field and the limit), the
//! run, and the record it makes (a JSON object). No exit codes and no file writing here: the
//! CLI (`cli/chi2.rs`) maps errors to exit codes and writes tables and heat maps.

pub mod bsdf;

use crate::oracle::chi2::{chi2_test_batch_in, Chi2Config, Chi2Result};
use crate::tolerance::{CELL_RELATIVE_TOLERANCE, KINKED_CELL_RELATIVE_TOLERANCE, MIN_EXPECTED};
use mfh_reference::family::FamilySpec;
use mfh_reference::{Model, ModelSpec, Vec3};
use serde_json::{json, Value};
use std::f64::consts::FRAC_PI_2;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;

/// The largest grid resolution R (R cos θ-rows × 2R φ-columns = 2R² cells). The observed and
/// expected tables take 16 bytes per cell (8 MiB at R = 512); measured on this machine:
/// R = 512 with 10⁷ GGX samples peaks at 49 MB resident and integrates the expected counts in
/// 2.6 s. Memory and integration time grow as R², so R = 10 000 (3.2 GB) and beyond are refused.
pub const MAX_RESOLUTION: usize = 512;

/// The largest sample count, 2³²: counts stay exact in u64 and in f64 (< 2⁵³), and at the
/// measured ≈ 10⁷ samples/s per core (GGX, 2 cores) the run is bounded by ≈ 4 minutes.
pub const MAX_SAMPLES: u64 = 1 << 32;

/// The smallest grid resolution R. The statistic has dof = bins − 1 and needs two bins of
/// expected count ≥ [`MIN_EXPECTED`] (cells below it are pooled). At R = 1 the grid is two
/// φ-halves: both must expect ≥ 5, which at the least sample count 10 is an exact equality that
/// the cubature's round-off breaks (4.999… pools both cells into one bin: measured
/// `--resolution 1 --samples 10` on GGX as FAIL with χ² NaN and dof 0). R = 2 gives 8 cells,
/// 4 of them (one per φ-quarter) in the upper cos θ-row where every reference lobe peaks.
pub const MIN_RESOLUTION: usize = 2;

/// The smallest useful sample count at resolution R: [`MIN_EXPECTED`] samples per cell on
/// average over the 2R² cells, N ≥ MIN_EXPECTED · 2R² (= 10R²; 40 at R = 2). Derivation: a pdf
/// spread evenly over the cells expects N/2R² per cell, so below this N no cell of an even pdf
/// reaches the pooling minimum and every cell is pooled into one bin (dof 0, χ² NaN: a
/// meaningless FAIL instead of a verdict); with R ≥ [`MIN_RESOLUTION`] it also exceeds the
/// 2·MIN_EXPECTED = 10 that two bins need whatever the pdf. (No N gives every pdf a degree of
/// freedom: a lobe inside one cell has none at any N.)
pub fn min_samples(resolution: usize) -> u64 {
    let cells = 2 * (resolution as u64) * (resolution as u64);
    (MIN_EXPECTED as u64) * cells
}

/// The default incidence θi (radians) for visible normals when none is given.
pub const DEFAULT_INCIDENCE: f64 = 0.5;

/// What `mfh chi2` samples.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SamplingKind {
    /// `sample_wm` against `pdf_wm` = D(m)(m·n).
    Normals,
    /// `sample_wm_visible(wi, ·)` against `pdf_wm_visible(wi, ·)` at the incidence.
    Visible,
}

impl SamplingKind {
    /// The name used on the command line and in the record.
    pub fn name(self) -> &'static str {
        match self {
            SamplingKind::Normals => "normals",
            SamplingKind::Visible => "visible",
        }
    }
}

/// A chi-square request as given (e.g. by the command line), before validation.
#[derive(Debug, Clone, PartialEq)]
pub struct Chi2Request {
    /// The model spec as JSON text.
    pub model: String,
    /// Samples to draw.
    pub samples: u64,
    /// Grid resolution R.
    pub resolution: usize,
    /// The seed (already resolved from `MFH_SEED` or the default by the caller).
    pub seed: u64,
    /// The significance level.
    pub alpha: f64,
    /// What to sample.
    pub sampling: SamplingKind,
    /// The incidence θi (radians); only with [`SamplingKind::Visible`].
    pub incidence: Option<f64>,
    /// The incidence azimuth φi (radians); only with [`SamplingKind::Visible`].
    pub azimuth: Option<f64>,
}

/// Why a chi-square request is bad input. Every message names the field and its limit.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Chi2InputError {
    /// The `--model` text is not a valid model spec.
    #[error("--model: {0}")]
    Model(String),
    /// The `--bsdf` text is not a valid reference BSDF spec (the message names the field).
    #[error("--bsdf: {0}")]
    Bsdf(String),
    /// The model has no sampler of the kind asked for.
    #[error("--sampling {sampling}: family `{family}` has no {what}; nothing to test")]
    NoSampler {
        /// The sampling kind.
        sampling: &'static str,
        /// The model family.
        family: String,
        /// The missing method, in words.
        what: &'static str,
    },
    /// A numeric option is outside its stated range.
    #[error("{field} {value} is out of range: {limit}")]
    OutOfRange {
        /// The option (`--resolution`, `--samples`, …).
        field: &'static str,
        /// The value given, as text.
        value: String,
        /// The limit, in words, with its reason.
        limit: String,
    },
    /// An option that only applies to another mode was given.
    #[error("{field} only applies with --sampling visible")]
    NotApplicable {
        /// The option.
        field: &'static str,
    },
}

/// A validated chi-square request: the built model and the run's parameters.
pub struct Chi2Plan {
    /// The model.
    pub model: Box<dyn Model>,
    /// The test's configuration.
    pub config: Chi2Config,
    /// What is sampled.
    pub sampling: SamplingKind,
    /// The incidence (θi, φi) for visible normals.
    pub incidence: Option<(f64, f64)>,
    /// The polar angles where the model's D has a kink for every azimuth (the registry's, e.g.
    /// a piecewise-linear profile's breakpoints): the normals' expected masses are cut there.
    pub theta_kinks: Vec<f64>,
}

fn out_of_range(field: &'static str, value: impl ToString, limit: String) -> Chi2InputError {
    Chi2InputError::OutOfRange {
        field,
        value: value.to_string(),
        limit,
    }
}

/// Validates a request against the stated limits ([`MAX_RESOLUTION`], [`MAX_SAMPLES`],
/// [`min_samples`]) and the model's capabilities.
pub fn validate(request: &Chi2Request) -> Result<Chi2Plan, Chi2InputError> {
    let spec: ModelSpec = serde_json::from_str(&request.model)
        .map_err(|e| Chi2InputError::Model(crate::messages::json_error_message(&e)))?;
    let model = spec
        .build()
        .map_err(|e| Chi2InputError::Model(format!("invalid model parameters: {e}")))?;
    let r = request.resolution;
    if !(MIN_RESOLUTION..=MAX_RESOLUTION).contains(&r) {
        return Err(out_of_range(
            "--resolution",
            r,
            format!(
                "must be in [{MIN_RESOLUTION}, {MAX_RESOLUTION}] (at least {MIN_RESOLUTION} for \
                 two bins of {MIN_EXPECTED} expected counts, one degree of freedom; at most \
                 2R² cells of 16 bytes each and an integration time growing as R²)"
            ),
        ));
    }
    let min = min_samples(r);
    if request.samples > MAX_SAMPLES {
        return Err(out_of_range(
            "--samples",
            request.samples,
            format!(
                "must be at most {MAX_SAMPLES} (2^32: counts exact, run time bounded to \
                 minutes)"
            ),
        ));
    }
    if request.samples < min {
        return Err(out_of_range(
            "--samples",
            request.samples,
            format!(
                "must be at least {min} at --resolution {r} ({MIN_EXPECTED} per cell on average \
                 over 2R² = {} cells; fewer leave the statistic without degrees of freedom)",
                2 * r * r
            ),
        ));
    }
    if !(request.alpha > 0.0 && request.alpha < 1.0) {
        return Err(out_of_range(
            "--alpha",
            request.alpha,
            "must be in (0, 1)".to_string(),
        ));
    }
    let incidence = match request.sampling {
        SamplingKind::Normals => {
            if model.as_sampler().is_none() {
                return Err(Chi2InputError::NoSampler {
                    sampling: "normals",
                    family: model.family().to_string(),
                    what: "normal sampler (sample_wm)",
                });
            }
            if request.incidence.is_some() {
                return Err(Chi2InputError::NotApplicable {
                    field: "--incidence",
                });
            }
            if request.azimuth.is_some() {
                return Err(Chi2InputError::NotApplicable { field: "--azimuth" });
            }
            None
        }
        SamplingKind::Visible => {
            if model.as_visible_sampler().is_none() {
                return Err(Chi2InputError::NoSampler {
                    sampling: "visible",
                    family: model.family().to_string(),
                    what: "visible-normal sampler (sample_wm_visible)",
                });
            }
            let theta = request.incidence.unwrap_or(DEFAULT_INCIDENCE);
            if !(0.0..FRAC_PI_2).contains(&theta) {
                return Err(out_of_range(
                    "--incidence",
                    theta,
                    "must be in [0, π/2) radians (strictly above the horizon)".to_string(),
                ));
            }
            let phi = request.azimuth.unwrap_or(0.0);
            if !phi.is_finite() {
                return Err(out_of_range(
                    "--azimuth",
                    phi,
                    "must be a finite angle in radians".to_string(),
                ));
            }
            Some((theta, phi))
        }
    };
    Ok(Chi2Plan {
        model,
        config: Chi2Config {
            resolution: r,
            samples: request.samples,
            seed: request.seed,
            alpha: request.alpha,
        },
        sampling: request.sampling,
        incidence,
        theta_kinks: spec.theta_kinks(),
    })
}

/// Progress of a run: samples drawn so far of those planned.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SampleProgress {
    /// Samples drawn so far (counted in batches, so it lags by less than a batch per thread).
    pub done: u64,
    /// Samples planned.
    pub planned: u64,
}

/// How often (in samples per thread) the shared progress counter is updated: rarely enough that
/// two threads do not fight over its cache line (a sample costs ≈ 45 ns).
const PROGRESS_BATCH: u64 = 1 << 14;

thread_local! {
    static LOCAL_COUNT: std::cell::Cell<u64> = const { std::cell::Cell::new(0) };
}

/// Runs a validated request. `progress`, if given, shares the count of samples drawn (updated
/// every [`PROGRESS_BATCH`] samples per thread); reading it never changes the result. The
/// model's batch samplers draw the samples (`sample_wm_batch`, `sample_wm_visible_batch`):
/// the same normals as the scalar methods.
pub fn run(plan: &Chi2Plan, progress: Option<Arc<AtomicU64>>) -> Chi2Result {
    // Counted per block of samples (the batch samplers' unit), flushed to the shared counter
    // once a thread holds PROGRESS_BATCH or more.
    let count = |progress: &Option<Arc<AtomicU64>>, n: usize| {
        if let Some(p) = progress {
            LOCAL_COUNT.with(|c| {
                let n = c.get() + n as u64;
                if n >= PROGRESS_BATCH {
                    p.fetch_add(n, Ordering::Relaxed);
                    c.set(0);
                } else {
                    c.set(n);
                }
            });
        }
    };
    match (plan.sampling, plan.incidence) {
        (SamplingKind::Visible, Some((theta, phi))) => {
            let v = plan
                .model
                .as_visible_sampler()
                .expect("validate checked the visible sampler");
            let wi = mfh_reference::geometry::from_spherical(theta, phi);
            // The visible density has a kink along the terminator of wi: cells that straddle
            // it converge slowly, so they are integrated to 1e-6 (still ≪ √count).
            chi2_test_batch_in(
                &|u: &[[f64; 2]], m: &mut [Vec3]| {
                    count(&progress, u.len());
                    v.sample_wm_visible_batch(wi, u, m)
                },
                &|m| v.pdf_wm_visible(wi, m),
                &plan.config,
                KINKED_CELL_RELATIVE_TOLERANCE,
                None,
                &[],
            )
        }
        _ => {
            let s = plan
                .model
                .as_sampler()
                .expect("validate checked the normal sampler");
            // Cut at the registry's kinks, as the audit's `sampling.chi2` does (the piecewise
            // material of the default scene: 15.4 s for the expected masses at R = 71 with its
            // breakpoints inside the cells).
            chi2_test_batch_in(
                &|u: &[[f64; 2]], m: &mut [Vec3]| {
                    count(&progress, u.len());
                    s.sample_wm_batch(u, m)
                },
                &|m| s.pdf_wm(m),
                &plan.config,
                CELL_RELATIVE_TOLERANCE,
                None,
                &plan.theta_kinks,
            )
        }
    }
}

fn finite_or_null(x: f64) -> Value {
    if x.is_finite() {
        json!(x)
    } else {
        Value::Null
    }
}

/// The record of a run as one JSON object (`mfh chi2 --json`); `artefacts` lists the files the
/// caller wrote.
pub fn record(plan: &Chi2Plan, result: &Chi2Result, artefacts: &[String]) -> Value {
    json!({
        "model": plan.model.spec(),
        "statistic": finite_or_null(result.statistic),
        "dof": result.dof,
        "p_value": result.p_value,
        "components": result.components,
        "alpha": result.alpha,
        "verdict": result.verdict,
        "reason": result.reason.as_ref().map(|r| r.to_string()),
        "samples": result.samples,
        "seed": result.seed,
        "resolution": result.resolution,
        "samples_per_second": finite_or_null(result.samples_per_second()),
        "pooled_cells": result.pooled_cells,
        "expected_mass": result.expected_mass,
        "expected_error_bound": result.expected_error_bound,
        "sampling_seconds": result.sampling_seconds,
        "integration_seconds": result.integration_seconds,
        "artefacts": artefacts,
        "sampling": plan.sampling.name(),
        "incidence": match plan.incidence {
            Some((theta, phi)) => json!({"theta": theta, "phi": phi}),
            None => Value::Null,
        },
    })
}

/// The command line that reproduces a run.
pub fn reproduce_command(plan: &Chi2Plan) -> String {
    let spec_text = serde_json::to_string(&plan.model.spec()).unwrap_or_default();
    let c = &plan.config;
    let mut s = format!(
        "mfh chi2 --model '{spec_text}' --samples {} --resolution {} --seed {}",
        c.samples, c.resolution, c.seed
    );
    if let Some((theta, phi)) = plan.incidence {
        s.push_str(&format!(
            " --sampling visible --incidence {theta} --azimuth {phi}"
        ));
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    fn request(model: &str) -> Chi2Request {
        Chi2Request {
            model: model.to_string(),
            samples: 1_000_000,
            resolution: 32,
            seed: 1,
            alpha: 1e-4,
            sampling: SamplingKind::Normals,
            incidence: None,
            azimuth: None,
        }
    }

    const GGX: &str = r#"{"family":"ggx","alpha":0.3}"#;

    fn field_of(e: Chi2InputError) -> &'static str {
        match e {
            Chi2InputError::OutOfRange { field, .. } | Chi2InputError::NotApplicable { field } => {
                field
            }
            Chi2InputError::Model(_) => "--model",
            Chi2InputError::Bsdf(_) => "--bsdf",
            Chi2InputError::NoSampler { .. } => "--sampling",
        }
    }

    /// `mfh chi2` of a piecewise-linear model cuts the expected masses at the profile's
    /// breakpoints (the registry's kinks), as the audit does: with the breakpoints inside the
    /// cells the cubature stopped at its depth limit with an error bound of 8.3e-5 at R = 16
    /// (and took 3.6 s); cut, every cell's mass is resolved (bound 1.6e-10) and the test passes.
    #[test]
    fn piecewise_expected_masses_are_cut_at_the_breakpoints() {
        let model = r#"{"family":"piecewise_linear",
            "x":{"theta":[0.0,0.5,1.0,1.5707963267948966],"value":[1.0,0.6,0.1,0.0]},
            "y":{"theta":[0.0,0.3,0.9,1.5707963267948966],"value":[2.0,0.8,0.05,0.0]}}"#;
        let mut r = request(model);
        r.resolution = 16;
        r.samples = 100_000;
        let plan = validate(&r).expect("valid request");
        assert_eq!(plan.theta_kinks, vec![0.3, 0.5, 0.9, 1.0]);
        let result = run(&plan, None);
        assert!(
            result.expected_error_bound < 1e-8,
            "error bound {:e}",
            result.expected_error_bound
        );
        assert!(
            (result.expected_mass - 1.0).abs() < 1e-8,
            "{}",
            result.expected_mass
        );
        assert_eq!(result.verdict, crate::oracle::chi2::TestOutcome::Pass);
        // A model without kinks has none.
        assert!(validate(&request(GGX)).unwrap().theta_kinks.is_empty());
    }

    #[test]
    fn limits_name_their_field() {
        let bad = |f: &dyn Fn(&mut Chi2Request)| {
            let mut r = request(GGX);
            f(&mut r);
            field_of(validate(&r).err().expect("rejected"))
        };
        assert_eq!(bad(&|r| r.resolution = usize::MAX), "--resolution");
        assert_eq!(bad(&|r| r.resolution = 100_000), "--resolution");
        assert_eq!(bad(&|r| r.resolution = 10_000), "--resolution");
        assert_eq!(bad(&|r| r.resolution = 0), "--resolution");
        assert_eq!(bad(&|r| r.samples = 1_000_000_000_000_000), "--samples");
        assert_eq!(bad(&|r| r.samples = 1), "--samples");
        assert_eq!(bad(&|r| r.samples = 0), "--samples");
        assert_eq!(bad(&|r| r.alpha = f64::NAN), "--alpha");
        assert_eq!(bad(&|r| r.incidence = Some(0.3)), "--incidence");
        assert_eq!(bad(&|r| r.azimuth = Some(0.3)), "--azimuth");
        let visible = |theta: Option<f64>, phi: Option<f64>| {
            let mut r = request(GGX);
            r.sampling = SamplingKind::Visible;
            r.incidence = theta;
            r.azimuth = phi;
            validate(&r).map(|p| p.incidence)
        };
        assert_eq!(
            field_of(visible(Some(0.2), Some(f64::NAN)).unwrap_err()),
            "--azimuth"
        );
        assert_eq!(
            field_of(visible(Some(f64::NAN), None).unwrap_err()),
            "--incidence"
        );
        assert_eq!(
            field_of(visible(Some(FRAC_PI_2), None).unwrap_err()),
            "--incidence"
        );
        assert_eq!(visible(None, None).unwrap(), Some((DEFAULT_INCIDENCE, 0.0)));
        // The smallest accepted sample count runs to a verdict with degrees of freedom.
        let mut r = request(GGX);
        r.resolution = 4;
        r.samples = min_samples(4);
        let plan = validate(&r).unwrap();
        let result = run(&plan, None);
        assert!(result.dof > 0 && result.statistic.is_finite(), "{result:?}");
    }

    #[test]
    fn progress_counts_every_sample_batch_without_changing_the_result() {
        let mut r = request(GGX);
        r.resolution = 8;
        r.samples = 300_000;
        let plan = validate(&r).unwrap();
        let counter = Arc::new(AtomicU64::new(0));
        let with = run(&plan, Some(counter.clone()));
        let without = run(&plan, None);
        assert_eq!(with.observed, without.observed);
        let done = counter.load(Ordering::Relaxed);
        // Each thread may hold back less than one batch.
        let threads = rayon::current_num_threads() as u64;
        assert!(
            done <= r.samples && done + threads * PROGRESS_BATCH >= r.samples,
            "{done}"
        );
    }
}
