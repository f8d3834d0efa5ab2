//! `sampling.batch_agrees`: a sampler's batch path against its scalar path. The chi-square,
//! KS and Monte Carlo checks draw through `sample_wm_batch` (and `sample_wm_visible_batch`),
//! the Jacobian check and a renderer through the scalar methods: two code paths, each
//! checked by different checks. The trait promises `batch[i] = scalar(u[i])` (to the ulps an
//! override documents; the reference models: GGX's visible normals within 2 ulps, the rest
//! bit for bit), so this check draws the audit's own
//! u — a seeded stream with the edge values 0 and 1 − 2⁻⁵³ in front — through both and
//! compares them component by component in ulps, one record per sampler, reporting the worst
//! index with its u and both vectors.

use crate::check::{covers, need, Check, PlannedCheck};
use crate::record::{CheckRecord, Measured, Verdict};
use crate::subject::Subject;
use crate::tolerance::{Tolerance, BATCH_SAMPLER, BATCH_SAMPLER_REFERENCE};
use mfh_reference::geometry::{from_spherical, Vec3};
use serde_json::json;
use std::sync::Arc;

/// The u pairs drawn through both paths.
pub const POINTS: usize = 4096;

/// The largest uniform below 1 (1 − 2⁻⁵³): the top of the audit's grid k·2⁻⁵³.
const ONE_BELOW: f64 = 1.0 - f64::EPSILON / 2.0;

const SOURCE: &str = "reference/src/model.rs: NormalSampler::sample_wm_batch and \
                      VisibleNormalSampler::sample_wm_visible_batch must equal the scalar \
                      method at every u";

/// The record of the normal sampler's paths (none for a model without one).
pub fn plan_normal<'a>(subject: &Arc<Subject<'a>>, why: &str) -> Vec<PlannedCheck<'a>> {
    if subject.model.as_sampler().is_none() {
        return Vec::new();
    }
    let m = subject.clone();
    let tol = tolerance(subject);
    vec![check(
        subject,
        "sample_wm",
        json!({"sampler": "sample_wm", "points": POINTS}),
    )
    .why(format!(
        "{why}: the batch sampler the statistical checks draw through must be the scalar one"
    ))
    .run(move |r, ctx| {
        let sampler = need(m.model.as_sampler(), "normal sampler")?;
        let u = uniforms(ctx.seed);
        let mut batch = vec![[0.0; 3]; u.len()];
        sampler.sample_wm_batch(&u, &mut batch);
        let scalar: Vec<Vec3> = u.iter().map(|&u| sampler.sample_wm(u)).collect();
        judge(r, &u, &batch, &scalar, tol);
        Ok(())
    })]
}

/// The record of the visible-normal sampler's paths at `incidences` (θ, φ) (none for a model
/// without one).
pub fn plan_visible<'a>(
    subject: &Arc<Subject<'a>>,
    incidences: &'static [(f64, f64)],
    why: &str,
) -> Vec<PlannedCheck<'a>> {
    if subject.model.as_visible_sampler().is_none() {
        return Vec::new();
    }
    let m = subject.clone();
    let tol = tolerance(subject);
    let case = json!({"sampler": "sample_wm_visible", "points": POINTS, "incidences": incidences});
    vec![check(subject, "sample_wm_visible", case)
        .why(format!(
            "{why}: the batch visible-normal sampler the chi-square draws through must be the \
             scalar one"
        ))
        .run(move |r, ctx| {
            let v = need(m.model.as_visible_sampler(), "visible-normal sampler")?;
            let u = uniforms(ctx.seed);
            // The incidence whose worst component is the worst of all is the one reported.
            let mut worst: Option<(f64, CheckRecord)> = None;
            for &(theta, phi) in incidences {
                let wi = from_spherical(theta, phi);
                let mut batch = vec![[0.0; 3]; u.len()];
                v.sample_wm_visible_batch(wi, &u, &mut batch);
                let scalar: Vec<Vec3> = u.iter().map(|&u| v.sample_wm_visible(wi, u)).collect();
                let mut one = r.clone();
                let ulps = judge(&mut one, &u, &batch, &scalar, tol);
                if let Some(obj) = one.case.as_object_mut() {
                    obj.insert("theta_i".into(), json!(theta));
                    obj.insert("phi_i".into(), json!(phi));
                }
                if worst.as_ref().is_none_or(|(w, _)| !(ulps <= *w)) {
                    worst = Some((ulps, one));
                }
            }
            if let Some((_, one)) = worst {
                *r = one;
            }
            Ok(())
        })]
}

/// The check of one sampler, seeded, covering its closed form.
fn check(subject: &Subject, sampler: &str, case: serde_json::Value) -> Check {
    Check::new("sampling.batch_agrees", subject.label.clone(), case, SOURCE)
        .covers(vec![covers(subject.family(), sampler, "default")])
        .seeded()
}

