//! An external process as one more implementation of the capability traits: every trait
//! method is a request to the child. Batches go through the inherent `*_batch` methods (split
//! into requests of at most [`MAX_BATCH`] items); a scalar trait call is one round trip.
//!
//! The BSDF capability (`bsdf_eval`, `bsdf_pdf`, `bsdf_sample`) is in `bsdf.rs` beside this
//! file.
//!
//! Trait methods cannot return errors, so the first protocol error is recorded (see
//! [`ExternalModel::first_error`]), the child is killed, and every later call answers NaN
//! (values) or a NaN direction (samples) at once: the audit's checks fail quickly, and the
//! runner appends an `external.protocol` error record with the message.
//!
//! A NaN in an answer is not a protocol error: the child may compute a NaN as a Rust model
//! may, and the checks judge it the same way (their records fail) while the audit goes on.
//! Each array that held one is listed by [`ExternalModel::nan_answers`] (the request, the
//! array, how many items, the first item and its input), from which the runner writes failing
//! `external.nan` records.

use super::process::{ExternalError, Session};
use super::protocol::{Answer, Description, Item, Request, Wire};
use mfh_reference::model::{visible_domain, NormalSampler, Smith, VisibleNormalSampler};
use mfh_reference::{Masking, Ndf, Vec3};
use std::sync::Mutex;
use std::time::Duration;

/// The most items sent in one request.
pub const MAX_BATCH: usize = 65_536;

const NAN3: Vec3 = [f64::NAN; 3];

/// The NaN items of one array of one kind of request (`op`) over the session.
#[derive(Debug, Clone, PartialEq)]
pub struct NanAnswers {
    /// The request (`d`, `bsdf_sample`, …).
    pub op: &'static str,
    /// The answer's array (`values`, `m`, `wo`, `pdf`, `weight`).
    pub field: String,
    /// How many items of that array were NaN, over every such request.
    pub count: u64,
    /// The first of them: the request, its item index and the item's input.
    pub first: ExternalError,
}

/// A model implemented by a child process speaking the external protocol.
pub struct ExternalModel {
    session: Mutex<Session>,
    description: Description,
    version: u32,
    first_error: Mutex<Option<ExternalError>>,
    nans: Mutex<Vec<NanAnswers>>,
}

impl ExternalModel {
    /// Starts `command` (with `sh -c`), asks for its description and validates it.
    pub fn start(command: &str, timeout: Duration) -> Result<Self, ExternalError> {
        let mut session = Session::start(command, timeout)?;
        let description = session.describe()?;
        if let Err(e) = description.validate() {
            session.fail();
            return Err(ExternalError::Describe(e));
        }
        Ok(Self {
            version: session.version(),
            session: Mutex::new(session),
            description,
            first_error: Mutex::new(None),
            nans: Mutex::new(Vec::new()),
        })
    }

    /// The protocol version spoken (the child's choice at `describe`).
    pub fn version(&self) -> u32 {
        self.version
    }

    /// What the child said of itself.
    pub fn description(&self) -> &Description {
        &self.description
    }

    /// The first protocol error of the session, if any.
    pub fn first_error(&self) -> Option<ExternalError> {
        self.first_error.lock().ok().and_then(|e| e.clone())
    }

    /// The arrays that held NaN answers, in the order first seen (each with its count and
    /// first item).
    pub fn nan_answers(&self) -> Vec<NanAnswers> {
        self.nans.lock().map(|n| n.clone()).unwrap_or_default()
    }

