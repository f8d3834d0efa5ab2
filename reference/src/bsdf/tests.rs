//! Unit tests of the reference BSDFs: sample/pdf/eval consistency, reciprocity in both
//! transport conventions, ∫pdf = 1 − failure mass and the albedo by quadrature over the sphere,
//! a stress grid, the spec's typed errors. (The values themselves: `golden_tests.rs`.)

use std::f64::consts::PI;
use std::sync::Arc;

use super::fresnel;
use super::microfacet::upper;
use super::{Bsdf, BsdfError, BsdfSpec, Transport};
use crate::geometry::{dot, from_spherical, Vec3};
use crate::special::gauss_kronrod::{WGK, XGK};

fn spec(text: &str) -> BsdfSpec {
    serde_json::from_str(text).unwrap_or_else(|e| panic!("{text}: {e}"))
}

pub(super) fn build(text: &str) -> Arc<dyn Bsdf> {
    spec(text).build().unwrap_or_else(|e| panic!("{text}: {e}"))
}

/// The R3 low-discrepancy sequence (Roberts 2018: additive recurrence with the powers of
/// 1/φ₃, φ₃ the real root of x⁴ = x + 1): deterministic u ∈ [0, 1)³ that fill the cube evenly,
/// so that sample means converge about as 1/N.
pub(super) fn r3(k: usize) -> [f64; 3] {
    const G: f64 = 1.220_744_084_605_759_5;
    let a = [1.0 / G, 1.0 / (G * G), 1.0 / (G * G * G)];
    a.map(|a| (0.5 + a * k as f64).fract())
}

/// |a − b| / |b| (|a| where b = 0).
fn rel(a: f64, b: f64) -> f64 {
    if b == 0.0 {
        a.abs()
    } else {
        ((a - b) / b).abs()
    }
}

/// The indices on either side of a dielectric of index `eta`: (η on w's side).
fn index(eta: f64, w: Vec3) -> f64 {
    if w[2] > 0.0 {
        1.0
    } else {
        eta
    }
}

/// The configurations every consistency test runs: every sampling route, both masking forms,
/// both transports, both BSDFs, several NDF families.
pub(super) const CONFIGS: &[&str] = &[
    r#"{"bsdf":"dielectric","eta":1.5,"ndf":{"family":"ggx","alpha":0.3},"masking":"height_correlated","sampling":"visible_normals"}"#,
    r#"{"bsdf":"dielectric","eta":0.6666666666666666,"ndf":{"family":"ggx","alpha_x":0.1,"alpha_y":0.5},"masking":"uncorrelated","sampling":"normals","transport":"importance"}"#,
    r#"{"bsdf":"dielectric","eta":1.33,"ndf":{"family":"beckmann","alpha_x":0.4,"alpha_y":0.2},"masking":"height_correlated","sampling":"visible_normals","transport":"importance"}"#,
    r#"{"bsdf":"dielectric","eta":2.4,"ndf":{"family":"std","gamma":3,"alpha":0.4},"sampling":"pseudo_vnis"}"#,
    r#"{"bsdf":"dielectric","eta":1.5,"ndf":{"family":"std","gamma":6,"alpha":0.4},"sampling":"pseudo_vnis","masking":"uncorrelated"}"#,
    r#"{"bsdf":"dielectric","eta":0.75,"ndf":{"family":"std","gamma":5,"alpha":0.1},"sampling":"pseudo_vnis"}"#,
    r#"{"bsdf":"dielectric","eta":1.5,"ndf":{"family":"gtr","gamma":1.5,"alpha":0.3},"sampling":"normals"}"#,
    r#"{"bsdf":"conductor","n":0.18,"k":3.42,"ndf":{"family":"ggx","alpha":0.3}}"#,
    r#"{"bsdf":"conductor","n":1.2,"k":7.0,"fresnel":"schlick","ndf":{"family":"beckmann","alpha_x":0.05,"alpha_y":0.5},"sampling":"normals","masking":"uncorrelated"}"#,
    r#"{"bsdf":"conductor","n":1.5,"k":0.0,"ndf":{"family":"piecewise_linear","x":{"theta":[0.0,0.3,0.8,1.2,1.5707963267948966],"value":[3.0,2.0,0.6,0.1,0.0]}},"sampling":"normals"}"#,
];

