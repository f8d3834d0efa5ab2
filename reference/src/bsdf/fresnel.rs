//! Fresnel reflectance of a smooth interface, unpolarized (the mean of the s and p
//! reflectances): exact for a dielectric (Walter 2007 eq 22) and for a conductor of complex
//! index n + ik, and Schlick's approximation.

/// Which Fresnel term a conductor uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FresnelModel {
    /// The exact unpolarized reflectance of the complex index ([`conductor`]).
    #[default]
    Exact,
    /// Schlick's approximation with the exact normal-incidence reflectance ([`schlick`]).
    Schlick,
}

impl FresnelModel {
    /// The name used in specs (`exact`, `schlick`).
    pub fn name(self) -> &'static str {
        match self {
            FresnelModel::Exact => "exact",
            FresnelModel::Schlick => "schlick",
        }
    }
}

/// The Fresnel terms of a dielectric interface at one incidence.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dielectric {
    /// The reflectance F ∈ [0, 1] (1 under total internal reflection).
    pub reflectance: f64,
    /// The transmittance 1 − F, computed without the cancellation of 1 − F near F = 1.
    pub transmittance: f64,
    /// The cosine of the refracted angle, |t·m| ∈ [0, 1] (0 under total internal reflection).
    pub cos_t: f64,
}

/// The exact unpolarized Fresnel reflectance of a dielectric interface (Walter 2007, eq 22):
///
/// ```text
/// F(c) = ½ (g − c)²/(g + c)² · (1 + (c(g + c) − 1)² / (c(g − c) + 1)²),   g² = η² − 1 + c²
/// ```
///
/// with c = |i·m| the cosine of incidence on the microfacet and η = η_t/η_i the index of the
/// far side over that of the incident side; g² < 0 is total internal reflection (F = 1). The
/// cosine of the refracted angle is g/η (Snell: η_t cos θt = √(η_t² − η_i² sin²θi)).
///
/// Eq 22 equals ½(r_s² + r_p²) with the amplitude reflectances r_s = (c − g)/(c + g) and
/// r_p = (η²c − g)/(η²c + g) (Born & Wolf, *Principles of Optics*, §1.5.2, with
/// η cos θt = g; eq 22's second factor is 1 + r_p²/r_s²), which is what is evaluated here, in
/// forms without cancellation for η near 1:
///
/// ```text
/// c − g    = (1 − η²)/(c + g)
/// η²c − g  = (η² − 1)((η² + 1)c² − 1)/(η²c + g)
/// 1 − F    = 2cg (1/(c + g)² + η²/(η²c + g)²)
///            (1 − r_s² = 4cg/(c + g)², 1 − r_p² = 4η²cg/(η²c + g)²)
/// ```
///
/// Domain: `cos_i` is taken as |cos_i| clamped to 1; `eta` finite and > 0. Exactly at the
/// critical angle (g = 0) F = 1 and cos_t = 0. NaN in gives NaN out.
pub fn dielectric(cos_i: f64, eta: f64) -> Dielectric {
    // (`f64::min` would turn a NaN cosine into 1.)
    let c = if cos_i.abs() > 1.0 { 1.0 } else { cos_i.abs() };
    let e2 = eta * eta;
    // η² − 1 as (η − 1)(η + 1): no cancellation near η = 1.
    let em1 = (eta - 1.0) * (eta + 1.0);
    let g2 = em1 + c * c;
    if !(g2 > 0.0) {
        if g2.is_nan() {
            return Dielectric {
                reflectance: f64::NAN,
                transmittance: f64::NAN,
                cos_t: f64::NAN,
            };
        }
        return Dielectric {
            reflectance: 1.0,
            transmittance: 0.0,
            cos_t: 0.0,
        };
    }
    let g = g2.sqrt();
    let s = c + g;
    let p = e2 * c + g;
    // r_s = (c − g)/(c + g), r_p = (η²c − g)/(η²c + g), both without cancellation.
    let rs = -em1 / (s * s);
    let rp = em1 * ((e2 + 1.0) * c * c - 1.0) / (p * p);
    let reflectance = 0.5 * (rs * rs + rp * rp);
    let transmittance = 2.0 * c * g * (1.0 / (s * s) + e2 / (p * p));
    Dielectric {
        reflectance: reflectance.min(1.0),
        transmittance: transmittance.clamp(0.0, 1.0),
        cos_t: (g / eta).min(1.0),
    }
}

