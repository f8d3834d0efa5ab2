use super::*;
use crate::check::RunContext;
use crate::oracle::chi2::chi2_test;
use crate::oracle::ks::{self as oracle_ks, KsConfig, Marginal};
use mfh_reference::{Masking, ModelSpec};

fn run(plan: &[PlannedCheck<'_>]) -> Vec<CheckRecord> {
    let ctx = RunContext { seed: 7 };
    plan.iter()
        .map(|p| {
            let r = (p.run)(&ctx);
            eprintln!(
                "{} {} {} {:?} {:?} {:.3}s",
                r.check, r.model, r.case, r.verdict, r.measured, r.cost.wall_seconds
            );
            r
        })
        .collect()
}

fn model(json: &str) -> (ModelSpec, Arc<Subject<'static>>) {
    let spec: ModelSpec = serde_json::from_str(json).unwrap();
    let m = Subject::reference(&spec).unwrap();
    (spec, m)
}

#[test]
fn visible_samplers_pass_their_checks() {
    for json in [
        r#"{"family":"ggx","alpha_x":0.2,"alpha_y":0.5}"#,
        r#"{"family":"beckmann","alpha_x":0.3,"alpha_y":0.15}"#,
        r#"{"family":"std","gamma":"inf","alpha":0.3}"#,
    ] {
        let (_, m) = model(json);
        let records = run(&plan_visible(&m, Profile::Quick, "test"));
        // chi-square and normalization per incidence, one `sampling.visible_jacobian` (its
        // own sweep of incidences) and one `sampling.batch_agrees`.
        assert_eq!(records.len(), 2 * VISIBLE_INCIDENCES.len() + 2);
        for r in &records {
            assert_eq!(r.verdict, Verdict::Pass, "{r:?}");
        }
    }
}

#[test]
fn a_model_without_a_visible_sampler_is_skipped_with_its_reason() {
    let (spec, m) = model(r#"{"family":"std","gamma":3,"alpha":0.3}"#);
    let records = run(&plan_visible(&m, Profile::Quick, "test"));
    assert_eq!(records.len(), 1);
    assert!(
        matches!(&records[0].verdict, Verdict::Skipped { reason } if reason.contains("std")),
        "{:?}",
        records[0].verdict
    );
    let (ggx, _) = model(r#"{"family":"ggx","alpha":0.3}"#);
    let records = run(&plan_pseudo_vnis(&ggx, None, Profile::Quick, "test"));
    assert!(matches!(&records[0].verdict, Verdict::Skipped { .. }));
    // An STD whose Λ diverges (γ ≤ 3/2) has no pseudo-VNIS weight.
    let (low, _) = model(r#"{"family":"std","gamma":1.4,"alpha":0.3}"#);
    let records = run(&plan_pseudo_vnis(&low, None, Profile::Quick, "test"));
    assert!(matches!(&records[0].verdict, Verdict::Skipped { .. }));
    let _ = spec;
}

#[test]
fn the_printed_pseudo_vnis_weight_is_biased_and_the_unbiased_one_is_not() {
    let pseudo_vnis = |json: &str, masking| {
        let (spec, _) = model(json);
        run(&plan_pseudo_vnis(
            &spec,
            Some(masking),
            Profile::Quick,
            "test",
        ))
    };
    let records = pseudo_vnis(
        r#"{"family":"std","gamma":3,"alpha":0.4}"#,
        Masking::Uncorrelated,
    );
    assert_eq!(records.len(), 3 * VISIBLE_INCIDENCES.len());
    for r in &records {
        assert_eq!(r.case["proxy"], "ggx");
        match r.case["weight"].as_str() {
            Some("printed") => assert!(
                matches!(&r.verdict, Verdict::ExpectedFailure { reason }
                         if reason.starts_with("[001-§7.2]")),
                "{r:?}"
            ),
            _ => assert_eq!(r.verdict, Verdict::Pass, "{r:?}"),
        }
    }
    // γ = 2 is GGX: the proxy is exact and eq 43 unbiased.
    let records = pseudo_vnis(
        r#"{"family":"std","gamma":2,"alpha":0.4}"#,
        Masking::HeightCorrelated,
    );
    for r in &records {
        assert_eq!(r.verdict, Verdict::Pass, "{r:?}");
    }
}

#[test]
fn the_ks_curves_show_the_samples_the_test_judged() {
    let (_, m) = model(r#"{"family":"ggx","alpha_x":0.1,"alpha_y":0.4}"#);
    let sampler = m.model.as_sampler().unwrap();
    for marginal in [Marginal::CosTheta, Marginal::Phi] {
        let config = KsConfig {
            samples: 100_000,
            seed: 11,
            alpha: STATISTICAL_ALPHA.value,
        };
        let kept = oracle_ks::ks_test_lobe_batch_kept(
            &|u: &[[f64; 2]], out: &mut [Vec3]| sampler.sample_wm_batch(u, out),
            &|w: &[Vec3], out: &mut [f64]| sampler.pdf_wm_batch(w, out),
            marginal,
            m.lobe(),
            &[],
            &config,
        );
        // What the plot shows is what the test judged: the same D_N from the kept samples.
        let (d, at) = oracle_ks::ks_statistic(&kept.sorted, &|x| kept.table.cdf(x));
        assert_eq!(
            (d, at),
            (kept.result.statistic, kept.result.at),
            "{marginal:?}"
        );
        assert_eq!(kept.sorted.len() as u64, config.samples);
        let Some(crate::record::RecordData::KsMarginal {
            x,
            model_cdf,
            empirical_cdf,
            ..
        }) = ks::ks_marginal_data(&kept)
        else {
            panic!("no KS data");
        };
        assert_eq!(x.len(), ks::KS_CURVE_POINTS);
        assert_eq!((model_cdf[0], empirical_cdf[0]), (0.0, 0.0));
        assert!((model_cdf[ks::KS_CURVE_POINTS - 1] - 1.0).abs() < 1e-6);
        assert_eq!(empirical_cdf[ks::KS_CURVE_POINTS - 1], 1.0);
        let worst = model_cdf
            .iter()
            .zip(&empirical_cdf)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(worst <= d, "{worst} > D_N = {d}");
    }
}

#[test]
fn a_wrong_visible_density_fails_the_chi_square() {
    let (_, a) = model(r#"{"family":"ggx","alpha":0.3}"#);
    let (_, b) = model(r#"{"family":"ggx","alpha":0.33}"#);
    let (va, vb) = (
        a.model.as_visible_sampler().unwrap(),
        b.model.as_visible_sampler().unwrap(),
    );
    let wi = from_spherical(1.3, 0.3);
    let config = Chi2Config {
        resolution: 16,
        samples: 200_000,
        seed: 3,
        alpha: STATISTICAL_ALPHA.value,
    };
    let r = chi2_test(
        &|u| va.sample_wm_visible(wi, u),
        &|m| vb.pdf_wm_visible(wi, m),
        &config,
    );
    assert!(r.p_value < 1e-6, "{r:?}");
    // The normal sampler is not a visible-normal sampler.
    let s = a.model.as_sampler().unwrap();
    let r = chi2_test(&|u| s.sample_wm(u), &|m| va.pdf_wm_visible(wi, m), &config);
    assert_eq!(r.verdict, crate::oracle::chi2::TestOutcome::Fail);
}
