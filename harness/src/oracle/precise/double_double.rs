//! Double-double arithmetic: a number is the unevaluated sum hi + lo of two f64 with
//! |lo| ≤ ½ ulp(hi), ≈ 106 significant bits (unit round-off u = 2⁻¹⁰⁴ ≈ 4.9e-32 per operation).
//!
//! Written by hand rather than taken from a crate: `twofloat`, the maintained Rust
//! double-double crate, documents its transcendental functions (exp, ln, powf, exp_m1) as
//! "very preliminary … they will not return values which are correct to the full precision of
//! the TwoFloat type" (its README; exp was fixed only in 2025, exp_m1 is still open as issue
//! #46), and this oracle needs exactly those, certified. The type below is small: the
//! error-free transformations TwoSum and TwoProd (via `f64::mul_add`), the arithmetic of
//! Joldeș, Muller and Popescu (ACM TOMS 44(2), 2017: AccurateDWPlusDW, DWTimesDW; relative
//! error ≤ 3u² and ≤ 5u² for + and ×, u = 2⁻⁵³), division and square root by one Newton
//! correction, and exp / expm1 / ln / ln1p / powf:
//!
//! - `expm1` near 0: Taylor series of e^{r/2¹⁰} − 1, then ten doublings p ← 2p + p², which
//!   keep the relative accuracy of e^r − 1 however small r is;
//! - `exp`: x = k ln 2 + r, |r| ≤ ½ ln 2, with ln 2 as a double-double; the absolute error of
//!   r, ≈ |k| · 1e-32, is the relative error of the result (≤ 1e-29 for |x| ≤ 700);
//! - `ln`, `ln1p`: one Newton step from the f64 logarithm (error ≈ 1e-16 → 1e-32) on
//!   y ↦ x e^{−y} − 1 after x = 2ᵉ m, m ∈ [1, 2), resp. on expm1(y) − x (which keeps relative
//!   accuracy near 0);
//! - `powf(y)` = exp(y ln x): relative error ≈ |y ln x| · 1e-32.
//!
//! The unit tests check exact identities: (1/3)·3, √2², exp(ln x) = x and ln(exp x) = x,
//! expm1(ln1p x) = x to 1e-30, e and π against their decimal expansions.
//!
//! Full precision needs |values| ≥ ~1e-290 (below, lo becomes subnormal and the precision
//! degrades gracefully to that of f64). Non-finite values are not supported beyond this: exp overflows to +∞ (lo = 0) and
//! underflows to 0; ln of a non-positive number is NaN.

use std::cmp::Ordering;
use std::ops::{Add, Div, Mul, Neg, Sub};

/// hi + lo with |lo| ≤ ½ ulp(hi): a double-double number.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct DoubleDouble {
    hi: f64,
    lo: f64,
}

/// The unit round-off of a double-double operation, 2⁻¹⁰⁴.
pub const UNIT_ROUNDOFF: f64 = 4.930380657631324e-32;

/// a + b = s + e exactly (Knuth's TwoSum; any order of magnitudes).
fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bb = s - a;
    (s, (a - (s - bb)) + (b - bb))
}

/// a + b = s + e exactly, for |a| ≥ |b| (Dekker's FastTwoSum).
fn fast_two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    (s, b - (s - a))
}

/// a · b = p + e exactly (TwoProd by a fused multiply-add).
fn two_prod(a: f64, b: f64) -> (f64, f64) {
    let p = a * b;
    (p, a.mul_add(b, -p))
}

impl DoubleDouble {
    /// 0.
    pub const ZERO: Self = Self { hi: 0.0, lo: 0.0 };
    /// 1.
    pub const ONE: Self = Self { hi: 1.0, lo: 0.0 };
    /// π to 106 bits.
    pub const PI: Self = Self {
        hi: std::f64::consts::PI,
        lo: 1.2246467991473532e-16,
    };
    /// ln 2 to 106 bits.
    pub const LN_2: Self = Self {
        hi: std::f64::consts::LN_2,
        lo: 2.3190468138462996e-17,
    };

    /// The double-double equal to `hi + lo` (renormalized).
    pub fn from_sum(hi: f64, lo: f64) -> Self {
        let (h, l) = two_sum(hi, lo);
        Self { hi: h, lo: l }
    }

    /// The leading part (the f64 nearest the value).
    pub fn hi(self) -> f64 {
        self.hi
    }

    /// The trailing part.
    pub fn lo(self) -> f64 {
        self.lo
    }

    /// The nearest f64.
    pub fn to_f64(self) -> f64 {
        self.hi + self.lo
    }

    /// Whether both parts are finite.
    pub fn is_finite(self) -> bool {
        self.hi.is_finite() && self.lo.is_finite()
    }

