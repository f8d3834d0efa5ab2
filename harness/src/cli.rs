//! The clap command line of `mfh`, callable in-process (the tests crate drives it this way).
//! Exit codes: 0 success, 1 failed checks, 2 bad input.

use clap::{Parser, Subcommand};
use std::ffi::OsString;
use std::io::{BufRead, BufReader, Write};
use std::path::PathBuf;

/// Exit status for bad input (unreadable files, malformed queries, invalid parameters).
pub const EXIT_BAD_INPUT: i32 = 2;

/// mfh — verification and conformance harness for microfacet BSDF mathematics.
#[derive(Debug, Parser)]
#[command(name = "mfh", version, about)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Evaluate closed forms: JSON-lines queries in, one JSON line per query out, in order.
    ///
    /// Each query is an object such as
    /// {"model":{"family":"std","gamma":2.5,"alpha":0.3},"quantity":"lambda","theta":1.2}.
    /// Exit status 2 if any line failed (its answer is an error line; the others are answered).
    Eval {
        /// Read queries from this file instead of standard input.
        #[arg(long)]
        input: Option<PathBuf>,
    },
    /// Audit a scene: plan the checks its materials and effects call for, run them against
    /// independent oracles, print a summary, write report.json and junit.xml into --out.
    ///
    /// Exit status 0 if every check passes (expected failures included), 1 if one fails, 2 on
    /// bad input.
    Audit {
        /// The scene file (JSON, DESIGN.md "Scenes"); default: the embedded default scene.
        #[arg(long)]
        scene: Option<PathBuf>,
        /// How hard to look.
        #[arg(long, value_enum, default_value = "quick")]
        profile: crate::check::Profile,
        /// The audit seed (default: MFH_SEED, else a fixed seed).
        #[arg(long)]
        seed: Option<u64>,
        /// Output folder.
        #[arg(long, default_value = "reports/latest")]
        out: PathBuf,
        /// Print report.json to standard output instead of the summary.
        #[arg(long)]
        json: bool,
    },
    /// Print the plan of a scene: one JSON line per check, with the reason it is planned.
    Plan {
        /// The scene file; default: the embedded default scene.
        #[arg(long)]
        scene: Option<PathBuf>,
        /// The profile.
        #[arg(long, value_enum, default_value = "quick")]
        profile: crate::check::Profile,
    },
    /// Chi-square test of a model's normal sampler (sample_wm) against its pdf (pdf_wm) over
    /// a grid of R cos θ-rows × 2R φ-columns of the upper hemisphere.
    ///
    /// Exit status 0 if the test passes, 1 if it fails, 2 on bad input.
    Chi2 {
        /// The model spec as JSON text, e.g. '{"family":"ggx","alpha":0.3}'.
        #[arg(long)]
        model: String,
        /// Samples to draw.
        #[arg(long, default_value_t = 1_000_000)]
        samples: u64,
        /// Grid resolution R: R cos θ-rows × 2R φ-columns.
        #[arg(long, default_value_t = 32)]
        resolution: usize,
        /// Seed of the random streams (default: MFH_SEED, else a fixed seed).
        #[arg(long)]
        seed: Option<u64>,
        /// Significance level.
        #[arg(long, default_value_t = 1e-4)]
        alpha: f64,
        /// Print one JSON object.
        #[arg(long)]
        json: bool,
        /// Write observed and expected count tables (JSON) and heat maps of observed, expected
        /// and (O − E)/√E (PNG) into this folder.
        #[arg(long)]
        out: Option<PathBuf>,
        /// What to sample: normals (`sample_wm`) or visible normals (`sample_wm_visible` at
        /// the incidence).
        #[arg(long, value_enum, default_value = "normals")]
        sampling: crate::chi2_command::SamplingKind,
        /// The incidence θi in radians (visible normals).
        #[arg(long, default_value_t = 0.5)]
        incidence: f64,
        /// The incidence azimuth φi in radians (visible normals).
        #[arg(long, default_value_t = 0.0)]
        azimuth: f64,
    },
    /// Audit an implementation in any language: start `--cmd` (with `sh -c`), speak the
    /// external protocol with it over stdin / stdout (README, "Audit an implementation in any
    /// language"), and run the checks its declared capabilities call for.
    ///
    /// Exit status 0 if every check passes, 1 if one fails (a protocol error during the audit
    /// is an `external.protocol` error record), 2 if the child cannot start or describe itself.
    AuditExternal {
        /// The command that starts the implementation, run with `sh -c`, e.g.
        /// "python3 examples/external/ggx.py".
        #[arg(long)]
        cmd: String,
        /// How hard to look.
        #[arg(long, value_enum, default_value = "ci")]
        profile: crate::check::Profile,
        /// Also compare value by value with this reference spec (JSON), e.g.
        /// '{"family":"ggx","alpha":0.3}'.
        #[arg(long)]
        against: Option<String>,
        /// Seconds to wait for each answer before the child is killed.
        #[arg(long, default_value_t = crate::external::DEFAULT_TIMEOUT_SECONDS)]
        timeout: f64,
        /// The audit seed (default: MFH_SEED, else a fixed seed).
        #[arg(long)]
        seed: Option<u64>,
        /// Output folder (report.json, junit.xml).
        #[arg(long, default_value = "reports/external")]
        out: PathBuf,
        /// Print report.json to standard output instead of the summary.
        #[arg(long)]
        json: bool,
    },
}

