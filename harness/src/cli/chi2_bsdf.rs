//! `mfh chi2 --bsdf SPEC`: the whole-sphere chi-square of a reference BSDF's sampling at one
//! incidence, by hand ([`crate::sampler_chi2::bsdf`] validates and runs it), with the
//! text or JSON summary of the NDF path and, with `--out`, the observed/expected tables and
//! heat maps of both hemispheres (the files a `bsdf.chi2` record of `mfh audit` gets).

use super::chi2::{bad, Chi2Args};
use super::{EXIT_FAIL, EXIT_PASS};
use crate::oracle::chi2::TestOutcome;
use crate::sampler_chi2::bsdf::{self as bsdf_chi2, BsdfChi2Request};
use crate::sampler_chi2::SamplingKind;
use std::io::Write;

/// Runs `mfh chi2 --bsdf`; the exit status (0 pass, 1 fail, 2 bad input).
pub fn run(
    args: &Chi2Args,
    bsdf: String,
    seed: u64,
    stdout: &mut dyn Write,
    stderr: &mut dyn Write,
) -> i32 {
    if args.sampling.kind() != SamplingKind::Normals {
        return bad(
            stderr,
            "--sampling only applies with --model or --cmd: a BSDF spec names its own \
             `sampling`"
                .into(),
        );
    }
    let request = BsdfChi2Request {
        bsdf,
        samples: args.samples,
        resolution: args.resolution,
        seed,
        alpha: args.alpha,
        incidence: args.incidence,
        azimuth: args.azimuth,
        inside: args.inside,
    };
    let plan = match bsdf_chi2::validate(&request) {
        Ok(plan) => plan,
        Err(e) => return bad(stderr, e.to_string()),
    };
    let result = bsdf_chi2::run(&plan);
    let spec_text = serde_json::to_string(&plan.spec).unwrap_or_default();
    let mut artefacts = Vec::new();
    if let Some(dir) = &args.out {
        let name = crate::report::artefacts::model_name(&serde_json::json!(plan.spec));
        let title = format!("mfh chi2 · {name} · {} samples", result.samples);
        let data = bsdf_chi2::table(&result);
        match crate::report::artefacts::write_record_data(dir, &title, "mfh chi2", &data) {
            Ok(paths) => artefacts = paths.iter().map(|p| p.display().to_string()).collect(),
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
    let reproduce = bsdf_chi2::reproduce_command(&plan);
    let written = super::write_stdout("chi2", stdout, stderr, |stdout| {
        if args.json {
            writeln!(stdout, "{}", bsdf_chi2::record(&plan, &result, &artefacts))
        } else {
            let r = &result;
            let (theta, phi) = plan.incidence;
            let num = crate::report::text::num;
            writeln!(
                stdout,
                "bsdf {spec_text}\n\
                 incidence θi {} φi {} from {} (wi = {})\n\
                 grid 2 × {} φ × {} cos θ cells, {} samples ({} failed), seed {}\n\
                 statistic {:.4}, dof {}, p-value {:.6e}\n\
                 expected mass {:.12} (cubature error bound {:.2e})\n\
                 sampling+binning {:.3} s, expected-mass integration {:.3} s\n\
                 verdict {} at α = {}{}\n{}\
                 reproduce: {}",
                num(theta),
                num(phi),
                if plan.inside { "inside" } else { "outside" },
                crate::report::text::json(&serde_json::json!(plan.wi)),
                2 * r.resolution,
                r.resolution,
                r.samples,
                r.observed.failed,
                r.seed,
                r.statistic,
                r.dof,
                r.p_value,
                r.mass(),
                r.mass_error_bound(),
                r.sampling_seconds,
                r.integration_seconds,
                if r.verdict == TestOutcome::Pass {
                    "pass"
                } else {
                    "FAIL"
                },
                crate::report::text::err(r.alpha),
                r.reason
                    .as_ref()
                    .map(|r| format!(": {r}"))
                    .unwrap_or_default(),
                artefacts
                    .iter()
                    .map(|a| format!("wrote {a}\n"))
                    .collect::<String>(),
                reproduce,
            )
        }
    });
    if let Err(code) = written {
        return code;
    }
    match result.verdict {
        TestOutcome::Pass => EXIT_PASS,
        TestOutcome::Fail => EXIT_FAIL,
    }
}
