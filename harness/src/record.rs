//! CheckRecord: what one check of one property of one model at one case found, and the schema
//! version of the records (ARCHITECTURE.md, "Checks and records").

use crate::record_serde::{interned, nullable_f64};
use serde::{Deserialize, Serialize};
use serde_json::Value;

/// The version of the record schema written into `report.json`; bump it when a field changes
/// meaning or disappears (adding a field keeps the version).
pub const SCHEMA_VERSION: u32 = 1;

/// The outcome of a check.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "verdict", rename_all = "snake_case")]
pub enum Verdict {
    /// The property holds within the tolerance.
    Pass,
    /// The property does not hold.
    Fail,
    /// The property does not hold, as expected: a printed formula with an erratum, or a route
    /// outside its domain of accuracy. `reason` says which.
    ExpectedFailure {
        /// Why the failure is expected (an erratum id and what it is).
        reason: String,
    },
    /// An expected failure that did not fail: the record met its tolerance although the table
    /// of expected failures lists it (as libm-test's xfail table), so the table is no longer
    /// true. Counts as a failure, so that the entry is removed or narrowed.
    UnexpectedPass {
        /// The entry that expected the failure (its erratum id and reason).
        reason: String,
    },
    /// The check did not run.
    Skipped {
        /// Why.
        reason: String,
    },
    /// The check could not be carried out (the model rejected the case, the oracle failed).
    Error {
        /// What went wrong.
        message: String,
    },
}

impl Verdict {
    /// The short name used in summaries: pass, fail, expected_failure, unexpected_pass,
    /// skipped, error.
    pub fn name(&self) -> &'static str {
        match self {
            Verdict::Pass => "pass",
            Verdict::Fail => "fail",
            Verdict::ExpectedFailure { .. } => "expected_failure",
            Verdict::UnexpectedPass { .. } => "unexpected_pass",
            Verdict::Skipped { .. } => "skipped",
            Verdict::Error { .. } => "error",
        }
    }

    /// Whether this verdict makes an audit fail (fail, unexpected_pass or error).
    pub fn is_failure(&self) -> bool {
        matches!(
            self,
            Verdict::Fail | Verdict::UnexpectedPass { .. } | Verdict::Error { .. }
        )
    }
}

/// The oracle's value with its own uncertainty.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct OracleValue {
    /// The value.
    #[serde(deserialize_with = "nullable_f64")]
    pub value: f64,
    /// The bound on the oracle's error (quadrature) or its standard error (Monte Carlo).
    #[serde(deserialize_with = "nullable_f64")]
    pub uncertainty: f64,
    /// What the uncertainty is: `error_bound` or `standard_error`.
    #[serde(deserialize_with = "interned")]
    pub kind: crate::record_serde::StaticStr,
    /// The rounding floor the oracle stopped at, where the implementation's declared precision
    /// set it above the accuracy the oracle was asked for (a float32 model): its uncertainty is
    /// then what that floor allows, not what the target asked. Absent for an f64 model and in
    /// reports written before it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub noise_floor: Option<NoiseFloor>,
}

/// The rounding floor an oracle integrating an implementation's values stopped at: below it
/// refinement only trades one rounding error for another (ARCHITECTURE.md, "Tolerances and
/// expected failures").
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct NoiseFloor {
    /// The relative rounding of one evaluation of the integrand (the declared precision's ε).
    #[serde(deserialize_with = "nullable_f64")]
    pub noise: f64,
    /// The relative error the oracle's stopping rule accepts because of it, at least the
    /// accuracy asked: 32 ε of ∫|f| for the adaptive quadratures, 64 ε per cell for the
    /// chi-square masses, 16 ε per span for the KS table.
    #[serde(deserialize_with = "nullable_f64")]
    pub floor: f64,
}

