//! The serde helpers the record types need to read back what they write (`report.json`,
//! `mfh merge`, `--baseline`): `null` for non-finite numbers, and `&'static str` fields read
//! through a process-wide interner.
//!
//! - Non-finite numbers: serde_json writes NaN and ±∞ as `null`; [`nullable_f64`] reads `null`
//!   back as NaN, which serializes to `null` again, so a report read back and written again is
//!   byte-identical (the sign of an infinite error is lost; both are "not finite").
//! - `&'static str` fields (tolerance names and reasons, the oracle's uncertainty kind, the
//!   mfh version) are built from constants by the checks; [`interned`] maps a read string to a
//!   `&'static str` through a process-wide interner, so each distinct string is allocated once
//!   (bounded by the distinct strings of the reports read, a few hundred), instead of changing
//!   the field types every check constructs.

use serde::{Deserialize, Deserializer};
use std::collections::BTreeSet;
use std::sync::{Mutex, OnceLock};

/// `&'static str` under another name: serde's derive borrows every field spelled `&str` from
/// the input (and so would demand `'de: 'static`) even when `deserialize_with` is set; the
/// alias is the same type, so the checks that build records are unaffected.
pub type StaticStr = &'static str;

/// Deserializes an `f64` written by serde_json, where `null` stands for a non-finite value
/// (read back as NaN).
pub fn nullable_f64<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    Ok(Option::<f64>::deserialize(d)?.unwrap_or(f64::NAN))
}

/// Deserializes a list of `f64` written by serde_json, each `null` read back as NaN (as
/// [`nullable_f64`]): the tables and curves of a record's data, read back from `report.jsonl`.
pub fn nullable_f64_vec<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<f64>, D::Error> {
    Ok(Vec::<Option<f64>>::deserialize(d)?
        .into_iter()
        .map(|x| x.unwrap_or(f64::NAN))
        .collect())
}

/// Deserializes a string into a `&'static str` through [`intern`].
pub fn interned<'de, D: Deserializer<'de>>(d: D) -> Result<&'static str, D::Error> {
    Ok(intern(&String::deserialize(d)?))
}

/// The `&'static str` equal to `text`: allocated (and kept for the life of the process) the
/// first time `text` is seen, shared afterwards.
pub fn intern(text: &str) -> &'static str {
    static TABLE: OnceLock<Mutex<BTreeSet<&'static str>>> = OnceLock::new();
    let mut table = TABLE
        .get_or_init(|| Mutex::new(BTreeSet::new()))
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner());
    if let Some(s) = table.get(text) {
        return s;
    }
    let s: &'static str = Box::leak(text.to_owned().into_boxed_str());
    table.insert(s);
    s
}