    /// Notes the NaN items of `field` (`width` numbers an item) among `numbers`, except the
    /// items `ignored` says mean nothing (a failed sample's wo and weight).
    pub(super) fn note_nans(
        &self,
        request: &Request<'_>,
        inputs: &dyn Fn(usize) -> String,
        field: &str,
        (numbers, width): (&[f64], usize),
        ignored: &dyn Fn(usize) -> bool,
    ) {
        let mut items = numbers
            .chunks_exact(width)
            .enumerate()
            .filter(|(i, c)| c.iter().any(|v| v.is_nan()) && !ignored(*i))
            .map(|(i, _)| i);
        let Some(index) = items.next() else {
            return;
        };
        let count = 1 + items.count() as u64;
        let Ok(mut nans) = self.nans.lock() else {
            return;
        };
        match nans
            .iter_mut()
            .find(|n| n.op == request.op() && n.field == field)
        {
            Some(n) => n.count += count,
            None => nans.push(NanAnswers {
                op: request.op(),
                field: field.to_string(),
                count,
                first: ExternalError::NotANumber {
                    request: format!("{} ({} items)", request.op(), request.len()),
                    field: field.to_string(),
                    index,
                    input: inputs(index),
                },
            }),
        }
    }

    /// Asks the child to exit and reaps it.
    pub fn shutdown(&self) {
        if let Ok(mut s) = self.session.lock() {
            s.shutdown();
        }
    }

    pub(super) fn call(&self, request: &Request<'_>) -> Result<Answer, ExternalError> {
        // A check past its wall-clock budget stops here, before the session's lock is taken
        // and once it has waited its turn for it (the lock released first).
        crate::check::budget::checkpoint();
        let mut session = self
            .session
            .lock()
            .unwrap_or_else(|poisoned| poisoned.into_inner());
        if crate::check::budget::passed() {
            drop(session);
            crate::check::budget::stop();
        }
        let result = session.call(request);
        if let Err(e) = &result {
            if let Ok(mut first) = self.first_error.lock() {
                first.get_or_insert_with(|| e.clone());
            }
        }
        result
    }

    /// Sends one request for scalar values and checks the answer: one finite-or-infinite
    /// number per item, no NaN.
    pub(super) fn values(
        &self,
        request: &Request<'_>,
        inputs: &dyn Fn(usize) -> String,
    ) -> Result<Vec<f64>, ExternalError> {
        let answer = self.call(request)?;
        self.items(request, inputs, "values", answer.values)
    }

    /// Sends one sampling request and checks the answer: one direction per item, no NaN.
    fn directions(
        &self,
        request: &Request<'_>,
        inputs: &dyn Fn(usize) -> String,
    ) -> Result<Vec<Vec3>, ExternalError> {
        let answer = self.call(request)?;
        let numbers = self.items(request, inputs, "m", answer.m)?;
        Ok(numbers
            .chunks_exact(3)
            .map(|c| [c[0], c[1], c[2]])
            .collect())
    }

    /// Checks an answer's array `field` against `request`: present, decodable in the session's
    /// protocol version, one item per item asked. Its numbers, row-major, NaN included (noted
    /// by the caller with [`ExternalModel::note_nans`]; [`ExternalModel::items`] does).
    pub(super) fn items_raw<T: Item>(
        &self,
        request: &Request<'_>,
        field: &str,
        wire: Option<Wire<T>>,
    ) -> Result<Vec<f64>, ExternalError> {
        let label = || format!("{} ({} items)", request.op(), request.len());
        let malformed = |reason: String| ExternalError::Malformed {
            request: label(),
            reason,
            got: String::new(),
        };
        let wire = wire
            .ok_or_else(|| self.record(malformed(format!("the answer has no {field:?} array"))))?;
        let numbers = wire
            .numbers(self.version)
            .map_err(|e| self.record(malformed(format!("{field:?}: {e}"))))?;
        let got = numbers.len() / T::WIDTH;
        if got != request.len() {
            return Err(self.record(ExternalError::WrongLength {
                request: label(),
                asked: request.len(),
                got,
            }));
        }
        Ok(numbers)
    }

    /// [`ExternalModel::items_raw`], with its NaN items noted.
    pub(super) fn items<T: Item>(
        &self,
        request: &Request<'_>,
        inputs: &dyn Fn(usize) -> String,
        field: &str,
        wire: Option<Wire<T>>,
    ) -> Result<Vec<f64>, ExternalError> {
        let numbers = self.items_raw(request, field, wire)?;
        self.note_nans(request, inputs, field, (&numbers, T::WIDTH), &|_| false);
        Ok(numbers)
    }

