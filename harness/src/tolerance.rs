//! The one table of tolerances, each with its reason, and the table of expected failures (known
//! errata and known numerical limits of printed routes), each with its reason (ARCHITECTURE.md,
//! "Tolerances and expected failures").
//!
//! The tolerances are here — every one a record is judged by, the documents' claims included
//! (`check/claims.rs` names them, it defines none) — except the BSDF checks', in
//! `tolerance/bsdf.rs`; their float32 rows are in `tolerance/precision.rs` (the BSDF checks'
//! `_f32` rows in `tolerance/bsdf.rs`), picked by [`Tolerance::at`]; the expected-failure types
//! (`Bound`, `ParameterBox`, `ExpectedFailure`) and their table are in `tolerance/expected.rs`, and
//! the chi-square oracle's numeric tolerances in `tolerance/chi2.rs`; all re-exported here.
//! [`TABLE`] lists every [`Tolerance`] (its test: a reason each, unique names).
//!
//! Not here, by design: an oracle's own accuracy targets and budgets (what it asks of its
//! quadrature, e.g. `check/claims.rs`'s `GTR_CLAIM_RELATIVE`, `oracle::quadrature`'s
//! `EVALUATION_BUDGET`) tune how an oracle reaches its error bound; the bound is then carried by
//! the record and judged against a tolerance of this table (`ORACLE_BOUND_FRACTION`).

mod bsdf;
mod chi2;
mod expected;
mod precision;

pub use bsdf::{
    BSDF_AGAINST_REFERENCE, BSDF_AGAINST_REFERENCE_F32, BSDF_ENERGY, BSDF_ENERGY_F32,
    BSDF_NDF_CONSISTENCY, BSDF_NDF_CONSISTENCY_F32, BSDF_RECIPROCITY, BSDF_RECIPROCITY_F32,
    BSDF_SAMPLE_CONSISTENCY, BSDF_SAMPLE_CONSISTENCY_F32, BSDF_SAMPLE_DIRECTION,
    BSDF_SAMPLE_DIRECTION_F32, BSDF_STABILITY,
};
pub use chi2::{
    CELL_ABSOLUTE_TOLERANCE, CELL_RELATIVE_TOLERANCE, KINKED_CELL_RELATIVE_TOLERANCE,
    LAYOUT_ABSOLUTE_TOLERANCE, LAYOUT_RELATIVE_TOLERANCE, MASS_TOLERANCE, MIN_EXPECTED,
    REMOTE_CELL_ABSOLUTE_TOLERANCE,
};
pub use expected::{expected_failures, Bound, ExpectedFailure, ParameterBox, EXPECTED_FAILURES};
pub use precision::{cell_relative_tolerance, EPS32, F32_TABLE};

/// A named tolerance.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tolerance {
    /// The name records carry.
    pub name: &'static str,
    /// The allowed error (relative unless the check says otherwise).
    pub value: f64,
    /// Why this value.
    pub reason: &'static str,
}

impl Tolerance {
    /// This tolerance for an implementation computing in `precision`: itself for f64; for f32
    /// its row of `tolerance/precision.rs` (an error budget in float32 ε with its reason), or
    /// itself where the tolerance does not depend on the implementation's precision (α, the
    /// documents' claims, bit-for-bit promises of mfh's own models).
    pub fn at(&self, precision: crate::precision::Precision) -> Tolerance {
        match precision {
            crate::precision::Precision::F64 => *self,
            crate::precision::Precision::F32 => F32_TABLE
                .iter()
                .find(|(name, _)| *name == self.name)
                .map_or(*self, |(_, t)| *t),
        }
    }
}