/// Runs the command line `args` (including the program name) with the given streams and
/// returns the exit status.
pub fn run<I, T>(
    args: I,
    stdin: &mut dyn BufRead,
    stdout: &mut dyn Write,
    stderr: &mut dyn Write,
) -> i32
where
    I: IntoIterator<Item = T>,
    T: Into<OsString> + Clone,
{
    let cli = match Cli::try_parse_from(args) {
        Ok(cli) => cli,
        Err(e) => {
            let code = if e.use_stderr() { EXIT_BAD_INPUT } else { 0 };
            let text = e.render().to_string();
            let _ = if e.use_stderr() {
                stderr.write_all(text.as_bytes())
            } else {
                stdout.write_all(text.as_bytes())
            };
            return code;
        }
    };
    match cli.command {
        Command::Audit {
            scene,
            profile,
            seed,
            out,
            json,
        } => run_audit(scene, profile, seed, out, json, stdout, stderr),
        Command::Plan { scene, profile } => {
            let scene = match load_scene(scene.as_deref()) {
                Ok(s) => s,
                Err(e) => {
                    let _ = writeln!(stderr, "mfh plan: {e}");
                    return EXIT_BAD_INPUT;
                }
            };
            let plan = crate::plan::plan(&scene, profile);
            for line in crate::plan::describe(&plan) {
                let _ = writeln!(stdout, "{line}");
            }
            let _ = writeln!(
                stderr,
                "{} checks planned for scene \"{}\"",
                plan.len(),
                scene.name
            );
            0
        }
        Command::Chi2 {
            model,
            samples,
            resolution,
            seed,
            alpha,
            json,
            out,
            sampling,
            incidence,
            azimuth,
        } => crate::chi2_command::run_chi2(
            &crate::chi2_command::Chi2Options {
                model,
                samples,
                resolution,
                seed,
                alpha,
                json,
                out,
                sampling,
                incidence,
                azimuth,
            },
            stdout,
            stderr,
        ),
        Command::AuditExternal {
            cmd,
            profile,
            against,
            timeout,
            seed,
            out,
            json,
        } => {
            let seed = match resolve_seed(seed) {
                Ok(s) => s,
                Err(e) => {
                    let _ = writeln!(stderr, "mfh audit-external: {e}");
                    return EXIT_BAD_INPUT;
                }
            };
            if !(timeout > 0.0 && timeout <= 86_400.0) {
                let _ = writeln!(
                    stderr,
                    "mfh audit-external: --timeout {timeout} is outside (0, 86400] seconds"
                );
                return EXIT_BAD_INPUT;
            }
            let request = crate::external::ExternalAudit {
                command: cmd,
                profile,
                seed,
                against,
                timeout: std::time::Duration::from_secs_f64(timeout),
                out: Some(out),
            };
            run_audit_external(&request, json, stdout, stderr)
        }
        Command::Eval { input } => {
            let result = match input {
                Some(path) => match std::fs::File::open(&path) {
                    Ok(f) => crate::eval::eval_stream(&mut BufReader::new(f), stdout),
                    Err(e) => {
                        let _ = writeln!(stderr, "mfh eval: cannot read {}: {e}", path.display());
                        return EXIT_BAD_INPUT;
                    }
                },
                None => crate::eval::eval_stream(stdin, stdout),
            };
            match result {
                Ok(summary) if summary.failed == 0 => 0,
                Ok(summary) => {
                    let _ = writeln!(
                        stderr,
                        "mfh eval: {} of {} queries failed",
                        summary.failed, summary.answered
                    );
                    EXIT_BAD_INPUT
                }
                Err(e) => {
                    let _ = writeln!(stderr, "mfh eval: {e}");
                    EXIT_BAD_INPUT
                }
            }
        }
    }
}

/// The scene at `path`, or the embedded default scene.
fn load_scene(
    path: Option<&std::path::Path>,
) -> Result<crate::scene::Scene, crate::scene::SceneError> {
    match path {
        Some(p) => crate::scene::Scene::load(p),
        None => Ok(crate::scene::Scene::default_scene()),
    }
}

/// The seed from the option, else `MFH_SEED`, else the default; an unparsable `MFH_SEED` is bad
/// input.
pub fn resolve_seed(seed: Option<u64>) -> Result<u64, String> {
    if let Some(s) = seed {
        return Ok(s);
    }
    match std::env::var("MFH_SEED") {
        Ok(text) => text
            .trim()
            .parse()
            .map_err(|_| format!("MFH_SEED={text:?} is not an unsigned integer")),
        Err(_) => Ok(crate::oracle::chi2::DEFAULT_SEED),
    }
}

