//! `mfh chi2`: the chi-square test of a model's sampler from the command line ([`crate::sampler_chi2`]
//! validates and runs it), with text or JSON output and optional observed/expected tables (JSON)
//! and heat maps (PNG).

use super::{resolve_seed, SamplingArg, EXIT_BAD_INPUT, EXIT_FAIL, EXIT_PASS};
use crate::oracle::chi2::{Chi2Result, TestOutcome};
use crate::sampler_chi2::{self, Chi2Request};
use clap::Args;

use std::io::Write;
use std::path::{Path, PathBuf};

/// The options of `mfh chi2`.
#[derive(Debug, Args)]
pub struct Chi2Args {
    /// The model spec as JSON text, e.g. '{"family":"ggx","alpha":0.3}'.
    #[arg(
        long,
        required_unless_present_any = ["cmd", "bsdf"],
        conflicts_with_all = ["cmd", "bsdf"]
    )]
    pub model: Option<String>,
    /// Test a reference BSDF's sampling over the whole sphere instead: its spec as JSON text,
    /// e.g. '{"bsdf":"dielectric","eta":1.5,"ndf":{"family":"ggx","alpha":0.3}}', at
    /// --incidence (default 0.5) and --azimuth, from above (or --inside).
    #[arg(long, conflicts_with = "cmd")]
    pub bsdf: Option<String>,
    /// With --bsdf: the incidence comes from inside (below the surface, z < 0).
    #[arg(long)]
    pub inside: bool,
    /// Test an implementation in any language instead: the command that starts it (run with
    /// `sh -c`, speaking the external protocol, see `mfh audit-external`), e.g.
    /// "python3 examples/external/ggx.py".
    #[arg(long)]
    pub cmd: Option<String>,
    /// With --cmd: seconds to wait for each answer before the child is killed.
    #[arg(long, default_value_t = crate::external::DEFAULT_TIMEOUT_SECONDS)]
    pub timeout: f64,
    /// Samples to draw: at least 5 per cell of the grid (10·R²), at most 2^32.
    #[arg(long, default_value_t = 1_000_000)]
    pub samples: u64,
    /// Grid resolution R: R cos θ-rows × 2R φ-columns, 2 ≤ R ≤ 512.
    #[arg(long, default_value_t = 32)]
    pub resolution: usize,
    /// Seed of the random streams (default: MFH_SEED, else a fixed seed).
    #[arg(long)]
    pub seed: Option<u64>,
    /// Significance level, in (0, 1).
    #[arg(long, default_value_t = 1e-4)]
    pub alpha: f64,
    /// Print one JSON object.
    #[arg(long)]
    pub json: bool,
    /// Write observed and expected count tables (JSON) and heat maps of observed, expected
    /// and (O − E)/√E (PNG) into this folder.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// What to sample: normals (`sample_wm`) or visible normals (`sample_wm_visible` at
    /// the incidence).
    #[arg(long, value_enum, default_value = "normals")]
    pub sampling: SamplingArg,
    /// The incidence θi in radians from the normal, in [0, π/2) (visible normals or --bsdf
    /// only; default 0.5).
    #[arg(long, allow_negative_numbers = true)]
    pub incidence: Option<f64>,
    /// The incidence azimuth φi in radians (visible normals or --bsdf only; default 0).
    #[arg(long, allow_negative_numbers = true)]
    pub azimuth: Option<f64>,
    /// No progress bar (it is shown only when standard error is a terminal anyway).
    #[arg(long, short)]
    pub quiet: bool,
}

/// Prints a bad-input message; the exit status 2.
pub(super) fn bad(stderr: &mut dyn Write, message: String) -> i32 {
    // Long numbers shortened: a value such as 1e308 printed whole is 309 digits.
    let message = crate::messages::compact_numbers(&message);
    let _ = writeln!(stderr, "mfh chi2: {message}");
    EXIT_BAD_INPUT
}

/// The options as a [`Chi2Request`] for the model `model` (a spec's JSON text), validated.
fn validate(args: &Chi2Args, model: String, seed: u64) -> Result<sampler_chi2::Chi2Plan, String> {
    let request = Chi2Request {
        model,
        samples: args.samples,
        resolution: args.resolution,
        seed,
        alpha: args.alpha,
        sampling: args.sampling.kind(),
        incidence: args.incidence,
        azimuth: args.azimuth,
    };
    sampler_chi2::validate(&request).map_err(|e| e.to_string())
}

