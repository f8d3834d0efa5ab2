use super::*;
use crate::geometry::from_spherical;
use crate::ndf::conformance::{self, assert_sampler_density};
use crate::ndf::Ggx;
use crate::test_support::rel_err;

fn gtr(gamma: f64, alpha: f64) -> Gtr {
    Gtr::new(gamma, alpha).unwrap()
}

const GAMMAS: [f64; 12] = [
    0.0,
    0.1,
    0.5,
    1.0 - 1e-6,
    1.0,
    1.0 + 1e-6,
    1.5,
    2.0,
    3.0,
    4.0,
    7.0,
    10.0,
];
const ALPHAS: [f64; 6] = [1e-3, 0.05, 0.3, 0.9, 0.999, 1.0];
/// θ from near normal incidence to just above the horizon.
const THETAS: [f64; 8] = [1e-3, 0.05, 0.3, 0.8, 1.2, 1.5, 1.57, FRAC_PI_2 - 1e-6];

/// Document 004 §3: P2^γ as printed, γ = 0…4; `literal_q2` reads the printed "4α²q2" of §3.5
/// literally (4α²·q·2) instead of 4α²q².
fn p2_printed(k: u8, alpha: f64, q: f64, literal_q2: bool) -> f64 {
    let (a2, q2) = (alpha * alpha, q * q);
    match k {
        0 => 1.0 / (2.0 * (q2 + 1.0).powf(1.5)),
        // (1/√B − 1/√A)/log α² with the difference taken without cancellation:
        // 1/√B − 1/√A = (A − B)/(√A √B (√A + √B)), A − B = α² − 1.
        1 => {
            let (ra, rb) = ((q2 + a2).sqrt(), (q2 + 1.0).sqrt());
            (a2 - 1.0) / (ra * rb * (ra + rb)) / a2.ln()
        }
        2 => a2 / (2.0 * (q2 + a2).powf(1.5)),
        3 => a2 * a2 * (a2 + 4.0 * q2 + 3.0) / (4.0 * (a2 + 1.0) * (q2 + a2).powf(2.5)),
        4 if literal_q2 => crate::errata::document004::p2_gamma4_printed(alpha, q),
        4 => crate::errata::document004::p2_gamma4_corrected(alpha, q),
        _ => f64::NAN,
    }
}

/// Document 004 §3: P22^γ as printed, γ = 0…4 (r² = p² + q²).
fn p22_printed(k: u8, alpha: f64, r2: f64) -> f64 {
    let a2 = alpha * alpha;
    match k {
        0 => 1.0 / (PI * (r2 + 1.0).powi(2)),
        1 => (a2 - 1.0) / (PI * (r2 + 1.0) * (r2 + a2) * a2.ln()),
        2 => a2 / (PI * (r2 + a2).powi(2)),
        3 => 2.0 * a2 * a2 * (r2 + 1.0) / (PI * (a2 + 1.0) * (r2 + a2).powi(3)),
        4 => {
            3.0 * a2 * a2 * a2 * (r2 + 1.0).powi(2)
                / (PI * (a2 * a2 + a2 + 1.0) * (r2 + a2).powi(4))
        }
        _ => f64::NAN,
    }
}

/// A slope distribution whose P2 is the document's printed P2^γ: the oracle for the closed
/// forms of Λ (document 004 eq 48* applied to the printed P2).
struct PrintedP2 {
    k: u8,
    alpha: f64,
}

impl SlopeDistribution for PrintedP2 {
    fn p22(&self, p: f64, q: f64) -> f64 {
        p22_printed(self.k, self.alpha, p * p + q * q)
    }
    fn p2(&self, q: f64, _phi: f64) -> f64 {
        p2_printed(self.k, self.alpha, q, false)
    }
    fn slope_moment(&self, _k: u32, _phi: f64) -> Option<f64> {
        None
    }
}

/// Λ from its definition (eq 48*) by the test oracle (double-exponential quadrature of
/// (q − μ) P2(q)), with the quadrature scale set to the slope width that matters.
fn lambda_oracle(slopes: &dyn SlopeDistribution, alpha: f64, theta: f64) -> f64 {
    let w = from_spherical(theta, 0.0);
    let mu = w[2] / w[0];
    conformance::lambda_integral(slopes, w, alpha.max(mu))
}

#[test]
fn normalized_over_the_hemisphere() {
    let mut worst: f64 = 0.0;
    for &g in &GAMMAS {
        for &a in &ALPHAS {
            let m = gtr(g, a);
            let n = conformance::normalization_isotropic(&|w| m.d(w), a);
            let e = (n - 1.0).abs();
            assert!(e < 1e-10, "γ={g} α={a}: ∫ D cos θ dω = {n}");
            worst = worst.max(e);
        }
    }
    eprintln!("GTR: max |∫ D cos θ dω − 1| = {worst:.2e}");
}

