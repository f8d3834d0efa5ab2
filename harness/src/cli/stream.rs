//! What `mfh audit` and `mfh audit-external` do while their checks run, and the options behind
//! it: each finished record appended to `report.jsonl` in `--out` (`report::jsonl`), the
//! progress lines of a non-terminal standard error (`progress::Lines`), `--resume DIR` (the
//! records of an interrupted run taken instead of running their checks again) and
//! `--max-time S` (no check started after S seconds), and the `MFH_TRACE` lines (`trace`). The
//! library only sends events (`run::RunControl`); the files are written here and in the sinks.

use super::progress::Lines;
use crate::record::Verdict;
use crate::report::jsonl::{self, Header, Sink};
use crate::run::{not_run_message, AuditReport, CheckEvent, CheckEventFn, RunControl};
use clap::Args;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Duration;

/// The options shared by `mfh audit` and `mfh audit-external` for long runs.
#[derive(Debug, Clone, Args)]
pub struct StreamArgs {
    /// Finish an interrupted audit: read DIR/report.jsonl (which must belong to the same
    /// audit: what is audited, profile, seed, plan), take its records, run the checks that
    /// have none, and write the whole report (into --out, by default DIR).
    #[arg(long, value_name = "DIR")]
    pub resume: Option<PathBuf>,
    /// End the audit after S seconds (> 0): checks not started by then are not run (each is an
    /// error record naming the limit, so the audit fails), running ones finish, and the report
    /// is written; `--resume` runs the rest later.
    #[arg(long, value_name = "S")]
    pub max_time: Option<f64>,
    /// The wall-clock budget of each record, seconds (> 0; default: the profile's, 120 s at
    /// ci, 300 quick, 900 standard, 3600 thorough): a check that runs past it is an error
    /// record naming the budget (not a verdict on the model; `--resume` runs it again).
    #[arg(long, value_name = "S")]
    pub record_budget: Option<f64>,
}

impl StreamArgs {
    /// The output folder: `out` if given, else the `--resume` folder, else `default`.
    pub fn out(&self, out: Option<PathBuf>, default: &str) -> PathBuf {
        out.or_else(|| self.resume.clone())
            .unwrap_or_else(|| PathBuf::from(default))
    }

    /// The time limit, if valid: a finite number of seconds > 0 that a duration can hold.
    pub fn max_time(&self) -> Result<Option<Duration>, String> {
        seconds("--max-time", self.max_time)
    }

    /// The record budget, if valid (as [`StreamArgs::max_time`]).
    pub fn record_budget(&self) -> Result<Option<Duration>, String> {
        seconds("--record-budget", self.record_budget)
    }
}

/// The duration of the option `flag` if given and valid: a finite number of seconds > 0 that a
/// duration can hold.
fn seconds(flag: &str, value: Option<f64>) -> Result<Option<Duration>, String> {
    match value {
        None => Ok(None),
        Some(s) if s > 0.0 && s.is_finite() => Duration::try_from_secs_f64(s)
            .map(Some)
            .map_err(|_| format!("{flag} {s}: too large (at most 1.8e19 seconds)")),
        Some(s) => Err(format!(
            "{flag} {s}: must be a finite number of seconds > 0"
        )),
    }
}

/// A run's streaming: the open `report.jsonl` and the progress lines.
pub struct Streaming {
    /// The resumed records not taken as stored ([`CheckEvent::Plan`]'s `distrusted`).
    distrusted: Arc<std::sync::Mutex<Vec<String>>>,
    sink: Arc<Sink>,
    lines: Option<Arc<Lines>>,
    max_time: Option<Duration>,
    command: String,
}

