//! Tanh–sinh (double-exponential) quadrature over [0, 1] in double-double arithmetic, with an
//! error estimate from successive levels.
//!
//! The rule (Takahasi and Mori 1974): x = ½ (1 + tanh(½π sinh τ)), τ = k h, so that
//!
//! ```text
//! ∫₀¹ f(x) dx ≈ h Σ_k w_k f(x_k),   w_k = π cosh τ_k · e_k / (1 + e_k)²,   e_k = e^{−π sinh |τ_k|}
//! ```
//!
//! The node's distance to its nearer end point, e_k / (1 + e_k), is computed directly (never as
//! 1 − x), and the integrand receives both x and 1 − x to full double-double precision, so
//! that end-point singularities such as (1 − x)^{−½} are evaluated where they are.
//!
//! Levels halve h from 1 to 2⁻⁸ (each reusing the previous nodes). The sum is truncated where
//! the distance to the end point falls below 1e-250 (|τ| ≈ 5.5): the dropped part of an
//! integrand bounded by |f| ≤ M (1 + x^{−½} + (1 − x)^{−½}) is < 1e-120 M. The error estimate
//! of level j is |S_j − S_{j−1}| (for an integrand analytic in the open interval the error of
//! S_j is of the order of |S_j − S_{j−1}|², so this is pessimistic by design) plus the
//! rounding of the sum, (n u + ε_f) Σ |h w_k f(x_k)|, with u = 2⁻¹⁰⁴, n the number of terms
//! and ε_f the relative error the caller states for its integrand.

use super::double_double::{DoubleDouble, UNIT_ROUNDOFF};
use std::sync::OnceLock;

/// The finest level: h = 2^{−MAX_LEVEL}.
pub const MAX_LEVEL: usize = 8;

/// The truncation of the rule: nodes closer to an end point than this are dropped.
const SMALLEST_DISTANCE: f64 = 1e-250;

/// One abscissa τ > 0 of the rule: the distance of its two nodes to their end points and the
/// weight (the τ = 0 node is x = ½, w = π/4).
#[derive(Debug, Clone, Copy)]
struct Node {
    distance: DoubleDouble,
    weight: DoubleDouble,
}

/// The nodes added at each level: level 0 is τ = 1, 2, …; level j the odd multiples of 2^{−j}.
fn levels() -> &'static [Vec<Node>] {
    static LEVELS: OnceLock<Vec<Vec<Node>>> = OnceLock::new();
    LEVELS.get_or_init(|| (0..=MAX_LEVEL).map(level_nodes).collect())
}

/// The nodes new at level `j`.
fn level_nodes(j: usize) -> Vec<Node> {
    let h = DoubleDouble::ONE.ldexp(-(j as i32));
    let step = if j == 0 { 1 } else { 2 };
    let mut nodes = Vec::new();
    let mut k = 1;
    loop {
        let node = node_at(h.mul_f64(f64::from(k)));
        if node.distance.hi() < SMALLEST_DISTANCE {
            return nodes;
        }
        nodes.push(node);
        k += step;
    }
}

/// The node at τ > 0.
fn node_at(tau: DoubleDouble) -> Node {
    let e_tau = tau.exp();
    let inverse = DoubleDouble::ONE / e_tau;
    let sinh = (e_tau - inverse).ldexp(-1);
    let cosh = (e_tau + inverse).ldexp(-1);
    let e = (-(DoubleDouble::PI * sinh)).exp();
    let one_plus = DoubleDouble::ONE + e;
    Node {
        distance: e / one_plus,
        weight: DoubleDouble::PI * cosh * e / one_plus.square(),
    }
}

/// ∫₀¹ f with its error estimate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Quadrature {
    /// The value at the last level computed.
    pub value: DoubleDouble,
    /// Estimated bound on |value − ∫₀¹ f|: level difference plus rounding (module docs).
    pub error: f64,
    /// The difference of the last two levels alone.
    pub level_difference: f64,
    /// The finest level used (h = 2^{−level}).
    pub level: usize,
    /// Integrand evaluations.
    pub evaluations: u64,
}

/// ∫₀¹ f(x, 1 − x) dx by tanh–sinh in double-double, refining until two successive levels
/// (from level 3 on) differ by ≤ `relative` · |S| or level [`MAX_LEVEL`] is reached.
/// `integrand_error` is the relative error of one evaluation of f (e.g. 1e-30).
pub fn integrate_unit(
    f: &dyn Fn(DoubleDouble, DoubleDouble) -> DoubleDouble,
    relative: f64,
    integrand_error: f64,
) -> Quadrature {
    let half = DoubleDouble::from(0.5);
    let centre = f(half, half);
    let mut sum = DoubleDouble::PI.ldexp(-2) * centre;
    let mut magnitude = sum.hi().abs();
    let mut evaluations = 1u64;
    let mut terms = 1u64;
    let mut previous: Option<DoubleDouble> = None;
    let mut result = Quadrature {
        value: sum,
        error: f64::INFINITY,
        level_difference: f64::INFINITY,
        level: 0,
        evaluations,
    };
    for (j, nodes) in levels().iter().enumerate() {
        for node in nodes {
            let near = node.distance;
            let far = DoubleDouble::ONE - near;
            let (left, right) = (f(near, far), f(far, near));
            evaluations += 2;
            terms += 2;
            magnitude += node.weight.hi() * (left.hi().abs() + right.hi().abs());
            sum = sum + node.weight * (left + right);
        }
        let h = DoubleDouble::ONE.ldexp(-(j as i32));
        let value = sum * h;
        let scale = magnitude * h.hi();
        let rounding = (terms as f64 * UNIT_ROUNDOFF + integrand_error) * scale;
        let difference = previous.map_or(f64::INFINITY, |p| (value - p).hi().abs());
        result = Quadrature {
            value,
            error: difference + rounding,
            level_difference: difference,
            level: j,
            evaluations,
        };
        if j >= 3 && difference <= relative * value.hi().abs() {
            break;
        }
        previous = Some(value);
    }
    result
}

#[cfg(test)]
mod tests {
    use super::*;

    type D = DoubleDouble;

    fn check(f: &dyn Fn(D, D) -> D, exact: D, tolerance: f64) -> Quadrature {
        let q = integrate_unit(f, 1e-30, 1e-31);
        let error = ((q.value - exact) / exact).hi().abs();
        assert!(error < tolerance, "error {error:e}, estimate {:e}", q.error);
        assert!(
            q.error >= (q.value - exact).hi().abs(),
            "estimate {:e} below the true error {error:e}",
            q.error
        );
        q
    }

    #[test]
    fn integrates_smooth_and_end_point_singular_functions_to_1e_30() {
        // ∫₀¹ eˣ = e − 1.
        check(&|x, _| x.exp(), D::ONE.expm1(), 1e-30);
        // ∫₀¹ (1 − x)^{−½} = 2, evaluated through the complement.
        check(&|_, c| D::ONE / c.sqrt(), D::from(2.0), 1e-30);
        // ∫₀¹ −ln x = 1.
        check(&|x, _| -x.ln(), D::ONE, 1e-30);
        // ∫₀¹ 1/(1 + x²) = π/4.
        check(
            &|x, _| D::ONE / (D::ONE + x.square()),
            D::PI.ldexp(-2),
            1e-30,
        );
    }
}
