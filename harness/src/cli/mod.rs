//! The clap command line of `mfh`, callable in-process (the tests crate drives it this way): one
//! file per command (`audit`, `plan`, `chi2` with `chi2_bsdf`, `cost`, `eval`, `selftest`,
//! `external` for `audit-external`), each parsing its options, calling the library and mapping
//! its errors to exit codes, except `merge`, which shares `audit.rs`'s report writing. The
//! library knows nothing of clap.
//!
//! Exit codes: [`EXIT_PASS`] 0 success, [`EXIT_FAIL`] 1 failed checks, [`EXIT_BAD_INPUT`] 2 bad
//! input, or an output that could not be written ([`write_stdout`]).

pub mod audit;
pub mod chi2;
pub mod chi2_bsdf;
pub mod closed_stdout;
pub mod cost;
pub mod eval;
pub mod external;
pub mod plan;
pub mod progress;
pub mod selftest;
pub mod signals;
pub mod stream;
pub mod trace;

use clap::{Parser, Subcommand, ValueEnum};
use std::ffi::OsString;
use std::io::{BufRead, Write};

/// Exit status when everything passed (or, for `eval`, every query was answered).
pub const EXIT_PASS: i32 = 0;

/// Exit status when a check failed.
pub const EXIT_FAIL: i32 = 1;

/// Exit status for bad input (unreadable files, malformed queries, invalid parameters) and for a
/// standard output that cannot be written (a full disk, a closed pipe).
pub const EXIT_BAD_INPUT: i32 = 2;

/// mfh — verification and conformance harness for microfacet BSDF mathematics.
#[derive(Debug, Parser)]
#[command(name = "mfh", version, about)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// The audit profile as the command line spells it; [`ProfileArg::profile`] maps it to the
/// library's [`crate::check::Profile`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum ProfileArg {
    /// Sized for one model in CI: the quick grids, 10⁶ chi-square and 2·10⁵ KS samples.
    Ci,
    /// A few cases per property, 2·10⁵ chi-square and 2·10⁶ KS samples per sampler.
    Quick,
    /// More incidence angles and 2·10⁶ samples per sampler.
    Standard,
    /// Dense grids, 10⁸ chi-square and Monte Carlo samples and 10⁷ KS samples per sampler.
    Thorough,
}

impl ProfileArg {
    /// The library profile.
    pub fn profile(self) -> crate::check::Profile {
        use crate::check::Profile;
        match self {
            ProfileArg::Ci => Profile::Ci,
            ProfileArg::Quick => Profile::Quick,
            ProfileArg::Standard => Profile::Standard,
            ProfileArg::Thorough => Profile::Thorough,
        }
    }
}

/// What `mfh chi2` samples, as the command line spells it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum SamplingArg {
    /// `sample_wm` against `pdf_wm` = D(m)(m·n).
    Normals,
    /// `sample_wm_visible(wi, ·)` against `pdf_wm_visible(wi, ·)` at the incidence.
    Visible,
}

impl SamplingArg {
    /// The library's sampling kind.
    pub fn kind(self) -> crate::sampler_chi2::SamplingKind {
        use crate::sampler_chi2::SamplingKind;
        match self {
            SamplingArg::Normals => SamplingKind::Normals,
            SamplingArg::Visible => SamplingKind::Visible,
        }
    }
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Evaluate closed forms: JSON-lines queries in, one JSON line per query out, in order.
    ///
    /// Each query is an object such as
    /// {"model":{"family":"std","gamma":2.5,"alpha":0.3},"quantity":"lambda","theta":1.2}.
    /// Exit status 2 if any line failed (its answer is an error line; the others are answered).
    Eval(eval::EvalArgs),
    /// Audit a scene: plan the checks its materials and effects call for, run them against
    /// independent oracles, print a summary, write report.json and junit.xml into --out.
    ///
    /// Exit status 0 if every check passes (expected failures included), 1 if one fails, 2 on
    /// bad input.
    Audit(audit::AuditArgs),
    /// Audit an implementation in any language: start `--cmd` (with `sh -c`), speak the
    /// external protocol with it over stdin / stdout (docs/external-protocol.md), and run the checks its declared capabilities call for.
    ///
    /// Exit status 0 if every check passes, 1 if one fails (a protocol error during the audit
    /// is an `external.protocol` error record), 2 if the child cannot start or describe itself.
    AuditExternal(external::ExternalArgs),
    /// Merge the output folders of `mfh audit --shard i/n` (every i of one n) into the
    /// unsharded report: report.json and junit.xml in --out.
    ///
    /// Exit status 0 if every check passes, 1 if one fails, 2 on bad input.
    Merge(audit::MergeArgs),
    /// Print the plan of a scene: one JSON line per check, with the reason it is planned.
    Plan(plan::PlanArgs),
    /// Chi-square test of a model's normal sampler (sample_wm) against its pdf (pdf_wm) over
    /// a grid of R cos θ-rows × 2R φ-columns of the upper hemisphere.
    ///
    /// Exit status 0 if the test passes, 1 if it fails, 2 on bad input.
    Chi2(chi2::Chi2Args),
    /// Prove the harness's power and calibration: audit a catalog of mutants (reference
    /// models with one injected defect each) for several seeds and print the kill matrix, or
    /// (`--calibrate N`) run seeded chi-square and KS tests of correct samplers.
    ///
    /// Exit status 0 if every mutant is killed at every seed by an expected check (and the
    /// calibration is within its bounds), 1 otherwise, 2 on bad input.
    Selftest(selftest::SelftestArgs),
    /// What accuracy costs in time: every route of every quantity with more than one route
    /// (and the oracles' knobs), its max error against a high-precision reference and its time
    /// per evaluation; cost.json, Pareto plots, cost.html and a terminal table.
    ///
    /// Exit status 0, or 2 on bad input or an output that cannot be written.
    Cost(cost::CostArgs),
}

