//! float32 BSDFs under audit: a rough GGX dielectric written as pbrt-v4's
//! `DielectricBxDF` writes it and a rough GGX conductor with Schlick's Fresnel, both in f32
//! arithmetic, handed over as f64. Declared `Precision::F32` they pass the `ci` profile with
//! `.against` their reference spec and `.ndf` their own float32 GGX (no false alarm from
//! float32 rounding); audited as f64, `audit.precision` names them float32; a planted
//! refraction defect fails on its named check.
//!
//! Conventions (mfh's, `reference/src/bsdf/mod.rs`): wi is the camera side (pbrt's wo), wo
//! the sampled side (pbrt's wi); eval = f·|cos θo|; radiance transport (pbrt's
//! `TransportMode::Radiance`: the BTDF divided by η′², η′ the far side's index over wi's).

#[path = "common/ggx32.rs"]
mod ggx32;
#[path = "common/verdicts.rs"]
mod verdicts;

use ggx32::{normalize, v32, v64, Ggx32};
use mfh_harness::run::AuditReport;
use mfh_harness::{Audit, Precision, Profile, Sampling};
use mfh_reference::{Bsdf, BsdfSample, Masking, Vec3};
use verdicts::{assert_fails_on, assert_named_float32, failing};

/// Which defect the float32 dielectric carries.
#[derive(Clone, Copy, PartialEq)]
enum Defect {
    None,
    /// The refraction Jacobian with the camera side's cosine |wi·m| for |wo·m| (in pdf and
    /// sample alike, so they stay consistent with each other).
    JacobianWithWi,
    /// Radiance transport without its 1/η′² (in eval and sample alike).
    NoEtaSquared,
    /// The pdf `sample` returns 0.2 % high (pdf itself right).
    SamplePdf,
}

fn dot(a: [f32; 3], b: [f32; 3]) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn neg(a: [f32; 3]) -> [f32; 3] {
    [-a[0], -a[1], -a[2]]
}

/// v above the surface: v or −v.
fn upper(v: [f32; 3]) -> [f32; 3] {
    if v[2] < 0.0 {
        neg(v)
    } else {
        v
    }
}

/// pbrt-v4's `FrDielectric`: cos θ of the incident side, η the far side's index over it.
fn fr_dielectric(cos: f32, eta: f32) -> f32 {
    let (mut c, mut eta) = (cos.clamp(-1.0, 1.0), eta);
    if c < 0.0 {
        eta = 1.0 / eta;
        c = -c;
    }
    let sin2_t = (1.0 - c * c) / (eta * eta);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin2_t).max(0.0).sqrt();
    let r_parl = (eta * c - cos_t) / (eta * c + cos_t);
    let r_perp = (c - eta * cos_t) / (c + eta * cos_t);
    (r_parl * r_parl + r_perp * r_perp) / 2.0
}

/// pbrt-v4's `Refract`: w refracted through n (either side), with the relative index it used.
fn refract(w: [f32; 3], n: [f32; 3], eta: f32) -> Option<([f32; 3], f32)> {
    let (mut cos_i, mut eta, mut n) = (dot(n, w), eta, n);
    if cos_i < 0.0 {
        eta = 1.0 / eta;
        cos_i = -cos_i;
        n = neg(n);
    }
    let sin2_t = (1.0 - cos_i * cos_i).max(0.0) / (eta * eta);
    if sin2_t >= 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).max(0.0).sqrt();
    let k = cos_i / eta - cos_t;
    Some((
        [
            -w[0] / eta + k * n[0],
            -w[1] / eta + k * n[1],
            -w[2] / eta + k * n[2],
        ],
        eta,
    ))
}

/// u in float32 as a renderer's sampler gives it: below 1 (an f64 u < 1 may round to 1.0).
fn u32(u: f64) -> f32 {
    (u as f32).min(1.0 - f32::EPSILON / 2.0)
}

fn reflect(w: [f32; 3], m: [f32; 3]) -> [f32; 3] {
    let c = 2.0 * dot(w, m);
    [c * m[0] - w[0], c * m[1] - w[1], c * m[2] - w[2]]
}

