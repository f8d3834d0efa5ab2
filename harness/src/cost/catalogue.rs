//! The route catalogue: every closed-form quantity with more than one route, the inputs its
//! routes are compared on, and the reference each is measured against (never one of the routes
//! under test).
//!
//! - STD Λ (document 001): every route of `student_lambda::ROUTES` per γ, against the certified
//!   double-double Λ (`oracle::precise`, relative bound ≤ 1e-25…1e-20) at the same f64 argument
//!   x = cot θ / (α √(γ − 1)).
//! - GTR G1 (document 004): every route of `gtr_lambda::ROUTES` (closed forms, the printed forms,
//!   the implementation's G1, the spline — clamped to γ = 4 above 4 — and the exact numeric
//!   route), against the certified GGX Λ at γ = 2 (GTR γ = 2 is GGX) and `oracle::gtr::g1`
//!   (harness quadrature of the definition) elsewhere.
//! - Piecewise-linear G1 (document 000): GGX discretized with n pieces, the domain split with the
//!   document's trapezoid rule (eq 28) and with adaptive quadrature, against the exact route
//!   (eq 10–13 by adaptive quadrature; the audit checks it against the harness's Λ oracle,
//!   which costs seconds per angle on these models).
//! - Spherical Gaussians (document 003): the SG inner product (closed form, as printed), the ASG
//!   integral (the document's form, its large-bandwidth form), the ASG–SG convolution (the
//!   document's approximation, quadrature to a tolerance), against the reference crate's
//!   adaptive quadrature to 1e-12…1e-13.
//! - Gaussian visible-slope moments (document 002): in `super::visible_moments`.

use super::{Candidate, Selection, Sweep};
use crate::oracle::precise::student_lambda_standardized;
use mfh_reference::ndf::{gtr_lambda, student_lambda};
use mfh_reference::ndf::{AngularProfile, PiecewiseLinear};
use mfh_reference::sg::{Asg, Sg};
use mfh_reference::Smith;
use std::f64::consts::FRAC_PI_2;
use std::rc::Rc;

/// The shapes of the STD Λ sweep: near the 3/2 limit, GGX's 2, the half-integer 7/2, integer
/// 7 and 20, 90 (where the integer sums lose their digits), 10³.
pub const STD_GAMMAS: [f64; 7] = [1.6, 2.0, 3.5, 7.0, 20.0, 90.0, 1e3];

/// The roughness of every NDF in the catalogue (Λ depends on α and θ only through cot θ/α).
pub const ALPHA: f64 = 0.3;

/// Incidence angles: near normal, across, and up to π/2 − 1e-6 (grazing).
pub const THETAS: [f64; 13] = [
    1e-6,
    1e-3,
    0.05,
    0.2,
    0.5,
    0.8,
    1.0,
    1.2,
    1.4,
    1.5,
    1.55,
    1.57,
    FRAC_PI_2 - 1e-6,
];

/// The GTR shapes: non-integer (no closed form), integer 2 (every route), 5 (the spline clamped
/// to γ = 4, document 004 §6).
pub const GTR_GAMMAS: [f64; 3] = [0.5, 2.0, 5.0];

/// Pieces of the piecewise-linear discretization of GGX.
pub const PIECES: [usize; 4] = [5, 9, 17, 65];

/// A sweep to build (its references are computed when it is built).
pub type Build = Box<dyn FnOnce() -> Sweep<'static>>;

/// The number of sweeps [`sweeps`] returns.
pub fn planned(selection: &Selection, quick: bool) -> usize {
    sweeps(selection, quick).len()
}

/// The sweeps of the selection, in report order. `quick` drops the GTR sweep at γ = 0.5 and
/// keeps two angles of the one at γ = 5 (their quadrature reference costs seconds per angle).
pub fn sweeps(selection: &Selection, quick: bool) -> Vec<Build> {
    let mut out: Vec<Build> = Vec::new();
    if selection.student {
        for c in STD_GAMMAS {
            out.push(Box::new(move || student(c)));
        }
    }
    if selection.gtr {
        for g in GTR_GAMMAS {
            if !(quick && g == 0.5) {
                out.push(Box::new(move || gtr(g, quick)));
            }
        }
    }
    if selection.piecewise {
        out.push(Box::new(piecewise));
    }
    if selection.spherical_gaussians {
        out.push(Box::new(sg_inner));
        out.push(Box::new(asg_integral));
        out.push(Box::new(asg_convolution));
    }
    if selection.visible_moments {
        out.push(Box::new(super::visible_moments::sweep));
    }
    out
}

fn relative(v: f64, r: f64) -> f64 {
    if r == 0.0 {
        v.abs()
    } else {
        (v - r).abs() / r.abs()
    }
}

