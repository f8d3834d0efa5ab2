//! Where a microfacet BSDF's lobes are centred at one incidence, from the laws of reflection
//! and refraction alone (no model): the mirror direction and, for a relative index η, the
//! refracted one (Snell's law; none beyond the critical angle) about the macro-normal; the
//! directions scattered about horizontal microfacets; and beyond the critical angle, the
//! directions refracted through the least tilted microfacets that still transmit.
//!
//! The whole-sphere integrals of a BSDF's pdf and eval start their lobe measurement there
//! ([`crate::oracle::lobe::Options::start_points`]): a lobe narrower than the survey's spacing — a
//! conductor at α 1e-4 off the surveyed azimuths, a reflection or transmission lobe at α 1e-7,
//! or the transmission lobe of η → 1, whose width in wo is about α·|η − 1| — is otherwise found
//! only where a survey point happens to fall on it, and its cells integrate to 0 with a bound
//! of 0 (measured before: a Beckmann α 1e-4 conductor at (θ 0.9, φ 0.3) gave mass 0 ± 1.6e-22;
//! the GGX α 0.3 dielectric of η 1.0001 at θ 0.9 gave 0.9444 ± 1e-4 for ≥ 0.9987). The
//! centres only guide the search; the masses are the pdf's own.

use mfh_reference::geometry::Vec3;
use std::f64::consts::FRAC_PI_2;

/// The mirror direction of `wi` about +z, and for a transmitting BSDF of relative index
/// `eta` (η_inside/η_outside, inside below the surface) the refracted direction, where it
/// exists (those two first); then the directions reflected and refracted about horizontal
/// microfacet normals at [`RING_AZIMUTHS`] azimuths; then, beyond the critical angle, those
/// of [`beyond_critical`]. Non-finite or degenerate input gives none.
pub fn lobe_centres(wi: Vec3, eta: Option<f64>) -> Vec<Vec3> {
    if !(wi.iter().all(|c| c.is_finite()) && wi[2] != 0.0) {
        return Vec::new();
    }
    // η_i/η_o from wi's side to the other.
    let ratio =
        eta.filter(|e| e.is_finite() && *e > 0.0)
            .map(|eta| if wi[2] > 0.0 { 1.0 / eta } else { eta });
    let mut out = Vec::with_capacity(2 + 2 * RING_AZIMUTHS);
    // About the macro-normal: the mirror and Snell directions.
    out.extend(scatter(wi, [0.0, 0.0, 1.0], ratio));
    // About horizontal microfacets, where a huge α puts them.
    for k in 0..RING_AZIMUTHS {
        let phi = std::f64::consts::TAU * k as f64 / RING_AZIMUTHS as f64;
        out.extend(scatter(wi, [phi.cos(), phi.sin(), 0.0], ratio));
    }
    if let Some(r) = ratio {
        out.extend(beyond_critical(wi, r));
    }
    out
}

/// The exit cosines (of the refracted direction against the microfacet normal) of the
/// directions [`beyond_critical`] gives at each tilt azimuth: a transmission lobe beyond the
/// critical angle leaves its microfacets near grazing, and its density in wo vanishes at
/// grazing exit (the refraction Jacobian's wo·h), so its mode lies a little above it.
pub const CRITICAL_EXITS: [f64; 3] = [1e-3, 1e-2, 0.1];