impl OracleValue {
    /// The oracle's bound relative to its value (absolute where the value is 0).
    pub fn relative_uncertainty(&self) -> f64 {
        if self.value == 0.0 {
            self.uncertainty
        } else {
            self.uncertainty / self.value.abs()
        }
    }

    /// One line on the rounding floor the oracle stopped at, if it did: "oracle stopped at the
    /// implementation's rounding floor: integrand noise 1.2e-7 relative, floor 3.8e-6, bound
    /// 2.1e-7".
    pub fn noise_note(&self) -> Option<String> {
        self.noise_floor.map(|n| {
            format!(
                "oracle stopped at the implementation's rounding floor: integrand noise {:.1e} \
                 relative, floor {:.1e}, bound {:.1e}",
                n.noise,
                n.floor,
                self.relative_uncertainty()
            )
        })
    }
}

/// The measured discrepancy.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Measured {
    /// |value − oracle|.
    Absolute {
        /// The error.
        #[serde(deserialize_with = "nullable_f64")]
        error: f64,
    },
    /// |value − oracle| / |oracle|.
    Relative {
        /// The error.
        #[serde(deserialize_with = "nullable_f64")]
        error: f64,
    },
    /// A statistical test.
    PValue {
        /// The p-value (of a chi-square: the test's, from its statistic split into the cos θ
        /// marginal's smooth components and the rest, `oracle/chi2/components.rs`; so not
        /// Q(dof/2, statistic/2) of the two fields below).
        #[serde(deserialize_with = "nullable_f64")]
        p: f64,
        /// The test statistic (of a chi-square: Pearson's, over the whole pooled table).
        #[serde(deserialize_with = "nullable_f64")]
        statistic: f64,
        /// Degrees of freedom (0 where the test has none, e.g. Kolmogorov–Smirnov).
        dof: usize,
        /// The level the verdict was taken at (after the Šidák correction).
        #[serde(deserialize_with = "nullable_f64")]
        alpha: f64,
    },
    /// An estimated rate (e.g. the exponent of a convergence law).
    Rate {
        /// The measured exponent.
        #[serde(deserialize_with = "nullable_f64")]
        exponent: f64,
        /// The expected exponent.
        #[serde(deserialize_with = "nullable_f64")]
        expected: f64,
    },
}

impl Measured {
    /// The error as one number for "worst error" summaries (p-values and rates excluded).
    pub fn error(&self) -> Option<f64> {
        match *self {
            Measured::Absolute { error } | Measured::Relative { error } => Some(error),
            Measured::Rate { exponent, expected } => Some((exponent - expected).abs()),
            Measured::PValue { .. } => None,
        }
    }
}

/// The tolerance a check applied, with its reason (from [`crate::tolerance`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AppliedTolerance {
    /// The tolerance's name in the table.
    #[serde(deserialize_with = "interned")]
    pub name: crate::record_serde::StaticStr,
    /// The allowed error (relative or absolute as `measured` says; for p-values, α).
    #[serde(deserialize_with = "nullable_f64")]
    pub value: f64,
    /// Why this tolerance.
    #[serde(deserialize_with = "interned")]
    pub reason: crate::record_serde::StaticStr,
}

/// What a check cost.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Cost {
    /// Wall time, seconds.
    #[serde(deserialize_with = "nullable_f64")]
    pub wall_seconds: f64,
    /// Function evaluations of the oracle.
    pub evaluations: u64,
    /// Random samples drawn.
    pub samples: u64,
}