fn thetas_text() -> String {
    let t: Vec<String> = THETAS.iter().map(|t| format!("{t}")).collect();
    t.join(", ")
}

/// STD Λ at shape γ: every route of document 001 against the certified double-double value.
pub fn student(c: f64) -> Sweep<'static> {
    let s = ALPHA * (c - 1.0).sqrt();
    let xs: Rc<Vec<f64>> = Rc::new(THETAS.iter().map(|t| t.cos() / t.sin() / s).collect());
    let refs: Vec<_> = xs
        .iter()
        .map(|&x| student_lambda_standardized(c, x).ok())
        .collect();
    let candidates = student_lambda::ROUTES
        .iter()
        .map(|&(name, _)| match student_lambda::route(name, c) {
            Err(e) => {
                let reason = e.to_string();
                Candidate {
                    route: name.to_string(),
                    accepts: Box::new(move |_| Err(reason.clone())),
                    value: Box::new(|_| f64::NAN),
                    subset: None,
                }
            }
            Ok(f) => {
                let (xa, xv) = (xs.clone(), xs.clone());
                Candidate {
                    route: name.to_string(),
                    accepts: Box::new(move |i| {
                        student_lambda::route_domain(name, c, xa[i]).map_err(|e| e.to_string())
                    }),
                    value: Box::new(move |i| f(c, xv[i], ALPHA)),
                    subset: None,
                }
            }
        })
        .collect();
    Sweep {
        name: format!("STD Λ, γ = {c}"),
        reference: "oracle::precise (double-double tanh-sinh quadrature of seed 001 eq 5, \
                    certified relative bound ≤ 1e-20) at the same f64 x"
            .into(),
        error: "relative, max over θ (inputs where Λ underflows the certified range are left out)"
            .into(),
        inputs_text: format!("α = {ALPHA}, φ = 0, θ ∈ {{{}}}", thetas_text()),
        inputs: THETAS.len(),
        error_of: Box::new(move |i, v| refs[i].map(|r| r.relative_error_of(v))),
        candidates,
    }
}

/// The incidence angles of the GTR sweeps at γ ≠ 2, where the reference is the harness's
/// nested quadrature (~10⁵ evaluations, seconds per angle).
pub const GTR_THETAS: [f64; 4] = [0.05, 0.5, 1.0, 1.5];

/// GTR G1 = 1/(1 + Λ) at shape γ: every route of document 004. The reference: at γ = 2, where GTR
/// is GGX (D = α²/(π(1 + (α² − 1) cos²θ)²), document 004 eq 1** with c = α²), the certified
/// double-double GGX Λ; elsewhere `oracle::gtr::g1` (harness nested quadrature of the
/// definition, relative bound 1e-9).
pub fn gtr(gamma: f64, quick: bool) -> Sweep<'static> {
    let ggx = gamma == 2.0;
    let thetas: Vec<f64> = if ggx {
        THETAS[1..THETAS.len() - 1].to_vec()
    } else if quick {
        vec![GTR_THETAS[1], GTR_THETAS[3]]
    } else {
        GTR_THETAS.to_vec()
    };
    let refs: Vec<f64> = thetas
        .iter()
        .map(|&t| {
            if ggx {
                crate::oracle::precise::PreciseModel::new(
                    crate::oracle::precise::Family::Ggx,
                    ALPHA,
                )
                .and_then(|m| m.lambda([t.sin(), 0.0, t.cos()]))
                .map(|l| 1.0 / (1.0 + l.value))
                .unwrap_or(f64::NAN)
            } else {
                crate::oracle::gtr::g1(gamma, ALPHA, t).value
            }
        })
        .collect();
    let mus: Rc<Vec<f64>> = Rc::new(thetas.iter().map(|t| t.cos() / t.sin()).collect());
    let candidates = gtr_lambda::ROUTES
        .iter()
        .map(|&(name, _)| {
            let (ma, mv) = (mus.clone(), mus.clone());
            let label = if name == "spline" && gamma > 4.0 {
                "spline (clamped to γ = 4)".to_string()
            } else {
                name.to_string()
            };
            Candidate {
                route: label,
                accepts: Box::new(move |i| {
                    gtr_lambda::lambda(name, gamma, ALPHA, ma[i])
                        .map(|_| ())
                        .map_err(|e| e.to_string())
                }),
                value: Box::new(move |i| {
                    1.0 / (1.0 + gtr_lambda::lambda(name, gamma, ALPHA, mv[i]).unwrap_or(f64::NAN))
                }),
                subset: None,
            }
        })
        .collect();
    let t: Vec<String> = thetas.iter().map(|t| format!("{t}")).collect();
    Sweep {
        name: format!("GTR G1, γ = {gamma}"),
        reference: if ggx {
            "oracle::precise GGX Λ (GTR γ = 2 is GGX; certified double-double), G1 = 1/(1 + Λ)"
                .into()
        } else {
            "oracle::gtr::g1 (harness nested quadrature of seed 004 eq 48*, relative bound 1e-9)"
                .into()
        },
        error: "relative, max over θ".into(),
        inputs_text: format!("α = {ALPHA}, θ ∈ {{{}}}", t.join(", ")),
        inputs: thetas.len(),
        error_of: Box::new(move |i, v| Some(relative(v, refs[i]))),
        candidates,
    }
}

