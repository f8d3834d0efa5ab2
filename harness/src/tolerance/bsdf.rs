//! The tolerances of the BSDF checks (`check/bsdf/`), each with its reason.

use super::Tolerance;

/// A BSDF's `sample` against its own `pdf` and `eval` at the sampled direction.
pub const BSDF_SAMPLE_CONSISTENCY: Tolerance = Tolerance {
    name: "bsdf_sample_consistency",
    value: 1e-9,
    reason: "the pdf and weight `sample` returns and pdf(wi, wo), eval(wi, wo)/pdf(wi, wo) are \
             two f64 evaluations of one closed form, possibly by different algebra (a renderer \
             often computes the sample's pdf from the sampled normal, the pdf from the half \
             vector rebuilt from wo: ~1e-15 apart, ~1e-11 where the refraction Jacobian's \
             denominator |η_i wi + η_o wo| is small; where a sample's pdf varies by more over \
             wo ± 16 ε only the excess is judged, check/bsdf/consistency.rs); 1e-9 leaves that \
             room and fails any misplaced factor (η², a cosine, G1) by orders of magnitude",
};

/// Reciprocity of a BSDF: f(wi, wo) against f(wo, wi) (with the η² of its transport).
pub const BSDF_RECIPROCITY: Tolerance = Tolerance {
    name: "bsdf_reciprocity",
    value: 1e-9,
    reason: "the two sides are the same closed form at swapped arguments; the reference BSDFs \
             agree to ~1e-14 (measured), a renderer's to the conditioning of its half vector \
             and Jacobian near grazing and near-critical angles (cosines of 1e-6: ~1e-10); \
             1e-9 fails a lost η² (a factor η² ≥ 1.0002 off at the accepted η) by 2·10⁵×",
};

/// A BSDF against Walter's eq 20/21 built from the D and Λ of the NDF it offers: the Fresnel
/// factors that remain must be a function of |wi·h| alone, in [0, 1], and sum to 1 across the
/// lobes (`bsdf.ndf_consistency`).
pub const BSDF_NDF_CONSISTENCY: Tolerance = Tolerance {
    name: "bsdf_ndf_consistency",
    value: 1e-9,
    reason: "each side is a handful of f64 operations on the same D, Λ and half vector, \
             evaluated by the BSDF and by the check from the NDF at directions 0.05 or more \
             from the horizon and refracted cosines of 0.1 or more: the reference BSDFs \
             measure ≤ 1e-14, a renderer's different algebra ~1e-13; 1e-9 leaves that room \
             and fails a D or Λ that is not the NDF's (GGX α × 1.01: 4 %), a G2 of the other \
             form (percents at α = 0.3) or a misplaced η² (≥ 0.02 % at the accepted η) by \
             orders of magnitude",
};

/// A user's BSDF against the reference BSDF of the same spec.
pub const BSDF_AGAINST_REFERENCE: Tolerance = Tolerance {
    name: "bsdf_against_reference",
    value: 1e-9,
    reason: "two f64 evaluations of Walter's formulas by different algebra (the half vector, \
             the Fresnel transmittance from either side, the Jacobian's denominator): ~1e-14 \
             where well conditioned, ~1e-10 at cosines of 1e-6; 1e-9 fails a Schlick-for-exact \
             Fresnel (≥ 1e-3 off) or a misplaced η² by orders of magnitude",
};

/// The sampled direction of a user's BSDF against the reference's for the same u (radians).
pub const BSDF_SAMPLE_DIRECTION: Tolerance = Tolerance {
    name: "bsdf_sample_direction",
    value: 1e-7,
    reason: "the same inversion by different algebra: ~1e-15 rad where well conditioned; the \
             visible-normal inversion amplifies rounding by up to ~1/α² near its poles (α = \
             1e-4: 1e-8); 1e-7 rad fails a swapped u or a wrong roughness by orders of \
             magnitude",
};

/// Energy conservation: ∫ eval dωo ≤ 1 (where the transport makes that a law).
pub const BSDF_ENERGY: Tolerance = Tolerance {
    name: "bsdf_energy",
    value: 1e-6,
    reason: "the albedo is integrated by adaptive cubature over both hemispheres to a kinked-cell \
             tolerance of 1e-4 per cell with the summed error bound as slack; 1e-6 more is \
             left for the bound's own looseness at the steps of total internal reflection, \
             against which a BSDF that gains energy (a lost Fresnel, a Jacobian off by η²) \
             exceeds 1 by percents",
};

/// Violations of the BSDF's invariants at the hard cases (a count; none is allowed).
pub const BSDF_STABILITY: Tolerance = Tolerance {
    name: "bsdf_stability",
    value: 0.5,
    reason: "a count of violations (a NaN, an infinity or a negative value, a value where the \
             BSDF never samples, a sampled direction off the unit sphere or with a zero or \
             non-finite pdf or weight): any one is a defect a renderer would ship, so the count \
             must be 0 (0.5 only makes the comparison strict)",
};

