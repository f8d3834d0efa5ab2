//! SIGTERM, SIGINT and SIGHUP of the `mfh` binary: the external children's process groups are
//! ended first (`external::group::end_all`: SIGTERM, a short grace, SIGKILL), then mfh exits
//! with the conventional status 128 + the signal's number (143, 130, 129). Without this a
//! `timeout 300 mfh audit-external …` would end mfh and leave the child's group running (it is
//! in a group of its own, which neither the terminal's Ctrl-C nor `timeout` reaches).
//!
//! Installed once by `main` ([`install`]), never by the library or by `cli::run`: the tests
//! that drive the CLI in-process keep their own signal handling. `main` exits through [`exit`],
//! so that a command which ends early because its child was just ended (its pipes closed)
//! cannot exit with its own status while the handler is still at work.

use std::sync::Mutex;

/// Held by whichever exits the process: the signal thread or `main`.
static EXITING: Mutex<()> = Mutex::new(());

/// Starts a thread that waits for SIGTERM, SIGINT or SIGHUP, ends the children's groups and
/// exits 128 + signal. Call it once, at the start of the program.
#[cfg(unix)]
pub fn install() -> std::io::Result<()> {
    use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
    let mut signals = signal_hook::iterator::Signals::new([SIGTERM, SIGINT, SIGHUP])?;
    std::thread::Builder::new()
        .name("mfh-signals".into())
        .spawn(move || {
            if let Some(signal) = signals.forever().next() {
                let _exiting = EXITING.lock().unwrap_or_else(|p| p.into_inner());
                crate::external::group::end_all();
                std::process::exit(128 + signal);
            }
        })?;
    Ok(())
}

/// Nothing to install where there are no POSIX signals.
#[cfg(not(unix))]
pub fn install() -> std::io::Result<()> {
    Ok(())
}

/// Exits with `code`, unless a signal is being handled: then the handler's exit (128 + signal)
/// comes first.
pub fn exit(code: i32) -> ! {
    let _exiting = EXITING.lock().unwrap_or_else(|p| p.into_inner());
    std::process::exit(code)
}
