//! The workspace's test tiers and tool gates, as cfg flags that each crate's build script sets
//! (`reference/build.rs`, `harness/build.rs`, `tests/build.rs` call [`emit`]). A test that the
//! tier or a missing tool leaves out is then *ignored* — `cargo test` and nextest list it as
//! ignored / skipped with the reason — instead of returning early and counting as a pass, and
//! every crate reads the same two rules:
//!
//! - `mfh_extensive`: the extensive tier is on if and only if `MFH_EXTENSIVE=1` ([`extensive`];
//!   unset, empty, `0` or anything else is off);
//! - `has_<tool>` ([`Tool`]): the tool answers on this machine, or `CI=true` ([`ci`]): under CI
//!   a missing tool must fail its tests, not skip them, so there they run and say what is
//!   missing.
//!
//! A gated test carries, for example,
//! `#[cfg_attr(not(mfh_extensive), ignore = "extensive tier: set MFH_EXTENSIVE=1")]`; code that
//! only scales with the tier (more fuzz cases, more sweep points) reads `cfg!(mfh_extensive)`.
//! The flags are decided when the crate is built; cargo reruns the build script (and rebuilds
//! the crate) when `MFH_EXTENSIVE`, `CI` or (for the tool gates) `PATH` changes, and when a
//! tool is installed or removed: the build script watches the places a tool appears in
//! ([`Tool::watched`]: the directories of `PATH`, and python3's site-packages for numpy), so
//! a test compiled as "ignored, no chromium" runs after `apt-get install chromium` without a
//! `cargo clean`. (`cargo test -- --include-ignored` runs the ignored tests anyway.)

use std::process::{Command, Stdio};

/// The variable that turns the extensive tier on.
pub const EXTENSIVE_VAR: &str = "MFH_EXTENSIVE";

/// The cfg flag of the extensive tier.
pub const EXTENSIVE_CFG: &str = "mfh_extensive";

/// The extensive tier's rule: on if and only if the variable's value is exactly `1`.
pub fn extensive(value: Option<&str>) -> bool {
    value == Some("1")
}

/// Whether this is a CI run (`CI=true`, as CI services set it): a missing tool then fails its
/// tests instead of skipping them.
pub fn ci(value: Option<&str>) -> bool {
    value == Some("true")
}

/// A program some tests need and a developer machine may lack.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Tool {
    /// Headless Chromium (`chromium`, `chromium-browser` or `google-chrome`), for the HTML
    /// report's rendering test.
    Chromium,
    /// numpy for python3, for the numpy example of the external protocol.
    Numpy,
    /// util-linux `script` (a pseudo-terminal), for the progress-bar test.
    Script,
    /// The GNU C++ compiler `g++`, for the C++ example of the external protocol.
    Gxx,
}

impl Tool {
    /// Every tool, so that each crate declares every flag (`rustc-check-cfg`).
    pub const ALL: [Tool; 4] = [Tool::Chromium, Tool::Numpy, Tool::Script, Tool::Gxx];

    /// The cfg flag set where the tool is present (or under CI).
    pub fn cfg(self) -> &'static str {
        match self {
            Tool::Chromium => "has_chromium",
            Tool::Numpy => "has_numpy",
            Tool::Script => "has_script",
            Tool::Gxx => "has_gxx",
        }
    }

    /// Whether the tool answers on this machine.
    pub fn present(self) -> bool {
        let runs = |program: &str, args: &[&str]| {
            Command::new(program)
                .args(args)
                .stdin(Stdio::null())
                .stdout(Stdio::null())
                .stderr(Stdio::null())
                .status()
                .is_ok_and(|s| s.success())
        };
        match self {
            Tool::Chromium => ["chromium", "chromium-browser", "google-chrome"]
                .iter()
                .any(|name| runs(name, &["--version"])),
            Tool::Numpy => runs("python3", &["-c", "import numpy"]),
            Tool::Script => runs("script", &["--version"]),
            Tool::Gxx => runs("g++", &["--version"]),
        }
    }
}