/// The reference models' stated ulps (GGX's batches; bit for bit for the others); a few ulps
/// for a user's.
fn tolerance(subject: &Subject) -> &'static Tolerance {
    if subject.reference.is_some() {
        &BATCH_SAMPLER_REFERENCE
    } else {
        &BATCH_SAMPLER
    }
}

/// The u pairs: the four corners of {0, 1 − 2⁻⁵³}², then the check's seeded stream.
pub fn uniforms(seed: u64) -> Vec<[f64; 2]> {
    let corners = [
        [0.0, 0.0],
        [0.0, ONE_BELOW],
        [ONE_BELOW, 0.0],
        [ONE_BELOW, ONE_BELOW],
    ];
    let mut u = vec![[0.0; 2]; POINTS];
    crate::random::stream(seed, 0).fill_pairs(&mut u[corners.len()..]);
    u[..corners.len()].copy_from_slice(&corners);
    u
}

/// The distance in ulps between two doubles: the count of doubles between them, with −0 one
/// below +0 (so that "bit for bit" is distance 0), 0 between two NaNs (the sampler is outside
/// its domain on both paths) and ∞ between a NaN and a number.
pub fn ulps(a: f64, b: f64) -> f64 {
    match (a.is_nan(), b.is_nan()) {
        (true, true) => return 0.0,
        (true, false) | (false, true) => return f64::INFINITY,
        _ => {}
    }
    let ordered = |x: f64| -> i128 {
        let bits = x.to_bits();
        let magnitude = i128::from(bits & !(1u64 << 63));
        if bits >> 63 == 1 {
            -magnitude - 1
        } else {
            magnitude
        }
    };
    (ordered(a) - ordered(b)).unsigned_abs() as f64
}

