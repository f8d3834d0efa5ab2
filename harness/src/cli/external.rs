//! `mfh audit-external`: audit an implementation in any language through the external
//! protocol (`crate::external`).

use super::{resolve_seed, ProfileArg, EXIT_BAD_INPUT, EXIT_FAIL, EXIT_PASS};
use clap::Args;
use std::io::Write;
use std::path::PathBuf;

/// The options of `mfh audit-external`.
#[derive(Debug, Args)]
pub struct ExternalArgs {
    /// The command that starts the implementation, run with `sh -c`, e.g.
    /// "python3 examples/external/ggx.py".
    #[arg(long)]
    pub cmd: String,
    /// How hard to look.
    #[arg(long, value_enum, default_value = "ci")]
    pub profile: ProfileArg,
    /// Also compare value by value with this reference spec (JSON): an NDF's, e.g.
    /// '{"family":"ggx","alpha":0.3}', or for a child that offers a BSDF a BSDF's, e.g.
    /// '{"bsdf":"dielectric","eta":1.5,"ndf":{"family":"ggx","alpha":0.3}}'.
    #[arg(long)]
    pub against: Option<String>,
    /// Seconds to wait for each answer before the child is killed.
    #[arg(long, default_value_t = crate::external::DEFAULT_TIMEOUT_SECONDS)]
    pub timeout: f64,
    /// The audit seed (default: MFH_SEED, else a fixed seed).
    #[arg(long)]
    pub seed: Option<u64>,
    /// Output folder (report.jsonl, report.json, junit.xml, report.html; default: the
    /// --resume folder, else reports/external).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Print report.json to standard output instead of the summary.
    #[arg(long)]
    pub json: bool,
    /// No progress lines (printed every 10 s when standard error is not a terminal).
    #[arg(long, short)]
    pub quiet: bool,
    /// Resuming and the time limit.
    #[command(flatten)]
    pub stream: super::stream::StreamArgs,
}

/// Runs `mfh audit-external`: 0 pass, 1 a check failed (a protocol error during the audit is
/// an `external.protocol` error record), 2 if the child cannot start or describe itself, on
/// bad options (every option is validated before the child starts) or an unwritable standard
/// output.
pub fn run(args: ExternalArgs, stdout: &mut dyn Write, stderr: &mut dyn Write) -> i32 {
    let seed = match resolve_seed(args.seed) {
        Ok(s) => s,
        Err(e) => {
            let _ = writeln!(stderr, "mfh audit-external: {e}");
            return EXIT_BAD_INPUT;
        }
    };
    if !(args.timeout > 0.0 && args.timeout <= 86_400.0) {
        let _ = writeln!(
            stderr,
            "mfh audit-external: --timeout {} is outside (0, 86400] seconds",
            args.timeout
        );
        return EXIT_BAD_INPUT;
    }
    if let Some(text) = &args.against {
        if let Err(e) = crate::external::Against::parse(text) {
            let _ = writeln!(stderr, "mfh audit-external: --against: {e}");
            return EXIT_BAD_INPUT;
        }
    }
    if let Err(e) = args.stream.max_time().and(args.stream.record_budget()) {
        let _ = writeln!(stderr, "mfh audit-external: {e}");
        return EXIT_BAD_INPUT;
    }
    let out = args.stream.out(args.out.clone(), "reports/external");
    if let Err(e) = std::fs::create_dir_all(&out) {
        let _ = writeln!(
            stderr,
            "mfh audit-external: cannot create {}: {e}",
            out.display()
        );
        return EXIT_BAD_INPUT;
    }
    let header = super::stream::external_header(
        args.cmd.clone(),
        args.against.clone(),
        args.profile.profile().name(),
        seed,
    );
    let (control, streaming) = match super::stream::prepare(
        "audit-external",
        &args.stream,
        header,
        &out,
        args.quiet,
        stderr,
    ) {
        Ok(prepared) => prepared,
        Err(e) => {
            let _ = writeln!(stderr, "mfh audit-external: {e}");
            return EXIT_BAD_INPUT;
        }
    };
    let request = crate::external::ExternalAudit {
        command: args.cmd,
        profile: args.profile.profile(),
        seed,
        against: args.against,
        timeout: std::time::Duration::from_secs_f64(args.timeout),
        out: Some(out.clone()),
        control,
    };
    let report = match crate::external::audit(&request) {
        Ok(r) => r,
        Err(e) => {
            let _ = writeln!(stderr, "mfh audit-external: {e}");
            return EXIT_BAD_INPUT;
        }
    };
    if let Err(e) = streaming.finish(&report, stderr) {
        let _ = writeln!(stderr, "mfh audit-external: {e}");
        return EXIT_BAD_INPUT;
    }
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
    let printed = super::write_stdout("audit-external", stdout, stderr, |stdout| {
        if args.json {
            return writeln!(stdout, "{}", crate::report::json::to_string(&report));
        }
        write!(stdout, "{}", crate::report::terminal::render(&report, 20))?;
        for p in written {
            writeln!(stdout, "wrote {}", p.display())?;
        }
        Ok(())
    });
    if let Err(code) = printed {
        return code;
    }
    if report.passed() {
        EXIT_PASS
    } else {
        EXIT_FAIL
    }
}
