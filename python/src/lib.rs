//! `mfh._mfh`: the harness in-process for Python. A model given as Python callables over numpy
//! arrays is one more implementation of the capability traits ([`model`]) and audited by the
//! same planner and runner as a Rust model (`Audit::of`, `Audit::of_bsdf`, [`audit`]); the
//! report is the same `AuditReport` ([`report`]). The Python side (`python/mfh/`) validates the
//! arguments and documents the API; this crate does no numpy itself: arrays travel as the bytes
//! of native f64 (`mfh/_call.py` builds and reads the numpy arrays), so that the abi3 build
//! needs no numpy C API.

mod audit;
mod caller;
mod model;
mod report;

use pyo3::prelude::*;

/// The extension module.
#[pymodule]
fn _mfh(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(audit::audit_bsdf, m)?)?;
    m.add_function(wrap_pyfunction!(audit::audit_ndf, m)?)?;
    m.add_class::<report::Report>()?;
    m.add("DEFAULT_SEED", mfh_harness::run::DEFAULT_SEED)?;
    m.add("MFH_VERSION", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