/// Runs the CLI in-process on `args` (without the program name) with an empty standard input:
/// (exit code, standard output, standard error), the outputs as (lossy) UTF-8. For embedding
/// `mfh` in another Rust program and for tests.
pub fn run_captured(args: &[&str]) -> (i32, String, String) {
    let (mut out, mut err) = (Vec::new(), Vec::new());
    let code = run(
        std::iter::once("mfh").chain(args.iter().copied()),
        &mut std::io::empty(),
        &mut out,
        &mut err,
    );
    (
        code,
        String::from_utf8_lossy(&out).into_owned(),
        String::from_utf8_lossy(&err).into_owned(),
    )
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
            let text = e.render().to_string();
            if e.use_stderr() {
                let _ = stderr.write_all(text.as_bytes());
                return EXIT_BAD_INPUT;
            }
            // --help, --version: their text is the output, and it must arrive.
            return match write_stdout("--help/--version", stdout, stderr, |stdout| {
                stdout.write_all(text.as_bytes())
            }) {
                Ok(()) => EXIT_PASS,
                Err(code) => code,
            };
        }
    };
    match cli.command {
        Command::Audit(args) => audit::run(args, stdout, stderr),
        Command::AuditExternal(args) => external::run(args, stdout, stderr),
        Command::Merge(args) => audit::run_merge(args, stdout, stderr),
        Command::Plan(args) => plan::run(args, stdout, stderr),
        Command::Chi2(args) => chi2::run(args, stdout, stderr),
        Command::Cost(args) => cost::run(args, stdout, stderr),
        Command::Eval(args) => eval::run(args, stdin, stdout, stderr),
        Command::Selftest(args) => selftest::run(args, stdout, stderr),
    }
}

/// Writes a command's output with `write` and flushes standard output; a write error (a full
/// disk, a pipe closed by `head`) is reported on standard error as "mfh COMMAND: cannot write
/// standard output: …" and is `Err(EXIT_BAD_INPUT)`: an output that did not arrive is not a
/// success. Every command that prints its result goes through this one function.
pub(crate) fn write_stdout(
    command: &str,
    stdout: &mut dyn Write,
    stderr: &mut dyn Write,
    write: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> Result<(), i32> {
    match write(stdout).and_then(|()| stdout.flush()) {
        Ok(()) => Ok(()),
        Err(e) => {
            let _ = writeln!(stderr, "mfh {command}: cannot write standard output: {e}");
            Err(EXIT_BAD_INPUT)
        }
    }
}

/// The scene at `path`, or the embedded default scene.
pub(crate) fn load_scene(
    path: Option<&std::path::Path>,
) -> Result<crate::scene::Scene, crate::scene::SceneError> {
    match path {
        Some(p) => crate::scene::Scene::load(p),
        None => Ok(crate::scene::Scene::default_scene()),
    }
}

/// How a scene is named in messages: its path, or `<default scene>`.
pub(crate) fn scene_origin(path: Option<&std::path::Path>) -> String {
    path.map(|p| p.display().to_string())
        .unwrap_or_else(|| "<default scene>".to_string())
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
        Err(_) => Ok(crate::run::DEFAULT_SEED),
    }
}
