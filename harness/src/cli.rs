//! The clap command line of `mfh`, callable in-process (the tests crate drives it this way).
//! Exit codes: 0 success, 1 failed checks, 2 bad input.

use clap::{Parser, Subcommand};
use std::ffi::OsString;
use std::io::{BufRead, BufReader, Write};
use std::path::PathBuf;

/// Exit status for bad input (unreadable files, malformed queries, invalid parameters).
pub const EXIT_BAD_INPUT: i32 = 2;

/// mfh — verification and conformance harness for microfacet BSDF mathematics.
#[derive(Debug, Parser)]
#[command(name = "mfh", version, about)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Evaluate closed forms: JSON-lines queries in, one JSON line per query out, in order.
    ///
    /// Each query is an object such as
    /// {"model":{"family":"std","gamma":2.5,"alpha":0.3},"quantity":"lambda","theta":1.2}.
    /// Exit status 2 if any line failed (its answer is an error line; the others are answered).
    Eval {
        /// Read queries from this file instead of standard input.
        #[arg(long)]
        input: Option<PathBuf>,
    },
}

/// Runs the command line `args` (including the program name) with the given streams and
/// returns the exit status.
pub fn run<I, T>(
    args: I,
    stdin: &mut dyn BufRead,
    stdout: &mut dyn Write,
    stderr: &mut dyn Write,
) -> i32
where
    I: IntoIterator<Item = T>,
    T: Into<OsString> + Clone,
{
    let cli = match Cli::try_parse_from(args) {
        Ok(cli) => cli,
        Err(e) => {
            let code = if e.use_stderr() { EXIT_BAD_INPUT } else { 0 };
            let text = e.render().to_string();
            let _ = if e.use_stderr() {
                stderr.write_all(text.as_bytes())
            } else {
                stdout.write_all(text.as_bytes())
            };
            return code;
        }
    };
    match cli.command {
        Command::Eval { input } => {
            let result = match input {
                Some(path) => match std::fs::File::open(&path) {
                    Ok(f) => crate::eval::eval_stream(&mut BufReader::new(f), stdout),
                    Err(e) => {
                        let _ = writeln!(stderr, "mfh eval: cannot read {}: {e}", path.display());
                        return EXIT_BAD_INPUT;
                    }
                },
                None => crate::eval::eval_stream(stdin, stdout),
            };
            match result {
                Ok(summary) if summary.failed == 0 => 0,
                Ok(summary) => {
                    let _ = writeln!(
                        stderr,
                        "mfh eval: {} of {} queries failed",
                        summary.failed, summary.answered
                    );
                    EXIT_BAD_INPUT
                }
                Err(e) => {
                    let _ = writeln!(stderr, "mfh eval: {e}");
                    EXIT_BAD_INPUT
                }
            }
        }
    }
}
