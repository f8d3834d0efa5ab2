use super::*;
use mfh_reference::ndf::Ggx;
use mfh_reference::{Model, ModelSpec};
use std::f64::consts::PI;

fn model(json: &str) -> Box<dyn Model> {
    serde_json::from_str::<ModelSpec>(json)
        .unwrap()
        .build()
        .unwrap()
}

fn config(samples: u64, seed: u64) -> KsConfig {
    KsConfig {
        samples,
        seed,
        alpha: 1e-4,
    }
}

fn hints(width: f64) -> LobeHints<'static> {
    LobeHints {
        width,
        theta_kinks: &[],
    }
}

fn report(name: &str, r: &KsResult) {
    eprintln!(
        "{name} {:?}: D = {:.3e}, λ = {:.3}, p = {:.4}, knots {}, table bound {:.1e}, \
         mass {:.12}, {} pdf evaluations, table {:.3} s, sampling {:.3} s",
        r.marginal,
        r.statistic,
        r.lambda,
        r.p_value,
        r.knots,
        r.table_error_bound,
        r.pdf_mass,
        r.evaluations,
        r.table_seconds,
        r.sampling_seconds
    );
}

#[test]
fn ks_kolmogorov_distribution_values() {
    // P(K ≤ 1) = 0.730000328322645…; the critical values of K at 0.05, 0.01 and 0.001
    // (the 99-term series in double precision, solved by bisection).
    assert!((kolmogorov_q(1.0) - 0.269_999_671_677_354_56).abs() < 1e-14);
    for (lambda, p) in [
        (1.358_098_639_322_550_5, 0.05),
        (1.627_623_611_518_950_2, 0.01),
        (1.949_474_603_504_375, 0.001),
    ] {
        assert!((kolmogorov_q(lambda) / p - 1.0).abs() < 1e-9, "{lambda}");
    }
    // The two series agree across their switch point.
    let series_small = |l: f64| {
        let y = (-PI * PI / (8.0 * l * l)).exp();
        1.0 - (TAU.sqrt() / l) * [1, 9, 25, 49, 81].iter().map(|&k| y.powi(k)).sum::<f64>()
    };
    let series_large = |l: f64| {
        let x = (-2.0 * l * l).exp();
        2.0 * (1..=10)
            .map(|k: i32| f64::from(if k % 2 == 1 { 1 } else { -1 }) * x.powi(k * k))
            .sum::<f64>()
    };
    for l in [0.9, 1.1, 1.18, 1.3, 1.6] {
        assert!((series_small(l) - series_large(l)).abs() < 1e-15, "{l}");
    }
    assert_eq!(kolmogorov_q(0.0), 1.0);
    assert_eq!(kolmogorov_q(-1.0), 1.0);
    assert!(kolmogorov_q(f64::NAN).is_nan());
    assert!(kolmogorov_q(0.1) > 0.999_999_999);
    assert!(kolmogorov_q(10.0) < 1e-80 && kolmogorov_q(10.0) > 0.0);
    // Stephens' λ at N = 10⁶: ≈ √N·D.
    assert!((stephens_lambda(1e-3, 1_000_000) - 1.000_120_11).abs() < 1e-12);
}

