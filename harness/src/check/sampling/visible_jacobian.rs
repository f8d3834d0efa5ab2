//! `sampling.visible_jacobian`: the visible-normal sampler's own density. At each incidence of
//! a sweep through the sampler's regimes (`check/regime.rs`: near normal, log-spaced in the
//! stretched tilt α tan θi from 1e-6 to 1e-1, oblique, towards grazing, and drawn per seed),
//! `pdf_wm_visible(wi, m)` against 1/|∂m/∂u₁ × ∂m/∂u₂|, the density of the map
//! u ↦ sample_wm_visible(wi, u), by Richardson-extrapolated central differences at
//! quasi-random points; a failure is narrowed by bisection in θi to the region where it holds.
//!
//! What it sees that the chi-square at two incidences does not: a sampler that changes its
//! tangent frame near the normal (a renderer shipped T1 = (1, 0, 0) for a stretched incidence
//! within 1e-5 of the normal, not orthogonal to it: ≈ 1 % density error for θi < 0.089 rad at
//! α 0.05), a clamp of the stretched normal's height, a branch near grazing.

use crate::check::regime::{self, AtIncidence, Density, SweepPoint};
use crate::check::step_ladder;
use crate::check::{applied, covers, need, Check, PlannedCheck};
use crate::record::{Measured, RecordData};
use crate::subject::Subject;
use crate::tolerance::PDF_JACOBIAN;
use mfh_reference::geometry::Vec3;
use mfh_reference::VisibleNormalSampler;
use serde_json::json;
use std::sync::Arc;

/// Points per incidence.
pub const POINTS: usize = 512;

const SOURCE: &str = "change of variables: pdf(m) = 1/|∂m/∂u₁ × ∂m/∂u₂| for u uniform on \
                      [0,1)²; Heitz 2018 (JCGT 7(4)) for the visible-normal density";

/// Measures the sampler at one incidence: the worst relative error over the resolved points,
/// each allowed `tolerance` plus its own extrapolation spread.
pub fn measure(
    v: &dyn VisibleNormalSampler,
    wi: Vec3,
    theta: f64,
    points: &[[f64; 2]],
    (step, unresolved, tolerance, eps): (f64, f64, f64, f64),
) -> AtIncidence {
    let centres: Vec<[f64; 3]> = points.iter().map(|p| [0.0, p[0], p[1]]).collect();
    let mut u2 = Vec::new();
    let mut ms = Vec::new();
    let mut map = |u: &[[f64; 3]], out: &mut [Option<Vec3>]| {
        u2.clear();
        u2.extend(u.iter().map(|u| [u[1], u[2]]));
        ms.clear();
        ms.resize(u.len(), [0.0; 3]);
        v.sample_wm_visible_batch(wi, &u2, &mut ms);
        for (o, m) in out.iter_mut().zip(&ms) {
            *o = m.iter().all(|c| c.is_finite()).then_some(*m);
        }
    };
    let mut d = step_ladder::densities(&centres, step, eps, &mut map);
    let normals: Vec<Vec3> = d
        .iter()
        .map(|(c, _)| c.unwrap_or([0.0, 0.0, 1.0]))
        .collect();
    let mut pdf = vec![0.0; normals.len()];
    v.pdf_wm_visible_batch(wi, &normals, &mut pdf);
    // A point's error and its excess over its allowance, where its density is resolved.
    let judged = |k: usize, density: Option<Density>| {
        let density = density?;
        let value = density.value();
        if !(value.is_finite() && value > 0.0 && density.resolved(unresolved)) {
            return None;
        }
        let error = ((pdf[k] - value) / value).abs();
        let allowance = density.allowance();
        Some((error, (error - allowance).max(0.0), allowance))
    };
    // What the single stencil cannot judge to the tolerance (unresolved, or allowed more than
    // the tolerance), or judges failing, is measured on the ladder.
    let again: Vec<usize> = (0..d.len())
        .filter(|&k| d[k].0.is_some() && !step_ladder::settled(judged(k, d[k].1), tolerance))
        .collect();
    step_ladder::measure_again(&mut d, &centres, &again, (step, eps, unresolved), &mut map);
    let mut out = AtIncidence::new(theta, points.len());
    for (k, (c, density)) in d.iter().enumerate() {
        let p = pdf[k];
        if c.is_none() || !p.is_finite() || p < 0.0 {
            // A sampled normal that is not one, or a pdf that is not a density, is wrong
            // wherever it happens.
            out.worst = f64::INFINITY;
            out.excess = f64::INFINITY;
            out.fails = true;
            out.resolved += 1;
            continue;
        }
        if let Some((error, excess, _)) = judged(k, *density) {
            out.add(error, excess);
        }
    }
    out.fails |= !(out.excess <= tolerance);
    out
}

