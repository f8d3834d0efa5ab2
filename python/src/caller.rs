//! Calls into Python from the harness's worker threads: the GIL is taken for one call (one
//! batch) and released between calls, so checks run in parallel wherever the callables release
//! it (numpy does in its loops, Dr.Jit in its kernels).
//!
//! As for a child process of the external protocol (`harness/src/external/model.rs`), trait
//! methods cannot return errors: the first error (an exception, an answer of the wrong shape, a
//! NaN) is kept for the report's `python.call` record and every later call answers NaN at once
//! (NaN values, NaN directions), so that the audit ends quickly. Ctrl-C (seen by the main
//! thread, [`crate::audit`]) stops the calls the same way.

use pyo3::exceptions::PyKeyboardInterrupt;
use pyo3::prelude::*;
use pyo3::types::{PyByteArray, PyBytes, PyTuple};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering::Relaxed};
use std::sync::Mutex;

/// The helpers of `mfh._call` and what a run's calls have met so far.
pub struct Caller {
    values: PyObject,
    sample: PyObject,
    format_error: PyObject,
    first_error: Mutex<Option<String>>,
    stop: AtomicBool,
    interrupted: AtomicBool,
    calls: AtomicU64,
    items: AtomicU64,
}

/// One input array of a call: its numbers (row-major) and its width (1, 2 or 3 per item).
pub type Input<'a> = (&'a [f64], usize);

impl Caller {
    /// The helpers from `mfh._call` (imported once, with the GIL held).
    pub fn new(py: Python<'_>) -> PyResult<Self> {
        let module = py.import("mfh._call")?;
        Ok(Self {
            values: module.getattr("values")?.unbind(),
            sample: module.getattr("sample")?.unbind(),
            format_error: module.getattr("format_error")?.unbind(),
            first_error: Mutex::new(None),
            stop: AtomicBool::new(false),
            interrupted: AtomicBool::new(false),
            calls: AtomicU64::new(0),
            items: AtomicU64::new(0),
        })
    }

    /// Whether calls have stopped (an error, or Ctrl-C): they answer NaN at once.
    pub fn stopped(&self) -> bool {
        self.stop.load(Relaxed)
    }

    /// Stops every later call (Ctrl-C).
    pub fn interrupt(&self) {
        self.interrupted.store(true, Relaxed);
        self.stop.store(true, Relaxed);
    }