#[test]
fn ks_cdf_tables_match_closed_forms() {
    // Every table's error is within its stated bound (with a factor 10 for a bound that is an
    // estimate), and the bound is below 5e-7, ≥ 6× under the 3.2e-6 the test needs at 10⁷
    // samples (QUADRATURE_TOLERANCE says why 1e-7 tolerances suffice).
    let within = |error: f64, t: &CdfTable| {
        error <= 10.0 * t.error_bound().max(1e-12) && t.error_bound() < 5e-7
    };
    // Uniform on the hemisphere: F_θ = 1 − cos θ, F_φ = φ/2π.
    let uniform = |m: Vec3| if m[2] >= 0.0 { 1.0 / TAU } else { 0.0 };
    let t = marginal_cdf(&uniform, Marginal::CosTheta, &hints(0.3));
    let p = marginal_cdf(&uniform, Marginal::Phi, &hints(0.3));
    for x in [0.0, 1e-3, 0.1, 0.7, 1.2, 1.5, FRAC_PI_2] {
        let e = (t.cdf(x) - (1.0 - x.cos())).abs();
        assert!(within(e, &t), "{x}: {e:.2e}, bound {:.2e}", t.error_bound());
        let e = (p.cdf(4.0 * x) - 4.0 * x / TAU).abs();
        assert!(within(e, &p), "{x}: {e:.2e}, bound {:.2e}", p.error_bound());
    }
    // GGX: P(θ ≤ t) = tan²t / (α² + tan²t); anisotropic: P(φ ≤ p) = atan((α_x/α_y) tan p)/2π
    // on the first quadrant.
    for alpha in [0.3, 0.05] {
        let g = Ggx::new(alpha, alpha).unwrap();
        let t = marginal_cdf(&|m| g.pdf_wm(m), Marginal::CosTheta, &hints(alpha.atan()));
        let mut worst = 0.0f64;
        for i in 0..=1000 {
            let x = FRAC_PI_2 * f64::from(i) / 1000.0;
            let tan2 = x.tan().powi(2);
            let want = if i == 1000 {
                1.0
            } else {
                tan2 / (alpha * alpha + tan2)
            };
            worst = worst.max((t.cdf(x) - want).abs());
        }
        eprintln!(
            "GGX α = {alpha}: {} knots, bound {:.2e}, worst {worst:.2e}, {} evaluations",
            t.knots(),
            t.error_bound(),
            t.evaluations
        );
        assert!(within(worst, &t));
    }
    let g = Ggx::new(0.1, 0.4).unwrap();
    let p = marginal_cdf(&|m| g.pdf_wm(m), Marginal::Phi, &hints(0.1f64.atan()));
    for i in 0..=100 {
        let x = 0.5 * PI * f64::from(i) / 100.0;
        let want = if i == 100 {
            0.25
        } else {
            (0.25 * x.tan()).atan() / TAU
        };
        assert!(
            within((p.cdf(x) - want).abs(), &p),
            "{x}: {} {want}",
            p.cdf(x)
        );
    }
    assert!((p.total() - 1.0).abs() < 1e-7);
}

fn passes(json: &str, samples: u64) {
    let m = model(json);
    let s = m.as_sampler().unwrap();
    let width = crate::subject::spec_width(&m.spec());
    for marginal in [Marginal::CosTheta, Marginal::Phi] {
        let r = ks_test_sampler(s, marginal, &hints(width), &config(samples, 7));
        report(json, &r);
        assert_eq!(r.verdict, TestOutcome::Pass, "{:?}", r.reason);
        assert!(r.p_value > 1e-3, "{r:?}");
    }
}