    /// |x|.
    pub fn abs(self) -> Self {
        if self.hi < 0.0 {
            -self
        } else {
            self
        }
    }

    /// x · 2ᵏ (exact unless the result leaves the normal range).
    pub fn ldexp(self, k: i32) -> Self {
        let mut x = self;
        let mut k = k;
        while k != 0 {
            let step = k.clamp(-1000, 1000);
            let f = 2f64.powi(step);
            x = Self {
                hi: x.hi * f,
                lo: x.lo * f,
            };
            k -= step;
        }
        x
    }

    /// x · b for an f64 b (relative error ≤ 3u², u = 2⁻⁵³).
    pub fn mul_f64(self, b: f64) -> Self {
        let (p, e) = two_prod(self.hi, b);
        if !p.is_finite() {
            return Self::from(p);
        }
        let (h, l) = fast_two_sum(p, self.lo.mul_add(b, e));
        Self { hi: h, lo: l }
    }

    /// x / b for an f64 b.
    pub fn div_f64(self, b: f64) -> Self {
        self / Self::from(b)
    }

    /// x² .
    pub fn square(self) -> Self {
        self * self
    }

    /// xⁿ by binary powering (n may be negative).
    pub fn powi(self, n: i32) -> Self {
        let mut base = if n < 0 { Self::ONE / self } else { self };
        let mut e = n.unsigned_abs();
        let mut acc = Self::ONE;
        while e > 0 {
            if e & 1 == 1 {
                acc = acc * base;
            }
            base = base.square();
            e >>= 1;
        }
        acc
    }

    /// √x (NaN for x < 0): one Newton correction of the f64 root, s + (x − s²)/(2s).
    pub fn sqrt(self) -> Self {
        if self.hi <= 0.0 {
            return if self.hi == 0.0 {
                Self::ZERO
            } else {
                Self::from(f64::NAN)
            };
        }
        let s = self.hi.sqrt();
        let (p, e) = two_prod(s, s);
        let correction = (((self.hi - p) - e) + self.lo) / (2.0 * s);
        let (h, l) = fast_two_sum(s, correction);
        Self { hi: h, lo: l }
    }

    /// e^r − 1 for |r| ≤ ~0.35: Taylor series of e^{r/2¹⁰} − 1 (|term| < 2e-34 · |sum| at the
    /// end), then ten doublings p ← 2p + p² (= (1 + p)² − 1).
    fn expm1_reduced(r: Self) -> Self {
        const HALVINGS: i32 = 10;
        let s = r.ldexp(-HALVINGS);
        let mut term = s;
        let mut sum = s;
        let mut n = 2.0;
        while term.hi.abs() > 2e-34 * sum.hi.abs() && n < 40.0 {
            term = (term * s).div_f64(n);
            sum = sum + term;
            n += 1.0;
        }
        for _ in 0..HALVINGS {
            sum = sum.ldexp(1) + sum.square();
        }
        sum
    }

    /// eˣ (+∞ above 709.78, 0 below −745.2).
    pub fn exp(self) -> Self {
        if self.hi.is_nan() {
            return self;
        }
        if self.hi > 709.78 {
            return Self::from(f64::INFINITY);
        }
        if self.hi < -745.2 {
            return Self::ZERO;
        }
        let k = (self.hi / std::f64::consts::LN_2).round();
        let r = self - Self::LN_2.mul_f64(k);
        let p = Self::expm1_reduced(r);
        // k ∈ [−1075, 1024]: scale in two steps so that 2ᵏ never overflows on its own.
        (Self::ONE + p).ldexp(k as i32)
    }

    /// eˣ − 1, with relative accuracy also for x near 0.
    pub fn expm1(self) -> Self {
        if self.hi.abs() <= 0.34 {
            Self::expm1_reduced(self)
        } else {
            self.exp() - Self::ONE
        }
    }

    /// ln x (NaN for x < 0, −∞ for 0): one Newton step y + x e^{−y} − 1 from y = ln(hi).
    pub fn ln(self) -> Self {
        if self.hi.is_nan() || self.hi < 0.0 {
            return Self::from(f64::NAN);
        }
        if self.hi == 0.0 {
            return Self::from(f64::NEG_INFINITY);
        }
        if self.hi == f64::INFINITY {
            return self;
        }
        if (self.hi - 1.0).abs() < 0.25 {
            return (self - Self::ONE).ln1p();
        }
        // x = 2ᵉ m with m ∈ [1, 2): ln x = ln m + e ln 2, so that e^{−y} below stays normal.
        let e = self.hi.log2().floor() as i32;
        let m = self.ldexp(-e);
        let y = Self::from(m.hi.ln());
        y + (m * (-y).exp() - Self::ONE) + Self::LN_2.mul_f64(f64::from(e))
    }