/// Incidences: normal, oblique, grazing (cos θ = 1e-3), and for a dielectric the same from
/// inside plus the critical angle ± 0.02 on the side where it exists.
pub(super) fn incidences(eta: Option<f64>) -> Vec<Vec3> {
    let mut out = vec![
        [0.0, 0.0, 1.0],
        from_spherical(0.7, 0.4),
        from_spherical(1.3, 2.0),
        from_spherical(1e-3f64.acos(), 4.0),
    ];
    if let Some(eta) = eta {
        let below: Vec<Vec3> = out.iter().map(|w| [w[1], w[0], -w[2]]).collect();
        out.extend(below);
        let crit = if eta > 1.0 {
            (1.0 / eta).asin()
        } else {
            eta.asin()
        };
        for t in [crit - 0.02, crit + 0.02] {
            let w = from_spherical(t, 1.0);
            out.push(if eta > 1.0 { [w[0], w[1], -w[2]] } else { w });
        }
    }
    out
}

/// The sample's pdf is pdf(wi, wo) and its weight eval/pdf at the sampled wo; every sample is
/// a finite unit vector with pdf > 0 and weight ≥ 0; most samples succeed, and a dielectric
/// lit below the critical angle returns both lobes.
#[test]
fn samples_agree_with_pdf_and_eval() {
    for text in CONFIGS {
        let b = build(text);
        for wi in incidences(b.eta()) {
            let (mut ok, mut refl, mut trans) = (0usize, 0usize, 0usize);
            let n = 1500;
            for k in 0..n {
                let u = r3(k);
                let Some(s) = b.sample(wi, u) else { continue };
                ok += 1;
                let wo = s.wo;
                assert!(
                    wo.iter().all(|c| c.is_finite()) && (dot(wo, wo).sqrt() - 1.0).abs() < 1e-12,
                    "{text} wi {wi:?}: wo {wo:?}"
                );
                if wo[2] * wi[2] > 0.0 {
                    refl += 1;
                } else {
                    trans += 1;
                }
                let (e, p) = b.eval_pdf(wi, wo);
                if k % 16 == 0 {
                    assert_eq!((b.eval(wi, wo), b.pdf(wi, wo)), (e, p));
                }
                assert!(
                    s.pdf > 0.0 && s.weight >= 0.0 && s.weight.is_finite(),
                    "{s:?}"
                );
                assert!(
                    rel(s.pdf, p) <= 1e-14,
                    "{text} wi {wi:?} u {u:?}: {} vs pdf {p}",
                    s.pdf
                );
                assert!(
                    rel(s.weight, e / p) <= 1e-14,
                    "{text} wi {wi:?} u {u:?}: weight {} vs eval/pdf {}",
                    s.weight,
                    e / p
                );
            }
            assert!(
                ok * 2 > n || wi[2].abs() < 0.01,
                "{text} wi {wi:?}: {ok} of {n}"
            );
            if b.eta().is_some() && wi[2].abs() > 0.5 {
                assert!(refl > 0 && trans > 0, "{text} wi {wi:?}: {refl} / {trans}");
            }
            if b.eta().is_none() {
                assert_eq!(trans, 0, "{text}: a conductor transmitted");
            }
        }
    }
}

/// f(wi, wo) = eval/|cos θo|.
fn f(b: &dyn Bsdf, wi: Vec3, wo: Vec3) -> f64 {
    b.eval(wi, wo) / wo[2].abs()
}

