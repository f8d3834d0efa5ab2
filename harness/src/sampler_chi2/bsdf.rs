//! Running one whole-sphere chi-square test of a reference BSDF's sampler, as `mfh chi2 --bsdf`
//! asks for it: the request (validated against the limits of the NDF path, with
//! typed errors naming the option and the limit), the run ([`crate::oracle::chi2::sphere`]), the
//! record (a JSON object) and its observed/expected tables ([`RecordData::SphereChi2Table`],
//! which the report sinks draw). No exit codes and no file writing here.

use super::{finite_or_null, MIN_RESOLUTION};
use super::{min_samples, out_of_range, Chi2InputError, MAX_RESOLUTION, MAX_SAMPLES};
use crate::oracle::chi2::sphere::{sphere_chi2_about, SphereChi2Result};
use crate::oracle::chi2::Chi2Config;
use crate::record::RecordData;
use crate::tolerance::MIN_EXPECTED;
use mfh_reference::bsdf::{Bsdf, BsdfSpec, Directions};
use mfh_reference::geometry::{from_spherical, Vec3};
use serde_json::{json, Value};
use std::f64::consts::FRAC_PI_2;
use std::sync::Arc;

/// The default incidence θi (radians from the normal) when none is given.
pub const DEFAULT_BSDF_INCIDENCE: f64 = 0.5;

/// A BSDF chi-square request as given (e.g. by the command line), before validation.
#[derive(Debug, Clone, PartialEq)]
pub struct BsdfChi2Request {
    /// The BSDF spec as JSON text (`mfh_reference::bsdf::BsdfSpec`).
    pub bsdf: String,
    /// Samples to draw.
    pub samples: u64,
    /// Grid resolution R (each hemisphere R cos θ-rows × 2R φ-columns).
    pub resolution: usize,
    /// The seed (already resolved by the caller).
    pub seed: u64,
    /// The significance level.
    pub alpha: f64,
    /// The incidence θi in radians from the normal, in [0, π/2) (default
    /// [`DEFAULT_BSDF_INCIDENCE`]).
    pub incidence: Option<f64>,
    /// The incidence azimuth φi in radians (default 0).
    pub azimuth: Option<f64>,
    /// Whether wi comes from inside (below the surface, z < 0).
    pub inside: bool,
}

/// A validated BSDF chi-square request.
pub struct BsdfChi2Plan {
    /// The spec.
    pub spec: BsdfSpec,
    /// The BSDF.
    pub bsdf: Arc<dyn Bsdf>,
    /// The test's configuration.
    pub config: Chi2Config,
    /// θi and φi as given (radians).
    pub incidence: (f64, f64),
    /// From inside.
    pub inside: bool,
    /// The incident direction.
    pub wi: Vec3,
}

/// The fewest samples at resolution R over the sphere: [`MIN_EXPECTED`] per cell on average
/// over the 4R² cells of both hemispheres (twice the NDF path's [`min_samples`]).
pub fn min_sphere_samples(resolution: usize) -> u64 {
    2 * min_samples(resolution)
}