/// The microfacet terms both BSDFs share, on the float32 GGX (with pbrt-v4's D when `.1`).
struct Facets(Ggx32, bool);

impl Facets {
    /// Λ of a direction on either side (pbrt's Λ is even in cos θ).
    fn lambda(&self, w: [f32; 3]) -> f32 {
        self.0.lambda32(upper(w))
    }
    /// Height-correlated G2 (pbrt-v4's `G`).
    fn g2(&self, a: [f32; 3], b: [f32; 3]) -> f32 {
        1.0 / (1.0 + self.lambda(a) + self.lambda(b))
    }
    /// D(m) as Mitsuba 3 writes it, 1/(π α² (x²/α² + y²/α² + z²)²): finite up to the
    /// horizon without a guard. (pbrt-v4's form, `Ggx32::d32`, returns 0 where cos⁴θ < 1e-16,
    /// i.e. within 1e-4 rad of the horizon, where D is far from 0: `bsdf.against` accepts
    /// that as a guard, see `pbrts_grazing_guard_passes_against_and_is_counted`.)
    fn d(&self, m: [f32; 3]) -> f32 {
        if self.1 {
            return self.0.d32(m);
        }
        if !(m[2] > 0.0) {
            return 0.0;
        }
        let a2 = self.0.alpha * self.0.alpha;
        let s = (m[0] * m[0] + m[1] * m[1]) / a2 + m[2] * m[2];
        1.0 / (std::f32::consts::PI * a2 * s * s)
    }
    /// The visible-normal density of m seen from w (pbrt-v4's `D(w, wm)`).
    fn visible_pdf(&self, w: [f32; 3], m: [f32; 3]) -> f32 {
        let w = upper(w);
        self.0.g1_32(w) * self.d(m) * dot(w, m).abs() / w[2]
    }
}

/// A rough GGX dielectric as pbrt-v4's `DielectricBxDF` (rough path), in f32.
struct Glass32 {
    eta: f32,
    facets: Facets,
    defect: Defect,
}

impl Glass32 {
    fn new(eta: f32, alpha: f32, defect: Defect) -> Self {
        Self {
            eta,
            facets: Facets(Ggx32::new(alpha), false),
            defect,
        }
    }

    /// The refraction Jacobian |dωm/dωo| as pbrt-v4 writes it, with the defect's cosine.
    fn jacobian(&self, i: [f32; 3], o: [f32; 3], m: [f32; 3], etap: f32) -> f32 {
        let denom = dot(o, m) + dot(i, m) / etap;
        let c = if self.defect == Defect::JacobianWithWi {
            dot(i, m)
        } else {
            dot(o, m)
        };
        c.abs() / (denom * denom)
    }

    /// The radiance-transport factor 1/η′² of the BTDF.
    fn transport(&self, etap: f32) -> f32 {
        if self.defect == Defect::NoEtaSquared {
            1.0
        } else {
            1.0 / (etap * etap)
        }
    }

    /// (f·|cos θo|, pdf) at (i, o), pbrt-v4's `f` and `PDF`.
    fn eval_pdf32(&self, i: [f32; 3], o: [f32; 3]) -> (f32, f32) {
        let (ci, co) = (i[2], o[2]);
        if ci == 0.0 || co == 0.0 {
            return (0.0, 0.0);
        }
        let reflect = ci * co > 0.0;
        let etap = match (reflect, ci > 0.0) {
            (true, _) => 1.0,
            (false, true) => self.eta,
            (false, false) => 1.0 / self.eta,
        };
        let wm = [o[0] * etap + i[0], o[1] * etap + i[1], o[2] * etap + i[2]];
        if dot(wm, wm) == 0.0 {
            return (0.0, 0.0);
        }
        let wm = upper(normalize(wm));
        if dot(wm, o) * co < 0.0 || dot(wm, i) * ci < 0.0 {
            return (0.0, 0.0);
        }
        let r = fr_dielectric(dot(i, wm), self.eta);
        let d = self.facets.d(wm);
        let g = self.facets.g2(i, o);
        let p = self.facets.visible_pdf(i, wm);
        if reflect {
            let f = r * d * g / (4.0 * ci * co).abs();
            (f * co.abs(), p / (4.0 * dot(i, wm).abs()) * r)
        } else {
            let t = 1.0 - r;
            let denom = dot(o, wm) + dot(i, wm) / etap;
            let denom = denom * denom * ci * co;
            let f = t * d * g * (dot(o, wm) * dot(i, wm) / denom).abs() * self.transport(etap);
            (f * co.abs(), p * self.jacobian(i, o, wm, etap) * t)
        }
    }
}

