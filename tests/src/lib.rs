//! mfh-tests: end-to-end tests of mfh (in `tests/`): the CLI driven in-process, the eval
//! contract, value-stability vectors. The library holds only what the tests and the
//! value-stability generator (`examples/generate_value_stability.rs`) share.

pub mod value_stability;