/// Walter 2007 eq 22 evaluated as printed (for tests: the same number as [`dielectric`] up to
/// rounding, away from η = 1 where its g − c cancels).
pub fn dielectric_eq22(cos_i: f64, eta: f64) -> f64 {
    let c = cos_i.abs().min(1.0);
    let g2 = eta * eta - 1.0 + c * c;
    if !(g2 > 0.0) {
        return 1.0;
    }
    let g = g2.sqrt();
    let a = (c * (g + c) - 1.0) / (c * (g - c) + 1.0);
    0.5 * (g - c).powi(2) / (g + c).powi(2) * (1.0 + a * a)
}

/// A complex number (re, im), for the conductor's Fresnel only.
#[derive(Debug, Clone, Copy, PartialEq)]
struct C(f64, f64);

impl C {
    fn add(self, o: C) -> C {
        C(self.0 + o.0, self.1 + o.1)
    }
    fn sub(self, o: C) -> C {
        C(self.0 - o.0, self.1 - o.1)
    }
    fn mul(self, o: C) -> C {
        C(self.0 * o.0 - self.1 * o.1, self.0 * o.1 + self.1 * o.0)
    }
    fn norm2(self) -> f64 {
        self.0 * self.0 + self.1 * self.1
    }
    /// The principal square root (Re ≥ 0), without cancellation: with r = |z|, the component
    /// of the sign of Re z is √((r + |Re z|)/2) and the other Im z / (2 · that).
    fn sqrt(self) -> C {
        let (a, b) = (self.0, self.1);
        let r = a.hypot(b);
        if r == 0.0 {
            return C(0.0, 0.0);
        }
        if a >= 0.0 {
            let re = (0.5 * (r + a)).sqrt();
            C(re, b / (2.0 * re))
        } else {
            let im = (0.5 * (r - a)).sqrt().copysign(b);
            C(b / (2.0 * im), im)
        }
    }
}

/// The exact unpolarized Fresnel reflectance of a conductor (or an absorbing dielectric) of
/// complex relative index η = n + ik (k ≥ 0) at incidence cosine c = `cos_i`.
///
/// Derived from the Fresnel equations with a complex index (Born & Wolf, *Principles of Optics*,
/// §14.2; pbrt-v4, Pharr, Jakob & Humphreys 2023, §9.5 "Conductor BRDF", which evaluates the same
/// amplitudes in complex arithmetic). Snell's law η sin θt = sin θi makes the transmitted cosine
/// complex, and only w = η cos θt is needed:
///
/// ```text
/// w   = √(η² − sin²θi) = √(η² − 1 + c²)          (principal root: Re w ≥ 0, Im w ≥ 0 for k ≥ 0,
///                                                  the refracted wave decays into the conductor)
/// r_s = (cos θi − η cos θt)/(cos θi + η cos θt) = (c − w)/(c + w)
/// r_p = (η cos θi − cos θt)/(η cos θi + cos θt) = (η²c − w)/(η²c + w)    (times η/η)
/// F   = (|r_s|² + |r_p|²)/2
/// ```
///
/// For k = 0 this is [`dielectric`] (with total internal reflection for n < 1: w is then
/// imaginary and |r_s| = |r_p| = 1). Domain: `cos_i` taken as |cos_i| clamped to 1; F = 1 at
/// grazing incidence (c = 0).
pub fn conductor(cos_i: f64, n: f64, k: f64) -> f64 {
    let c = cos_i.abs().min(1.0);
    if c == 0.0 {
        return 1.0;
    }
    let eta = C(n, k);
    let e2 = eta.mul(eta);
    let w = C(e2.0 - 1.0 + c * c, e2.1).sqrt();
    let cc = C(c, 0.0);
    let rs = cc.sub(w).norm2() / cc.add(w).norm2();
    let e2c = C(e2.0 * c, e2.1 * c);
    let rp = e2c.sub(w).norm2() / e2c.add(w).norm2();
    (0.5 * (rs + rp)).min(1.0)
}

/// The normal-incidence reflectance of the complex index n + ik:
/// F0 = ((n − 1)² + k²)/((n + 1)² + k²) (the exact F at c = 1: r_s = (1 − η)/(1 + η)).
pub fn f0(n: f64, k: f64) -> f64 {
    ((n - 1.0).powi(2) + k * k) / ((n + 1.0).powi(2) + k * k)
}