/// Reflection: f(wi, wo) = f(wo, wi); refraction: f(wi, wo)/η_o² = f(wo, wi)/η_i² in the
/// importance convention, f(wi, wo)/η_i² = f(wo, wi)/η_o² in the radiance convention (module
/// documentation), on a grid with grazing (cos θ = ±1e-3) and near-critical directions; and the
/// radiance BTDF is the importance one times (η_i/η_o)².
#[test]
fn reciprocity_in_both_transport_conventions() {
    let mut dirs = Vec::new();
    for &t in &[
        0.0,
        0.4,
        0.9,
        1.3,
        1e-3f64.acos(),
        (1.0f64 / 1.5).asin() + 1e-3,
    ] {
        for &p in &[0.0, 1.1, 2.9, 4.4] {
            let w = from_spherical(t, p);
            dirs.push(w);
            dirs.push([w[0], w[1], -w[2]]);
        }
    }
    let (mut checked_r, mut checked_t, mut worst) = (0, 0, 0.0f64);
    for eta in [1.5, 1.0 / 1.5] {
        for (family, alpha) in [("ggx", "0.3"), ("beckmann", "0.5")] {
            let make = |transport: &str, masking: &str| {
                build(&format!(
                    r#"{{"bsdf":"dielectric","eta":{eta},"ndf":{{"family":"{family}","alpha":{alpha}}},"masking":"{masking}","transport":"{transport}"}}"#
                ))
            };
            for masking in ["uncorrelated", "height_correlated"] {
                let imp = make("importance", masking);
                let rad = make("radiance", masking);
                for &wi in &dirs {
                    for &wo in &dirs {
                        let (a, b) = (f(&*imp, wi, wo), f(&*imp, wo, wi));
                        let (ei, eo) = (index(eta, wi), index(eta, wo));
                        let (ra, rb) = (f(&*rad, wi, wo), f(&*rad, wo, wi));
                        if wi[2] * wo[2] > 0.0 {
                            assert!(rel(a, b) <= 1e-12, "{eta} {wi:?} {wo:?}: {a} vs {b}");
                            assert_eq!(ra, a);
                            checked_r += usize::from(a > 0.0);
                        } else {
                            let e = rel(a / (eo * eo), b / (ei * ei));
                            worst = worst.max(e);
                            assert!(e <= 1e-12, "importance {eta} {wi:?} {wo:?}: {a} vs {b}");
                            let e = rel(ra / (ei * ei), rb / (eo * eo));
                            assert!(e <= 1e-12, "radiance {eta} {wi:?} {wo:?}: {ra} vs {rb}");
                            assert!(rel(ra, a * (ei / eo).powi(2)) <= 1e-15);
                            checked_t += usize::from(a > 0.0);
                        }
                    }
                }
            }
        }
    }
    eprintln!(
        "reciprocity: {checked_r} reflection, {checked_t} refraction pairs; worst {worst:.1e}"
    );
    assert!(checked_r > 1000 && checked_t > 1000);
    // Conductors too.
    let c = build(
        r#"{"bsdf":"conductor","n":0.18,"k":3.42,"ndf":{"family":"ggx","alpha_x":0.1,"alpha_y":0.4},"masking":"uncorrelated"}"#,
    );
    for &wi in &dirs {
        for &wo in &dirs {
            assert!(rel(f(&*c, wi, wo), f(&*c, wo, wi)) <= 1e-12);
        }
    }
}

/// ∫ g(wo) dωo over the whole sphere: composite Gauss–Kronrod (15 points) in z = cos θ on
/// `panels` panels per hemisphere, the trapezoid rule (spectrally accurate for periodic
/// integrands) on `nphi` azimuths. `g` returns two integrands at once.
fn sphere_integral(g: &dyn Fn(Vec3) -> (f64, f64), panels: usize, nphi: usize) -> (f64, f64) {
    let mut nodes = Vec::with_capacity(15);
    for j in 0..7 {
        nodes.push((-XGK[j], WGK[j]));
        nodes.push((XGK[j], WGK[j]));
    }
    nodes.push((0.0, WGK[7]));
    let trig: Vec<(f64, f64)> = (0..nphi)
        .map(|k| (2.0 * PI * (k as f64 + 0.5) / nphi as f64).sin_cos())
        .collect();
    let (mut a, mut b) = (0.0, 0.0);
    let h = 1.0 / panels as f64;
    for side in [-1.0, 1.0] {
        for p in 0..panels {
            let c = (p as f64 + 0.5) * h;
            for &(x, w) in &nodes {
                let z = c + 0.5 * h * x;
                let s = (1.0 - z * z).max(0.0).sqrt();
                let (mut ra, mut rb) = (0.0, 0.0);
                for &(sp, cp) in &trig {
                    let (u, v) = g([s * cp, s * sp, side * z]);
                    ra += u;
                    rb += v;
                }
                let wt = 0.5 * h * w * 2.0 * PI / nphi as f64;
                a += wt * ra;
                b += wt * rb;
            }
        }
    }
    (a, b)
}

