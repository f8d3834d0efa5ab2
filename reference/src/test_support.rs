//! Test-only numerical integration (double-exponential quadrature from the `quadrature` crate,
//! made adaptive by bisection): the independent oracle the closed-form unit tests use.

/// ∫_a^b f with relative accuracy `rel` (absolute floor `abs`), by bisecting until the
/// double-exponential error estimate of every piece is small enough. Returns (value, estimate
/// of the error).
pub fn integrate(f: &dyn Fn(f64) -> f64, a: f64, b: f64, rel: f64, abs: f64) -> (f64, f64) {
    // A first pass fixes the magnitude the relative target refers to.
    let whole = quadrature::double_exponential::integrate(f, a, b, abs);
    let target = (rel * whole.integral.abs()).max(abs);
    piece(f, a, b, target, 0)
}

fn piece(f: &dyn Fn(f64) -> f64, a: f64, b: f64, target: f64, depth: u32) -> (f64, f64) {
    let o = quadrature::double_exponential::integrate(f, a, b, target * 0.1);
    if o.error_estimate <= target || depth >= 40 {
        return (o.integral, o.error_estimate);
    }
    let m = 0.5 * (a + b);
    let (l, el) = piece(f, a, m, target * 0.5, depth + 1);
    let (r, er) = piece(f, m, b, target * 0.5, depth + 1);
    (l + r, el + er)
}

/// ∫_a^∞ f by the substitution t = a + scale · u/(1 − u), u ∈ [0, 1); `scale` should be the
/// width over which f decays.
pub fn integrate_tail(f: &dyn Fn(f64) -> f64, a: f64, scale: f64, rel: f64) -> f64 {
    let g = |u: f64| {
        let one_minus = 1.0 - u;
        let t = a + scale * u / one_minus;
        let v = f(t) * scale / (one_minus * one_minus);
        if v.is_finite() {
            v
        } else {
            0.0
        }
    };
    // Split at the points that map to a + scale·{0.5, 1, 2, 8, 64}: resolves both the body and
    // the algebraic tail.
    let cuts = [0.0, 1.0 / 3.0, 0.5, 2.0 / 3.0, 8.0 / 9.0, 64.0 / 65.0, 1.0];
    cuts.windows(2)
        .map(|w| integrate(&g, w[0], w[1], rel, 0.0).0)
        .sum()
}

/// ∫_{−∞}^{∞} f for an f centred at 0 with width `scale`.
pub fn integrate_line(f: &dyn Fn(f64) -> f64, scale: f64, rel: f64) -> f64 {
    integrate_tail(f, 0.0, scale, rel) + integrate_tail(&|t| f(-t), 0.0, scale, rel)
}

/// The relative difference |a − b| / |b| (absolute where b = 0).
pub fn rel_err(a: f64, b: f64) -> f64 {
    if b == 0.0 {
        a.abs()
    } else {
        ((a - b) / b).abs()
    }
}
