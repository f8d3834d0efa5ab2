//! mfh-tests: end-to-end tests of mfh (in `tests/`): the CLI driven in-process, the eval
//! contract, value-stability vectors. This library is empty on purpose.