#[test]
fn d_is_the_printed_formula_and_p22_over_cos4() {
    // Eq 1** (γ ≠ 1) and 4** (γ = 1) as printed, where they are not 0/0.
    for &g in &[0.0, 0.5, 1.0, 1.5, 2.0, 3.0, 7.0] {
        for &a in &[0.01, 0.3, 0.9] {
            let m = gtr(g, a);
            let a2: f64 = a * a;
            let c = if g == 1.0 {
                (a2 - 1.0) / (PI * a2.ln())
            } else {
                (g - 1.0) * (a2 - 1.0) / (PI * (1.0 - a2.powf(1.0 - g)))
            };
            for &theta in &[0.0, 0.2, 0.9, 1.5] {
                let w = from_spherical(theta, 0.4);
                let printed = c / (1.0 + (a2 - 1.0) * w[2] * w[2]).powf(g);
                let e = rel_err(m.d(w), printed);
                assert!(e < 1e-12, "γ={g} α={a} θ={theta}: {e:e}");
                let (p, q) = (w[0] / w[2], w[1] / w[2]);
                let e = rel_err(m.d(w), m.p22(p, q) / w[2].powi(4));
                assert!(e < 1e-12, "γ={g} α={a} θ={theta}: D vs P22/cos⁴θ {e:e}");
            }
        }
    }
    // γ = 2 is GGX (document 004 §3.3), D, Λ and the sampler.
    for &a in &[1e-3, 0.2, 0.8] {
        let (m, ggx) = (gtr(2.0, a), Ggx::new(a, a).unwrap());
        for &theta in &[0.0, 0.3, 1.1, 1.55] {
            let w = from_spherical(theta, 1.0);
            assert!(rel_err(m.d(w), ggx.d(w)) < 1e-13);
            assert!(
                rel_err(m.lambda(w), ggx.lambda(w)) < 1e-12,
                "α={a} θ={theta}"
            );
        }
        for &u in &[[0.1, 0.3], [0.7, 0.95]] {
            let (x, y) = (m.sample_wm(u), ggx.sample_wm(u));
            assert!((0..3).all(|i| (x[i] - y[i]).abs() < 1e-12), "{x:?} {y:?}");
        }
    }
}

#[test]
fn continuous_through_gamma_one_and_alpha_one() {
    // The printed constant is 0/0 at γ = 1 and α = 1; the evaluated one has no jump: the
    // mean of γ = 1 ± h agrees with γ = 1 to O(h²).
    let h = 1e-9;
    for &a in &[1e-4, 0.05, 0.5, 0.999] {
        let (lo, mid, hi) = (gtr(1.0 - h, a), gtr(1.0, a), gtr(1.0 + h, a));
        let e = rel_err(0.5 * (lo.c + hi.c), mid.c);
        assert!(e < 1e-13, "α={a}: c {} {} {}", lo.c, mid.c, hi.c);
        assert!(rel_err(lo.c, mid.c) < 1e-7 && rel_err(hi.c, mid.c) < 1e-7);
        for &theta in &[0.0, 0.7, 1.4] {
            let w = from_spherical(theta, 0.0);
            let e = rel_err(0.5 * (lo.d(w) + hi.d(w)), mid.d(w));
            assert!(e < 1e-12, "α={a} θ={theta}: D {e:e}");
            let e = rel_err(0.5 * (lo.lambda(w) + hi.lambda(w)), mid.lambda(w));
            assert!(theta == 0.0 || e < 1e-12, "α={a} θ={theta}: Λ {e:e}");
        }
        for &u in &[0.1, 0.5, 0.9] {
            let (c_lo, _) = lo.cos2_sin2(u);
            let (c_mid, _) = mid.cos2_sin2(u);
            let (c_hi, _) = hi.cos2_sin2(u);
            assert!(rel_err(0.5 * (c_lo + c_hi), c_mid) < 1e-12, "α={a} u={u}");
        }
    }
    // α → 1: D → 1/π and Λ → Λ⁰ for every γ.
    for &g in &[0.0, 0.5, 1.0, 2.0, 10.0] {
        let (near, at) = (gtr(g, 1.0 - 1e-9), gtr(g, 1.0));
        assert_eq!(at.c, 1.0 / PI);
        for &theta in &[0.0, 0.7, 1.4] {
            let w = from_spherical(theta, 0.0);
            assert!(rel_err(near.d(w), 1.0 / PI) < 1e-7 * (1.0 + g));
            assert!(rel_err(at.d(w), 1.0 / PI) < 1e-15);
            if theta > 0.0 {
                let l0 = routes::lambda_closed_form(0, 1.0, Gtr::mu(w));
                assert!(rel_err(at.lambda(w), l0) < 1e-12, "γ={g} θ={theta}");
                assert!(rel_err(near.lambda(w), l0) < 1e-7 * (1.0 + g));
            }
        }
        for &u in &[0.1, 0.9] {
            let (c_near, s_near) = near.cos2_sin2(u);
            assert!(
                (c_near - (1.0 - u)).abs() < 1e-7 * (1.0 + g)
                    && (s_near - u).abs() < 1e-7 * (1.0 + g)
            );
        }
    }
}

#[test]
fn p2_is_the_marginal_of_p22() {
    let mut worst: f64 = 0.0;
    for &g in &[0.0, 0.1, 0.5, 1.0, 1.5, 2.5, 4.0, 7.0, 10.0] {
        for &a in &[1e-3, 0.05, 0.3, 0.9, 1.0] {
            let m = gtr(g, a);
            for &q in &[0.0, 0.3 * a, a, 3.0 * a, 1.0, 10.0] {
                let want = conformance::p2_marginal(&m, q, 0.0, q.hypot(a));
                let e = rel_err(m.p2(q, 0.7), want);
                assert!(
                    e < 1e-11,
                    "γ={g} α={a} q={q}: P2 {} vs {want} ({e:e})",
                    m.p2(q, 0.0)
                );
                worst = worst.max(e);
            }
        }
    }
    eprintln!("GTR: max rel err of P2 against ∫ P22 dp: {worst:.2e}");
    // The P2 tail cπ/(2q³) makes every slope moment beyond ν₀ diverge.
    let m = gtr(3.0, 0.2);
    let q: f64 = 1e5;
    assert!(rel_err(m.p2(q, 0.0), m.c * PI / (2.0 * q.powi(3))) < 1e-8);
    assert_eq!(m.slope_moment(0, 0.0), Some(1.0));
    assert_eq!(m.slope_moment(1, 0.0), None);
    assert_eq!(m.variance(0.0), None);
    assert_eq!(m.excess_kurtosis(), None);
}