/// [`BSDF_SAMPLE_CONSISTENCY`] for a float32 BSDF.
pub const BSDF_SAMPLE_CONSISTENCY_F32: Tolerance = Tolerance {
    name: "bsdf_sample_consistency_f32",
    value: 1e-3,
    reason: "8400 ε₃₂: the sample's pdf comes from the sampled normal, pdf(wi, wo) from the half \
             vector rebuilt from the float32 wo (a few ε₃₂ per component, times D's log-slope \
             in the lobe's tail and the refraction half vector's 1/|η_i wi + η_o wo|); where a \
             sample's pdf varies by more over wo ± 16 ε (1 − F near the critical angle, whose \
             slope is infinite) only the excess is judged (check/bsdf/consistency.rs). A float32 \
             GGX dielectric after pbrt-v4 measures 1.6e-4 to 2.2e-4 raw (η 1.5, α 0.3, from \
             inside), Mitsuba 3.9.1's roughdielectric 3.3e-4, the numpy example 5.2e-4; fails \
             a weight or pdf off by 0.1 % (a lost η² at |η − 1| ≥ 5e-4, a cosine, G1)",
};

/// [`BSDF_RECIPROCITY`] for a float32 BSDF.
pub const BSDF_RECIPROCITY_F32: Tolerance = Tolerance {
    name: "bsdf_reciprocity_f32",
    value: 1e-3,
    reason: "8400 ε₃₂: the two sides round their float32 half vectors, Jacobians and 1 − F \
             differently, and 1 − F computed from the denser side cancels near its critical \
             angle (condition 1/T); a float32 GGX dielectric after pbrt-v4 measures 1.2e-4 \
             (η 1.5, α 0.1 and 0.3), 5.8e-5 at η 1.05, Mitsuba 3.9.1's roughdielectric 4.5e-4 \
             (GGX α 0.3, η 1.5): 2.2× margin; fails a lost η² at \
             |η − 1| ≥ 5e-4",
};

/// [`BSDF_NDF_CONSISTENCY`] for a float32 BSDF.
pub const BSDF_NDF_CONSISTENCY_F32: Tolerance = Tolerance {
    name: "bsdf_ndf_consistency_f32",
    value: 1e-4,
    reason: "840 ε₃₂: the BSDF's float32 D, G and Jacobian against the check's f64 algebra on \
             the float32 NDF's D and Λ, at directions 0.05 or more from the horizon: a float32 \
             GGX dielectric after pbrt-v4 measures 3.0e-6 (η 1.5), 7.4e-6 (η 1.05), a float32 \
             conductor 1.1e-6: 13× margin; fails a D or Λ not the NDF's (α × 1.01: 4 %) or \
             the other G2 form (percents) by orders of magnitude",
};

/// [`BSDF_AGAINST_REFERENCE`] for a float32 BSDF.
pub const BSDF_AGAINST_REFERENCE_F32: Tolerance = Tolerance {
    name: "bsdf_against_reference_f32",
    value: 1e-3,
    reason: "8400 ε₃₂: a float32 evaluation of Walter's formulas against the f64 reference: \
             the inputs rounded to float32 (ε₃₂/2, times D's log-slope in the tail), and 1 − F \
             cancelling near the critical angle; a float32 GGX dielectric after pbrt-v4 \
             measures 1.2e-4 (η 1.5, α 0.1 and 0.3), a float32 conductor 6.8e-7, Mitsuba 3.9.1's \
             roughdielectric 4.6e-4 and roughconductor 8.1e-7 (GGX α 0.3): 2.2× margin; \
             fails a misplaced η² or G1 by orders of magnitude and a Schlick-for-exact Fresnel \
             where it is more than 0.1 % off (percents at grazing microfacet incidence)",
};

/// [`BSDF_SAMPLE_DIRECTION`] for a float32 BSDF (radians).
pub const BSDF_SAMPLE_DIRECTION_F32: Tolerance = Tolerance {
    name: "bsdf_sample_direction_f32",
    value: 1e-2,
    reason: "radians: the same inversion in float32 (u given exactly, the top step 1 − 2⁻¹², \
             check/bsdf/against.rs): the visible-normal map amplifies rounding near its rim \
             and poles; a float32 GGX dielectric after pbrt-v4 measures 9e-6 rad (α 0.3, \
             0.1), 1.4e-4 (α 0.02), 2.7e-4 (α 0.005) and 3.0e-4 (α 0.001: the amplification \
             saturates), a float32 conductor the same: 33× margin. Fails a \
             swapped u, a mirrored azimuth or an inverted lobe choice (radians apart)",
};

/// [`BSDF_ENERGY`] for a float32 BSDF.
pub const BSDF_ENERGY_F32: Tolerance = Tolerance {
    name: "bsdf_energy_f32",
    value: 1e-5,
    reason: "84 ε₃₂: the integral of a float32 eval carries its systematic rounding where the \
             lobe's mass lies (≤ 16 ε₃₂ for ~10 operations; the float32 GGX BSDFs of \
             tests/float32_bsdf.rs measure ≤ 7e-7 against the reference in the lobe's bulk), \
             on top of BSDF_ENERGY's cubature slack; a BSDF that gains energy (a lost Fresnel, \
             a Jacobian off by η²) exceeds 1 by percents",
};