/// The largest relative error bound of an oracle, as a fraction of the tolerance it judges
/// against, for which `check::compare` gives a verdict of pass: beyond it the oracle cannot
/// tell a value within the tolerance from one outside it, and the record is an error.
///
/// 0.5: the slack a pass may take from the oracle is then at most half the tolerance, so a
/// pass certifies the true error within 1.5× the stated tolerance (without the rule a user D
/// scaled by 1e308 passed `smith.white_furnace`). The oracles ask their quadrature
/// for a hundredth of the tolerance they serve (the Λ oracle 1e-12 against `CLOSED_FORM`'s
/// 1e-10), so a converged oracle sits 50× inside the fraction; in the default quick audit the
/// largest bound of a passing record is 0.056 of its tolerance (`smith.white_furnace`).
pub const ORACLE_BOUND_FRACTION: f64 = 0.5;

/// Closed forms that are cancellation-free against adaptive quadrature of their definition.
pub const CLOSED_FORM: Tolerance = Tolerance {
    name: "closed_form",
    value: 1e-10,
    reason: "a well-conditioned closed form in double precision is good to ~1e-14; the oracle \
             (adaptive double-exponential quadrature) is asked for 1e-12; 1e-10 leaves room for \
             conditioning near grazing incidence (≤ 1e-10 where well conditioned)",
};

/// Closed forms against the double-double reference (`oracle::precise`, certified to ~1e-24).
pub const PRECISE: Tolerance = Tolerance {
    name: "precise",
    value: 1e-14,
    reason: "the closed forms of seed 001 are built for ~1e-14 where well conditioned (\
             1e-14 for ₂F₁, the Student Λ measured ≤ 4.4e-15 × condition against mpmath); the \
             reference is certified to 1e-24, and the check adds 8εκ for the rounding of the \
             f64 input (κ = d ln Λ / d ln cot θ or d ln D / d ln tan²θ)",
};

/// Routes that are themselves numerical integrals (GTR exact, piecewise-linear exact, blend).
pub const NUMERICAL_ROUTE: Tolerance = Tolerance {
    name: "numerical_route",
    value: 1e-9,
    reason: "the model integrates with adaptive Gauss–Kronrod to a stated 1e-12 relative; the \
             oracle uses a different rule (double-exponential) to 1e-12; 1e-9 is the sum with \
             margin for the conditioning of Λ near grazing incidence",
};

/// The normalization ∫ D(m)(m·n) dm = 1.
pub const NORMALIZATION: Tolerance = Tolerance {
    name: "normalization",
    value: 1e-9,
    reason: "nested adaptive quadrature over the hemisphere asked for 1e-11; heavy-tailed \
             members (γ near 1.5) converge slowly at the horizon, so 1e-9",
};

/// Identities that hold exactly in exact arithmetic (Λ(−w) = −1 − Λ(w), G1 ≤ 1, …).
pub const IDENTITY: Tolerance = Tolerance {
    name: "identity",
    value: 1e-13,
    reason: "an algebraic identity between two evaluations of the same closed form: only \
             round-off separates the sides",
};

/// Sampled directions mapped back by the pdf: pdf_wm(m) against D(m)(m·n).
pub const PDF_CONSISTENCY: Tolerance = Tolerance {
    name: "pdf_consistency",
    value: 1e-12,
    reason: "pdf_wm and D(m)(m·n) are two evaluations of one closed form; round-off only",
};

/// The significance level of every statistical check, before the Šidák correction across the
/// audit.
pub const STATISTICAL_ALPHA: Tolerance = Tolerance {
    name: "statistical_alpha",
    value: 1e-3,
    reason: "family-wise level of the audit's statistical checks (chi-square, Monte Carlo \
             z-tests): one false alarm in a thousand audits; each check gets the Šidák share",
};

/// The γ → ∞ rate: |D_STD − D_Beckmann| = O(1/γ).
pub const LIMIT_RATE: Tolerance = Tolerance {
    name: "limit_rate",
    value: 0.1,
    reason: "the fitted exponent of the error against γ over γ = 10²…10⁸ must be −1 ± 0.1 \
             (seed 001 §4: O(1/γ) convergence of STD to Beckmann)",
};

