//! The pseudo-VNIS of document 001 §7.2 for STD: Algorithm 1's choice of a proxy visible-normal
//! sampler (GGX, Beckmann or plain normal sampling), its samples and density, and the weight of
//! eq 43 as printed next to the unbiased one.

use crate::error::ParamError;
use crate::geometry::{dot, Vec3};
use crate::model::{visible_domain, Masking, Ndf, NormalSampler, Smith, VisibleNormalSampler};
use crate::ndf::student::{Member, Student};
use crate::ndf::{Beckmann, Ggx};

/// The sampler Algorithm 1 of document 001 §7.2 picks.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Proxy {
    /// Plain normal sampling of the STD itself (document 001 §6, eq 40–42): lines 2 and 13.
    Normals,
    /// Visible normals of GGX with the STD's roughness: line 9.
    Ggx,
    /// Visible normals of Beckmann with the STD's roughness: lines 4 and 11.
    Beckmann,
}

impl Proxy {
    /// The name used in records (`normals`, `ggx`, `beckmann`).
    pub fn name(self) -> &'static str {
        match self {
            Proxy::Normals => "normals",
            Proxy::Ggx => "ggx",
            Proxy::Beckmann => "beckmann",
        }
    }
}

/// Algorithm 1 of document 001 §7.2, as printed, for STD with roughness σ and shape γ:
///
/// ```text
/// 1:  if σ ≤ 0.01: normal sampling (§6)
/// 3:  else if γ > 10: Beckmann VNIS
/// 6:  else: GGX upper bound ← min(5, 2 + σ/0.1)
/// 7:        Beckmann lower bound ← max(5, 10 − 5 · max(0, σ − 0.2)/0.1)
/// 8:        if γ < GGX upper bound: GGX VNIS
/// 10:       else if γ > Beckmann lower bound: Beckmann VNIS
/// 12:       else: normal sampling (§6)
/// ```
///
/// Domain: any σ and γ (comparisons with NaN fall through to normal sampling).
pub fn algorithm1(gamma: f64, sigma: f64) -> Proxy {
    if !(sigma > 0.01) {
        return Proxy::Normals;
    }
    if gamma > 10.0 {
        return Proxy::Beckmann;
    }
    let ggx_upper = 5.0f64.min(2.0 + sigma / 0.1);
    let beckmann_lower = 5.0f64.max(10.0 - 5.0 * (sigma - 0.2).max(0.0) / 0.1);
    if gamma < ggx_upper {
        Proxy::Ggx
    } else if gamma > beckmann_lower {
        Proxy::Beckmann
    } else {
        Proxy::Normals
    }
}

/// The pseudo-VNIS of document 001 §7.2 for an STD material: samples microfacet normals for an
/// incident direction `wi` from the proxy Algorithm 1 picks (with the STD's roughness), and
/// weights them for the estimator of the reflected energy with F = 1,
///
/// ```text
/// E(wi) = ∫ G2(wo, wi, m) ⟨wi·m⟩⁺ D(m) / cos θi dm = E_{m ∼ D_wi}[G2(wo, wi, m) / G1(wi)]
/// ```
///
/// (wo is the reflection of wi about m in a renderer; any wo here), where D, Λ, G1, G2 are the
/// STD's and D_wi(m) = G1(wi)⟨wi·m⟩⁺D(m)/cos θi is its distribution of visible normals.
///
/// - The weight as printed (eq 43): `weight(v) = G/G1(v)`, i.e. G2(wo, wi, m)/G1(wi) — the
///   VNIS weight, unbiased only if m is distributed as the STD's own D_wi. For the proxies it is
///   not (GGX's D_wi is the STD's only at γ = 2, Beckmann's only as γ → ∞), so the estimator
///   is biased for every γ ∉ {2, ∞} that Algorithm 1 sends to a proxy: its mean is
///   ∫ G2/G1(wi) D_wi^proxy(m) dm instead. On the normal-sampling branches (lines 2 and 13) the
///   document prescribes the §6 estimator, whose weight G2⟨wi·m⟩/(cos θi cos θm) is unbiased;
///   `weight_printed` uses it there.
/// - The unbiased weight for samples of density p(m): G2 ⟨wi·m⟩⁺ D(m) / (cos θi p(m)) (the
///   integrand of E over the density), which is eq 43's G2/G1 exactly when p = D_wi.
///
/// Anisotropic roughness: Algorithm 1 takes one σ; this uses σ = √(αx αy) (an extension, the
/// document is isotropic), while the proxies keep (αx, αy).
#[derive(Debug, Clone)]
pub struct PseudoVnis {
    std: Student,
    proxy: Proxy,
    sigma: f64,
    ggx: Ggx,
    beckmann: Beckmann,
}

