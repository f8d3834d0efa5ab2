//! A GGX computed in f32 arithmetic the way a renderer writes it (D, Λ, the normal and
//! visible-normal samplers and their pdfs), handed over as f64: the float32 model of
//! `float32.rs` and the NDF under the float32 BSDFs of `float32_bsdf.rs`. Shared test code.
#![allow(dead_code)] // each test binary uses its own part

use mfh_reference::{Ndf, NormalSampler, Smith, Vec3, VisibleNormalSampler};
use std::f32::consts::PI;

/// Which defect the float32 GGX carries.
#[derive(Clone, Copy, PartialEq)]
pub enum Defect {
    None,
    /// The normal sampler's exponent off by 0.1 %: tan θ = α √(u/(1−u))^1.001.
    SamplerExponent,
    /// The visible-normal pdf without its G1 factor.
    VisiblePdfWithoutG1,
}

pub struct Ggx32 {
    pub alpha: f32,
    pub defect: Defect,
}

pub fn v32(m: Vec3) -> [f32; 3] {
    [m[0] as f32, m[1] as f32, m[2] as f32]
}

pub fn v64(m: [f32; 3]) -> Vec3 {
    [f64::from(m[0]), f64::from(m[1]), f64::from(m[2])]
}

pub fn normalize(v: [f32; 3]) -> [f32; 3] {
    let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    [v[0] / l, v[1] / l, v[2] / l]
}

impl Ggx32 {
    pub fn new(alpha: f32) -> Self {
        Self {
            alpha,
            defect: Defect::None,
        }
    }

    /// D(m) as pbrt-v4 writes it: tan²θ, cos⁴θ, e = tan²θ/α².
    pub fn d32(&self, m: [f32; 3]) -> f32 {
        if m[2] <= 0.0 {
            return 0.0;
        }
        let cos2 = m[2] * m[2];
        let sin2 = (m[0] * m[0] + m[1] * m[1]).max(0.0);
        let tan2 = sin2 / cos2;
        if !tan2.is_finite() {
            return 0.0;
        }
        let cos4 = cos2 * cos2;
        // pbrt-v4's guard: cos⁴θ underflows near grazing.
        if cos4 < 1e-16 {
            return 0.0;
        }
        let e = tan2 / (self.alpha * self.alpha);
        1.0 / (PI * self.alpha * self.alpha * cos4 * (1.0 + e) * (1.0 + e))
    }

    pub fn lambda32(&self, w: [f32; 3]) -> f32 {
        let tan2 = (w[0] * w[0] + w[1] * w[1]) / (w[2] * w[2]);
        if !tan2.is_finite() {
            // Grazing: Λ = ∞, G1 = 0.
            return f32::INFINITY;
        }
        let l = ((1.0 + self.alpha * self.alpha * tan2).sqrt() - 1.0) / 2.0;
        if w[2] < 0.0 {
            -1.0 - l
        } else {
            l
        }
    }

    /// Heitz 2018's visible-normal sampler in f32, for wi in the upper hemisphere.
    pub fn visible32(&self, wi: [f32; 3], u0: f32, u1: f32) -> [f32; 3] {
        let a = self.alpha;
        let vh = normalize([a * wi[0], a * wi[1], wi[2]]);
        let len2 = vh[0] * vh[0] + vh[1] * vh[1];
        let t1 = if len2 > 0.0 {
            let inv = 1.0 / len2.sqrt();
            [-vh[1] * inv, vh[0] * inv, 0.0]
        } else {
            [1.0, 0.0, 0.0]
        };
        let t2 = [
            vh[1] * t1[2] - vh[2] * t1[1],
            vh[2] * t1[0] - vh[0] * t1[2],
            vh[0] * t1[1] - vh[1] * t1[0],
        ];
        let r = u0.sqrt();
        let phi = 2.0 * PI * u1;
        let p1 = r * phi.cos();
        let s = 0.5 * (1.0 + vh[2]);
        let p2 = (1.0 - s) * (1.0 - p1 * p1).max(0.0).sqrt() + s * r * phi.sin();
        let p3 = (1.0 - p1 * p1 - p2 * p2).max(0.0).sqrt();
        let nh = [
            p1 * t1[0] + p2 * t2[0] + p3 * vh[0],
            p1 * t1[1] + p2 * t2[1] + p3 * vh[1],
            p1 * t1[2] + p2 * t2[2] + p3 * vh[2],
        ];
        normalize([a * nh[0], a * nh[1], nh[2].max(1e-6)])
    }

    pub fn g1_32(&self, w: [f32; 3]) -> f32 {
        1.0 / (1.0 + self.lambda32(w))
    }
}

impl Ndf for Ggx32 {
    fn d(&self, m: Vec3) -> f64 {
        f64::from(self.d32(v32(m)))
    }
    fn as_smith(&self) -> Option<&dyn Smith> {
        Some(self)
    }
    fn as_sampler(&self) -> Option<&dyn NormalSampler> {
        Some(self)
    }
    fn as_visible_sampler(&self) -> Option<&dyn VisibleNormalSampler> {
        Some(self)
    }
}

impl Smith for Ggx32 {
    fn lambda(&self, w: Vec3) -> f64 {
        f64::from(self.lambda32(v32(w)))
    }
}

impl NormalSampler for Ggx32 {
    fn sample_wm(&self, u: [f64; 2]) -> Vec3 {
        let (u0, u1) = (u[0] as f32, u[1] as f32);
        let mut ratio = u0 / (1.0 - u0);
        if self.defect == Defect::SamplerExponent {
            ratio = ratio.powf(1.001);
        }
        let tan2 = self.alpha * self.alpha * ratio;
        let cos = 1.0 / (1.0 + tan2).sqrt();
        let sin = (1.0 - cos * cos).max(0.0).sqrt();
        let phi = 2.0 * PI * u1;
        v64([sin * phi.cos(), sin * phi.sin(), cos])
    }
    fn pdf_wm(&self, m: Vec3) -> f64 {
        let m = v32(m);
        f64::from(self.d32(m) * m[2].max(0.0))
    }
}

impl VisibleNormalSampler for Ggx32 {
    /// Heitz 2018, in f32.
    fn sample_wm_visible(&self, wi: Vec3, u: [f64; 2]) -> Vec3 {
        v64(self.visible32(v32(wi), u[0] as f32, u[1] as f32))
    }
    fn pdf_wm_visible(&self, wi: Vec3, m: Vec3) -> f64 {
        let (wi, m) = (v32(wi), v32(m));
        let dot = (wi[0] * m[0] + wi[1] * m[1] + wi[2] * m[2]).max(0.0);
        let g1 = if self.defect == Defect::VisiblePdfWithoutG1 {
            1.0
        } else {
            self.g1_32(wi)
        };
        f64::from(g1 * dot * self.d32(m) / wi[2].abs())
    }
}