/// Moments of the slope distribution against ∫ q^{2k} P2(q) dq.
pub const MOMENT: Tolerance = Tolerance {
    name: "moment",
    value: 1e-9,
    reason: "the moment integral of a heavy tail (γ near the moment's limit) converges slowly \
             under the tail substitution; 1e-9 against a 1e-11 request",
};

/// Visible-slope moments (document 002) against 2-D quadrature.
pub const VISIBLE_MOMENTS: Tolerance = Tolerance {
    name: "visible_moments",
    value: 1e-8,
    reason: "the oracle is a 2-D adaptive integral of a Gaussian times a kinked visibility \
             factor (1e-11 requested); the covariance subtracts mean², so relative error of \
             small covariances is amplified: 1e-8",
};

/// Demonstrations of errata: the corrected form against its defining integral or property.
pub const ERRATUM: Tolerance = Tolerance {
    name: "erratum",
    value: 1e-8,
    reason: "errata.printed_formula: the corrected form must agree with the harness oracle \
             (quadrature asked for 1e-12, or an exact defining property) to 1e-8, and the \
             printed form must miss it by more; every printed form with an erratum misses by \
             > 1e-3 (ERRATA.md), so the margin is wide on both sides",
};

/// Demonstrations whose corrected form is itself right only to leading order.
pub const ERRATUM_ASYMPTOTIC: Tolerance = Tolerance {
    name: "erratum_asymptotic",
    value: 1e-3,
    reason: "errata whose corrected form holds to leading order only (seed 003 E4: O(1/A) at \
             A = 1e4; S1: O(r²/d²) at r/d = 1e-3): 1e-3 bounds the neglected terms, while the \
             printed forms are off by a factor 2",
};

/// Demonstrations compared through 2-D quadrature of kinked integrands.
pub const ERRATUM_VISIBLE_MOMENTS: Tolerance = Tolerance {
    name: "erratum_visible_moments",
    value: 1e-6,
    reason: "the oracle is a 2-D cubature (visible slope moments of seed 002) or a hemisphere \
             integral with a kinked indicator (seed 000 E15), good to ~1e-8; the printed forms \
             are off by > 1e-2",
};

/// Document 004 §4: the α → 0 limit of G1 at μ = 1.
pub const GTR_LIMIT: Tolerance = Tolerance {
    name: "gtr_limit",
    value: 1e-6,
    reason:
        "seed 004 §4: \"All height fields converge to G1⁰ when μ → 1 and α → 0\"; at α = 1e-4, \
             γ = 2, μ = 1 the true G1 is 1 − O(α²) ≈ 1 − 2.5e-9, so a limit must be met to 1e-6",
};

/// Document 004 §2 / §5: the spline's claimed error.
pub const GTR_SPLINE: Tolerance = Tolerance {
    name: "gtr_spline",
    value: 1e-3,
    reason: "seed 004 §2: \"an approximation for computing G1, which we measured to give less \
             than 0.1 % error\"; §5: \"ca. 0.1 % difference … the mean difference was 0.001\"",
};

/// Document 004 §6: the γ > 4 clamp.
pub const GTR_CLAMP: Tolerance = Tolerance {
    name: "gtr_clamp",
    value: 0.3,
    reason: "seed 004 §6: |G1⁴ − G1¹⁰| over α ∈ (0, 1), μ ∈ (0, 2): \"the biggest difference is \
             in μ ∈ (0, 1) and it's up to 0.3\" (absolute)",
};

/// Document 003 §3.2.3: the ASG–SG convolution error claim.
pub const SG_CONVOLUTION_L2: Tolerance = Tolerance {
    name: "sg_convolution_l2",
    value: 2e-3,
    reason: "seed 003 §3.2.3: \"When λ, μ > 3, the L2-error is less than 0.2 %. When λ, μ > 1, \
             the error is bounded by 2.8 %.\" (relative L2 over the SG axis, ERRATA.md 003-E5)",
};