#[test]
fn printed_p22_and_p2_of_section_3_against_their_integrals() {
    let mut worst: f64 = 0.0;
    for k in 0..=4u8 {
        for &a in &[0.01, 0.3, 0.9] {
            let m = gtr(f64::from(k), a);
            for &q in &[0.0, 0.5 * a, 2.0 * a, 1.0, 7.0] {
                // P22 as printed equals the model's P22 (eq 42* applied to 1**).
                for &p in &[0.0, 0.3, 2.0] {
                    let e = rel_err(p22_printed(k, a, p * p + q * q), m.p22(p, q));
                    assert!(e < 1e-12, "P22^{k} α={a} p={p} q={q}: {e:e}");
                }
                // P2 as printed (with 4α²q² in §3.5) equals ∫ P22 dp.
                let want = conformance::p2_marginal(&m, q, 0.0, q.hypot(a));
                let e = rel_err(p2_printed(k, a, q, false), want);
                assert!(e < 1e-11, "P2^{k} α={a} q={q}: {e:e}");
                worst = worst.max(e);
            }
        }
    }
    eprintln!("seed 004 §3 P2^γ (γ = 0…4): max rel err against ∫ P22 dp: {worst:.2e}");
}

#[test]
fn erratum_p2_gamma4_printed_q2_read_literally_fails() {
    // ERRATA.md §1: §3.5 prints "4α²q2"; read literally (4α²·q·2) P2⁴ is not even in q
    // and misses ∫ P22 dp by percents. The corrected term 4α²q² agrees to 1e-11 (above).
    let a = 0.3;
    let m = gtr(4.0, a);
    let mut worst: f64 = 0.0;
    for &q in &[0.1, 0.5, 3.0] {
        let want = conformance::p2_marginal(&m, q, 0.0, q.hypot(a));
        let literal = p2_printed(4, a, q, true);
        let e = rel_err(literal, want);
        assert!(e > 1e-3, "the literal reading agreed at q={q}: {e:e}");
        worst = worst.max(e);
        assert!(rel_err(p2_printed(4, a, q, false), want) < 1e-11);
    }
    eprintln!("seed 004 §3.5 P2⁴ with '4α²q2' read as 8α²q: rel err up to {worst:.2e}");
}

/// θ for the checks against the (costly) nested-quadrature oracle: near normal incidence to
/// near grazing (μ from 1000 down to 8e-4); θ = 0 and π/2 are the end-point tests', smaller μ
/// the stability test's.
const ORACLE_THETAS: [f64; 5] = [1e-3, 0.3, 0.9, 1.3, 1.57];

fn assert_exact_route(gammas: &[f64]) -> f64 {
    let mut worst: f64 = 0.0;
    for &g in gammas {
        for &a in &[1e-3, 0.05, 0.3, 0.9] {
            let m = gtr(g, a);
            for &theta in &ORACLE_THETAS {
                let w = from_spherical(theta, 0.0);
                let got = m.lambda(w);
                let want = lambda_oracle(&m, a, theta);
                let e = rel_err(got, want);
                assert!(
                    e < 1e-12,
                    "γ={g} α={a} θ={theta}: Λ {got:e} vs {want:e} ({e:e})"
                );
                worst = worst.max(e);
                // Λ(−w) = −1 − Λ(w), G1 in [0, 1].
                let below = m.lambda([-w[0], -w[1], -w[2]]);
                assert!((below + 1.0 + got).abs() <= 1e-12 * (1.0 + got));
                let g1 = m.g1(w, [0.0, 0.0, 1.0]);
                assert!((0.0..=1.0).contains(&g1));
            }
        }
    }
    worst
}

#[test]
fn exact_lambda_matches_its_defining_integral_gamma_below_one() {
    let worst = assert_exact_route(&[0.0, 0.1, 0.5]);
    eprintln!("GTR exact Λ, γ < 1: max rel err against ∫(q−μ)P2: {worst:.2e}");
}

#[test]
fn exact_lambda_matches_its_defining_integral_gamma_near_one() {
    let worst = assert_exact_route(&[1.0 - 1e-6, 1.0, 1.0 + 1e-6, 1.5]);
    eprintln!("GTR exact Λ, γ ≈ 1: max rel err against ∫(q−μ)P2: {worst:.2e}");
}

#[test]
fn exact_lambda_matches_its_defining_integral_gamma_above_two() {
    let worst = assert_exact_route(&[2.5, 4.0, 7.0, 10.0]);
    eprintln!("GTR exact Λ, γ > 2: max rel err against ∫(q−μ)P2: {worst:.2e}");
}

#[test]
#[allow(clippy::excessive_precision)] // the reference values with all computed digits
fn exact_lambda_matches_high_precision_values() {
    // mpmath 1.3 (mp.dps = 25): the double integral of eq 48* over P22 of eq 1**
    // (reference/ERRATA.md, "High-precision values", has the script).
    let cases = [
        (0.5, 0.3, 0.2, 1.523_149_694_360_503_730_298),
        (2.5, 0.3, 0.2, 0.236_628_915_841_348_448_958_2),
        (7.0, 0.3, 0.2, 0.007_404_487_004_039_036_483_814),
        (0.5, 0.05, 1.0, 0.113_389_602_778_521_397_276_3),
        (7.0, 0.05, 0.02, 0.040_714_367_865_888_325_372_54),
    ];
    for (g, a, mu, want) in cases {
        let got = gtr(g, a).lambda_mu(mu);
        let e = rel_err(got, want);
        assert!(e < 1e-13, "γ={g} α={a} μ={mu}: {got} vs {want} ({e:e})");
    }
    // P2(0.1) from the same computation.
    for (g, a, want) in [
        (0.5, 0.3, 0.669_120_455_419_083_225_74),
        (2.5, 0.3, 1.652_287_331_788_768_399_5),
        (7.0, 0.3, 2.280_401_027_603_817_900_9),
        (0.5, 0.05, 0.857_231_623_538_377_077_23),
        (7.0, 0.05, 0.000_816_891_810_703_014_150_53),
    ] {
        let got = gtr(g, a).p2(0.1, 0.0);
        assert!(
            rel_err(got, want) < 1e-13,
            "P2 γ={g} α={a}: {got} vs {want}"
        );
    }
}

