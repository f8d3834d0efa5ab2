//! `bsdf.ndf_consistency`: a BSDF that offers the NDF it is built on (its D and Smith Λ)
//! against Walter 2007's microfacet BSDF built from that D and Λ. The Fresnel factor is the
//! BSDF's own business (exact, Schlick, a measured table), so it is not compared with a
//! formula; what is well defined is what remains once D, G2 and the Jacobians are divided out:
//!
//! ```text
//! reflection (eq 20):   R(wi, wo) = eval · 4|wi·n| / (D(h) G2(wi, wo, h))              = F(c)
//! refraction (eq 21):   T(wi, wo) = eval · |wi·n| (η_i(wi·h) + η_o(wo·h))²
//!                                   / (|wi·h||wo·h| η_o² D(h) G2 · t)                 = 1 − F(c)
//! ```
//!
//! with h the half vector of eq 13 (reflection) or eq 16 (refraction, h·n > 0), c = |wi·h|,
//! η_i, η_o the indices on wi's and wo's sides, t the transport's factor (1 for importance,
//! (η_i/η_o)² for radiance; `mfh_reference::bsdf::Transport`) and `eval` = f·|wo·n|. So:
//!
//! 1. **reflection**: R depends on c alone (on each side of the surface: from inside F is the
//!    Fresnel factor of 1/η) and lies in [0, 1];
//! 2. **transmission** (a BSDF that declares η): T = 1 − F(c) with F the reflection factor on
//!    wi's side at the same c (F_r + F_t = 1, eq 22's two sides);
//! 3. **visible_normal_pdf** (a BSDF that declares visible-normal sampling, Heitz & d'Eon 2014
//!    eq 2, with Walter §5.3's lobe choice by F): pdf = G1(wi) D(h) / (4|wi·n|) for a
//!    reflection-only BSDF (eq 14), and pdf = eval · G1(wi) / (G2 · t) for a transmitting one
//!    (eq 14 and 17: F or 1 − F is the lobe's probability as well as its value).
//!
//! **Which G2.** G2 is uncorrelated, G1(wi)G1(wo), or height-correlated,
//! 1/(1 + Λ(wi⁺) + Λ(wo⁺)) (w⁺ = ±w above the surface; reference/src/bsdf/microfacet.rs). The
//! two agree exactly where wi or wo is the normal (Λ(n) = 0): with wi = ±n and h at θ_h = θ_d
//! the reflection factor F(cos θ_d) is known whatever the form, for θ_d < π/4 (wo stays above
//! the horizon). Those pairs are the references; every other pair at the same c (h tilted, wi
//! turned about h, so that D(h), Λ(wi) and Λ(wo) all change while c does not) must give the
//! same factor. Beyond π/4 the reference is the pair mirrored about the normal (h = n), under
//! the form. A declared form is used; an undeclared one is the form under which reflection's
//! worst error is smaller, and the records say which (and both forms' errors). A D or Λ that is not the NDF's changes the
//! factor with the tilt of h and the incidence (GGX α × 1.01: ±2 %), under either form.
//!
//! Directions stay 0.05 away from the horizon in cosine (where the relations are well
//! conditioned), refracted cosines above 0.1 (away from the critical angle).

use super::BsdfSubject;
use crate::check::{applied, covers, Check, PlannedCheck};
use crate::record::{CheckRecord, Measured, Verdict};
use crate::subject::bsdf::OwnNdf;
use crate::tolerance::{Tolerance, BSDF_NDF_CONSISTENCY};
use mfh_reference::bsdf::microfacet::{reflect, upper};
use mfh_reference::geometry::{cross, dot, from_spherical, normalize, Vec3};
use mfh_reference::{Bsdf, Masking};
use serde_json::{json, Value};
use std::sync::{Arc, OnceLock};

/// What these checks cite.
const SOURCE: &str = "Walter et al. 2007 (seed 001 [13]) eq 20 (reflection), eq 21–22 \
                      (refraction, F_r + F_t = 1), eq 14 and 17 with Heitz & d'Eon 2014 eq 2 \
                      (visible-normal pdf)";