/// Document 000 eq 28: the trapezoid rule has no stated bound; the measured envelope guards it.
pub const PIECEWISE_TRAPEZOID: Tolerance = Tolerance {
    name: "piecewise_trapezoid",
    value: 5e-2,
    reason: "seed 000 eq 28 states the trapezoid rule without an error bound (as an equality it \
             is an expected failure, errata 000-E10); ERRATA.md E10 measured ≤ 3.3e-2 relative \
             in G1 for 5–11 irregular breakpoints, so 5e-2 catches a regression",
};

/// Document 001 eq 7 and 9: slope-moment claims, against quadrature of P2.
pub const SLOPE_MOMENT_CLAIM: Tolerance = Tolerance {
    name: "slope_moment_claim",
    value: 1e-8,
    reason: "seed 001 eq 9: \"The variance of this distribution is σ²/2 for γ > 2\"; eq 7: excess \
             kurtosis 3/(C − 3): exact statements, checked against ∫q^{2k}P2 dq by quadrature of \
             an algebraic tail (1e-12 asked, heavy tails converge slowly: 1e-8)",
};

/// SG/ASG identities between two evaluations (document 003): product of SGs against the product of
/// evaluations, the SG decomposition into circular Gaussians, evaluation against the definition.
pub const SG_IDENTITY: Tolerance = Tolerance {
    name: "sg_identity",
    value: 1e-12,
    reason: "two evaluations of an exact identity; round-off in exponents up to ~λ(1 − cos θ) ≈ \
             50 and in unit vectors with λ up to 1e4 (an absolute error λ·1e-16 in the exponent) \
             gives relative differences up to ~1e-13: 1e-12",
};

/// The clamped-cosine fit max(v·n, 0) ≈ G(v; n, 2.133, 1.170) in use, G · C* (document 003 §2.4).
pub const CLAMPED_COSINE_FIT: Tolerance = Tolerance {
    name: "clamped_cosine_fit",
    value: 0.195,
    reason: "the document states no error for the fit; the reference measured ≤ 0.1944 (relative) \
             for SG lights of sharpness 1e-3…1e4 within 60° of n (sg::isotropic \
             CLAMPED_COSINE_MAX_REL_ERROR_60): a bound on the measured error, so a changed fit \
             constant or inner product fails",
};

/// The lobe warp's sharpness λ_W = λ/(4|p·o|) (document 003 §2.1), as a factor of ln 10/(2λ).
pub const SG_WARP_AREA: Tolerance = Tolerance {
    name: "sg_warp_area",
    value: 1.1,
    reason: "the document states no error; f_a(λ_W) exceeds the true area of ψ(A) by \
             2/(1 + cos θ₀) − 1 ≈ ln 10/(2λ), cos θ₀ = 1 − ln 10/λ (ERRATA.md seed 003, claims \
             measured): the check allows 1.1 × (2/(1 + cos θ₀) − 1) relative, so it fails if \
             the warp's sharpness is off by more than a tenth of its own error",
};

/// The ASG integral's large-bandwidth form π/√(λμ) for λ, μ > 5 (document 003 §3.2.1).
pub const ASG_LARGE_BANDWIDTH: Tolerance = Tolerance {
    name: "asg_large_bandwidth",
    value: 7e-3,
    reason: "the document says only that the F terms \"become small\" for λ, μ > 5; its worst \
             case is λ = μ = 5, where the relative error is e^{−5}/(1 − e^{−5}) = 0.68 %: 0.7 %",
};

/// The ASG × ASG product with the smooth terms frozen at z₃ (document 003 §3.2.2), error relative
/// to the exact product's peak.
pub const ASG_PRODUCT_FIT: Tolerance = Tolerance {
    name: "asg_product_fit",
    value: 0.2,
    reason: "the document states no error; the reference measured max |approx − exact| / peak of \
             0.19 at bandwidth 1 falling to 2.1e-3 at 1000 (ERRATA.md seed 003, claims measured): \
             0.2 bounds it over the planned bandwidths ≥ 1",
};