/// Runs `mfh chi2`; returns the exit status (0 pass, 1 fail, 2 bad input).
pub fn run(args: Chi2Args, stdout: &mut dyn Write, stderr: &mut dyn Write) -> i32 {
    let seed = match resolve_seed(args.seed) {
        Ok(seed) => seed,
        Err(e) => return bad(stderr, e),
    };
    if let Some(bsdf) = args.bsdf.clone() {
        return super::chi2_bsdf::run(&args, bsdf, seed, stdout, stderr);
    }
    if args.inside {
        return bad(stderr, "--inside only applies with --bsdf".into());
    }
    if let Some(cmd) = args.cmd.clone() {
        return run_external(&args, &cmd, seed, stdout, stderr);
    }
    let plan = match validate(&args, args.model.clone().unwrap_or_default(), seed) {
        Ok(plan) => plan,
        Err(e) => return bad(stderr, e),
    };
    let result = run_with_progress(&plan, args.quiet);
    let name = crate::report::artefacts::model_name(&serde_json::json!(plan.model.spec()));
    let spec_text = serde_json::to_string(&plan.model.spec()).unwrap_or_default();
    let record = sampler_chi2::record(&plan, &result, &[]);
    let reproduce = sampler_chi2::reproduce_command(&plan);
    report(
        &args,
        &result,
        (&name, &spec_text),
        record,
        &reproduce,
        stdout,
        stderr,
    )
}

/// `mfh chi2 --cmd`: the same test of an external implementation's sampler (through the
/// protocol's batches: one round trip per 65 536 samples, and per step of the expected-count
/// cubature), the same output and heat maps. The other options are validated as for `--model`
/// (by validating them with a stand-in GGX spec, whose sampler is never called).
fn run_external(
    args: &Chi2Args,
    cmd: &str,
    seed: u64,
    stdout: &mut dyn Write,
    stderr: &mut dyn Write,
) -> i32 {
    if !(args.timeout > 0.0 && args.timeout <= 86_400.0) {
        return bad(
            stderr,
            format!("--timeout {} is outside (0, 86400] seconds", args.timeout),
        );
    }
    let plan = match validate(args, r#"{"family":"ggx","alpha":0.5}"#.into(), seed) {
        Ok(plan) => plan,
        Err(e) => return bad(stderr, e),
    };
    let timeout = std::time::Duration::from_secs_f64(args.timeout);
    let model = match crate::external::ExternalModel::start(cmd, timeout) {
        Ok(m) => m,
        Err(e) => return bad(stderr, format!("--cmd: {e}")),
    };
    let description = model.description().clone();
    let name = description.name.clone().unwrap_or_else(|| cmd.to_string());
    use mfh_reference::Ndf;
    let result = match plan.incidence {
        Some((theta, phi)) => {
            let Some(v) = model.as_visible_sampler() else {
                model.shutdown();
                return bad(
                    stderr,
                    format!(
                        "--sampling visible: `{name}` does not declare sample_wm_visible; \
                         nothing to test"
                    ),
                );
            };
            let wi = mfh_reference::geometry::from_spherical(theta, phi);
            crate::oracle::chi2::chi2_test_batches_in(
                &|u: &[[f64; 2]], m: &mut [mfh_reference::Vec3]| {
                    v.sample_wm_visible_batch(wi, u, m)
                },
                &|m: &[mfh_reference::Vec3], out: &mut [f64]| v.pdf_wm_visible_batch(wi, m, out),
                &plan.config,
                (
                    crate::tolerance::KINKED_CELL_RELATIVE_TOLERANCE,
                    crate::tolerance::REMOTE_CELL_ABSOLUTE_TOLERANCE,
                ),
                None,
            )
        }
        None => {
            let Some(s) = model.as_sampler() else {
                model.shutdown();
                return bad(
                    stderr,
                    format!(
                        "--sampling normals: `{name}` does not declare sample_wm; nothing to test"
                    ),
                );
            };
            crate::oracle::chi2::chi2_test_batches_in(
                &|u: &[[f64; 2]], m: &mut [mfh_reference::Vec3]| s.sample_wm_batch(u, m),
                &|m: &[mfh_reference::Vec3], out: &mut [f64]| s.pdf_wm_batch(m, out),
                &plan.config,
                (
                    crate::tolerance::CELL_RELATIVE_TOLERANCE,
                    crate::tolerance::CELL_ABSOLUTE_TOLERANCE,
                ),
                None,
            )
        }
    };
    let protocol_error = model.first_error();
    model.shutdown();
    if let Some(e) = protocol_error {
        // The counts of a broken session mean nothing: say what went wrong instead.
        let _ = writeln!(stderr, "mfh chi2: --cmd: {e}");
        return EXIT_FAIL;
    }
    let label = serde_json::json!({
        "name": name,
        "command": cmd,
        "parameters": description.parameters,
    });
    let mut record = sampler_chi2::record(&plan, &result, &[]);
    record["model"] = label.clone();
    let mut reproduce = sampler_chi2::reproduce_command(&plan);
    if let Some(rest) = reproduce
        .split_once(" --samples ")
        .map(|(_, r)| r.to_string())
    {
        reproduce = format!("mfh chi2 --cmd {cmd:?} --samples {rest}");
    }
    let model_name = crate::report::artefacts::model_name(&label);
    let label_text = serde_json::to_string(&label).unwrap_or_default();
    report(
        args,
        &result,
        (&model_name, &label_text),
        record,
        &reproduce,
        stdout,
        stderr,
    )
}

