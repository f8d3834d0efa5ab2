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
    fn slopes_to_normal() {
        let m = normal_from_slopes(0.5, -0.25);
        assert!((m[0] / m[2] - 0.5).abs() < 1e-15);
        assert!((m[1] / m[2] + 0.25).abs() < 1e-15);
        assert!((length(m) - 1.0).abs() < 1e-15);
        let h = normal_from_slopes(f64::INFINITY, 0.0);
        assert_eq!(h, [1.0, 0.0, 0.0]);
    }
}