/// The least |cos θ| of a direction, and of a refracted direction's facet cosine.
const MIN_COS: f64 = 0.05;
/// The least cosine of a refracted direction on its facet (away from the critical angle).
const MIN_COS_T: f64 = 0.1;
/// D below this is out of resolution (a subnormal quotient).
const D_MIN: f64 = 1e-250;
/// The angles θ_d between wi and h (c = cos θ_d); the first four (< π/4) have a reference
/// with wi at the normal.
const THETA_D: [f64; 7] = [0.1, 0.3, 0.5, 0.7, 0.9, 1.1, 1.3];
/// The tilts θ_h of the half vector, and its azimuths.
const THETA_H: [f64; 5] = [0.0, 0.2, 0.45, 0.7, 1.0];
const PHI_H: [f64; 2] = [0.3, 1.9];
/// The turns of wi about h.
const PSI: usize = 6;
/// The azimuth of the references' half vector.
const PHI_REF: f64 = 0.3;

/// Which lobe a pair is in.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Lobe {
    Reflection,
    Transmission,
}

/// A direction pair, what the BSDF and the NDF answer there, and the factor that turns
/// eval / (D G2) into the Fresnel factor.
#[derive(Debug, Clone, Copy)]
struct Point {
    wi: Vec3,
    wo: Vec3,
    lobe: Lobe,
    /// (side of wi, θ_d index): the pairs that share c.
    group: usize,
    /// Whether it is its group's reference (reflection, wi at the normal or h = n).
    reference: bool,
    c: f64,
    eval: f64,
    pdf: f64,
    d: f64,
    lambda_i: f64,
    lambda_o: f64,
    /// 4|wi·n| (reflection), |wi·n||v|²/(|wi·h||wo·h| η_o² t) (refraction).
    k: f64,
    /// The transport factor t (1 for reflection).
    t: f64,
}

/// G2 of `form` from Λ(wi⁺) and Λ(wo⁺) (the side conditions hold at every pair).
fn g2(form: Masking, li: f64, lo: f64) -> f64 {
    match form {
        Masking::Uncorrelated => 1.0 / ((1.0 + li) * (1.0 + lo)),
        Masking::HeightCorrelated => 1.0 / (1.0 + li + lo),
    }
}

fn form_name(form: Masking) -> &'static str {
    match form {
        Masking::Uncorrelated => "uncorrelated",
        Masking::HeightCorrelated => "height_correlated",
    }
}

impl Point {
    /// The Fresnel factor eval·k/(D G2) under `form`; None where it cannot be resolved (D and
    /// eval both 0, or D subnormal); ∞ where the BSDF has a value the NDF has no facet for.
    fn factor(&self, form: Masking) -> Option<f64> {
        let g = g2(form, self.lambda_i, self.lambda_o);
        if self.d == 0.0 || !(g > 0.0) {
            return (self.eval != 0.0).then_some(f64::INFINITY);
        }
        if !(self.d >= D_MIN) || !g.is_finite() {
            return None;
        }
        Some(self.eval * self.k / (self.d * g))
    }
}

/// The unit vector at angle `theta` from the unit vector `m`, turned by `psi` about it.
fn about(m: Vec3, theta: f64, psi: f64) -> Vec3 {
    let t = if m[2].abs() < 0.9 {
        [0.0, 0.0, 1.0]
    } else {
        [1.0, 0.0, 0.0]
    };
    let b = normalize(cross(m, t));
    let t = cross(b, m);
    let (s, c) = theta.sin_cos();
    let (sp, cp) = psi.sin_cos();
    normalize(std::array::from_fn(|k| {
        s * cp * t[k] + s * sp * b[k] + c * m[k]
    }))
}

fn neg(v: Vec3) -> Vec3 {
    [-v[0], -v[1], -v[2]]
}