/// One check of one property of one model at one case.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CheckRecord {
    /// The check id, `family.property` (e.g. `smith.lambda_integral`).
    pub check: String,
    /// The model spec (JSON), or null for checks of non-NDF objects (SG, ASG).
    pub model: Value,
    /// The case: the point and parameters (θ, route, γ, …).
    pub case: Value,
    /// The value under test.
    pub value: Option<f64>,
    /// The oracle's value and its uncertainty.
    pub oracle: Option<OracleValue>,
    /// The measured discrepancy.
    pub measured: Option<Measured>,
    /// The tolerance applied.
    pub tolerance: Option<AppliedTolerance>,
    /// The verdict.
    #[serde(flatten)]
    pub verdict: Verdict,
    /// The cost.
    pub cost: Cost,
    /// The seed of the check's random stream (statistical checks).
    pub seed: Option<u64>,
    /// The precision the implementation was judged at (its value tolerances and the oracles'
    /// rounding floors; `f64` in reports written before float32 support).
    #[serde(default)]
    pub precision: crate::precision::Precision,
    /// The source: document and equation.
    pub source: String,
    /// The closed forms this record exercises (`family/quantity/route`), for the coverage registry.
    pub covers: Vec<String>,
    /// Paths of artefacts written for this record (heat maps, tables), by the sinks.
    pub artefacts: Vec<String>,
    /// Data the check measured beyond one number (a chi-square table, a KS marginal), for the
    /// sinks to write as artefacts and plot. Checks fill it and do no I/O; the file sinks
    /// write it into artefact files and leave it out of `report.json` (which lists the paths).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub data: Option<RecordData>,
    /// Where a check that sweeps incidences fails: the interval of θi its failure was narrowed
    /// to by bisection (`check/regime.rs`); None for a check that does not sweep, or passes.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub region: Option<Region>,
}

/// The region a failing sweep was narrowed to: "density off by up to 1.1 % for
/// θi ∈ [0, 0.089] rad at α 0.05".
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Region {
    /// The swept quantity (`theta_i`, radians).
    pub quantity: String,
    /// The region's ends: the failing incidences nearest the passing ones after bisection.
    pub from: f64,
    /// See `from`.
    pub to: f64,
    /// The largest error measured in the region.
    #[serde(deserialize_with = "nullable_f64")]
    pub worst: f64,
    /// The incidence of the worst error among the sweep's.
    pub at: f64,
    /// How many of the sweep's incidences fail (the region holds the run around the worst;
    /// others may fail elsewhere).
    pub failing_incidences: usize,
    /// How many incidences the sweep measured.
    pub incidences: usize,
    /// The region in words.
    pub text: String,
}

