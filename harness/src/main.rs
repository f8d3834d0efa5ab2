//! The `mfh` command line: parse, call the library, map errors to exit codes.

fn main() {
    // Standard output and error are passed unlocked: audit checks run on worker threads, and
    // a panic message or `MFH_TRACE` line printed there must not wait on a lock main holds.
    let code = mfh_harness::cli::run(
        std::env::args_os(),
        &mut std::io::stdin().lock(),
        &mut std::io::stdout(),
        &mut std::io::stderr(),
    );
    std::process::exit(code);
}
