//! A renderer's own microfacet code, as an outside user of mfh writes it: GGX and Beckmann,
//! written here from the published formulas (Walter et al. 2007; Heitz 2014), with no code from
//! mfh. The tests in `tests/` gate it with `mfh_harness::Audit` exactly as a renderer crate
//! would, and check that deliberately wrong variants ([`Defect`]) fail on the right check.

use std::f64::consts::PI;

/// A direction or normal in the shading frame (n = +z).
pub type Vec3 = [f64; 3];

/// A deliberate defect, for proving that the gate catches it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Defect {
    /// None: the correct model.
    None,
    /// D scaled by 1.01 (normalization off by 1 %).
    NormalizationOnePercent,
    /// Λ 1 % too large above θ = 1.3 only (kept consistent with Λ(−w) = −1 − Λ(w)).
    LambdaWrongAboveOnePointThree,
    /// The sampler draws tan²θ ∝ (u/(1−u))^1.03 (GGX) or (−ln(1−u))^1.03 (Beckmann).
    SamplerExponent,
    /// The sampler draws φ over half the circle.
    HalfCirclePhi,
    /// pdf_wm 0.5 % larger than the sampler's density.
    PdfMismatch,
    /// A normal below the horizon for u₁ = 0 only.
    BelowHorizonAtUZero,
    /// D is NaN at exactly θ = 0.
    NanAtNormalIncidence,
    /// The height-correlated G2 replaced by the uncorrelated product.
    G2Uncorrelated,
    /// α_x and α_y swapped in D only.
    AxesSwappedInD,
}

/// Which NDF.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Family {
    /// GGX / Trowbridge–Reitz.
    Ggx,
    /// Beckmann.
    Beckmann,
}

/// A renderer's microfacet distribution.
#[derive(Debug, Clone, Copy)]
pub struct Microfacet {
    /// The NDF.
    pub family: Family,
    /// Roughness along x.
    pub alpha_x: f64,
    /// Roughness along y.
    pub alpha_y: f64,
    /// The deliberate defect (Defect::None in a real renderer).
    pub defect: Defect,
}

impl Microfacet {
    /// An isotropic distribution.
    pub fn new(family: Family, alpha: f64) -> Self {
        Self::anisotropic(family, alpha, alpha)
    }

    /// An anisotropic distribution.
    pub fn anisotropic(family: Family, alpha_x: f64, alpha_y: f64) -> Self {
        Self {
            family,
            alpha_x,
            alpha_y,
            defect: Defect::None,
        }
    }

    /// The same distribution with a defect.
    pub fn with(mut self, defect: Defect) -> Self {
        self.defect = defect;
        self
    }

    /// D(m): GGX 1/(π αx αy cos⁴θ (1 + s²)²), Beckmann exp(−s²)/(π αx αy cos⁴θ), with
    /// s² = tan²θ (cos²φ/αx² + sin²φ/αy²).
    pub fn d(&self, m: Vec3) -> f64 {
        if self.defect == Defect::NanAtNormalIncidence && m[0] == 0.0 && m[1] == 0.0 {
            return f64::NAN;
        }
        if m[2] <= 0.0 {
            return 0.0;
        }
        let (ax, ay) = if self.defect == Defect::AxesSwappedInD {
            (self.alpha_y, self.alpha_x)
        } else {
            (self.alpha_x, self.alpha_y)
        };
        let z2 = m[2] * m[2];
        let s2 = ((m[0] / ax).powi(2) + (m[1] / ay).powi(2)) / z2;
        let scale = if self.defect == Defect::NormalizationOnePercent {
            1.01
        } else {
            1.0
        };
        scale
            * match self.family {
                Family::Ggx => 1.0 / (PI * ax * ay * z2 * z2 * (1.0 + s2).powi(2)),
                Family::Beckmann => (-s2).exp() / (PI * ax * ay * z2 * z2),
            }
    }

    /// Smith Λ(w) (Heitz 2014, eq 72 and 86), with Λ(−w) = −1 − Λ(w) below the horizon.
    pub fn lambda(&self, w: Vec3) -> f64 {
        if w[2] < 0.0 {
            return -1.0 - self.lambda([-w[0], -w[1], -w[2]]);
        }
        let t2 = (self.alpha_x * w[0]).powi(2) + (self.alpha_y * w[1]).powi(2);
        if t2 == 0.0 {
            return 0.0;
        }
        if w[2] == 0.0 {
            return f64::INFINITY; // exactly grazing: every facet is masked
        }
        let l = match self.family {
            // (√(1 + a⁻²) − 1)/2 with a⁻² = t2/z², written without cancellation.
            Family::Ggx => {
                let inv_a2 = t2 / (w[2] * w[2]);
                inv_a2 / (2.0 * (1.0 + (1.0 + inv_a2).sqrt()))
            }
            Family::Beckmann => {
                let a = w[2] / t2.sqrt();
                if a > 26.0 {
                    0.0 // e^{−a²} < 1e-293: Λ underflows
                } else {
                    ((-a * a).exp() / (a * PI.sqrt()) - libm::erfc(a)) / 2.0
                }
            }
        };
        let theta = (w[0].hypot(w[1])).atan2(w[2]);
        if self.defect == Defect::LambdaWrongAboveOnePointThree && theta > 1.3 {
            l * 1.01
        } else {
            l
        }
    }

    /// G2 in the form the renderer uses: height-correlated (Heitz 2014 eq 99).
    pub fn g2_height_correlated(&self, wo: Vec3, wi: Vec3) -> f64 {
        if self.defect == Defect::G2Uncorrelated {
            return 1.0 / ((1.0 + self.lambda(wo)) * (1.0 + self.lambda(wi)));
        }
        1.0 / (1.0 + self.lambda(wo) + self.lambda(wi))
    }

    /// Samples a normal with density D(m)(m·n): φ = 2πu₁ and the standardized slope radius
    /// ρ² = u₂/(1 − u₂) (GGX) or −ln(1 − u₂) (Beckmann); slope (αx ρ cos φ, αy ρ sin φ).
    pub fn sample_wm(&self, u: [f64; 2]) -> Vec3 {
        let phi = if self.defect == Defect::HalfCirclePhi {
            PI * u[0]
        } else {
            2.0 * PI * u[0]
        };
        let mut rho2 = match self.family {
            Family::Ggx => u[1] / (1.0 - u[1]),
            Family::Beckmann => -(-u[1]).ln_1p(),
        };
        if self.defect == Defect::SamplerExponent {
            rho2 = rho2.powf(1.03);
        }
        let rho = rho2.sqrt();
        let (px, py) = (
            self.alpha_x * rho * phi.cos(),
            self.alpha_y * rho * phi.sin(),
        );
        let norm = (1.0 + px * px + py * py).sqrt();
        let z = if self.defect == Defect::BelowHorizonAtUZero && u[0] == 0.0 {
            -1.0
        } else {
            1.0
        };
        [-px / norm, -py / norm, z / norm]
    }

    /// The density of `sample_wm`: D(m)(m·n).
    pub fn pdf_wm(&self, m: Vec3) -> f64 {
        let scale = if self.defect == Defect::PdfMismatch {
            1.005
        } else {
            1.0
        };
        scale * self.d(m) * m[2].max(0.0)
    }
}
