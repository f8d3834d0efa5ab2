use super::*;
use crate::oracle::hemisphere_grid::CellFinder;
use crate::random::stream;
use mfh_reference::{Model, ModelSpec};

fn model(json: &str) -> Box<dyn Model> {
    serde_json::from_str::<ModelSpec>(json)
        .unwrap()
        .build()
        .unwrap()
}

fn config() -> Chi2Config {
    Chi2Config {
        resolution: 16,
        samples: 1_000_000,
        seed: 7,
        alpha: 1e-4,
    }
}

fn assert_passes(json: &str) -> Chi2Result {
    let m = model(json);
    let r = chi2_test_sampler(m.as_sampler().unwrap(), &config());
    eprintln!(
        "{json}: χ² = {:.1}, dof = {}, p = {:.4}, pooled = {}, mass = {} ± {:.1e} counts, \
         {:.3e} samples/s, integration {:.3} s",
        r.statistic,
        r.dof,
        r.p_value,
        r.pooled_cells,
        r.expected_mass,
        r.expected_error_bound,
        r.samples_per_second(),
        r.integration_seconds
    );
    assert_eq!(r.verdict, TestOutcome::Pass, "{:?}", r.reason);
    assert!(r.p_value > 1e-4);
    assert!((r.expected_mass - 1.0).abs() < 1e-6);
    assert!(r.expected_error_bound < 1e-2);
    assert_eq!(r.observed.iter().sum::<u64>(), r.samples);
    r
}

