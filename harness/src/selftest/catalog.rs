//! The catalog of mutants: each a reference model with one defect ([`super::mutant`]), the
//! check ids expected to kill it, and how it is audited (the `Audit::of` gate, or the D_s
//! check directly where the gate has no D_s capability for a user model).

use super::mutant::Defect;
use serde::Serialize;

/// How a mutant is audited.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Route {
    /// Through the public gate, `Audit::of(&mutant)`, every capability audited (with slope
    /// moments when `slope_moments`).
    Gate {
        /// Whether the renderer declares slope-moment filtering.
        slope_moments: bool,
    },
    /// Through the D_s check (`check::ds::plan`) with the mutant as the model: the gate does
    /// not audit visible-slope moments of a user model (they need the reference spec for the
    /// oracle), so the check is called on the trait object directly.
    VisibleMoments,
    /// Through the `sg.product` check (`check::sg::product_check`) with the mutated product
    /// as the function it checks, over the profile's sharpness grid: the SG checks take no
    /// model (they exercise mfh's own SG closed forms), so there is no capability to wrap.
    SgProduct,
}

/// One mutant of the catalog.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Entry {
    /// A stable id, `family.defect`.
    pub id: &'static str,
    /// One line: what is wrong.
    pub description: &'static str,
    /// The base model's spec (JSON).
    pub base: &'static str,
    /// The defect.
    pub defect: Defect,
    /// The check ids expected to kill it (at least one must be among the killers).
    pub expected: &'static [&'static str],
    /// How it is audited.
    pub route: Route,
    /// Whether it is in the CI subset (`--subset ci`).
    pub ci: bool,
}

const GGX: &str = r#"{"family":"ggx","alpha":0.3}"#;
const GGX_ANISO: &str = r#"{"family":"ggx","alpha_x":0.1,"alpha_y":0.4}"#;
/// A smooth GGX: its near-normal regime (α tan θi < 4.5e-3) spans θi < 0.089 rad.
const GGX_SMOOTH: &str = r#"{"family":"ggx","alpha":0.05}"#;
const GGX_VIS: &str = r#"{"family":"ggx","alpha_x":0.2,"alpha_y":0.5}"#;
const BECKMANN: &str = r#"{"family":"beckmann","alpha":0.3}"#;
const BECKMANN_ANISO: &str = r#"{"family":"beckmann","alpha_x":0.3,"alpha_y":0.15}"#;
const STD: &str = r#"{"family":"std","gamma":2.5,"alpha":0.3}"#;
const STD_ANISO: &str = r#"{"family":"std","gamma":3.0,"alpha_x":0.08,"alpha_y":0.35}"#;
const HYPER_CAUCHY: &str = r#"{"family":"hyper_cauchy","gamma":2.0,"alpha":0.25}"#;
const GTR: &str = r#"{"family":"gtr","gamma":2.5,"alpha":0.4}"#;
const GTR1: &str = r#"{"family":"gtr","gamma":1.0,"alpha":0.3}"#;
const PIECEWISE: &str = r#"{"family":"piecewise_linear","x":{"theta":[0,0.5,1.0,1.5707963267948966],"value":[1,0.6,0.1,0]}}"#;
const PIECEWISE_ANISO: &str = r#"{"family":"piecewise_linear","x":{"theta":[0,0.5,1.0,1.5707963267948966],"value":[1,0.6,0.1,0]},"y":{"theta":[0,0.3,0.9,1.5707963267948966],"value":[2,0.8,0.05,0]}}"#;
const GAUSSIAN: &str =
    r#"{"family":"gaussian_slopes","mean":[0.1,-0.05],"cov":[[0.04,0.01],[0.01,0.09]]}"#;

/// The SG mutants have no model: their base is the empty spec.
const SG: &str = "{}";