#[test]
fn closed_form_routes_match_the_integral_of_the_printed_p2() {
    let mut worst_closed: f64 = 0.0;
    let mut worst_printed: [f64; 5] = [0.0; 5];
    for k in 0..=4u8 {
        for &a in &[1e-3, 0.05, 0.3, 0.9] {
            let m = gtr(f64::from(k), a);
            let oracle = PrintedP2 { k, alpha: a };
            for &theta in &THETAS {
                let w = from_spherical(theta, 0.0);
                let want = lambda_oracle(&oracle, a, theta);
                let closed = m.lambda_route(w, "closed_form").unwrap();
                let e = rel_err(closed, want);
                assert!(
                    e < 1e-10,
                    "closed_form γ={k} α={a} θ={theta}: {closed:e} vs {want:e} ({e:e})"
                );
                worst_closed = worst_closed.max(e);
                // The exact route against the same oracle.
                let e = rel_err(m.lambda(w), want);
                assert!(e < 1e-10, "exact γ={k} α={a} θ={theta}: {e:e}");
                // As printed: correct, but the arithmetic cancels as μ/α grows. Asserted
                // where the cancellation costs less than 1e-10; measured everywhere.
                let printed = m.lambda_route(w, "closed_form_printed").unwrap();
                let e = rel_err(printed, want);
                let mu = Gtr::mu(w);
                if mu <= a {
                    assert!(e < 1e-10, "printed γ={k} α={a} θ={theta}: {e:e}");
                }
                worst_printed[k as usize] = worst_printed[k as usize].max(e);
            }
        }
    }
    eprintln!("closed_form: max rel err against ∫(q−μ)P2^γ: {worst_closed:.2e}");
    eprintln!(
        "closed_form_printed (γ = 0…4), max rel err over the grid incl. μ ≫ α: {worst_printed:?}"
    );
}

#[test]
fn implementation_g1_forms_match_the_exact_route() {
    let mut worst: f64 = 0.0;
    for k in 0..=4u8 {
        for &a in &[1e-4, 1e-3, 0.05, 0.3, 0.9, 0.999] {
            let m = gtr(f64::from(k), a);
            for &theta in &THETAS {
                let w = from_spherical(theta, 0.0);
                let exact = m.g1_route(w, "exact").unwrap();
                let g1 = m.g1_route(w, "implementation").unwrap();
                let e = rel_err(g1, exact);
                // G1¹ divides log(α²(μ+B)/(μ+A)) by μ log α²: near α = 1 both are small
                // and the logarithm of a number near 1 loses ≈ 1e-16/|log α²| relatively.
                let tol = if k == 1 {
                    1e-12 + 1e-15 / (2.0 * a.ln()).abs()
                } else {
                    1e-12
                };
                assert!(e < tol, "γ={k} α={a} θ={theta}: G1 {g1} vs {exact} ({e:e})");
                worst = worst.max(e);
            }
        }
    }
    eprintln!("implementation G1 (γ = 0…4): max rel err against the exact route: {worst:.2e}");
    assert!(gtr(1.0, 1.0)
        .lambda_route([0.6, 0.0, 0.8], "implementation")
        .is_err());
    assert!(gtr(1.0, 1.0)
        .lambda_route([0.6, 0.0, 0.8], "closed_form_printed")
        .is_err());
    assert!(gtr(1.0, 1.0)
        .lambda_route([0.6, 0.0, 0.8], "closed_form")
        .is_ok());
}

/// The error of the spline route in G1 over a grid: max |ΔG1| with where it occurs
/// (γ, α, μ), mean |ΔG1|, and max |ΔG1|/G1.
struct SplineError {
    max_abs: f64,
    at: (f64, f64, f64),
    mean_abs: f64,
    max_rel: f64,
}

fn spline_error(gammas: &[f64], alphas: &[f64], mus: &[f64]) -> SplineError {
    let mut r = SplineError {
        max_abs: 0.0,
        at: (0.0, 0.0, 0.0),
        mean_abs: 0.0,
        max_rel: 0.0,
    };
    let mut n = 0;
    for &a in alphas {
        for &mu in mus {
            let w = [1.0 / mu.hypot(1.0), 0.0, mu / mu.hypot(1.0)];
            for &g in gammas {
                let m = gtr(g, a);
                let exact = m.g1_route(w, "exact").unwrap();
                let spline = m.g1_route(w, "spline").unwrap();
                let e = (spline - exact).abs();
                if e > r.max_abs {
                    r.max_abs = e;
                    r.at = (g, a, mu);
                }
                r.max_rel = r.max_rel.max(e / exact);
                r.mean_abs += e;
                n += 1;
            }
        }
    }
    r.mean_abs /= n as f64;
    r
}

fn report(label: &str, r: &SplineError) {
    eprintln!(
        "spline {label}: max |ΔG1| = {:.3e} at (γ, α, μ) = {:?}, mean |ΔG1| = {:.6e}, max |ΔG1|/G1 = {:.3e}",
        r.max_abs, r.at, r.mean_abs, r.max_rel
    );
}