/// GGX's D(θ) with α = 0.5 in a form finite at θ = π/2: α²/(π(α² cos²θ + sin²θ)²).
fn ggx_profile(theta: f64) -> f64 {
    let a2 = 0.25;
    let (s, c) = theta.sin_cos();
    let t = a2 * c * c + s * s;
    a2 / (std::f64::consts::PI * t * t)
}

/// Piecewise-linear G1 (document 000) of GGX (α = 0.5) discretized with n pieces: the document's
/// domain split with the trapezoid rule of eq 28, and the exact route, against the Λ oracle.
pub fn piecewise() -> Sweep<'static> {
    let thetas = [0.05, 0.3, 0.6, 0.9, 1.2, 1.4, 1.5, 1.57];
    let models: Rc<Vec<PiecewiseLinear>> = Rc::new(
        PIECES
            .iter()
            .map(|&n| {
                PiecewiseLinear::new(AngularProfile::discretize(&ggx_profile, n), None)
                    .expect("a discretized GGX profile is a valid piecewise-linear model")
            })
            .collect(),
    );
    let input = move |i: usize| (i / thetas.len(), thetas[i % thetas.len()]);
    let w = |t: f64| [t.sin(), 0.0, t.cos()];
    let refs: Vec<f64> = (0..PIECES.len() * thetas.len())
        .map(|i| {
            let (k, t) = input(i);
            1.0 / (1.0 + models[k].lambda(w(t)))
        })
        .collect();
    let mut candidates = Vec::new();
    for (k, n) in PIECES.iter().enumerate() {
        let subset: Vec<usize> = (k * thetas.len()..(k + 1) * thetas.len()).collect();
        for (route, label) in [
            ("domain_split", format!("trapezoid (eq 28), n = {}", n - 1)),
            (
                "domain_split_adaptive",
                format!("domain split, adaptive, n = {}", n - 1),
            ),
        ] {
            let m = models.clone();
            candidates.push(Candidate {
                route: label,
                accepts: Box::new(|_| Ok(())),
                value: Box::new(move |i| {
                    let (k, t) = input(i);
                    1.0 / (1.0 + m[k].lambda_route(w(t), route).unwrap_or(f64::NAN))
                }),
                subset: Some(subset.clone()),
            });
        }
    }
    Sweep {
        name: "piecewise-linear G1 (GGX α = 0.5 in n pieces)".into(),
        reference: "the exact route of the same piecewise model (adaptive Gauss–Kronrod of the \
                    back-facing projected area, seed 000 eq 10–13, relative 1e-13; checked \
                    against the harness's quadrature oracle by the audit's smith.lambda_route — \
                    the oracle itself costs seconds per angle here), G1 = 1/(1 + Λ)"
            .into(),
        error: "relative, max over θ".into(),
        inputs_text: format!(
            "n ∈ {{{}}} pieces, φ = 0, θ ∈ {{0.05, 0.3, 0.6, 0.9, 1.2, 1.4, 1.5, 1.57}}",
            PIECES
                .iter()
                .map(|n| (n - 1).to_string())
                .collect::<Vec<_>>()
                .join(", ")
        ),
        inputs: PIECES.len() * thetas.len(),
        error_of: Box::new(move |i, v| Some(relative(v, refs[i]))),
        candidates,
    }
}

fn unit(v: [f64; 3]) -> [f64; 3] {
    let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    [v[0] / n, v[1] / n, v[2] / n]
}

/// SG pairs: (sharpness 1, sharpness 2, angle between axes).
const SG_PAIRS: [(f64, f64, f64); 6] = [
    (1.0, 1.0, 0.0),
    (2.0, 10.0, 0.5),
    (10.0, 100.0, 0.2),
    (100.0, 100.0, 1.0),
    (400.0, 400.0, 0.05),
    (1e3, 10.0, 2.5),
];

