//! What the external-protocol tests share (included by `external.rs` and `external_audit.rs`
//! with `#[path]`): where the examples are, the CLI runner, and the numpy / extensive-tier gates.

#![allow(dead_code)] // each test file uses its own subset

use std::path::{Path, PathBuf};

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

/// Whether python3 has numpy. Without it a numpy test is skipped with a message, except under
/// CI (`.ci/run` installs numpy, so there a missing numpy fails the test).
pub fn has_numpy() -> bool {
    let present = std::process::Command::new("python3")
        .args(["-c", "import numpy"])
        .status()
        .is_ok_and(|s| s.success());
    if !present {
        assert!(
            std::env::var_os("CI").is_none(),
            "CI is set but numpy is missing: .ci/run installs it"
        );
        eprintln!("SKIPPED: numpy is not installed (python3 -m pip install numpy)");
    }
    present
}

/// Whether the extensive tier runs (MFH_EXTENSIVE set); if not, says why the test is skipped.
pub fn extensive(why: &str) -> bool {
    let on = std::env::var_os("MFH_EXTENSIVE").is_some();
    if !on {
        eprintln!("skipped: extensive tier ({why}), run with MFH_EXTENSIVE=1");
    }
    on
}