/// The data a check measured beyond one number: what the sinks (`crate::report`) write as
/// artefact files and draw as plots.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum RecordData {
    /// The observed and expected counts of a chi-square test over the (φ, cos θ) grid of the
    /// upper hemisphere: `rows` cos θ-rows (row 0 at the horizon, cos θ ∈ [z_i, z_{i+1})) ×
    /// `columns` = 2R φ-columns (φ ∈ [φ_j, φ_{j+1})), row-major; the edges are `z_edges` and
    /// `phi_edges` (empty in records written before the lobe-quantile cells: the equal-area i/R and 2πj/2R).
    Chi2Table {
        /// cos θ-rows R.
        rows: usize,
        /// φ-columns 2R.
        columns: usize,
        /// Samples drawn.
        samples: u64,
        /// The seed of the random streams.
        seed: u64,
        /// Observed counts per cell.
        observed: Vec<u64>,
        /// Expected counts per cell (pdf mass × samples).
        #[serde(deserialize_with = "crate::record_serde::nullable_f64_vec")]
        expected: Vec<f64>,
        /// The row edges z₀ = 0 < … < z_R = 1 (cos θ; empty: i/R).
        #[serde(default, skip_serializing_if = "Vec::is_empty")]
        z_edges: Vec<f64>,
        /// The column edges φ₀ = 0 < … < φ_2R = 2π (empty: 2πj/2R).
        #[serde(default, skip_serializing_if = "Vec::is_empty")]
        phi_edges: Vec<f64>,
    },
    /// The observed and expected counts of a BSDF's chi-square test over the whole sphere: each
    /// hemisphere on a grid as [`RecordData::Chi2Table`]'s, with edges of its own (the lower
    /// one mirrored through the surface: its row 0 is at the horizon, its last row at −z), the
    /// expected counts those of the successful samples.
    SphereChi2Table {
        /// cos θ-rows R of each hemisphere.
        rows: usize,
        /// φ-columns 2R.
        columns: usize,
        /// Samples drawn (failed ones included).
        samples: u64,
        /// The seed of the random streams.
        seed: u64,
        /// Observed counts per cell above the surface (reflection from outside).
        upper_observed: Vec<u64>,
        /// Expected counts per cell above the surface.
        #[serde(deserialize_with = "crate::record_serde::nullable_f64_vec")]
        upper_expected: Vec<f64>,
        /// Observed counts per cell below the surface, mirrored.
        lower_observed: Vec<u64>,
        /// Expected counts per cell below the surface, mirrored.
        #[serde(deserialize_with = "crate::record_serde::nullable_f64_vec")]
        lower_expected: Vec<f64>,
        /// The upper hemisphere's row edges z₀ = 0 < … < z_R = 1 (cos θ; empty: i/R).
        #[serde(default, skip_serializing_if = "Vec::is_empty")]
        upper_z_edges: Vec<f64>,
        /// The upper hemisphere's column edges φ₀ = 0 < … < φ_2R = 2π (empty: 2πj/2R).
        #[serde(default, skip_serializing_if = "Vec::is_empty")]
        upper_phi_edges: Vec<f64>,
        /// The lower hemisphere's row edges (mirrored cos θ, as `upper_z_edges`).
        #[serde(default, skip_serializing_if = "Vec::is_empty")]
        lower_z_edges: Vec<f64>,
        /// The lower hemisphere's column edges.
        #[serde(default, skip_serializing_if = "Vec::is_empty")]
        lower_phi_edges: Vec<f64>,
    },
    /// A Kolmogorov–Smirnov marginal: the model's CDF and an empirical CDF at `x`.
    KsMarginal {
        /// The marginal (`cos_theta` or `phi`).
        marginal: String,
        /// Points of the marginal's range.
        #[serde(deserialize_with = "crate::record_serde::nullable_f64_vec")]
        x: Vec<f64>,
        /// The model's CDF at `x` (the oracle's table).
        #[serde(deserialize_with = "crate::record_serde::nullable_f64_vec")]
        model_cdf: Vec<f64>,
        /// The empirical CDF at `x`.
        #[serde(deserialize_with = "crate::record_serde::nullable_f64_vec")]
        empirical_cdf: Vec<f64>,
        /// Samples behind the empirical CDF.
        samples: u64,
        /// The seed of those samples.
        seed: u64,
    },
    /// A curve y(x), e.g. an error against θ.
    Curve {
        /// What the curve shows.
        label: String,
        /// The abscissae.
        #[serde(deserialize_with = "crate::record_serde::nullable_f64_vec")]
        x: Vec<f64>,
        /// The ordinates.
        #[serde(deserialize_with = "crate::record_serde::nullable_f64_vec")]
        y: Vec<f64>,
    },
}

impl CheckRecord {
    /// A record with the identity fields set and everything else empty (verdict: error, until
    /// the check decides).
    pub fn new(check: &str, model: Value, case: Value, source: &str) -> Self {
        Self {
            check: check.to_string(),
            model,
            case,
            value: None,
            oracle: None,
            measured: None,
            tolerance: None,
            verdict: Verdict::Error {
                message: "the check did not reach a verdict".to_string(),
            },
            cost: Cost::default(),
            seed: None,
            precision: crate::precision::Precision::F64,
            source: source.to_string(),
            covers: Vec::new(),
            artefacts: Vec::new(),
            data: None,
            region: None,
        }
    }

    /// Whether the record is a statistical test (its verdict depends on the audit's α).
    pub fn is_statistical(&self) -> bool {
        matches!(self.measured, Some(Measured::PValue { .. }))
    }