    /// Records an error found in an answer (the session itself is still alive: stop it).
    pub(super) fn record(&self, e: ExternalError) -> ExternalError {
        if let Ok(mut first) = self.first_error.lock() {
            first.get_or_insert_with(|| e.clone());
        }
        if let Ok(mut s) = self.session.lock() {
            s.fail();
        }
        e
    }

    /// D(m) for a batch.
    pub fn d_batch(&self, m: &[Vec3]) -> Result<Vec<f64>, ExternalError> {
        chunked(m.len(), |r| {
            self.values(&Request::D { m: &m[r.clone()] }, &|i| show(m[r.start + i]))
        })
    }

    /// Λ(w) for a batch.
    pub fn lambda_batch(&self, w: &[Vec3]) -> Result<Vec<f64>, ExternalError> {
        chunked(w.len(), |r| {
            self.values(&Request::Lambda { w: &w[r.clone()] }, &|i| {
                show(w[r.start + i])
            })
        })
    }

    /// The density of `sample_wm` for a batch.
    pub fn pdf_wm_batch(&self, m: &[Vec3]) -> Result<Vec<f64>, ExternalError> {
        chunked(m.len(), |r| {
            self.values(&Request::PdfWm { m: &m[r.clone()] }, &|i| {
                show(m[r.start + i])
            })
        })
    }

    /// `sample_wm` for a batch of uniform pairs, written into `out` (same length as `u`). On a
    /// protocol error `out` is filled with NaN directions and the error is recorded.
    pub fn sample_wm_batch(&self, u: &[[f64; 2]], out: &mut [Vec3]) {
        same_length("sample_wm_batch", "u", u.len(), out.len());
        for (start, chunk) in (0..u.len())
            .step_by(MAX_BATCH)
            .zip(out.chunks_mut(MAX_BATCH))
        {
            let r = start..start + chunk.len();
            let got = self.directions(&Request::SampleWm { u: &u[r.clone()] }, &|i| {
                format!("u = {:?}", u[r.start + i])
            });
            match got {
                Ok(m) => chunk.copy_from_slice(&m),
                Err(_) => {
                    out[start..].fill(NAN3);
                    return;
                }
            }
        }
    }

    fn one_value(&self, request: Request<'_>, input: String) -> f64 {
        self.values(&request, &|_| input.clone())
            .map_or(f64::NAN, |v| v[0])
    }
}

/// Runs `f` on consecutive ranges of at most [`MAX_BATCH`] items and concatenates.
pub(super) fn chunked(
    n: usize,
    f: impl Fn(std::ops::Range<usize>) -> Result<Vec<f64>, ExternalError>,
) -> Result<Vec<f64>, ExternalError> {
    let mut out = Vec::with_capacity(n);
    for start in (0..n).step_by(MAX_BATCH) {
        out.extend(f(start..(start + MAX_BATCH).min(n))?);
    }
    Ok(out)
}

/// The batch methods' contract: as many outputs as inputs (a caller's bug otherwise: panics).
#[track_caller]
pub(super) fn same_length(method: &str, input: &str, n_in: usize, n_out: usize) {
    assert_eq!(n_in, n_out, "{method}: {input} and out differ in length");
}

pub(super) fn show(v: Vec3) -> String {
    format!("[{}, {}, {}]", v[0], v[1], v[2])
}

/// Copies a batch result into `out`, or NaN everywhere after a protocol error (recorded).
pub(super) fn fill(out: &mut [f64], got: Result<Vec<f64>, ExternalError>) {
    match got {
        Ok(v) => out.copy_from_slice(&v),
        Err(_) => out.fill(f64::NAN),
    }
}