impl PseudoVnis {
    /// The pseudo-VNIS of the STD with shape `gamma` (1.5 < γ ≤ 1e8: G1 needs Λ, which
    /// diverges for γ ≤ 3/2) and roughness (`alpha_x`, `alpha_y`).
    pub fn new(gamma: f64, alpha_x: f64, alpha_y: f64) -> Result<Self, ParamError> {
        if !(gamma > 1.5) {
            return Err(ParamError::GammaOutOfRange {
                family: "std",
                requirement: "> 1.5 for the pseudo-VNIS (its weight needs Λ)",
                value: gamma,
            });
        }
        let std = Student::new(Member::Std, gamma, alpha_x, alpha_y)?;
        let sigma = (alpha_x * alpha_y).sqrt();
        Ok(Self {
            std,
            proxy: algorithm1(gamma, sigma),
            sigma,
            ggx: Ggx::new(alpha_x, alpha_y)?,
            beckmann: Beckmann::new(alpha_x, alpha_y)?,
        })
    }

    /// The proxy Algorithm 1 picked.
    pub fn proxy(&self) -> Proxy {
        self.proxy
    }

    /// The σ Algorithm 1 was given (√(αx αy)).
    pub fn sigma(&self) -> f64 {
        self.sigma
    }

    /// The STD whose visible normals are being approximated.
    pub fn target(&self) -> &Student {
        &self.std
    }

    /// A microfacet normal for incidence `wi` from the chosen proxy (`u ∈ [0, 1)²`); NaN
    /// components for `wi` outside the visible-normal domain (wi_z > 0, unit).
    pub fn sample_wm(&self, wi: Vec3, u: [f64; 2]) -> Vec3 {
        match self.proxy {
            Proxy::Normals if visible_domain(wi) => self.std.sample_wm(u),
            Proxy::Normals => [f64::NAN; 3],
            Proxy::Ggx => self.ggx.sample_wm_visible(wi, u),
            Proxy::Beckmann => self.beckmann.sample_wm_visible(wi, u),
        }
    }

    /// The density of `sample_wm` with respect to solid angle: D(m)(m·n) of the STD, or the
    /// proxy's D_wi(m).
    pub fn pdf_wm(&self, wi: Vec3, m: Vec3) -> f64 {
        match self.proxy {
            Proxy::Normals if visible_domain(wi) => self.std.pdf_wm(m),
            Proxy::Normals => 0.0,
            Proxy::Ggx => self.ggx.pdf_wm_visible(wi, m),
            Proxy::Beckmann => self.beckmann.pdf_wm_visible(wi, m),
        }
    }

    /// The STD's own distribution of visible normals D_wi(m) = G1(wi)⟨wi·m⟩⁺D(m)/cos θi (0
    /// outside the domain), which the proxy stands in for.
    pub fn pdf_target(&self, wi: Vec3, m: Vec3) -> f64 {
        if !visible_domain(wi) || !(m[2] > 0.0) {
            return 0.0;
        }
        let c = dot(wi, m);
        if !(c > 0.0) {
            return 0.0;
        }
        c * self.std.d(m) / (wi[2] * (1.0 + self.std.lambda(wi)))
    }

    /// Eq 43 of document 001 as printed, `weight(v) = G/G1(v)`: G2(wo, wi, m)/G1(wi, m) with the
    /// STD's G1 and G2 (`masking` picks G2), on the VNIS branches of Algorithm 1; on its
    /// normal-sampling branches, the §6 weight G2⟨wi·m⟩/(cos θi cos θm). 0 where G1(wi, m) = 0.
    pub fn weight_printed(&self, wi: Vec3, wo: Vec3, m: Vec3, masking: Masking) -> f64 {
        if !visible_domain(wi) || !(m[2] > 0.0) || !(dot(wi, m) > 0.0) {
            return 0.0;
        }
        let g2 = self.std.g2(wo, wi, m, masking);
        match self.proxy {
            Proxy::Normals => g2 * dot(wi, m) / (wi[2] * m[2]),
            Proxy::Ggx | Proxy::Beckmann => g2 / self.std.g1(wi, m),
        }
    }