/// The fraction of failed samples and the mean weight over `n` R3 points.
fn sampled(b: &dyn Bsdf, wi: Vec3, n: usize) -> (f64, f64) {
    let (mut fail, mut sum) = (0usize, 0.0);
    for k in 0..n {
        match b.sample(wi, r3(k)) {
            Some(s) => sum += s.weight,
            None => fail += 1,
        }
    }
    (fail as f64 / n as f64, sum / n as f64)
}

/// ∫ pdf dωo over the sphere (quadrature) = 1 − the failure rate of `sample` (10⁶ R3 points),
/// and ∫ eval dωo (quadrature) = the mean sampled weight: this sees a wrong Jacobian, a lost
/// lobe or a pdf that does not describe the sampler. In the importance convention the albedo
/// is ≤ 1 from either side; normal sampling at grazing incidence fails often (back-facing
/// normals), and the failure mass is accounted for.
#[test]
fn pdf_integrates_to_the_success_rate_and_albedo_to_the_mean_weight() {
    let cases: &[(&str, &[Vec3])] = &[
        (
            r#"{"bsdf":"dielectric","eta":1.5,"ndf":{"family":"ggx","alpha":0.5},"transport":"importance"}"#,
            &[
                [0.0, 0.0, 1.0],
                [0.479425538604203, 0.0, 0.8775825618903728],
                [0.0, -0.963558185417193, -0.26749882862458735],
            ],
        ),
        (
            r#"{"bsdf":"dielectric","eta":0.6666666666666666,"ndf":{"family":"beckmann","alpha_x":0.3,"alpha_y":0.6},"sampling":"normals","masking":"uncorrelated","transport":"importance"}"#,
            // beyond the critical angle (41.8°) from outside, and from inside
            &[
                [0.0, 0.8414709848078965, 0.5403023058681398],
                [0.3, 0.2, -0.9327379053088815],
            ],
        ),
        (
            r#"{"bsdf":"conductor","n":0.18,"k":3.42,"ndf":{"family":"ggx","alpha":0.4},"sampling":"normals"}"#,
            &[[0.963558185417193, 0.0, 0.26749882862458735]],
        ),
    ];
    let mut worst_pdf = 0.0f64;
    let mut worst_albedo = 0.0f64;
    let mut max_fail = 0.0f64;
    for (text, wis) in cases {
        let b = build(text);
        for &wi in *wis {
            let (ieval, ipdf) = sphere_integral(&|wo| b.eval_pdf(wi, wo), 120, 512);
            let (fail, mean_weight) = sampled(&*b, wi, 1 << 20);
            eprintln!(
                "{text} wi {wi:?}: ∫pdf {ipdf:.6} vs 1 − failure {:.6}; ∫eval {ieval:.6} vs mean weight {mean_weight:.6}",
                1.0 - fail
            );
            worst_pdf = worst_pdf.max((ipdf - (1.0 - fail)).abs());
            worst_albedo = worst_albedo.max((ieval - mean_weight).abs());
            max_fail = max_fail.max(fail);
            assert!(ieval <= 1.0 + 1e-3, "albedo {ieval}");
        }
    }
    eprintln!(
        "worst |∫pdf − (1 − failure)| {worst_pdf:.2e}, |∫eval − E weight| {worst_albedo:.2e}"
    );
    assert!(worst_pdf < 3e-3, "{worst_pdf}");
    assert!(worst_albedo < 3e-3, "{worst_albedo}");
    // The check above is not vacuous: some case loses a visible fraction of its samples.
    assert!(max_fail > 0.01, "{max_fail}");
}