#[test]
fn spline_in_gamma_error_against_the_exact_route() {
    // Document 004 §5 claims "ca. 0.1 %" ("mean difference 0.001" in G1); its plots cover
    // α ∈ (0.1, 0.5), μ ∈ (0, 5). Measured on that domain and on α ∈ [0.01, 0.99].
    let inner: Vec<f64> = (1..40)
        .map(|i| i as f64 * 0.1)
        .filter(|g| (g - g.round()).abs() > 1e-9)
        .collect();
    let mus: Vec<f64> = (1..=50).map(|i| i as f64 * 0.1).collect();
    let plot_alphas = [0.1, 0.2, 0.3, 0.4, 0.5];
    let wide_alphas = [0.01, 0.05, 0.1, 0.3, 0.5, 0.7, 0.9, 0.99];
    let plot = spline_error(&inner, &plot_alphas, &mus);
    report("0 < γ < 4, α ∈ [0.1, 0.5], μ ∈ [0.1, 5]", &plot);
    let wide = spline_error(&inner, &wide_alphas, &[0.01, 0.05, 0.1, 0.3, 1.0, 3.0]);
    report("0 < γ < 4, α ∈ [0.01, 0.99], μ ∈ [0.01, 3]", &wide);
    let knots = spline_error(&[0.0, 1.0, 2.0, 3.0, 4.0], &wide_alphas, &[0.01, 0.3, 3.0]);
    assert!(knots.max_abs < 1e-12, "knots: {:e}", knots.max_abs);
    // γ > 4 is G1⁴ (§6).
    let clamp = spline_error(&[4.5, 5.0, 6.0, 7.0, 8.0, 10.0], &plot_alphas, &mus);
    report(
        "γ ∈ [4.5, 10] (clamped to 4), α ∈ [0.1, 0.5], μ ∈ [0.1, 5]",
        &clamp,
    );
    for &g in &[4.5, 10.0] {
        let w = from_spherical(0.9, 0.0);
        let clamped = gtr(g, 0.3).g1_route(w, "spline").unwrap();
        assert_eq!(clamped, gtr(4.0, 0.3).g1_route(w, "spline").unwrap());
    }
    // ERRATA.md E3: "ca. 0.1 %" holds as a mean over the document's plot domain, not as a
    // maximum (an expected failure of the claim read as a bound).
    assert!(
        plot.mean_abs < 1e-3,
        "the mean claim fails: {:e}",
        plot.mean_abs
    );
    assert!(
        plot.max_abs > 1e-2,
        "the claim held as a maximum: {:e}",
        plot.max_abs
    );
    // What was measured (with margin), recorded in ERRATA.md.
    assert!(plot.max_abs < SPLINE_PLOT_MAX_ABS && plot.mean_abs < SPLINE_PLOT_MEAN_ABS);
    assert!(wide.max_abs < SPLINE_WIDE_MAX_ABS && wide.mean_abs < SPLINE_WIDE_MEAN_ABS);
    assert!(clamp.max_abs < SPLINE_CLAMP_MAX_ABS);
}

// Measured: 2.85e-2, 4.56e-4, 1.68e-1, 4.72e-3, 2.83e-1.
const SPLINE_PLOT_MAX_ABS: f64 = 0.035;
const SPLINE_PLOT_MEAN_ABS: f64 = 6e-4;
const SPLINE_WIDE_MAX_ABS: f64 = 0.2;
const SPLINE_WIDE_MEAN_ABS: f64 = 6e-3;
const SPLINE_CLAMP_MAX_ABS: f64 = 0.3;

#[test]
fn erratum_section_4_convergence_claim_is_false_as_printed() {
    // ERRATA.md §2: §4 says "All height fields converge to G1⁰ when μ → 1 and α → 0".
    // At μ = 1 and α → 0, G1^γ → 1 for γ ≥ 1 (slowly: Λ¹ ~ 1/|log α²|), while G1⁰(1) =
    // 2/(1 + √2) ≈ 0.83 does not depend on α.
    let w = from_spherical(std::f64::consts::FRAC_PI_4, 0.0); // μ = 1
    let g1_0 = 2.0 / (1.0 + 2f64.sqrt());
    assert!(rel_err(gtr(0.0, 1e-4).g1(w, [0.0, 0.0, 1.0]), g1_0) < 1e-12);
    for k in 1..=4 {
        let g1 = gtr(f64::from(k), 1e-4).g1(w, [0.0, 0.0, 1.0]);
        assert!(g1 - g1_0 > 0.15, "γ={k}: G1 = {g1} (G1⁰ = {g1_0})");
    }
    // What holds: at α = 1 every G1^γ is G1⁰ (D ≡ 1/π), for every μ; and G1 → 1 as μ → ∞.
    for &theta in &[0.2, 0.9, 1.5] {
        let w = from_spherical(theta, 0.0);
        let reference = gtr(0.0, 1.0).g1(w, [0.0, 0.0, 1.0]);
        for &g in &[0.5, 1.0, 3.0, 10.0] {
            let near = gtr(g, 1.0 - 1e-6).g1(w, [0.0, 0.0, 1.0]);
            assert!(rel_err(near, reference) < 1e-5, "γ={g} θ={theta}");
        }
    }
}