/// Fills `r` with the worst component distance (ulps) between `batch` and `scalar` and, in its
/// case, the worst index with its u and both vectors; returns the distance.
fn judge(
    r: &mut CheckRecord,
    u: &[[f64; 2]],
    batch: &[Vec3],
    scalar: &[Vec3],
    tol: &Tolerance,
) -> f64 {
    let (mut worst, mut at) = (0.0f64, 0usize);
    for (i, (b, s)) in batch.iter().zip(scalar).enumerate() {
        let d = (0..3).map(|k| ulps(b[k], s[k])).fold(0.0, f64::max);
        if d > worst {
            (worst, at) = (d, i);
        }
    }
    if let Some(obj) = r.case.as_object_mut() {
        obj.insert("unit".into(), json!("ulp"));
        obj.insert("worst_index".into(), json!(at));
        obj.insert("worst_u".into(), json!(u.get(at)));
        obj.insert("batch".into(), json!(batch.get(at)));
        obj.insert("scalar".into(), json!(scalar.get(at)));
    }
    r.value = Some(worst);
    r.measured = Some(Measured::Absolute { error: worst });
    r.tolerance = Some(crate::check::applied(tol));
    r.cost.samples = 2 * u.len() as u64;
    r.verdict = if batch.len() != u.len() || scalar.len() != u.len() {
        Verdict::Error {
            message: "the batch and scalar paths returned different counts".into(),
        }
    } else if worst <= tol.value {
        Verdict::Pass
    } else {
        Verdict::Fail
    };
    worst
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::check::RunContext;
    use crate::subject::Hints;
    use mfh_reference::ndf::Ggx;
    use mfh_reference::{ModelSpec, Ndf, NormalSampler, Smith, VisibleNormalSampler};

    /// GGX whose batch paths flip the sign of x at every `every`-th element (0: never), as a
    /// vectorized loop with a bad remainder would; the scalar paths are right.
    struct FlippedBatch {
        ggx: Ggx,
        every: usize,
    }
    impl FlippedBatch {
        fn flip(&self, out: &mut [Vec3]) {
            if self.every == 0 {
                return;
            }
            for o in out.iter_mut().step_by(self.every) {
                o[0] = -o[0];
            }
        }
    }
    impl Ndf for FlippedBatch {
        fn d(&self, m: Vec3) -> f64 {
            self.ggx.d(m)
        }
        fn as_smith(&self) -> Option<&dyn Smith> {
            Some(self)
        }
        fn as_sampler(&self) -> Option<&dyn NormalSampler> {
            Some(self)
        }
        fn as_visible_sampler(&self) -> Option<&dyn VisibleNormalSampler> {
            Some(self)
        }
    }
    impl Smith for FlippedBatch {
        fn lambda(&self, w: Vec3) -> f64 {
            self.ggx.lambda(w)
        }
    }
    impl NormalSampler for FlippedBatch {
        fn sample_wm(&self, u: [f64; 2]) -> Vec3 {
            self.ggx.sample_wm(u)
        }
        fn sample_wm_batch(&self, u: &[[f64; 2]], out: &mut [Vec3]) {
            self.ggx.sample_wm_batch(u, out);
            self.flip(out);
        }
    }
    impl VisibleNormalSampler for FlippedBatch {
        fn sample_wm_visible(&self, wi: Vec3, u: [f64; 2]) -> Vec3 {
            self.ggx.sample_wm_visible(wi, u)
        }
        fn sample_wm_visible_batch(&self, wi: Vec3, u: &[[f64; 2]], out: &mut [Vec3]) {
            self.ggx.sample_wm_visible_batch(wi, u, out);
            self.flip(out);
        }
    }

    fn records(subject: &Arc<Subject<'static>>) -> Vec<CheckRecord> {
        let ctx = RunContext { seed: 7 };
        let mut plan = plan_normal(subject, "test");
        plan.extend(plan_visible(
            subject,
            &crate::check::sampling::VISIBLE_INCIDENCES,
            "test",
        ));
        plan.iter().map(|p| (p.run)(&ctx)).collect()
    }

    fn user(every: usize) -> Arc<Subject<'static>> {
        let ggx = Ggx::new(0.2, 0.5).unwrap();
        Subject::user(
            Arc::new(FlippedBatch { ggx, every }),
            "flipped batch",
            Hints::default(),
        )
    }

    #[test]
    fn ulps_count_the_doubles_between() {
        assert_eq!(ulps(1.0, 1.0), 0.0);
        assert_eq!(ulps(1.0, 1.0 + f64::EPSILON), 1.0);
        assert_eq!(ulps(1.0, 1.0 - f64::EPSILON / 2.0), 1.0);
        assert_eq!(ulps(0.0, -0.0), 1.0);
        assert_eq!(ulps(-0.5, -0.5), 0.0);
        assert_eq!(ulps(f64::NAN, -f64::NAN), 0.0);
        assert_eq!(ulps(f64::NAN, 0.0), f64::INFINITY);
        assert!(ulps(-0.3, 0.3) > 1e18);
        assert_eq!(ulps(f64::from_bits(1), -f64::from_bits(1)), 3.0);
    }

    #[test]
    fn the_uniforms_start_at_the_edges_and_are_seeded() {
        let u = uniforms(7);
        assert_eq!(u.len(), POINTS);
        assert_eq!(u[0], [0.0, 0.0]);
        assert_eq!(u[3], [ONE_BELOW, ONE_BELOW]);
        assert_eq!(ONE_BELOW, 1.0 - 2f64.powi(-53));
        assert!(u.iter().flatten().all(|x| (0.0..1.0).contains(x)));
        assert_eq!(u, uniforms(7));
        assert_ne!(u, uniforms(8));
    }

    /// The reference GGX (isotropic and anisotropic) agrees bit for bit for normals and within
    /// its stated ulps for visible normals (its batch normalizes by one reciprocal), and
    /// Beckmann bit for bit.
    #[test]
    fn the_reference_samplers_agree_within_their_stated_ulps() {
        for json in [
            r#"{"family":"ggx","alpha":0.3}"#,
            r#"{"family":"ggx","alpha_x":0.2,"alpha_y":0.5}"#,
            r#"{"family":"beckmann","alpha_x":0.3,"alpha_y":0.15}"#,
        ] {
            let spec: ModelSpec = serde_json::from_str(json).unwrap();
            let rs = records(&Subject::reference(&spec).unwrap());
            assert_eq!(rs.len(), 2, "{json}");
            for r in rs {
                assert_eq!(r.verdict, Verdict::Pass, "{json} {r:?}");
                let bound = match (json.contains("ggx"), r.case["sampler"].as_str()) {
                    (true, Some("sample_wm_visible")) => {
                        mfh_reference::ndf::GGX_VISIBLE_BATCH_MAX_ULPS
                    }
                    _ => 0.0,
                };
                assert!(r.value.unwrap() <= bound, "{json} {r:?}");
                assert_eq!(r.tolerance.unwrap().name, "batch_sampler_reference");
                assert!(r.seed.is_some());
            }
        }
    }

    /// A user's batch path with a sign flipped at every 1000th element fails, for the normal
    /// and the visible sampler, and the record names the element and both vectors; the same
    /// model with right batch paths passes at the user tolerance.
    #[test]
    fn a_batch_path_with_a_planted_defect_fails() {
        for r in records(&user(0)) {
            assert_eq!(r.verdict, Verdict::Pass, "{r:?}");
            assert_eq!(r.tolerance.unwrap().name, "batch_sampler");
        }
        let rs = records(&user(1000));
        assert_eq!(rs.len(), 2);
        for r in rs {
            assert_eq!(r.verdict, Verdict::Fail, "{r:?}");
            let at = r.case["worst_index"].as_u64().unwrap();
            assert_eq!(at % 1000, 0, "{r:?}");
            let x = |key: &str| r.case[key][0].as_f64().unwrap();
            // The flipped component, to the wrapped reference GGX's stated ulps.
            let flipped = ulps(x("batch"), -x("scalar"));
            assert!(flipped <= BATCH_SAMPLER_REFERENCE.value, "{r:?}");
            assert!(r.case["worst_u"].is_array());
            assert!(r.value.unwrap() > 1e15);
            if r.case["sampler"] == "sample_wm_visible" {
                assert!(r.case["theta_i"].is_number());
            }
        }
    }
}