    /// ln(1 + x), with relative accuracy also for x near 0: one Newton step on
    /// expm1(y) − x from y = ln_1p(hi).
    pub fn ln1p(self) -> Self {
        if self.hi.abs() > 0.25 {
            return (Self::ONE + self).ln();
        }
        let y = Self::from(self.hi.ln_1p());
        let e = y.expm1();
        y - (e - self) / (Self::ONE + e)
    }

    /// xʸ = e^{y ln x} for x > 0 (0 for x = 0 and y > 0; NaN for x < 0).
    pub fn powf(self, y: Self) -> Self {
        if self.hi == 0.0 && y.hi > 0.0 {
            return Self::ZERO;
        }
        (y * self.ln()).exp()
    }

    /// The value as a decimal string with `digits` significant digits (≤ 34), e.g.
    /// `1.2345678901234567890123456789012e-3` (scientific, exponent always shown).
    pub fn to_decimal(self, digits: usize) -> String {
        if !self.is_finite() {
            return format!("{}", self.hi);
        }
        if self.hi == 0.0 {
            return "0".to_string();
        }
        let digits = digits.clamp(1, 34);
        let sign = if self.hi < 0.0 { "-" } else { "" };
        let x = self.abs();
        let mut exponent = x.hi.log10().floor() as i32;
        let mut m = x * Self::from(10.0).powi(-exponent);
        if m.hi >= 10.0 {
            m = m.div_f64(10.0);
            exponent += 1;
        } else if m.hi < 1.0 {
            m = m.mul_f64(10.0);
            exponent -= 1;
        }
        // digits + 1 digits, then round half up on the last one.
        let mut out: Vec<u8> = Vec::with_capacity(digits + 1);
        for _ in 0..=digits {
            let d = m.hi.floor().clamp(0.0, 9.0);
            out.push(d as u8);
            m = (m - Self::from(d)).mul_f64(10.0);
        }
        let round_up = out.pop().is_some_and(|d| d >= 5);
        if round_up {
            let mut i = out.len();
            loop {
                if i == 0 {
                    out.insert(0, 1);
                    out.pop();
                    exponent += 1;
                    break;
                }
                i -= 1;
                if out[i] == 9 {
                    out[i] = 0;
                } else {
                    out[i] += 1;
                    break;
                }
            }
        }
        let mut text = String::from(sign);
        for (i, d) in out.iter().enumerate() {
            if i == 1 {
                text.push('.');
            }
            text.push(char::from(b'0' + d));
        }
        format!("{text}e{exponent}")
    }
}

impl From<f64> for DoubleDouble {
    fn from(x: f64) -> Self {
        Self { hi: x, lo: 0.0 }
    }
}

impl Neg for DoubleDouble {
    type Output = Self;
    fn neg(self) -> Self {
        Self {
            hi: -self.hi,
            lo: -self.lo,
        }
    }
}

impl Add for DoubleDouble {
    type Output = Self;
    /// AccurateDWPlusDW (Joldeș–Muller–Popescu, Algorithm 6): relative error ≤ 3u².
    fn add(self, y: Self) -> Self {
        let (sh, sl) = two_sum(self.hi, y.hi);
        let (th, tl) = two_sum(self.lo, y.lo);
        let (vh, vl) = fast_two_sum(sh, sl + th);
        let (h, l) = fast_two_sum(vh, tl + vl);
        if h.is_finite() {
            Self { hi: h, lo: l }
        } else {
            Self::from(self.hi + y.hi)
        }
    }
}

impl Sub for DoubleDouble {
    type Output = Self;
    fn sub(self, y: Self) -> Self {
        self + (-y)
    }
}

impl Mul for DoubleDouble {
    type Output = Self;
    /// DWTimesDW with FMA (Joldeș–Muller–Popescu, Algorithm 12): relative error ≤ 5u².
    fn mul(self, y: Self) -> Self {
        let (ch, cl1) = two_prod(self.hi, y.hi);
        let tl0 = self.lo * y.lo;
        let tl1 = self.hi.mul_add(y.lo, tl0);
        let cl2 = self.lo.mul_add(y.hi, tl1);
        let (h, l) = fast_two_sum(ch, cl1 + cl2);
        if h.is_finite() {
            Self { hi: h, lo: l }
        } else {
            Self::from(self.hi * y.hi)
        }
    }
}