#[test]
fn ks_correct_samplers_pass() {
    passes(r#"{"family":"ggx","alpha":0.3}"#, 1_000_000);
    passes(r#"{"family":"ggx","alpha_x":0.1,"alpha_y":0.4}"#, 1_000_000);
    passes(r#"{"family":"beckmann","alpha":0.3}"#, 1_000_000);
}

#[test]
fn ks_defects_of_one_percent_fail() {
    // The sampler of α·1.02 against the pdf of α: D ≈ 0.02·max 2F(1 − F) = 0.01.
    let sampler = Ggx::new(0.306, 0.306).unwrap();
    let pdf = Ggx::new(0.3, 0.3).unwrap();
    let h = hints(0.3f64.atan());
    let r = ks_test(
        &|u| sampler.sample_wm(u),
        &|m| pdf.pdf_wm(m),
        Marginal::CosTheta,
        &h,
        &config(1_000_000, 7),
    );
    report("α·1.02", &r);
    assert_eq!(r.verdict, TestOutcome::Fail);
    assert!(r.p_value < 1e-12, "{r:?}");
    assert!(matches!(r.reason, Some(Failure::Rejected { .. })));
    // φ = 2π·(1.01 u₁ mod 1) (GGX maps u₁ to the azimuth): 1 % of the azimuths wrapped
    // back onto [0, 0.02π].
    let g = Ggx::new(0.3, 0.3).unwrap();
    let stretched = |u: [f64; 2]| g.sample_wm([(1.01 * u[0]).fract(), u[1]]);
    let r = ks_test(
        &stretched,
        &|m| g.pdf_wm(m),
        Marginal::Phi,
        &h,
        &config(1_000_000, 7),
    );
    report("φ stretched 1 %", &r);
    assert!(r.p_value < 1e-12, "{r:?}");
    // The θ marginal of the φ defect is right: that test passes.
    let r = ks_test(
        &stretched,
        &|m| g.pdf_wm(m),
        Marginal::CosTheta,
        &h,
        &config(1_000_000, 7),
    );
    assert_eq!(r.verdict, TestOutcome::Pass, "{r:?}");
}

#[test]
fn ks_sanity_failures() {
    let g = Ggx::new(0.3, 0.3).unwrap();
    let h = hints(0.3);
    let flipped = |u: [f64; 2]| {
        let m = g.sample_wm(u);
        if u[0] < 0.01 {
            [m[0], m[1], -m[2]]
        } else {
            m
        }
    };
    let r = ks_test(
        &flipped,
        &|m| g.pdf_wm(m),
        Marginal::Phi,
        &h,
        &config(10_000, 3),
    );
    assert!(matches!(
        r.reason,
        Some(Failure::OutsideHemisphere(
            crate::oracle::chi2::OutsideHemisphere {
                error: DirectionError::BelowHorizon(_),
                ..
            }
        ))
    ));
    let half = ks_test(
        &|u| g.sample_wm(u),
        &|m| 0.5 * g.pdf_wm(m),
        Marginal::CosTheta,
        &h,
        &config(10_000, 3),
    );
    assert!(
        matches!(half.reason, Some(Failure::MassOff { .. })),
        "{half:?}"
    );
    let negative = ks_test(
        &|u| g.sample_wm(u),
        &|m| -g.pdf_wm(m),
        Marginal::CosTheta,
        &h,
        &config(10_000, 3),
    );
    assert!(
        matches!(negative.reason, Some(Failure::InvalidDensity { .. })),
        "{negative:?}"
    );
    // The double-exponential rule reads a NaN integrand as 0: a NaN pdf has mass 0.
    let nan = ks_test(
        &|u| g.sample_wm(u),
        &|_| f64::NAN,
        Marginal::CosTheta,
        &h,
        &config(10_000, 3),
    );
    assert!(
        matches!(nan.reason, Some(Failure::MassOff { .. })),
        "{nan:?}"
    );
    assert_eq!(nan.verdict, TestOutcome::Fail);
}

#[test]
fn ks_results_do_not_depend_on_thread_count() {
    let g = Ggx::new(0.1, 0.4).unwrap();
    let run = |threads| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| {
                let mut r =
                    ks_test_sampler(&g, Marginal::Phi, &hints(0.1), &config(3 * CHUNK + 77, 5));
                r.sampling_seconds = 0.0;
                r.table_seconds = 0.0;
                r
            })
    };
    let (one, two) = (run(1), run(2));
    assert_eq!(one, two);
    let other = ks_test_sampler(&g, Marginal::Phi, &hints(0.1), &config(3 * CHUNK + 77, 6));
    assert_ne!(one.statistic, other.statistic);
}

#[test]
fn ks_p_values_of_a_correct_sampler_spread_over_seeds() {
    let g = Ggx::new(0.3, 0.3).unwrap();
    let h = hints(0.3f64.atan());
    let table = marginal_cdf(&|m| g.pdf_wm(m), Marginal::CosTheta, &h);
    let p: Vec<f64> = (0..12u64)
        .map(|seed| {
            let mut d = draw_batch(
                &|u: &[[f64; 2]], m: &mut [Vec3]| g.sample_wm_batch(u, m),
                Marginal::CosTheta,
                50_000,
                seed,
            );
            d.values.sort_unstable_by(f64::total_cmp);
            ks_p_value(ks_statistic(&d.values, &|x| table.cdf(x)).0, 50_000)
        })
        .collect();
    eprintln!("p-values over 12 seeds: {p:.3?}");
    let mean = p.iter().sum::<f64>() / p.len() as f64;
    assert!((0.25..0.75).contains(&mean), "{p:?}");
    assert!(p.iter().all(|&p| p > 1e-3), "{p:?}");
    assert!(
        p.iter().any(|&p| p < 0.5) && p.iter().any(|&p| p > 0.5),
        "{p:?}"
    );
}

/// The table walk and the chunked statistic give `CdfTable::cdf` and `ks_statistic` bit for
/// bit (values below, inside and above the table, ties, chunk boundaries), and the batched
/// table build is the same whatever the thread count.
#[test]
fn ks_walk_and_batched_table_match_the_scalar_forms() {
    let g = Ggx::new(0.2, 0.5).unwrap();
    let h = hints(0.2);
    let run = |threads| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| marginal_cdf(&|m| g.pdf_wm(m), Marginal::CosTheta, &h))
    };
    let table = run(1);
    assert_eq!(table, run(2));
    let mut d = draw_batch(
        &|u: &[[f64; 2]], m: &mut [Vec3]| g.sample_wm_batch(u, m),
        Marginal::CosTheta,
        40_000,
        3,
    );
    d.values.extend([-1.0, 0.0, 0.0, 1.0, 1.0, FRAC_PI_2, 2.0]);
    d.values.sort_unstable_by(f64::total_cmp);
    let mut walked = vec![f64::NAN; d.values.len()];
    table.cdf_ascending(&d.values, |i, f| walked[i] = f);
    for (x, w) in d.values.iter().zip(&walked) {
        assert_eq!(table.cdf(*x).to_bits(), w.to_bits(), "{x}");
    }
    let want = ks_statistic(&d.values, &|x| table.cdf(x));
    let got = ks_statistic_table(&d.values, &table);
    assert_eq!(want.0.to_bits(), got.0.to_bits());
    assert_eq!(want.1.to_bits(), got.1.to_bits());
}

