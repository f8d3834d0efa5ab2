//! The `audit.precision` record: whether a model's answers are all float32 values (issue 27).
//! A float32 implementation audited as f64 would have its rounding noise judged against f64
//! tolerances and chased by the oracles; this probe notices it from the answers themselves —
//! every D, Λ and pdf on a fixed set of directions exactly representable in float32 — and says
//! so, instead of a report of value failures or an audit that spins.

use crate::precision::Precision;
use crate::record::{CheckRecord, Verdict};
use mfh_reference::{Bsdf, Ndf, Vec3};
use serde_json::json;

/// Directions probed: 512, spread over the upper hemisphere (z = (i + ½)/512, golden azimuths).
pub const PROBE_DIRECTIONS: usize = 512;

/// The fewest distinct non-trivial answers (finite, non-zero, not an integer) on which the probe
/// concludes: 64, so that an f64 model whose answers are f32 values by chance (probability
/// ~2⁻²⁹ each) is never taken for one.
pub const MIN_NONTRIVIAL: usize = 64;

/// The directions of the probe.
fn directions() -> Vec<Vec3> {
    let golden = 0.618_033_988_749_894_9;
    (0..PROBE_DIRECTIONS)
        .map(|i| {
            let z = (i as f64 + 0.5) / PROBE_DIRECTIONS as f64;
            let s = (1.0 - z * z).sqrt();
            let phi = std::f64::consts::TAU * (i as f64 * golden).fract();
            [s * phi.cos(), s * phi.sin(), z]
        })
        .collect()
}

/// What the probe saw: the non-trivial answers and how many of them are float32 values.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Seen {
    /// Distinct non-trivial answers (finite, non-zero, not an integer) of D, Λ and pdf_wm (of
    /// a BSDF: eval and pdf).
    pub nontrivial: usize,
    /// Of them, exactly representable in float32.
    pub float32: usize,
}

impl Seen {
    /// Whether the model answers in float32: at least [`MIN_NONTRIVIAL`] non-trivial answers,
    /// all float32 values.
    pub fn is_float32(&self) -> bool {
        self.nontrivial >= MIN_NONTRIVIAL && self.float32 == self.nontrivial
    }
}

/// Evaluates D, Λ and pdf_wm (those the model has) on the probe's directions, in batches.
pub fn probe(model: &dyn Ndf) -> Seen {
    let dirs = directions();
    let mut answers = vec![0.0; dirs.len()];
    let mut all = Vec::with_capacity(3 * dirs.len());
    model.d_batch(&dirs, &mut answers);
    all.extend_from_slice(&answers);
    if let Some(s) = model.as_smith() {
        s.lambda_batch(&dirs, &mut answers);
        all.extend_from_slice(&answers);
    }
    if let Some(s) = model.as_sampler() {
        s.pdf_wm_batch(&dirs, &mut answers);
        all.extend_from_slice(&answers);
    }
    seen(all)
}

/// Evaluates a BSDF's eval and pdf (in batches) from three incidences — cos θi = 0.9 and 0.5
/// from outside, and 0.7 from inside for a transmitting BSDF — towards the probe's directions
/// and their mirror images below the surface.
pub fn probe_bsdf(bsdf: &dyn Bsdf) -> Seen {
    let up = directions();
    let wo: Vec<Vec3> = up
        .iter()
        .copied()
        .chain(up.iter().map(|w| [w[0], w[1], -w[2]]))
        .collect();
    let mut incidences: Vec<f64> = vec![0.9, 0.5];
    if bsdf.eta().is_some() {
        incidences.push(-0.7);
    }
    let mut answers = vec![0.0; wo.len()];
    let mut all = Vec::with_capacity(2 * incidences.len() * wo.len());
    for cos in incidences {
        let wi = vec![[(1.0 - cos * cos).sqrt(), 0.0, cos]; wo.len()];
        bsdf.eval_batch(&wi, &wo, &mut answers);
        all.extend_from_slice(&answers);
        bsdf.pdf_batch(&wi, &wo, &mut answers);
        all.extend_from_slice(&answers);
    }
    seen(all)
}

/// What answers say: their distinct non-trivial values and how many are float32 values.
fn seen(all: Vec<f64>) -> Seen {
    // Distinct values only: a constant (or dyadic) answer repeated says nothing.
    let mut nontrivial: Vec<f64> = all
        .into_iter()
        .filter(|x| x.is_finite() && *x != 0.0 && x.fract() != 0.0)
        .collect();
    nontrivial.sort_by(f64::total_cmp);
    nontrivial.dedup();
    Seen {
        nontrivial: nontrivial.len(),
        float32: nontrivial
            .iter()
            .filter(|&&x| Precision::F32.represents(x))
            .count(),
    }
}

