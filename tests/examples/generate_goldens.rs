//! Writes `reference/golden/lambda_dd.json`: certified double-double values of Smith Λ and D
//! over the grid of `mfh_tests::goldens` (see its provenance block).
//!
//! Run after a change of the grid or of `mfh_harness::oracle::precise`, and review the diff
//! (the test `goldens` fails until the file is current):
//!
//! ```sh
//! cargo run -p mfh-tests --release --example generate_goldens
//! ```

use mfh_tests::goldens::{golden_file, golden_path};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let file = golden_file()?;
    let path = golden_path();
    let mut text = serde_json::to_string_pretty(&file)?;
    text.push('\n');
    std::fs::write(&path, text)?;
    let count = |k: &str| file[k].as_array().map_or(0, Vec::len);
    println!(
        "wrote {} Λ and {} D values to {}",
        count("lambda"),
        count("d"),
        path.display()
    );
    Ok(())
}
