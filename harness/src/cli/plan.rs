//! `mfh plan`: print the plan of a scene, one JSON line per check with the reason it is
//! planned.

use super::{load_scene, ProfileArg, EXIT_BAD_INPUT, EXIT_PASS};
use clap::Args;
use std::io::Write;
use std::path::PathBuf;

/// The options of `mfh plan`.
#[derive(Debug, Args)]
pub struct PlanArgs {
    /// The scene file; default: the embedded default scene.
    #[arg(long)]
    pub scene: Option<PathBuf>,
    /// The profile.
    #[arg(long, value_enum, default_value = "quick")]
    pub profile: ProfileArg,
    /// JSON lines (for machines) or a table (for people).
    #[arg(long, value_enum, default_value = "jsonl")]
    pub format: PlanFormat,
}

/// The output format of `mfh plan`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum PlanFormat {
    /// One JSON object per line.
    Jsonl,
    /// A text table.
    Table,
}

/// Runs `mfh plan`; returns the exit status (0, or 2 on bad input or an unwritable standard
/// output).
pub fn run(args: PlanArgs, stdout: &mut dyn Write, stderr: &mut dyn Write) -> i32 {
    let scene = match load_scene(args.scene.as_deref()) {
        Ok(s) => s,
        Err(e) => {
            let _ = writeln!(stderr, "mfh plan: {e}");
            return EXIT_BAD_INPUT;
        }
    };
    let profile = args.profile.profile();
    let plan = crate::plan::plan(&scene, profile);
    let origin = super::scene_origin(args.scene.as_deref());
    if let Err(e) = crate::scene::Scene::check_plan_size(plan.len(), &origin, profile.name()) {
        let _ = writeln!(stderr, "mfh plan: {e}");
        return EXIT_BAD_INPUT;
    }
    let written = super::write_stdout("plan", stdout, stderr, |stdout| match args.format {
        PlanFormat::Table => {
            let table = crate::report::plan_table::plan_table(&plan, &scene.not_audited);
            write!(stdout, "{table}")
        }
        PlanFormat::Jsonl => {
            for line in crate::plan::describe(&plan) {
                writeln!(stdout, "{line}")?;
            }
            for n in &scene.not_audited {
                let line = serde_json::json!({"not_audited": n, "why": n.to_string()});
                writeln!(stdout, "{line}")?;
            }
            Ok(())
        }
    });
    if let Err(code) = written {
        return code;
    }
    let _ = writeln!(
        stderr,
        "{} checks planned for scene \"{}\"",
        plan.len(),
        scene.name
    );
    EXIT_PASS
}