fn run_audit(
    scene_path: Option<PathBuf>,
    profile: crate::check::Profile,
    seed: Option<u64>,
    out: PathBuf,
    json: bool,
    stdout: &mut dyn Write,
    stderr: &mut dyn Write,
) -> i32 {
    let scene = match load_scene(scene_path.as_deref()) {
        Ok(s) => s,
        Err(e) => {
            let _ = writeln!(stderr, "mfh audit: {e}");
            return EXIT_BAD_INPUT;
        }
    };
    let seed = match resolve_seed(seed) {
        Ok(s) => s,
        Err(e) => {
            let _ = writeln!(stderr, "mfh audit: {e}");
            return EXIT_BAD_INPUT;
        }
    };
    if let Err(e) = std::fs::create_dir_all(&out) {
        let _ = writeln!(stderr, "mfh audit: cannot create {}: {e}", out.display());
        return EXIT_BAD_INPUT;
    }
    let options = crate::audit::AuditOptions {
        profile,
        seed,
        out: Some(out.clone()),
    };
    let scene_name = scene_path.as_ref().map(|p| p.display().to_string());
    let report = crate::audit::audit_scene(&scene, scene_name.as_deref(), &options);
    let written = match crate::report::write_all(&report, &out) {
        Ok(w) => w,
        Err(e) => {
            let _ = writeln!(
                stderr,
                "mfh audit: cannot write the report into {}: {e}",
                out.display()
            );
            return EXIT_BAD_INPUT;
        }
    };
    if json {
        let _ = writeln!(stdout, "{}", crate::report::json::to_string(&report));
    } else {
        let _ = write!(stdout, "{}", crate::report::terminal::render(&report, 20));
        for p in written {
            let _ = writeln!(stdout, "wrote {}", p.display());
        }
    }
    if report.passed() {
        0
    } else {
        1
    }
}

/// `mfh audit-external`: audits the child, writes the report, maps the outcome to 0 / 1 / 2.
fn run_audit_external(
    request: &crate::external::ExternalAudit,
    json: bool,
    stdout: &mut dyn Write,
    stderr: &mut dyn Write,
) -> i32 {
    let out = request.out.clone().unwrap_or_else(|| PathBuf::from("."));
    if let Err(e) = std::fs::create_dir_all(&out) {
        let _ = writeln!(
            stderr,
            "mfh audit-external: cannot create {}: {e}",
            out.display()
        );
        return EXIT_BAD_INPUT;
    }
    let report = match crate::external::audit(request) {
        Ok(r) => r,
        Err(e) => {
            let _ = writeln!(stderr, "mfh audit-external: {e}");
            return EXIT_BAD_INPUT;
        }
    };
    let written = match crate::report::write_all(&report, &out) {
        Ok(w) => w,
        Err(e) => {
            let _ = writeln!(
                stderr,
                "mfh audit-external: cannot write the report into {}: {e}",
                out.display()
            );
            return EXIT_BAD_INPUT;
        }
    };
    if json {
        let _ = writeln!(stdout, "{}", crate::report::json::to_string(&report));
    } else {
        let _ = write!(stdout, "{}", crate::report::terminal::render(&report, 20));
        for p in written {
            let _ = writeln!(stdout, "wrote {}", p.display());
        }
    }
    if report.passed() {
        0
    } else {
        1
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run_args(args: &[&str]) -> (i32, String, String) {
        let (mut out, mut err) = (Vec::new(), Vec::new());
        let code = run(
            std::iter::once("mfh").chain(args.iter().copied()),
            &mut std::io::empty(),
            &mut out,
            &mut err,
        );
        (
            code,
            String::from_utf8(out).unwrap(),
            String::from_utf8(err).unwrap(),
        )
    }

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
        // The heat maps: valid PNGs of 16 φ × 8 cos θ cells, 16 px each (256 × 128), listed.
        let listed: Vec<&str> = v["artefacts"]
            .as_array()
            .unwrap()
            .iter()
            .filter_map(|a| a.as_str())
            .collect();
        assert_eq!(listed.len(), 5, "{listed:?}");
        for name in [
            "chi2_observed.png",
            "chi2_expected.png",
            "chi2_difference.png",
        ] {
            let path = dir.join(name);
            assert!(listed.contains(&path.to_str().unwrap()), "{listed:?}");
            let bytes = std::fs::read(&path).unwrap();
            assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n", "{name}");
            let reader = png::Decoder::new(std::io::Cursor::new(bytes))
                .read_info()
                .unwrap();
            let info = reader.info();
            assert_eq!((info.width, info.height), (256, 128), "{name}");
            assert_eq!(info.color_type, png::ColorType::Rgb);
        }
        let _ = std::fs::remove_dir_all(&dir);
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
        let (code, out, _) = run_args(&[
            "chi2",
            "--model",
            r#"{"family":"ggx","alpha":0.3}"#,
            "--samples",
            "1",
            "--resolution",
            "1",
        ]);
        assert_eq!(code, 1, "{out}");
        assert!(out.contains("verdict FAIL") && out.contains("bin"), "{out}");
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
}
