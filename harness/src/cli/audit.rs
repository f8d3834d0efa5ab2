//! `mfh audit`: plan a scene's checks, run them, print the summary, write the report.

use super::progress::Bar;
use super::{load_scene, resolve_seed, ProfileArg, EXIT_BAD_INPUT, EXIT_FAIL, EXIT_PASS};
use crate::audit::{Progress, ProgressFn};
use clap::Args;
use std::io::Write;
use std::path::PathBuf;

/// The options of `mfh audit`.
#[derive(Debug, Args)]
pub struct AuditArgs {
    /// The scene file (JSON, DESIGN.md "Scenes"); default: the embedded default scene.
    #[arg(long)]
    pub scene: Option<PathBuf>,
    /// How hard to look.
    #[arg(long, value_enum, default_value = "quick")]
    pub profile: ProfileArg,
    /// The audit seed (default: MFH_SEED, else a fixed seed).
    #[arg(long)]
    pub seed: Option<u64>,
    /// Output folder.
    #[arg(long, default_value = "reports/latest")]
    pub out: PathBuf,
    /// Print report.json to standard output instead of the summary.
    #[arg(long)]
    pub json: bool,
    /// No progress bar (it is shown only when standard error is a terminal anyway).
    #[arg(long, short)]
    pub quiet: bool,
}

/// Runs `mfh audit`; returns the exit status (0 pass, 1 a check failed, 2 bad input).
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
    let out = args.out;
    if let Err(e) = std::fs::create_dir_all(&out) {
        let _ = writeln!(stderr, "mfh audit: cannot create {}: {e}", out.display());
        return EXIT_BAD_INPUT;
    }
    let mut options = crate::audit::AuditOptions {
        profile: args.profile.profile(),
        seed,
        out: Some(out.clone()),
        progress: None,
    };
    let planned = crate::plan::plan(&scene, options.profile).len();
    let origin = super::scene_origin(args.scene.as_deref());
    if let Err(e) = crate::scene::Scene::check_plan_size(planned, &origin, options.profile.name()) {
        let _ = writeln!(stderr, "mfh audit: {e}");
        return EXIT_BAD_INPUT;
    }
    let scene_name = args.scene.as_ref().map(|p| p.display().to_string());
    let bar = std::sync::Arc::new(Bar::new(planned as u64, "checks", args.quiet));
    if bar.enabled() {
        let b = bar.clone();
        options.progress = Some(ProgressFn(std::sync::Arc::new(move |p: Progress| {
            b.update(p.done as u64, format!(", {} failed", p.failures));
        })));
    }
    let report = crate::audit::audit_scene(&scene, scene_name.as_deref(), &options);
    bar.finish();
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
    if args.json {
        let _ = writeln!(stdout, "{}", crate::report::json::to_string(&report));
    } else {
        let _ = write!(stdout, "{}", crate::report::terminal::render(&report, 20));
        for p in written {
            let _ = writeln!(stdout, "wrote {}", p.display());
        }
    }
    if report.passed() {
        EXIT_PASS
    } else {
        EXIT_FAIL
    }
}
