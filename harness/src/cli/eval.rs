//! `mfh eval`: JSON-lines queries in, one answer line per query out (the library's
//! [`crate::eval::eval_stream`]); exit 2 if any line failed.

use super::{EXIT_BAD_INPUT, EXIT_PASS};
use clap::Args;
use std::io::{BufRead, BufReader, Write};
use std::path::PathBuf;

/// The options of `mfh eval`.
#[derive(Debug, Args)]
pub struct EvalArgs {
    /// Read queries from this file instead of standard input.
    #[arg(long)]
    pub input: Option<PathBuf>,
}

/// Runs `mfh eval`; returns the exit status (0 when every query is answered, else 2).
pub fn run(
    args: EvalArgs,
    stdin: &mut dyn BufRead,
    stdout: &mut dyn Write,
    stderr: &mut dyn Write,
) -> i32 {
    let result = match args.input {
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
        Ok(summary) if summary.failed == 0 => EXIT_PASS,
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