impl Bsdf for Glass32 {
    fn eval(&self, wi: Vec3, wo: Vec3) -> f64 {
        f64::from(self.eval_pdf32(v32(wi), v32(wo)).0)
    }
    fn pdf(&self, wi: Vec3, wo: Vec3) -> f64 {
        f64::from(self.eval_pdf32(v32(wi), v32(wo)).1)
    }
    /// pbrt-v4's `Sample_f`: m from the visible normals at wi⁺, reflect if u₀ < F.
    fn sample(&self, wi: Vec3, u: [f64; 3]) -> Option<BsdfSample> {
        let i = v32(wi);
        if i[2] == 0.0 {
            return None;
        }
        let m = self.facets.0.visible32(upper(i), u32(u[1]), u32(u[2]));
        let r = fr_dielectric(dot(i, m), self.eta);
        let p = self.facets.visible_pdf(i, m);
        let d = self.facets.d(m);
        let (o, f, pdf) = if u32(u[0]) < r {
            let o = reflect(i, m);
            if o[2] * i[2] <= 0.0 {
                return None;
            }
            let f = d * self.facets.g2(i, o) * r / (4.0 * i[2] * o[2]).abs();
            (o, f, p / (4.0 * dot(i, m).abs()) * r)
        } else {
            let (o, etap) = refract(i, m, self.eta)?;
            if o[2] * i[2] >= 0.0 || o[2] == 0.0 {
                return None;
            }
            let t = 1.0 - r;
            let denom = dot(o, m) + dot(i, m) / etap;
            let denom = denom * denom;
            let f = t * d * self.facets.g2(i, o) * (dot(o, m) * dot(i, m)).abs()
                / (i[2] * o[2] * denom).abs()
                * self.transport(etap);
            (o, f, p * self.jacobian(i, o, m, etap) * t)
        };
        if !(pdf > 0.0) || !pdf.is_finite() {
            return None;
        }
        let weight = f * o[2].abs() / pdf;
        let pdf = if self.defect == Defect::SamplePdf {
            pdf * 1.002
        } else {
            pdf
        };
        Some(BsdfSample {
            wo: v64(o),
            pdf: f64::from(pdf),
            weight: f64::from(weight),
        })
    }
    fn eta(&self) -> Option<f64> {
        Some(f64::from(self.eta))
    }
}

/// A rough GGX conductor with Schlick's Fresnel (F0 from n + ik), one-sided, in f32.
struct Metal32 {
    f0: f32,
    facets: Facets,
}

impl Metal32 {
    fn new(n: f32, k: f32, alpha: f32) -> Self {
        let f0 = ((n - 1.0) * (n - 1.0) + k * k) / ((n + 1.0) * (n + 1.0) + k * k);
        Self {
            f0,
            facets: Facets(Ggx32::new(alpha), false),
        }
    }

    fn fresnel(&self, c: f32) -> f32 {
        let x = 1.0 - c.abs().min(1.0);
        self.f0 + (1.0 - self.f0) * x * x * x * x * x
    }

    fn eval_pdf32(&self, i: [f32; 3], o: [f32; 3]) -> (f32, f32) {
        if !(i[2] > 0.0 && o[2] > 0.0) {
            return (0.0, 0.0);
        }
        let h = [i[0] + o[0], i[1] + o[1], i[2] + o[2]];
        if dot(h, h) == 0.0 {
            return (0.0, 0.0);
        }
        let m = normalize(h);
        let c = dot(i, m);
        let f = self.fresnel(c) * self.facets.d(m) * self.facets.g2(i, o) / (4.0 * i[2]);
        (f, self.facets.visible_pdf(i, m) / (4.0 * c))
    }
}