impl Ndf for ExternalModel {
    fn d(&self, m: Vec3) -> f64 {
        self.one_value(Request::D { m: &[m] }, format!("m = {}", show(m)))
    }
    /// D through the protocol: up to 65 536 directions per request.
    fn d_batch(&self, m: &[Vec3], out: &mut [f64]) {
        same_length("d_batch", "m", m.len(), out.len());
        fill(out, ExternalModel::d_batch(self, m));
    }
    fn as_smith(&self) -> Option<&dyn Smith> {
        self.description.has("lambda").then_some(self as &dyn Smith)
    }
    fn as_sampler(&self) -> Option<&dyn NormalSampler> {
        self.description
            .has("sample_wm")
            .then_some(self as &dyn NormalSampler)
    }
    fn as_visible_sampler(&self) -> Option<&dyn VisibleNormalSampler> {
        self.description
            .has("sample_wm_visible")
            .then_some(self as &dyn VisibleNormalSampler)
    }
}

impl Smith for ExternalModel {
    fn lambda(&self, w: Vec3) -> f64 {
        self.one_value(Request::Lambda { w: &[w] }, format!("w = {}", show(w)))
    }
    /// Λ through the protocol: up to 65 536 directions per request.
    fn lambda_batch(&self, w: &[Vec3], out: &mut [f64]) {
        same_length("lambda_batch", "w", w.len(), out.len());
        fill(out, ExternalModel::lambda_batch(self, w));
    }
    fn g1(&self, w: Vec3, m: Vec3) -> f64 {
        if !self.description.has("g1") {
            return default_g1(self, w, m);
        }
        self.one_value(
            Request::G1 { w: &[w], m: &[m] },
            format!("w = {}, m = {}", show(w), show(m)),
        )
    }
    fn g2(&self, wo: Vec3, wi: Vec3, m: Vec3, masking: Masking) -> f64 {
        if !self.description.has("g2") {
            return default_g2(self, wo, wi, m, masking);
        }
        self.one_value(
            Request::G2 {
                wo: &[wo],
                wi: &[wi],
                m: &[m],
                masking,
            },
            format!("wo = {}, wi = {}, m = {}", show(wo), show(wi), show(m)),
        )
    }
}

/// The trait's default G1 (document 001, eq 16), for a child without `g1`.
fn default_g1(s: &ExternalModel, w: Vec3, m: Vec3) -> f64 {
    if w[2] <= 0.0 || w[0] * m[0] + w[1] * m[1] + w[2] * m[2] <= 0.0 {
        return 0.0;
    }
    1.0 / (1.0 + s.lambda(w))
}

/// The trait's default G2 (document 001, eq 22 / 23), for a child without `g2`.
fn default_g2(s: &ExternalModel, wo: Vec3, wi: Vec3, m: Vec3, masking: Masking) -> f64 {
    match masking {
        Masking::Uncorrelated => default_g1(s, wo, m) * default_g1(s, wi, m),
        Masking::HeightCorrelated => {
            let facing = |w: Vec3| w[2] > 0.0 && w[0] * m[0] + w[1] * m[1] + w[2] * m[2] > 0.0;
            if facing(wo) && facing(wi) {
                1.0 / (1.0 + s.lambda(wo) + s.lambda(wi))
            } else {
                0.0
            }
        }
    }
}

impl NormalSampler for ExternalModel {
    fn sample_wm(&self, u: [f64; 2]) -> Vec3 {
        let mut out = [NAN3];
        ExternalModel::sample_wm_batch(self, &[u], &mut out);
        out[0]
    }
    /// The batch capability through the protocol: up to 65 536 pairs per request.
    fn sample_wm_batch(&self, u: &[[f64; 2]], out: &mut [Vec3]) {
        ExternalModel::sample_wm_batch(self, u, out)
    }
    fn pdf_wm(&self, m: Vec3) -> f64 {
        if !self.description.has("pdf_wm") {
            return if m[2] <= 0.0 { 0.0 } else { self.d(m) * m[2] };
        }
        self.one_value(Request::PdfWm { m: &[m] }, format!("m = {}", show(m)))
    }
    /// pdf_wm through the protocol (D(m) m_z from a `d` batch when not declared).
    fn pdf_wm_batch(&self, m: &[Vec3], out: &mut [f64]) {
        same_length("pdf_wm_batch", "m", m.len(), out.len());
        if self.description.has("pdf_wm") {
            return fill(out, ExternalModel::pdf_wm_batch(self, m));
        }
        Ndf::d_batch(self, m, out);
        for (o, m) in out.iter_mut().zip(m) {
            *o = if m[2] <= 0.0 { 0.0 } else { *o * m[2] };
        }
    }
}