#[test]
fn chi2_ggx_passes() {
    assert_passes(r#"{"family":"ggx","alpha":0.3}"#);
}

#[test]
fn chi2_beckmann_passes() {
    assert_passes(r#"{"family":"beckmann","alpha":0.3}"#);
}

#[test]
fn chi2_std_anisotropic_passes() {
    assert_passes(r#"{"family":"std","gamma":2.5,"alpha_x":0.1,"alpha_y":0.4}"#);
}

#[test]
fn chi2_narrow_lobes_pass() {
    // The expected-count integration once found a mass of ~1e-113 for Beckmann
    // α = 1e-3 (it missed the lobe); the `mfh chi2` path (no lobe given: measured from the
    // pdf) at resolution 16.
    for json in [
        r#"{"family":"beckmann","alpha":0.001}"#,
        r#"{"family":"ggx","alpha":0.0001}"#,
        r#"{"family":"ggx","alpha":0.001}"#,
    ] {
        let m = model(json);
        let r = chi2_test_sampler(
            m.as_sampler().unwrap(),
            &Chi2Config {
                samples: 200_000,
                ..config()
            },
        );
        eprintln!(
            "{json}: p = {:.3}, mass = {} ± {:.1e} counts, integration {:.3} s",
            r.p_value, r.expected_mass, r.expected_error_bound, r.integration_seconds
        );
        assert_eq!(r.verdict, TestOutcome::Pass, "{json}: {:?}", r.reason);
        assert!(
            (r.expected_mass - 1.0).abs() < 1e-9,
            "{json}: {}",
            r.expected_mass
        );
    }
    // 10⁴ cells (R = 71: 10 082) for GGX α = 1e-4: the mass and the cost, printed.
    let m = model(r#"{"family":"ggx","alpha":0.0001}"#);
    let s = m.as_sampler().unwrap();
    let t = Instant::now();
    let e = expected_mass(&|w| s.pdf_wm(w), HemisphereGrid::new(71).unwrap());
    eprintln!(
        "R = 71 (10 082 cells), GGX α = 1e-4: mass {} ± {:.1e}, {} evaluations, {:.3} s",
        e.total,
        e.error_bound,
        e.evaluations,
        t.elapsed().as_secs_f64()
    );
    assert!(
        (e.total - 1.0).abs() < 1e-9 && e.error_bound < 1e-8,
        "{e:?}"
    );
}

#[test]
fn chi2_wrong_roughness_fails() {
    let sampler = model(r#"{"family":"ggx","alpha":0.3}"#);
    let pdf = model(r#"{"family":"ggx","alpha":0.33}"#);
    let (s, p) = (sampler.as_sampler().unwrap(), pdf.as_sampler().unwrap());
    let r = chi2_test(&|u| s.sample_wm(u), &|m| p.pdf_wm(m), &config());
    assert_eq!(r.verdict, TestOutcome::Fail);
    assert!(r.p_value < 1e-12, "{r:?}");
    assert!(matches!(r.reason, Some(Failure::Rejected { .. })));
}

#[test]
fn chi2_printed_half_azimuth_sampler_fails() {
    let m =
        mfh_reference::ndf::Student::new(mfh_reference::ndf::student::Member::Std, 2.5, 0.1, 0.4)
            .unwrap();
    let r = chi2_test(
        &|u| m.sample_wm_printed(u),
        &|w| m.pdf_wm(w),
        &Chi2Config {
            samples: 200_000,
            ..config()
        },
    );
    assert_eq!(r.verdict, TestOutcome::Fail);
    assert_eq!(r.p_value, 0.0);
    assert!(matches!(r.reason, Some(Failure::Rejected { .. })));
}

#[test]
fn chi2_below_horizon_is_a_sanity_failure() {
    let m = model(r#"{"family":"ggx","alpha":0.3}"#);
    let s = m.as_sampler().unwrap();
    let sample = |u: [f64; 2]| {
        let w = s.sample_wm(u);
        if u[0] < 0.01 {
            [w[0], w[1], -w[2]]
        } else {
            w
        }
    };
    let r = chi2_test(&sample, &|w| s.pdf_wm(w), &config());
    assert_eq!(r.verdict, TestOutcome::Fail);
    match r.reason {
        Some(Failure::OutsideHemisphere(OutsideHemisphere {
            error: DirectionError::BelowHorizon(_),
            count,
            ..
        })) => assert!((5_000..15_000).contains(&count), "{count}"),
        other => panic!("{other:?}"),
    }
    let nan = chi2_test(&|_| [f64::NAN; 3], &|w| s.pdf_wm(w), &config());
    assert!(matches!(
        nan.reason,
        Some(Failure::OutsideHemisphere(OutsideHemisphere {
            index: 0,
            error: DirectionError::NotFinite(_),
            ..
        }))
    ));
}

#[test]
fn chi2_mass_and_zero_pdf_sanity_failures() {
    let m = model(r#"{"family":"ggx","alpha":0.3}"#);
    let s = m.as_sampler().unwrap();
    let cfg = Chi2Config {
        samples: 10_000,
        ..config()
    };
    let half = chi2_test(&|u| s.sample_wm(u), &|w| 0.5 * s.pdf_wm(w), &cfg);
    assert!(
        matches!(half.reason, Some(Failure::MassOff { .. })),
        "{:?}",
        half.reason
    );
    // A pdf that is zero for m_x < 0, renormalized: the sampler still puts samples there.
    let right = chi2_test(
        &|u| s.sample_wm(u),
        &|w| if w[0] > 0.0 { 2.0 * s.pdf_wm(w) } else { 0.0 },
        &cfg,
    );
    assert!(
        matches!(right.reason, Some(Failure::ZeroPdfCell { .. })),
        "{:?}",
        right.reason
    );
}

#[test]
fn chi2_counts_do_not_depend_on_thread_count() {
    let m = model(r#"{"family":"std","gamma":2.5,"alpha_x":0.1,"alpha_y":0.4}"#);
    let s = m.as_sampler().unwrap();
    let grid = HemisphereGrid::new(8).unwrap();
    let run = |threads| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| observe(&|u| s.sample_wm(u), grid.clone(), 5 * CHUNK + 123, 99))
    };
    let one = run(1);
    let two = run(2);
    assert_eq!(one, two);
    assert_eq!(one, run(4));
    assert_eq!(one.counts.iter().sum::<u64>(), 5 * CHUNK + 123);
    assert_ne!(
        one,
        observe(&|u| s.sample_wm(u), grid.clone(), 5 * CHUNK + 123, 100)
    );
}

#[test]
fn chi2_batch_counts_are_the_scalar_counts_whatever_the_thread_count() {
    let samples = 3 * CHUNK + 777;
    for json in [
        r#"{"family":"ggx","alpha":0.3}"#,
        r#"{"family":"ggx","alpha":0.01}"#,
        r#"{"family":"beckmann","alpha_x":0.1,"alpha_y":0.5}"#,
        r#"{"family":"std","gamma":2.5,"alpha_x":0.1,"alpha_y":0.4}"#,
        r#"{"family":"gtr","gamma":1.5,"alpha":0.3}"#,
    ] {
        let m = model(json);
        let s = m.as_sampler().unwrap();
        // The equal-area grid and the lobe's (rows, and for the anisotropic ones columns, at
        // the pdf's marginal quantiles: the finder's counting path).
        let pdf = |w: &[Vec3], out: &mut [f64]| {
            for (o, &w) in out.iter_mut().zip(w) {
                *o = s.pdf_wm(w);
            }
        };
        let lobe = lobe::measure_density(&|w| s.pdf_wm(w));
        let (follow, _) = cells::layout(&pdf, &lobe, 16, &[], Layout::FollowLobe);
        assert!(!follow.is_equal_area(), "{json}");
        for grid in [HemisphereGrid::new(16).unwrap(), follow] {
            // The plainest reference: one pair, one scalar sample, one cell at a time.
            let finder = CellFinder::new(grid.clone());
            let mut counts = vec![0u64; grid.cells()];
            for chunk in 0..samples.div_ceil(CHUNK) {
                let mut rng = stream(11, chunk);
                for _ in chunk * CHUNK..((chunk + 1) * CHUNK).min(samples) {
                    let m = s.sample_wm(rng.pair());
                    let cell = finder.cell_of(m).unwrap();
                    assert_eq!(Ok(cell), grid.cell_of(m), "{json}");
                    counts[cell] += 1;
                }
            }
            let batch = |threads| {
                rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .build()
                    .unwrap()
                    .install(|| {
                        observe_batch(
                            &|u, out| s.sample_wm_batch(u, out),
                            grid.clone(),
                            samples,
                            11,
                        )
                    })
            };
            let (one, two, four) = (batch(1), batch(2), batch(4));
            // The reference batch samplers give their scalar samplers' normals bit for bit.
            assert_eq!(one.counts, counts, "{json}");
            assert_eq!(one, two, "{json}");
            assert_eq!(one, four, "{json}");
            assert_eq!(
                one,
                observe(&|u| s.sample_wm(u), grid.clone(), samples, 11),
                "{json}"
            );
            assert_eq!((one.outside, one.first_outside), (0, None));
        }
    }
}

/// Rows at the pdf's cos θ quantiles: for GGX α = 0.3 (whose equal-area top two rows hold
/// 77 % of the samples) every row expects 1/R of the mass within 10 % (the layout interpolates
/// the marginal linearly within strips: balance, not validity), and an anisotropic lobe gets
/// columns at its φ quantiles; on those cells the test passes the correct sampler and catches
/// a roughness error of 3 % of GGX α = 0.01 at 2·10⁵ samples, which the equal-area grid misses.
#[test]
fn lobe_layout_balances_the_cells_and_catches_a_roughness_error() {
    fn pdf_of(s: &dyn mfh_reference::NormalSampler) -> impl Fn(&[Vec3], &mut [f64]) + Sync + '_ {
        move |w: &[Vec3], out: &mut [f64]| {
            for (o, &w) in out.iter_mut().zip(w) {
                *o = s.pdf_wm(w);
            }
        }
    }
    let m = model(r#"{"family":"ggx","alpha":0.3}"#);
    let s = m.as_sampler().unwrap();
    let lobe = lobe::measure_density(&|w| s.pdf_wm(w));
    let (grid, _) = cells::layout(&pdf_of(s), &lobe, 16, &[], Layout::FollowLobe);
    assert_eq!(
        grid.phi_edges(),
        HemisphereGrid::new(16).unwrap().phi_edges()
    );
    let e = expected_mass(&|w| s.pdf_wm(w), grid.clone());
    for row in e.mass.chunks(32) {
        let mass: f64 = row.iter().sum();
        assert!((mass * 16.0 - 1.0).abs() < 0.1, "row mass {mass}");
    }
    let equal = expected_mass(&|w| s.pdf_wm(w), HemisphereGrid::new(16).unwrap());
    let top_two: f64 = equal.mass[14 * 32..].iter().sum();
    // 0.77 of the mass in the top two of the equal-area grid's 16 rows.
    assert!(top_two > 0.75, "{top_two}");
    // Anisotropic: columns at φ quantiles, each about 1/32 of the mass.
    let a = model(r#"{"family":"ggx","alpha_x":0.1,"alpha_y":0.5}"#);
    let sa = a.as_sampler().unwrap();
    let lobe_a = lobe::measure_density(&|w| sa.pdf_wm(w));
    let (grid_a, _) = cells::layout(&pdf_of(sa), &lobe_a, 16, &[], Layout::FollowLobe);
    let ea = expected_mass(&|w| sa.pdf_wm(w), grid_a.clone());
    for j in 0..32 {
        let column: f64 = (0..16).map(|i| ea.mass[i * 32 + j]).sum();
        assert!(
            (column * 32.0 - 1.0).abs() < 0.1,
            "column {j} mass {column}"
        );
    }
    // The planted defect: the sampler of α = 0.01·1.03 against the pdf of 0.01 (a narrow lobe:
    // the equal-area grid puts every sample into its top row).
    let narrow = model(r#"{"family":"ggx","alpha":0.01}"#);
    let s = narrow.as_sampler().unwrap();
    let wrong = model(r#"{"family":"ggx","alpha":0.0103}"#);
    let w = wrong.as_sampler().unwrap();
    let config = Chi2Config {
        resolution: 16,
        samples: 200_000,
        seed: 1,
        alpha: 1e-3,
    };
    let run = |sampler: &dyn mfh_reference::NormalSampler, layout| {
        chi2_test_batch_layout(
            &|u: &[[f64; 2]], m: &mut [Vec3]| sampler.sample_wm_batch(u, m),
            &|m| s.pdf_wm(m),
            &config,
            (CELL_RELATIVE_TOLERANCE, None, &[]),
            layout,
        )
    };
    let caught = run(w, Layout::FollowLobe);
    assert_eq!(caught.verdict, TestOutcome::Fail, "{}", caught.p_value);
    // The record's edges are the narrow lobe's: every row above cos θ = 0.999.
    assert!(caught.z_edges[1] > 0.999, "{:?}", caught.z_edges);
    let missed = run(w, Layout::EqualArea);
    assert_eq!(missed.verdict, TestOutcome::Pass, "{}", missed.p_value);
    let correct = run(s, Layout::FollowLobe);
    assert_eq!(correct.verdict, TestOutcome::Pass, "{}", correct.p_value);
}

#[test]
fn chi2_pooling() {
    // Two regular bins and a pooled remainder of 3 expected merged into the smaller bin.
    let (stat, bins, pooled) = pooled_statistic(&[10, 20, 1, 2], &[10.0, 20.0, 1.0, 2.0]);
    assert_eq!((stat, bins, pooled), (0.0, 2, 2));
    let (stat, bins, pooled) = pooled_statistic(&[10, 20, 3, 3], &[10.0, 20.0, 3.0, 3.0]);
    assert_eq!((stat, bins, pooled), (0.0, 3, 2));
}

#[test]
fn expected_masses_cut_at_the_kinks_of_a_piecewise_profile() {
    // The isotropic piecewise-linear profile of the default scene: pdf = D(θ) cos θ has kinks
    // at θ = 0.5 and 1.0 for every azimuth. Cut there, the cells' masses meet an independent
    // oracle — each row's mass 2π ∫ pdf(θ) sin θ dθ by composite Simpson on the smooth pieces
    // between the kinks (4 000 intervals each: error ~1e-14) — to the cubature's tolerance,
    // without the cubature subdividing the kinks (it spent ~10⁸ evaluations on them before).
    let json = r#"{"family":"piecewise_linear",
                   "x":{"theta":[0,0.5,1.0,1.5707963267948966],"value":[1,0.6,0.1,0]}}"#;
    let m = model(json);
    let s = m.as_sampler().unwrap();
    let grid = HemisphereGrid::new(16).unwrap();
    let lobe = lobe::measure_density(&|w| s.pdf_wm(w));
    let kinks = [0.5, 1.0];
    let e = expected_mass_in(
        &|w| s.pdf_wm(w),
        grid.clone(),
        CELL_RELATIVE_TOLERANCE,
        &lobe,
        &kinks,
    );
    let band = |a: f64, b: f64| {
        let f = |t: f64| s.pdf_wm(mfh_reference::geometry::from_spherical(t, 0.7)) * t.sin();
        let mut cuts = vec![a];
        cuts.extend(kinks.iter().copied().filter(|k| *k > a && *k < b));
        cuts.push(b);
        let mut sum = 0.0;
        for w in cuts.windows(2) {
            let n = 4000;
            let h = (w[1] - w[0]) / n as f64;
            let mut part = f(w[0]) + f(w[1]);
            for i in 1..n {
                part += f(w[0] + h * i as f64) * if i % 2 == 1 { 4.0 } else { 2.0 };
            }
            sum += part * h / 3.0;
        }
        std::f64::consts::TAU * sum
    };
    for row in 0..grid.rows() {
        let cell = grid.cell(row * grid.columns());
        let (a, b) = (
            cell.z[1].clamp(0.0, 1.0).acos(),
            cell.z[0].clamp(0.0, 1.0).acos(),
        );
        let cubature: f64 = e.mass[row * grid.columns()..(row + 1) * grid.columns()]
            .iter()
            .sum();
        let oracle = band(a, b);
        assert!(
            (cubature - oracle).abs() <= 2e-9 * oracle + 1e-13,
            "row {row}: cubature {cubature}, Simpson {oracle}"
        );
    }
    assert!((e.total - 1.0).abs() < 1e-8, "{}", e.total);
    assert!(e.evaluations < 2_000_000, "{} evaluations", e.evaluations);
}
