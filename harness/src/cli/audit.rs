//! `mfh audit`: plan a scene's checks, run them, print the summary, write the report.

use super::progress::Bar;
use super::{load_scene, resolve_seed, ProfileArg, EXIT_BAD_INPUT, EXIT_FAIL, EXIT_PASS};
use crate::run::{Progress, ProgressFn};
use clap::Args;
use std::io::Write;
use std::path::PathBuf;

/// The options of `mfh audit`.
#[derive(Debug, Args)]
pub struct AuditArgs {
    /// The scene file (JSON, ARCHITECTURE.md "Scenes"); default: the embedded default scene.
    #[arg(long)]
    pub scene: Option<PathBuf>,
    /// How hard to look.
    #[arg(long, value_enum, default_value = "quick")]
    pub profile: ProfileArg,
    /// The audit seed (default: MFH_SEED, else a fixed seed).
    #[arg(long)]
    pub seed: Option<u64>,
    /// Output folder (default: the --resume folder, else reports/latest).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Print report.json to standard output instead of the summary.
    #[arg(long)]
    pub json: bool,
    /// No progress: neither the bar of a terminal nor the lines (every 10 s) of a
    /// non-terminal standard error.
    #[arg(long, short)]
    pub quiet: bool,
    /// Run only shard i of n (1 ≤ i ≤ n) of the plan, balanced by estimated cost; writes
    /// shard.json beside report.json for `mfh merge`.
    #[arg(long, conflicts_with = "resume")]
    pub shard: Option<crate::shard::ShardSpec>,
    /// Resuming and the time limit.
    #[command(flatten)]
    pub stream: super::stream::StreamArgs,
    /// Comparison with a saved run.
    #[command(flatten)]
    pub baseline: BaselineArgs,
}

/// Comparison with a saved run (`mfh audit` and `mfh merge`).
#[derive(Debug, Clone, Args)]
pub struct BaselineArgs {
    /// A saved report.json: report checks whose error grew or whose cost rose by more than the
    /// factors of `baseline.rs` (error ×2, cost ×3).
    #[arg(long)]
    pub baseline: Option<PathBuf>,
    /// Exit 1 when the baseline comparison finds a regression.
    #[arg(long, requires = "baseline")]
    pub fail_on_regression: bool,
}

/// The options of `mfh merge`.
#[derive(Debug, Args)]
pub struct MergeArgs {
    /// The shard output folders.
    #[arg(required = true)]
    pub dirs: Vec<PathBuf>,
    /// Output folder.
    #[arg(long, default_value = "reports/merged")]
    pub out: PathBuf,
    /// Print report.json to standard output instead of the summary.
    #[arg(long)]
    pub json: bool,
    /// Comparison with a saved run.
    #[command(flatten)]
    pub baseline: BaselineArgs,
}

/// Runs `mfh merge`; returns the exit status (0 pass, 1 a check failed, 2 bad input).
pub fn run_merge(args: MergeArgs, stdout: &mut dyn Write, stderr: &mut dyn Write) -> i32 {
    match crate::merge::merge_dirs(&args.dirs) {
        Ok(merged) => {
            if !merged.corrected.is_empty() {
                let _ = writeln!(
                    stderr,
                    "mfh merge: corrected {} stored verdict(s) that their records' numbers \
                     contradict:",
                    merged.corrected.len()
                );
                for line in &merged.corrected {
                    let _ = writeln!(stderr, "  {line}");
                }
            }
            finish_report(
                &merged.report,
                &args.out,
                args.json,
                &args.baseline,
                "merge",
                stdout,
                stderr,
            )
        }
        Err(e) => {
            let _ = writeln!(stderr, "mfh merge: {e}");
            EXIT_BAD_INPUT
        }
    }
}