    /// Why calls have stopped, for the records of the checks not run since: None while they
    /// go on.
    pub fn stop_reason(&self) -> Option<&'static str> {
        if !self.stopped() {
            None
        } else if self.interrupted.load(Relaxed) {
            Some("not run: the audit was interrupted (Ctrl-C)")
        } else {
            Some("not run: a call of the Python functions had failed (the python.call record)")
        }
    }

    /// The first error met, if any.
    pub fn first_error(&self) -> Option<String> {
        self.first_error
            .lock()
            .unwrap_or_else(|p| p.into_inner())
            .clone()
    }

    /// Calls made and items asked so far.
    pub fn counts(&self) -> (u64, u64) {
        (self.calls.load(Relaxed), self.items.load(Relaxed))
    }

    fn record(&self, message: String) {
        self.first_error
            .lock()
            .unwrap_or_else(|p| p.into_inner())
            .get_or_insert(message);
        self.stop.store(true, Relaxed);
    }

    fn record_py(&self, py: Python<'_>, op: &str, err: PyErr) {
        if err.is_instance_of::<PyKeyboardInterrupt>(py) {
            return self.interrupt();
        }
        let text = self
            .format_error
            .call1(py, (err.value(py), err.traceback(py)))
            .and_then(|t| t.extract::<String>(py))
            .unwrap_or_else(|_| err.to_string());
        self.record(format!("{op} raised an exception:\n{text}"));
    }

    fn arrays<'py>(py: Python<'py>, inputs: &[Input<'_>]) -> Vec<Bound<'py, PyTuple>> {
        inputs
            .iter()
            .map(|&(numbers, width)| {
                let bytes = PyByteArray::new(py, bytemuck::cast_slice(numbers));
                PyTuple::new(
                    py,
                    [
                        bytes.into_any(),
                        width.into_pyobject(py).unwrap().into_any(),
                    ],
                )
                .expect("a tuple of two")
            })
            .collect()
    }

    /// `function(*inputs)` for `n` items, answering `width` numbers an item (1: values of shape
    /// (n,), 3: directions of shape (n, 3)); None after an error or an interruption (recorded).
    /// `inputs_of(i)` names item i's inputs in the error of a NaN answer.
    pub fn values(
        &self,
        op: &str,
        function: &PyObject,
        n: usize,
        width: usize,
        inputs: &[Input<'_>],
        inputs_of: &dyn Fn(usize) -> String,
    ) -> Option<Vec<f64>> {
        if self.stopped() || n == 0 {
            return (n == 0).then(Vec::new);
        }
        self.calls.fetch_add(1, Relaxed);
        self.items.fetch_add(n as u64, Relaxed);
        let got = Python::with_gil(|py| {
            let mut args = vec![
                function.clone_ref(py).into_any(),
                op.into_pyobject(py).unwrap().into_any().unbind(),
                n.into_pyobject(py).unwrap().into_any().unbind(),
                width.into_pyobject(py).unwrap().into_any().unbind(),
            ];
            args.extend(
                Self::arrays(py, inputs)
                    .into_iter()
                    .map(|t| t.into_any().unbind()),
            );
            let args = PyTuple::new(py, args).expect("a tuple");
            match self.values.call1(py, args) {
                Ok(answer) => Some(numbers(py, &answer)),
                Err(e) => {
                    self.record_py(py, op, e);
                    None
                }
            }
        })?;
        self.check(op, got, n, width, inputs_of)
    }

    /// `sample(wi, u)` for `n` items: (wo, pdf, weight) as flat arrays; None after an error.
    pub fn sample(
        &self,
        function: &PyObject,
        n: usize,
        wi: &[f64],
        u: &[f64],
        inputs_of: &dyn Fn(usize) -> String,
    ) -> Option<(Vec<f64>, Vec<f64>, Vec<f64>)> {
        if self.stopped() {
            return None;
        }
        self.calls.fetch_add(1, Relaxed);
        self.items.fetch_add(n as u64, Relaxed);
        let (wo, pdf, weight) = Python::with_gil(|py| {
            let inputs = Self::arrays(py, &[(wi, 3), (u, 3)]);
            let args = (
                function.clone_ref(py),
                n,
                inputs[0].clone(),
                inputs[1].clone(),
            );
            match self
                .sample
                .call1(py, args)
                .and_then(|t| t.extract::<(PyObject, PyObject, PyObject)>(py))
            {
                Ok((a, b, c)) => Some((numbers(py, &a), numbers(py, &b), numbers(py, &c))),
                Err(e) => {
                    self.record_py(py, "sample", e);
                    None
                }
            }
        })?;
        let wo = self.check("sample (wo)", wo, n, 3, inputs_of)?;
        let pdf = self.check("sample (pdf)", pdf, n, 1, inputs_of)?;
        let weight = self.check("sample (weight)", weight, n, 1, inputs_of)?;
        Some((wo, pdf, weight))
    }

    /// `width` numbers for each of the `n` items (`mfh._call` checked the shape; this guards
    /// the bytes), and no NaN: NaN is refused as an answer, as the external protocol refuses
    /// it; the error names the item and its inputs.
    fn check(
        &self,
        op: &str,
        got: Vec<f64>,
        n: usize,
        width: usize,
        inputs_of: &dyn Fn(usize) -> String,
    ) -> Option<Vec<f64>> {
        if got.len() != n * width {
            self.record(format!(
                "{op} answered {} numbers for {n} items of {width}",
                got.len()
            ));
            return None;
        }
        match got.iter().position(|v| v.is_nan()) {
            None => Some(got),
            Some(k) => {
                self.record(format!(
                    "{op} returned NaN for item {} of a batch of {} ({}): answer 0 where the \
                     function is 0, never NaN",
                    k / width,
                    got.len() / width,
                    inputs_of(k / width)
                ));
                None
            }
        }
    }
}

/// The f64 numbers of the bytes `mfh._call` answered (native byte order, as numpy's
/// `tobytes()` writes them; the helper checked the shape).
fn numbers(py: Python<'_>, answer: &PyObject) -> Vec<f64> {
    let bytes = answer
        .downcast_bound::<PyBytes>(py)
        .map(|b| b.as_bytes())
        .unwrap_or(&[]);
    bytes
        .chunks_exact(8)
        .map(|c| f64::from_ne_bytes(c.try_into().expect("8 bytes")))
        .collect()
}

/// A direction for error messages.
pub fn show(v: [f64; 3]) -> String {
    format!("[{}, {}, {}]", v[0], v[1], v[2])
}
