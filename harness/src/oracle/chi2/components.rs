//! The chi-square statistic of a table split into two independent parts, so that the few
//! degrees of freedom where the common sampler errors live are not diluted by the many where
//! they do not (a roughness error moves only the cos θ marginal, and a 16 × 32
//! table's 511 degrees of freedom spread its non-centrality over 496 azimuthal cells that
//! carry no signal).
//!
//! The rows of the table are ordered along one axis (cos θ). Pearson's statistic of the row
//! marginal is the sum of the squares of its *smooth components* (Rayner & Best, "Smooth Tests
//! of Goodness of Fit", 1989, §5.3, categorized data; Lancaster's decomposition):
//!
//! ```text
//! V_j = Σ_i O_i h_j(i) / √N,   X²_rows = Σ_{j=1}^{r−1} V_j²
//! ```
//!
//! with h_j the polynomials (in the rows' mid-cumulative-probability scores) orthonormal under
//! the rows' expected probabilities p_i (Σ p_i h_j h_l = δ_jl, h_0 = 1). Under the null each
//! V_j is asymptotically N(0, 1), independent of the others. The first [`SMOOTH_COMPONENTS`]
//! see shifts, spreads and skews of the marginal — a sampler drawing α(1 + ε) shifts the GGX
//! marginal in log tan θ, which V_1 alone captures (the logistic's score is linear in its
//! probability transform) — and form the **smooth part** S = Σ_{j ≤ K} V_j² ~ χ²_K.
//!
//! The **rest** is everything else in the table: the row marginal's higher components
//! X²_rows − S (r − 1 − K degrees of freedom) plus, row by row, Pearson's statistic of the
//! row's cells against their expected shares of the row's observed count (the table given
//! its row totals; cells below [`MIN_EXPECTED`] pooled within the row as in
//! [`super::pooled_statistic`]). Given the row totals the rows are independent multinomials,
//! so the within-row part is asymptotically independent of the marginal, and the two parts'
//! p-values are independent and uniform under the null. The test's p-value is the smaller of
//! the two, Šidák-corrected: p = 1 − (1 − min(p_S, p_rest))², exactly uniform under the null
//! for two independent uniform p-values (the calibration's KS test sees that). (Fisher's
//! combination −2 Σ ln p was tried: it is better when both parts carry signal, but the
//! sampler errors this split is for put theirs in one part, and there it cost a factor of
//! about 3 in p at 10⁶ samples and 0.5 % roughness error.)
//!
//! [`MIN_EXPECTED`]: crate::tolerance::MIN_EXPECTED

use super::pooled_statistic;
use serde::Serialize;

/// K: the smooth components of the row marginal kept apart: location and spread of the cos θ
/// marginal (where a roughness and an exponent error of a sampler land). K = 4 (with skewness
/// and kurtosis) was measured too: 0.75 % roughness instead of 0.5 % caught at every seed
/// (docs/chi2.md, "Detection power").
pub const SMOOTH_COMPONENTS: usize = 2;

/// One part of the statistic with its distribution's degrees of freedom and p-value.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Part {
    /// The part's statistic.
    pub statistic: f64,
    /// Its degrees of freedom.
    pub dof: usize,
    /// Q(dof/2, statistic/2) (1 for a part without degrees of freedom).
    pub p_value: f64,
}

impl Part {
    fn new(statistic: f64, dof: usize) -> Self {
        let p_value = if dof == 0 || statistic == 0.0 {
            1.0
        } else {
            statrs::function::gamma::checked_gamma_ur(0.5 * dof as f64, 0.5 * statistic)
                .unwrap_or(f64::NAN)
        };
        Self {
            statistic,
            dof,
            p_value,
        }
    }
}

/// The two parts and their combination.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Components {
    /// The first K smooth components of the row marginal.
    pub smooth: Part,
    /// The rest of the table: the marginal's higher components and the rows given their
    /// totals.
    pub rest: Part,
    /// The two p-values combined: 1 − (1 − min)².
    pub p_value: f64,
}

