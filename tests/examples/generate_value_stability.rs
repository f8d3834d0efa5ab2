//! Writes `tests/data/value_stability.jsonl`: the value-stability vectors of mfh, i.e. the
//! answers `mfh eval` gives today to the query set of `mfh_tests::value_stability::queries`.
//!
//! Run once, after a deliberate change of a closed form (the test `value_stability` then
//! fails and says which values moved), and review the diff:
//!
//! ```sh
//! cargo run -p mfh-tests --example generate_value_stability
//! ```

use mfh_tests::value_stability::{data_path, header, queries, record};
use std::io::Write;

fn main() -> std::io::Result<()> {
    let queries = queries();
    let path = data_path();
    let mut out = std::io::BufWriter::new(std::fs::File::create(&path)?);
    writeln!(out, "{}", header(queries.len()))?;
    for query in &queries {
        writeln!(out, "{}", record(query))?;
    }
    out.flush()?;
    println!("wrote {} vectors to {}", queries.len(), path.display());
    Ok(())
}