const GATE: Route = Route::Gate {
    slope_moments: false,
};
const NORM: &[&str] = &["normalization.projected_area"];
const LAMBDA: &[&str] = &["smith.lambda_route"];
/// D with its axes swapped keeps its normalization; Λ (from the reference) and pdf_wm (the
/// reference's D cos θ) no longer match it.
const D_SWAPPED: &[&str] = &[
    "smith.lambda_route",
    "smith.white_furnace",
    "sampling.pdf_consistency",
];
const STAB: &[&str] = &["stability.incidence"];
const G2: &[&str] = &["smith.g1_g2"];
const STAT: &[&str] = &["sampling.chi2", "sampling.ks_marginals"];
const PDF: &[&str] = &["sampling.pdf_jacobian", "sampling.pdf_consistency"];
const VIS: &[&str] = &["sampling.chi2_visible"];
/// The regime defects of a visible-normal sampler: local in the incidence or in u, seen by the
/// Jacobian at the sweep's incidences.
const VIS_JACOBIAN: &[&str] = &["sampling.visible_jacobian"];
const VIS_PDF: &[&str] = &[
    "sampling.pdf_visible_normalization",
    "sampling.chi2_visible",
];
const DS: &[&str] = &[
    "ds.visible_moments",
    "ds.visible_moments_backfacing",
    "ds.visible_moments_singular",
];

macro_rules! entry {
    ($id:literal, $desc:literal, $base:expr, $defect:expr, $expected:expr, $ci:literal) => {
        entry!($id, $desc, $base, $defect, $expected, GATE, $ci)
    };
    ($id:literal, $desc:literal, $base:expr, $defect:expr, $expected:expr, $route:expr, $ci:literal) => {
        Entry {
            id: $id,
            description: $desc,
            base: $base,
            defect: $defect,
            expected: $expected,
            route: $route,
            ci: $ci,
        }
    };
}

