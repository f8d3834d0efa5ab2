//! Adaptive Gauss–Kronrod (G7–K15) quadrature in one dimension, and nested over directions
//! (θ, φ) with breakpoints at the lobes' peaks: the `_exact` routes of the SG/ASG module.
//!
//! Why a quadrature inside the reference crate: `mfh eval` answers `"route": "exact"` for the
//! approximations of document 003 from this crate, which may depend neither on the harness (whose
//! oracles must stay independent of the closed forms they check) nor on dev-dependencies (the
//! `quadrature` crate is test-only here). The unit tests check these routes against that
//! independent test quadrature (`crate::test_support`).
//!
//! The rule and its error estimate are QUADPACK's QK15 (Piessens et al. 1983); the driver is
//! globally adaptive: it bisects the piece with the largest error estimate until the sum of
//! the estimates is below `max(rel·|I|, abs)`.

use crate::special::gauss_kronrod::{WG, WGK, XGK};

use super::{add, scale};
use crate::geometry::{dot, Vec3};
use std::cmp::Ordering;
use std::collections::BinaryHeap;
use std::f64::consts::PI;

/// An integral's value and an estimate of its absolute error.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct LobeIntegral {
    /// The value.
    pub value: f64,
    /// The estimated absolute error.
    pub error: f64,
}

#[derive(Debug, Clone, Copy)]
struct Piece {
    a: f64,
    b: f64,
    value: f64,
    error: f64,
}

impl PartialEq for Piece {
    fn eq(&self, other: &Self) -> bool {
        self.error.total_cmp(&other.error) == Ordering::Equal
    }
}
impl Eq for Piece {}
impl PartialOrd for Piece {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for Piece {
    fn cmp(&self, other: &Self) -> Ordering {
        self.error.total_cmp(&other.error)
    }
}

/// QK15 on [a, b] with QUADPACK's error estimate.
fn gk15(f: &dyn Fn(f64) -> f64, a: f64, b: f64) -> Piece {
    let c = 0.5 * (a + b);
    let h = 0.5 * (b - a);
    let fc = f(c);
    let mut resk = fc * WGK[7];
    let mut resg = fc * WG[3];
    let mut resabs = resk.abs();
    let mut fv = [(0.0, 0.0); 7];
    for (j, fvj) in fv.iter_mut().enumerate() {
        let x = h * XGK[j];
        let (f1, f2) = (f(c - x), f(c + x));
        *fvj = (f1, f2);
        resk += WGK[j] * (f1 + f2);
        resabs += WGK[j] * (f1.abs() + f2.abs());
        if j % 2 == 1 {
            resg += WG[j / 2] * (f1 + f2);
        }
    }
    let reskh = 0.5 * resk;
    let mut resasc = WGK[7] * (fc - reskh).abs();
    for (j, &(f1, f2)) in fv.iter().enumerate() {
        resasc += WGK[j] * ((f1 - reskh).abs() + (f2 - reskh).abs());
    }
    let value = resk * h;
    resabs *= h.abs();
    resasc *= h.abs();
    let mut error = ((resk - resg) * h).abs();
    if resasc != 0.0 && error != 0.0 {
        error = resasc * (200.0 * error / resasc).powf(1.5).min(1.0);
    }
    if resabs > f64::MIN_POSITIVE / (50.0 * f64::EPSILON) {
        error = error.max(50.0 * f64::EPSILON * resabs);
    }
    if !value.is_finite() {
        error = f64::INFINITY;
    }
    Piece { a, b, value, error }
}

/// The nodes and weights of the 15-point Kronrod rule on [a, b] (for fixed-grid sweeps).
#[cfg(test)]
pub(crate) fn kronrod_rule(a: f64, b: f64) -> Vec<(f64, f64)> {
    let c = 0.5 * (a + b);
    let h = 0.5 * (b - a);
    let mut v = vec![(c, WGK[7] * h)];
    for j in 0..7 {
        v.push((c - h * XGK[j], WGK[j] * h));
        v.push((c + h * XGK[j], WGK[j] * h));
    }
    v
}

/// The nodes and weights of the 7-point Gauss rule on [a, b] (for fixed-grid sweeps).
#[cfg(test)]
pub(crate) fn gauss_rule(a: f64, b: f64) -> Vec<(f64, f64)> {
    let c = 0.5 * (a + b);
    let h = 0.5 * (b - a);
    let mut v = vec![(c, WG[3] * h)];
    for j in 0..3 {
        v.push((c - h * XGK[2 * j + 1], WG[j] * h));
        v.push((c + h * XGK[2 * j + 1], WG[j] * h));
    }
    v
}

/// The most pieces one 1-D integral may be cut into.
const MAX_PIECES: usize = 4000;

/// ∫ f over [breaks[0], breaks[last]], each interval between consecutive breakpoints a
/// first piece, bisected adaptively until the summed error estimate is at most
/// `max(rel·|I|, abs)`. Breakpoints must be increasing.
pub(crate) fn integrate(
    f: &dyn Fn(f64) -> f64,
    breaks: &[f64],
    rel: f64,
    abs: f64,
) -> LobeIntegral {
    let mut heap: BinaryHeap<Piece> = breaks
        .windows(2)
        .filter(|w| w[1] > w[0])
        .map(|w| gk15(f, w[0], w[1]))
        .collect();
    let mut done: Vec<Piece> = Vec::new();
    loop {
        let (value, error) = heap
            .iter()
            .chain(done.iter())
            .fold((0.0, 0.0), |(v, e), p| (v + p.value, e + p.error));
        if !value.is_finite() {
            return LobeIntegral {
                value,
                error: f64::INFINITY,
            };
        }
        if error <= (rel * value.abs()).max(abs) || heap.len() + done.len() >= MAX_PIECES {
            return LobeIntegral { value, error };
        }
        let Some(worst) = heap.pop() else {
            return LobeIntegral { value, error };
        };
        let m = 0.5 * (worst.a + worst.b);
        if !(m > worst.a && m < worst.b) || worst.b - worst.a < 1e-15 * worst.a.abs().max(1.0) {
            // Too narrow to split further: keep it as it is.
            done.push(worst);
            continue;
        }
        heap.push(gk15(f, worst.a, m));
        heap.push(gk15(f, m, worst.b));
    }
}

/// A peak the integrand has near the direction `peak` (unit), of angular width `width`
/// (radians): the nested quadrature puts breakpoints around it.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Lobe {
    /// The peak's direction.
    pub peak: Vec3,
    /// The lobe's angular width (about 1/√sharpness).
    pub width: f64,
}