/// The pairs (wi, wo, lobe, group, reference) of a BSDF of relative index `eta`: reflection
/// on each side it is lit from, refraction both ways where it transmits.
fn pairs(eta: Option<f64>) -> Vec<(Vec3, Vec3, Lobe, usize, bool)> {
    let sides: &[f64] = if eta.is_some() { &[1.0, -1.0] } else { &[1.0] };
    let mut out = Vec::new();
    for (si, &s) in sides.iter().enumerate() {
        for (j, &theta_d) in THETA_D.iter().enumerate() {
            let group = si * THETA_D.len() + j;
            // The reference: wi at the normal (θ_d < π/4), else h = n.
            let (m, v) = if (2.0 * theta_d).cos() >= MIN_COS {
                let m = from_spherical(theta_d, PHI_REF);
                (m, [0.0, 0.0, 1.0])
            } else {
                ([0.0, 0.0, 1.0], from_spherical(theta_d, PHI_REF))
            };
            let at = |v: Vec3| if s > 0.0 { v } else { neg(v) };
            out.push((at(v), at(reflect(v, m)), Lobe::Reflection, group, true));
            let mut facets = vec![(m, v)];
            for &theta_h in &THETA_H {
                for &phi_h in &PHI_H {
                    let m = from_spherical(theta_h, phi_h);
                    for k in 0..PSI {
                        let psi = 0.2 + std::f64::consts::TAU * k as f64 / PSI as f64;
                        facets.push((m, about(m, theta_d, psi)));
                    }
                }
            }
            for (k, &(m, v)) in facets.iter().enumerate() {
                let r = reflect(v, m);
                if k > 0 && v[2] >= MIN_COS && r[2] >= MIN_COS {
                    out.push((at(v), at(r), Lobe::Reflection, group, false));
                }
                let Some(eta) = eta else { continue };
                // Refraction of wi = at(v) through m into the other side.
                let (eta_i, eta_o) = if s > 0.0 { (1.0, eta) } else { (eta, 1.0) };
                let e = eta_i / eta_o;
                let c = theta_d.cos();
                let cos_t2 = 1.0 - e * e * (1.0 - c * c);
                if !(cos_t2 >= MIN_COS_T * MIN_COS_T) || v[2] < MIN_COS {
                    continue;
                }
                let wi = at(v);
                let sign = dot(wi, m).signum();
                let kk = (e * c - cos_t2.sqrt()) * sign;
                let wo: Vec3 = std::array::from_fn(|q| -e * wi[q] + kk * m[q]);
                if wo[2].abs() >= MIN_COS && wo[2] * wi[2] < 0.0 {
                    out.push((wi, normalize(wo), Lobe::Transmission, group, false));
                }
            }
        }
    }
    out
}

/// Everything the records need, computed once for all of them.
struct Analysis {
    points: Vec<Point>,
    evaluations: u64,
}

/// The BSDF and its NDF at every pair; `Err` names what the NDF lacks.
fn analyse(bsdf: &dyn Bsdf, own: &OwnNdf<'_>) -> Result<Analysis, String> {
    let smith = own
        .ndf
        .as_smith()
        .ok_or("the NDF has no Smith Λ (capability `lambda`)")?;
    let eta = bsdf.eta();
    let transport = bsdf.transport();
    let raw = pairs(eta);
    let wi: Vec<Vec3> = raw.iter().map(|p| p.0).collect();
    let wo: Vec<Vec3> = raw.iter().map(|p| p.1).collect();
    let n = raw.len();
    let mut evals = vec![0.0; n];
    bsdf.eval_batch(&wi, &wo, &mut evals);
    let mut pdfs = vec![0.0; n];
    if own.visible_normals {
        bsdf.pdf_batch(&wi, &wo, &mut pdfs);
    }
    let index = |w: Vec3| if w[2] > 0.0 { 1.0 } else { eta.unwrap_or(1.0) };
    // The half vectors of eq 13 and 16 (h·n > 0), from the pair as the BSDF sees it.
    let hs: Vec<(Vec3, f64)> = raw
        .iter()
        .map(|&(wi, wo, lobe, ..)| {
            let (a, b) = match lobe {
                Lobe::Reflection => (1.0, 1.0),
                Lobe::Transmission => (index(wi), index(wo)),
            };
            let v: Vec3 = std::array::from_fn(|q| a * wi[q] + b * wo[q]);
            let len2 = dot(v, v);
            let s = if v[2] > 0.0 { 1.0 } else { -1.0 } / len2.sqrt();
            (v.map(|x| s * x), len2)
        })
        .collect();
    let h: Vec<Vec3> = hs.iter().map(|x| x.0).collect();
    let mut d = vec![0.0; n];
    own.ndf.d_batch(&h, &mut d);
    let (mut li, mut lo) = (vec![0.0; n], vec![0.0; n]);
    smith.lambda_batch(&wi.iter().map(|&w| upper(w)).collect::<Vec<_>>(), &mut li);
    smith.lambda_batch(&wo.iter().map(|&w| upper(w)).collect::<Vec<_>>(), &mut lo);
    let mut points = Vec::with_capacity(n);
    for (q, &(wi, wo, lobe, group, reference)) in raw.iter().enumerate() {
        let (h, len2) = hs[q];
        let (cim, com) = (dot(wi, h), dot(wo, h));
        // The side conditions (χ⁺ of G2): both directions see h from its front.
        if !(h[2] > 0.0 && cim * wi[2] > 0.0 && com * wo[2] > 0.0) {
            continue;
        }
        let (eta_i, eta_o) = (index(wi), index(wo));
        let (k, t) = match lobe {
            Lobe::Reflection => (4.0 * wi[2].abs(), 1.0),
            Lobe::Transmission => {
                let t = transport.factor(eta_i, eta_o);
                let k = wi[2].abs() * len2 / (cim.abs() * com.abs() * eta_o * eta_o * t);
                (k, t)
            }
        };
        points.push(Point {
            wi,
            wo,
            lobe,
            group,
            reference,
            c: cim.abs(),
            eval: evals[q],
            pdf: pdfs[q],
            d: d[q],
            lambda_i: li[q],
            lambda_o: lo[q],
            k,
            t,
        });
    }
    let visible = if own.visible_normals { n } else { 0 };
    Ok(Analysis {
        points,
        evaluations: (4 * n + visible) as u64,
    })
}

