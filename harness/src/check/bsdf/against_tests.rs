//! `bsdf.against` reports nothing that is not a defect, and every defect of the values: a
//! correct dielectric written as a renderer writes it (a concentric disk map, the other u order,
//! its own tangent frame, pbrt-v4's grazing guard on D) passes; the reference with its eval or
//! its pdf 1e-3 off in a small cone anywhere in its lobes fails; a float32 BSDF stating η in
//! float32 passes; two-sidedness is compared.

use super::against::GRAZING_GUARD_COS;
use super::*;
use crate::audit::Audit;
use crate::check::{Profile, RunContext};
use crate::precision::Precision;
use crate::record::{CheckRecord, Verdict};
use mfh_reference::bsdf::{fresnel, BsdfSpec, Transport};
use mfh_reference::geometry::dot;

const DIELECTRIC: &str = r#"{"bsdf":"dielectric","eta":1.5,"ndf":{"family":"ggx","alpha":0.3}}"#;

fn spec(text: &str) -> BsdfSpec {
    serde_json::from_str(text).unwrap()
}

/// The `bsdf.against` records (and `audit.precision`) of the public gate's plan for `b` against
/// `text`, declared at `precision`.
fn against(b: &dyn Bsdf, text: &str, precision: Precision) -> Vec<CheckRecord> {
    let (plan, errors) = Audit::of_bsdf(&b)
        .profile(Profile::Ci)
        .precision(precision)
        .against(text)
        .plan();
    let mut records: Vec<CheckRecord> = plan
        .iter()
        .filter(|p| p.check == "bsdf.against")
        .map(|p| (p.run)(&RunContext { seed: 7 }))
        .collect();
    assert_eq!(records.len(), 3);
    records.extend(errors);
    records
}

fn failures(records: &[CheckRecord]) -> Vec<String> {
    records
        .iter()
        .filter(|r| r.verdict.is_failure())
        .map(|r| format!("{} {} {:?} {:?}", r.check, r.case, r.verdict, r.measured))
        .collect()
}

fn normalize(v: Vec3) -> Vec3 {
    let l = dot(v, v).sqrt();
    [v[0] / l, v[1] / l, v[2] / l]
}

fn cross(a: Vec3, b: Vec3) -> Vec3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// Shirley & Chiu 1997's concentric map of the unit square onto the unit disk.
fn concentric(u: [f64; 2]) -> (f64, f64) {
    let (a, b) = (2.0 * u[0] - 1.0, 2.0 * u[1] - 1.0);
    if a == 0.0 && b == 0.0 {
        return (0.0, 0.0);
    }
    let (r, phi) = if a.abs() > b.abs() {
        (a, std::f64::consts::FRAC_PI_4 * (b / a))
    } else {
        (
            b,
            std::f64::consts::FRAC_PI_2 - std::f64::consts::FRAC_PI_4 * (a / b),
        )
    };
    (r * phi.cos(), r * phi.sin())
}

/// A correct GGX dielectric written as a renderer writes it: eval and pdf are the reference's
/// (Walter 2007) but for pbrt-v4's guard on D (cos⁴θh < 1e-16 → D = 0, so eval = pdf = 0);
/// `sample` draws GGX's visible normals (Heitz 2018, "Sampling the GGX distribution of visible
/// normals", JCGT 7(4), listing 1) with the *concentric* disk map of (u2, u1) — the other u
/// order — and the tangent frame T1 = (−V_y, V_x, 0)/|…| of that listing, then chooses the lobe
/// with u0 against the exact Fresnel reflectance (Walter §5.3).
struct RendererDielectric {
    reference: Arc<dyn Bsdf>,
    alpha: f64,
    eta: f64,
}

impl RendererDielectric {
    fn new() -> Self {
        Self {
            reference: spec(DIELECTRIC).build().unwrap(),
            alpha: 0.3,
            eta: 1.5,
        }
    }