impl Bsdf for Metal32 {
    fn eval(&self, wi: Vec3, wo: Vec3) -> f64 {
        f64::from(self.eval_pdf32(v32(wi), v32(wo)).0)
    }
    fn pdf(&self, wi: Vec3, wo: Vec3) -> f64 {
        f64::from(self.eval_pdf32(v32(wi), v32(wo)).1)
    }
    fn sample(&self, wi: Vec3, u: [f64; 3]) -> Option<BsdfSample> {
        let i = v32(wi);
        if !(i[2] > 0.0) {
            return None;
        }
        let m = self.facets.0.visible32(i, u32(u[1]), u32(u[2]));
        let o = reflect(i, m);
        if !(o[2] > 0.0) {
            return None;
        }
        let (f, pdf) = self.eval_pdf32(i, o);
        if !(pdf > 0.0) {
            return None;
        }
        Some(BsdfSample {
            wo: v64(o),
            pdf: f64::from(pdf),
            weight: f64::from(f / pdf),
        })
    }
}

const GLASS: &str = r#"{"bsdf":"dielectric","eta":1.5,"ndf":{"family":"ggx","alpha":0.3},
    "masking":"height_correlated","sampling":"visible_normals","transport":"radiance"}"#;
const METAL: &str = r#"{"bsdf":"conductor","n":0.2,"k":3.0,"fresnel":"schlick",
    "ndf":{"family":"ggx","alpha":0.3},"masking":"height_correlated",
    "sampling":"visible_normals"}"#;

/// The audit of a float32 BSDF on its own float32 GGX, against `spec`, at `precision`.
fn audit<B: Bsdf>(bsdf: &B, ndf: &Ggx32, spec: &str, precision: Precision) -> AuditReport {
    Audit::of_bsdf(bsdf)
        .ndf(ndf)
        .masking(Some(Masking::HeightCorrelated))
        .sampling(Some(Sampling::VisibleNormals))
        .against(spec)
        .precision(precision)
        .profile(Profile::Ci)
        .run()
}

/// Prints each check's worst measured value against its tolerance (the budgets' evidence).
fn print_worst(what: &str, report: &AuditReport) {
    let mut worst: std::collections::BTreeMap<String, (f64, f64)> = Default::default();
    for r in &report.records {
        if let (Some(m), Some(t)) = (&r.measured, &r.tolerance) {
            if let Some(v) = m.error() {
                let e = worst
                    .entry(format!("{} ({})", r.check, t.name))
                    .or_insert((0.0, t.value));
                e.0 = e.0.max(v);
            }
        }
    }
    eprintln!(
        "{what}: {} records in {:.1} s",
        report.records.len(),
        report.summary.wall_seconds
    );
    for (check, (v, t)) in worst {
        eprintln!("  {check:60} worst {v:.3e}  tolerance {t:.3e}");
    }
}

#[test]
fn a_float32_dielectric_declared_f32_passes_the_ci_profile() {
    let b = Glass32::new(1.5, 0.3, Defect::None);
    let report = audit(&b, &b.facets.0, GLASS, Precision::F32);
    print_worst("float32 dielectric", &report);
    assert!(report.passed(), "{:#?}", failing(&report));
    assert!(report.records.iter().all(|r| r.precision == Precision::F32));
    for check in [
        "bsdf.chi2",
        "bsdf.sample_consistency",
        "bsdf.reciprocity",
        "bsdf.against",
        "bsdf.albedo",
        "bsdf.ndf_consistency",
    ] {
        assert!(
            report.records.iter().any(|r| r.check == check),
            "no {check} record"
        );
    }
}

#[test]
fn a_float32_conductor_declared_f32_passes_the_ci_profile() {
    let b = Metal32::new(0.2, 3.0, 0.3);
    let report = audit(&b, &b.facets.0, METAL, Precision::F32);
    print_worst("float32 conductor", &report);
    assert!(report.passed(), "{:#?}", failing(&report));
}

