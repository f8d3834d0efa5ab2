//! Printed forms of the source documents that reference/ERRATA.md records as wrong or unstable,
//! beside their corrected forms (`*_printed` / `*_corrected`), one file per document. They are
//! transcriptions, not routes: the models never call them. The reference's unit tests and the
//! harness's `errata.printed_formula` demonstrations both evaluate these functions, so each
//! printed formula is written once.

pub mod document000;
pub mod document001;
pub mod document002;
pub mod document003;
pub mod document004;