/// The parts of the table `observed` (row-major, `columns` a row, rows in order along their
/// axis) against the expected counts `expected` (same layout; rows of zero expected count
/// take no part: a sample there is a sanity failure judged before). `None` when fewer than
/// two rows expect samples (no marginal to decompose).
pub fn components(observed: &[u64], expected: &[f64], columns: usize) -> Option<Components> {
    assert_eq!(
        observed.len(),
        expected.len(),
        "observed and expected differ"
    );
    let columns = columns.max(1);
    let rows: Vec<(u64, f64, usize)> = observed
        .chunks(columns)
        .zip(expected.chunks(columns))
        .enumerate()
        .map(|(i, (o, e))| (o.iter().sum::<u64>(), e.iter().sum::<f64>(), i))
        .filter(|&(_, e, _)| e > 0.0)
        .collect();
    if rows.len() < 2 {
        return None;
    }
    let n: f64 = rows.iter().map(|r| r.0 as f64).sum();
    let total: f64 = rows.iter().map(|r| r.1).sum();
    let p: Vec<f64> = rows.iter().map(|r| r.1 / total).collect();
    let h = orthonormal_polynomials(&p, SMOOTH_COMPONENTS.min(rows.len() - 1));
    let k = h.len();
    let smooth: f64 = h
        .iter()
        .map(|h| {
            let v: f64 = rows.iter().zip(h).map(|(r, h)| r.0 as f64 * h).sum::<f64>() / n.sqrt();
            v * v
        })
        .sum();
    // Pearson's statistic of the marginal (unpooled: every row expects N p_i > 0).
    let marginal: f64 = rows
        .iter()
        .zip(&p)
        .map(|(r, p)| {
            let e = n * p;
            (r.0 as f64 - e) * (r.0 as f64 - e) / e
        })
        .sum();
    let (mut within, mut within_dof) = (0.0, 0usize);
    for &(o_row, e_row, i) in &rows {
        if o_row == 0 {
            continue;
        }
        let cells = i * columns..(i + 1) * columns;
        let conditional: Vec<f64> = expected[cells.clone()]
            .iter()
            .map(|e| o_row as f64 * e / e_row)
            .collect();
        let (statistic, bins, _) = pooled_statistic(&observed[cells], &conditional);
        within += statistic;
        within_dof += bins.saturating_sub(1);
    }
    let smooth = Part::new(smooth, k);
    let rest = Part::new(
        (marginal - smooth.statistic).max(0.0) + within,
        rows.len() - 1 - k + within_dof,
    );
    let least = smooth.p_value.min(rest.p_value);
    let p_value = if rest.dof == 0 {
        smooth.p_value
    } else {
        least * (2.0 - least)
    };
    Some(Components {
        smooth,
        rest,
        p_value,
    })
}

