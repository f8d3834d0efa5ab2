//! Progress bars (indicatif) for the long commands, `mfh audit` and `mfh chi2`: shown on
//! standard error only when it is a terminal, `--quiet` is not given, and the run has taken
//! more than [`SHOW_AFTER`]; never written into the command's own output streams.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::time::{Duration, Instant};

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
