//! The `mfh` command line: parse, call the library, map errors to exit codes.

fn main() {
    // SIGTERM / SIGINT / SIGHUP end the external children's process groups before mfh exits.
    if let Err(e) = mfh_harness::cli::signals::install() {
        eprintln!("mfh: cannot watch for SIGTERM / SIGINT ({e}): a signal may leave children");
    }
    // An output closed at startup is lost without a write error: refuse, as for /dev/full.
    if let Some(reason) = mfh_harness::cli::closed_stdout::closed_stdout() {
        eprintln!("mfh: {reason}");
        mfh_harness::cli::signals::exit(mfh_harness::cli::EXIT_BAD_INPUT);
    }
    // Standard output and error are passed unlocked: audit checks run on worker threads, and
    // a panic message or `MFH_TRACE` line printed there must not wait on a lock main holds.
    let code = mfh_harness::cli::run(
        std::env::args_os(),
        &mut std::io::stdin().lock(),
        &mut std::io::stdout(),
        &mut std::io::stderr(),
    );
    mfh_harness::cli::signals::exit(code);
}