    /// Whether the measured error meets the tolerance: an absolute or relative error within
    /// [`allowed_error`] (the tolerance plus the oracle's own error bound), a rate within the
    /// tolerance of its expected exponent. A NaN error does not meet it. `None` where there is
    /// no error and tolerance to judge: nothing measured, or a p-value (judged at the audit's
    /// level by `run::judge_statistical`). This is the pass rule of `check::compare`, which
    /// calls it, and what `mfh merge` re-judges stored verdicts by.
    pub fn meets_tolerance(&self) -> Option<bool> {
        let tolerance = self.tolerance.as_ref()?;
        Some(match self.measured? {
            Measured::Absolute { error } | Measured::Relative { error } => {
                error <= allowed_error(tolerance.value, self.oracle.as_ref())
            }
            Measured::Rate { exponent, expected } => (exponent - expected).abs() <= tolerance.value,
            Measured::PValue { .. } => return None,
        })
    }

    /// Whether the stored verdict contradicts the record's own numbers
    /// ([`CheckRecord::contradiction`]).
    pub fn verdict_contradicts_measurement(&self) -> bool {
        self.contradiction().is_some()
    }

    /// How the stored verdict contradicts the rest of the record, if it does (what `mfh merge`
    /// and `--resume` re-judge a record read back from a file by, `record_trust::rejudge`):
    /// - a pass whose measured error exceeds the tolerance plus the oracle's slack
    ///   ([`CheckRecord::meets_tolerance`]), or whose check set a tolerance and measured
    ///   nothing against it (a chi-square that failed its sanity checks fails outright, with
    ///   no p-value), or whose case names a sanity failure;
    /// - a skip with anything measured (a skipped check runs nothing);
    /// - an expected failure whose error is within the tolerance (nothing failed).
    ///
    /// A failure, an unexpected pass and an error fail the audit whatever the numbers say, so a
    /// failure with no numbers to re-judge cannot be turned into a pass or a skip.
    pub fn contradiction(&self) -> Option<String> {
        let numbers = || {
            let error = self.measured.and_then(|m| m.error()).unwrap_or(f64::NAN);
            let tolerance = self.tolerance.as_ref().map_or(f64::NAN, |t| t.value);
            let slack = allowed_error(0.0, self.oracle.as_ref());
            format!(
                "measured error {error:e} against tolerance {tolerance:e} + oracle slack {slack:e}"
            )
        };
        let sanity = self.case.get("sanity_failure").is_some();
        match self.verdict {
            Verdict::Pass if self.meets_tolerance() == Some(false) => {
                Some(format!("contradicts {}", numbers()))
            }
            Verdict::Pass if self.tolerance.is_some() && self.measured.is_none() => Some(
                "has a tolerance but nothing measured against it (a check that measured \
                 nothing earned no pass)"
                    .into(),
            ),
            Verdict::Pass | Verdict::Skipped { .. } if sanity => Some(format!(
                "contradicts the sanity failure its case names ({})",
                self.case["sanity_failure"]
            )),
            Verdict::Skipped { .. }
                if self.measured.is_some() || self.tolerance.is_some() || self.value.is_some() =>
            {
                Some("has measurements, but a skipped check runs nothing".into())
            }
            Verdict::ExpectedFailure { .. } if self.meets_tolerance() == Some(true) => {
                Some(format!("contradicts {} (nothing failed)", numbers()))
            }
            _ => None,
        }
    }
}

/// The error a comparison with `oracle` may show and pass: `tolerance` plus the oracle's error
/// bound relative to its value, |(o + u) − o| / |o| (absolute where o = 0). NaN when the oracle
/// value is not finite, so that nothing passes against it.
pub fn allowed_error(tolerance: f64, oracle: Option<&OracleValue>) -> f64 {
    tolerance + oracle.map_or(0.0, |o| relative_error(o.value + o.uncertainty, o.value))
}

