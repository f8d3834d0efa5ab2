//! The incidence-dependent part of Heitz's GGX visible-normal sampler (Heitz 2018, "Sampling
//! the GGX Distribution of Visible Normals", JCGT 7(4), Listing 1; see `Ggx`'s
//! `sample_wm_visible`), shared by the scalar sampler (`ndf::ggx`) and the batch one
//! (`ndf::ggx_visible_batch`), so neither of the two needs the other's file.

use crate::geometry::Vec3;
use crate::model::visible_domain;

/// The part of Heitz's visible-normal sampler that depends only on the incidence (the
/// stretched view V_h, its tangent frame T1, T2 and the warp s; the listing above), computed
/// once per incidence by the scalar and the batch sampler alike.
#[derive(Debug, Clone, Copy)]
pub(crate) struct VisibleFrame {
    alpha_x: f64,
    alpha_y: f64,
    vh: Vec3,
    t1: Vec3,
    t2: Vec3,
    s: f64,
}

impl VisibleFrame {
    /// The frame of incidence `wi`, or `None` outside the visible domain (non-unit, or at or
    /// below the horizon).
    pub(crate) fn new(alpha_x: f64, alpha_y: f64, wi: Vec3) -> Option<Self> {
        if !visible_domain(wi) {
            return None;
        }
        let vh = normalize([alpha_x * wi[0], alpha_y * wi[1], wi[2]]);
        let lensq = vh[0] * vh[0] + vh[1] * vh[1];
        let t1 = if lensq > 0.0 {
            let inv = 1.0 / lensq.sqrt();
            [-vh[1] * inv, vh[0] * inv, 0.0]
        } else {
            [1.0, 0.0, 0.0]
        };
        let t2 = [
            vh[1] * t1[2] - vh[2] * t1[1],
            vh[2] * t1[0] - vh[0] * t1[2],
            vh[0] * t1[1] - vh[1] * t1[0],
        ];
        Some(Self {
            alpha_x,
            alpha_y,
            vh,
            t1,
            t2,
            s: 0.5 * (1.0 + vh[2]),
        })
    }

    /// The sampled normal from r = √u₀ and (sin, cos) of 2πu₁: the per-sample part of the
    /// listing, without a branch (`max` and `sqrt` only), so that a loop over it vectorizes.
    #[inline(always)]
    pub(crate) fn normal(&self, r: f64, sp: f64, cp: f64) -> Vec3 {
        normalize(self.unnormalized(r, sp, cp))
    }

    /// [`VisibleFrame::normal`] before its normalization: (αx N_h,x, αy N_h,y, max(0, N_h,z)),
    /// which the batch sampler (`ndf::ggx_visible_batch`) normalizes its own way.
    #[inline(always)]
    pub(crate) fn unnormalized(&self, r: f64, sp: f64, cp: f64) -> Vec3 {
        let (vh, t1v, t2v, s) = (self.vh, self.t1, self.t2, self.s);
        let t1 = r * cp;
        let t2 = (1.0 - s) * (1.0 - t1 * t1).max(0.0).sqrt() + s * r * sp;
        let lift = (1.0 - t1 * t1 - t2 * t2).max(0.0).sqrt();
        let nh = [
            t1 * t1v[0] + t2 * t2v[0] + lift * vh[0],
            t1 * t1v[1] + t2 * t2v[1] + lift * vh[1],
            t1 * t1v[2] + t2 * t2v[2] + lift * vh[2],
        ];
        [self.alpha_x * nh[0], self.alpha_y * nh[1], nh[2].max(0.0)]
    }
}

/// `v / |v|`.
#[inline(always)]
fn normalize(v: Vec3) -> Vec3 {
    let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    [v[0] / l, v[1] / l, v[2] / l]
}
