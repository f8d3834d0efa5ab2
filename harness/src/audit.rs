//! The CI gate for a renderer's own model: `Audit::of(&model)` plans the checks its
//! capabilities and declared effects call for, optionally compares it value by value with a
//! reference spec, runs them, and returns the same report as `mfh audit`.
//!
//! ```
//! use mfh_harness::{Audit, Profile};
//! use mfh_reference::ndf::Ggx;
//! let ggx = Ggx::new(0.3, 0.3).unwrap();
//! Audit::of(&ggx)
//!     .profile(Profile::Ci)
//!     .against(r#"{"family":"ggx","alpha":0.3}"#)
//!     .run()
//!     .assert_pass();
//! ```

pub mod capabilities;
mod precision_probe;

use crate::check::{self, against, PlannedCheck, Profile};
use crate::plan::{plan_model, Effects};
use crate::precision::Precision;
use crate::record::{CheckRecord, Verdict};
use crate::run::DEFAULT_SEED;
use crate::run::{run_plan, AuditOptions, AuditReport};
use crate::scene::Sampling;
use crate::subject::bsdf::{BsdfSubject, OwnNdf};
use crate::subject::{Hints, Subject};
use mfh_reference::bsdf::{Bsdf, BsdfSpec};
use mfh_reference::{Masking, ModelSpec, Ndf};
use serde_json::json;
use std::f64::consts::FRAC_PI_2;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;

/// An audit of one model, configured by its builder methods and carried out by [`Audit::run`].
pub struct Audit<'a> {
    model: Arc<dyn Ndf + 'a>,
    /// The BSDF under audit ([`Audit::of_bsdf`]); then `model` is unused.
    bsdf: Option<Arc<dyn Bsdf + 'a>>,
    /// The NDF the BSDF is built on ([`Audit::ndf`]).
    own_ndf: Option<Arc<dyn Ndf + 'a>>,
    name: String,
    hints: Hints,
    options: AuditOptions,
    masking: Option<Option<Masking>>,
    sampling: Option<Option<Sampling>>,
    slope_moments: bool,
    theta_max: f64,
    against: Option<String>,
    /// `MFH_SEED` when it is set but not a seed: an error record, as the CLI's exit 2.
    seed_error: Option<String>,
    /// The capability traits the model's type implements, when [`crate::audit!`] detected them.
    implemented: Option<capabilities::Implemented>,
    /// The precision the model computes in.
    precision: Precision,
    /// The caller states that D is all the model offers ([`Audit::d_only`]).
    d_only: bool,
    /// The model is a child behind the external protocol ([`Audit::remote`]).
    remote: bool,
}