impl Lobe {
    /// A lobe of sharpness `k` (exp(−k θ²/2)-like) at `peak`.
    pub fn of_sharpness(peak: Vec3, k: f64) -> Self {
        Lobe {
            peak,
            width: 1.0 / (1.0 + k).sqrt(),
        }
    }
}

/// Breakpoints at `centre ± width·3^k` inside (lo, hi), with lo and hi.
fn geometric_breaks(out: &mut Vec<f64>, centre: f64, width: f64, lo: f64, hi: f64) {
    let mut d = width;
    for _ in 0..12 {
        for x in [centre - d, centre + d] {
            if x > lo && x < hi {
                out.push(x);
            }
        }
        if d > hi - lo {
            break;
        }
        d *= 3.0;
    }
    if centre > lo && centre < hi {
        out.push(centre);
    }
}

fn sorted_unique(mut v: Vec<f64>) -> Vec<f64> {
    v.sort_by(f64::total_cmp);
    v.dedup_by(|a, b| (*a - *b).abs() < 1e-13);
    v
}

/// ∫ f(v) dv over the directions within `theta_max` of `frame[2]` (π: the whole sphere; π/2:
/// the hemisphere v·frame[2] ≥ 0), with `dv = sin θ dθ dφ` in the orthonormal frame
/// `frame = [t, b, pole]`. The θ and φ ranges are cut around every lobe's peak (peaks outside
/// the region are clamped to its edge) so that lobes of sharpness up to 1e4 and more are
/// resolved; then the nested G7–K15 integration is adaptive in both. Relative accuracy about
/// `rel` (absolute floor `rel` × a first estimate of ∫|f|).
pub(crate) fn integrate_directions(
    f: &dyn Fn(Vec3) -> f64,
    frame: &[Vec3; 3],
    theta_max: f64,
    lobes: &[Lobe],
    rel: f64,
) -> f64 {
    let mut theta_breaks = vec![0.0, theta_max];
    let mut phi_breaks = vec![0.0, 0.5 * PI, PI, 1.5 * PI, 2.0 * PI];
    for lobe in lobes {
        let z = dot(lobe.peak, frame[2]).clamp(-1.0, 1.0);
        let theta = z.acos().min(theta_max);
        let w = lobe.width.max(1e-8);
        geometric_breaks(&mut theta_breaks, theta, w, 0.0, theta_max);
        let s = theta.sin();
        if s > w {
            let phi = dot(lobe.peak, frame[1])
                .atan2(dot(lobe.peak, frame[0]))
                .rem_euclid(2.0 * PI);
            let mut around = Vec::new();
            geometric_breaks(&mut around, 0.0, w / s, -PI, PI);
            for d in around {
                phi_breaks.push((phi + d).rem_euclid(2.0 * PI));
            }
        }
    }
    let theta_breaks = sorted_unique(theta_breaks);
    let phi_breaks = sorted_unique(phi_breaks);
    let point = |theta: f64, phi: f64| -> Vec3 {
        let (st, ct) = theta.sin_cos();
        let (sp, cp) = phi.sin_cos();
        add(
            add(scale(frame[0], st * cp), scale(frame[1], st * sp)),
            scale(frame[2], ct),
        )
    };
    let nested = |rel: f64, abs: f64| -> f64 {
        let inner_abs = abs / (2.0 * PI * theta_max) * 0.1;
        let g = |theta: f64| -> f64 {
            let s = theta.sin();
            if s == 0.0 {
                return 0.0;
            }
            let h = |phi: f64| f(point(theta, phi));
            s * integrate(&h, &phi_breaks, rel * 0.1, inner_abs / s).value
        };
        integrate(&g, &theta_breaks, rel, abs).value
    };
    // A first, coarse pass fixes the magnitude the absolute floor refers to.
    let magnitude = nested(1e-4, 0.0).abs();
    let abs = (rel * magnitude * 1e-2).max(f64::MIN_POSITIVE);
    nested(rel, abs)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sg::frame_around;
    use crate::test_support::rel_err;

    #[test]
    fn one_dimensional_rules() {
        let e = integrate(&|x: f64| x.exp(), &[0.0, 1.0], 1e-14, 0.0);
        assert!(rel_err(e.value, std::f64::consts::E - 1.0) < 1e-15);
        // A peak of width 1e-4 at an interior breakpoint.
        let w = 1e-4;
        let f = |x: f64| (-(x - 0.3f64).powi(2) / (w * w)).exp();
        // (A peak exactly at a breakpoint is invisible to the rule's nodes unless pieces of
        // its own width surround it: that is what `integrate_directions` does.)
        let e = integrate(
            &f,
            &[
                0.0,
                0.3 - 1e-3,
                0.3 - 1e-4,
                0.3,
                0.3 + 1e-4,
                0.3 + 1e-3,
                1.0,
            ],
            1e-13,
            0.0,
        );
        assert!(rel_err(e.value, w * PI.sqrt()) < 1e-12, "{e:?}");
        // A kink.
        let e = integrate(&|x: f64| (x - 0.123).abs(), &[0.0, 1.0], 1e-13, 0.0);
        let exact = 0.5 * (0.123f64.powi(2) + 0.877f64.powi(2));
        assert!(rel_err(e.value, exact) < 1e-12, "{e:?}");
    }

    #[test]
    fn sphere_area_and_sharp_lobe() {
        let frame = frame_around([0.0, 0.6, 0.8]);
        let area = integrate_directions(&|_| 1.0, &frame, PI, &[], 1e-13);
        assert!(rel_err(area, 4.0 * PI) < 1e-13, "{area}");
        // ∫ e^{k (v·p − 1)} dv = 2π (1 − e^{−2k}) / k for a lobe away from the pole.
        let p = crate::sg::normalize([1.0, 2.0, -0.5]);
        for k in [1e-3, 1.0, 100.0, 1e4] {
            let f = |v: Vec3| (k * (dot(v, p) - 1.0)).exp();
            let got = integrate_directions(&f, &frame, PI, &[Lobe::of_sharpness(p, k)], 1e-12);
            let exact = 2.0 * PI * -(-2.0 * k).exp_m1() / k;
            assert!(rel_err(got, exact) < 1e-11, "k = {k}: {got} vs {exact}");
        }
    }
}
