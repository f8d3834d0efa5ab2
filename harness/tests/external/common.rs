//! What the external-protocol tests share (included by `external.rs` and `external_audit.rs`
//! with `#[path]`): where the examples are, the CLI runner, and what a numpy test checks first.
//! Which tests run is decided by cfg flags (`has_numpy`, `mfh_extensive`) that the build script
//! sets by the rules of `mfh-test-tiers`: a test left out is ignored, and listed as such.

#![allow(dead_code)] // each test file uses its own subset

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// The repository root.
pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// The command that runs `examples/external/<file>` with `args`.
pub fn example(file: &str, args: &str) -> String {
    format!(
        "python3 {}/examples/external/{file} {args}",
        root().display()
    )
    .trim_end()
    .to_string()
}

/// Runs the `mfh` CLI in-process: (exit code, stdout, stderr).
pub fn run(args: &[&str]) -> (i32, String, String) {
    mfh_harness::cli::run_captured(args)
}

/// Fails the test with a clear message if python3 has no numpy. A numpy test runs where the
/// build found numpy (`has_numpy`) or under `CI=true`, where `.ci/run` installs it: there a
/// missing numpy is a failure, not a skip.
pub fn require_numpy() {
    let present = std::process::Command::new("python3")
        .args(["-c", "import numpy"])
        .status()
        .is_ok_and(|s| s.success());
    assert!(
        present,
        "numpy is missing (CI=true, or it was removed since the build): .ci/run installs it \
         (python3 -m pip install numpy)"
    );
}

/// Whether process `pid` is running (a zombie is not: it has ended, only its parent has not
/// reaped it yet).
pub fn alive(pid: u32) -> bool {
    std::fs::read_to_string(format!("/proc/{pid}/stat"))
        .map(|s| {
            let state = s.rsplit(')').next().unwrap_or("").trim_start();
            !state.starts_with('Z') && !state.starts_with('X')
        })
        .unwrap_or(false)
}

/// The pid a child wrote into `file` (`echo $! > file`), waiting up to `limit` for it.
pub fn wait_for_pid(file: &Path, limit: Duration) -> u32 {
    let t = Instant::now();
    loop {
        if let Some(pid) = std::fs::read_to_string(file)
            .ok()
            .and_then(|s| s.trim().parse().ok())
        {
            return pid;
        }
        assert!(
            t.elapsed() < limit,
            "no pid in {} after {limit:?}",
            file.display()
        );
        std::thread::sleep(Duration::from_millis(20));
    }
}
