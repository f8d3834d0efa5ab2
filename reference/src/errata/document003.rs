//! Document 003 (spherical Gaussians, Khungurn): derivation steps and building blocks that no
//! route evaluates, as printed and corrected.

/// Cook–Torrance's Fresnel factor ½ ((g − c)/(g + c))² (1 + ((c(g + c) − 1)/(c(g − c) + 1))²)
/// for a given g (c = cos θ_d), the form of document 003 §2.1.
fn fresnel_with_g(c: f64, g: f64) -> f64 {
    let a = (g - c) / (g + c);
    let b = (c * (g + c) - 1.0) / (c * (g - c) + 1.0);
    0.5 * a * a * (1.0 + b * b)
}

/// Document 003 §2.1's Fresnel factor as printed, with g = √(η² − c² − 1) (ERRATA 003-E1: the sign
/// of c²; NaN where η² < c² + 1, e.g. at normal incidence for η < √2).
pub fn fresnel_printed(eta: f64, c: f64) -> f64 {
    fresnel_with_g(c, (eta * eta - c * c - 1.0).sqrt())
}

/// Document 003 §2.1's Fresnel factor corrected: g = √(η² + c² − 1) (Cook and Torrance 1982), the
/// mean of the s and p reflectances of a dielectric of relative index η.
pub fn fresnel_corrected(eta: f64, c: f64) -> f64 {
    fresnel_with_g(c, (eta * eta + c * c - 1.0).sqrt())
}

/// Document 003 §4.1, the third line of the derivation of ω·ξ − 1 for ω = (θ, φ), ξ = (θ', φ') on
/// the fibre parametrization, as printed: sin θ sin θ' + cos θ cos θ' (cos φ cos φ' + sin φ sin
/// φ'), which is ω·ξ (ERRATA 003-E8: the − 1 dropped).
pub fn eq_sec41_line3_printed(theta: f64, phi: f64, theta1: f64, phi1: f64) -> f64 {
    theta.sin() * theta1.sin()
        + theta.cos() * theta1.cos() * (phi.cos() * phi1.cos() + phi.sin() * phi1.sin())
}

/// Document 003 §4.1, the third line corrected: the printed line − 1 = ω·ξ − 1.
pub fn eq_sec41_line3_corrected(theta: f64, phi: f64, theta1: f64, phi1: f64) -> f64 {
    eq_sec41_line3_printed(theta, phi, theta1, phi1) - 1.0
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The corrected factor is the mean of the s and p reflectances (Snell and Fresnel's
    /// equations, written independently here) for every c, and ((η − 1)/(η + 1))² at c = 1; the
    /// printed one is off by more than 100 % at c = 1, η = 1.5.
    #[test]
    fn fresnel_printed_and_corrected_against_the_s_and_p_reflectances() {
        let eta: f64 = 1.5;
        let sp = |c: f64| {
            let st = (1.0 - c * c).sqrt() / eta;
            let ct = (1.0 - st * st).sqrt();
            let rs = (c - eta * ct) / (c + eta * ct);
            let rp = (eta * c - ct) / (eta * c + ct);
            0.5 * (rs * rs + rp * rp)
        };
        for c in [1.0, 0.8, 0.5, 0.2] {
            let right = fresnel_corrected(eta, c);
            assert!((right / sp(c) - 1.0).abs() < 1e-14, "c = {c}");
        }
        let normal = ((eta - 1.0) / (eta + 1.0)).powi(2);
        let printed = fresnel_printed(eta, 1.0);
        assert!(
            !((printed / normal - 1.0).abs() <= 1.0),
            "{printed} vs {normal}"
        );
    }

    /// The printed line is ω·ξ, the corrected one ω·ξ − 1, which the exact split (cos(θ − θ')
    /// − 1) + cos θ cos θ'(cos(φ − φ') − 1) also gives.
    #[test]
    fn sec41_line3_printed_is_the_dot_product_not_its_excess() {
        let (t, p, t1, p1) = (0.3f64, 1.1f64, -0.2f64, 0.4f64);
        let fibre = |t: f64, p: f64| [t.sin(), t.cos() * p.cos(), t.cos() * p.sin()];
        let (w, x) = (fibre(t, p), fibre(t1, p1));
        let dot = w[0] * x[0] + w[1] * x[1] + w[2] * x[2];
        assert!((eq_sec41_line3_printed(t, p, t1, p1) - dot).abs() < 1e-15);
        let right = ((t - t1).cos() - 1.0) + t.cos() * t1.cos() * ((p - p1).cos() - 1.0);
        assert!((eq_sec41_line3_corrected(t, p, t1, p1) - right).abs() < 1e-15);
        assert!((eq_sec41_line3_printed(t, p, t1, p1) - right - 1.0).abs() < 1e-15);
    }
}
