//! `mfh cost`: what accuracy costs in time. For every quantity with more than one route (or an
//! oracle with a knob), the largest error of each route against a high-precision reference and
//! its time per evaluation on the same inputs, and the Pareto frontier of the two.
//!
//! One concept per file: [`catalogue`] (the closed-form routes and their references),
//! [`oracles`] (the oracles' own knobs: quadrature tolerance, Monte Carlo N, chi-square sample
//! count), [`timing`] (medians of repeated batches) and [`frontier`]. The errors are
//! deterministic (fixed inputs and seeds); the timings are not (machine and load). Nothing here
//! does I/O: the CLI and the report sinks write `cost.json`, the plots and the tables.

pub mod catalogue;
pub mod frontier;
pub mod oracles;
pub mod timing;
pub mod visible_moments;

use serde::{Deserialize, Serialize};
use timing::{time_per_evaluation, Budget, Timing};

/// The version of the `cost.json` schema (bumped on any incompatible change).
pub const SCHEMA_VERSION: u32 = 1;

/// What to run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CostOptions {
    /// Fewer oracle knob settings and shorter timing batches (a few seconds in all).
    pub quick: bool,
    /// Measure times (off: errors only, which are deterministic; what the staleness test of
    /// the generated reports compares).
    pub timed: bool,
    /// The seed of the Monte Carlo and chi-square streams.
    pub seed: u64,
    /// Which groups of quantities to run.
    pub selection: Selection,
}

/// Which quantities a run covers (from a scene: only what its materials and effects use).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Selection {
    /// STD Λ routes (a Student-family material with masking).
    pub student: bool,
    /// GTR G1 routes.
    pub gtr: bool,
    /// Piecewise-linear G1 routes.
    pub piecewise: bool,
    /// Spherical-Gaussian and ASG approximations.
    pub spherical_gaussians: bool,
    /// The visible-slope moments of Gaussian slopes (D_s) against cubature.
    pub visible_moments: bool,
    /// The oracles' knobs (always useful: every audit uses them).
    pub oracles: bool,
}

impl Selection {
    /// Everything.
    pub const ALL: Selection = Selection {
        student: true,
        gtr: true,
        piecewise: true,
        spherical_gaussians: true,
        visible_moments: true,
        oracles: true,
    };

    /// What a scene uses: the families of its materials (a Student-family material with
    /// masking, or a BSDF on one, which masks with G2, selects the STD Λ routes), its lighting
    /// effects; the oracles always.
    pub fn of_scene(scene: &crate::scene::Scene) -> Selection {
        let families: Vec<&str> = scene
            .materials
            .iter()
            .filter_map(|m| m.ndf().map(|s| s.family()))
            .collect();
        let masks = |f: &[&str]| {
            scene.materials.iter().any(|m| {
                m.ndf().is_some_and(|s| f.contains(&s.family()))
                    && (m.masking.is_some() || m.bsdf.is_some())
            })
        };
        Selection {
            student: masks(&[
                "std",
                "hyper_cauchy",
                "student_fixed_variance",
                "student_general",
            ]),
            gtr: families.contains(&"gtr"),
            piecewise: families.contains(&"piecewise_linear"),
            spherical_gaussians: scene.lighting.spherical_gaussians
                || scene.lighting.anisotropic_spherical_gaussians,
            visible_moments: families.contains(&"gaussian_slopes"),
            oracles: true,
        }
    }
}

/// `cost.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CostReport {
    /// [`SCHEMA_VERSION`].
    pub schema_version: u32,
    /// The mfh version that measured it.
    pub mfh_version: String,
    /// Whether this was a `--quick` run.
    pub quick: bool,
    /// Whether times were measured.
    pub timed: bool,
    /// The seed of the statistical oracles.
    pub seed: u64,
    /// One entry per quantity.
    pub quantities: Vec<Quantity>,
}

/// One quantity and its routes.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Quantity {
    /// Its name, e.g. "STD Λ, γ = 2".
    pub name: String,
    /// What the error is measured against (the reference), and its own accuracy.
    pub reference: String,
    /// The error measure ("relative", "absolute", …) and what is maximized over.
    pub error: String,
    /// The inputs every route is evaluated on.
    pub inputs: String,
    /// The routes, in catalogue order.
    pub routes: Vec<RouteCost>,
    /// The routes on the Pareto frontier of (seconds per evaluation, max error), fastest first.
    pub frontier: Vec<String>,
}

/// One route (or one setting of a knob) of a quantity.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RouteCost {
    /// The route's name (or knob setting, e.g. "tolerance 1e-6").
    pub route: String,
    /// `measured`, or `refused` (the route answers a typed route error for every input; not
    /// timed).
    pub status: String,
    /// Why it refused, or what limits it (the first route error met).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reason: Option<String>,
    /// The largest error over the inputs it accepted; `None` if refused or non-finite.
    pub max_error: Option<f64>,
    /// Inputs measured (accepted and with a reference).
    pub evaluated: usize,
    /// Inputs it refused with a route error (outside its domain).
    pub refused_inputs: usize,
    /// Inputs where it answered NaN or ±∞ with a finite reference (max_error is then `None`).
    pub non_finite: usize,
    /// Median seconds per evaluation (`None` when not timed or refused).
    pub seconds_per_eval: Option<f64>,
    /// The timing behind it (median, spread, batches).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub timing: Option<Timing>,
    /// Further measurements (e.g. the Monte Carlo standard error).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
}

