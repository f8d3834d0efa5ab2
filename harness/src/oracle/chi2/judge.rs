//! The verdict of the chi-square test from its observed and expected counts: the sanity
//! failures first, then the verdict step [`pearson_test`] — the pooled statistic, its two
//! parts and their p-value against α — which the whole sphere's test
//! (`crate::oracle::chi2::sphere`) takes too.

use super::components::{components, Components};
use super::{Chi2Config, Chi2Result, Expected, Failure, Observed, OutsideHemisphere, TestOutcome};
use crate::oracle::hemisphere_grid::{DirectionError, HemisphereGrid};
use crate::tolerance::{MASS_TOLERANCE, MIN_EXPECTED};

/// The verdict from the observed and expected counts.
pub(super) fn judge(
    config: &Chi2Config,
    grid: HemisphereGrid,
    observed: Observed,
    expected: Expected,
    sampling_seconds: f64,
    integration_seconds: f64,
) -> Chi2Result {
    let n = config.samples as f64;
    let mut result = Chi2Result {
        resolution: grid.rows(),
        statistic: f64::NAN,
        dof: 0,
        p_value: 0.0,
        components: None,
        alpha: config.alpha,
        pooled_cells: 0,
        samples: config.samples,
        seed: config.seed,
        verdict: TestOutcome::Fail,
        reason: None,
        expected_mass: expected.total,
        expected_error_bound: expected.error_bound * n,
        sampling_seconds,
        integration_seconds,
        expected: expected.mass.iter().map(|m| m * n).collect(),
        observed: observed.counts,
        z_edges: grid.z_edges(),
        phi_edges: grid.phi_edges(),
    };
    result.reason = sanity(&result, &expected, observed.outside, observed.first_outside);
    // Masses whose cubature ran out of budget above its target judge nothing (not even a
    // mass off or a zero-pdf cell); samples outside the upper hemisphere are wrong whatever they are.
    if let Some(hit) = expected.budget_hit.filter(|h| !(h.bound <= h.target)) {
        if !matches!(result.reason, Some(Failure::OutsideHemisphere(_))) {
            result.reason = Some(Failure::CubatureBudget {
                rectangles: hit.rectangles,
                budget: crate::oracle::cubature::MAX_RECTANGLES,
                bound: hit.bound,
                target: hit.target,
            });
        }
    }
    if result.reason.is_some() {
        return result;
    }
    let counts = (&result.observed[..], &result.expected[..]);
    let test = match pearson_test(counts, counts, grid.columns(), config.alpha) {
        Ok(test) => test,
        Err(few) => {
            result.pooled_cells = few.pooled_cells;
            result.reason = Some(Failure::TooFewBins { bins: few.bins });
            return result;
        }
    };
    result.pooled_cells = test.pooled_cells;
    result.statistic = test.statistic;
    result.dof = test.dof;
    result.components = test.components;
    result.p_value = test.p_value;
    result.verdict = test.verdict;
    if test.verdict == TestOutcome::Fail {
        result.reason = Some(Failure::Rejected {
            p_value: result.p_value,
            alpha: config.alpha,
        });
    }
    result
}

/// The outcome of the verdict step ([`pearson_test`]).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct PearsonTest {
    /// Σ (O − E)² / E over the pooled bins.
    pub statistic: f64,
    /// Bins − 1.
    pub dof: usize,
    /// The cells pooled because they expect fewer than [`MIN_EXPECTED`] samples.
    pub pooled_cells: usize,
    /// The statistic's two parts ([`components`]), where the table has two rows that expect
    /// samples.
    pub components: Option<Components>,
    /// The p-value: the two parts' combination, or Q(dof/2, statistic/2) without them.
    pub p_value: f64,
    /// Pass when the p-value is at least α.
    pub verdict: TestOutcome,
}

/// Fewer than two bins after pooling: no statistic to judge.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct TooFewBins {
    /// The bins left.
    pub bins: usize,
    /// The cells pooled.
    pub pooled_cells: usize,
}

