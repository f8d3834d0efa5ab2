//! A signal to `mfh audit-external` ends its child's whole process group before mfh exits with
//! the conventional status (128 + the signal): `timeout 300 mfh audit-external …` (SIGTERM) or
//! Ctrl-C (SIGINT) must not leave the child, nor what it started, running.

#![cfg(unix)]

#[path = "external/common.rs"]
mod common;

use common::{alive, wait_for_pid};
use rustix::process::{kill_process, Pid, Signal};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

#[test]
fn a_signal_to_mfh_ends_its_childs_process_group() {
    for (signal, name, status) in [(Signal::TERM, "TERM", 143), (Signal::INT, "INT", 130)] {
        let dir = std::env::temp_dir().join(format!("mfh-signal-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        let pid_file = dir.join("grandchild.pid");
        // The child starts a grandchild in the background, writes its pid, and never answers
        // `describe` (mfh waits up to the 120 s timeout).
        let cmd = format!("sleep 1000 & echo $! > '{}'; wait", pid_file.display());
        let mut mfh = Command::new(env!("CARGO_BIN_EXE_mfh"))
            .args(["audit-external", "--cmd", &cmd, "--timeout", "120", "--out"])
            .arg(dir.join("out"))
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        let grandchild = wait_for_pid(&pid_file, Duration::from_secs(20));
        assert!(alive(grandchild), "SIG{name}: the grandchild did not start");
        let mfh_pid = Pid::from_raw(mfh.id() as i32).unwrap();
        kill_process(mfh_pid, signal).unwrap();
        let t = Instant::now();
        let exit = loop {
            if let Some(exit) = mfh.try_wait().unwrap() {
                break Some(exit);
            }
            if t.elapsed() > Duration::from_secs(10) {
                let _ = mfh.kill();
                let _ = mfh.wait();
                break None;
            }
            std::thread::sleep(Duration::from_millis(20));
        };
        while alive(grandchild) && t.elapsed() < Duration::from_secs(10) {
            std::thread::sleep(Duration::from_millis(20));
        }
        let survived = alive(grandchild);
        if survived {
            let _ = kill_process(Pid::from_raw(grandchild as i32).unwrap(), Signal::KILL);
        }
        let _ = std::fs::remove_dir_all(&dir);
        let exit = exit.unwrap_or_else(|| panic!("SIG{name}: mfh did not exit within 10 s"));
        assert_eq!(exit.code(), Some(status), "SIG{name}: {exit}");
        assert!(
            !survived,
            "SIG{name}: the grandchild {grandchild} outlived mfh"
        );
        eprintln!("SIG{name}: mfh exited {status}, its child's group ended");
    }
}