/// |a − b| / max(|a|, |b|) (0 where both are 0; ∞ for NaN).
fn discrepancy(a: f64, b: f64) -> f64 {
    let scale = a.abs().max(b.abs());
    if scale == 0.0 {
        0.0
    } else if (a - b).is_nan() || scale.is_infinite() {
        f64::INFINITY
    } else {
        (a - b).abs() / scale
    }
}

/// How far a Fresnel factor is outside [0, 1].
fn outside_unit(x: f64) -> f64 {
    if x.is_nan() {
        f64::INFINITY
    } else {
        (x - 1.0).max(-x).max(0.0)
    }
}

/// The worst error of one relation, where, and how many pairs it compared.
#[derive(Debug, Clone, Default)]
struct Worst {
    error: f64,
    at: Value,
    compared: u64,
}

impl Worst {
    fn push(&mut self, error: f64, p: &Point, value: f64, expected: f64) {
        self.compared += 1;
        let error = if error.is_nan() { f64::INFINITY } else { error };
        if error > self.error || self.at.is_null() {
            self.error = error;
            self.at = json!({
                "wi": p.wi, "wo": p.wo, "cos_wi_h": p.c, "value": value, "expected": expected,
            });
        }
    }
}

/// The reflection and transmission relations under `form`.
fn fresnel_relations(points: &[Point], form: Masking) -> (Worst, Worst) {
    let groups = 2 * THETA_D.len();
    let mut reference = vec![None; groups];
    for p in points.iter().filter(|p| p.reference) {
        reference[p.group] = p.factor(form);
    }
    let (mut r, mut t) = (Worst::default(), Worst::default());
    for p in points {
        let (Some(value), Some(f)) = (p.factor(form), reference[p.group]) else {
            continue;
        };
        match p.lobe {
            Lobe::Reflection => {
                r.push(discrepancy(value, f).max(outside_unit(value)), p, value, f);
            }
            Lobe::Transmission => {
                let error = discrepancy(value, 1.0 - f).max(outside_unit(value));
                t.push(error, p, value, 1.0 - f);
            }
        }
    }
    (r, t)
}

/// The visible-normal pdf relation under `form`.
fn pdf_relation(points: &[Point], form: Masking, transmits: bool) -> Worst {
    let mut w = Worst::default();
    for p in points {
        let g1 = 1.0 / (1.0 + p.lambda_i);
        let expected = if transmits {
            p.eval * g1 / (g2(form, p.lambda_i, p.lambda_o) * p.t)
        } else {
            g1 * p.d / (4.0 * p.wi[2].abs())
        };
        if p.d > 0.0 && p.d < D_MIN {
            continue; // out of resolution
        }
        w.push(discrepancy(p.pdf, expected), p, p.pdf, expected);
    }
    w
}

/// The form the records judge under: the declared one, else the one under which reflection
/// (which no η², Jacobian of refraction or lobe choice enters) fits better, transmission
/// deciding a tie (both exact: Λ ≈ 0); with the worst errors under both when fitted.
fn choose_form(points: &[Point], declared: Option<Masking>) -> (Masking, Value) {
    if let Some(form) = declared {
        return (form, json!({"masking": form_name(form), "declared": true}));
    }
    let worst = |form| {
        let (r, t) = fresnel_relations(points, form);
        (r.error, t.error)
    };
    let (u, hc) = (
        worst(Masking::Uncorrelated),
        worst(Masking::HeightCorrelated),
    );
    let form = if u.0 < hc.0 || (u.0 == hc.0 && u.1 < hc.1) {
        Masking::Uncorrelated
    } else {
        Masking::HeightCorrelated
    };
    let info = json!({
        "masking": form_name(form),
        "declared": false,
        "uncorrelated": {"reflection": u.0, "transmission": u.1},
        "height_correlated": {"reflection": hc.0, "transmission": hc.1},
    });
    (form, info)
}