/// A route to measure: which inputs it accepts (an error names its domain) and its value.
pub struct Candidate<'a> {
    /// The route's name.
    pub route: String,
    /// Whether input i is in the route's domain.
    pub accepts: Box<dyn Fn(usize) -> Result<(), String> + 'a>,
    /// The route's value at input i.
    pub value: Box<dyn Fn(usize) -> f64 + 'a>,
    /// The inputs that concern it (None: all). A knob route may concern a part of the inputs
    /// (e.g. the piecewise-linear model with n pieces); the others are not its refusals.
    pub subset: Option<Vec<usize>>,
}

impl<'a> Candidate<'a> {
    /// A route defined at every input.
    pub fn total(route: impl Into<String>, value: impl Fn(usize) -> f64 + 'a) -> Self {
        Self {
            route: route.into(),
            accepts: Box::new(|_| Ok(())),
            value: Box::new(value),
            subset: None,
        }
    }
}

/// A quantity to measure: its inputs, its reference's error measure, its candidates.
pub struct Sweep<'a> {
    /// [`Quantity::name`].
    pub name: String,
    /// [`Quantity::reference`].
    pub reference: String,
    /// [`Quantity::error`].
    pub error: String,
    /// [`Quantity::inputs`].
    pub inputs_text: String,
    /// The number of inputs.
    pub inputs: usize,
    /// The error of a candidate's value at input i; `None` where there is no reference (the
    /// input is then not measured).
    pub error_of: Box<dyn Fn(usize, f64) -> Option<f64> + 'a>,
    /// The routes.
    pub candidates: Vec<Candidate<'a>>,
}

/// Measures every candidate of a sweep: errors over the inputs each accepts, then (when
/// `budget` is given) the time of a sweep over those inputs.
pub fn measure(sweep: Sweep<'_>, budget: Option<Budget>) -> Quantity {
    let mut routes = Vec::new();
    for c in &sweep.candidates {
        let mut accepted = Vec::new();
        let mut reason = None;
        let mut refused_inputs = 0;
        let inputs: Vec<usize> = c.subset.clone().unwrap_or((0..sweep.inputs).collect());
        for i in inputs {
            match (c.accepts)(i) {
                Ok(()) => accepted.push(i),
                Err(e) => {
                    refused_inputs += 1;
                    reason.get_or_insert(e);
                }
            }
        }
        if accepted.is_empty() {
            routes.push(RouteCost {
                route: c.route.clone(),
                status: "refused".into(),
                reason,
                max_error: None,
                evaluated: 0,
                refused_inputs,
                non_finite: 0,
                seconds_per_eval: None,
                timing: None,
                note: None,
            });
            continue;
        }
        let (mut worst, mut evaluated, mut non_finite) = (0.0f64, 0, 0);
        for &i in &accepted {
            let v = (c.value)(i);
            if let Some(e) = (sweep.error_of)(i, v) {
                evaluated += 1;
                if e.is_finite() {
                    worst = worst.max(e);
                } else {
                    non_finite += 1;
                }
            }
        }
        let timing = budget.map(|b| {
            time_per_evaluation(
                &mut || accepted.iter().map(|&i| (c.value)(i)).sum(),
                accepted.len() as u64,
                b,
            )
        });
        routes.push(RouteCost {
            route: c.route.clone(),
            status: "measured".into(),
            reason,
            max_error: (non_finite == 0 && evaluated > 0).then_some(worst),
            evaluated,
            refused_inputs,
            non_finite,
            seconds_per_eval: timing.map(|t| t.median),
            timing,
            note: None,
        });
    }
    finish(Quantity {
        name: sweep.name,
        reference: sweep.reference,
        error: sweep.error,
        inputs: sweep.inputs_text,
        routes,
        frontier: vec![],
    })
}

/// Sets the quantity's frontier from its routes' (time, error).
pub fn finish(mut q: Quantity) -> Quantity {
    let points: Vec<(f64, f64)> = q
        .routes
        .iter()
        .map(|r| {
            (
                r.seconds_per_eval.unwrap_or(f64::NAN),
                r.max_error.unwrap_or(f64::NAN),
            )
        })
        .collect();
    q.frontier = frontier::pareto_frontier(&points)
        .into_iter()
        .map(|i| q.routes[i].route.clone())
        .collect();
    q
}

/// The number of quantities a run will measure (for a progress bar).
pub fn planned(options: &CostOptions) -> usize {
    catalogue::planned(&options.selection, options.quick) + oracles::planned(options)
}

/// Runs the catalogue; `progress(done, planned, name)` is called after each quantity.
pub fn run(options: &CostOptions, progress: &mut dyn FnMut(usize, usize, &str)) -> CostReport {
    let budget = options.timed.then_some(if options.quick {
        Budget::QUICK
    } else {
        Budget::FULL
    });
    let total = planned(options);
    let mut quantities = Vec::new();
    let mut push = |q: Quantity, quantities: &mut Vec<Quantity>| {
        progress(quantities.len() + 1, total, &q.name);
        quantities.push(q);
    };
    for build in catalogue::sweeps(&options.selection, options.quick) {
        push(measure(build(), budget), &mut quantities);
    }
    for run in oracles::quantities(options, budget) {
        push(run(), &mut quantities);
    }
    CostReport {
        schema_version: SCHEMA_VERSION,
        mfh_version: env!("CARGO_PKG_VERSION").to_string(),
        quick: options.quick,
        timed: options.timed,
        seed: options.seed,
        quantities,
    }
}