/// The verdict step of every chi-square test of the harness, after its sanity failures:
/// Pearson's statistic over the cells `cells` = (observed, expected counts), those expecting
/// fewer than [`MIN_EXPECTED`] pooled ([`pooled_statistic`]), dof = bins − 1; the statistic's
/// two parts on `table` (the same counts as rows ordered along cos θ, `columns` a row:
/// [`components`]) and the p-value judged against `alpha`. The hemisphere's test passes its
/// grid for both; the whole sphere's its cells as binned (upper hemisphere, then lower) and the
/// table of both hemispheres' rows from cos θ = 1 to −1.
pub(crate) fn pearson_test(
    cells: (&[u64], &[f64]),
    table: (&[u64], &[f64]),
    columns: usize,
    alpha: f64,
) -> Result<PearsonTest, TooFewBins> {
    let (statistic, bins, pooled_cells) = pooled_statistic(cells.0, cells.1);
    if bins < 2 {
        return Err(TooFewBins { bins, pooled_cells });
    }
    let dof = bins - 1;
    let components = components(table.0, table.1, columns);
    let p_value = match &components {
        Some(c) => c.p_value,
        None => statrs::function::gamma::checked_gamma_ur(0.5 * dof as f64, 0.5 * statistic)
            .unwrap_or(f64::NAN),
    };
    let verdict = if p_value >= alpha {
        TestOutcome::Pass
    } else {
        TestOutcome::Fail
    };
    Ok(PearsonTest {
        statistic,
        dof,
        pooled_cells,
        components,
        p_value,
        verdict,
    })
}

/// The sanity failures, in order: samples outside the upper hemisphere, invalid or off mass, samples in
/// zero-pdf cells.
fn sanity(
    result: &Chi2Result,
    expected: &Expected,
    outside: u64,
    first_outside: Option<(u64, DirectionError)>,
) -> Option<Failure> {
    if let Some((index, error)) = first_outside {
        return Some(Failure::OutsideHemisphere(OutsideHemisphere {
            index,
            error,
            count: outside,
        }));
    }
    if let Some((cell, &mass)) = expected
        .mass
        .iter()
        .enumerate()
        .find(|(_, m)| !(m.is_finite() && **m >= 0.0))
    {
        return Some(Failure::InvalidMass { cell, mass });
    }
    if !((expected.total - 1.0).abs() <= MASS_TOLERANCE) {
        return Some(Failure::MassOff {
            mass: expected.total,
            error_bound: expected.error_bound,
            tolerance: MASS_TOLERANCE,
        });
    }
    result
        .observed
        .iter()
        .zip(&expected.mass)
        .enumerate()
        .find(|(_, (&o, &m))| m == 0.0 && o > 0)
        .map(|(cell, (&observed, _))| Failure::ZeroPdfCell { cell, observed })
}

/// Σ (O − E)² / E over the pooled bins; returns (statistic, bins, pooled cells).
pub(crate) fn pooled_statistic(observed: &[u64], expected: &[f64]) -> (f64, usize, usize) {
    let mut bins: Vec<(f64, f64)> = Vec::with_capacity(expected.len());
    let (mut pool_o, mut pool_e, mut pooled) = (0.0, 0.0, 0);
    for (&o, &e) in observed.iter().zip(expected) {
        if e < MIN_EXPECTED {
            pool_o += o as f64;
            pool_e += e;
            pooled += 1;
        } else {
            bins.push((o as f64, e));
        }
    }
    if pool_e >= MIN_EXPECTED || (bins.is_empty() && pool_e > 0.0) {
        bins.push((pool_o, pool_e));
    } else if pool_e > 0.0 {
        let smallest = bins
            .iter_mut()
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .expect("bins is not empty");
        smallest.0 += pool_o;
        smallest.1 += pool_e;
    }
    let statistic = bins.iter().map(|(o, e)| (o - e) * (o - e) / e).sum();
    (statistic, bins.len(), pooled)
}
