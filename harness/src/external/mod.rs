//! Audit an implementation in any language: a child process speaking the external protocol
//! (JSON lines over stdin / stdout, [`protocol`]) is one more implementation of the capability
//! traits and of [`mfh_reference::bsdf::Bsdf`] ([`model::ExternalModel`], [`bsdf`]), audited
//! by [`crate::audit::Audit`] like a Rust model or BSDF.
//!
//! **One concept per file.** `protocol.rs` the wire format of versions 1 (JSON arrays) and 2
//! (base64 f64 arrays); `process.rs` the child, its reader and writer threads and timeouts;
//! `group.rs` its process group (ended by SIGTERM, then SIGKILL; the live groups listed for a
//! signal handler); `stderr_tail.rs` its stderr drained into a ring buffer of fixed size;
//! `model.rs` the capability traits; `bsdf.rs` the `Bsdf` capability; `against.rs` the NDF or
//! BSDF spec of `--against`.

pub mod against;
pub mod bsdf;
pub mod group;
pub mod model;
pub mod process;
pub mod protocol;
pub mod stderr_tail;

pub use against::Against;
pub use model::ExternalModel;
pub use process::{ExternalError, DEFAULT_TIMEOUT_SECONDS};

use crate::audit::{capabilities, Audit};
use crate::check::{PlannedCheck, Profile};
use crate::record::{CheckRecord, Verdict};
use crate::run::{run_plan, AuditOptions, AuditReport};
use serde_json::json;
use std::path::PathBuf;
use std::time::{Duration, Instant};

/// What `mfh audit-external` is asked to do.
#[derive(Debug, Clone)]
pub struct ExternalAudit {
    /// The command, run with `sh -c`.
    pub command: String,
    /// The profile.
    pub profile: Profile,
    /// The audit seed.
    pub seed: u64,
    /// A reference spec (JSON) to compare with value by value: an NDF's or a BSDF's
    /// ([`Against`]).
    pub against: Option<String>,
    /// The per-request timeout.
    pub timeout: Duration,
    /// Where artefacts go.
    pub out: Option<PathBuf>,
    /// Check events, resumed records and the time limit ([`crate::run::RunControl`]).
    pub control: crate::run::RunControl,
}

/// Starts the child, audits it, shuts it down: the NDF checks if it offers an NDF (`d`), the
/// BSDF checks ([`crate::check::bsdf::plan`], as [`Audit::of_bsdf`]) if it offers a BSDF, both
/// in one plan, and then, if the NDF has a Smith Λ, the BSDF against that NDF
/// (`bsdf.ndf_consistency`, with the `masking` and `sampling` it declares); `against` goes to the side its spec is of ([`Against`]). A child that cannot be
/// started or describe itself is an error (bad input); a protocol error during the audit is an
/// `external.protocol` error record in the report (the audit fails).
pub fn audit(request: &ExternalAudit) -> Result<AuditReport, ExternalError> {
    let t = Instant::now();
    let model = ExternalModel::start(&request.command, request.timeout)?;
    let description = model.description().clone();
    // A reference of a kind the child does not offer is bad input, refused before any check
    // runs (as a failing record it was found only once the whole audit had run).
    if let Some(why) = against_not_offered(request.against.as_deref(), &description) {
        model.shutdown();
        return Err(ExternalError::Describe(why));
    }
    let name = description
        .name
        .clone()
        .unwrap_or_else(|| request.command.clone());
    let label = json!({
        "name": name,
        "command": request.command,
        "parameters": description.parameters,
        "capabilities": description.capabilities,
    });
    let options = AuditOptions {
        profile: request.profile,
        seed: request.seed,
        out: request.out.clone(),
        control: request.control.clone(),
        ..Default::default()
    };
    let (plan, mut errors) = plan(&model, request, &name, &label);
    let (mut records, k, alpha) = run_plan(&plan, &options);
    drop(plan);
    records.append(&mut errors);
    let protocol_error = model.first_error();
    let nans = model.nan_answers();
    model.shutdown();
    records.extend(nans.iter().map(|n| nan_record(&label, n)));
    if let Some(e) = protocol_error {
        records.push(error_record("external.protocol", &label, e.to_string()));
    }
    let mut command = format!(
        "MFH_SEED={} mfh audit-external --cmd {:?} --profile {}",
        request.seed,
        request.command,
        request.profile.name()
    );
    if let Some(spec) = &request.against {
        command.push_str(&format!(" --against '{spec}'"));
    }
    Ok(AuditReport::from_records(
        name,
        &options,
        command,
        records,
        (k, alpha),
        t.elapsed().as_secs_f64(),
    ))
}

