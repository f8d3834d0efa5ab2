//! The `mfh` command line: parse, call the library, map errors to exit codes.

fn main() {
    let code = mfh_harness::cli::run(
        std::env::args_os(),
        &mut std::io::stdin().lock(),
        &mut std::io::stdout().lock(),
        &mut std::io::stderr().lock(),
    );
    std::process::exit(code);
}