/// A smooth-ish GGX dielectric (α = 0.05) in the importance convention reflects or transmits
/// nearly everything (the single-scattering loss is the masking of a few facets): the albedo
/// (mean weight of visible-normal samples, = ∫ eval dωo where eval > 0 ⇒ pdf > 0) is in
/// (0.97, 1]; a conductor's is below 1 and above its Fresnel F0 times the same loss. In the
/// radiance convention the transmitted part is scaled by (η_i/η_o)².
#[test]
fn albedo_of_smooth_dielectrics_is_near_one() {
    for eta in [1.5, 1.0 / 1.5] {
        let imp = build(&format!(
            r#"{{"bsdf":"dielectric","eta":{eta},"ndf":{{"family":"ggx","alpha":0.05}},"transport":"importance"}}"#
        ));
        let rad = build(&format!(
            r#"{{"bsdf":"dielectric","eta":{eta},"ndf":{{"family":"ggx","alpha":0.05}}}}"#
        ));
        for wi in [
            from_spherical(0.3, 0.2),
            from_spherical(1.0, 2.0),
            [0.3, 0.0, -0.953_939_201_416_945_7],
        ] {
            let (fail, albedo) = sampled(&*imp, wi, 1 << 18);
            eprintln!("η {eta} wi {wi:?}: albedo {albedo:.6}, failure {fail:.2e}");
            assert!(
                albedo > 0.97 && albedo <= 1.0,
                "η {eta} wi {wi:?}: {albedo}"
            );
            // Radiance: reflection unchanged, transmission × (η_i/η_o)².
            let ei = index(eta, wi);
            let mut r = 0.0;
            let mut expect = 0.0;
            for k in 0..(1 << 14) {
                if let (Some(a), Some(b)) = (imp.sample(wi, r3(k)), rad.sample(wi, r3(k))) {
                    assert_eq!(a.wo, b.wo);
                    let eo = index(eta, a.wo);
                    expect += a.weight * (ei / eo).powi(2);
                    r += b.weight;
                }
            }
            assert!(rel(r, expect) < 1e-12);
        }
    }
    let c = build(r#"{"bsdf":"conductor","n":0.18,"k":3.42,"ndf":{"family":"ggx","alpha":0.05}}"#);
    let (_, albedo) = sampled(&*c, from_spherical(0.3, 0.0), 1 << 18);
    let f0 = fresnel::f0(0.18, 3.42);
    assert!(albedo < 1.0 && albedo > 0.97 * f0, "{albedo} vs F0 {f0}");
}

/// No NaN, no infinity, no negative value, no panic on a stress grid: α 1e-4 and anisotropy
/// 1:100, cos θ ±1e-6 … ±1, η from 1.0001 to 4 and the inverses, incidence exactly at the
/// critical angle, the degenerate half vectors (wi + wo = 0 at the horizon, wo = −wi), exactly
/// grazing and non-finite directions; pdf = 0 wherever eval = 0 and conversely.
#[test]
fn stress_grid_is_finite() {
    let ndfs = [
        r#"{"family":"ggx","alpha":1e-4}"#,
        r#"{"family":"ggx","alpha_x":0.01,"alpha_y":1.0}"#,
        r#"{"family":"beckmann","alpha":1e-4}"#,
        r#"{"family":"beckmann","alpha_x":1.0,"alpha_y":0.01}"#,
        r#"{"family":"ggx","alpha":1.0}"#,
    ];
    let etas: [f64; 6] = [1.0001, 1.0 / 1.0001, 1.5, 1.0 / 1.5, 4.0, 0.25];
    let mut bsdfs: Vec<(String, Arc<dyn Bsdf>)> = Vec::new();
    for ndf in ndfs {
        for sampling in ["normals", "visible_normals"] {
            for eta in etas {
                let t = format!(
                    r#"{{"bsdf":"dielectric","eta":{eta},"ndf":{ndf},"sampling":"{sampling}"}}"#
                );
                bsdfs.push((t.clone(), build(&t)));
            }
            let t = format!(
                r#"{{"bsdf":"conductor","n":0.18,"k":3.42,"ndf":{ndf},"sampling":"{sampling}"}}"#
            );
            bsdfs.push((t.clone(), build(&t)));
        }
    }
    let mut zs: Vec<f64> = vec![1e-6, 1e-3, 0.3, 0.7, 1.0];
    zs.extend(zs.clone().iter().map(|z| -z));
    for eta in etas {
        // The critical angle on either side: cos θc = √(1 − (η_o/η_i)²).
        let r = if eta > 1.0 { 1.0 / eta } else { eta };
        zs.push((1.0 - r * r).sqrt());
        zs.push(-(1.0 - r * r).sqrt());
    }
    let mut dirs: Vec<Vec3> = Vec::new();
    for &z in &zs {
        for p in [0.0f64, 0.8, 2.5, 4.0] {
            let s = (1.0 - z * z).sqrt();
            dirs.push([s * p.cos(), s * p.sin(), z]);
        }
    }
    let special = [
        ([1.0, 0.0, 0.0], [-1.0, 0.0, 0.0]),
        ([0.6, 0.0, 0.8], [-0.6, 0.0, -0.8]),
        ([0.0, 0.0, 1.0], [0.0, 0.0, -1.0]),
        ([f64::NAN, 0.0, 1.0], [0.0, 0.0, 1.0]),
        ([0.0, 0.0, 1.0], [f64::INFINITY, 0.0, 1.0]),
        ([0.6, 0.0, 0.8], [0.6, 0.0, 0.0]),
    ];
    let edges = [
        [0.0, 0.0, 0.0],
        [1.0 - 1e-16, 1.0 - 1e-16, 1.0 - 1e-16],
        [0.5, 0.0, 1.0 - 1e-16],
        [0.999, 0.5, 0.5],
    ];
    let mut count = 0;
    for (t, b) in &bsdfs {
        let check = |wi: Vec3, wo: Vec3| {
            let (e, p) = b.eval_pdf(wi, wo);
            assert!(e.is_finite() && e >= 0.0, "{t} {wi:?} {wo:?}: eval {e}");
            assert!(p.is_finite() && p >= 0.0, "{t} {wi:?} {wo:?}: pdf {p}");
            assert_eq!(e == 0.0, p == 0.0, "{t} {wi:?} {wo:?}: eval {e} pdf {p}");
        };
        for &wi in &dirs {
            for &wo in &dirs {
                check(wi, wo);
                count += 1;
            }
            for u in edges.iter().copied().chain((0..64).map(r3)) {
                if let Some(s) = b.sample(wi, u) {
                    assert!(
                        s.pdf > 0.0 && s.pdf.is_finite() && s.weight.is_finite() && s.weight >= 0.0,
                        "{t} {wi:?} {u:?}: {s:?}"
                    );
                    assert!(s.wo.iter().all(|c| c.is_finite()));
                }
            }
        }
        for (wi, wo) in special {
            check(wi, wo);
            let _ = b.sample(wi, [0.5, 0.5, 0.5]);
        }
        // Exactly grazing and non-finite: zero and no sample.
        assert_eq!(b.eval_pdf([1.0, 0.0, 0.0], [-1.0, 0.0, 0.0]), (0.0, 0.0));
        assert_eq!(b.eval_pdf([0.6, 0.0, 0.8], [0.6, 0.0, 0.0]), (0.0, 0.0));
        assert!(b.sample([1.0, 0.0, 0.0], [0.5, 0.5, 0.5]).is_none());
        assert!(b.sample([f64::NAN, 0.0, 1.0], [0.5, 0.5, 0.5]).is_none());
    }
    eprintln!("stress: {} BSDFs, {count} (wi, wo) pairs", bsdfs.len());
    // wo = −wi (where the reflection half vector wi + wo vanishes) is the straight-through
    // refraction direction: h_t = ±wi, finite and positive for a dielectric.
    let b = build(r#"{"bsdf":"dielectric","eta":1.5,"ndf":{"family":"ggx","alpha":0.3}}"#);
    let wi = [0.6, 0.0, 0.8];
    let (e, p) = b.eval_pdf(wi, [-0.6, 0.0, -0.8]);
    assert!(e > 0.0 && p > 0.0 && e.is_finite() && p.is_finite());
}

/// A sample's lobe follows u₀ against the Fresnel reflectance of the sampled normal: for a
/// facet-normal incidence on a very smooth surface (α = 1e-3), u₀ below F((η−1)²/(η+1)²)
/// reflects and above it refracts.
#[test]
fn the_lobe_is_chosen_by_the_fresnel_of_the_sampled_normal() {
    let b = build(r#"{"bsdf":"dielectric","eta":1.5,"ndf":{"family":"ggx","alpha":1e-3}}"#);
    let f = fresnel::dielectric(1.0, 1.5).reflectance;
    let wi = [0.0, 0.0, 1.0];
    for (u0, reflects) in [
        (0.5 * f, true),
        (0.99 * f, true),
        (1.01 * f, false),
        (0.9, false),
    ] {
        let s = b.sample(wi, [u0, 0.3, 0.6]).expect("a sample");
        assert_eq!(s.wo[2] > 0.0, reflects, "u0 {u0}, F {f}");
    }
    // Total internal reflection: from inside beyond the critical angle, every sample reflects.
    let wi = from_spherical(PI - 1.0, 0.3);
    for k in 0..200 {
        let s = b.sample(wi, r3(k));
        if let Some(s) = s {
            assert!(s.wo[2] < 0.0, "{s:?}");
        }
    }
    // upper(): the mirror into the upper hemisphere is the point reflection.
    assert_eq!(upper([0.1, -0.2, -0.9]), [-0.1, 0.2, 0.9]);
}

#[test]
fn spec_parses_validates_and_round_trips() {
    let text = r#"{"bsdf":"dielectric","eta":1.5,"ndf":{"family":"ggx","alpha":0.3},"masking":"height_correlated","sampling":"visible_normals"}"#;
    let s = spec(text);
    assert_eq!(s.kind(), "dielectric");
    assert_eq!(s.eta(), Some(1.5));
    assert_eq!(s.ndf().family(), "ggx");
    let b = s.build().unwrap();
    assert_eq!(b.eta(), Some(1.5));
    assert_eq!(b.transport(), Transport::Radiance);
    let out = serde_json::to_string(&s).unwrap();
    assert_eq!(
        out,
        r#"{"bsdf":"dielectric","eta":1.5,"ndf":{"family":"ggx","alpha":0.3},"masking":"height_correlated","sampling":"visible_normals","transport":"radiance"}"#
    );
    assert_eq!(spec(&out), s);
    let c = spec(
        r#"{"bsdf":"conductor","n":0.18,"k":3.42,"fresnel":"schlick","ndf":{"family":"beckmann","alpha":0.2},"masking":"uncorrelated","sampling":"normals"}"#,
    );
    assert_eq!(spec(&serde_json::to_string(&c).unwrap()), c);
    let cb = c.build().unwrap();
    assert_eq!(cb.eta(), None);
    // Unknown keys, unknown kinds and unknown enum values are parse errors naming them.
    for (bad, word) in [
        (
            r#"{"bsdf":"dielectric","eta":1.5,"ndf":{"family":"ggx","alpha":0.3},"roughness":2}"#,
            "roughness",
        ),
        (
            r#"{"bsdf":"plastic","ndf":{"family":"ggx","alpha":0.3}}"#,
            "plastic",
        ),
        (
            r#"{"bsdf":"conductor","n":1,"k":1,"eta":1.5,"ndf":{"family":"ggx","alpha":0.3}}"#,
            "eta",
        ),
        (
            r#"{"bsdf":"dielectric","eta":1.5,"ndf":{"family":"ggx","alpha":0.3},"sampling":"vndf"}"#,
            "vndf",
        ),
        (
            r#"{"bsdf":"dielectric","ndf":{"family":"ggx","alpha":0.3}}"#,
            "eta",
        ),
    ] {
        let e = serde_json::from_str::<BsdfSpec>(bad)
            .unwrap_err()
            .to_string();
        assert!(e.contains(word), "{bad}: {e}");
    }
    // Typed errors naming the field and the limit.
    let err = |t: &str| spec(t).build().map(|_| ()).unwrap_err();
    let cases: Vec<(String, &str, &str)> = vec![
        (r#"{"bsdf":"dielectric","eta":1.0,"ndf":{"family":"ggx","alpha":0.3}}"#.into(), "eta", "5e-5"),
        (r#"{"bsdf":"dielectric","eta":1.00001,"ndf":{"family":"ggx","alpha":0.3}}"#.into(), "eta", "5e-5"),
        (r#"{"bsdf":"dielectric","eta":20,"ndf":{"family":"ggx","alpha":0.3}}"#.into(), "eta", "[0.1, 10]"),
        (r#"{"bsdf":"dielectric","eta":1.0001,"ndf":{"family":"ggx","alpha":1e-7}}"#.into(), "eta", "1e-10/alpha"),
        (r#"{"bsdf":"conductor","n":1,"k":3,"ndf":{"family":"beckmann","alpha_x":0.5,"alpha_y":1e-3}}"#.into(), "ndf.alpha_x", "factor of 100"),
        (r#"{"bsdf":"dielectric","eta":-1.5,"ndf":{"family":"ggx","alpha":0.3}}"#.into(), "eta", "[0.1, 10]"),
        (r#"{"bsdf":"conductor","n":-1,"k":3,"ndf":{"family":"ggx","alpha":0.3}}"#.into(), "n", "[1e-3, 100]"),
        (r#"{"bsdf":"conductor","n":1,"k":300,"ndf":{"family":"ggx","alpha":0.3}}"#.into(), "k", "[0, 100]"),
        (r#"{"bsdf":"dielectric","eta":1.5,"ndf":{"family":"ggx","alpha":-0.3}}"#.into(), "ndf", "alpha"),
        (r#"{"bsdf":"dielectric","eta":1.5,"ndf":{"family":"std","gamma":1.2,"alpha":0.3}}"#.into(), "ndf", "std"),
        (r#"{"bsdf":"dielectric","eta":1.5,"ndf":{"family":"blend","x":{"family":"ggx","alpha":0.2},"y":{"family":"beckmann","alpha":0.4}},"sampling":"normals"}"#.into(), "sampling", "blend"),
        (r#"{"bsdf":"dielectric","eta":1.5,"ndf":{"family":"gtr","gamma":1.5,"alpha":0.3}}"#.into(), "sampling", "visible"),
        (r#"{"bsdf":"dielectric","eta":1.5,"ndf":{"family":"ggx","alpha":0.3},"sampling":"pseudo_vnis"}"#.into(), "sampling", "std"),
        (r#"{"bsdf":"dielectric","eta":1.5,"ndf":{"family":"std","gamma":"inf","alpha":0.3},"sampling":"pseudo_vnis"}"#.into(), "sampling", "inf"),
    ];
    for (t, field, limit) in cases {
        let e = err(&t);
        let msg = e.to_string();
        assert_eq!(e.field(), field, "{t}: {msg}");
        assert!(msg.contains(limit), "{t}: {msg}");
        assert!(msg.starts_with(field), "{t}: {msg}");
        assert!(spec(&t).validate().is_err());
    }
    assert!(matches!(
        err(r#"{"bsdf":"dielectric","eta":1.5,"ndf":{"family":"std","gamma":1.2,"alpha":0.3}}"#),
        BsdfError::NoSmith { .. }
    ));
    // η = 1.0001 and its inverse are accepted (the stress range).
    for eta in [1.0001, 1.0 / 1.0001, 4.0, 0.25] {
        spec(&format!(
            r#"{{"bsdf":"dielectric","eta":{eta},"ndf":{{"family":"ggx","alpha":0.3}}}}"#
        ))
        .validate()
        .unwrap();
    }
}

/// Every registered family with a Smith Λ and a normal sampler builds a conductor and a
/// dielectric that sample consistently (the BSDF is built on any such NDF).
#[test]
fn every_registered_family_with_smith_builds() {
    let mut built = 0;
    for info in crate::registry::FAMILIES {
        for example in info.examples {
            let ndf: crate::ModelSpec = serde_json::from_str(example).unwrap();
            for sampling in ["normals", "visible_normals"] {
                let t = format!(
                    r#"{{"bsdf":"dielectric","eta":1.5,"ndf":{example},"sampling":"{sampling}"}}"#
                );
                let Ok(b) = spec(&t).build() else {
                    let e = spec(&t).build().map(|_| ()).unwrap_err();
                    assert!(
                        matches!(e, BsdfError::NoSampler { .. } | BsdfError::NoSmith { .. }),
                        "{t}: {e}"
                    );
                    continue;
                };
                built += 1;
                let wi = from_spherical(0.6, 0.3);
                for k in 0..200 {
                    if let Some(s) = b.sample(wi, r3(k)) {
                        assert!(rel(s.pdf, b.pdf(wi, s.wo)) <= 1e-14, "{t}");
                    }
                }
                assert_eq!(spec(&t).ndf(), &ndf);
            }
        }
    }
    assert!(built >= 8, "{built}");
}
