//! Python callables as the harness's capability traits: a BSDF ([`PyBsdf`]: `eval`, `pdf`,
//! `sample`) and an NDF ([`PyNdf`]: `d` and the optional `lambda_`, `sample_wm`, `pdf_wm`,
//! `sample_wm_visible`, `pdf_wm_visible`). Every batch method of the traits is one call of the
//! Python function on the whole batch; a scalar method is a batch of one. The defaults of the
//! optional densities are the external protocol's (`harness/src/external/model.rs`): pdf_wm =
//! D(m) m_z, pdf_wm_visible = G1(wi)⟨wi·m⟩⁺D(m)/cos θi (Heitz & d'Eon 2014, eq 2).

use crate::caller::{show, Caller};
use mfh_reference::bsdf::{Bsdf, BsdfSample, Transport};
use mfh_reference::model::{visible_domain, NormalSampler, Smith, VisibleNormalSampler};
use mfh_reference::{Ndf, Vec3};
use pyo3::PyObject;
use std::sync::Arc;

const NAN3: Vec3 = [f64::NAN; 3];

/// The numbers of a slice of directions (or pairs, triples), row-major.
fn flat<const N: usize>(v: &[[f64; N]]) -> &[f64] {
    v.as_flattened()
}

fn rows<const N: usize>(numbers: &[f64]) -> impl Iterator<Item = [f64; N]> + '_ {
    numbers
        .chunks_exact(N)
        .map(|c| std::array::from_fn(|j| c[j]))
}

/// A copy of `got` into `out`, or NaN everywhere when the call failed.
fn fill(out: &mut [f64], got: Option<Vec<f64>>) {
    match got {
        Some(v) => out.copy_from_slice(&v),
        None => out.fill(f64::NAN),
    }
}

fn fill_directions(out: &mut [Vec3], got: Option<Vec<f64>>) {
    match got {
        Some(v) => out.iter_mut().zip(rows::<3>(&v)).for_each(|(o, m)| *o = m),
        None => out.fill(NAN3),
    }
}

/// The answer to a sample after an error: NaN everywhere (the checks fail quickly).
const BROKEN: BsdfSample = BsdfSample {
    wo: NAN3,
    pdf: f64::NAN,
    weight: f64::NAN,
};

/// A BSDF given as three Python callables over (N, 3) arrays.
pub struct PyBsdf {
    /// `eval(wi, wo)` → (N,).
    pub eval: PyObject,
    /// `pdf(wi, wo)` → (N,).
    pub pdf: PyObject,
    /// `sample(wi, u)` → (wo (N, 3), pdf (N,), weight (N,)).
    pub sample: PyObject,
    /// η inside / η outside (None: reflection only).
    pub eta: Option<f64>,
    /// The transport convention of its transmission lobe.
    pub transport: Transport,
    /// The calls.
    pub caller: Arc<Caller>,
}

impl PyBsdf {
    fn pairs(&self, op: &str, function: &PyObject, wi: &[Vec3], wo: &[Vec3], out: &mut [f64]) {
        assert!(
            wi.len() == out.len() && wo.len() == out.len(),
            "{op}_batch: wi, wo and out differ in length"
        );
        let got = self.caller.values(
            op,
            function,
            out.len(),
            1,
            &[(flat(wi), 3), (flat(wo), 3)],
            &|i| format!("wi = {}, wo = {}", show(wi[i]), show(wo[i])),
        );
        fill(out, got);
    }
}

impl Bsdf for PyBsdf {
    fn eval(&self, wi: Vec3, wo: Vec3) -> f64 {
        let mut out = [f64::NAN];
        self.eval_batch(&[wi], &[wo], &mut out);
        out[0]
    }

    fn pdf(&self, wi: Vec3, wo: Vec3) -> f64 {
        let mut out = [f64::NAN];
        self.pdf_batch(&[wi], &[wo], &mut out);
        out[0]
    }

    fn sample(&self, wi: Vec3, u: [f64; 3]) -> Option<BsdfSample> {
        let mut out = [None];
        self.sample_batch(wi, &[u], &mut out);
        out[0]
    }

    fn eta(&self) -> Option<f64> {
        self.eta
    }