/// Runs `mfh audit`; returns the exit status (0 pass, 1 a check failed, 2 bad input or an
/// unwritable standard output).
pub fn run(args: AuditArgs, stdout: &mut dyn Write, stderr: &mut dyn Write) -> i32 {
    let scene = match load_scene(args.scene.as_deref()) {
        Ok(s) => s,
        Err(e) => {
            let _ = writeln!(stderr, "mfh audit: {e}");
            return EXIT_BAD_INPUT;
        }
    };
    let seed = match resolve_seed(args.seed) {
        Ok(s) => s,
        Err(e) => {
            let _ = writeln!(stderr, "mfh audit: {e}");
            return EXIT_BAD_INPUT;
        }
    };
    if let Err(e) = args.stream.max_time().and(args.stream.record_budget()) {
        let _ = writeln!(stderr, "mfh audit: {e}");
        return EXIT_BAD_INPUT;
    }
    let out = args.stream.out(args.out.clone(), "reports/latest");
    if let Err(e) = std::fs::create_dir_all(&out) {
        let _ = writeln!(stderr, "mfh audit: cannot create {}: {e}", out.display());
        return EXIT_BAD_INPUT;
    }
    let mut options = crate::run::AuditOptions {
        profile: args.profile.profile(),
        seed,
        out: Some(out.clone()),
        ..Default::default()
    };
    let (planned, fingerprint) = {
        let plan = crate::plan::plan(&scene, options.profile);
        (plan.len(), crate::shard::fingerprint(&plan))
    };
    let origin = super::scene_origin(args.scene.as_deref());
    if let Err(e) = crate::scene::Scene::check_plan_size(planned, &origin, options.profile.name()) {
        let _ = writeln!(stderr, "mfh audit: {e}");
        return EXIT_BAD_INPUT;
    }
    let header =
        super::stream::audit_header(origin, options.profile.name(), seed, (fingerprint, planned));
    let streaming =
        match super::stream::prepare("audit", &args.stream, header, &out, args.quiet, stderr) {
            Ok((control, streaming)) => {
                options.control = control;
                streaming
            }
            Err(e) => {
                let _ = writeln!(stderr, "mfh audit: {e}");
                return EXIT_BAD_INPUT;
            }
        };
    let scene_name = args.scene.as_ref().map(|p| p.display().to_string());
    let bar = std::sync::Arc::new(Bar::new(planned as u64, "checks", args.quiet));
    if bar.enabled() {
        let b = bar.clone();
        options.progress = Some(ProgressFn(std::sync::Arc::new(move |p: Progress| {
            b.update(p.done as u64, format!(", {} failed", p.failures));
        })));
    }
    let report = match args.shard {
        None => crate::run::audit_scene(&scene, scene_name.as_deref(), &options),
        Some(spec) => {
            let (report, info) =
                crate::shard::audit_shard(&scene, scene_name.as_deref(), &options, spec);
            let path = out.join(crate::shard::SHARD_FILE);
            let text = serde_json::to_string_pretty(&info).unwrap_or_default();
            if let Err(e) = std::fs::write(&path, text + "\n") {
                let _ = writeln!(stderr, "mfh audit: cannot write {}: {e}", path.display());
                return EXIT_BAD_INPUT;
            }
            report
        }
    };
    bar.finish();
    let streamed = streaming.finish(&report, stderr);
    let code = finish_report(
        &report,
        &out,
        args.json,
        &args.baseline,
        "audit",
        stdout,
        stderr,
    );
    match streamed {
        // The whole report is written; a report.jsonl that misses records is still an error.
        Err(e) => {
            let _ = writeln!(stderr, "mfh audit: {e}");
            EXIT_BAD_INPUT
        }
        Ok(()) => code,
    }
}

/// Writes the report's sinks into `out`, prints the summary (or the JSON), the not-audited
/// list and the baseline comparison; returns the exit status.
fn finish_report(
    report: &crate::run::AuditReport,
    out: &std::path::Path,
    json: bool,
    baseline: &BaselineArgs,
    command: &str,
    stdout: &mut dyn Write,
    stderr: &mut dyn Write,
) -> i32 {
    let old = match &baseline.baseline {
        Some(path) => match crate::readback::read_report(path) {
            Ok(r) => Some((path.display().to_string(), r)),
            Err(e) => {
                let _ = writeln!(stderr, "mfh {command}: --baseline: {e}");
                return EXIT_BAD_INPUT;
            }
        },
        None => None,
    };
    let written = match crate::report::write_all(report, out) {
        Ok(w) => w,
        Err(e) => {
            let _ = writeln!(
                stderr,
                "mfh {command}: cannot write the report into {}: {e}",
                out.display()
            );
            return EXIT_BAD_INPUT;
        }
    };
    let printed = super::write_stdout(command, stdout, stderr, |stdout| {
        if json {
            return writeln!(stdout, "{}", crate::report::json::to_string(report));
        }
        write!(stdout, "{}", crate::report::terminal::render(report, 20))?;
        for n in &report.not_audited {
            writeln!(stdout, "{n}")?;
        }
        for p in written {
            writeln!(stdout, "wrote {}", p.display())?;
        }
        Ok(())
    });
    if let Err(code) = printed {
        return code;
    }
    let mut regressed = false;
    if let Some((name, old)) = old {
        let c = crate::baseline::compare(&old, report);
        regressed = !c.regressions.is_empty();
        let text = crate::baseline::render(&c, &name, 20);
        if json {
            let _ = write!(stderr, "{text}");
        } else if let Err(code) =
            super::write_stdout(command, stdout, stderr, |stdout| write!(stdout, "{text}"))
        {
            return code;
        }
    }
    if !report.passed() || (regressed && baseline.fail_on_regression) {
        EXIT_FAIL
    } else {
        EXIT_PASS
    }
}
