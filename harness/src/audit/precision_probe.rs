//! The `audit.precision` record: whether a model's answers are all float32 values.
//! A float32 implementation audited as f64 would have its rounding noise judged against f64
//! tolerances and chased by the oracles; this probe notices it from the answers themselves —
//! every D, Λ and pdf on a fixed set of directions exactly representable in float32 — and says
//! so, instead of a report of value failures or an audit that spins.
//!
//! The reverse lie is found the same way: a model declared float32 whose answers are (almost)
//! never float32 values computes in f64, and float32 tolerances would hide its defects (a
//! weight error of 5e-4 passes a float32 BSDF's tolerances and fails an f64 one's). It is
//! judged at f64, and the record fails saying so.

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
    /// The batches probed (D, Λ, pdf_wm; a BSDF's eval and pdf at each incidence) in which
    /// more than half of the non-trivial answers are float32 values.
    pub float32_quantities: usize,
}

impl Seen {
    /// Whether the model answers in float32: at least [`MIN_NONTRIVIAL`] non-trivial answers,
    /// all float32 values.
    pub fn is_float32(&self) -> bool {
        self.nontrivial >= MIN_NONTRIVIAL && self.float32 == self.nontrivial
    }

    /// Whether the model answers in f64: at least [`MIN_NONTRIVIAL`] non-trivial answers, and
    /// in no batch are most of them float32 values. A float32 model's own quantities (its D,
    /// Λ, eval or pdf) are all float32 values, even where another is finished in f64 by a trait
    /// default or by mfh (`pdf_wm` = D·cos θ from its D); an f64 computation gives a float32
    /// value by chance only (measured: 18 of the 512 answers of D = 0.7 cos³θ, whose inputs are
    /// float32 values and whose cubes are exact; ~2⁻²⁹ per answer of a GGX).
    pub fn is_float64(&self) -> bool {
        self.nontrivial >= MIN_NONTRIVIAL && self.float32_quantities == 0
    }
}

/// Evaluates D, Λ and pdf_wm (those the model has) on the probe's directions, in batches.
pub fn probe(model: &dyn Ndf) -> Seen {
    let dirs = directions();
    let mut answers = vec![0.0; dirs.len()];
    let mut all = Vec::with_capacity(3);
    model.d_batch(&dirs, &mut answers);
    all.push(answers.clone());
    if let Some(s) = model.as_smith() {
        s.lambda_batch(&dirs, &mut answers);
        all.push(answers.clone());
    }
    if let Some(s) = model.as_sampler() {
        s.pdf_wm_batch(&dirs, &mut answers);
        all.push(answers.clone());
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
    let mut all = Vec::with_capacity(2 * incidences.len());
    for cos in incidences {
        let wi = vec![[(1.0 - cos * cos).sqrt(), 0.0, cos]; wo.len()];
        bsdf.eval_batch(&wi, &wo, &mut answers);
        all.push(answers.clone());
        bsdf.pdf_batch(&wi, &wo, &mut answers);
        all.push(answers.clone());
    }
    seen(all)
}

/// What answers say, batch by batch: their distinct non-trivial values and how many are
/// float32 values.
fn seen(batches: Vec<Vec<f64>>) -> Seen {
    let mut out = Seen {
        nontrivial: 0,
        float32: 0,
        float32_quantities: 0,
    };
    for all in batches {
        // Distinct values only: a constant (or dyadic) answer repeated says nothing.
        let mut nontrivial: Vec<f64> = all
            .into_iter()
            .filter(|x| x.is_finite() && *x != 0.0 && x.fract() != 0.0)
            .collect();
        nontrivial.sort_by(f64::total_cmp);
        nontrivial.dedup();
        let float32 = nontrivial
            .iter()
            .filter(|&&x| Precision::F32.represents(x))
            .count();
        out.nontrivial += nontrivial.len();
        out.float32 += float32;
        if 2 * float32 > nontrivial.len() {
            out.float32_quantities += 1;
        }
    }
    out
}

/// The `audit.precision` record of a model declared at `declared` that answered as `seen`: it
/// fails when a model declared f64 answers only float32 values (the audit then judges it at
/// float32 precision, so that the report says what is wrong instead of spinning), and when a
/// model declared f32 answers f64 values ([`Seen::is_float64`]: the audit judges it at f64, so
/// that float32 tolerances hide none of its defects); it passes otherwise, stating what it saw.
pub fn record(model: &serde_json::Value, declared: Precision, seen: Seen) -> CheckRecord {
    let mut r = CheckRecord::new(
        "audit.precision",
        model.clone(),
        json!({
            "declared": declared.name(),
            "answers": seen.nontrivial,
            "float32_answers": seen.float32,
        }),
        "precision is a property of the implementation",
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
    } else if declared == Precision::F32 && seen.is_float64() {
        Verdict::Error {
            message: format!(
                "{} of {} answers are float32 values: the implementation computes in f64, \
                 not in the float32 it declares; the audit judged it at f64 (declare precision \
                 f64, the default, or round its answers to float32 if it computes in float32)",
                seen.float32, seen.nontrivial
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

/// The precision an audit judges at: the declared one, float32 when a model declared f64
/// answers only float32 values, f64 when a model declared float32 answers f64 values.
pub fn effective(declared: Precision, seen: Seen) -> Precision {
    if declared == Precision::F64 && seen.is_float32() {
        Precision::F32
    } else if declared == Precision::F32 && seen.is_float64() {
        Precision::F64
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
        // The reverse lie: declared f32, answers f64 values: judged at f64, and the record
        // fails saying so.
        assert!(seen.is_float64(), "{seen:?}");
        assert_eq!(effective(Precision::F32, seen), Precision::F64);
        let r = record(&json!({}), Precision::F32, seen);
        assert!(
            matches!(&r.verdict, Verdict::Error { message } if message.contains("computes in f64")),
            "{r:?}"
        );
        assert!(!probe(&Rounded(3.0)).is_float64());
        assert!(!probe(&Half).is_float64());
    }

    /// A float32 model whose one quantity is finished in f64 (D in float32, pdf_wm = D·cos θ
    /// by the trait's default) is no f64 model: a third or more of its answers are float32.
    #[test]
    fn a_float32_model_finished_in_f64_is_not_taken_for_f64() {
        struct Mixed;
        impl Ndf for Mixed {
            fn d(&self, m: Vec3) -> f64 {
                f64::from((m[2] as f32).powf(3.0) * 0.7)
            }
            fn as_sampler(&self) -> Option<&dyn mfh_reference::model::NormalSampler> {
                Some(self)
            }
        }
        impl mfh_reference::model::NormalSampler for Mixed {
            fn sample_wm(&self, _: [f64; 2]) -> Vec3 {
                [0.0, 0.0, 1.0]
            }
            fn pdf_wm(&self, m: Vec3) -> f64 {
                self.d(m) * m[2]
            }
        }
        let seen = probe(&Mixed);
        assert!(!seen.is_float64() && !seen.is_float32(), "{seen:?}");
        assert_eq!(effective(Precision::F32, seen), Precision::F32);
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