    fn transport(&self) -> Transport {
        self.transport
    }

    fn eval_batch(&self, wi: &[Vec3], wo: &[Vec3], out: &mut [f64]) {
        self.pairs("eval", &self.eval, wi, wo, out)
    }

    fn pdf_batch(&self, wi: &[Vec3], wo: &[Vec3], out: &mut [f64]) {
        self.pairs("pdf", &self.pdf, wi, wo, out)
    }

    /// One call of `sample` for the whole batch (`wi` repeated); pdf 0 is a failed sample.
    fn sample_batch(&self, wi: Vec3, u: &[[f64; 3]], out: &mut [Option<BsdfSample>]) {
        assert_eq!(
            u.len(),
            out.len(),
            "sample_batch: u and out differ in length"
        );
        if u.is_empty() {
            return;
        }
        let wis = vec![wi; u.len()];
        let got = self
            .caller
            .sample(&self.sample, u.len(), flat(&wis), flat(u), &|i| {
                format!("wi = {}, u = {:?}", show(wi), u[i])
            });
        match got {
            None => out.fill(Some(BROKEN)),
            Some((wo, pdf, weight)) => {
                for (k, (o, wo)) in out.iter_mut().zip(rows::<3>(&wo)).enumerate() {
                    // A failed sample answers pdf 0 (and weight 0); its wo means nothing.
                    *o = (pdf[k] != 0.0).then_some(BsdfSample {
                        wo,
                        pdf: pdf[k],
                        weight: weight[k],
                    });
                }
            }
        }
    }
}

/// An NDF given as Python callables: `d` and the optional capabilities.
pub struct PyNdf {
    /// `d(m)` → (N,).
    pub d: PyObject,
    /// `lambda_(w)` → (N,).
    pub lambda: Option<PyObject>,
    /// `sample_wm(u)`, u (N, 2) → (N, 3).
    pub sample_wm: Option<PyObject>,
    /// `pdf_wm(m)` → (N,).
    pub pdf_wm: Option<PyObject>,
    /// `sample_wm_visible(wi, u)`, (N, 3) and (N, 2) → (N, 3).
    pub sample_wm_visible: Option<PyObject>,
    /// `pdf_wm_visible(wi, m)` → (N,).
    pub pdf_wm_visible: Option<PyObject>,
    /// The calls.
    pub caller: Arc<Caller>,
}

impl PyNdf {
    fn one(&self, op: &str, function: &PyObject, w: Vec3) -> f64 {
        let mut out = [f64::NAN];
        self.directions(op, function, &[w], &mut out);
        out[0]
    }

    fn directions(&self, op: &str, function: &PyObject, w: &[Vec3], out: &mut [f64]) {
        assert_eq!(
            w.len(),
            out.len(),
            "{op}_batch: the input and out differ in length"
        );
        let got = self
            .caller
            .values(op, function, out.len(), 1, &[(flat(w), 3)], &|i| {
                format!("input = {}", show(w[i]))
            });
        fill(out, got);
    }
}

impl Ndf for PyNdf {
    fn d(&self, m: Vec3) -> f64 {
        self.one("d", &self.d, m)
    }
    fn d_batch(&self, m: &[Vec3], out: &mut [f64]) {
        self.directions("d", &self.d, m, out)
    }
    fn as_smith(&self) -> Option<&dyn Smith> {
        self.lambda.as_ref().map(|_| self as &dyn Smith)
    }
    fn as_sampler(&self) -> Option<&dyn NormalSampler> {
        self.sample_wm.as_ref().map(|_| self as &dyn NormalSampler)
    }
    fn as_visible_sampler(&self) -> Option<&dyn VisibleNormalSampler> {
        (self.lambda.is_some() && self.sample_wm_visible.is_some())
            .then_some(self as &dyn VisibleNormalSampler)
    }
}

impl Smith for PyNdf {
    fn lambda(&self, w: Vec3) -> f64 {
        match &self.lambda {
            Some(f) => self.one("lambda_", f, w),
            None => f64::NAN,
        }
    }
    fn lambda_batch(&self, w: &[Vec3], out: &mut [f64]) {
        match &self.lambda {
            Some(f) => self.directions("lambda_", f, w, out),
            None => out.fill(f64::NAN),
        }
    }
}

