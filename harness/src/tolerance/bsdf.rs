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
             denominator |η_i wi + η_o wo| is small); 1e-9 leaves that room and fails any \
             misplaced factor (η², a cosine, G1) by orders of magnitude",
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
