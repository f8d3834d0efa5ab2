//! Where a microfacet BSDF's lobes are centred at one incidence, from the laws of reflection
//! and refraction about the macro-normal alone (no model): the mirror direction and, for a
//! relative index η, the refracted one (Snell's law; none beyond the critical angle).
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

/// The mirror direction of `wi` about +z, and for a transmitting BSDF of relative index
/// `eta` (η_inside/η_outside, inside below the surface) the refracted direction, where it
/// exists (those two first); then the directions reflected and refracted about horizontal
/// microfacet normals at [`RING_AZIMUTHS`] azimuths. Non-finite or degenerate input gives
/// none.
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
    out
}

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
}