/// Validates a request.
pub fn validate(request: &BsdfChi2Request) -> Result<BsdfChi2Plan, Chi2InputError> {
    let spec: BsdfSpec = serde_json::from_str(&request.bsdf)
        .map_err(|e| Chi2InputError::Bsdf(crate::messages::json_error_message(&e)))?;
    let bsdf = spec
        .build()
        .map_err(|e| Chi2InputError::Bsdf(format!("{}: {e}", e.field())))?;
    let r = request.resolution;
    if !(MIN_RESOLUTION..=MAX_RESOLUTION).contains(&r) {
        return Err(out_of_range(
            "--resolution",
            r,
            format!("must be in [{MIN_RESOLUTION}, {MAX_RESOLUTION}]"),
        ));
    }
    if request.samples > MAX_SAMPLES {
        return Err(out_of_range(
            "--samples",
            request.samples,
            format!("must be at most {MAX_SAMPLES} (2^32)"),
        ));
    }
    let min = min_sphere_samples(r);
    if request.samples < min {
        return Err(out_of_range(
            "--samples",
            request.samples,
            format!(
                "must be at least {min} at --resolution {r} ({MIN_EXPECTED} per cell on average \
                 over the 4R² = {} cells of both hemispheres)",
                4 * r * r
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
    let theta = request.incidence.unwrap_or(DEFAULT_BSDF_INCIDENCE);
    if !(0.0..FRAC_PI_2).contains(&theta) {
        return Err(out_of_range(
            "--incidence",
            theta,
            "must be in [0, π/2) radians from the normal (use --inside for an incidence from \
             below the surface)"
                .to_string(),
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
    let mut wi = from_spherical(theta, phi);
    if request.inside {
        wi[2] = -wi[2];
    }
    Ok(BsdfChi2Plan {
        spec,
        bsdf,
        config: Chi2Config {
            resolution: r,
            samples: request.samples,
            seed: request.seed,
            alpha: request.alpha,
        },
        incidence: (theta, phi),
        inside: request.inside,
        wi,
    })
}

/// Runs a validated request: the BSDF's batch sampler (a sample of pdf 0 is a failed sample,
/// as `bsdf.chi2` counts it) against its pdf over the sphere.
pub fn run(plan: &BsdfChi2Plan) -> SphereChi2Result {
    let bsdf = plan.bsdf.as_ref();
    let wi = plan.wi;
    sphere_chi2_about(
        &|u: &[[f64; 3]], out: &mut Directions| bsdf.sample_wo_batch(wi, u, out),
        &|wo: &[Vec3], out: &mut [f64]| {
            let wis = vec![wi; wo.len()];
            bsdf.pdf_batch(&wis, wo, out);
        },
        &plan.config,
        &crate::oracle::lobe_centres::lobe_centres(wi, bsdf.eta()),
    )
}

/// The observed and expected counts of both hemispheres, as the `bsdf.chi2` records carry them.
pub fn table(result: &SphereChi2Result) -> RecordData {
    crate::check::bsdf::chi2_table(result)
}

/// The record of a run as one JSON object (`mfh chi2 --bsdf … --json`).
pub fn record(plan: &BsdfChi2Plan, result: &SphereChi2Result, artefacts: &[String]) -> Value {
    let seconds = result.sampling_seconds;
    json!({
        "bsdf": plan.spec,
        "statistic": finite_or_null(result.statistic),
        "dof": result.dof,
        "p_value": result.p_value,
        "components": result.components,
        "alpha": result.alpha,
        "verdict": result.verdict,
        "reason": result.reason,
        "sanity_failure": result.sanity_failure,
        "samples": result.samples,
        "failed_samples": result.observed.failed,
        "seed": result.seed,
        "resolution": result.resolution,
        "samples_per_second": finite_or_null(result.samples as f64 / seconds),
        "expected_mass": result.mass(),
        "expected_error_bound": result.mass_error_bound(),
        "sampling_seconds": result.sampling_seconds,
        "integration_seconds": result.integration_seconds,
        "artefacts": artefacts,
        "incidence": {
            "theta": plan.incidence.0,
            "phi": plan.incidence.1,
            "inside": plan.inside,
            "wi": plan.wi,
        },
    })
}

/// The command line that reproduces a run.
pub fn reproduce_command(plan: &BsdfChi2Plan) -> String {
    let spec_text = serde_json::to_string(&plan.spec).unwrap_or_default();
    let c = &plan.config;
    format!(
        "mfh chi2 --bsdf '{spec_text}' --incidence {} --azimuth {}{} --samples {} --resolution {} \
         --seed {}",
        plan.incidence.0,
        plan.incidence.1,
        if plan.inside { " --inside" } else { "" },
        c.samples,
        c.resolution,
        c.seed
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn request(bsdf: &str) -> BsdfChi2Request {
        BsdfChi2Request {
            bsdf: bsdf.to_string(),
            samples: 100_000,
            resolution: 8,
            seed: 1,
            alpha: 1e-4,
            incidence: Some(0.7),
            azimuth: None,
            inside: true,
        }
    }

    const GLASS: &str = r#"{"bsdf":"dielectric","eta":1.5,"ndf":{"family":"ggx","alpha":0.4}}"#;

    #[test]
    fn a_reference_dielectric_from_inside_passes() {
        let plan = validate(&request(GLASS)).unwrap();
        assert!(plan.wi[2] < 0.0);
        let result = run(&plan);
        assert_eq!(
            result.verdict,
            crate::oracle::chi2::TestOutcome::Pass,
            "{:?}",
            result.reason
        );
        match table(&result) {
            RecordData::SphereChi2Table {
                rows,
                lower_observed,
                ..
            } => {
                assert_eq!(rows, 8);
                assert!(lower_observed.iter().sum::<u64>() > 0, "transmits");
            }
            other => panic!("{other:?}"),
        }
        let r = record(&plan, &result, &[]);
        assert_eq!(r["incidence"]["inside"], true);
        assert!(reproduce_command(&plan).contains("--inside"));
    }

    #[test]
    fn bad_requests_name_the_option() {
        let cases: Vec<(BsdfChi2Request, &[&str])> = vec![
            (
                BsdfChi2Request {
                    incidence: Some(1.6),
                    ..request(GLASS)
                },
                &["--incidence", "π/2", "--inside"],
            ),
            (
                BsdfChi2Request {
                    samples: 10,
                    ..request(GLASS)
                },
                &["--samples", "at least 1280"],
            ),
            (
                request(r#"{"bsdf":"dielectric","eta":0.01,"ndf":{"family":"ggx","alpha":0.4}}"#),
                &["--bsdf", "eta", "[0.1, 10]"],
            ),
            (request(r#"{"bsdf":"plastic"}"#), &["--bsdf", "plastic"]),
        ];
        for (req, names) in cases {
            let e = validate(&req).err().expect("bad input").to_string();
            for n in names {
                assert!(e.contains(n), "{e} lacks {n}");
            }
        }
    }
}