/// The relative difference |a − b| / |b| (absolute where b = 0).
pub fn relative_error(a: f64, b: f64) -> f64 {
    if b == 0.0 {
        a.abs()
    } else {
        ((a - b) / b).abs()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A record measuring `error` against `tolerance` with an oracle of value 2 and error bound
    /// `bound` (slack bound/2), its verdict `verdict`.
    fn record(error: f64, tolerance: f64, bound: f64, verdict: Verdict) -> CheckRecord {
        let mut r = CheckRecord::new("x.y", Value::Null, Value::Null, "");
        r.oracle = Some(OracleValue {
            value: 2.0,
            uncertainty: bound,
            kind: "error_bound",
            noise_floor: None,
        });
        r.measured = Some(Measured::Relative { error });
        r.tolerance = Some(AppliedTolerance {
            name: "t",
            value: tolerance,
            reason: "r",
        });
        r.verdict = verdict;
        r
    }

    /// The rule merge re-judges by: the tolerance plus the oracle's relative bound.
    #[test]
    fn a_verdict_is_judged_by_its_error_tolerance_and_oracle_slack() {
        assert_eq!(
            record(1.0, 1e-10, 0.0, Verdict::Pass).meets_tolerance(),
            Some(false)
        );
        assert!(record(1.0, 1e-10, 0.0, Verdict::Pass).verdict_contradicts_measurement());
        // 1.5e-10 ≤ 1e-10 + 2e-10/2: within the oracle's slack.
        assert!(!record(1.5e-10, 1e-10, 2e-10, Verdict::Pass).verdict_contradicts_measurement());
        assert!(record(f64::NAN, 1e-10, 0.0, Verdict::Pass).verdict_contradicts_measurement());
        let skipped = Verdict::Skipped { reason: "s".into() };
        assert!(record(1.0, 1e-10, 0.0, skipped.clone()).verdict_contradicts_measurement());
        // A skip runs nothing: any measurement contradicts it, a bare skip does not.
        assert!(record(0.0, 1e-10, 0.0, skipped.clone()).verdict_contradicts_measurement());
        let mut bare = CheckRecord::new("x.y", Value::Null, Value::Null, "");
        bare.verdict = skipped;
        assert!(!bare.verdict_contradicts_measurement());
        let expected = Verdict::ExpectedFailure { reason: "e".into() };
        assert!(record(0.0, 1e-10, 0.0, expected.clone()).verdict_contradicts_measurement());
        assert!(!record(1.0, 1e-10, 0.0, expected).verdict_contradicts_measurement());
        // A failure stays one whatever its numbers; p-values are judge_statistical's.
        assert!(!record(0.0, 1e-10, 0.0, Verdict::Fail).verdict_contradicts_measurement());
        let mut p = record(0.0, 1e-4, 0.0, Verdict::Pass);
        p.measured = Some(Measured::PValue {
            p: 0.0,
            statistic: 1.0,
            dof: 1,
            alpha: 1e-4,
        });
        assert_eq!(p.meets_tolerance(), None);
    }

    /// A failure without numbers (a chi-square's sanity failure: a tolerance, no p-value, the
    /// reason in its case) cannot be turned into a pass or a skip.
    #[test]
    fn a_numberless_failure_cannot_become_a_pass_or_a_skip() {
        let mut r = record(0.0, 1e-4, 0.0, Verdict::Fail);
        r.measured = None;
        r.case = serde_json::json!({"theta": 0.5, "sanity_failure": "pdf mass 0.9"});
        assert_eq!(r.contradiction(), None);
        r.verdict = Verdict::Pass;
        let why = r.contradiction().unwrap();
        assert!(why.contains("nothing measured"), "{why}");
        r.tolerance = None;
        let why = r.contradiction().unwrap();
        assert!(why.contains("sanity failure"), "{why}");
        r.verdict = Verdict::Skipped { reason: "s".into() };
        assert!(r.contradiction().unwrap().contains("sanity failure"));
    }
}
