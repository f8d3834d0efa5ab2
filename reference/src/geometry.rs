//! Directions in the local shading frame (macro-normal n = +z) and the conversions between
//! unit vectors, spherical angles and slopes.

/// A direction as `[x, y, z]` in the local shading frame; unit length unless said otherwise.
pub type Vec3 = [f64; 3];

/// The unit vector at polar angle `theta` from +z and azimuth `phi` from +x (radians).
pub fn from_spherical(theta: f64, phi: f64) -> Vec3 {
    let (st, ct) = theta.sin_cos();
    let (sp, cp) = phi.sin_cos();
    // cos(π/2) is 6e-17 in floating point: snap the horizon so that θ = π/2 is exactly grazing.
    let ct = if (theta - std::f64::consts::FRAC_PI_2).abs() < 1e-15 {
        0.0
    } else {
        ct
    };
    [st * cp, st * sp, ct]
}

/// Dot product.
#[inline]
pub fn dot(a: Vec3, b: Vec3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Euclidean length.
#[inline]
pub fn length(a: Vec3) -> f64 {
    dot(a, a).sqrt()
}

/// Cross product a × b.
#[inline]
pub fn cross(a: Vec3, b: Vec3) -> Vec3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// a / |a| (a must be non-zero), each component divided by the length.
#[inline]
pub fn normalize(a: Vec3) -> Vec3 {
    let n = length(a);
    [a[0] / n, a[1] / n, a[2] / n]
}

/// The microfacet normal of slope `(p, q)`: m = (p, q, 1)/√(1 + p² + q²), so that
/// tan θ_m cos φ_m = p and tan θ_m sin φ_m = q. Infinite slopes give the horizon direction.
#[inline]
pub fn normal_from_slopes(p: f64, q: f64) -> Vec3 {
    if p.is_finite() && q.is_finite() {
        let inv = 1.0 / (1.0 + p * p + q * q).sqrt();
        [p * inv, q * inv, inv]
    } else {
        // Slope radius is infinite: the normal lies on the horizon, in the direction of (p, q).
        let px = if p.is_infinite() { p.signum() } else { 0.0 };
        let qy = if q.is_infinite() { q.signum() } else { 0.0 };
        let l = (px * px + qy * qy).sqrt();
        [px / l, qy / l, 0.0]
    }
}

/// (sin 2πu, cos 2πu) for u ∈ [0, 1] (also correct for |u| < 2⁵⁰, less fast below 0; NaN
/// gives NaN).
///
/// The argument is reduced exactly in turns before 2π multiplies it: u = k/4 + r with
/// k = round(4u) and |r| ≤ 1/8 (u − k/4 is exact by Sterbenz's lemma), so that only
/// 2π r ∈ [−π/4, π/4] reaches `libm::sincos` (musl's kernel polynomials, no further reduction),
/// and the quadrant k permutes the pair. Written by hand because std has no sin/cos of
/// turns: `(2π u).sin_cos()` costs about twice as much (glibc's general reduction) and rounds
/// 2π u first, an absolute error up to 4e-16 in the angle that makes sin 2πu relatively
/// inaccurate near u = ½ (e.g. sin 2π·½ = −2.4e-16 instead of 0).
#[inline]
pub fn sin_cos_turns(u: f64) -> (f64, f64) {
    // round(4u) by truncation (u ≥ 0; `f64::round` is a libm call without SSE4.1).
    let k = (4.0 * u + 0.5) as i64;
    let r = u - 0.25 * k as f64;
    let (s, c) = libm::sincos(std::f64::consts::TAU * r);
    match k & 3 {
        0 => (s, c),
        1 => (c, -s),
        2 => (-s, -c),
        _ => (-c, s),
    }
}

/// Whether `w` is a unit vector to within `tol` (and finite).
pub fn is_unit(w: Vec3, tol: f64) -> bool {
    w.iter().all(|c| c.is_finite()) && (length(w) - 1.0).abs() <= tol
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spherical_round_trip_and_horizon() {
        let w = from_spherical(0.3, 1.1);
        assert!((length(w) - 1.0).abs() < 1e-15);
        assert!((w[2] - 0.3f64.cos()).abs() < 1e-16);
        assert_eq!(from_spherical(std::f64::consts::FRAC_PI_2, 0.0)[2], 0.0);
    }

    #[test]
    fn sin_cos_of_turns() {
        for i in 0..=4000 {
            let u = i as f64 / 4000.0;
            let (s, c) = sin_cos_turns(u);
            let (ws, wc) = (std::f64::consts::TAU * u).sin_cos();
            // The old route's angle carries ≤ 4.4e-16 absolute error.
            assert!((s - ws).abs() < 1e-15 && (c - wc).abs() < 1e-15, "u = {u}");
        }
        // Exact at the quadrant points.
        assert_eq!(sin_cos_turns(0.0), (0.0, 1.0));
        assert_eq!(sin_cos_turns(0.25), (1.0, -0.0));
        assert_eq!(sin_cos_turns(0.5), (-0.0, -1.0));
        assert_eq!(sin_cos_turns(0.75), (-1.0, 0.0));
        assert_eq!(sin_cos_turns(1.0), (0.0, 1.0));
        let (s, c) = sin_cos_turns(1.0 / 12.0);
        assert!((s - 0.5).abs() <= f64::EPSILON / 4.0);
        assert!((c - 0.75f64.sqrt()).abs() <= f64::EPSILON / 2.0);
        assert!(sin_cos_turns(f64::NAN).0.is_nan());
        for &u in &[-0.3, -1.7, 12.4] {
            let (s, c) = sin_cos_turns(u);
            let (ws, wc) = (std::f64::consts::TAU * u).sin_cos();
            assert!((s - ws).abs() < 1e-14 && (c - wc).abs() < 1e-14, "u = {u}");
        }
    }

    #[test]
    fn slopes_to_normal() {
        let m = normal_from_slopes(0.5, -0.25);
        assert!((m[0] / m[2] - 0.5).abs() < 1e-15);
        assert!((m[1] / m[2] + 0.25).abs() < 1e-15);
        assert!((length(m) - 1.0).abs() < 1e-15);
        let h = normal_from_slopes(f64::INFINITY, 0.0);
        assert_eq!(h, [1.0, 0.0, 0.0]);
    }
}