#[test]
fn section_6_difference_between_gamma_4_and_10() {
    // §6: "|G1⁴ − G1¹⁰| multiplied 10x with α ∈ (0, 1) and μ ∈ (0, 2) … the biggest difference
    // is in μ ∈ (0, 1) and it's up to 0.3". Measured on the unmagnified difference.
    let (mut worst, mut at) = (0.0f64, (0.0, 0.0));
    for i in 1..100 {
        let a = i as f64 * 0.01;
        let (g4, g10) = (gtr(4.0, a), gtr(10.0, a));
        for j in 1..=40 {
            let mu = j as f64 * 0.05;
            let w = [1.0 / mu.hypot(1.0), 0.0, mu / mu.hypot(1.0)];
            let d = (g4.g1(w, [0.0, 0.0, 1.0]) - g10.g1(w, [0.0, 0.0, 1.0])).abs();
            if d > worst {
                (worst, at) = (d, (a, mu));
            }
        }
    }
    eprintln!("§6: max |G1⁴ − G1¹⁰| = {worst:.4} at (α, μ) = {at:?}");
    assert!(
        worst > 0.25 && worst < 0.35 && at.1 < 1.0,
        "{worst} at {at:?}"
    );
}

#[test]
fn end_points_of_every_route() {
    let zenith = [0.0, 0.0, 1.0];
    let horizon = from_spherical(FRAC_PI_2, 0.3);
    for &g in &[0.0, 1.0, 2.5, 4.0, 10.0] {
        for &a in &[1e-4, 0.3, 1.0] {
            let m = gtr(g, a);
            for route in m.lambda_routes() {
                let Ok(l0) = m.lambda_route(zenith, route) else {
                    continue;
                };
                assert_eq!(l0, 0.0, "γ={g} α={a} {route}: Λ(θ=0)");
                assert_eq!(m.g1_route(zenith, route).unwrap(), 1.0);
                assert_eq!(m.g1_route(horizon, route).unwrap(), 0.0, "{route}: G1(π/2)");
                assert_eq!(m.lambda_route(horizon, route).unwrap(), f64::INFINITY);
                let w = from_spherical(1.1, 0.0);
                let (up, down) = (
                    m.lambda_route(w, route).unwrap(),
                    m.lambda_route([-w[0], -w[1], -w[2]], route).unwrap(),
                );
                assert!((down + 1.0 + up).abs() < 1e-12, "{route}: Λ(−w)");
            }
            assert_eq!(m.lambda(zenith), 0.0);
            assert_eq!(m.g1(horizon, zenith), 0.0);
            assert_eq!(m.lambda([0.0, 0.0, -1.0]), -1.0);
        }
    }
}

#[test]
fn routes_are_restricted_in_gamma() {
    let m = gtr(2.5, 0.3);
    let w = from_spherical(0.8, 0.0);
    for route in ["closed_form", "closed_form_printed", "implementation"] {
        assert!(matches!(
            m.lambda_route(w, route),
            Err(QueryError::Route { .. })
        ));
    }
    assert!(m.lambda_route(w, "spline").is_ok());
    assert!(m.lambda_route(w, "default").is_ok());
    let e = m.lambda_route(w, "nope").unwrap_err();
    assert!(e.to_string().contains("exact"), "{e}");
    assert_eq!(m.lambda_routes()[0], "exact");
}

#[test]
fn sampler_density_is_d_cos() {
    for &g in &[0.0, 0.5, 1.0, 1.0 + 1e-9, 2.0, 4.0, 10.0] {
        for &a in &[1e-3, 0.3, 0.9, 1.0] {
            assert_sampler_density(&gtr(g, a), 2e-5, &format!("gtr γ={g} α={a}"));
        }
    }
}

#[test]
fn sampler_round_trips_through_the_cdf() {
    // F(θ) = (α^{2s} − (sin²θ + α²cos²θ)^s)/(α^{2s} − 1), s = 1 − γ (s → 0: log ratio).
    for &g in &[0.0, 0.5, 1.0, 3.0, 10.0] {
        for &a in &[1e-3, 0.3, 0.999] {
            let m = gtr(g, a);
            let l = 2.0 * f64::ln(a);
            for &u in &[[0.1, 1e-6], [0.45, 0.2], [0.8, 0.5], [0.99, 0.999]] {
                let w = m.sample_wm(u);
                let u1 = conformance::azimuth(w) / std::f64::consts::TAU;
                let ell = (w[0] * w[0] + w[1] * w[1] + a * a * w[2] * w[2]).ln();
                let s = 1.0 - g;
                let u2 = if s == 0.0 {
                    (l - ell) / l
                } else {
                    ((s * l).exp() - (s * ell).exp()) / (s * l).exp_m1()
                };
                assert!((u1 - u[0]).abs() < 1e-12, "γ={g} α={a} u={u:?}: u1 {u1}");
                assert!(rel_err(u2, u[1]) < 1e-6, "γ={g} α={a} u={u:?}: u2 {u2}");
            }
        }
    }
}

#[test]
fn parameters_are_validated() {
    for g in [-1e-12, 10.0 + 1e-9, f64::NAN, f64::INFINITY] {
        assert!(
            matches!(Gtr::new(g, 0.3), Err(ParamError::GammaOutOfRange { .. })),
            "{g}"
        );
    }
    for a in [0.0, -0.1, f64::NAN, f64::INFINITY] {
        assert!(
            matches!(Gtr::new(2.0, a), Err(ParamError::AlphaNotPositive { .. })),
            "{a}"
        );
    }
    for a in [9.9e-5, 1.0 + 1e-12, 2.0] {
        assert!(
            matches!(Gtr::new(2.0, a), Err(ParamError::OutOfRange { .. })),
            "{a}"
        );
    }
    for (g, a) in [(0.0, 1e-4), (10.0, 1.0), (1.0, 0.5)] {
        assert!(Gtr::new(g, a).is_ok());
    }
}

