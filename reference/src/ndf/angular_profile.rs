//! The angular profile of document 000 (eq 4): an isotropic D_iso(θ) given by its values at
//! breakpoints, the data a piecewise-linear NDF (`ndf::piecewise`) is built from. Named for
//! what it is, a function of the polar angle (the audit's check profiles are another thing).

use serde::{Deserialize, Serialize};
use std::f64::consts::FRAC_PI_2;

/// An isotropic profile D_iso(θ) given by its values at breakpoints θ₀ = 0 < θ₁ < … < θₙ = π/2
/// (document 000, eq 4), linear in between. The values need not be normalized: the model divides
/// them by c_iso (eq 5).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AngularProfile {
    /// The breakpoints θᵢ in radians: strictly increasing from 0 to π/2.
    pub theta: Vec<f64>,
    /// D_iso(θᵢ): finite, ≥ 0, not all zero.
    pub value: Vec<f64>,
}

impl AngularProfile {
    /// A profile from breakpoints and values (validated when a model is built from it).
    pub fn new(theta: Vec<f64>, value: Vec<f64>) -> Self {
        Self { theta, value }
    }

    /// Values at n equally spaced breakpoints θᵢ = i·π/(2(n−1)) (the document's constant Δθ,
    /// eq 28).
    pub fn uniform(value: Vec<f64>) -> Self {
        let n = value.len();
        let theta = (0..n)
            .map(|i| {
                if i + 1 == n {
                    FRAC_PI_2
                } else {
                    i as f64 * FRAC_PI_2 / (n.max(2) - 1) as f64
                }
            })
            .collect();
        Self { theta, value }
    }

    /// An isotropic NDF discretized at `n` equally spaced breakpoints (document 000 §1.2: "D_x and
    /// D_y can be discretized from any common NDFs"). `d_of_theta` gives D(θ).
    pub fn discretize(d_of_theta: &dyn Fn(f64) -> f64, n: usize) -> Self {
        let grid = Self::uniform(vec![0.0; n]).theta;
        let value = grid.iter().map(|&t| d_of_theta(t)).collect();
        Self { theta: grid, value }
    }
}