    /// Whether pbrt-v4's guard zeroes D at the half vector of (wi, wo).
    fn guarded(&self, wi: Vec3, wo: Vec3) -> bool {
        let h = if wi[2] * wo[2] > 0.0 {
            [wi[0] + wo[0], wi[1] + wo[1], wi[2] + wo[2]]
        } else {
            let (ei, eo) = if wi[2] > 0.0 {
                (1.0, self.eta)
            } else {
                (self.eta, 1.0)
            };
            [
                ei * wi[0] + eo * wo[0],
                ei * wi[1] + eo * wo[1],
                ei * wi[2] + eo * wo[2],
            ]
        };
        let c = normalize(h)[2];
        c.powi(4) < 1e-16
    }

    /// Heitz 2018's visible GGX normal for wi⁺ (z > 0) from the disk point of `u`.
    fn visible_normal(&self, v: Vec3, u: [f64; 2]) -> Vec3 {
        let a = self.alpha;
        let vh = normalize([a * v[0], a * v[1], v[2]]);
        let len2 = vh[0] * vh[0] + vh[1] * vh[1];
        let t1 = if len2 > 0.0 {
            let l = len2.sqrt();
            [-vh[1] / l, vh[0] / l, 0.0]
        } else {
            [1.0, 0.0, 0.0]
        };
        let t2 = cross(vh, t1);
        let (p1, p2) = concentric(u);
        let s = 0.5 * (1.0 + vh[2]);
        let p2 = (1.0 - s) * (1.0 - p1 * p1).max(0.0).sqrt() + s * p2;
        let nz = (1.0 - p1 * p1 - p2 * p2).max(0.0).sqrt();
        let nh = [
            p1 * t1[0] + p2 * t2[0] + nz * vh[0],
            p1 * t1[1] + p2 * t2[1] + nz * vh[1],
            p1 * t1[2] + p2 * t2[2] + nz * vh[2],
        ];
        normalize([a * nh[0], a * nh[1], nh[2].max(0.0)])
    }
}

impl Bsdf for RendererDielectric {
    fn eval(&self, wi: Vec3, wo: Vec3) -> f64 {
        if self.guarded(wi, wo) {
            return 0.0;
        }
        self.reference.eval(wi, wo)
    }

    fn pdf(&self, wi: Vec3, wo: Vec3) -> f64 {
        if self.guarded(wi, wo) {
            return 0.0;
        }
        self.reference.pdf(wi, wo)
    }

    fn sample(&self, wi: Vec3, u: [f64; 3]) -> Option<BsdfSample> {
        if !(wi[2] != 0.0) {
            return None;
        }
        let outside = wi[2] > 0.0;
        let v = if outside {
            wi
        } else {
            [-wi[0], -wi[1], -wi[2]]
        };
        // The other u order: u2 first.
        let m = self.visible_normal(v, [u[2], u[1]]);
        let c = dot(wi, m);
        let ratio = if outside { self.eta } else { 1.0 / self.eta };
        let f = fresnel::dielectric(c, ratio);
        let wo = if u[0] < f.reflectance {
            [
                2.0 * c * m[0] - wi[0],
                2.0 * c * m[1] - wi[1],
                2.0 * c * m[2] - wi[2],
            ]
        } else {
            // Refraction: wo = −wi/η′ + (c/η′ − cos θt) m, oriented against wi's side of m.
            let s = c.signum();
            let (ms, cs) = ([s * m[0], s * m[1], s * m[2]], c.abs());
            let r = 1.0 / ratio;
            let ct = f.cos_t;
            normalize([
                -r * wi[0] + (r * cs - ct) * ms[0],
                -r * wi[1] + (r * cs - ct) * ms[1],
                -r * wi[2] + (r * cs - ct) * ms[2],
            ])
        };
        let reflect = u[0] < f.reflectance;
        if (wo[2] * wi[2] > 0.0) != reflect || wo[2] == 0.0 {
            return None;
        }
        BsdfSample::at(wo, (self.eval(wi, wo), self.pdf(wi, wo)))
    }