/// Plans `sampling.visible_jacobian` for a model with a visible-normal sampler.
pub fn plan<'a>(subject: &Arc<Subject<'a>>, why: &str) -> PlannedCheck<'a> {
    let family = subject.family();
    let precision = subject.precision;
    let (step, unresolved) = regime::stencil(precision);
    let tolerance = PDF_JACOBIAN.at(precision);
    let case = json!({"points": POINTS, "step": step, "sweep": "stretched tilt 1e-6..1e-1, \
                      oblique, grazing, drawn"});
    let s = subject.clone();
    Check::new(
        "sampling.visible_jacobian",
        subject.label.clone(),
        case,
        SOURCE,
    )
    .why(format!(
        "{why}: pdf_wm_visible must be the density of the visible-normal sampling map at every \
         incidence, near normal and grazing included"
    ))
    .covers(vec![
        covers(family, "sample_wm_visible", "default"),
        covers(family, "pdf_wm_visible", "default"),
    ])
    .seeded()
    .run(move |r, ctx| {
        let v = need(s.model.as_visible_sampler(), "visible-normal sampler")?;
        // The lobe's polar scale stands for α (GGX: the mass per ln θ peaks at θ = atan α).
        let alpha = s.lobe().width().tan();
        let sweep: Vec<SweepPoint> = regime::sweep(alpha, None, Some(ctx.seed));
        let points = regime::points(POINTS, step);
        let limits = (step, unresolved, tolerance.value, precision.epsilon());
        let at_theta = |p: SweepPoint| measure(v, p.direction(false), p.theta, &points, limits);
        let at: Vec<AtIncidence> = sweep.iter().map(|p| at_theta(*p)).collect();
        let worst = at
            .iter()
            .max_by(|a, b| a.excess.total_cmp(&b.excess))
            .copied()
            .expect("a sweep has incidences");
        let resolved: usize = at.iter().map(|a| a.resolved).sum();
        let measured: usize = at.iter().map(|a| a.measured).sum();
        // The value: the worst raw error; measured: the worst error beyond each point's own
        // extrapolation spread, which the tolerance judges.
        r.value = Some(worst.worst);
        r.measured = Some(Measured::Relative {
            error: worst.excess,
        });
        r.tolerance = Some(applied(&tolerance));
        r.cost.evaluations = (measured * 10) as u64;
        r.case = json!({
            "points": POINTS, "step": step, "alpha": alpha,
            "incidences": sweep.len(), "resolved": resolved, "measured": measured,
            "worst_theta_i": worst.theta,
            "drawn_theta_i": sweep.iter().filter(|p| p.regime == "drawn")
                .map(|p| [p.theta, p.phi]).collect::<Vec<_>>(),
        });
        r.data = Some(RecordData::Curve {
            label: "worst relative pdf error against θi".into(),
            x: at.iter().map(|a| a.theta).collect(),
            y: at.iter().map(|a| a.worst).collect(),
        });
        let phi = regime::PHI;
        r.region = regime::narrow(
            &at,
            &mut |theta| {
                at_theta(SweepPoint {
                    theta,
                    phi,
                    regime: "narrowed",
                })
            },
            "visible-normal density",
            &format!("at α ≈ {alpha:.3} (lobe scale), φi {phi}"),
        );
        r.verdict = regime::verdict(resolved, measured, 0.9, at.iter().any(|a| a.fails));
        Ok(())
    })
}