impl NormalSampler for PyNdf {
    fn sample_wm(&self, u: [f64; 2]) -> Vec3 {
        let mut out = [NAN3];
        self.sample_wm_batch(&[u], &mut out);
        out[0]
    }
    fn sample_wm_batch(&self, u: &[[f64; 2]], out: &mut [Vec3]) {
        assert_eq!(
            u.len(),
            out.len(),
            "sample_wm_batch: u and out differ in length"
        );
        let Some(f) = &self.sample_wm else {
            return out.fill(NAN3);
        };
        let got = self
            .caller
            .values("sample_wm", f, u.len(), 3, &[(flat(u), 2)], &|i| {
                format!("u = {:?}", u[i])
            });
        fill_directions(out, got);
    }
    fn pdf_wm(&self, m: Vec3) -> f64 {
        let mut out = [f64::NAN];
        self.pdf_wm_batch(&[m], &mut out);
        out[0]
    }
    /// `pdf_wm` when given, else D(m) m_z from one `d` call.
    fn pdf_wm_batch(&self, m: &[Vec3], out: &mut [f64]) {
        if let Some(f) = &self.pdf_wm {
            return self.directions("pdf_wm", f, m, out);
        }
        self.d_batch(m, out);
        for (o, m) in out.iter_mut().zip(m) {
            *o = if m[2] <= 0.0 { 0.0 } else { *o * m[2] };
        }
    }
}

impl VisibleNormalSampler for PyNdf {
    fn sample_wm_visible(&self, wi: Vec3, u: [f64; 2]) -> Vec3 {
        let mut out = [NAN3];
        self.sample_wm_visible_batch(wi, &[u], &mut out);
        out[0]
    }
    fn pdf_wm_visible(&self, wi: Vec3, m: Vec3) -> f64 {
        let mut out = [f64::NAN];
        self.pdf_wm_visible_batch(wi, &[m], &mut out);
        out[0]
    }
    /// One call for the batch (`wi` repeated); NaN directions outside the domain (the
    /// function is not asked there: the trait's contract).
    fn sample_wm_visible_batch(&self, wi: Vec3, u: &[[f64; 2]], out: &mut [Vec3]) {
        assert_eq!(
            u.len(),
            out.len(),
            "sample_wm_visible_batch: u and out differ in length"
        );
        let Some(f) = &self.sample_wm_visible else {
            return out.fill(NAN3);
        };
        if !visible_domain(wi) {
            return out.fill(NAN3);
        }
        let wis = vec![wi; u.len()];
        let got = self.caller.values(
            "sample_wm_visible",
            f,
            u.len(),
            3,
            &[(flat(&wis), 3), (flat(u), 2)],
            &|i| format!("wi = {}, u = {:?}", show(wi), u[i]),
        );
        fill_directions(out, got);
    }
    /// `pdf_wm_visible` when given, else G1(wi)⟨wi·m⟩⁺D(m)/cos θi from one `d` call and Λ(wi);
    /// 0 outside the domain.
    fn pdf_wm_visible_batch(&self, wi: Vec3, m: &[Vec3], out: &mut [f64]) {
        assert_eq!(
            m.len(),
            out.len(),
            "pdf_wm_visible_batch: m and out differ in length"
        );
        if !visible_domain(wi) {
            return out.fill(0.0);
        }
        if let Some(f) = &self.pdf_wm_visible {
            let wis = vec![wi; m.len()];
            let got = self.caller.values(
                "pdf_wm_visible",
                f,
                m.len(),
                1,
                &[(flat(&wis), 3), (flat(m), 3)],
                &|i| format!("wi = {}, m = {}", show(wi), show(m[i])),
            );
            return fill(out, got);
        }
        self.d_batch(m, out);
        let lambda = self.lambda(wi);
        for (o, m) in out.iter_mut().zip(m) {
            let c = wi[0] * m[0] + wi[1] * m[1] + wi[2] * m[2];
            *o = if !(m[2] > 0.0) || !(c > 0.0) || *o == 0.0 {
                0.0
            } else {
                c * *o / (wi[2] * (1.0 + lambda))
            };
        }
    }
}