/// The table's hoisted directions are `from_spherical`'s bit for bit (the horizon included).
#[test]
fn ks_table_directions_are_from_spherical() {
    for theta in [0.0, 1e-9, 0.3, 1.0, FRAC_PI_2 - 1e-16, FRAC_PI_2] {
        for phi in [0.0f64, 0.4, 2.0, 3.9, 6.2] {
            let ((st, ct), (sp, cp)) = (table::polar_sin_cos(theta), phi.sin_cos());
            let want = mfh_reference::geometry::from_spherical(theta, phi);
            assert_eq!(
                [st * cp, st * sp, ct].map(f64::to_bits),
                want.map(f64::to_bits)
            );
        }
    }
}

/// The sort of the drawn values gives `total_cmp`'s order bit for bit, with edge values, ties
/// and a −0 (which takes the comparison sort).
#[test]
fn ks_sort_values_is_total_cmp_order() {
    let g = Ggx::new(0.2, 0.5).unwrap();
    let d = draw_batch(
        &|u: &[[f64; 2]], m: &mut [Vec3]| g.sample_wm_batch(u, m),
        Marginal::Phi,
        30_000,
        5,
    );
    let mut values = d.values;
    values.extend([0.0, 0.0, 1e-300, 0.3, 0.3, FRAC_PI_2, TAU, 7.0]);
    for extra in [None, Some(-0.0)] {
        values.extend(extra);
        let mut want = values.clone();
        want.sort_unstable_by(f64::total_cmp);
        let mut got = values.clone();
        sort_values(&mut got);
        assert_eq!(
            got.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
            want.iter().map(|v| v.to_bits()).collect::<Vec<_>>()
        );
    }
}

/// The block form of the marginal values is the scalar form bit for bit, and both stay within
/// a few ulps of glibc's atan2: random directions, the pole, the φ = 0 seam from both sides
/// (−1e-17 wraps to 0, not 2π), the horizon and near-pole radii where x² + y² underflows.
#[test]
fn ks_marginal_values_block_is_scalar_and_near_atan2() {
    let mut rng = crate::random::Stream::new(5, 0);
    let mut uniform = || rng.uniform();
    let mut m: Vec<Vec3> = (0..100_000)
        .map(|_| {
            let (phi, z) = (uniform() * TAU, uniform());
            let r = (1.0 - z * z).sqrt();
            [r * phi.cos(), r * phi.sin(), z]
        })
        .collect();
    m.extend([
        [0.0, 0.0, 1.0],
        [1.0, -1e-17, 0.0],
        [1.0, 1e-17, 0.0],
        [-1.0, 0.0, 0.0],
        [-1.0, -0.0, 0.0],
        [1e-160, -3e-161, 1.0],
        [-2e-300, 1e-300, 1.0],
    ]);
    for marginal in [Marginal::CosTheta, Marginal::Phi] {
        let mut block = vec![f64::NAN; m.len()];
        marginal.values(&m, &mut block);
        for (&m, &b) in m.iter().zip(&block) {
            let scalar = marginal.value(m);
            assert_eq!(b.to_bits(), scalar.to_bits(), "{marginal:?} {m:?}");
            let glibc = match marginal {
                Marginal::CosTheta => m[0].hypot(m[1]).atan2(m[2]),
                Marginal::Phi => azimuth(m, m[1].atan2(m[0])),
            };
            assert!(
                (b - glibc).abs() <= 4.0 * f64::EPSILON * glibc.abs().max(f64::MIN_POSITIVE),
                "{marginal:?} {m:?}: {b:e} vs {glibc:e}"
            );
            // θ ∈ [0, π/2] (the horizon included), φ ∈ [0, 2π).
            let [lo, hi] = marginal.range();
            assert!(
                b >= lo && (b < hi || (b == hi && marginal == Marginal::CosTheta)),
                "{b}"
            );
        }
    }
}
