//! Whether mfh was started with its standard output closed (`mfh audit >&-`): every write then
//! goes nowhere, yet succeeds, so no write error tells the command that its output is lost.
//!
//! Rust's runtime, before `main`, replaces a closed standard descriptor by `/dev/null` opened
//! for reading *and* writing (`O_RDWR`, so that any of 0, 1, 2 works); a shell's `> /dev/null`,
//! systemd's `StandardOutput=null` and `std::process::Stdio::null()` open it write-only. A
//! standard output that is `/dev/null` open read-write is therefore one that was closed: the
//! command refuses to run (exit 2, as for any output that cannot be written), where
//! `> /dev/null`, a choice to discard the output, still runs. The one shape this mistakes for a
//! closed output is `1<> /dev/null`, which nobody writes to discard output. No crate answers
//! this (it is a property of Rust's own startup), so it is written here with rustix's safe
//! `fstat` and `fcntl(F_GETFL)`.

/// The reason standard output is lost, when it was closed at startup; None otherwise (and on
/// platforms without file descriptors).
pub fn closed_stdout() -> Option<&'static str> {
    #[cfg(unix)]
    {
        use rustix::fs::{fcntl_getfl, fstat, stat, FileType, OFlags};
        use std::os::fd::AsFd;
        let out = std::io::stdout();
        let fd = out.as_fd();
        let st = fstat(fd).ok()?;
        let null = stat("/dev/null").ok()?;
        let is_null = FileType::from_raw_mode(st.st_mode) == FileType::CharacterDevice
            && st.st_rdev == null.st_rdev;
        let read_write = fcntl_getfl(fd).ok()? & OFlags::RWMODE == OFlags::RDWR;
        (is_null && read_write).then_some(
            "standard output was closed when mfh started (Rust's runtime put /dev/null, open \
             read-write, in its place): the output would be lost; redirect it (`> /dev/null` \
             to discard it)",
        )
    }
    #[cfg(not(unix))]
    {
        None
    }
}
