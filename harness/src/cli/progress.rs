//! Progress for the long commands, on standard error, never in the command's own output:
//! - a bar (indicatif, `mfh audit` and `mfh chi2`) when standard error is a terminal and
//!   `--quiet` is not given, once the run has taken more than [`SHOW_AFTER`];
//! - a line every [`LINE_INTERVAL`] ([`Lines`], `mfh audit` and `mfh audit-external`) when
//!   standard error is not a terminal (a CI log) and `--quiet` is not given: checks done of
//!   those planned, failures, and the check running longest, so that a long audit never looks
//!   hung.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::collections::BTreeMap;
use std::io::IsTerminal;
use std::sync::{mpsc, Arc, Mutex};
use std::time::{Duration, Instant};

/// How often [`Lines`] prints a progress line: often enough that a CI log shows life (CI
/// systems kill jobs silent for minutes), rarely enough that a long audit's log stays short
/// (360 lines an hour).
pub const LINE_INTERVAL: Duration = Duration::from_secs(10);

/// An environment variable that replaces [`LINE_INTERVAL`] (milliseconds, ≥ 1), for the test
/// that shows the line appears; not documented for users.
pub const LINE_INTERVAL_ENV: &str = "MFH_PROGRESS_INTERVAL_MS";

/// What [`Lines`] knows of a run.
#[derive(Debug, Default)]
struct LineState {
    /// Checks planned, once the run has begun.
    planned: Option<usize>,
    done: usize,
    failures: usize,
    /// The running checks by plan index: their label and start.
    running: BTreeMap<usize, (String, Instant)>,
}

/// A progress line on standard error every [`LINE_INTERVAL`] while a run lasts, from a thread
/// of its own: "mfh audit: 12/40 checks done, 1 failed, 2 running, longest
/// sampling.chi2 {…} for 35 s (1 min 20 s elapsed)". Stops when dropped.
pub struct Lines {
    state: Arc<Mutex<LineState>>,
    stop: Mutex<Option<(mpsc::Sender<()>, std::thread::JoinHandle<()>)>>,
}

impl Lines {
    /// Starts the lines of `command` (e.g. "audit"); None when `quiet` or when standard error
    /// is a terminal (the bar shows progress there).
    pub fn start(command: &str, quiet: bool) -> Option<Self> {
        if quiet || std::io::stderr().is_terminal() {
            return None;
        }
        let interval = std::env::var(LINE_INTERVAL_ENV)
            .ok()
            .and_then(|v| v.trim().parse::<u64>().ok())
            .filter(|&ms| ms >= 1)
            .map(Duration::from_millis)
            .unwrap_or(LINE_INTERVAL);
        let state = Arc::new(Mutex::new(LineState::default()));
        let (stop, stopped) = mpsc::channel::<()>();
        let (shared, command, start) = (state.clone(), command.to_string(), Instant::now());
        let thread = std::thread::Builder::new()
            .name("mfh-progress".into())
            .spawn(move || {
                while let Err(mpsc::RecvTimeoutError::Timeout) = stopped.recv_timeout(interval) {
                    let line = {
                        let s = shared.lock().unwrap_or_else(|p| p.into_inner());
                        render_line(&command, &s, start.elapsed())
                    };
                    eprintln!("{line}");
                }
            })
            .ok()?;
        Some(Self {
            state,
            stop: Mutex::new(Some((stop, thread))),
        })
    }

    /// The run has begun: `checks` planned, `resumed` of them already done.
    pub fn plan(&self, checks: usize, resumed: usize) {
        let mut s = self.state.lock().unwrap_or_else(|p| p.into_inner());
        s.planned = Some(checks);
        s.done = resumed;
    }

    /// Stops the lines (waits for the thread); idempotent.
    pub fn finish(&self) {
        let taken = self.stop.lock().unwrap_or_else(|p| p.into_inner()).take();
        if let Some((stop, thread)) = taken {
            drop(stop);
            let _ = thread.join();
        }
    }

    /// Check `index` (named `label`) has started.
    pub fn started(&self, index: usize, label: String) {
        let mut s = self.state.lock().unwrap_or_else(|p| p.into_inner());
        s.running.insert(index, (label, Instant::now()));
    }