fn sg_pair(i: usize) -> (Sg, Sg) {
    let (a, b, angle) = SG_PAIRS[i];
    let first = Sg::new([0.0, 0.0, 1.0], a, 1.0).expect("valid SG");
    let second = Sg::new([angle.sin(), 0.0, angle.cos()], b, 1.0).expect("valid SG");
    (first, second)
}

/// The SG inner product (document 003): the closed form, and the form as printed.
pub fn sg_inner() -> Sweep<'static> {
    let refs: Vec<f64> = (0..SG_PAIRS.len())
        .map(|i| {
            let (a, b) = sg_pair(i);
            a.inner_exact(&b)
        })
        .collect();
    Sweep {
        name: "SG inner product".into(),
        reference: "Sg::inner_exact (adaptive quadrature over the sphere, relative ≈ 1e-12)".into(),
        error: "relative, max over the pairs".into(),
        inputs_text:
            "unit amplitudes, (λ₁, λ₂, angle) ∈ {(1, 1, 0), (2, 10, 0.5), (10, 100, 0.2), \
                      (100, 100, 1), (400, 400, 0.05), (1000, 10, 2.5)}"
                .into(),
        inputs: SG_PAIRS.len(),
        error_of: Box::new(move |i, v| Some(relative(v, refs[i]))),
        candidates: vec![
            Candidate::total("closed form (expm1)", |i| {
                let (a, b) = sg_pair(i);
                a.inner(&b)
            }),
            Candidate::total("as printed (e^{λ₁+λ₂}, sinh)", |i| {
                let (a, b) = sg_pair(i);
                a.inner_printed(&b)
            }),
        ],
    }
}

/// ASG bandwidths (λ, μ) of the integral and convolution sweeps.
const BANDWIDTHS: [[f64; 2]; 6] = [
    [1.0, 1.0],
    [2.0, 1.0],
    [5.0, 5.0],
    [10.0, 2.0],
    [100.0, 50.0],
    [0.5, 0.1],
];

fn asg(i: usize) -> Asg {
    Asg::new(
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        BANDWIDTHS[i],
        1.0,
    )
    .expect("valid ASG")
}

/// The ASG integral (document 003 §3.2.1): the document's form and its large-bandwidth form.
pub fn asg_integral() -> Sweep<'static> {
    let refs: Vec<f64> = (0..BANDWIDTHS.len())
        .map(|i| asg(i).integral_exact())
        .collect();
    Sweep {
        name: "ASG integral".into(),
        reference: "Asg::integral_exact (closed form in cos θ, adaptive quadrature in φ, \
                    relative ≈ 1e-13)"
            .into(),
        error: "relative, max over the bandwidths".into(),
        inputs_text: "(λ, μ) ∈ {(1, 1), (2, 1), (5, 5), (10, 2), (100, 50), (0.5, 0.1)}".into(),
        inputs: BANDWIDTHS.len(),
        error_of: Box::new(move |i, v| Some(relative(v, refs[i]))),
        candidates: vec![
            Candidate::total("document (with F terms)", |i| {
                asg(i).integral().unwrap_or(f64::NAN)
            }),
            Candidate::total("large bandwidth π/√(λμ)", |i| {
                asg(i).integral_large_bandwidth().unwrap_or(f64::NAN)
            }),
        ],
    }
}

/// The ASG–SG convolution (document 003 §3.3): the document's approximation, and quadrature to a
/// few tolerances (the knob of the exact route).
pub fn asg_convolution() -> Sweep<'static> {
    let sg_of = |i: usize| {
        let angle = 0.3 * i as f64;
        Sg::new(unit([angle.sin(), 0.2, angle.cos()]), 10.0, 1.0).expect("valid SG")
    };
    let refs: Vec<f64> = (0..BANDWIDTHS.len())
        .map(|i| asg(i).convolve_sg_exact(&sg_of(i)))
        .collect();
    let mut candidates = vec![Candidate::total("document approximation", move |i| {
        asg(i).convolve_sg(&sg_of(i)).unwrap_or(f64::NAN)
    })];
    for rel in [1e-3, 1e-6, 1e-9] {
        candidates.push(Candidate::total(
            format!("quadrature to {rel:e}"),
            move |i| asg(i).convolve_sg_exact_to(&sg_of(i), rel),
        ));
    }
    Sweep {
        name: "ASG–SG convolution".into(),
        reference: "Asg::convolve_sg_exact (adaptive quadrature over the hemisphere, relative \
                    ≈ 1e-12)"
            .into(),
        error: "relative, max over the inputs".into(),
        inputs_text: "(λ, μ) as the ASG integral; SG of sharpness 10, axis tilted 0.3·i".into(),
        inputs: BANDWIDTHS.len(),
        error_of: Box::new(move |i, v| Some(relative(v, refs[i]))),
        candidates,
    }
}
