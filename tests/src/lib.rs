//! mfh-tests: end-to-end tests of mfh (in `tests/`): the CLI driven in-process, the eval
//! contract, value-stability vectors. The library holds only what the tests and the
//! value-stability and golden generators (`examples/`) share.

pub mod goldens;
pub mod value_stability;