    /// Check `index` has finished, `failed` or not.
    pub fn finished(&self, index: usize, failed: bool) {
        let mut s = self.state.lock().unwrap_or_else(|p| p.into_inner());
        s.running.remove(&index);
        s.done += 1;
        s.failures += usize::from(failed);
    }
}

impl Drop for Lines {
    fn drop(&mut self) {
        self.finish();
    }
}

/// A duration as "35 s", "4 min 05 s" or "1 h 02 min".
fn human(d: Duration) -> String {
    let s = d.as_secs();
    match s {
        0..=59 => format!("{s} s"),
        60..=3599 => format!("{} min {:02} s", s / 60, s % 60),
        _ => format!("{} h {:02} min", s / 3600, (s % 3600) / 60),
    }
}

/// One progress line.
fn render_line(command: &str, s: &LineState, elapsed: Duration) -> String {
    let planned = s.planned.map(|n| format!("/{n}")).unwrap_or_default();
    let mut line = format!(
        "mfh {command}: {}{planned} checks done, {} failed",
        s.done, s.failures
    );
    if let Some((label, since)) = s.running.values().min_by_key(|(_, since)| *since) {
        line.push_str(&format!(
            ", {} running, longest {label} for {}",
            s.running.len(),
            human(since.elapsed())
        ));
    }
    line.push_str(&format!(" ({} elapsed)", human(elapsed)));
    line
}

/// Runs shorter than this show no bar.
pub const SHOW_AFTER: Duration = Duration::from_secs(1);

/// A bar that appears on a terminal's standard error once the run has lasted [`SHOW_AFTER`].
pub struct Bar {
    bar: ProgressBar,
    start: Instant,
    enabled: bool,
}

impl Bar {
    /// A bar of `len` steps of `unit` (e.g. "checks"); disabled when `quiet` or when standard
    /// error is not a terminal.
    pub fn new(len: u64, unit: &str, quiet: bool) -> Self {
        let bar = ProgressBar::with_draw_target(Some(len), ProgressDrawTarget::hidden());
        let template = format!(
            "{{elapsed_precise}} [{{bar:40}}] {{human_pos}}/{{human_len}} {unit}{{msg}}, ETA {{eta}}"
        );
        if let Ok(style) = ProgressStyle::with_template(&template) {
            bar.set_style(style.progress_chars("=> "));
        }
        Self {
            bar,
            start: Instant::now(),
            enabled: !quiet && std::io::stderr().is_terminal(),
        }
    }

    /// Whether the bar can ever be drawn.
    pub fn enabled(&self) -> bool {
        self.enabled
    }

    /// Sets the position and the message (e.g. ", 2 failures"); draws once the run is long.
    pub fn update(&self, position: u64, message: String) {
        if !self.enabled {
            return;
        }
        if self.bar.is_hidden() && self.start.elapsed() >= SHOW_AFTER {
            self.bar.set_draw_target(ProgressDrawTarget::stderr());
        }
        self.bar.set_position(position);
        self.bar.set_message(message);
    }

    /// Removes the bar from the terminal.
    pub fn finish(&self) {
        if self.enabled {
            self.bar.finish_and_clear();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The line names the counts and the check running longest.
    #[test]
    fn the_line_names_counts_and_the_longest_running_check() {
        let now = Instant::now();
        let mut s = LineState {
            planned: Some(40),
            done: 12,
            failures: 1,
            ..LineState::default()
        };
        s.running.insert(3, ("smith.g1 {\"theta\":1}".into(), now));
        s.running.insert(
            7,
            (
                "sampling.chi2 {}".into(),
                now.checked_sub(Duration::from_secs(95)).unwrap_or(now),
            ),
        );
        let line = render_line("audit", &s, Duration::from_secs(3725));
        assert!(
            line.starts_with(
                "mfh audit: 12/40 checks done, 1 failed, 2 running, longest sampling.chi2 {}"
            ),
            "{line}"
        );
        assert!(line.ends_with("(1 h 02 min elapsed)"), "{line}");
        assert_eq!(human(Duration::from_secs(245)), "4 min 05 s");
    }
}