#[test]
fn stable_at_the_edges_of_the_domain() {
    for &g in &[0.0, 1e-9, 1e-3, 1.0, 10.0 - 1e-9, 10.0] {
        for &a in &[1e-4, 0.5, 1.0] {
            let m = gtr(g, a);
            for &theta in &[
                0.0,
                1e-8,
                0.5,
                FRAC_PI_2 - 1e-4,
                FRAC_PI_2 - 1e-12,
                FRAC_PI_2,
            ] {
                let w = from_spherical(theta, 0.3);
                let d = m.d(w);
                assert!(
                    d.is_finite() && (d > 0.0 || w[2] == 0.0),
                    "γ={g} α={a} θ={theta}: D = {d}"
                );
                let p = m.pdf_wm(w);
                assert!(p.is_finite() && p >= 0.0);
                let l = m.lambda(w);
                assert!(!l.is_nan() && l >= 0.0, "γ={g} α={a} θ={theta}: Λ = {l}");
                let g1 = m.g1(w, [0.0, 0.0, 1.0]);
                assert!(
                    (0.0..=1.0).contains(&g1),
                    "γ={g} α={a} θ={theta}: G1 = {g1}"
                );
                let s = m.lambda_route(w, "spline").unwrap();
                assert!(!s.is_nan(), "spline γ={g} α={a} θ={theta}");
                let (p, q) = (w[0] / w[2], w[1] / w[2]);
                if w[2] > 0.0 {
                    assert!(m.p22(p, q).is_finite() && m.p2(q, 0.0).is_finite());
                }
            }
            // Λ keeps growing like 1/μ down to μ of denormal size.
            for &mu in &[1e-90, 1e-101, 1e-200, 1e-300] {
                let l = m.lambda_mu(mu);
                assert!(l > 0.0 && !l.is_nan(), "γ={g} α={a} μ={mu}: {l}");
                let l2 = m.lambda_mu(2.0 * mu);
                assert!(
                    rel_err(l2 + 0.5, 0.5 * (l + 0.5)) < 1e-9,
                    "1/μ scaling at {mu}"
                );
            }
            for &mu in &[1e8, 1e10, 1e200] {
                let l = m.lambda_mu(mu);
                assert!(
                    rel_err(l, m.c * PI / (4.0 * mu * mu)) < 1e-12 || l < 1e-300,
                    "μ={mu}"
                );
            }
            for &u in &[[0.0, 0.0], [0.3, 1e-300], [0.3, 0.999_999_999], [0.99, 0.5]] {
                let w = m.sample_wm(u);
                assert!(w.iter().all(|c| c.is_finite()) && w[2] >= 0.0, "{w:?}");
                assert!((w[0].hypot(w[1]).hypot(w[2]) - 1.0).abs() < 1e-14);
            }
        }
    }
}

/// The accuracy table of document 004: for every route, the max relative error
/// against an independent numerical integral over a grid of γ (columns), α and θ.
///
/// Oracles: Λ from its definition (eq 48*), (1/μ)∫_μ^∞ (q − μ) P2(q) dq by
/// double-exponential quadrature (`conformance::lambda_integral`), with P2 the printed
/// closed form P2^γ of §3.1–3.5 at γ ∈ {0, 1, 2, 3, 4} and the model's P2 (the Euler
/// integral of eq 43*, itself checked against ∫ P22 dp by `p2_is_the_marginal_of_p22`)
/// elsewhere; G1 = 1/(1 + Λ_oracle); the normalization ∫ D cos θ dω by quadrature; the
/// sampler by F(θ(u)) = 2π∫_0^θ D cos t sin t dt against u. Grid: α ∈ {1e-4, 1e-3, 0.05,
/// 0.3, 0.9, 1 − 1e-6, 1}, θ ∈ {1e-6, 1e-3, 0.05, 0.3, 0.9, 1.3, 1.5, 1.57, π/2 − 1e-6}.
/// Run: `MFH_EXTENSIVE=1 cargo test -p mfh-reference --release accuracy_table_gtr -- --nocapture`.
mod accuracy_table {
    use super::*;
    use crate::test_support::{integrate, tline, ReportTable};
    use std::f64::consts::TAU;

    const TABLE_GAMMAS: [f64; 13] = [
        0.0,
        1e-6,
        0.5,
        1.0 - 1e-6,
        1.0,
        1.0 + 1e-6,
        1.5,
        2.0,
        3.0,
        4.0,
        5.0,
        7.0,
        10.0,
    ];
    const TABLE_ALPHAS: [f64; 7] = [1e-4, 1e-3, 0.05, 0.3, 0.9, 1.0 - 1e-6, 1.0];
    const TABLE_THETAS: [f64; 9] = [1e-6, 1e-3, 0.05, 0.3, 0.9, 1.3, 1.5, 1.57, FRAC_PI_2 - 1e-6];

    /// Λ by the oracle at (γ, α, θ).
    fn oracle(g: f64, a: f64, theta: f64) -> f64 {
        match routes::integer_gamma(g) {
            Some(k) if !(k == 1 && a == 1.0) => lambda_oracle(&PrintedP2 { k, alpha: a }, a, theta),
            _ => lambda_oracle(&gtr(g, a), a, theta),
        }
    }

    /// F(θ) = 2π ∫_0^θ D(t) cos t sin t dt, cut at multiples of α (the width of D).
    fn cdf_theta(m: &Gtr, theta: f64) -> f64 {
        let f = |t: f64| m.d(from_spherical(t, 0.0)) * t.cos() * t.sin();
        let mut cuts = vec![0.0];
        cuts.extend(
            [0.1, 1.0, 10.0, 100.0, 1e3]
                .iter()
                .map(|k| (k * m.alpha()).atan())
                .filter(|&c| c < theta),
        );
        cuts.push(theta);
        TAU * cuts
            .windows(2)
            .map(|w| integrate(&f, w[0], w[1], 1e-14, 1e-300).0)
            .sum::<f64>()
    }