#[test]
fn a_float32_dielectric_audited_as_f64_is_named_by_audit_precision() {
    let b = Glass32::new(1.5, 0.3, Defect::None);
    let report = audit(&b, &b.facets.0, GLASS, Precision::F64);
    assert_named_float32(&report);
}

#[test]
fn a_float32_refraction_jacobian_with_wi_fails_the_chi_square() {
    let b = Glass32::new(1.5, 0.3, Defect::JacobianWithWi);
    let report = audit(&b, &b.facets.0, GLASS, Precision::F32);
    assert_fails_on(&report, "bsdf.chi2", "");
}

#[test]
fn a_float32_radiance_btdf_without_eta_squared_fails_reciprocity() {
    let b = Glass32::new(1.5, 0.3, Defect::NoEtaSquared);
    let report = audit(&b, &b.facets.0, GLASS, Precision::F32);
    assert_fails_on(&report, "bsdf.reciprocity", "");
}

/// pbrt-v4's GGX D returns 0 where cos⁴θ < 1e-16 (within 1e-4 rad of the horizon), where D is
/// far from 0 (α²/π at the horizon): a float32 BSDF on it differs from the reference by 100 %
/// at the grazing pairs of `bsdf.against` (cos θ = 1e-6 on both sides). That is a renderer's
/// guard, not a defect: `bsdf.against` accepts a value between 0 and the reference's where the
/// half vector is within cos θh < 1e-4 of the horizon, counts those pairs, and the audit passes.
#[test]
fn pbrts_grazing_guard_passes_against_and_is_counted() {
    let mut b = Glass32::new(1.5, 0.3, Defect::None);
    b.facets.1 = true;
    let report = audit(&b, &b.facets.0, GLASS, Precision::F32);
    assert!(report.passed(), "{:#?}", failing(&report));
    let excused: u64 = report
        .records
        .iter()
        .filter(|r| r.check == "bsdf.against")
        .filter_map(|r| r.case["excused_grazing_guard"].as_u64())
        .sum();
    assert!(excused > 0, "no pair in the grazing band");
}

/// Tiny roughness in float32 (α = 0.001, a near-mirror): no false alarm. At normal incidence
/// every weight of the conductor is the same float32 number, 9 ε₃₂ off the f64 integral of
/// its eval, with a standard error of 0: `bsdf.albedo` allows the weights' rounding (64 ε of
/// the declared precision) and passes.
#[test]
fn float32_bsdfs_at_tiny_roughness_pass() {
    let glass = r#"{"bsdf":"dielectric","eta":1.5,"ndf":{"family":"ggx","alpha":0.001},
        "masking":"height_correlated","sampling":"visible_normals","transport":"radiance"}"#;
    let metal = r#"{"bsdf":"conductor","n":0.2,"k":3.0,"fresnel":"schlick",
        "ndf":{"family":"ggx","alpha":0.001},"masking":"height_correlated",
        "sampling":"visible_normals"}"#;
    let g = Glass32::new(1.5, 0.001, Defect::None);
    let report = audit(&g, &g.facets.0, glass, Precision::F32);
    print_worst("float32 dielectric, α = 0.001", &report);
    assert!(report.passed(), "{:#?}", failing(&report));
    let m = Metal32::new(0.2, 3.0, 0.001);
    let report = audit(&m, &m.facets.0, metal, Precision::F32);
    print_worst("float32 conductor, α = 0.001", &report);
    assert!(report.passed(), "{:#?}", failing(&report));
}

/// A sample pdf 0.2 % high is not excused by the consistency check's conditioning allowance
/// (which only the samples near the critical angle and the horizon use): it fails.
#[test]
fn a_float32_sample_pdf_two_permille_high_fails_consistency() {
    let b = Glass32::new(1.5, 0.3, Defect::SamplePdf);
    let report = audit(&b, &b.facets.0, GLASS, Precision::F32);
    assert_fails_on(&report, "bsdf.sample_consistency", "");
}