/// Beyond the critical angle (wi on the denser side, `ratio` = η_i/η_o > 1, |cos θi| below
/// cos θc = √(1 − 1/ratio²)) no direction refracts about the macro-normal, yet microfacets
/// tilted past the critical cone about wi transmit: the least tilted ones, the most probable,
/// refract near grazing to them. For [`RING_AZIMUTHS`] tilt azimuths ψ, the normal tilted
/// towards ψ by the least angle at which wi meets it at the exit cosine e (of
/// [`CRITICAL_EXITS`]) after refraction, and the direction refracted through it. An
/// anisotropic NDF narrow along the plane of incidence and wide across it (GGX α 1e-6 × 1e-4
/// at η 1.0001, cos θi 0.0094 from inside) transmits 1.3e-5 of its samples there, in a lobe
/// about 1e-4 wide that no survey point meets (its mass was 1e-13 before these centres).
/// None within the critical angle or for a ratio ≤ 1.
fn beyond_critical(wi: Vec3, ratio: f64) -> Vec<Vec3> {
    let mut out = Vec::new();
    if !(ratio > 1.0) {
        return out;
    }
    // In the frame where wi is above the surface.
    let below = wi[2] < 0.0;
    let w = [wi[0], wi[1], wi[2].abs()];
    let critical = (1.0 - 1.0 / (ratio * ratio)).sqrt();
    if !(w[2] < critical) {
        return out;
    }
    for k in 0..RING_AZIMUTHS {
        let psi = std::f64::consts::TAU * k as f64 / RING_AZIMUTHS as f64;
        let (sin_psi, cos_psi) = psi.sin_cos();
        // w·h(t) = a sin t + b cos t = reach · cos(t − t0) for h tilted by t towards ψ.
        let (a, b) = (w[0] * cos_psi + w[1] * sin_psi, w[2]);
        if !(a > 0.0) {
            continue;
        }
        let reach = a.hypot(b);
        let t0 = a.atan2(b);
        // The direction refracted through the normal tilted by t towards ψ, if any.
        let refracted = |t: f64| {
            let (sin_t, cos_t) = f64::sin_cos(t);
            let h = [sin_t * cos_psi, sin_t * sin_psi, cos_t];
            scatter(w, h, Some(ratio)).get(1).copied()
        };
        if !(reach > critical) {
            continue;
        }
        for e in CRITICAL_EXITS {
            // The local cosine c at which the refracted direction leaves at cosine e:
            // 1 − ratio²(1 − c²) = e².
            let c = (1.0 - (1.0 - e * e) / (ratio * ratio)).sqrt();
            if !(c < reach) {
                continue;
            }
            let t = t0 - (c / reach).acos();
            if !(t > 0.0 && t < FRAC_PI_2) {
                continue;
            }
            if let Some(t) = refracted(t).filter(|t| t[2] < 0.0) {
                out.push(t);
            }
        }
        // Where refraction near grazing to the microfacet stays on wi's side (η 1.5 at cos θi
        // 0.53: the least tilted transmitting normals refract upwards), the lobe begins where
        // the refracted direction crosses the horizon: the least tilt at which it lies
        // [`CROSSING_DEPTHS`] below it, found on a grid of tilts and refined by bisection.
        let t_min = t0 - (critical / reach).acos();
        let depth = |t: f64| refracted(t).map_or(f64::NAN, |d| -d[2]);
        let steps = 128;
        let at = |i: usize| t_min + (FRAC_PI_2 - t_min) * i as f64 / steps as f64;
        for &d in &CROSSING_DEPTHS {
            let Some(i) = (1..steps).find(|&i| depth(at(i)) >= d) else {
                continue;
            };
            let (mut lo, mut hi) = (at(i - 1), at(i));
            for _ in 0..40 {
                let mid = 0.5 * (lo + hi);
                if depth(mid) >= d {
                    hi = mid;
                } else {
                    lo = mid;
                }
            }
            out.extend(refracted(hi).filter(|t| t[2] < 0.0));
        }
    }
    out.into_iter()
        .map(|t| if below { [t[0], t[1], -t[2]] } else { t })
        .collect()
}

/// The depths below the horizon (−z on the far side, in the frame of wi above) of the
/// directions [`beyond_critical`] places where refraction first crosses it.
pub const CROSSING_DEPTHS: [f64; 3] = [1e-3, 1e-2, 0.1];

/// The azimuths of the horizontal microfacet normals whose scattered directions are centres:
/// at α 1e4 the microfacets lie within 1e-4 of the horizon, and the directions refracted
/// through them form a ring (cos θo = cos θi·η_i/η_o, about 1e-4 wide) that a survey along
/// azimuths from the pole crosses between its points.
pub const RING_AZIMUTHS: usize = 16;

