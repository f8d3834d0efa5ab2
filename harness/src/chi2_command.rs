//! `mfh chi2`: the chi-square test of a model's normal sampler from the command line, with
//! text or JSON output and optional observed/expected tables (JSON) and heat maps (SVG).

use crate::cli::EXIT_BAD_INPUT;
use crate::oracle::chi2::{
    chi2_test_sampler, chi2_test_to, Chi2Config, Chi2Result, Verdict, DEFAULT_SEED,
    KINKED_CELL_RELATIVE_TOLERANCE,
};
use mfh_reference::ModelSpec;
use serde_json::{json, Value};
use std::io::Write;
use std::path::{Path, PathBuf};

/// The options of `mfh chi2`, as parsed by the CLI.
#[derive(Debug, Clone, PartialEq)]
pub struct Chi2Options {
    /// The model spec as JSON text.
    pub model: String,
    /// Samples to draw.
    pub samples: u64,
    /// Grid resolution R (R cos θ-rows × 2R φ-columns).
    pub resolution: usize,
    /// The seed; `None` takes `MFH_SEED` or the default seed.
    pub seed: Option<u64>,
    /// The significance level.
    pub alpha: f64,
    /// Print one JSON object instead of text.
    pub json: bool,
    /// Write `chi2_observed.json`, `chi2_expected.json` and the heat maps
    /// `chi2_observed.svg`, `chi2_expected.svg`, `chi2_difference.svg` into this folder.
    pub out: Option<PathBuf>,
    /// What to sample: normals (`sample_wm` against `pdf_wm`) or visible normals
    /// (`sample_wm_visible` against `pdf_wm_visible` at the incidence).
    pub sampling: SamplingKind,
    /// The incidence θi (radians) for visible normals.
    pub incidence: f64,
    /// The incidence azimuth φi (radians) for visible normals.
    pub azimuth: f64,
}

/// What `mfh chi2` samples.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum SamplingKind {
    /// `sample_wm` against `pdf_wm` = D(m)(m·n).
    Normals,
    /// `sample_wm_visible(wi, ·)` against `pdf_wm_visible(wi, ·)` at the incidence.
    Visible,
}