    /// The unbiased weight G2(wo, wi, m)⟨wi·m⟩⁺D(m)/(cos θi pdf_wm(wi, m)) of the STD for a
    /// sample of `sample_wm` (0 where the sampler's density is 0).
    ///
    /// Its variance is finite for the GGX proxy (γ ≥ 2: the STD's slope tail (1 + r²)^{−γ} is
    /// no heavier than GGX's) but infinite for the Beckmann proxy at every finite γ: the weight
    /// grows like e^{r²/α²} r^{−2γ} in the slope tail, and ∫ D_STD²/D_Beckmann diverges. The
    /// estimator stays unbiased, but its standard error is then not a reliable measure of its
    /// error.
    pub fn weight(&self, wi: Vec3, wo: Vec3, m: Vec3, masking: Masking) -> f64 {
        if !visible_domain(wi) || !(m[2] > 0.0) || !(dot(wi, m) > 0.0) {
            return 0.0;
        }
        let pdf = self.pdf_wm(wi, m);
        if !(pdf > 0.0) {
            return 0.0;
        }
        let g2 = self.std.g2(wo, wi, m, masking);
        g2 * dot(wi, m) * self.std.d(m) / (wi[2] * pdf)
    }
}

/// The mirror direction of `wi` about `m`: 2(wi·m)m − wi.
pub fn reflect(wi: Vec3, m: Vec3) -> Vec3 {
    let c = 2.0 * dot(wi, m);
    [c * m[0] - wi[0], c * m[1] - wi[1], c * m[2] - wi[2]]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::from_spherical;
    use crate::ndf::conformance::{hemisphere_integral, terminator, terminator_azimuths};
    use crate::test_support::rel_err;

    #[test]
    fn algorithm1_as_printed() {
        assert_eq!(algorithm1(3.0, 0.005), Proxy::Normals);
        assert_eq!(algorithm1(20.0, 0.01), Proxy::Normals);
        assert_eq!(algorithm1(20.0, 0.02), Proxy::Beckmann);
        // σ = 0.4: GGX below min(5, 6) = 5, Beckmann above max(5, 0) = 5.
        assert_eq!(algorithm1(3.0, 0.4), Proxy::Ggx);
        assert_eq!(algorithm1(4.99, 0.4), Proxy::Ggx);
        assert_eq!(algorithm1(5.0, 0.4), Proxy::Normals);
        assert_eq!(algorithm1(5.01, 0.4), Proxy::Beckmann);
        // σ = 0.1: GGX below 3, Beckmann above 10: the gap 3 ≤ γ ≤ 10 samples normals.
        assert_eq!(algorithm1(2.5, 0.1), Proxy::Ggx);
        assert_eq!(algorithm1(3.0, 0.1), Proxy::Normals);
        assert_eq!(algorithm1(8.0, 0.1), Proxy::Normals);
        assert_eq!(algorithm1(10.5, 0.1), Proxy::Beckmann);
        // σ = 0.25: GGX below 4.5, Beckmann above 7.5.
        assert_eq!(algorithm1(4.4, 0.25), Proxy::Ggx);
        assert_eq!(algorithm1(6.0, 0.25), Proxy::Normals);
        assert_eq!(algorithm1(7.6, 0.25), Proxy::Beckmann);
        assert_eq!(algorithm1(3.0, f64::NAN), Proxy::Normals);
    }

    /// The kinks of the integrands along azimuth φ of m: the terminator of ⟨wi·m⟩⁺ and the
    /// horizon of the mirror direction (2(wi·m)m_z = wi_z, at θ = π/4 + ψ/2 with
    /// tan ψ = (wi_x cos φ + wi_y sin φ)/wi_z).
    fn kinks(wi: Vec3, phi: f64) -> Vec<f64> {
        let k = wi[0] * phi.cos() + wi[1] * phi.sin();
        let mut out = terminator(wi, phi);
        out.push(std::f64::consts::FRAC_PI_4 + 0.5 * k.atan2(wi[2]));
        out
    }

    /// E = ∫ w(m) p(m) dm by quadrature, for the weight w and the sampler's density p.
    fn expectation(v: &PseudoVnis, wi: Vec3, printed: bool) -> f64 {
        let f = |m: Vec3| {
            let wo = reflect(wi, m);
            let w = if printed {
                v.weight_printed(wi, wo, m, Masking::Uncorrelated)
            } else {
                v.weight(wi, wo, m, Masking::Uncorrelated)
            };
            w * v.pdf_wm(wi, m)
        };
        hemisphere_integral(&f, 0.4, &|p| kinks(wi, p), &terminator_azimuths(wi))
    }

    #[test]
    fn the_printed_weight_is_biased_for_a_proxy_and_the_unbiased_one_is_not() {
        let wi = from_spherical(1.2, 0.3);
        let truth = |v: &PseudoVnis| {
            let f = |m: Vec3| {
                let wo = reflect(wi, m);
                let g2 = v.target().g2(wo, wi, m, Masking::Uncorrelated);
                g2 * v.pdf_target(wi, m) / v.target().g1(wi, m).max(f64::MIN_POSITIVE)
            };
            hemisphere_integral(&f, 0.4, &|p| kinks(wi, p), &terminator_azimuths(wi))
        };
        // γ = 3, σ = 0.4: GGX proxy.
        let v = PseudoVnis::new(3.0, 0.4, 0.4).unwrap();
        assert_eq!(v.proxy(), Proxy::Ggx);
        let t = truth(&v);
        let fixed = expectation(&v, wi, false);
        let printed = expectation(&v, wi, true);
        eprintln!("γ = 3, σ = 0.4: E = {t}, unbiased {fixed}, printed {printed}");
        assert!(rel_err(fixed, t) < 1e-7, "{fixed} vs {t}");
        assert!(rel_err(printed, t) > 1e-3, "{printed} vs {t}");
        // γ = 2 (GGX itself): the printed weight is unbiased.
        let v = PseudoVnis::new(2.0, 0.4, 0.4).unwrap();
        let t = truth(&v);
        assert!(rel_err(expectation(&v, wi, true), t) < 1e-7);
        // γ = 6, σ = 0.4: Beckmann proxy, biased too.
        let v = PseudoVnis::new(6.0, 0.4, 0.4).unwrap();
        assert_eq!(v.proxy(), Proxy::Beckmann);
        let t = truth(&v);
        let printed = expectation(&v, wi, true);
        eprintln!("γ = 6, σ = 0.4: E = {t}, printed {printed}");
        assert!(rel_err(expectation(&v, wi, false), t) < 1e-7);
        assert!(rel_err(printed, t) > 1e-3, "{printed} vs {t}");
        // The normal-sampling branch (σ = 0.1, γ = 5) uses the §6 weight: unbiased.
        let v = PseudoVnis::new(5.0, 0.1, 0.1).unwrap();
        assert_eq!(v.proxy(), Proxy::Normals);
        let t = truth(&v);
        assert!(rel_err(expectation(&v, wi, true), t) < 1e-6);
    }

    #[test]
    fn domain_is_validated() {
        assert!(PseudoVnis::new(1.5, 0.3, 0.3).is_err());
        assert!(PseudoVnis::new(3.0, 0.0, 0.3).is_err());
        let v = PseudoVnis::new(3.0, 0.3, 0.3).unwrap();
        assert!(v.sample_wm([0.0, 0.0, -1.0], [0.2, 0.3])[0].is_nan());
        assert_eq!(v.pdf_wm([0.0, 0.0, -1.0], [0.0, 0.0, 1.0]), 0.0);
        let m = [0.0, 0.0, 1.0];
        assert_eq!(
            v.weight([0.0, 0.0, -1.0], m, m, Masking::HeightCorrelated),
            0.0
        );
        let r = reflect(from_spherical(0.5, 0.0), m);
        assert!((r[0] + 0.5f64.sin()).abs() < 1e-15 && (r[2] - 0.5f64.cos()).abs() < 1e-15);
    }
}