impl VisibleNormalSampler for ExternalModel {
    fn sample_wm_visible(&self, wi: Vec3, u: [f64; 2]) -> Vec3 {
        // Outside the domain the contract is a NaN direction; the child is not asked.
        if !visible_domain(wi) {
            return NAN3;
        }
        self.directions(&Request::SampleWmVisible { wi: &[wi], u: &[u] }, &|_| {
            format!("wi = {}, u = {u:?}", show(wi))
        })
        .map_or(NAN3, |m| m[0])
    }
    fn pdf_wm_visible(&self, wi: Vec3, m: Vec3) -> f64 {
        if !visible_domain(wi) {
            return 0.0;
        }
        if !self.description.has("pdf_wm_visible") {
            if !(m[2] > 0.0) {
                return 0.0;
            }
            let c = wi[0] * m[0] + wi[1] * m[1] + wi[2] * m[2];
            if !(c > 0.0) {
                return 0.0;
            }
            let d = self.d(m);
            if d == 0.0 {
                return 0.0;
            }
            return c * d / (wi[2] * (1.0 + self.lambda(wi)));
        }
        self.one_value(
            Request::PdfWmVisible { wi: &[wi], m: &[m] },
            format!("wi = {}, m = {}", show(wi), show(m)),
        )
    }
    /// sample_wm_visible through the protocol: up to 65 536 pairs per request (NaN directions
    /// outside the domain, and after a protocol error).
    fn sample_wm_visible_batch(&self, wi: Vec3, u: &[[f64; 2]], out: &mut [Vec3]) {
        same_length("sample_wm_visible_batch", "u", u.len(), out.len());
        if !visible_domain(wi) {
            return out.fill(NAN3);
        }
        let wis = vec![wi; u.len().min(MAX_BATCH)];
        for (start, chunk) in (0..u.len())
            .step_by(MAX_BATCH)
            .zip(out.chunks_mut(MAX_BATCH))
        {
            let r = start..start + chunk.len();
            let request = Request::SampleWmVisible {
                wi: &wis[..chunk.len()],
                u: &u[r.clone()],
            };
            match self.directions(&request, &|i| {
                format!("wi = {}, u = {:?}", show(wi), u[r.start + i])
            }) {
                Ok(m) => chunk.copy_from_slice(&m),
                Err(_) => {
                    out[start..].fill(NAN3);
                    return;
                }
            }
        }
    }
    /// pdf_wm_visible through the protocol (from `d` and Λ batches when not declared).
    fn pdf_wm_visible_batch(&self, wi: Vec3, m: &[Vec3], out: &mut [f64]) {
        same_length("pdf_wm_visible_batch", "m", m.len(), out.len());
        if !visible_domain(wi) {
            return out.fill(0.0);
        }
        if !self.description.has("pdf_wm_visible") {
            Ndf::d_batch(self, m, out);
            let lambda = self.lambda(wi);
            for (o, m) in out.iter_mut().zip(m) {
                let c = wi[0] * m[0] + wi[1] * m[1] + wi[2] * m[2];
                *o = if !(m[2] > 0.0) || !(c > 0.0) || *o == 0.0 {
                    0.0
                } else {
                    c * *o / (wi[2] * (1.0 + lambda))
                };
            }
            return;
        }
        let wis = vec![wi; m.len().min(MAX_BATCH)];
        let got = chunked(m.len(), |r| {
            let n = r.len();
            self.values(
                &Request::PdfWmVisible {
                    wi: &wis[..n],
                    m: &m[r.clone()],
                },
                &|i| format!("wi = {}, m = {}", show(wi), show(m[r.start + i])),
            )
        });
        fill(out, got);
    }
}