/// h_1 … h_K (at most `k`) orthonormal under the weights `p` (Σ p = 1), polynomials in the
/// mid-cumulative scores x_i = 2(Σ_{l<i} p_l + p_i/2) − 1, by the Stieltjes recurrence
/// (x·h_{j−1}, orthogonalized twice against h_0 … h_{j−1}); stops early where a new
/// polynomial vanishes on the support (fewer distinct rows than degrees).
fn orthonormal_polynomials(p: &[f64], k: usize) -> Vec<Vec<f64>> {
    let mut cumulative = 0.0;
    let x: Vec<f64> = p
        .iter()
        .map(|&p| {
            let mid = cumulative + 0.5 * p;
            cumulative += p;
            2.0 * mid - 1.0
        })
        .collect();
    let dot =
        |a: &[f64], b: &[f64]| -> f64 { a.iter().zip(b).zip(p).map(|((a, b), p)| a * b * p).sum() };
    let mut basis: Vec<Vec<f64>> = vec![vec![1.0; p.len()]];
    for _ in 0..k {
        let last = basis.last().expect("h_0");
        let mut v: Vec<f64> = last.iter().zip(&x).map(|(h, x)| h * x).collect();
        for _ in 0..2 {
            for b in &basis {
                let c = dot(&v, b);
                for (v, b) in v.iter_mut().zip(b) {
                    *v -= c * b;
                }
            }
        }
        let norm = dot(&v, &v).sqrt();
        if !(norm > 1e-9) {
            break;
        }
        v.iter_mut().for_each(|v| *v /= norm);
        basis.push(v);
    }
    basis.remove(0);
    basis
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The polynomials are orthonormal under p and orthogonal to h_0; the components of a
    /// marginal with r rows kept whole (K = r − 1) sum to its Pearson statistic.
    #[test]
    fn the_components_decompose_pearsons_statistic() {
        let p = [0.1, 0.2, 0.3, 0.25, 0.15];
        let h = orthonormal_polynomials(&p, 4);
        assert_eq!(h.len(), 4);
        for (j, a) in h.iter().enumerate() {
            let mean: f64 = a.iter().zip(&p).map(|(a, p)| a * p).sum();
            assert!(mean.abs() < 1e-13, "h_{} mean {mean}", j + 1);
            for (l, b) in h.iter().enumerate() {
                let g: f64 = a.iter().zip(b).zip(&p).map(|((a, b), p)| a * b * p).sum();
                let want = if j == l { 1.0 } else { 0.0 };
                assert!((g - want).abs() < 1e-12, "<h{j}, h{l}> = {g}");
            }
        }
        // One column of three rows: the table is its marginal; with r − 1 = 2 = K components
        // the smooth part is all of Pearson's statistic and the rest has no degrees of freedom.
        let p = [0.2, 0.5, 0.3];
        let observed = [190u64, 520, 290];
        let expected: Vec<f64> = p.iter().map(|p| p * 1000.0).collect();
        let c = components(&observed, &expected, 1).unwrap();
        let pearson: f64 = observed
            .iter()
            .zip(&expected)
            .map(|(&o, e)| (o as f64 - e).powi(2) / e)
            .sum();
        assert!((c.smooth.statistic - pearson).abs() < 1e-10 * pearson);
        assert_eq!((c.smooth.dof, c.rest.dof), (2, 0));
        assert_eq!(c.p_value, c.smooth.p_value);
    }

    /// A shift of the marginal lands in V_1: the smooth part rejects where the whole table's
    /// Pearson statistic, its non-centrality spread over many cells, does not.
    #[test]
    fn a_shifted_marginal_is_seen_by_the_smooth_part() {
        let (rows, columns, n) = (16usize, 32usize, 1_000_000f64);
        // Equal-probability rows; the observed marginal tilted linearly by ±1.5 %.
        let expected = vec![n / (rows * columns) as f64; rows * columns];
        let observed: Vec<u64> = (0..rows * columns)
            .map(|c| {
                let t = (c / columns) as f64 / (rows - 1) as f64 - 0.5;
                (expected[c] * (1.0 + 0.03 * t)).round() as u64
            })
            .collect();
        let c = components(&observed, &expected, columns).unwrap();
        let (whole, bins, _) = pooled_statistic(&observed, &expected);
        let p_whole =
            statrs::function::gamma::checked_gamma_ur(0.5 * (bins - 1) as f64, 0.5 * whole)
                .unwrap();
        assert!(
            c.p_value < 1e-6 && p_whole > 1e-3,
            "{c:?}, whole p {p_whole}"
        );
        assert!(c.smooth.statistic > 0.99 * whole, "{c:?}");
    }

    /// Exactly expected counts: both parts 0, p = 1; a table off only within its rows (the
    /// marginal exact) is seen by the rest alone.
    #[test]
    fn the_rest_sees_what_the_marginal_cannot() {
        let expected = vec![100.0; 4 * 8];
        let c = components(&vec![100; 32], &expected, 8).unwrap();
        assert!(
            c.smooth.statistic < 1e-20 && c.rest.statistic == 0.0,
            "{c:?}"
        );
        assert!(c.p_value > 1.0 - 1e-9, "{c:?}");
        let observed: Vec<u64> = (0..32).map(|c| if c % 2 == 0 { 140 } else { 60 }).collect();
        let c = components(&observed, &expected, 8).unwrap();
        assert!(c.smooth.statistic < 1e-20, "{c:?}");
        assert!(c.rest.p_value < 1e-30 && c.p_value < 1e-30, "{c:?}");
        assert_eq!(c.rest.dof, 3 - 2 + 4 * 7);
    }
}