/// The relations a subject is checked on.
const RELATIONS: [&str; 3] = ["reflection", "transmission", "visible_normal_pdf"];

/// Plans the NDF-consistency checks of `subject`: none unless it offers its NDF with a Smith Λ;
/// reflection always, transmission where it declares η, the visible-normal pdf where it
/// declares that sampling.
pub fn plan<'a>(subject: &Arc<BsdfSubject<'a>>, why: &str) -> Vec<PlannedCheck<'a>> {
    let Some(own) = &subject.own_ndf else {
        return Vec::new();
    };
    if own.ndf.as_smith().is_none() {
        return Vec::new();
    }
    let eta = subject.bsdf.eta();
    let shared: Arc<OnceLock<Result<Analysis, String>>> = Arc::new(OnceLock::new());
    let mut out = Vec::new();
    for (k, relation) in RELATIONS.into_iter().enumerate() {
        if (k == 1 && eta.is_none()) || (k == 2 && !own.visible_normals) {
            continue;
        }
        let (s, own, shared) = (subject.clone(), own.clone(), shared.clone());
        let case = json!({
            "relation": relation,
            "eta": eta,
            "transport": subject.bsdf.transport().name(),
        });
        let what = match relation {
            "reflection" => {
                "eval/(D G2) of reflection is a Fresnel factor of |wi·h| alone, in [0, 1]"
            }
            "transmission" => {
                "eval/(D G2 · Jacobian · η²) of refraction is 1 − the reflection factor"
            }
            _ => "the pdf is the visible-normal density of the NDF through Walter's Jacobians",
        };
        out.push(
            Check::new("bsdf.ndf_consistency", subject.label.clone(), case, SOURCE)
                .why(format!("{why}: the BSDF offers its NDF (D, Λ): {what}"))
                .covers(vec![covers(
                    subject.family(),
                    "bsdf_eval",
                    "ndf_consistency",
                )])
                .run(move |r, _| {
                    let analysis = shared.get_or_init(|| analyse(s.bsdf.as_ref(), &own));
                    let transmits = s.bsdf.eta().is_some();
                    let tolerance = BSDF_NDF_CONSISTENCY.at(s.precision);
                    judge(r, analysis, (&own, tolerance), relation, transmits);
                    Ok(())
                }),
        );
    }
    out
}

/// Fills the record of `relation` from the shared analysis.
fn judge(
    r: &mut CheckRecord,
    analysis: &Result<Analysis, String>,
    (own, tolerance): (&OwnNdf<'_>, Tolerance),
    relation: &str,
    transmits: bool,
) {
    let a = match analysis {
        Ok(a) => a,
        Err(message) => {
            r.verdict = Verdict::Error {
                message: message.clone(),
            };
            return;
        }
    };
    if relation == "reflection" {
        // The evaluations are billed to one record (the others share them).
        r.cost.evaluations += a.evaluations;
    }
    let (form, masking) = choose_form(&a.points, own.masking);
    let worst = match relation {
        "reflection" => fresnel_relations(&a.points, form).0,
        "transmission" => fresnel_relations(&a.points, form).1,
        _ => pdf_relation(&a.points, form, transmits),
    };
    if let Value::Object(case) = &mut r.case {
        case.insert("g2".into(), masking);
        case.insert("pairs".into(), json!(worst.compared));
        case.insert("worst".into(), worst.at.clone());
    }
    r.tolerance = Some(applied(&tolerance));
    if worst.compared == 0 {
        r.verdict = Verdict::Error {
            message: format!(
                "no direction pair of the {relation} relation could be compared (D below \
                 {D_MIN:e} or no value wherever the relation is defined)"
            ),
        };
        return;
    }
    r.value = Some(worst.error);
    r.measured = Some(Measured::Relative { error: worst.error });
    r.verdict = if worst.error <= tolerance.value {
        Verdict::Pass
    } else {
        Verdict::Fail
    };
}

#[cfg(test)]
#[path = "ndf_tests.rs"]
mod tests;
