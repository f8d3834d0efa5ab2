//! The test tiers and tool gates as cfg flags (`mfh_extensive`, `has_<tool>`): the rules are
//! `mfh-test-tiers`'s (tests/tiers/src/lib.rs), the same for every crate.

use mfh_test_tiers::Tool;

fn main() {
    mfh_test_tiers::emit(&[Tool::Numpy, Tool::Script, Tool::Gxx]);
}