impl<'a> Audit<'a> {
    /// An audit of `model`: by default every capability it has is audited (masking checked in
    /// both G2 forms, normal sampling, visible-normal sampling where it has that), at the quick
    /// profile, with the default seed (`MFH_SEED` overrides it).
    pub fn of<M: Ndf + 'a>(model: &'a M) -> Self {
        let (seed, seed_error) = seed_from_env(std::env::var("MFH_SEED").ok());
        Self {
            model: Arc::new(model),
            bsdf: None,
            own_ndf: None,
            name: std::any::type_name::<M>().to_string(),
            hints: Hints::default(),
            options: AuditOptions {
                profile: Profile::Quick,
                seed,
                out: None,
                ..Default::default()
            },
            masking: None,
            sampling: None,
            slope_moments: false,
            theta_max: FRAC_PI_2,
            against: None,
            seed_error,
            implemented: None,
            precision: Precision::F64,
            d_only: false,
            remote: false,
        }
    }

    /// `Audit::of(model)` with the capability traits `found` wired in: what [`crate::audit!`]
    /// calls, after the compiler has found the traits the model's type implements. Prefer the
    /// macro.
    #[doc(hidden)]
    pub fn of_found<M: Ndf + 'a>(model: &'a M, found: capabilities::Found<'a>) -> Self {
        let mut audit = Audit::of(model);
        audit.model = Arc::new(capabilities::Wired::new(model, found));
        audit.implemented = Some(found.implemented());
        audit
    }

    /// The model answers from another process (the external protocol): each evaluation is a
    /// round trip, and checks whose oracle accuracy is a cost trade-off may use the looser of
    /// their two stated tolerances ([`crate::subject::Subject::remote`]).
    #[doc(hidden)]
    pub fn remote(mut self) -> Self {
        self.remote = true;
        self
    }

    /// States that D is all the model offers (no Smith Λ, no sampler, no slopes): without it, an
    /// audit of a model that offers D alone fails `audit.capabilities`, since a gate written
    /// for a model with Λ and samplers that forgot to offer them would otherwise pass on D.
    pub fn d_only(mut self) -> Self {
        self.d_only = true;
        self
    }

    /// An audit of a whole BSDF `bsdf` (reflection and refraction, sampled and evaluated; see
    /// [`mfh_reference::bsdf`] for the conventions): the chi-square of its sampling over the
    /// whole sphere, the consistency of its sample weights, its failure rate, albedo, energy,
    /// reciprocity and stability at the hard cases; `.against` takes a reference BSDF spec
    /// (`{"bsdf": "dielectric", "eta": 1.5, "ndf": {...}}`); `.ndf` gives the NDF it is built
    /// on, with which it is then compared (`bsdf.ndf_consistency`). The other NDF options
    /// (slope moments, θ max, hints) do not apply.
    ///
    /// ```
    /// use mfh_harness::{Audit, Profile};
    /// use mfh_reference::bsdf::BsdfSpec;
    /// let spec: BsdfSpec = serde_json::from_str(
    ///     r#"{"bsdf":"conductor","n":0.2,"k":3.0,"ndf":{"family":"ggx","alpha":0.5}}"#,
    /// ).unwrap();
    /// let conductor = spec.build().unwrap();
    /// assert!(Audit::of_bsdf(&conductor).profile(Profile::Ci).run().passed());
    /// ```
    pub fn of_bsdf<B: Bsdf + 'a>(bsdf: &'a B) -> Self {
        struct NoNdf;
        impl Ndf for NoNdf {
            fn d(&self, _: mfh_reference::Vec3) -> f64 {
                0.0
            }
        }
        // `&NoNdf` is promoted to a 'static constant: the NDF side plans nothing here.
        let mut audit = Audit::of(&NoNdf);
        audit.bsdf = Some(Arc::new(bsdf));
        audit.name = std::any::type_name::<B>().to_string();
        audit
    }

    /// The NDF (with a Smith Λ) that the BSDF of [`Audit::of_bsdf`] is built on: the BSDF's
    /// values are then compared with Walter 2007's eq 20 and 21 built from this NDF's D and Λ
    /// (`bsdf.ndf_consistency`: the Fresnel factor they leave is a function of |wi·h| alone, in
    /// [0, 1], and reflected and transmitted factors sum to 1). [`Audit::masking`] declares the
    /// BSDF's G2 form (undeclared: the check finds the form that fits, and says which);
    /// [`Audit::sampling`] with visible normals declares that the BSDF samples this NDF's
    /// visible normals (choosing reflection with probability F where it transmits), which adds
    /// its pdf to the comparison. The NDF itself is audited by [`Audit::of`].
    pub fn ndf<N: Ndf + 'a>(mut self, ndf: &'a N) -> Self {
        self.own_ndf = Some(Arc::new(ndf));
        self
    }

    /// The capability traits the model's type implements (set by [`crate::audit!`], which has
    /// the compiler find them): one that its `as_*` method does not declare fails the
    /// `audit.capabilities` record.
    pub fn implemented(mut self, implemented: capabilities::Implemented) -> Self {
        self.implemented = Some(implemented);
        self
    }

    /// The precision the model computes in (default f64): a float32 implementation is judged
    /// with value tolerances budgeted in float32 ε (`tolerance::Tolerance::at`) and oracles
    /// that stop at its rounding floor; statistical checks are unchanged. For
    /// [`Audit::of_bsdf`] too (the BSDF checks' `_f32` rows, `tolerance/bsdf.rs`).
    pub fn precision(mut self, precision: Precision) -> Self {
        self.precision = precision;
        self
    }

    /// The name records give the model (default: its Rust type name).
    pub fn name(mut self, name: &str) -> Self {
        self.name = name.to_string();
        self
    }

    /// The profile (default quick; `Profile::Ci` is sized for one model in CI).
    pub fn profile(mut self, profile: Profile) -> Self {
        self.options.profile = profile;
        self
    }

    /// The audit seed.
    pub fn seed(mut self, seed: u64) -> Self {
        self.options.seed = seed;
        self
    }

    /// What is known of the model's lobe, to speed the oracles up (never needed).
    pub fn hint(mut self, hints: Hints) -> Self {
        self.hints = hints;
        self
    }

    /// The G2 form the renderer uses (None: it does not mask; default: checked if the model
    /// has Smith masking). For [`Audit::of_bsdf`] with [`Audit::ndf`]: the BSDF's G2 form
    /// (None or default: not declared).
    pub fn masking(mut self, masking: Option<Masking>) -> Self {
        self.masking = Some(masking);
        self
    }

    /// How the renderer samples (None: it does not; default: normals if the model has a
    /// sampler, visible normals too if it has a visible-normal sampler). For
    /// [`Audit::of_bsdf`] with [`Audit::ndf`]: visible normals declares that the BSDF samples
    /// that NDF's visible normals (Walter §5.3's lobe choice by F where it transmits).
    pub fn sampling(mut self, sampling: Option<Sampling>) -> Self {
        self.sampling = Some(sampling);
        self
    }

    /// Whether the renderer filters with slope moments (needs the slope capability).
    pub fn slope_moments(mut self, on: bool) -> Self {
        self.slope_moments = on;
        self
    }

    /// The largest incidence the renderer evaluates (radians, default π/2).
    pub fn theta_max(mut self, theta_max: f64) -> Self {
        self.theta_max = theta_max;
        self
    }

    /// Also compare the model value by value with the reference closed forms of `spec`
    /// (JSON, e.g. `{"family":"ggx","alpha":0.3}`; for [`Audit::of_bsdf`] a reference BSDF
    /// spec, e.g. `{"bsdf":"dielectric","eta":1.5,"ndf":{"family":"ggx","alpha":0.3}}`).
    pub fn against(mut self, spec: &str) -> Self {
        self.against = Some(spec.to_string());
        self
    }

    /// Where reports' artefacts go (chi-square tables, heat maps).
    pub fn out(mut self, dir: impl Into<PathBuf>) -> Self {
        self.options.out = Some(dir.into());
        self
    }

    /// Streaming, resuming and a time limit ([`crate::run::RunControl`]): a callback told when
    /// each check starts and finishes (with its record, e.g. to stream records to a log as the
    /// CLI does into `report.jsonl`), records of an earlier run to take instead of running their
    /// checks, and a wall-time limit after which no check starts.
    pub fn control(mut self, control: crate::run::RunControl) -> Self {
        self.options.control = control;
        self
    }

    /// The effects the plan follows: the declared ones, else what the capabilities allow.
    pub fn effects(&self) -> Effects {
        let m = &self.model;
        Effects {
            masking: self
                .masking
                .unwrap_or_else(|| m.as_smith().is_some().then_some(Masking::HeightCorrelated)),
            sampling: self.sampling.unwrap_or_else(|| {
                if m.as_visible_sampler().is_some() {
                    Some(Sampling::VisibleNormals)
                } else {
                    m.as_sampler().is_some().then_some(Sampling::Normals)
                }
            }),
            slope_moments: self.slope_moments,
            theta_max: self.theta_max,
        }
    }

    /// The planned checks, each with the reason it is planned, and any configuration error as
    /// a record that fails.
    pub fn plan(&self) -> (Vec<PlannedCheck<'a>>, Vec<CheckRecord>) {
        if let Some(bsdf) = &self.bsdf {
            return self.plan_bsdf(bsdf.clone());
        }
        // What the model's answers say of its precision (`audit.precision`); a float32 model
        // declared f64 is judged at f32, and the record says so.
        let (seen, precision) = precision_probe::judge(self.precision, || {
            precision_probe::probe(self.model.as_ref())
        });
        let constructor = if self.remote {
            Subject::remote_at
        } else {
            Subject::user_at
        };
        let subject = constructor(
            self.model.clone(),
            &self.name,
            self.hints.clone(),
            precision,
        );
        let why = format!("model `{}`", self.name);
        let mut errors = Vec::new();
        if let Some(message) = &self.seed_error {
            errors.push(config_error(&subject.label, message.clone()));
        }
        if !(self.theta_max > 0.0 && self.theta_max <= FRAC_PI_2) {
            errors.push(config_error(
                &subject.label,
                format!("theta_max = {} is outside (0, π/2]", self.theta_max),
            ));
        }
        if let Some(seen) = seen {
            let mut r = precision_probe::record(&subject.label, self.precision, seen);
            r.precision = precision;
            errors.push(r);
        }
        let effects = self.effects();
        errors.push(capabilities_record(
            &subject.label,
            self.model.as_ref(),
            self.implemented,
            self.d_only,
        ));
        let mut plan = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            plan_model(&subject, &effects, self.options.profile, &why)
        }))
        .unwrap_or_else(|_| {
            errors.push(config_error(
                &subject.label,
                "the model panicked while the audit was planned".into(),
            ));
            Vec::new()
        });
        if let Some(text) = &self.against {
            match serde_json::from_str::<ModelSpec>(text)
                .map_err(|e| e.to_string())
                .and_then(|s| s.build().map(|_| s).map_err(|e| e.to_string()))
            {
                Ok(spec) => plan.extend(against::plan(&subject, &spec, &why)),
                Err(e) => errors.push(config_error(
                    &subject.label,
                    format!("against: the reference spec {text} is invalid: {e}"),
                )),
            }
        }
        stamp_precision(&mut plan, &mut errors, precision);
        (plan, errors)
    }

    /// The plan of a BSDF audit.
    fn plan_bsdf(&self, bsdf: Arc<dyn Bsdf + 'a>) -> (Vec<PlannedCheck<'a>>, Vec<CheckRecord>) {
        let own_ndf = self.own_ndf.clone().map(|ndf| OwnNdf {
            ndf,
            masking: self.masking.flatten(),
            visible_normals: self.sampling == Some(Some(Sampling::VisibleNormals)),
        });
        // What its answers say of its precision, as for a model (`audit.precision`).
        let (seen, precision) = precision_probe::judge(self.precision, || {
            precision_probe::probe_bsdf(bsdf.as_ref())
        });
        let subject = BsdfSubject::user(bsdf, &self.name, own_ndf, precision);
        let why = format!("BSDF `{}`", self.name);
        let mut errors = Vec::new();
        if let Some(message) = &self.seed_error {
            errors.push(config_error(&subject.label, message.clone()));
        }
        if let Some(seen) = seen {
            errors.push(precision_probe::record(
                &subject.label,
                self.precision,
                seen,
            ));
        }
        let mut plan = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            check::bsdf::plan(&subject, self.options.profile, &why)
        }))
        .unwrap_or_else(|_| {
            errors.push(config_error(
                &subject.label,
                "the BSDF panicked while the audit was planned".into(),
            ));
            Vec::new()
        });
        if let Some(text) = &self.against {
            match serde_json::from_str::<BsdfSpec>(text)
                .map_err(|e| e.to_string())
                .and_then(|s| s.validate().map(|_| s).map_err(|e| e.to_string()))
            {
                Ok(spec) => plan.extend(check::bsdf::plan_against(&subject, &spec, &why)),
                Err(e) => errors.push(config_error(
                    &subject.label,
                    format!("against: the reference BSDF spec {text} is invalid: {e}"),
                )),
            }
        }
        stamp_precision(&mut plan, &mut errors, precision);
        (plan, errors)
    }

    /// Runs the audit. Consumes the builder, so that
    /// `Audit::of(&m).profile(Profile::Ci).run().passed()` is a valid tail expression of a
    /// function that owns `m` (a borrowing `run` left the builder a temporary that outlived
    /// `m`: E0597 on edition 2021).
    pub fn run(self) -> AuditReport {
        let t = Instant::now();
        let (plan, mut errors) = self.plan();
        let (mut records, k, alpha) = run_plan(&plan, &self.options);
        records.append(&mut errors);

        let command = format!(
            "MFH_SEED={} cargo test (Audit::of({}).profile(Profile::{:?}))",
            self.options.seed, self.name, self.options.profile
        );
        AuditReport::from_records(
            self.name.clone(),
            &self.options,
            command,
            records,
            (k, alpha),
            t.elapsed().as_secs_f64(),
        )
    }
}

