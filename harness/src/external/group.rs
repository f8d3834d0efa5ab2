//! A child's process group: the child is started as the leader of a group of its own, so that
//! ending the group also ends whatever it started (`sh -c`'s commands, their children). Ending
//! it is SIGTERM to the group, a short grace ([`GRACE`]) for it to go, then SIGKILL; the leader
//! is reaped.
//!
//! The live groups are listed so that a signal handler can end them all before mfh exits
//! ([`end_all`]); this module installs no handler itself (`mfh`'s is `cli::signals`).

use std::process::{Child, Command};
use std::sync::Mutex;
use std::thread;
use std::time::{Duration, Instant};

/// How long a group is given between SIGTERM and SIGKILL.
pub const GRACE: Duration = Duration::from_millis(500);

/// The process groups (their leaders' pids) of the children alive now.
static LIVE: Mutex<Vec<u32>> = Mutex::new(Vec::new());

/// Makes the child that `command` starts the leader of a new process group.
pub fn own_group(command: &mut Command) {
    #[cfg(unix)]
    std::os::unix::process::CommandExt::process_group(command, 0);
    #[cfg(not(unix))]
    let _ = command;
}

/// The process group of a child started with [`own_group`], listed while it lives.
#[derive(Debug)]
pub struct Group {
    leader: u32,
    ended: bool,
}

impl Group {
    /// Lists the group of `child` (started with [`own_group`]) among the live ones.
    pub fn of(child: &Child) -> Self {
        let leader = child.id();
        if let Ok(mut live) = LIVE.lock() {
            live.push(leader);
        }
        Self {
            leader,
            ended: false,
        }
    }

    /// Ends the group (SIGTERM, [`GRACE`], SIGKILL) and reaps `child`, its leader. Later calls
    /// do nothing.
    pub fn end(&mut self, child: &mut Child) {
        if self.ended {
            return;
        }
        self.ended = true;
        #[cfg(unix)]
        {
            let group = unix::pid(self.leader);
            unix::signal(group, rustix::process::Signal::TERM);
            let deadline = Instant::now() + GRACE;
            loop {
                // The leader is reaped as soon as it exits: as a zombie it would keep the
                // group in existence.
                let _ = child.try_wait();
                if !unix::exists(group) || Instant::now() >= deadline {
                    break;
                }
                thread::sleep(Duration::from_millis(5));
            }
            if unix::exists(group) {
                unix::signal(group, rustix::process::Signal::KILL);
            }
        }
        let _ = child.kill();
        let _ = child.wait();
        unlist(self.leader);
    }
}

impl Drop for Group {
    fn drop(&mut self) {
        unlist(self.leader);
    }
}

fn unlist(leader: u32) {
    if let Ok(mut live) = LIVE.lock() {
        live.retain(|&l| l != leader);
    }
}

/// Ends every live group (SIGTERM to all, up to [`GRACE`] for them to go, SIGKILL to the rest),
/// for a signal handler about to exit mfh. The leaders are reaped here (their `Child` is
/// elsewhere, and mfh is exiting).
pub fn end_all() {
    let leaders = LIVE.lock().map(|l| l.clone()).unwrap_or_default();
    #[cfg(unix)]
    {
        let groups: Vec<_> = leaders.iter().map(|&l| unix::pid(l)).collect();
        for &g in groups.iter().flatten() {
            unix::signal(Some(g), rustix::process::Signal::TERM);
        }
        let deadline = Instant::now() + GRACE;
        loop {
            for &g in groups.iter().flatten() {
                let _ = rustix::process::waitpid(Some(g), rustix::process::WaitOptions::NOHANG);
            }
            if !groups.iter().any(|&g| unix::exists(g)) || Instant::now() >= deadline {
                break;
            }
            thread::sleep(Duration::from_millis(5));
        }
        for &g in groups.iter().flatten().filter(|&&g| unix::exists(Some(g))) {
            unix::signal(Some(g), rustix::process::Signal::KILL);
            let _ = rustix::process::waitpid(Some(g), rustix::process::WaitOptions::NOHANG);
        }
    }
    #[cfg(not(unix))]
    let _ = leaders;
}

#[cfg(unix)]
mod unix {
    use rustix::process::{kill_process_group, test_kill_process_group, Pid, Signal};

    /// The group whose leader is `leader` (None for a pid that cannot be one).
    pub fn pid(leader: u32) -> Option<Pid> {
        i32::try_from(leader).ok().and_then(Pid::from_raw)
    }

    /// Sends `signal` to the group (a group already gone is not an error).
    pub fn signal(group: Option<Pid>, signal: Signal) {
        if let Some(g) = group {
            let _ = kill_process_group(g, signal);
        }
    }

    /// Whether any process (a zombie included) is still in the group.
    pub fn exists(group: Option<Pid>) -> bool {
        group.is_some_and(|g| test_kill_process_group(g).is_ok())
    }
}
