//! An external process as a [`Bsdf`]: `bsdf_eval`, `bsdf_pdf` and `bsdf_sample` requests of
//! up to [`MAX_BATCH`] items; a scalar call is a batch of one. The relative index and the
//! transport convention are those the child declared in `describe` (`eta`, `transport`).
//!
//! As for the NDF methods ([`super::model`]), the first protocol error is recorded, the child is
//! stopped, and every later call answers at once: NaN values, and samples with a NaN direction,
//! pdf and weight (so that the checks fail quickly, beside the `external.protocol` record). A
//! NaN the child answers is no protocol error: it reaches the checks as a Rust BSDF's would,
//! and is listed by array (`values`, `wo`, `pdf`, `weight`) and item for the `external.nan`
//! records (a failed sample's — pdf 0 — wo and weight are ignored).

use super::model::{chunked, fill, same_length, show, ExternalModel, MAX_BATCH};
use super::process::ExternalError;
use super::protocol::Request;
use mfh_reference::bsdf::{Bsdf, BsdfSample, Sampling, Transport};
use mfh_reference::Vec3;

/// The answer to a sample after a protocol error.
const BROKEN: BsdfSample = BsdfSample {
    wo: [f64::NAN; 3],
    pdf: f64::NAN,
    weight: f64::NAN,
};

impl ExternalModel {
    /// eval(wi, wo) for a batch of pairs.
    pub fn bsdf_eval_batch(&self, wi: &[Vec3], wo: &[Vec3]) -> Result<Vec<f64>, ExternalError> {
        self.pairs(wi, wo, |wi, wo| Request::BsdfEval { wi, wo })
    }

    /// pdf(wi, wo) for a batch of pairs.
    pub fn bsdf_pdf_batch(&self, wi: &[Vec3], wo: &[Vec3]) -> Result<Vec<f64>, ExternalError> {
        self.pairs(wi, wo, |wi, wo| Request::BsdfPdf { wi, wo })
    }

    fn pairs<'r>(
        &self,
        wi: &'r [Vec3],
        wo: &'r [Vec3],
        request: impl Fn(&'r [Vec3], &'r [Vec3]) -> Request<'r>,
    ) -> Result<Vec<f64>, ExternalError> {
        chunked(wo.len(), |r| {
            self.values(&request(&wi[r.clone()], &wo[r.clone()]), &|i| {
                format!(
                    "wi = {}, wo = {}",
                    show(wi[r.start + i]),
                    show(wo[r.start + i])
                )
            })
        })
    }

    /// `bsdf_sample` for a batch of (wi, u) (at most [`MAX_BATCH`]): (wo, pdf, weight) each.
    fn bsdf_sample_request(
        &self,
        wi: &[Vec3],
        u: &[[f64; 3]],
    ) -> Result<Vec<Option<BsdfSample>>, ExternalError> {
        let request = Request::BsdfSample { wi, u };
        let inputs = |i: usize| format!("wi = {}, u = {:?}", show(wi[i]), u[i]);
        let answer = self.call(&request)?;
        let wo = self.items_raw(&request, "wo", answer.wo)?;
        let pdf = self.items(&request, &inputs, "pdf", answer.pdf)?;
        let weight = self.items_raw(&request, "weight", answer.weight)?;
        // A failed sample's wo and weight mean nothing, NaN included.
        let failed = |i: usize| pdf[i] == 0.0;
        self.note_nans(&request, &inputs, "wo", (&wo, 3), &failed);
        self.note_nans(&request, &inputs, "weight", (&weight, 1), &failed);
        Ok(pdf
            .iter()
            .zip(&weight)
            .zip(wo.chunks_exact(3))
            .map(|((&pdf, &weight), wo)| {
                // A failed sample answers pdf 0 (and weight 0); its wo means nothing.
                (pdf != 0.0).then_some(BsdfSample {
                    wo: [wo[0], wo[1], wo[2]],
                    pdf,
                    weight,
                })
            })
            .collect())
    }
}

impl Bsdf for ExternalModel {
    fn eval(&self, wi: Vec3, wo: Vec3) -> f64 {
        let mut out = [f64::NAN];
        Bsdf::eval_batch(self, &[wi], &[wo], &mut out);
        out[0]
    }

    fn pdf(&self, wi: Vec3, wo: Vec3) -> f64 {
        let mut out = [f64::NAN];
        Bsdf::pdf_batch(self, &[wi], &[wo], &mut out);
        out[0]
    }

    fn sample(&self, wi: Vec3, u: [f64; 3]) -> Option<BsdfSample> {
        let mut out = [None];
        Bsdf::sample_batch(self, wi, &[u], &mut out);
        out[0]
    }

    fn eta(&self) -> Option<f64> {
        self.description().eta()
    }

    fn transport(&self) -> Transport {
        self.description().transport()
    }

    fn two_sided(&self) -> bool {
        self.description().two_sided()
    }

    fn reference_map(&self) -> Option<Sampling> {
        self.description().reference_map()
    }

    /// eval through the protocol: up to 65 536 pairs per request.
    fn eval_batch(&self, wi: &[Vec3], wo: &[Vec3], out: &mut [f64]) {
        same_length("eval_batch", "wi", wi.len(), out.len());
        same_length("eval_batch", "wo", wo.len(), out.len());
        fill(out, self.bsdf_eval_batch(wi, wo));
    }

    /// pdf through the protocol: up to 65 536 pairs per request.
    fn pdf_batch(&self, wi: &[Vec3], wo: &[Vec3], out: &mut [f64]) {
        same_length("pdf_batch", "wi", wi.len(), out.len());
        same_length("pdf_batch", "wo", wo.len(), out.len());
        fill(out, self.bsdf_pdf_batch(wi, wo));
    }

    /// sample through the protocol: up to 65 536 triples per request (samples with NaN
    /// fields after a protocol error).
    fn sample_batch(&self, wi: Vec3, u: &[[f64; 3]], out: &mut [Option<BsdfSample>]) {
        same_length("sample_batch", "u", u.len(), out.len());
        let wis = vec![wi; u.len().min(MAX_BATCH)];
        for (start, chunk) in (0..u.len())
            .step_by(MAX_BATCH)
            .zip(out.chunks_mut(MAX_BATCH))
        {
            let n = chunk.len();
            match self.bsdf_sample_request(&wis[..n], &u[start..start + n]) {
                Ok(samples) => chunk.copy_from_slice(&samples),
                Err(_) => {
                    out[start..].fill(Some(BROKEN));
                    return;
                }
            }
        }
    }
}