    fn eta(&self) -> Option<f64> {
        Some(self.eta)
    }

    fn transport(&self) -> Transport {
        Transport::Radiance
    }
}

/// The correct renderer dielectric passes `bsdf.against`, and its guard and its map are what
/// the comparison was blind to: the guard zeroes pairs the grid holds (counted as excused), and
/// its sampled directions differ from the reference's for the same u by radians.
#[test]
fn a_renderers_correct_dielectric_passes() {
    let b = RendererDielectric::new();
    let records = against(&b, DIELECTRIC, Precision::F64);
    assert_eq!(failures(&records), Vec::<String>::new());
    let excused: u64 = records
        .iter()
        .filter(|r| r.check == "bsdf.against" && r.case["quantity"] != "sample")
        .map(|r| r.case["excused_grazing_guard"].as_u64().unwrap())
        .sum();
    let sample = records
        .iter()
        .find(|r| r.case["quantity"] == "sample")
        .unwrap();
    eprintln!(
        "excused by the grazing guard (eval + pdf): {excused}; sample record: {} {:?}",
        sample.case, sample.measured
    );
    for r in records.iter().filter(|r| r.check == "bsdf.against") {
        eprintln!(
            "{}: worst {:?}, excused {} (worst excused error {})",
            r.case["quantity"],
            r.measured,
            r.case["excused_grazing_guard"],
            r.case["worst_excused_error"]
        );
    }
    assert!(excused > 0, "the guard zeroes no compared pair");
    // The map differs from the reference's: the same u gives another direction.
    let wi = [0.6, 0.0, 0.8];
    let u = [0.7, 0.2, 0.9];
    let (x, y) = (
        b.sample(wi, u).unwrap().wo,
        b.reference.sample(wi, u).unwrap().wo,
    );
    assert!(dot(x, y) < 1.0 - 1e-6, "{x:?} {y:?}");
    // It samples the reference's distribution: its samples' pdf is the reference's (the
    // `sample` record) and the chi-square of its directions at the oblique incidence passes.
    let subject = BsdfSubject::user(Arc::new(b), "renderer", None, Precision::F64);
    let inc = incidences(subject.bsdf.as_ref())[1];
    let shared = Integrals::new(inc.wi, Profile::Ci.chi2_samples());
    let r = (chi2::plan(&subject, inc, &shared, Profile::Ci, "test").run)(&RunContext { seed: 7 });
    assert_eq!(r.verdict, Verdict::Pass, "{:?} {:?}", r.case, r.measured);
}