/// Every mutant.
pub const CATALOG: &[Entry] = &[
    // GGX α = 0.3.
    entry!(
        "ggx.d_scale_0.1pct",
        "D off by 0.1 % everywhere (normalization constant)",
        GGX,
        Defect::DScale { e: 1e-3 },
        NORM,
        true
    ),
    entry!(
        "ggx.d_scale_1pct",
        "D off by 1 % everywhere",
        GGX,
        Defect::DScale { e: 1e-2 },
        NORM,
        false
    ),
    entry!(
        "ggx.d_tail_0.1pct",
        "D off by 0.1 % beyond θm = 1 only (the tail)",
        GGX,
        Defect::DScaleAbove {
            theta: 1.0,
            e: 1e-3
        },
        NORM,
        false
    ),
    entry!(
        "ggx.d_nan_at_normal",
        "D is NaN at exactly m = n",
        GGX,
        Defect::DNanAtNormal,
        STAB,
        false
    ),
    entry!(
        "ggx.lambda_grazing_1pct",
        "Λ off by 1 % only at grazing (θ > 1.4)",
        GGX,
        Defect::LambdaScaleAbove {
            theta: 1.4,
            e: 1e-2
        },
        LAMBDA,
        true
    ),
    entry!(
        "ggx.lambda_near_normal_branch",
        "Λ off by 0.1 % in the θ < 1 branch only",
        GGX,
        Defect::LambdaScaleBelow {
            theta: 1.0,
            e: 1e-3
        },
        LAMBDA,
        false
    ),
    entry!(
        "ggx.lambda_lower_branch",
        "Λ(−w) = Λ(w) below the horizon instead of −1 − Λ(w)",
        GGX,
        Defect::LambdaLowerBranch,
        &["smith.identities"],
        false
    ),
    entry!(
        "ggx.lambda_nan_at_normal",
        "Λ is NaN at exactly θ = 0",
        GGX,
        Defect::LambdaNanAtNormal,
        STAB,
        false
    ),
    entry!(
        "ggx.lambda_precision_near_normal",
        "Λ = 1/G1 − 1: precision lost near normal incidence",
        GGX,
        Defect::LambdaViaG1,
        LAMBDA,
        false
    ),
    entry!(
        "ggx.g2_uncorrelated",
        "height-correlated G2 replaced by the uncorrelated product",
        GGX,
        Defect::G2Uncorrelated,
        G2,
        true
    ),
    entry!(
        "ggx.g2_correlated_for_uncorrelated",
        "uncorrelated G2 replaced by the height-correlated form",
        GGX,
        Defect::G2CorrelatedForUncorrelated,
        G2,
        false
    ),
    entry!(
        "ggx.sampler_exponent_1pct",
        "sampled tan²θ exponent off by 1 %",
        GGX,
        Defect::SamplerExponent {
            scale: 0.3,
            e: 1e-2
        },
        STAT,
        true
    ),
    entry!(
        "ggx.sampler_half_phi",
        "sampled φ covers half the circle",
        GGX,
        Defect::SamplerHalfPhi,
        STAT,
        true
    ),
    entry!(
        "ggx.sampler_below_horizon_u0",
        "sampled normal below the horizon at u₁ = 0 only",
        GGX,
        Defect::SamplerBelowHorizonAtU0,
        STAB,
        true
    ),
    entry!(
        "ggx.pdf_mismatch_0.5pct",
        "pdf_wm 0.5 % off its sampler",
        GGX,
        Defect::PdfScale { e: 5e-3 },
        PDF,
        true
    ),
    entry!(
        "ggx.pdf_missing_cosine",
        "pdf_wm = D(m) without m·n",
        GGX,
        Defect::PdfMissingCosine,
        PDF,
        false
    ),
    // GGX anisotropic: axes swapped in one quantity.
    entry!(
        "ggx_aniso.d_axes_swapped",
        "α_x and α_y swapped in D only",
        GGX_ANISO,
        Defect::DAxesSwapped,
        D_SWAPPED,
        false
    ),
    entry!(
        "ggx_aniso.lambda_axes_swapped",
        "α_x and α_y swapped in Λ only",
        GGX_ANISO,
        Defect::LambdaAxesSwapped,
        LAMBDA,
        false
    ),
    entry!(
        "ggx_aniso.sampler_axes_swapped",
        "α_x and α_y swapped in the sampler only",
        GGX_ANISO,
        Defect::SamplerAxesSwapped,
        STAT,
        false
    ),
    entry!(
        "ggx_vis.d_axes_swapped",
        "α_x and α_y swapped in D only",
        GGX_VIS,
        Defect::DAxesSwapped,
        D_SWAPPED,
        true
    ),
    entry!(
        "ggx_vis.lambda_axes_swapped",
        "α_x and α_y swapped in Λ only",
        GGX_VIS,
        Defect::LambdaAxesSwapped,
        LAMBDA,
        false
    ),
    // GGX with a visible-normal sampler.
    entry!(
        "ggx_vis.visible_ignores_incidence",
        "visible-normal sampler samples D(m)(m·n), ignoring wi",
        GGX_VIS,
        Defect::VisibleIgnoresIncidence,
        VIS,
        true
    ),
    entry!(
        "ggx_vis.visible_wrong_incidence",
        "visible-normal sampler uses θi 5 % too large",
        GGX_VIS,
        Defect::VisibleWrongIncidence { e: 0.05 },
        VIS,
        false
    ),
    entry!(
        "ggx_vis.pdf_visible_0.5pct",
        "pdf_wm_visible 0.5 % off",
        GGX_VIS,
        Defect::VisiblePdfScale { e: 5e-3 },
        VIS_PDF,
        true
    ),
    // Regime defects of the visible-normal sampler (GGX, Heitz 2018).
    entry!(
        "ggx_smooth.visible_frame_switch",
        "visible-normal sampler switches its frame to (1, 0, 0) where V_h is within 1e-5 of \
         the normal (≈ 1 % density error for θi < 0.089 rad at α 0.05)",
        GGX_SMOOTH,
        Defect::VisibleFrameSwitch { within: 1e-5 },
        VIS_JACOBIAN,
        false
    ),
    entry!(
        "ggx.visible_height_clamp",
        "visible-normal sampler clamps the stretched normal's height at 1e-2",
        GGX,
        Defect::VisibleHeightClamp { floor: 1e-2 },
        VIS_JACOBIAN,
        false
    ),
    // Beckmann α = 0.3.
    entry!(
        "beckmann.d_scale_0.5pct",
        "D off by 0.5 %",
        BECKMANN,
        Defect::DScale { e: 5e-3 },
        NORM,
        false
    ),
    entry!(
        "beckmann.lambda_grazing_1pct",
        "Λ off by 1 % only at grazing (θ > 1.4)",
        BECKMANN,
        Defect::LambdaScaleAbove {
            theta: 1.4,
            e: 1e-2
        },
        LAMBDA,
        false
    ),
    entry!(
        "beckmann.lambda_precision_near_normal",
        "Λ = 1/G1 − 1: precision lost near normal incidence",
        BECKMANN,
        Defect::LambdaViaG1,
        LAMBDA,
        false
    ),
    entry!(
        "beckmann.g2_uncorrelated",
        "height-correlated G2 replaced by the uncorrelated product",
        BECKMANN,
        Defect::G2Uncorrelated,
        G2,
        false
    ),
    entry!(
        "beckmann.sampler_exponent_1pct",
        "sampled tan²θ exponent off by 1 %",
        BECKMANN,
        Defect::SamplerExponent {
            scale: 0.3,
            e: 1e-2
        },
        STAT,
        false
    ),
    entry!(
        "beckmann.sampler_half_phi",
        "sampled φ covers half the circle",
        BECKMANN,
        Defect::SamplerHalfPhi,
        STAT,
        false
    ),
    entry!(
        "beckmann.pdf_mismatch_0.5pct",
        "pdf_wm 0.5 % off its sampler",
        BECKMANN,
        Defect::PdfScale { e: 5e-3 },
        PDF,
        false
    ),
    entry!(
        "beckmann.slope_variance_1pct",
        "slope moments ν₂ₖ off by 1 %",
        BECKMANN,
        Defect::SlopeMomentScale { e: 1e-2 },
        &["moments.slopes"],
        Route::Gate {
            slope_moments: true
        },
        false
    ),
    // Beckmann anisotropic, visible-normal sampler.
    entry!(
        "beckmann_aniso.d_axes_swapped",
        "α_x and α_y swapped in D only",
        BECKMANN_ANISO,
        Defect::DAxesSwapped,
        D_SWAPPED,
        false
    ),
    entry!(
        "beckmann_aniso.sampler_axes_swapped",
        "α_x and α_y swapped in the sampler only",
        BECKMANN_ANISO,
        Defect::SamplerAxesSwapped,
        STAT,
        false
    ),
    entry!(
        "beckmann_aniso.visible_wrong_incidence",
        "visible-normal sampler uses θi 5 % too large",
        BECKMANN_ANISO,
        Defect::VisibleWrongIncidence { e: 0.05 },
        VIS,
        false
    ),
    entry!(
        "beckmann_aniso.pdf_visible_0.5pct",
        "pdf_wm_visible 0.5 % off",
        BECKMANN_ANISO,
        Defect::VisiblePdfScale { e: 5e-3 },
        VIS_PDF,
        false
    ),
    // STD γ = 2.5, α = 0.3.
    entry!(
        "std.d_scale_0.1pct",
        "D off by 0.1 %",
        STD,
        Defect::DScale { e: 1e-3 },
        NORM,
        false
    ),
    entry!(
        "std.radius_exponent_1pct",
        "sampled radius exponent (tan²θ) off by 1 %",
        STD,
        Defect::SamplerExponent {
            scale: 0.3,
            e: 1e-2
        },
        STAT,
        true
    ),
    entry!(
        "std.lambda_grazing_1pct",
        "Λ off by 1 % only at grazing (θ > 1.4)",
        STD,
        Defect::LambdaScaleAbove {
            theta: 1.4,
            e: 1e-2
        },
        LAMBDA,
        false
    ),
    entry!(
        "std.sampler_half_phi",
        "sampled φ covers half the circle",
        STD,
        Defect::SamplerHalfPhi,
        STAT,
        false
    ),
    entry!(
        "std.pdf_mismatch_0.5pct",
        "pdf_wm 0.5 % off its sampler",
        STD,
        Defect::PdfScale { e: 5e-3 },
        PDF,
        false
    ),
    entry!(
        "std_aniso.lambda_axes_swapped",
        "α_x and α_y swapped in Λ only",
        STD_ANISO,
        Defect::LambdaAxesSwapped,
        LAMBDA,
        false
    ),
    entry!(
        "hyper_cauchy.sampler_exponent_1pct",
        "sampled tan²θ exponent off by 1 %",
        HYPER_CAUCHY,
        Defect::SamplerExponent {
            scale: 0.25,
            e: 1e-2
        },
        STAT,
        false
    ),
    // GTR.
    entry!(
        "gtr.d_scale_0.5pct",
        "D off by 0.5 %",
        GTR,
        Defect::DScale { e: 5e-3 },
        NORM,
        false
    ),
    entry!(
        "gtr.sampler_exponent_1pct",
        "sampled tan²θ exponent off by 1 %",
        GTR,
        Defect::SamplerExponent {
            scale: 0.4,
            e: 1e-2
        },
        STAT,
        false
    ),
    entry!(
        "gtr1.lambda_grazing_1pct",
        "Λ off by 1 % only at grazing (θ > 1.4)",
        GTR1,
        Defect::LambdaScaleAbove {
            theta: 1.4,
            e: 1e-2
        },
        LAMBDA,
        false
    ),
    // Piecewise-linear profiles.
    entry!(
        "piecewise.d_scale_0.5pct",
        "D off by 0.5 %",
        PIECEWISE,
        Defect::DScale { e: 5e-3 },
        NORM,
        false
    ),
    entry!(
        "piecewise.sampler_half_phi",
        "sampled φ covers half the circle",
        PIECEWISE,
        Defect::SamplerHalfPhi,
        STAT,
        false
    ),
    entry!(
        "piecewise.lambda_grazing_1pct",
        "Λ off by 1 % only at grazing (θ > 1.4)",
        PIECEWISE,
        Defect::LambdaScaleAbove {
            theta: 1.4,
            e: 1e-2
        },
        LAMBDA,
        false
    ),
    entry!(
        "piecewise_aniso.d_axes_swapped",
        "the x and y profiles swapped in D only",
        PIECEWISE_ANISO,
        Defect::DAxesSwapped,
        D_SWAPPED,
        false
    ),
    // Gaussian slopes: visible-slope moments (through the D_s check).
    entry!(
        "gaussian.ds_cross_dropped",
        "D_s cross covariance dropped",
        GAUSSIAN,
        Defect::DsCrossDropped,
        DS,
        Route::VisibleMoments,
        true
    ),
    entry!(
        "gaussian.ds_e1_sign_flipped",
        "D_s with E₁ of sign flipped (eq 59 as printed)",
        GAUSSIAN,
        Defect::DsE1Flipped,
        DS,
        Route::VisibleMoments,
        true
    ),
    entry!(
        "gaussian.ds_mean_0.1pct",
        "D_s mean off by 0.1 %",
        GAUSSIAN,
        Defect::DsMeanScale { e: 1e-3 },
        DS,
        Route::VisibleMoments,
        false
    ),
    // Spherical Gaussians.
    entry!(
        "sg.product_amplitude_0.1pct",
        "SG vector product amplitude off by 0.1 %",
        SG,
        Defect::SgProductAmplitude { e: 1e-3 },
        &["sg.product"],
        Route::SgProduct,
        true
    ),
];

#[cfg(test)]
mod tests {
    use super::*;
    use mfh_reference::ModelSpec;

    #[test]
    fn the_catalog_has_40_mutants_with_unique_ids_and_valid_bases() {
        assert!(CATALOG.len() >= 40, "{}", CATALOG.len());
        let mut ids: Vec<&str> = CATALOG.iter().map(|e| e.id).collect();
        ids.sort_unstable();
        ids.dedup();
        assert_eq!(ids.len(), CATALOG.len());
        for e in CATALOG.iter().filter(|e| e.route != Route::SgProduct) {
            let spec: ModelSpec = serde_json::from_str(e.base).expect(e.id);
            spec.build().expect(e.id);
            assert!(!e.expected.is_empty(), "{}", e.id);
        }
        assert!(CATALOG.iter().filter(|e| e.ci).count() >= 10);
    }
}
