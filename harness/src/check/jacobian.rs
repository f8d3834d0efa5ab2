//! The sampler's own density: `pdf_wm` against 1/|∂m/∂u₁ × ∂m/∂u₂|, the density of the map
//! u ↦ sample_wm(u) with respect to solid angle, by Richardson-extrapolated central differences
//! at quasi-random interior points. Unlike comparing `pdf_wm` with D(m)(m·n), this fails a pdf
//! that disagrees with its sampler whatever D says.

use super::{applied, covers, PlannedCheck};
use crate::check::{need, Check};
use crate::precision::Precision;
use crate::record::{Measured, OracleValue, Verdict};
use crate::subject::Subject;
use crate::tolerance::PDF_JACOBIAN;
use mfh_reference::geometry::Vec3;
use mfh_reference::NormalSampler;
use serde_json::json;
use std::sync::Arc;

/// Points at which the Jacobian is measured.
const POINTS: u32 = 1024;
/// The finite-difference step in u (and half of it, for Richardson extrapolation) for an f64
/// sampler: truncation O(h⁴) after extrapolation, round-off ε/h ≈ 2e-12.
const STEP: f64 = 1e-4;
/// The step for a float32 sampler: central differences balance truncation h² against
/// round-off ε₃₂/h at h ≈ ε₃₂^(1/3) ≈ 5e-3; 4e-3 (round-off ≈ 3e-5 per derivative, the
/// extrapolated truncation O(h⁴) ≈ 3e-10) keeps the stencil (±2h) inside the margin.
const STEP_F32: f64 = 4e-3;
/// [`UNRESOLVED`] for a float32 sampler: the two steps' densities differ by their round-off
/// (≈ 3e-5 × the map's condition, ≤ 20) and truncation (≈ h² ≈ 1.6e-5): 1e-2.
const UNRESOLVED_F32: f64 = 1e-2;

/// The step and the unresolved threshold for a sampler computing in `precision`.
fn stencil(precision: Precision) -> (f64, f64) {
    match precision {
        Precision::F64 => (STEP, UNRESOLVED),
        Precision::F32 => (STEP_F32, UNRESOLVED_F32),
    }
}
/// Interior margin of the unit square: the points keep 2·STEP away from its edges.
const MARGIN: f64 = 0.01;
/// Where the two step sizes disagree by more than this (relative), the map has a kink or a
/// discontinuity within the stencil (a profile breakpoint, a branch of the inversion): the
/// point says nothing about the density and is left out.
const UNRESOLVED: f64 = 1e-3;
/// At least this fraction of the points must be resolved for a verdict.
const MIN_RESOLVED: f64 = 0.9;

fn sub(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn cross_norm(a: Vec3, b: Vec3) -> f64 {
    let c = [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ];
    (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt()
}

/// The density of the sampling map at `u` with step `h`: 1/|∂m/∂u₁ × ∂m/∂u₂| by central
/// differences.
fn map_density(sampler: &dyn NormalSampler, u: [f64; 2], h: f64) -> f64 {
    let d = |k: usize| {
        let (mut a, mut b) = (u, u);
        a[k] += h;
        b[k] -= h;
        let diff = sub(sampler.sample_wm(a), sampler.sample_wm(b));
        [
            diff[0] / (2.0 * h),
            diff[1] / (2.0 * h),
            diff[2] / (2.0 * h),
        ]
    };
    1.0 / cross_norm(d(0), d(1))
}

/// What the measurement found: the worst relative error of `pdf_wm` at the resolved points,
/// where it is attained, and how many points were resolved.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JacobianResult {
    /// The worst |pdf_wm − density| / density over the resolved points.
    pub worst: f64,
    /// The u where it is attained.
    pub at: [f64; 2],
    /// `pdf_wm` and the map's density there.
    pub pdf_and_density: (f64, f64),
    /// Points resolved / measured.
    pub resolved: u32,
}

/// Measures `pdf_wm` against the density of the sampling map.
pub fn measure(sampler: &dyn NormalSampler) -> JacobianResult {
    measure_at(sampler, Precision::F64)
}

/// [`measure`] with the steps for a sampler computing in `precision`.
pub fn measure_at(sampler: &dyn NormalSampler, precision: Precision) -> JacobianResult {
    let (step, unresolved) = stencil(precision);
    let golden = 0.618_033_988_749_894_9;
    let mut out = JacobianResult {
        worst: 0.0,
        at: [0.0; 2],
        pdf_and_density: (0.0, 0.0),
        resolved: 0,
    };
    for i in 0..POINTS {
        let span = 1.0 - 2.0 * MARGIN;
        let u = [
            MARGIN + span * (f64::from(i) + 0.5) / f64::from(POINTS),
            MARGIN + span * (f64::from(i) * golden).fract(),
        ];
        let coarse = map_density(sampler, u, step);
        let fine = map_density(sampler, u, step / 2.0);
        // Central differences err as h²: (4 fine − coarse)/3 cancels that term.
        let density = (4.0 * fine - coarse) / 3.0;
        let pdf = sampler.pdf_wm(sampler.sample_wm(u));
        let error = if !pdf.is_finite() || pdf < 0.0 {
            f64::INFINITY
        } else if !(density.is_finite() && density > 0.0)
            || (coarse - fine).abs() > unresolved * fine.abs()
        {
            continue;
        } else {
            ((pdf - density) / density).abs()
        };
        out.resolved += 1;
        if !(error <= out.worst) {
            out.worst = error;
            out.at = u;
            out.pdf_and_density = (pdf, density);
        }
    }
    out
}

/// Plans the Jacobian check of a model with a sampler.
pub fn plan<'a>(subject: &Arc<Subject<'a>>, why: &str) -> PlannedCheck<'a> {
    let family = subject.family();
    let precision = subject.precision;
    let (step, _) = stencil(precision);
    let tolerance = PDF_JACOBIAN.at(precision);
    let case = json!({"points": POINTS, "step": step});
    let s = subject.clone();
    Check::new(
        "sampling.pdf_jacobian",
        subject.label.clone(),
        case,
        "change of variables: pdf(m) = 1/|∂m/∂u₁ × ∂m/∂u₂| for u uniform on [0,1)²",
    )
    .why(format!(
        "{why}: pdf_wm must be the density of the sampling map itself"
    ))
    .covers(vec![covers(family, "pdf_wm", "default")])
    .run(move |r, _| {
        let sampler = need(s.model.as_sampler(), "normal sampler")?;
        let j = measure_at(sampler, precision);
        r.value = Some(j.pdf_and_density.0);
        r.oracle = Some(OracleValue {
            value: j.pdf_and_density.1,
            uncertainty: 0.0,
            kind: "error_bound",
            noise_floor: None,
        });
        r.measured = Some(Measured::Relative { error: j.worst });
        r.tolerance = Some(applied(&tolerance));
        r.case = json!({"points": POINTS, "step": step, "resolved": j.resolved,
                                "worst_at_u": j.at});
        r.verdict = if f64::from(j.resolved) < MIN_RESOLVED * f64::from(POINTS) {
            Verdict::Error {
                message: format!(
                    "only {} of {POINTS} points had a smooth sampling map within the \
                             finite-difference stencil (need {MIN_RESOLVED})",
                    j.resolved
                ),
            }
        } else if j.worst <= tolerance.value {
            Verdict::Pass
        } else {
            Verdict::Fail
        };
        Ok(())
    })
}