/// Runs `mfh chi2`; returns the exit status (0 pass, 1 fail, 2 bad input).
pub fn run_chi2(options: &Chi2Options, stdout: &mut dyn Write, stderr: &mut dyn Write) -> i32 {
    let bad = |stderr: &mut dyn Write, message: String| {
        let _ = writeln!(stderr, "mfh chi2: {message}");
        EXIT_BAD_INPUT
    };
    let spec: ModelSpec = match serde_json::from_str(&options.model) {
        Ok(spec) => spec,
        Err(e) => return bad(stderr, format!("bad --model spec: {e}")),
    };
    let model = match spec.build() {
        Ok(model) => model,
        Err(e) => return bad(stderr, format!("invalid model parameters: {e}")),
    };
    if options.sampling == SamplingKind::Normals && model.as_sampler().is_none() {
        return bad(
            stderr,
            format!(
                "family `{}` has no normal sampler (sample_wm); nothing to test",
                model.family()
            ),
        );
    }
    if options.sampling == SamplingKind::Visible {
        if model.as_visible_sampler().is_none() {
            return bad(
                stderr,
                format!(
                    "family `{}` has no visible-normal sampler (sample_wm_visible); nothing to \
                     test",
                    model.family()
                ),
            );
        }
        let valid = options.incidence >= 0.0
            && options.incidence < std::f64::consts::FRAC_PI_2
            && options.azimuth.is_finite();
        if !valid {
            return bad(
                stderr,
                format!(
                    "--incidence {} must be in [0, π/2) and --azimuth finite",
                    options.incidence
                ),
            );
        }
    }
    if options.resolution == 0 || options.samples == 0 {
        return bad(stderr, "--samples and --resolution must be ≥ 1".to_string());
    }
    if !(options.alpha > 0.0 && options.alpha < 1.0) {
        return bad(
            stderr,
            format!("--alpha {} is not in (0, 1)", options.alpha),
        );
    }
    let seed = match options.seed {
        Some(seed) => seed,
        None => match std::env::var("MFH_SEED") {
            Ok(text) => match text.trim().parse() {
                Ok(seed) => seed,
                Err(e) => return bad(stderr, format!("MFH_SEED {text:?}: {e}")),
            },
            Err(_) => DEFAULT_SEED,
        },
    };
    let config = Chi2Config {
        resolution: options.resolution,
        samples: options.samples,
        seed,
        alpha: options.alpha,
    };
    let result = match (
        options.sampling,
        model.as_sampler(),
        model.as_visible_sampler(),
    ) {
        (SamplingKind::Normals, Some(sampler), _) => chi2_test_sampler(sampler, &config),
        (SamplingKind::Visible, _, Some(v)) => {
            let wi = mfh_reference::geometry::from_spherical(options.incidence, options.azimuth);
            // The visible density has a kink along the terminator of wi: cells that straddle
            // it converge slowly, so they are integrated to 1e-6 (still ≪ √count).
            chi2_test_to(
                &|u| v.sample_wm_visible(wi, u),
                &|m| v.pdf_wm_visible(wi, m),
                &config,
                KINKED_CELL_RELATIVE_TOLERANCE,
            )
        }
        _ => return bad(stderr, "no sampler for this --sampling".to_string()),
    };
    let mut artefacts = Vec::new();
    if let Some(dir) = &options.out {
        let name = crate::report::artefacts::model_name(&json!(model.spec()));
        match write_artefacts(dir, &name, &result) {
            Ok(paths) => artefacts = paths,
            Err(e) => {
                return bad(
                    stderr,
                    format!(
                        "cannot write tables and heat maps to {}: {e}",
                        dir.display()
                    ),
                )
            }
        }
    }
    let artefacts: Vec<String> = artefacts.iter().map(|p| p.display().to_string()).collect();
    let spec_text = serde_json::to_string(&model.spec()).unwrap_or_default();
    let reason = result.reason.as_ref().map(|r| r.to_string());
    let written = if options.json {
        let value = json!({
            "model": model.spec(),
            "statistic": finite_or_null(result.statistic),
            "dof": result.dof,
            "p_value": result.p_value,
            "alpha": result.alpha,
            "verdict": result.verdict,
            "reason": reason,
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
            "sampling": if options.sampling == SamplingKind::Visible { "visible" } else { "normals" },
            "incidence": if options.sampling == SamplingKind::Visible {
                json!({"theta": options.incidence, "phi": options.azimuth})
            } else {
                Value::Null
            },
        });
        writeln!(stdout, "{value}")
    } else {
        let r = &result;
        writeln!(
            stdout,
            "model {spec_text}\n\
             grid {} φ × {} cos θ cells, {} samples, seed {}\n\
             statistic {:.4}, dof {}, p-value {:.6e}, pooled cells {}\n\
             expected mass {:.12} (cubature error bound {:.2e} counts)\n\
             sampling+binning {:.3e} samples/s ({:.3} s), expected-count integration {:.3} s\n\
             verdict {} at α = {:e}{}\n{}\
             reproduce: mfh chi2 --model '{spec_text}' --samples {} --resolution {} --seed {}{}",
            2 * r.resolution,
            r.resolution,
            r.samples,
            r.seed,
            r.statistic,
            r.dof,
            r.p_value,
            r.pooled_cells,
            r.expected_mass,
            r.expected_error_bound,
            r.samples_per_second(),
            r.sampling_seconds,
            r.integration_seconds,
            if r.verdict == Verdict::Pass {
                "pass"
            } else {
                "FAIL"
            },
            r.alpha,
            reason.map(|r| format!(": {r}")).unwrap_or_default(),
            artefacts
                .iter()
                .map(|a| format!("wrote {a}\n"))
                .collect::<String>(),
            r.samples,
            r.resolution,
            r.seed,
            if options.sampling == SamplingKind::Visible {
                format!(
                    " --sampling visible --incidence {} --azimuth {}",
                    options.incidence, options.azimuth
                )
            } else {
                String::new()
            },
        )
    };
    if let Err(e) = written.and_then(|_| stdout.flush()) {
        return bad(stderr, format!("cannot write output: {e}"));
    }
    match result.verdict {
        Verdict::Pass => 0,
        Verdict::Fail => 1,
    }
}

fn finite_or_null(x: f64) -> Value {
    if x.is_finite() {
        json!(x)
    } else {
        Value::Null
    }
}

/// Writes the observed and expected counts as JSON tables `chi2_observed.json` and
/// `chi2_expected.json` (rows of cos θ, row 0 at the horizon; columns of φ from 0) and the heat
/// maps `chi2_observed.svg`, `chi2_expected.svg`, `chi2_difference.svg` (axes in θ and φ, a
/// colour bar, titled with the model; see [`crate::report::artefacts`], which writes the same
/// files for `mfh audit`); returns the paths written.
pub fn write_artefacts(
    dir: &Path,
    model: &str,
    result: &Chi2Result,
) -> Result<Vec<PathBuf>, crate::report::artefacts::ArtefactError> {
    let data = crate::record::RecordData::Chi2Table {
        rows: result.resolution,
        columns: 2 * result.resolution,
        samples: result.samples,
        seed: result.seed,
        observed: result.observed.clone(),
        expected: result.expected.clone(),
    };
    let title = format!("mfh chi2 · {model} · {} samples", result.samples);
    crate::report::artefacts::write_record_data(dir, &title, "mfh chi2", &data)
}