/// The statistic's two parts as the text output prints them.
fn parts_text(c: &crate::oracle::chi2::components::Components) -> String {
    format!(
        "cos θ marginal's smooth components χ² {:.4} (dof {}, p {:.3e}), rest χ² {:.4} (dof {}, \
         p {:.3e}); p = 1 − (1 − min)²",
        c.smooth.statistic,
        c.smooth.dof,
        c.smooth.p_value,
        c.rest.statistic,
        c.rest.dof,
        c.rest.p_value
    )
}

/// Writes the artefacts (with `--out`) and prints the result, text or JSON; the exit status.
fn report(
    args: &Chi2Args,
    result: &Chi2Result,
    (name, spec_text): (&str, &str),
    mut record: serde_json::Value,
    reproduce: &str,
    stdout: &mut dyn Write,
    stderr: &mut dyn Write,
) -> i32 {
    let mut artefacts = Vec::new();
    if let Some(dir) = &args.out {
        match write_artefacts(dir, name, result) {
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
    let written = super::write_stdout("chi2", stdout, stderr, |stdout| {
        if args.json {
            record["artefacts"] = serde_json::json!(artefacts);
            writeln!(stdout, "{record}")
        } else {
            let r = result;
            let reason = r.reason.as_ref().map(|r| r.to_string());
            writeln!(
                stdout,
                "model {spec_text}\n\
             grid {} φ × {} cos θ cells, {} samples, seed {}\n\
             statistic {:.4}, dof {}, p-value {:.6e}, pooled cells {}\n\
             parts: {}\n\
             expected mass {:.12} (cubature error bound {:.2e} counts)\n\
             sampling+binning {:.3e} samples/s ({:.3} s), expected-count integration {:.3} s\n\
             verdict {} at α = {}{}\n{}\
             reproduce: {}",
                2 * r.resolution,
                r.resolution,
                r.samples,
                r.seed,
                r.statistic,
                r.dof,
                r.p_value,
                r.pooled_cells,
                r.components
                    .as_ref()
                    .map_or("none (one row)".to_string(), parts_text),
                r.expected_mass,
                r.expected_error_bound,
                r.samples_per_second(),
                r.sampling_seconds,
                r.integration_seconds,
                if r.verdict == TestOutcome::Pass {
                    "pass"
                } else {
                    "FAIL"
                },
                crate::report::text::err(r.alpha),
                reason.map(|r| format!(": {r}")).unwrap_or_default(),
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

/// Runs the test with a progress bar of samples drawn (see [`super::progress`]); the bar
/// reads a shared counter from a second thread, so the result is the same with or without it.
fn run_with_progress(plan: &sampler_chi2::Chi2Plan, quiet: bool) -> Chi2Result {
    use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
    use std::sync::Arc;
    let bar = super::progress::Bar::new(plan.config.samples, "samples", quiet);
    if !bar.enabled() {
        return sampler_chi2::run(plan, None);
    }
    let counter = Arc::new(AtomicU64::new(0));
    let finished = AtomicBool::new(false);
    let result = std::thread::scope(|scope| {
        scope.spawn(|| {
            while !finished.load(Ordering::Relaxed) {
                let done = counter.load(Ordering::Relaxed).min(plan.config.samples);
                let phase = if done + (1 << 16) >= plan.config.samples {
                    ", integrating expected counts"
                } else {
                    ""
                };
                bar.update(done, phase.to_string());
                std::thread::sleep(std::time::Duration::from_millis(100));
            }
        });
        let result = sampler_chi2::run(plan, Some(counter.clone()));
        finished.store(true, Ordering::Relaxed);
        result
    });
    bar.finish();
    result
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
    let data = crate::check::sampling::chi2_table(result);
    let title = format!("mfh chi2 · {model} · {} samples", result.samples);
    crate::report::artefacts::write_record_data(dir, &title, "mfh chi2", &data)
}

#[cfg(test)]
mod tests {
    use crate::cli::run_captured as run_args;

    #[test]
    fn chi2_cli_visible_normals_at_an_incidence() {
        let (code, out, err) = run_args(&[
            "chi2",
            "--model",
            r#"{"family":"beckmann","alpha_x":0.3,"alpha_y":0.15}"#,
            "--sampling",
            "visible",
            "--incidence",
            "1.2",
            "--azimuth",
            "0.3",
            "--samples",
            "200000",
            "--resolution",
            "8",
            "--json",
        ]);
        assert_eq!(code, 0, "{out}{err}");
        let v: serde_json::Value = serde_json::from_str(out.trim()).unwrap();
        assert_eq!(v["verdict"], "pass");
        assert_eq!(v["sampling"], "visible");
        assert_eq!(v["incidence"]["theta"], 1.2);
        // A model without a visible sampler, and an incidence below the horizon: bad input.
        for args in [
            vec![
                "chi2",
                "--model",
                r#"{"family":"std","gamma":3,"alpha":0.3}"#,
            ],
            vec![
                "chi2",
                "--model",
                r#"{"family":"ggx","alpha":0.3}"#,
                "--incidence",
                "2",
            ],
        ] {
            let mut args = args;
            args.extend(["--sampling", "visible"]);
            let (code, _, err) = run_args(&args);
            assert_eq!(code, 2, "{err}");
        }
    }

    #[test]
    fn chi2_cli_json_pass_and_tables() {
        let dir = std::env::temp_dir().join(format!("mfh-chi2-cli-{}", std::process::id()));
        let (code, out, err) = run_args(&[
            "chi2",
            "--model",
            r#"{"family":"ggx","alpha":0.3}"#,
            "--samples",
            "200000",
            "--resolution",
            "8",
            "--seed",
            "3",
            "--json",
            "--out",
            dir.to_str().unwrap(),
        ]);
        assert_eq!(code, 0, "{out}{err}");
        let v: serde_json::Value = serde_json::from_str(out.trim()).unwrap();
        assert_eq!(v["verdict"], "pass");
        assert_eq!(v["samples"], 200000);
        assert_eq!(v["dof"], 127);
        for key in [
            "statistic",
            "p_value",
            "samples_per_second",
            "pooled_cells",
            "expected_mass",
            "expected_error_bound",
            "integration_seconds",
        ] {
            assert!(v[key].is_number(), "{key}: {v}");
        }
        let table: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(dir.join("chi2_observed.json")).unwrap())
                .unwrap();
        assert_eq!(table["counts"].as_array().unwrap().len(), 8);
        assert_eq!(table["counts"][0].as_array().unwrap().len(), 16);
        assert!(dir.join("chi2_expected.json").exists());
        // The heat maps: SVGs with axes in θ and φ (radians), a colour bar and the model, listed.
        let listed: Vec<&str> = v["artefacts"]
            .as_array()
            .unwrap()
            .iter()
            .filter_map(|a| a.as_str())
            .collect();
        assert_eq!(listed.len(), 5, "{listed:?}");
        for name in [
            "chi2_observed.svg",
            "chi2_expected.svg",
            "chi2_difference.svg",
        ] {
            let path = dir.join(name);
            assert!(listed.contains(&path.to_str().unwrap()), "{listed:?}");
            let svg = std::fs::read_to_string(&path).unwrap();
            assert!(svg.starts_with("<svg"), "{name}");
            for text in ["θ (radians)", "φ (radians)", "ggx alpha=0.3"] {
                assert!(svg.contains(text), "{name}: {text}");
            }
            // The 16 φ × 8 cos θ cells as one embedded bitmap, and the colour bar's 64 steps.
            assert!(svg.contains("<image"), "{name}");
            assert!(svg.matches("<rect").count() >= 64, "{name}");
        }
        let _ = std::fs::remove_dir_all(&dir);
    }

    /// The measured bad inputs: each is exit 2 with a message naming the option and
    /// its limit, before any allocation or sampling.
    #[test]
    fn chi2_cli_bad_input_names_the_option_and_the_limit() {
        let ggx = r#"{"family":"ggx","alpha":0.3}"#;
        for (args, names) in [
            (
                vec!["--resolution", "18446744073709551615"],
                vec!["--resolution", "512"],
            ),
            (vec!["--resolution", "100000"], vec!["--resolution", "512"]),
            (vec!["--resolution", "10000"], vec!["--resolution", "512"]),
            (
                vec!["--samples", "1000000000000000"],
                vec!["--samples", "4294967296"],
            ),
            (vec!["--samples", "1"], vec!["--samples", "at least 10240"]),
            (
                vec!["--sampling", "visible", "--azimuth", "nan"],
                vec!["--azimuth", "finite"],
            ),
            (
                vec!["--incidence", "0.3"],
                vec!["--incidence", "--sampling visible"],
            ),
            (
                vec!["--azimuth", "0.3"],
                vec!["--azimuth", "--sampling visible"],
            ),
        ] {
            let mut all = vec!["chi2", "--model", ggx];
            all.extend(args.iter().copied());
            let (code, out, err) = run_args(&all);
            assert_eq!(code, 2, "{args:?}: {out}{err}");
            assert!(out.is_empty(), "{args:?}: {out}");
            for n in names {
                assert!(err.contains(n), "{args:?}: {err:?} lacks {n:?}");
            }
            assert!(err.lines().count() == 1 && err.len() < 300, "{err}");
        }
        // `--samples 1e15` is not an integer: clap's own bad-input error, exit 2.
        let (code, _, err) = run_args(&["chi2", "--model", ggx, "--samples", "1e15"]);
        assert_eq!(code, 2);
        assert!(err.contains("--samples"), "{err}");
    }

    /// `--resolution 1 --samples 10` reported a correct sampler as FAIL (χ² NaN,
    /// dof 0); too few cells or samples for a degree of freedom are bad input, exit 2, naming
    /// the option and its limit. The least accepted run has degrees of freedom and passes.
    #[test]
    fn chi2_cli_refuses_a_grid_or_sample_count_without_degrees_of_freedom() {
        let ggx = r#"{"family":"ggx","alpha":0.3}"#;
        for (args, names) in [
            (
                vec!["--resolution", "1", "--samples", "10"],
                vec!["--resolution", "[2, 512]"],
            ),
            (
                vec!["--resolution", "2", "--samples", "10"],
                vec!["--samples", "at least 40"],
            ),
            (
                vec!["--resolution", "2", "--samples", "39"],
                vec!["--samples", "at least 40"],
            ),
        ] {
            let mut all = vec!["chi2", "--model", ggx, "--json"];
            all.extend(args.iter().copied());
            let (code, out, err) = run_args(&all);
            assert_eq!(code, 2, "{args:?}: {out}{err}");
            assert!(out.is_empty(), "{args:?}: {out}");
            for n in names {
                assert!(err.contains(n), "{args:?}: {err:?} lacks {n:?}");
            }
        }
        let (code, out, err) = run_args(&[
            "chi2",
            "--model",
            ggx,
            "--json",
            "--resolution",
            "2",
            "--samples",
            "40",
        ]);
        assert_eq!(code, 0, "{out}{err}");
        let v: serde_json::Value = serde_json::from_str(out.trim()).unwrap();
        assert!(v["dof"].as_u64().unwrap() >= 1, "{v}");
        assert!(v["statistic"].is_number(), "{v}");
    }

    #[test]
    fn chi2_cli_text_and_bad_input() {
        let (code, out, _) = run_args(&[
            "chi2",
            "--model",
            r#"{"family":"beckmann","alpha":0.5}"#,
            "--samples",
            "100000",
            "--resolution",
            "5",
        ]);
        assert_eq!(code, 0, "{out}");
        assert!(
            out.contains("verdict pass") && out.contains("samples/s"),
            "{out}"
        );
        assert!(out.contains("reproduce: mfh chi2"), "{out}");
        let (code, _, err) = run_args(&["chi2", "--model", "{\"family\":\"ggx\"}"]);
        assert_eq!(code, 2, "{err}");
        let blend = r#"{"family":"blend","x":{"family":"ggx","alpha":0.3},"y":{"family":"beckmann","alpha":0.2}}"#;
        let (code, _, err) = run_args(&["chi2", "--model", blend]);
        assert_eq!(code, 2);
        assert!(err.contains("no normal sampler"), "{err}");
        let (code, _, _) = run_args(&["chi2", "--model", "not json"]);
        assert_eq!(code, 2);
        let (code, _, _) = run_args(&[
            "chi2",
            "--model",
            r#"{"family":"ggx","alpha":0.3}"#,
            "--resolution",
            "0",
        ]);
        assert_eq!(code, 2);
    }

    const GLASS: &str = r#"{"bsdf":"dielectric","eta":1.5,"ndf":{"family":"ggx","alpha":0.4}}"#;

    /// `--bsdf` runs the whole-sphere chi-square of a reference BSDF, from inside
    /// with `--inside`, and writes both hemispheres' tables and heat maps with `--out`.
    #[test]
    fn chi2_cli_bsdf_over_the_sphere_with_tables() {
        let dir = std::env::temp_dir().join(format!("mfh-chi2-bsdf-{}", std::process::id()));
        let (code, out, err) = run_args(&[
            "chi2",
            "--bsdf",
            GLASS,
            "--incidence",
            "0.7",
            "--inside",
            "--samples",
            "100000",
            "--resolution",
            "8",
            "--seed",
            "3",
            "--json",
            "--out",
            dir.to_str().unwrap(),
        ]);
        assert_eq!(code, 0, "{out}{err}");
        let v: serde_json::Value = serde_json::from_str(out.trim()).unwrap();
        assert_eq!(v["verdict"], "pass", "{v}");
        assert_eq!(v["incidence"]["inside"], true);
        assert!(v["incidence"]["wi"][2].as_f64().unwrap() < 0.0, "{v}");
        assert!(v["dof"].as_u64().unwrap() > 1, "{v}");
        for name in ["upper_chi2_observed.json", "lower_chi2_expected.json"] {
            assert!(dir.join(name).exists(), "{name}");
        }
        let listed = v["artefacts"].as_array().unwrap();
        assert!(listed.len() >= 4, "{listed:?}");
        let _ = std::fs::remove_dir_all(&dir);
        // The text summary, from outside.
        let (code, out, err) = run_args(&[
            "chi2",
            "--bsdf",
            r#"{"bsdf":"conductor","n":0.2,"k":3,"ndf":{"family":"beckmann","alpha":0.3}}"#,
            "--samples",
            "50000",
            "--resolution",
            "6",
        ]);
        assert_eq!(code, 0, "{out}{err}");
        for text in ["verdict pass", "from outside", "reproduce: mfh chi2 --bsdf"] {
            assert!(out.contains(text), "{out} lacks {text}");
        }
    }

    /// `--bsdf`'s options are validated as the NDF path's: exit 2 naming the option.
    #[test]
    fn chi2_cli_bsdf_bad_input_names_the_option() {
        let bad_eta = r#"{"bsdf":"dielectric","eta":20,"ndf":{"family":"ggx","alpha":0.4}}"#;
        for (args, names) in [
            (
                vec!["--bsdf", GLASS, "--incidence", "2"],
                vec!["--incidence", "--inside"],
            ),
            (
                vec!["--bsdf", GLASS, "--incidence", "-0.1"],
                vec!["--incidence"],
            ),
            (
                vec!["--bsdf", GLASS, "--azimuth", "nan"],
                vec!["--azimuth", "finite"],
            ),
            (
                vec!["--bsdf", GLASS, "--samples", "1", "--resolution", "4"],
                vec!["--samples", "at least 320"],
            ),
            (
                vec!["--bsdf", GLASS, "--resolution", "1000"],
                vec!["--resolution", "512"],
            ),
            (vec!["--bsdf", GLASS, "--alpha", "2"], vec!["--alpha"]),
            (vec!["--bsdf", bad_eta], vec!["--bsdf", "eta", "[0.1, 10]"]),
            (vec!["--bsdf", "not json"], vec!["--bsdf"]),
            (
                vec!["--bsdf", GLASS, "--sampling", "visible"],
                vec!["--sampling"],
            ),
            (
                vec!["--model", r#"{"family":"ggx","alpha":0.3}"#, "--inside"],
                vec!["--inside", "--bsdf"],
            ),
        ] {
            let mut all = vec!["chi2"];
            all.extend(args.iter().copied());
            let (code, out, err) = run_args(&all);
            assert_eq!(code, 2, "{args:?}: {out}{err}");
            assert!(out.is_empty(), "{args:?}: {out}");
            for n in names {
                assert!(err.contains(n), "{args:?}: {err:?} lacks {n:?}");
            }
        }
        // --bsdf with --model: clap's conflict, exit 2.
        let (code, _, err) = run_args(&["chi2", "--bsdf", GLASS, "--model", "{}"]);
        assert_eq!(code, 2, "{err}");
    }
}