/// The checks of the child's NDF and of its BSDF, each planned as [`Audit::of`] and
/// [`Audit::of_bsdf`] (with [`Audit::ndf`] when it offers both) plan them, and the
/// configuration errors (an `--against` spec that is invalid, or of a kind the child does not
/// offer) as records that fail. Public for tests that run part of an external audit.
pub fn plan<'a>(
    model: &'a ExternalModel,
    request: &ExternalAudit,
    name: &str,
    label: &serde_json::Value,
) -> (Vec<PlannedCheck<'a>>, Vec<CheckRecord>) {
    let description = model.description();
    let against = request.against.as_deref().map(Against::parse);
    let configure = |audit: Audit<'a>, wanted: fn(&Against) -> bool| {
        let audit = audit
            .name(name)
            .profile(request.profile)
            .seed(request.seed)
            .precision(description.precision());
        match (&against, &request.against) {
            (Some(Ok(spec)), Some(text)) if wanted(spec) => audit.against(text),
            _ => audit,
        }
    };
    let (mut plan, mut errors) = (Vec::new(), Vec::new());
    if description.has_ndf() {
        let mut audit = configure(Audit::of(model), |a| matches!(a, Against::Ndf(_))).remote();
        if capabilities::declared(model).iter().all(|d| !d.2) {
            // The child's describe names its capabilities: D alone is its own statement.
            audit = audit.d_only();
        }
        let (p, e) = audit.plan();
        plan.extend(p);
        errors.extend(e);
    }
    if description.has_bsdf() {
        let mut audit = configure(Audit::of_bsdf(model), |a| matches!(a, Against::Bsdf(_)));
        if description.has_ndf() && description.has("lambda") {
            // Its own NDF: the BSDF is also compared with Walter's formulas built from it.
            audit = audit.ndf(model).masking(description.masking());
            if description.visible_normals() {
                audit = audit.sampling(Some(crate::scene::Sampling::VisibleNormals));
            }
        }
        let (p, e) = audit.plan();
        plan.extend(p);
        errors.extend(e);
    }
    match &against {
        Some(Err(e)) => errors.push(error_record(
            "audit.configuration",
            label,
            format!("against: {e}"),
        )),
        Some(Ok(_)) => errors.extend(
            against_not_offered(request.against.as_deref(), description)
                .map(|why| error_record("audit.configuration", label, why)),
        ),
        None => {}
    }
    (plan, errors)
}

/// The failing `external.nan` record of one array that held NaN answers: the request, the
/// array, how many items and the first (its index and input). The checks that met the NaN fail
/// on their own, as for a Rust model; this record says where it came from.
pub fn nan_record(label: &serde_json::Value, n: &model::NanAnswers) -> CheckRecord {
    let (index, input) = match &n.first {
        ExternalError::NotANumber { index, input, .. } => (*index, input.clone()),
        _ => (0, String::new()),
    };
    let mut r = CheckRecord::new(
        "external.nan",
        label.clone(),
        json!({
            "request": n.op,
            "array": n.field,
            "nan_items": n.count,
            "first_item": index,
            "input": input,
            "finding": format!(
                "the child answered NaN in {:?} of {} ({} items; first: {})",
                n.field, n.op, n.count, n.first
            ),
        }),
        "the external protocol: answers are numbers; NaN is a defect of the model",
    );
    r.value = Some(n.count as f64);
    r.verdict = Verdict::Fail;
    r
}

/// Why the reference `against` (valid) is of a kind the child does not offer — an NDF spec for
/// a child that offers only a BSDF, or the reverse — or None.
fn against_not_offered(
    against: Option<&str>,
    description: &protocol::Description,
) -> Option<String> {
    let spec = Against::parse(against?).ok()?;
    let offered = match spec {
        Against::Ndf(_) => description.has_ndf(),
        Against::Bsdf(_) => description.has_bsdf(),
    };
    (!offered).then(|| {
        format!(
            "against: the spec is of {}, which the child does not offer (its capabilities: \
             {})",
            spec.kind(),
            description.capabilities.join(", ")
        )
    })
}

/// A record of `check` that errs with `message`.
fn error_record(check: &str, label: &serde_json::Value, message: String) -> CheckRecord {
    let mut r = CheckRecord::new(check, label.clone(), json!({}), "");
    r.verdict = Verdict::Error { message };
    r
}