/// The ASG–SG convolution approximation (document 003 §3.2.3).
pub const ASG_CONVOLUTION_CLAIM: Tolerance = Tolerance {
    name: "asg_convolution_claim",
    value: 0.028,
    reason: "the document claims an L2 error below 2.8 % for λ, μ > 1 (0.2 % for λ, μ > 3); the \
             check measures the relative error at the SG axis and 0.3 rad off, which is within \
             the claimed L2 bound wherever the claim holds (ERRATA.md seed 003 E5: it does not \
             unless the SG is sharp)",
};

/// The ASG–SG convolution approximation for λ, μ > 3 (document 003 §3.2.3).
pub const ASG_CONVOLUTION_CLAIM_SHARP: Tolerance = Tolerance {
    name: "asg_convolution_claim_sharp",
    value: 0.002,
    reason: "the document claims an L2 error below 0.2 % for λ, μ > 3; measured as the relative \
             error at the SG axis and 0.3 rad off (ERRATA.md seed 003 E5: the claim fails unless \
             the SG is very sharp)",
};

/// Document 003 §3.2.1's ASG integral with F, an approximation the document states no error for
/// (not an erratum: "can be approximated as follows"). Judged by `claims.asg_integral`
/// (`check/claims.rs`).
pub const ASG_INTEGRAL_APPROXIMATION: Tolerance = Tolerance {
    name: "asg_integral_approximation",
    value: 0.045,
    reason: "the document states no error; the reference measured max 4.24 % relative for \
             bandwidths μ ≥ 1, λ ≥ μ (at λ = 2, μ = 1; exact for λ = μ; unbounded as μ → 0): \
             4.5 % bounds the measured error over the planned grid, so a changed form fails",
};

/// Document 003 §4.3's ∫g^c ≈ ∫g (erf form), as a multiple of its leading-order relative error
/// σ²/16. Judged by `claims.circular_interval_erf` (`check/claims.rs`).
pub const CIRCULAR_ERF_LEADING_ORDER: Tolerance = Tolerance {
    name: "circular_erf_leading_order",
    value: 1.2,
    reason: "the document says \"approximated\" and states no error; g^c = g·e^{x⁴/(12σ²) + …} \
             gives a relative error σ²/16 to leading order; measured ≤ 1.15 σ²/16 for σ ≤ 1 and \
             means in [−1.4, 1.4]: the check allows 1.2 σ²/16",
};

/// Every tolerance, for the report and the README.
pub const TABLE: &[Tolerance] = &[
    CLOSED_FORM,
    PRECISE,
    NUMERICAL_ROUTE,
    NORMALIZATION,
    IDENTITY,
    PDF_CONSISTENCY,
    PDF_JACOBIAN,
    AGAINST_REFERENCE,
    BATCH_SAMPLER,
    BATCH_SAMPLER_REFERENCE,
    STATISTICAL_ALPHA,
    LIMIT_RATE,
    MOMENT,
    VISIBLE_MOMENTS,
    SG_IDENTITY,
    CLAMPED_COSINE_FIT,
    SG_WARP_AREA,
    ASG_LARGE_BANDWIDTH,
    ASG_PRODUCT_FIT,
    ASG_CONVOLUTION_CLAIM,
    ASG_CONVOLUTION_CLAIM_SHARP,
    ASG_INTEGRAL_APPROXIMATION,
    CIRCULAR_ERF_LEADING_ORDER,
    ERRATUM,
    ERRATUM_ASYMPTOTIC,
    ERRATUM_VISIBLE_MOMENTS,
    GTR_LIMIT,
    GTR_SPLINE,
    GTR_CLAMP,
    SG_CONVOLUTION_L2,
    PIECEWISE_TRAPEZOID,
    SLOPE_MOMENT_CLAIM,
    BSDF_SAMPLE_CONSISTENCY,
    BSDF_RECIPROCITY,
    BSDF_NDF_CONSISTENCY,
    BSDF_AGAINST_REFERENCE,
    BSDF_SAMPLE_DIRECTION,
    BSDF_ENERGY,
    BSDF_STABILITY,
];

