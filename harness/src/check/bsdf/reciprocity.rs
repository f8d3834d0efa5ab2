//! `bsdf.reciprocity`: f(wi, wo) = f(wo, wi) for reflection; for refraction the η² relation of
//! the BSDF's stated transport ([`mfh_reference::bsdf::Transport`]): importance
//! f(wi, wo)/η_o² = f(wo, wi)/η_i², radiance f(wi, wo)/η_i² = f(wo, wi)/η_o², η_i and η_o the
//! indices on wi's and wo's sides. On a grid of direction pairs that includes normal and grazing
//! (cos θ = 1e-6) directions on both sides and, for a transmitting BSDF, directions at the
//! critical angle ± 1e-9 rad on the denser side.

use super::{BsdfSubject, SOURCE};
use crate::check::{applied, covers, Check, PlannedCheck};
use crate::record::{Measured, Verdict};
use crate::tolerance::BSDF_RECIPROCITY;
use mfh_reference::bsdf::{Bsdf, Transport};
use mfh_reference::geometry::Vec3;
use serde_json::{json, Value};
use std::sync::Arc;

/// Directions of the grid: cos θ of each, on the outside (the grid adds the inside mirror).
const COSINES: [f64; 6] = [1.0, 0.9, 0.5, 0.2, 0.05, 1e-6];
/// Azimuths of the grid (radians): the pairs differ by each.
const AZIMUTHS: [f64; 3] = [0.0, 0.7, std::f64::consts::PI];

/// The direction at cos θ = `c` (z < 0 if `inside`) and azimuth `phi`.
pub fn direction(c: f64, phi: f64, inside: bool) -> Vec3 {
    let s = (1.0 - c * c).max(0.0).sqrt();
    [s * phi.cos(), s * phi.sin(), if inside { -c } else { c }]
}

/// The directions of the grid (both sides), with the near-critical ones of a transmitting BSDF.
pub fn directions(eta: Option<f64>) -> Vec<Vec3> {
    let mut cosines = COSINES.to_vec();
    let mut dense_side: Option<bool> = None;
    if let Some(eta) = eta {
        let critical = eta.min(1.0 / eta).asin();
        for d in [-1e-9, 0.0, 1e-9] {
            cosines.push((critical + d).cos());
        }
        dense_side = Some(eta > 1.0);
    }
    let mut out = Vec::new();
    for (k, &c) in cosines.iter().enumerate() {
        for (j, &phi) in AZIMUTHS.iter().enumerate() {
            for inside in [false, true] {
                // The near-critical cosines only on the denser side.
                if k >= COSINES.len() && dense_side != Some(inside) {
                    continue;
                }
                out.push(direction(c, phi + 0.1 * j as f64, inside));
            }
        }
    }
    out
}

/// f(wi, wo) = eval / |cos θo|.
fn f(bsdf: &dyn Bsdf, wi: Vec3, wo: Vec3) -> f64 {
    bsdf.eval(wi, wo) / wo[2].abs()
}

/// |a − b| / max(|a|, |b|) (0 where both are 0; 1 where one is 0; ∞ for NaN).
fn discrepancy(a: f64, b: f64) -> f64 {
    let scale = a.abs().max(b.abs());
    if scale == 0.0 {
        0.0
    } else if (a - b).is_nan() {
        f64::INFINITY
    } else {
        (a - b).abs() / scale
    }
}

/// Plans the reciprocity check of `subject`.
pub fn plan<'a>(subject: &Arc<BsdfSubject<'a>>, why: &str) -> PlannedCheck<'a> {
    let s = subject.clone();
    let case = json!({"transport": subject.bsdf.transport().name(), "eta": subject.bsdf.eta()});
    Check::new("bsdf.reciprocity", subject.label.clone(), case, SOURCE)
        .why(format!("{why}: the BSDF's reciprocity"))
        .covers(vec![covers(subject.family(), "bsdf_eval", "reciprocity")])
        .run(move |r, _| {
            let bsdf = s.bsdf.as_ref();
            let eta = bsdf.eta().unwrap_or(1.0);
            let transport = bsdf.transport();
            let dirs = directions(bsdf.eta());
            let (mut worst, mut at, mut pairs) = (0.0f64, Value::Null, 0u64);
            for &wi in &dirs {
                for &wo in &dirs {
                    if wi[2] == 0.0 || wo[2] == 0.0 {
                        continue;
                    }
                    let index = |w: Vec3| if w[2] > 0.0 { 1.0 } else { eta };
                    let (ni, no) = (index(wi), index(wo));
                    let (a, b) = (f(bsdf, wi, wo), f(bsdf, wo, wi));
                    let (lhs, rhs) = match transport {
                        Transport::Importance => (a / (no * no), b / (ni * ni)),
                        Transport::Radiance => (a / (ni * ni), b / (no * no)),
                    };
                    pairs += 1;
                    let e = discrepancy(lhs, rhs);
                    if e > worst || (at.is_null() && e.is_nan()) {
                        worst = e;
                        at = json!({"wi": wi, "wo": wo, "f_wi_wo": a, "f_wo_wi": b});
                    }
                }
            }
            r.cost.evaluations += 2 * pairs;
            r.value = Some(worst);
            r.measured = Some(Measured::Relative { error: worst });
            let tolerance = BSDF_RECIPROCITY.at(s.precision);
            r.tolerance = Some(applied(&tolerance));
            if let Value::Object(case) = &mut r.case {
                case.insert("pairs".into(), json!(pairs));
                case.insert("worst".into(), at);
            }
            r.verdict = if worst <= tolerance.value {
                Verdict::Pass
            } else {
                Verdict::Fail
            };
            Ok(())
        })
}