/// Every record carries the precision it was judged at (the declared one, or f32 when
/// `audit.precision` found a float32 implementation declared f64): stamped by the runner, so
/// that `Audit::run` and the external audit's own runner both see it.
fn stamp_precision(
    plan: &mut [PlannedCheck<'_>],
    errors: &mut [CheckRecord],
    precision: Precision,
) {
    for p in plan {
        let run = std::mem::replace(&mut p.run, Box::new(|_| unreachable_record()));
        p.run = Box::new(move |ctx| {
            let mut r = run(ctx);
            r.precision = precision;
            r
        });
    }
    for e in errors {
        e.precision = precision;
    }
}

/// The audit seed from `MFH_SEED`'s value: the default when unset; when set but not a seed,
/// the default and the error the audit reports as a failing `audit.configuration` record
/// (the CLI refuses it with exit 2).
fn seed_from_env(value: Option<String>) -> (u64, Option<String>) {
    match value {
        None => (DEFAULT_SEED, None),
        Some(text) => match text.trim().parse::<u64>() {
            Ok(seed) => (seed, None),
            Err(_) => (
                DEFAULT_SEED,
                Some(format!(
                    "MFH_SEED = {text:?} is not a seed (an integer in 0..=18446744073709551615)"
                )),
            ),
        },
    }
}

/// The `audit.capabilities` record: the capabilities the model offers (and so is audited on)
/// and those it does not; with [`crate::audit!`], those its type implements, among them the
/// ones wired in because no `as_*` method declared them. It fails when the model offers D
/// alone and the caller did not state so ([`Audit::d_only`]), or stated so of a model that
/// offers more.
fn capabilities_record(
    model: &serde_json::Value,
    ndf: &dyn Ndf,
    implemented: Option<capabilities::Implemented>,
    d_only: bool,
) -> CheckRecord {
    let declared = capabilities::declared(ndf);
    let audited: Vec<&str> = declared.iter().filter(|d| d.2).map(|d| d.1).collect();
    let not_offered: Vec<&str> = declared.iter().filter(|d| !d.2).map(|d| d.1).collect();
    let mut case = json!({"audited": audited, "not_offered": not_offered, "d_only": d_only});
    let mut r = CheckRecord::new(
        "audit.capabilities",
        model.clone(),
        json!({}),
        "the capability traits of mfh_reference::model",
    );
    r.verdict = Verdict::Pass;
    match implemented {
        None => {
            case["implemented"] = json!(
                "not detected: Audit::of sees only what the as_* methods declare \
                 (audit with mfh_harness::audit!(model) to find and wire every trait)"
            );
        }
        Some(i) => {
            case["implemented"] = json!(declared
                .iter()
                .filter(|d| i.has(d.0))
                .map(|d| d.1)
                .collect::<Vec<_>>());
        }
    }
    let mut problems = Vec::new();
    if audited.is_empty() && !d_only {
        problems.push(
            "the model offers D alone, so only D is audited: if D is all it has, say so with \
             .d_only(); if its type implements Smith or a sampler, audit it with \
             mfh_harness::audit!(model), which finds and wires them"
                .to_string(),
        );
    }
    if d_only && !audited.is_empty() {
        problems.push(format!(
            ".d_only() was stated, but the model offers {}",
            audited.join(", ")
        ));
    }
    if !problems.is_empty() {
        case["problems"] = json!(problems);
        r.verdict = Verdict::Fail;
    }
    r.case = case;
    r
}

/// The placeholder runner while a planned check's runner is wrapped (never run).
fn unreachable_record() -> CheckRecord {
    config_error(&json!(null), "a placeholder runner ran".into())
}

fn config_error(model: &serde_json::Value, message: String) -> CheckRecord {
    let mut r = CheckRecord::new("audit.configuration", model.clone(), json!({}), "");
    r.verdict = Verdict::Error { message };
    r
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_unparsable_mfh_seed_is_an_error_naming_it() {
        assert_eq!(seed_from_env(None), (DEFAULT_SEED, None));
        assert_eq!(seed_from_env(Some(" 42 ".into())), (42, None));
        let (seed, error) = seed_from_env(Some("0x2a".into()));
        assert_eq!(seed, DEFAULT_SEED);
        let error = error.expect("an error");
        assert!(
            error.contains("MFH_SEED") && error.contains("0x2a"),
            "{error}"
        );
        assert!(seed_from_env(Some("-1".into())).1.is_some());
    }
}