/// Schlick's approximation (Schlick 1994, "An inexpensive BRDF model for physically-based
/// rendering", Computer Graphics Forum 13(3)): F ≈ F0 + (1 − F0)(1 − c)⁵ with F0 = [`f0`]`(n, k)`
/// (exact at c = 1 and c = 0). Domain: `cos_i` taken as |cos_i| clamped to 1.
pub fn schlick(cos_i: f64, n: f64, k: f64) -> f64 {
    let c = cos_i.abs().min(1.0);
    let f0 = f0(n, k);
    f0 + (1.0 - f0) * (1.0 - c).powi(5)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::rel_err;

    #[test]
    fn dielectric_is_eq22_and_its_complement() {
        for &eta in &[1.5, 1.0 / 1.5, 1.33, 2.4, 0.4, 3.9] {
            for i in 0..=200 {
                let c = i as f64 / 200.0;
                let d = dielectric(c, eta);
                let printed = dielectric_eq22(c, eta);
                assert!(
                    (d.reflectance - printed).abs() <= 1e-14,
                    "η {eta} c {c}: {} vs eq 22 {printed}",
                    d.reflectance
                );
                assert!((d.reflectance + d.transmittance - 1.0).abs() <= 1e-14);
                // Snell: η_i sin θi = η_t sin θt.
                if d.reflectance < 1.0 {
                    let st = (1.0 - d.cos_t * d.cos_t).sqrt();
                    assert!((eta * st - (1.0 - c * c).sqrt()).abs() < 1e-13);
                }
            }
            // Normal incidence: ((η − 1)/(η + 1))².
            let n = dielectric(1.0, eta).reflectance;
            assert!(rel_err(n, ((eta - 1.0) / (eta + 1.0)).powi(2)) < 1e-14);
        }
        // Total internal reflection beyond the critical angle sin θc = η (η < 1), at it F = 1.
        let eta = 1.0f64 / 1.5;
        let cc = (1.0 - eta * eta).sqrt();
        assert_eq!(dielectric(cc - 1e-3, eta).reflectance, 1.0);
        assert_eq!(dielectric(cc - 1e-3, eta).cos_t, 0.0);
        assert!(dielectric(cc + 1e-3, eta).reflectance < 1.0);
        assert!(dielectric(cc + 1e-9, eta).reflectance > 0.99);
        // Grazing: F = 1 on either side; index matched: F = 0.
        assert!((dielectric(0.0, 1.5).reflectance - 1.0).abs() < 1e-15);
        assert_eq!(dielectric(0.3, 1.0).reflectance, 0.0);
        // Near η = 1 the stable form keeps its relative accuracy (eq 22 as printed loses
        // about 10 of its 16 digits here): mpmath, 30 digits, η = 1 + 1e-5 (the f64), c = 0.8.
        let d = dielectric(0.8, 1.0 + 1e-5);
        assert!(
            rel_err(d.reflectance, 3.290_957_996_739_398e-11) < 1e-13,
            "{d:?}"
        );
        let e = 1.0 + 1e-5f64;
        assert!(
            rel_err(
                dielectric(1.0, e).reflectance,
                ((e - 1.0) / (e + 1.0)).powi(2)
            ) < 1e-14
        );
        assert!(dielectric(f64::NAN, 1.5).reflectance.is_nan());
    }

    #[test]
    fn conductor_reduces_to_the_dielectric_and_to_f0() {
        for &n in &[1.5, 0.5, 2.4] {
            for i in 0..=50 {
                let c = i as f64 / 50.0;
                let a = conductor(c, n, 0.0);
                let b = dielectric(c, n).reflectance;
                assert!((a - b).abs() < 1e-14, "n {n} c {c}: {a} vs {b}");
            }
        }
        for &(n, k) in &[(0.18, 3.42), (1.66, 8.05), (2.9, 0.1)] {
            assert!(rel_err(conductor(1.0, n, k), f0(n, k)) < 1e-14);
            assert_eq!(conductor(0.0, n, k), 1.0);
            assert!(rel_err(schlick(1.0, n, k), f0(n, k)) < 1e-15);
            assert_eq!(schlick(0.0, n, k), 1.0);
            for i in 0..=50 {
                let c = i as f64 / 50.0;
                let f = conductor(c, n, k);
                assert!((0.0..=1.0).contains(&f));
            }
        }
        // Gold-like n = 0.18, k = 3.42 at 60° (mpmath complex arithmetic, 30 digits; the
        // golden file golden/bsdf.json compares the whole BSDF).
        let f = conductor(0.5, 0.18, 3.42);
        assert!(rel_err(f, 0.939_539_840_933_417_5) < 1e-14, "{f}");
        // The exact and Schlick's differ (Schlick misses the dip of r_p): a named variant,
        // not a synonym.
        assert!((schlick(0.2, 0.18, 3.42) - conductor(0.2, 0.18, 3.42)).abs() > 1e-3);
    }
}