/// The directions `wi` reflects into and (with the index ratio η_i/η_o) refracts into about
/// the unit normal `h` (turned towards wi; none refracted beyond the critical angle).
fn scatter(wi: Vec3, h: Vec3, ratio: Option<f64>) -> Vec<Vec3> {
    let mut c = wi[0] * h[0] + wi[1] * h[1] + wi[2] * h[2];
    let h = if c < 0.0 {
        c = -c;
        [-h[0], -h[1], -h[2]]
    } else {
        h
    };
    let mut out = vec![[
        2.0 * c * h[0] - wi[0],
        2.0 * c * h[1] - wi[1],
        2.0 * c * h[2] - wi[2],
    ]];
    if let Some(r) = ratio {
        let k = 1.0 - r * r * (1.0 - c * c);
        if k > 0.0 {
            let b = r * c - k.sqrt();
            out.push([
                -r * wi[0] + b * h[0],
                -r * wi[1] + b * h[1],
                -r * wi[2] + b * h[2],
            ]);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_centres_obey_reflection_and_snell() {
        let (s, c) = 0.9f64.sin_cos();
        let wi = [s * 0.3f64.cos(), s * 0.3f64.sin(), c];
        let centres = lobe_centres(wi, Some(1.5));
        assert!(centres.len() > 2 && centres[1][2] < 0.0);
        let m = centres[0];
        assert!((m[0] + wi[0]).abs() < 1e-16 && m[2] == wi[2]);
        let t = centres[1];
        // Snell: sin θt = sin θi / η, on the other side, the azimuth opposite.
        let sin_t = t[0].hypot(t[1]);
        assert!((sin_t - s / 1.5).abs() < 1e-15, "{t:?}");
        assert!(t[2] < 0.0 && (t[0] * wi[1] - t[1] * wi[0]).abs() < 1e-15);
        assert!((t.iter().map(|x| x * x).sum::<f64>() - 1.0).abs() < 1e-15);
        // From inside beyond the critical angle: the mirror direction alone.
        let (s, c) = 1.2f64.sin_cos();
        assert_eq!(scatter([s, 0.0, -c], [0.0, 0.0, 1.0], Some(1.5)).len(), 1);
        // From inside below it: refracted upwards.
        let (s, c) = 0.3f64.sin_cos();
        let t = lobe_centres([s, 0.0, -c], Some(1.5))[1];
        assert!(t[2] > 0.0 && (t[0] + 1.5 * s).abs() < 1e-15);
        assert!(lobe_centres([1.0, 0.0, 0.0], None).is_empty());
        // Within the critical angle, or from the thinner side: no centres beyond it.
        let (s, c) = 0.3f64.sin_cos();
        assert!(beyond_critical([s, 0.0, -c], 1.5).is_empty());
        assert!(beyond_critical([s, 0.0, 0.01], 1.0 / 1.5).is_empty());
        // The ring of horizontal microfacets: cos θo = cos θi/η below.
        let (s, c) = 0.001f64.sin_cos();
        for t in &lobe_centres([s, 0.0, c], Some(1.5))[2..] {
            let norm: f64 = t.iter().map(|x| x * x).sum();
            assert!((norm - 1.0).abs() < 1e-14, "{t:?}");
            if t[2] < 0.0 && t[2] != -c {
                assert!((t[2] + c / 1.5).abs() < 1e-15, "{t:?}");
            }
        }
    }

    /// Beyond the critical angle from inside (η 1.0001 at cos θi 0.0094, the audit's incidence
    /// there, and η 1.5 at cos θi 0.53, the glass's): each centre is refracted upwards through
    /// a microfacet normal h — the generalized half vector ∝ η_i·wi + η_o·wo (Walter et al.
    /// 2007 eq 16) — with wi meeting h at the angle Snell's law gives for it, and either leaves
    /// h at one of the exit cosines or lies at one of the depths beyond the horizon.
    #[test]
    fn the_centres_beyond_the_critical_angle_leave_their_microfacets_near_grazing() {
        let dot = |a: Vec3, b: Vec3| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        let near = |x: f64, set: &[f64]| set.iter().any(|e| (x - e).abs() < 1e-9 * e.max(1e-3));
        for (eta, c, exits) in [
            (1.0001f64, 0.009427557946721532f64, true),
            (1.5, 0.532, false),
        ] {
            let s = (1.0 - c * c).sqrt();
            let wi = [s * 0.3f64.cos(), s * 0.3f64.sin(), -c];
            let centres = beyond_critical(wi, eta);
            assert!(centres.len() >= 4, "{eta}: {}", centres.len());
            assert!(lobe_centres(wi, Some(eta)).ends_with(&centres));
            let mut exited = 0;
            for t in &centres {
                assert!(t[2] > 0.0 && (dot(*t, *t) - 1.0).abs() < 1e-14, "{t:?}");
                let v = [eta * wi[0] + t[0], eta * wi[1] + t[1], eta * wi[2] + t[2]];
                let norm = dot(v, v).sqrt();
                let h = v.map(|x| x / norm);
                let exit = dot(*t, h).abs();
                if near(exit, &CRITICAL_EXITS) {
                    exited += 1;
                } else {
                    assert!(near(t[2], &CROSSING_DEPTHS), "{eta}: exit {exit} {t:?}");
                }
                // Snell: η_i sin θ_i = η_o sin θ_t about h.
                let ci = dot(wi, h).abs();
                let (si, st) = ((1.0 - ci * ci).sqrt(), (1.0 - exit * exit).sqrt());
                assert!((eta * si - st).abs() < 1e-12, "{} vs {st}", eta * si);
            }
            // Near η 1 the near-grazing exits cross the surface; at η 1.5 they stay above.
            assert_eq!(exited > 0, exits, "{eta}: {exited}");
        }
    }
}
