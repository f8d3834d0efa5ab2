//! The value tolerances of a float32 implementation: each an error budget in units
//! of ε₃₂ = 2⁻²³ ≈ 1.19e-7 with its reason. The f64 tolerances of `tolerance.rs` hold for
//! `Precision::F64`; [`super::Tolerance::at`] picks the row of the declared precision.
//! Statistical tolerances (α) and the claims of the documents do not depend on the precision of
//! the implementation and have no row here.

use super::Tolerance;

/// ε of float32, as f64.
pub const EPS32: f64 = 1.192_092_895_507_812_5e-7;

/// A closed form (Λ, G1, D at a point) against its defining integral, in float32.
pub const CLOSED_FORM_F32: Tolerance = Tolerance {
    name: "closed_form_f32",
    value: 1024.0 * EPS32,
    reason: "1024 ε₃₂ (1.2e-4): a float32 closed form rounds each of its ~10 operations \
             (≤ 10 ε₃₂ well conditioned); GGX-like Λ = (√(1 + α²tan²θ) − 1)/2 cancels near \
             normal incidence and grows like tan θ at grazing, a condition up to ~50 at the \
             audit's points; the oracle integrates to its float32 rounding floor (32 ε₃₂). A \
             0.1 % defect still fails by 8×",
};

/// A numerical route in float32.
pub const NUMERICAL_ROUTE_F32: Tolerance = Tolerance {
    name: "numerical_route_f32",
    value: 1024.0 * EPS32,
    reason: "1024 ε₃₂ (1.2e-4), as closed_form_f32: a float32 quadrature cannot be asked for \
             less than its own rounding, so the closed-form budget applies",
};

/// ∫ D(m)(m·n) dm = 1 in float32.
pub const NORMALIZATION_F32: Tolerance = Tolerance {
    name: "normalization_f32",
    value: 256.0 * EPS32,
    reason: "256 ε₃₂ (3.1e-5): a float32 D is off by a systematic few ε₃₂ (π, α² and the \
             squares rounded: ≤ 16 ε₃₂ summed), the nested quadrature stops at its rounding \
             floor (32 ε₃₂ of ∫|f| per level, two levels: ≤ 64 ε₃₂ with its error bound); the \
             margin is 2×; a D scaled by 1.0001 fails",
};

/// Identities between two evaluations, in float32.
pub const IDENTITY_F32: Tolerance = Tolerance {
    name: "identity_f32",
    value: 64.0 * EPS32,
    reason: "64 ε₃₂ (7.6e-6): two float32 evaluations of the same closed form differ by their \
             roundings (≤ 16 ε₃₂ each for ~10 operations); 1 + Λ and 1/(1 + Λ) add two more",
};

/// pdf_wm against D(m)(m·n), in float32.
pub const PDF_CONSISTENCY_F32: Tolerance = Tolerance {
    name: "pdf_consistency_f32",
    value: 64.0 * EPS32,
    reason: "64 ε₃₂ (7.6e-6): pdf and D·cos are two float32 evaluations of one closed form \
             (≤ 16 ε₃₂ each), and the sampled direction itself is a float32 unit vector \
             (its |m| off by ~ε₃₂, D's condition in m_z ≤ 4 at the lobe)",
};

/// The Jacobian check in float32.
pub const PDF_JACOBIAN_F32: Tolerance = Tolerance {
    name: "pdf_jacobian_f32",
    value: 2e-3,
    reason: "central differences of a float32 sampler with steps h = 4e-3 and 2e-3 \
             (≈ ε₃₂^(1/3)·{8, 4}, the step that balances truncation h² against round-off \
             ε₃₂/h): round-off ε₃₂·|m|/h ≈ 3e-5 per derivative, times the map's condition \
             (≤ 20 away from the poles), Richardson-extrapolated truncation O(h⁴) ≈ 3e-10: \
             2e-3 leaves 3× over the worst measured and fails a 1 % mismatch",
};

/// A user's closed form against mfh's reference, in float32.
pub const AGAINST_REFERENCE_F32: Tolerance = Tolerance {
    name: "against_reference_f32",
    value: 1024.0 * EPS32,
    reason: "1024 ε₃₂ (1.2e-4): a float32 evaluation against the f64 reference of the same \
             closed form: ≤ 16 ε₃₂ well conditioned, times the condition of Λ near normal \
             incidence and grazing (≤ 50 at the audit's points)",
};

/// A float32 batch sampler against its scalar sampler, in f64 ulps.
pub const BATCH_SAMPLER_F32: Tolerance = Tolerance {
    name: "batch_sampler_f32",
    value: 4.0 * 536_870_912.0,
    reason: "ulps of f64 per component: 4 float32 ulps (4 × 2²⁹ f64 ulps), the batch_sampler \
             budget (a few reordered roundings) in the implementation's own format",
};

/// The float32 row of every f64 tolerance that has one.
pub const F32_TABLE: &[(&str, Tolerance)] = &[
    ("closed_form", CLOSED_FORM_F32),
    ("numerical_route", NUMERICAL_ROUTE_F32),
    ("normalization", NORMALIZATION_F32),
    ("identity", IDENTITY_F32),
    ("pdf_consistency", PDF_CONSISTENCY_F32),
    ("pdf_jacobian", PDF_JACOBIAN_F32),
    ("against_reference", AGAINST_REFERENCE_F32),
    ("batch_sampler", BATCH_SAMPLER_F32),
    (
        "bsdf_sample_consistency",
        super::BSDF_SAMPLE_CONSISTENCY_F32,
    ),
    ("bsdf_reciprocity", super::BSDF_RECIPROCITY_F32),
    ("bsdf_ndf_consistency", super::BSDF_NDF_CONSISTENCY_F32),
    ("bsdf_against_reference", super::BSDF_AGAINST_REFERENCE_F32),
    ("bsdf_sample_direction", super::BSDF_SAMPLE_DIRECTION_F32),
    ("bsdf_energy", super::BSDF_ENERGY_F32),
];

/// The per-cell relative tolerance of the chi-square expected masses for a density computed
/// in `precision`: `f64_value` (the tolerance of `tolerance/chi2.rs`) or, above f64, at least
/// 64 ε of the format (7.6e-6 for float32): the G7/K15 difference of a cell whose density is
/// rounded to ε relative is ~ε × its mass, so a smaller target bisects rounding noise to the
/// depth limit (2·10⁸ evaluations for a float32 GGX). The masses stay far inside
/// the statistical resolution (1/√(N·p) ≈ 2e-2 per cell at 10⁶ samples).
pub fn cell_relative_tolerance(f64_value: f64, precision: crate::precision::Precision) -> f64 {
    match precision {
        crate::precision::Precision::F64 => f64_value,
        p => f64_value.max(64.0 * p.epsilon()),
    }
}