/// The `audit.precision` record of a model declared at `declared` that answered as `seen`: it
/// fails when a model declared f64 answers only float32 values (the audit then judges it at
/// float32 precision, so that the report says what is wrong instead of spinning), and passes
/// otherwise, stating what it saw.
pub fn record(model: &serde_json::Value, declared: Precision, seen: Seen) -> CheckRecord {
    let mut r = CheckRecord::new(
        "audit.precision",
        model.clone(),
        json!({
            "declared": declared.name(),
            "answers": seen.nontrivial,
            "float32_answers": seen.float32,
        }),
        "issue 27: precision is a property of the implementation",
    );
    r.verdict = if declared == Precision::F64 && seen.is_float32() {
        Verdict::Error {
            message: format!(
                "all {} answers are float32 values; declare precision f32 \
                 (Audit::precision(Precision::F32), or \"precision\": \"f32\" in describe): \
                 the audit judged it at f32",
                seen.nontrivial
            ),
        }
    } else {
        Verdict::Pass
    };
    r
}

/// Runs `probe` (a model's or a BSDF's, which may panic: then nothing was seen) and gives
/// what it saw with the precision the audit judges at ([`effective`]).
pub fn judge(declared: Precision, probe: impl FnOnce() -> Seen) -> (Option<Seen>, Precision) {
    let seen = std::panic::catch_unwind(std::panic::AssertUnwindSafe(probe)).ok();
    (
        seen,
        seen.map_or(declared, |seen| effective(declared, seen)),
    )
}

/// The precision an audit judges at: the declared one, or float32 when a model declared f64
/// answers only float32 values.
pub fn effective(declared: Precision, seen: Seen) -> Precision {
    if declared == Precision::F64 && seen.is_float32() {
        Precision::F32
    } else {
        declared
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    struct Rounded(f32);
    impl Ndf for Rounded {
        fn d(&self, m: Vec3) -> f64 {
            f64::from((m[2] as f32).powf(self.0) * 0.7)
        }
    }
    struct Exact(f64);
    impl Ndf for Exact {
        fn d(&self, m: Vec3) -> f64 {
            m[2].powf(self.0) * 0.7
        }
    }

    #[test]
    fn a_float32_model_is_told_from_an_f64_one() {
        let seen = probe(&Rounded(3.0));
        assert!(
            seen.is_float32() && seen.nontrivial >= MIN_NONTRIVIAL,
            "{seen:?}"
        );
        let r = record(&json!({"name": "r"}), Precision::F64, seen);
        assert!(
            matches!(&r.verdict, Verdict::Error { message } if message.contains("float32")),
            "{r:?}"
        );
        assert_eq!(effective(Precision::F64, seen), Precision::F32);
        assert_eq!(
            record(&json!({}), Precision::F32, seen).verdict,
            Verdict::Pass
        );
        // A constant dyadic D is a float32 value, but one value says nothing.
        struct Half;
        impl Ndf for Half {
            fn d(&self, _: Vec3) -> f64 {
                0.5
            }
        }
        assert!(!probe(&Half).is_float32());
        let seen = probe(&Exact(3.0));
        assert!(!seen.is_float32(), "{seen:?}");
        assert_eq!(effective(Precision::F64, seen), Precision::F64);
        assert_eq!(
            record(&json!({}), Precision::F64, seen).verdict,
            Verdict::Pass
        );
    }

    /// A BSDF whose answers are rounded to float32 is told from the f64 reference it rounds.
    #[test]
    fn a_float32_bsdf_is_told_from_an_f64_one() {
        let spec: mfh_reference::bsdf::BsdfSpec = serde_json::from_str(
            r#"{"bsdf":"dielectric","eta":1.5,"ndf":{"family":"ggx","alpha":0.3}}"#,
        )
        .unwrap();
        let exact = spec.build().unwrap();
        struct Rounded(std::sync::Arc<dyn Bsdf>);
        impl Bsdf for Rounded {
            fn eval(&self, wi: Vec3, wo: Vec3) -> f64 {
                f64::from(self.0.eval(wi, wo) as f32)
            }
            fn pdf(&self, wi: Vec3, wo: Vec3) -> f64 {
                f64::from(self.0.pdf(wi, wo) as f32)
            }
            fn sample(&self, wi: Vec3, u: [f64; 3]) -> Option<mfh_reference::bsdf::BsdfSample> {
                self.0.sample(wi, u)
            }
            fn eta(&self) -> Option<f64> {
                self.0.eta()
            }
        }
        let seen = probe_bsdf(&Rounded(exact.clone()));
        assert!(seen.is_float32(), "{seen:?}");
        let seen = probe_bsdf(exact.as_ref());
        assert!(!seen.is_float32() && seen.nontrivial > 1000, "{seen:?}");
    }
}