/// The reference with eval or pdf multiplied by 1 + 1e-3 within 0.05 rad of a direction in its
/// lobes: the reflection and the refraction lobe at oblique incidence, each at the peak and in
/// the tail, from outside and inside. `bsdf.against` fails on the quantity, and counts the
/// pairs that differ.
#[test]
fn a_1e_3_error_anywhere_in_the_lobes_fails() {
    struct Off {
        reference: Arc<dyn Bsdf>,
        centre: Vec3,
        pdf: bool,
    }
    impl Off {
        fn factor(&self, wo: Vec3) -> f64 {
            if dot(wo, self.centre) > 0.05f64.cos() {
                1.0 + 1e-3
            } else {
                1.0
            }
        }
    }
    impl Bsdf for Off {
        fn eval(&self, wi: Vec3, wo: Vec3) -> f64 {
            let f = if self.pdf { 1.0 } else { self.factor(wo) };
            self.reference.eval(wi, wo) * f
        }
        fn pdf(&self, wi: Vec3, wo: Vec3) -> f64 {
            let f = if self.pdf { self.factor(wo) } else { 1.0 };
            self.reference.pdf(wi, wo) * f
        }
        fn sample(&self, wi: Vec3, u: [f64; 3]) -> Option<BsdfSample> {
            let s = self.reference.sample(wi, u)?;
            BsdfSample::at(s.wo, (self.eval(wi, s.wo), self.pdf(wi, s.wo)))
        }
        fn eta(&self) -> Option<f64> {
            self.reference.eta()
        }
    }
    let reference = spec(DIELECTRIC).build().unwrap();
    let incs = incidences(reference.as_ref());
    // (incidence, u): the reflection peak and tail, the refraction peak and tail.
    let places = [
        (1, [0.01, 0.5, 0.5]),
        (1, [0.01, 0.9, 0.8]),
        (1, [0.9, 0.5, 0.5]),
        (1, [0.9, 0.95, 0.3]),
        (3, [0.9, 0.5, 0.5]),
        (0, [0.9, 0.9, 0.1]),
    ];
    for (k, (inc, u)) in places.into_iter().enumerate() {
        let centre = reference
            .sample(incs[inc].wi, u)
            .unwrap_or_else(|| panic!("place {k}: no sample"))
            .wo;
        let pdf = k % 2 == 1;
        let b = Off {
            reference: reference.clone(),
            centre,
            pdf,
        };
        let records = against(&b, DIELECTRIC, Precision::F64);
        let quantity = if pdf { "pdf" } else { "eval" };
        let r = records
            .iter()
            .find(|r| r.case["quantity"] == quantity)
            .unwrap();
        eprintln!(
            "{quantity} off near {centre:?}: {:?} {:?}, {} of {} pairs differ",
            r.verdict, r.measured, r.case["differ"], r.case["pairs"]
        );
        assert_eq!(r.verdict, Verdict::Fail, "{quantity} near {centre:?}");
        assert!(r.case["differ"].as_u64().unwrap() >= 1);
        assert!(r.case["differing"]
            .as_array()
            .is_some_and(|d| !d.is_empty()));
    }
}

/// A float32 BSDF (answers rounded to float32) stating η = 1/1.5 in float32 (0.6666667) passes
/// against the spec's 1/1.5, compared at f32; an f64 one stating the same η fails.
#[test]
fn eta_is_compared_at_the_declared_precision() {
    struct Float32 {
        reference: Arc<dyn Bsdf>,
        round: bool,
    }
    impl Float32 {
        fn rounded(&self, x: f64) -> f64 {
            if self.round {
                f64::from(x as f32)
            } else {
                x
            }
        }
    }
    impl Bsdf for Float32 {
        fn eval(&self, wi: Vec3, wo: Vec3) -> f64 {
            self.rounded(self.reference.eval(wi, wo))
        }
        fn pdf(&self, wi: Vec3, wo: Vec3) -> f64 {
            self.rounded(self.reference.pdf(wi, wo))
        }
        fn sample(&self, wi: Vec3, u: [f64; 3]) -> Option<BsdfSample> {
            let s = self.reference.sample(wi, u)?;
            BsdfSample::at(s.wo, (self.eval(wi, s.wo), self.pdf(wi, s.wo)))
        }
        fn eta(&self) -> Option<f64> {
            Some(f64::from(1.0f32 / 1.5f32))
        }
    }
    let text =
        r#"{"bsdf":"dielectric","eta":0.6666666666666666,"ndf":{"family":"ggx","alpha":0.3}}"#;
    let mut b = Float32 {
        reference: spec(text).build().unwrap(),
        round: true,
    };
    assert_eq!(
        failures(&against(&b, text, Precision::F32)),
        Vec::<String>::new()
    );
    b.round = false;
    let records = against(&b, text, Precision::F64);
    let mismatch: Vec<_> = records
        .iter()
        .filter(|r| r.case.get("mismatch").is_some())
        .collect();
    assert_eq!(mismatch.len(), 3, "{:?}", failures(&records));
}