impl Div for DoubleDouble {
    type Output = Self;
    /// Long division with three f64 quotient digits q1 + q2 + q3, each from the remainder.
    fn div(self, y: Self) -> Self {
        let q1 = self.hi / y.hi;
        if !q1.is_finite() || q1 == 0.0 {
            return Self::from(q1);
        }
        let r = self - y.mul_f64(q1);
        let q2 = r.hi / y.hi;
        let r = r - y.mul_f64(q2);
        let q3 = r.hi / y.hi;
        let (h, l) = fast_two_sum(q1, q2);
        Self { hi: h, lo: l } + Self::from(q3)
    }
}

impl PartialOrd for DoubleDouble {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        match self.hi.partial_cmp(&other.hi) {
            Some(Ordering::Equal) => self.lo.partial_cmp(&other.lo),
            order => order,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    type D = DoubleDouble;

    /// |a − b| / |b| in double-double, as an f64.
    fn rel(a: D, b: D) -> f64 {
        ((a - b) / b).hi.abs()
    }

    #[test]
    fn arithmetic_identities_hold_to_double_double_precision() {
        let third = D::ONE / D::from(3.0);
        assert!(rel(third * D::from(3.0), D::ONE) < 1e-31);
        assert!(rel(D::from(2.0).sqrt().square(), D::from(2.0)) < 1e-31);
        let x = D::from(0.1) + D::from_sum(1e-3, 1e-20);
        assert!(rel((x * x).sqrt(), x) < 1e-31);
        assert!(rel(x / x, D::ONE) < 1e-31);
        assert!(rel(D::from(7.0).powi(-3) * D::from(343.0), D::ONE) < 1e-31);
        // 1 + 2⁻⁶⁰ is exact in double-double, not in f64.
        let tiny = D::from(2f64.powi(-60));
        assert_eq!((D::ONE + tiny - D::ONE).hi(), 2f64.powi(-60));
    }

    #[test]
    fn exp_and_ln_are_inverse_to_1e_30() {
        let mut worst: f64 = 0.0;
        for i in 0..200 {
            let x = D::from(-40.0 + 0.41 * i as f64) + D::from(1e-18 * i as f64);
            worst = worst.max((x.exp().ln() - x).hi.abs() / x.hi.abs().max(1.0));
            let y = D::from(10f64.powf(-30.0 + 0.3 * i as f64));
            worst = worst.max(rel(y.ln().exp(), y));
        }
        assert!(worst < 1e-30, "worst {worst:e}");
    }

    #[test]
    fn expm1_and_ln1p_keep_relative_accuracy_near_zero() {
        let mut worst: f64 = 0.0;
        for i in 0..120 {
            let s = if i % 2 == 0 { 1.0 } else { -1.0 };
            let x = D::from(s * 10f64.powf(-25.0 + 0.2 * i as f64));
            worst = worst.max(rel(x.ln1p().expm1(), x));
            worst = worst.max(rel(x.expm1().ln1p(), x));
        }
        assert!(worst < 1e-30, "worst {worst:e}");
        // expm1(x) = x + x²/2 + x³/6 + … at x = 1e-10.
        let x = D::from(1e-10);
        let series = x + x.square().div_f64(2.0) + (x.square() * x).div_f64(6.0);
        assert!(rel(x.expm1(), series) < 1e-31);
    }

    #[test]
    fn constants_and_decimals_match_known_expansions() {
        assert_eq!(
            D::ONE.exp().to_decimal(31),
            "2.718281828459045235360287471353e0"
        );
        assert_eq!(D::PI.to_decimal(30), "3.14159265358979323846264338328e0");
        assert_eq!(
            D::from(2.0).ln().to_decimal(30),
            "6.93147180559945309417232121458e-1"
        );
        assert_eq!(
            D::from(2.0).sqrt().to_decimal(30),
            "1.41421356237309504880168872421e0"
        );
        assert_eq!(D::from(-0.00125).to_decimal(5), "-1.2500e-3");
        assert_eq!(D::from(9.99999).to_decimal(3), "1.00e1");
        // π^(1/2) squared, and 2^0.5 by powf.
        assert!(rel(D::PI.sqrt().square(), D::PI) < 1e-31);
        assert!(rel(D::from(2.0).powf(D::from(0.5)), D::from(2.0).sqrt()) < 1e-30);
    }

    #[test]
    fn non_finite_and_extreme_arguments_do_not_produce_nan() {
        assert_eq!(D::from(800.0).exp().hi(), f64::INFINITY);
        assert_eq!(D::from(-800.0).exp().hi(), 0.0);
        assert!(D::from(-1.0).ln().hi().is_nan());
        assert_eq!(D::ZERO.ln().hi(), f64::NEG_INFINITY);
        assert!(rel(D::from(700.0).exp().ln(), D::from(700.0)) < 1e-30);
    }
}