    fn cell(e: Option<f64>) -> String {
        match e {
            Some(e) => format!("{e:.1e}"),
            None => "—".to_string(),
        }
    }

    #[test]
    #[cfg_attr(not(mfh_extensive), ignore = "extensive tier: set MFH_EXTENSIVE=1")]
    fn accuracy_table_gtr() {
        let mut out = ReportTable::new("document004");
        // route label, quantity compared ("Λ" or "G1").
        let rows = [
            ("exact", "Λ"),
            ("closed_form", "Λ"),
            ("closed_form_printed", "Λ"),
            ("implementation", "G1"),
            ("spline", "G1"),
            ("exact", "G1"),
        ];
        let mut table = vec![vec![None::<f64>; TABLE_GAMMAS.len()]; rows.len()];
        let mut norm = vec![0.0f64; TABLE_GAMMAS.len()];
        let mut sampler = vec![0.0f64; TABLE_GAMMAS.len()];
        // The spline's |ΔG1| (the document's "mean difference 0.001" is absolute): max.
        let mut spline_abs = vec![0.0f64; TABLE_GAMMAS.len()];
        for (j, &g) in TABLE_GAMMAS.iter().enumerate() {
            for &a in &TABLE_ALPHAS {
                let m = gtr(g, a);
                norm[j] =
                    norm[j].max((conformance::normalization_isotropic(&|w| m.d(w), a) - 1.0).abs());
                for &u in &[1e-9, 1e-3, 0.1, 0.5, 0.9, 0.999, 1.0 - 1e-9] {
                    let w = m.sample_wm([0.3, u]);
                    let theta = w[0].hypot(w[1]).atan2(w[2]);
                    sampler[j] = sampler[j].max((cdf_theta(&m, theta) - u).abs());
                }
                for &theta in &TABLE_THETAS {
                    let w = from_spherical(theta, 0.0);
                    let want = oracle(g, a, theta);
                    let g1_want = 1.0 / (1.0 + want);
                    let spline = m.g1_route(w, "spline").unwrap();
                    spline_abs[j] = spline_abs[j].max((spline - g1_want).abs());
                    for (i, &(route, quantity)) in rows.iter().enumerate() {
                        let got = if quantity == "Λ" {
                            m.lambda_route(w, route).map(|l| rel_err(l, want))
                        } else {
                            m.g1_route(w, route).map(|x| rel_err(x, g1_want))
                        };
                        if let Ok(e) = got {
                            let e = if e.is_nan() { f64::INFINITY } else { e };
                            table[i][j] = Some(table[i][j].unwrap_or(0.0).max(e));
                        }
                    }
                }
            }
        }
        tline!(
            out,
            "| quantity | route | {} |",
            TABLE_GAMMAS.map(|g| format!("γ={g}")).join(" | ")
        );
        tline!(out, "|---|---|{}", "---|".repeat(TABLE_GAMMAS.len()));
        tline!(
            out,
            "| ∫D cos θ dω − 1 (abs) | eq 1**, 4** | {} |",
            norm.iter()
                .map(|&e| cell(Some(e)))
                .collect::<Vec<_>>()
                .join(" | ")
        );
        tline!(
            out,
            "| sample_wm: \\|F(θ(u)) − u\\| (abs) | Burley inversion | {} |",
            sampler
                .iter()
                .map(|&e| cell(Some(e)))
                .collect::<Vec<_>>()
                .join(" | ")
        );
        for (i, (route, quantity)) in rows.iter().enumerate() {
            tline!(
                out,
                "| {quantity} (rel) | `{route}` | {} |",
                table[i]
                    .iter()
                    .map(|&e| cell(e))
                    .collect::<Vec<_>>()
                    .join(" | ")
            );
        }
        tline!(
            out,
            "| G1 (abs) | `spline` | {} |",
            spline_abs
                .iter()
                .map(|&e| cell(Some(e)))
                .collect::<Vec<_>>()
                .join(" | ")
        );
        out.check_report();
        // What the table must show: the default route and the rearranged closed forms at
        // 1e-10 everywhere; the printed forms fail where they cancel (γ = 3, 4); the
        // spline's claimed 0.1 % fails as a bound off the knots.
        let col = |g: f64| TABLE_GAMMAS.iter().position(|&x| x == g).unwrap();
        assert!(norm.iter().all(|&e| e < 1e-10), "{norm:?}");
        assert!(sampler.iter().all(|&e| e < 1e-9), "{sampler:?}");
        assert!(
            table[0].iter().all(|e| e.unwrap() < 1e-10),
            "exact {:?}",
            table[0]
        );
        assert!(
            table[5].iter().all(|e| e.unwrap() < 1e-10),
            "exact G1 {:?}",
            table[5]
        );
        for g in [0.0, 1.0, 2.0, 3.0, 4.0] {
            assert!(table[1][col(g)].unwrap() < 1e-10, "closed_form γ={g}");
            // G1¹ loses ≈ 1e-16/|log α²| near α = 1 (5e-11 at α = 1 − 1e-6).
            assert!(table[3][col(g)].unwrap() < 1e-9, "implementation γ={g}");
            assert!(table[4][col(g)].unwrap() < 1e-10, "spline knot γ={g}");
        }
        assert!(table[2][col(4.0)].unwrap() > 1.0, "printed γ = 4 cancels");
        assert!(table[4][col(1.5)].unwrap() > 1e-3, "spline off the knots");
        assert!(spline_abs[col(1.5)] > 1e-2 && spline_abs[col(7.0)] > 0.1);
        assert!(table[1][col(1.5)].is_none() && table[2][col(1.5)].is_none());
    }
}