/// `pdf_wm` against the density of the sampling map (finite differences of `sample_wm`).
pub const PDF_JACOBIAN: Tolerance = Tolerance {
    name: "pdf_jacobian",
    value: 1e-6,
    reason: "Richardson-extrapolated central differences with steps 1e-4 and 5e-5 err by \
             O(h⁴) (~1e-12 for the smooth samplers) plus round-off ε/h (~1e-11), amplified by \
             the map's conditioning near the poles of the inversion; 1e-6 keeps a margin of \
             10³ over what correct samplers measure and fails a 0.5 % mismatch by 5000×",
};

/// A user's batch sampler against its scalar sampler at the same u (`sampling.batch_agrees`),
/// in ulps per component.
pub const BATCH_SAMPLER: Tolerance = Tolerance {
    name: "batch_sampler",
    value: 4.0,
    reason: "ulps per component: the trait asks a batch override to agree with the scalar \
             sampler to the ulps it documents; a vectorized path (FMA contraction, a SIMD \
             sin/cos or sqrt good to ~1 ulp each, a reciprocal instead of divisions as mfh's \
             own GGX visible-normal batch, 1 ulp measured) reorders a few roundings of a unit \
             vector's components, so 4 ulps; a defect (a flipped sign, a swapped u) is ~10¹⁶ \
             ulps",
};

/// mfh's reference models' batch samplers against their scalar samplers: GGX's visible-normal
/// sampler within its stated ulps, every other bit for bit.
pub const BATCH_SAMPLER_REFERENCE: Tolerance = Tolerance {
    name: "batch_sampler_reference",
    value: mfh_reference::ndf::GGX_VISIBLE_BATCH_MAX_ULPS,
    reason: "ulps per component: GGX's batch visible-normal sampler normalizes by one \
             reciprocal instead of three divisions, within 2 ulps (ndf/ggx_visible_batch.rs; \
             1 measured), the same bits on every dispatch path; every other reference batch \
             sampler evaluates the scalar arithmetic lane by lane, bit for bit (ndf/batch.rs)",
};

/// A user's closed form against mfh's reference closed form of the same model.
pub const AGAINST_REFERENCE: Tolerance = Tolerance {
    name: "against_reference",
    value: 1e-10,
    reason: "two double-precision evaluations of the same closed form, by different algebra: \
             ~1e-14 where well conditioned; 1e-10 allows conditioning near grazing incidence \
             (as CLOSED_FORM) but not a cancellation that loses digits near normal incidence",
};

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_tolerance_has_a_reason_and_a_unique_name() {
        for (i, t) in TABLE.iter().enumerate() {
            // 0 only for a bit-for-bit promise.
            assert!(t.value >= 0.0 && t.reason.len() > 40, "{t:?}");
            assert!(TABLE[..i].iter().all(|u| u.name != t.name), "{}", t.name);
        }
        // Every float32 row names an f64 tolerance, is looser than it, and has its reason.
        for (name, t) in F32_TABLE {
            let f64_row = TABLE.iter().find(|u| u.name == *name).expect(name);
            assert!(t.value > f64_row.value && t.reason.len() > 40, "{t:?}");
            assert_eq!(f64_row.at(crate::precision::Precision::F32), *t);
            assert_eq!(f64_row.at(crate::precision::Precision::F64), *f64_row);
        }
        assert_eq!(
            STATISTICAL_ALPHA.at(crate::precision::Precision::F32),
            STATISTICAL_ALPHA
        );
        assert!(
            expected_failures("smith.lambda_route", "std", "2f1_algorithm2")
                .next()
                .is_some()
        );
        assert!(expected_failures("smith.lambda_route", "student", "stable")
            .next()
            .is_none());
    }
}
