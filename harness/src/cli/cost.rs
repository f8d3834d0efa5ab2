//! `mfh cost`: what accuracy costs in time. Runs the route catalogue (`crate::cost`), prints
//! the terminal table, writes cost.json, the Pareto plots and cost.html into `--out`, and with
//! `--markdown DIR` the generated report `DIR/accuracy-versus-time.md`.

use super::progress::Bar;
use super::{load_scene, resolve_seed, EXIT_BAD_INPUT, EXIT_PASS};
use crate::cost::{CostOptions, Selection};
use clap::Args;
use std::io::Write;
use std::path::PathBuf;

/// The options of `mfh cost`.
#[derive(Debug, Args)]
pub struct CostArgs {
    /// Measure only the quantities a scene uses (its families and effects; the oracles
    /// always); default: every quantity.
    #[arg(long)]
    pub scene: Option<PathBuf>,
    /// Output folder of cost.json, cost/*.svg and cost.html (`mfh audit --out` into the same
    /// folder then shows them in report.html).
    #[arg(long, default_value = "reports/latest")]
    pub out: PathBuf,
    /// Fewer oracle settings and short timing batches: a few seconds.
    #[arg(long)]
    pub quick: bool,
    /// Also write the generated markdown report (accuracy-versus-time.md) into this folder
    /// (`reports/` in the repository).
    #[arg(long)]
    pub markdown: Option<PathBuf>,
    /// Errors only, no timing (deterministic output).
    #[arg(long)]
    pub no_time: bool,
    /// The seed of the Monte Carlo and chi-square oracles (default: MFH_SEED, else fixed).
    #[arg(long)]
    pub seed: Option<u64>,
    /// Print cost.json to standard output instead of the table.
    #[arg(long)]
    pub json: bool,
    /// No progress bar.
    #[arg(long, short)]
    pub quiet: bool,
}

/// Runs `mfh cost`; returns the exit status (0, or 2 on bad input or an unwritable output).
pub fn run(args: CostArgs, stdout: &mut dyn Write, stderr: &mut dyn Write) -> i32 {
    let selection = match &args.scene {
        None => Selection::ALL,
        Some(path) => match load_scene(Some(path)) {
            Ok(scene) => Selection::of_scene(&scene),
            Err(e) => {
                let _ = writeln!(stderr, "mfh cost: {e}");
                return EXIT_BAD_INPUT;
            }
        },
    };
    let seed = match resolve_seed(args.seed) {
        Ok(s) => s,
        Err(e) => {
            let _ = writeln!(stderr, "mfh cost: {e}");
            return EXIT_BAD_INPUT;
        }
    };
    if let Some(dir) = &args.markdown {
        if !dir.is_dir() {
            let _ = writeln!(
                stderr,
                "mfh cost: --markdown {} is not a folder",
                dir.display()
            );
            return EXIT_BAD_INPUT;
        }
    }
    // The output folder is created before the (minutes-long) measurement, so that an
    // unwritable --out is reported at once.
    if let Err(e) = std::fs::create_dir_all(&args.out) {
        let _ = writeln!(
            stderr,
            "mfh cost: cannot create the output folder {}: {e}",
            args.out.display()
        );
        return EXIT_BAD_INPUT;
    }
    let options = CostOptions {
        quick: args.quick,
        timed: !args.no_time,
        seed,
        selection,
    };
    let planned = crate::cost::planned(&options);
    let bar = Bar::new(planned as u64, "quantities", args.quiet);
    let trace = super::trace::enabled();
    let mut last = std::time::Instant::now();
    let report = crate::cost::run(&options, &mut |done, _, name| {
        bar.update(done as u64, format!(", {name}"));
        if trace {
            eprintln!("mfh cost: {name}: {:.2} s", last.elapsed().as_secs_f64());
            last = std::time::Instant::now();
        }
    });
    bar.finish();
    let written = match crate::report::cost::write_all(&report, &args.out) {
        Ok(w) => w,
        Err(e) => {
            let _ = writeln!(stderr, "mfh cost: {e}");
            return EXIT_BAD_INPUT;
        }
    };
    let markdown = match &args.markdown {
        None => None,
        Some(dir) => match crate::report::cost::write_markdown(&report, dir) {
            Ok(p) => Some(p),
            Err(e) => {
                let _ = writeln!(stderr, "mfh cost: {e}");
                return EXIT_BAD_INPUT;
            }
        },
    };
    let printed = super::write_stdout("cost", stdout, stderr, |stdout| {
        if args.json {
            return writeln!(
                stdout,
                "{}",
                serde_json::to_string(&report).expect("a cost report serializes")
            );
        }
        write!(stdout, "{}", crate::report::cost::terminal(&report))?;
        writeln!(
            stdout,
            "wrote {} files into {} (cost.json, cost/*.svg, cost.html){}",
            written.len(),
            args.out.display(),
            markdown
                .map(|p| format!(" and {}", p.display()))
                .unwrap_or_default()
        )
    });
    match printed {
        Ok(()) => EXIT_PASS,
        Err(code) => code,
    }
}