/// A two-sided conductor passes against a two-sided spec and is audited from below; the
/// one-sided one fails against it on the declaration, and the reverse too.
#[test]
fn two_sidedness_is_declared_compared_and_audited_from_below() {
    let two = r#"{"bsdf":"conductor","n":0.2,"k":3.4,"two_sided":true,"ndf":{"family":"ggx","alpha":0.3}}"#;
    let one = r#"{"bsdf":"conductor","n":0.2,"k":3.4,"ndf":{"family":"ggx","alpha":0.3}}"#;
    let b2 = spec(two).build().unwrap();
    let b1 = spec(one).build().unwrap();
    let below: Vec<_> = incidences(b2.as_ref())
        .into_iter()
        .filter(|i| i.wi[2] < 0.0)
        .map(|i| i.name)
        .collect();
    assert_eq!(below, ["back_oblique", "back_grazing"]);
    assert!(incidences(b1.as_ref()).iter().all(|i| i.wi[2] > 0.0));
    assert_eq!(
        failures(&against(b2.as_ref(), two, Precision::F64)),
        Vec::<String>::new()
    );
    for (b, text) in [(&b1, two), (&b2, one)] {
        let records = against(b.as_ref(), text, Precision::F64);
        assert!(
            records
                .iter()
                .filter(|r| r.check == "bsdf.against")
                .all(|r| r.verdict == Verdict::Fail
                    && r.case["mismatch"].as_str().unwrap().contains("two_sided")),
            "{:?}",
            failures(&records)
        );
    }
    // The whole ci audit of the two-sided reference conductor passes, from below too.
    let subject = BsdfSubject::reference(&spec(two)).unwrap();
    let plan = super::plan(&subject, Profile::Ci, "test");
    let records: Vec<CheckRecord> = plan
        .iter()
        .enumerate()
        .map(|(i, p)| {
            (p.run)(&RunContext {
                seed: 11 + i as u64,
            })
        })
        .collect();
    assert!(records
        .iter()
        .any(|r| r.case["incidence"] == "back_grazing"));
    assert_eq!(failures(&records), Vec::<String>::new());
}

/// The guard's band is pbrt-v4's: cos⁴θ < 1e-16.
#[test]
fn the_grazing_band_is_pbrts_guard() {
    assert!((GRAZING_GUARD_COS.powi(4) / 1e-16 - 1.0).abs() < 1e-12);
}

/// The precision lie: a BSDF declared float32 whose answers are f64 values, with sample
/// weights 5e-4 too large. Judged at f32 that error is inside every tolerance; the precision
/// probe sees f64 answers, `audit.precision` fails saying so, and the audit judges it at f64,
/// where `bsdf.sample_consistency` fails on the weight.
#[test]
fn a_bsdf_declared_f32_that_answers_f64_is_judged_at_f64() {
    struct Heavy(Arc<dyn Bsdf>);
    impl Bsdf for Heavy {
        fn eval(&self, wi: Vec3, wo: Vec3) -> f64 {
            self.0.eval(wi, wo)
        }
        fn pdf(&self, wi: Vec3, wo: Vec3) -> f64 {
            self.0.pdf(wi, wo)
        }
        fn sample(&self, wi: Vec3, u: [f64; 3]) -> Option<BsdfSample> {
            let s = self.0.sample(wi, u)?;
            Some(BsdfSample {
                weight: s.weight * (1.0 + 5e-4),
                ..s
            })
        }
        fn eta(&self) -> Option<f64> {
            self.0.eta()
        }
    }
    let b = Heavy(spec(DIELECTRIC).build().unwrap());
    let (plan, errors) = Audit::of_bsdf(&b)
        .profile(Profile::Ci)
        .precision(Precision::F32)
        .plan();
    let probe = errors
        .iter()
        .find(|r| r.check == "audit.precision")
        .unwrap();
    assert!(
        matches!(&probe.verdict, Verdict::Error { message } if message.contains("computes in f64")),
        "{probe:?}"
    );
    assert_eq!(probe.precision, Precision::F64);
    let consistency = plan
        .iter()
        .find(|p| p.check == "bsdf.sample_consistency" && p.case["incidence"] == "oblique")
        .unwrap();
    let r = (consistency.run)(&RunContext { seed: 7 });
    assert_eq!(r.precision, Precision::F64);
    assert_eq!(r.verdict, Verdict::Fail, "{:?} {:?}", r.case, r.measured);
}