impl Tool {
    /// The directories whose contents change when the tool is installed or removed, for
    /// `cargo::rerun-if-changed`: every existing directory of `PATH` (where `apt-get` and
    /// `pip` put programs), and for numpy also python3's site-packages directories. Cargo
    /// compares the newest modification time inside a watched directory, the directory's own
    /// included, which moves when an entry is added or removed. Only existing directories are
    /// listed: a missing path would make cargo rerun the build script, and rebuild the crate,
    /// on every invocation.
    pub fn watched(self) -> Vec<std::path::PathBuf> {
        let mut dirs: Vec<std::path::PathBuf> = std::env::var_os("PATH")
            .map(|p| std::env::split_paths(&p).collect())
            .unwrap_or_default();
        if self == Tool::Numpy {
            dirs.extend(site_packages());
        }
        let mut seen = Vec::new();
        for dir in dirs {
            if dir.is_absolute() && dir.is_dir() && !seen.contains(&dir) {
                seen.push(dir);
            }
        }
        seen
    }
}

/// python3's site-packages directories (system and user), as python3 on `PATH` reports them;
/// none where python3 does not run.
fn site_packages() -> Vec<std::path::PathBuf> {
    let script =
        "import site\nfor d in site.getsitepackages() + [site.getusersitepackages()]: print(d)";
    Command::new("python3")
        .args(["-c", script])
        .stdin(Stdio::null())
        .stderr(Stdio::null())
        .output()
        .ok()
        .filter(|out| out.status.success())
        .map(|out| {
            String::from_utf8_lossy(&out.stdout)
                .lines()
                .map(std::path::PathBuf::from)
                .collect()
        })
        .unwrap_or_default()
}

/// What a build script prints: the flags' declarations, `mfh_extensive` by [`extensive`],
/// `has_<tool>` for each of `tools` that is present or wanted by [`ci`], and the directories
/// to watch for each tool's arrival or removal ([`Tool::watched`]).
pub fn emit(tools: &[Tool]) {
    let var = |name: &str| std::env::var(name).ok();
    println!("cargo::rustc-check-cfg=cfg({EXTENSIVE_CFG})");
    for tool in Tool::ALL {
        println!("cargo::rustc-check-cfg=cfg({})", tool.cfg());
    }
    println!("cargo::rerun-if-env-changed={EXTENSIVE_VAR}");
    if extensive(var(EXTENSIVE_VAR).as_deref()) {
        println!("cargo::rustc-cfg={EXTENSIVE_CFG}");
    }
    if tools.is_empty() {
        return;
    }
    println!("cargo::rerun-if-env-changed=CI");
    println!("cargo::rerun-if-env-changed=PATH");
    let mut watched = Vec::new();
    for &tool in tools {
        for dir in tool.watched() {
            if !watched.contains(&dir) {
                println!("cargo::rerun-if-changed={}", dir.display());
                watched.push(dir);
            }
        }
    }
    let ci = ci(var("CI").as_deref());
    for &tool in tools {
        if ci || tool.present() {
            println!("cargo::rustc-cfg={}", tool.cfg());
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_tier_is_on_for_exactly_one() {
        assert!(extensive(Some("1")));
        for off in [
            None,
            Some(""),
            Some("0"),
            Some("true"),
            Some("yes"),
            Some(" 1"),
        ] {
            assert!(!extensive(off), "{off:?}");
        }
        assert!(ci(Some("true")));
        assert!(!ci(None) && !ci(Some("false")));
    }

    #[test]
    fn watched_directories_exist_and_include_path() {
        for tool in Tool::ALL {
            let dirs = tool.watched();
            for dir in &dirs {
                assert!(
                    dir.is_absolute() && dir.is_dir(),
                    "{tool:?}: {}",
                    dir.display()
                );
            }
            // The directory that holds `sh` is on PATH on every machine the tests run on.
            let sh = std::env::split_paths(&std::env::var_os("PATH").unwrap())
                .find(|d| d.join("sh").is_file());
            if let Some(sh) = sh {
                assert!(
                    dirs.contains(&sh),
                    "{tool:?} does not watch {}",
                    sh.display()
                );
            }
        }
    }
}
