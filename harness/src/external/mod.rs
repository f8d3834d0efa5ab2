//! Audit an implementation in any language: a child process speaking the external protocol
//! (JSON lines over stdin / stdout, [`protocol`]) is one more implementation of the capability
//! traits ([`model::ExternalModel`]), audited by [`crate::audit::Audit`] like a Rust model.

pub mod group;
pub mod model;
pub mod process;
pub mod protocol;
pub mod stderr_tail;

pub use model::ExternalModel;
pub use process::{ExternalError, DEFAULT_TIMEOUT_SECONDS};

use crate::audit::Audit;
use crate::check::Profile;
use crate::record::{CheckRecord, Verdict};
use crate::run::{AuditOptions, AuditReport};
use serde_json::json;
use std::path::PathBuf;
use std::time::Duration;

/// What `mfh audit-external` is asked to do.
#[derive(Debug, Clone)]
pub struct ExternalAudit {
    /// The command, run with `sh -c`.
    pub command: String,
    /// The profile.
    pub profile: Profile,
    /// The audit seed.
    pub seed: u64,
    /// A reference spec (JSON) to compare with value by value.
    pub against: Option<String>,
    /// The per-request timeout.
    pub timeout: Duration,
    /// Where artefacts go.
    pub out: Option<PathBuf>,
}

/// Starts the child, audits it, shuts it down. A child that cannot be started or describe
/// itself is an error (bad input); a protocol error during the audit is an `external.protocol`
/// error record in the report (the audit fails).
pub fn audit(request: &ExternalAudit) -> Result<AuditReport, ExternalError> {
    let model = ExternalModel::start(&request.command, request.timeout)?;
    let description = model.description().clone();
    let name = description
        .name
        .clone()
        .unwrap_or_else(|| request.command.clone());
    let mut audit = Audit::of(&model)
        .name(&name)
        .profile(request.profile)
        .seed(request.seed);
    if let Some(spec) = &request.against {
        audit = audit.against(spec);
    }
    if let Some(out) = &request.out {
        audit = audit.out(out.clone());
    }
    let mut report = audit.run();
    let protocol_error = model.first_error();
    model.shutdown();
    let label = json!({
        "name": name,
        "command": request.command,
        "parameters": description.parameters,
        "capabilities": description.capabilities,
    });
    let mut records = std::mem::take(&mut report.records);
    if let Some(e) = protocol_error {
        let mut r = CheckRecord::new("external.protocol", label, json!({}), "");
        r.verdict = Verdict::Error {
            message: e.to_string(),
        };
        records.push(r);
    }
    let options = AuditOptions {
        profile: request.profile,
        seed: request.seed,
        out: request.out.clone(),
        ..Default::default()
    };
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
        report.summary.statistical,
        report.summary.wall_seconds,
    ))
}