/// Prepares the streaming of `command` ("audit", "audit-external") into `out` for the run
/// `header` describes: reads and checks `--resume`'s report.jsonl, (re)creates
/// `out/report.jsonl` with the header and the resumed records, starts the progress lines
/// (unless `quiet`), and returns the [`RunControl`] to run with. Err: the message of an exit 2.
pub fn prepare(
    command: &str,
    args: &StreamArgs,
    header: Header,
    out: &Path,
    quiet: bool,
    stderr: &mut dyn Write,
) -> Result<(RunControl, Streaming), String> {
    let max_time = args.max_time()?;
    let record_budget = args.record_budget()?;
    let (resume, kept) = match &args.resume {
        None => (None, Vec::new()),
        Some(dir) => {
            let stream = jsonl::read(&dir.join(jsonl::FILE))
                .map_err(|e| format!("--resume {}: {e}", dir.display()))?;
            let differences = header.differences(&stream.header);
            if !differences.is_empty() {
                return Err(format!(
                    "--resume {}: its {} belongs to another audit ({})",
                    dir.display(),
                    jsonl::FILE,
                    differences.join("; ")
                ));
            }
            if stream.dropped_partial_line {
                let _ = writeln!(
                    stderr,
                    "mfh {command}: --resume: dropped the last line of {}, cut short when \
                     the run was stopped (its check runs again)",
                    dir.join(jsonl::FILE).display()
                );
            }
            (Some(Arc::new(stream.records)), stream.lines)
        }
    };
    let sink = Arc::new(Sink::create(out, &header, &kept).map_err(|e| e.to_string())?);
    let lines = Lines::start(command, quiet).map(Arc::new);
    let (s, l) = (sink.clone(), lines.clone());
    let distrusted = Arc::new(std::sync::Mutex::new(Vec::new()));
    let dist = distrusted.clone();
    let trace = super::trace::enabled();
    let on_check = CheckEventFn(Arc::new(move |event: CheckEvent<'_>| {
        if trace {
            super::trace::print(&event);
        }
        match event {
            CheckEvent::Plan {
                checks,
                resumed,
                distrusted,
            } => {
                if let Ok(mut d) = dist.lock() {
                    d.extend(distrusted.iter().cloned());
                }
                if let Some(l) = &l {
                    l.plan(checks, resumed);
                }
            }
            CheckEvent::Started { index, planned } => {
                if let Some(l) = &l {
                    l.started(index, format!("{} {}", planned.check, planned.case));
                }
            }
            CheckEvent::Finished {
                index,
                planned,
                record,
            } => {
                // A record stopped by its budget is not kept: `--resume` runs its check again.
                if !crate::check::budget::is_over_budget(&record.verdict) {
                    s.append(&crate::run::plan_key(planned), record);
                }
                if let Some(l) = &l {
                    l.finished(index, record.verdict.is_failure());
                }
            }
        }
    }));
    let control = RunControl {
        on_check: Some(on_check),
        resume,
        max_time,
        record_budget,
    };
    let streaming = Streaming {
        distrusted,
        sink,
        lines,
        max_time,
        command: command.to_string(),
    };
    Ok((control, streaming))
}

impl Streaming {
    /// Ends the streaming after the run: stops the progress lines, says on `stderr` which
    /// resumed records were re-judged or not taken, and which checks the time limit left unrun; Err: a record could not be appended to
    /// `report.jsonl` (the message of an exit 2).
    pub fn finish(&self, report: &AuditReport, stderr: &mut dyn Write) -> Result<(), String> {
        if let Some(l) = &self.lines {
            l.finish();
        }
        let distrusted = self
            .distrusted
            .lock()
            .map(|d| d.clone())
            .unwrap_or_default();
        if !distrusted.is_empty() {
            let _ = writeln!(
                stderr,
                "mfh {}: --resume: {} stored record(s) of {} were not taken as written:",
                self.command,
                distrusted.len(),
                jsonl::FILE
            );
            for line in &distrusted {
                let _ = writeln!(stderr, "  {line}");
            }
        }
        if let Some(limit) = self.max_time {
            let message = not_run_message(limit);
            let not_run = report
                .records
                .iter()
                .filter(|r| matches!(&r.verdict, Verdict::Error { message: m } if *m == message))
                .count();
            if not_run > 0 {
                let _ = writeln!(
                    stderr,
                    "mfh {}: --max-time {} s ran out: {not_run} of {} checks were not run \
                     (an error record each); --resume {} runs them",
                    self.command,
                    limit.as_secs_f64(),
                    report.records.len(),
                    self.sink
                        .path()
                        .parent()
                        .unwrap_or(Path::new("."))
                        .display()
                );
            }
        }
        match self.sink.error() {
            Some(e) => Err(e),
            None => Ok(()),
        }
    }
}

/// The header of `mfh audit`'s report.jsonl.
pub fn audit_header(subject: String, profile: &str, seed: u64, plan: (String, usize)) -> Header {
    Header {
        format: jsonl::FORMAT,
        schema_version: crate::record::SCHEMA_VERSION,
        mfh_version: env!("CARGO_PKG_VERSION").to_string(),
        command: "audit".into(),
        subject,
        against: None,
        profile: profile.to_string(),
        seed,
        plan: Some(plan),
    }
}

/// The header of `mfh audit-external`'s report.jsonl (its plan follows from the child's
/// `describe` answer: see [`Header::plan`]).
pub fn external_header(child: String, against: Option<String>, profile: &str, seed: u64) -> Header {
    Header {
        format: jsonl::FORMAT,
        schema_version: crate::record::SCHEMA_VERSION,
        mfh_version: env!("CARGO_PKG_VERSION").to_string(),
        command: "audit-external".into(),
        subject: child,
        against,
        profile: profile.to_string(),
        seed,
        plan: None,
    }
}
