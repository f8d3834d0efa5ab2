//! False-alarm calibration: N seeded chi-square and KS runs of *correct* samplers (reference
//! models), each test exactly as the audit runs it (`oracle::chi2::chi2_test_batch_in`,
//! `oracle::ks::ks_test_lobe`) with the quick profile's sample counts. Under the null the
//! rejections at level α are Binomial(N, α): the observed count must lie in the 99 % binomial
//! interval (statrs' quantiles), and the N p-values must pass a KS test of uniformity on [0, 1]
//! (at level [`UNIFORMITY_LEVEL`]).

use crate::check::Profile;
use crate::oracle::chi2::{chi2_test_batch_in, Chi2Config};
use crate::oracle::ks::ks_p_value;
use crate::oracle::ks::{ks_statistic, ks_test_lobe, KsConfig, Marginal};
use crate::oracle::lobe;
use crate::tolerance::CELL_RELATIVE_TOLERANCE;
use mfh_reference::bsdf::Directions;
use mfh_reference::family::FamilySpec;
use mfh_reference::{ModelSpec, Vec3};
use rayon::prelude::*;
use serde::Serialize;
use serde_json::Value;
use statrs::distribution::{Binomial, DiscreteCDF};
use std::time::Instant;

/// The levels α at which the rejection fraction is checked: the audit's own α
/// (`tolerance::STATISTICAL_ALPHA`, before the Šidák correction) and two coarser ones, which
/// the same p-values answer for free and which have more rejections to count.
pub const LEVELS: [f64; 3] = [1e-3, 1e-2, 5e-2];

/// The confidence of the binomial interval the rejection count must lie in.
pub const INTERVAL_CONFIDENCE: f64 = 0.99;

/// The p-values of a test's N runs must not be rejected as non-uniform at this level.
pub const UNIFORMITY_LEVEL: f64 = 0.01;

/// The first seed of the calibration runs (run i uses `CALIBRATION_SEED + i`): distinct from
/// the audit seeds.
pub const CALIBRATION_SEED: u64 = 0x6d66_6863_616c_0000;

/// The models calibrated by default: GGX and Beckmann at α = 0.3.
pub const DEFAULT_MODELS: [&str; 2] = [
    r#"{"family":"ggx","alpha":0.3}"#,
    r#"{"family":"beckmann","alpha":0.3}"#,
];

/// The rejection count at one level against its binomial interval.
#[derive(Debug, Clone, Serialize)]
pub struct LevelCheck {
    /// The level α.
    pub alpha: f64,
    /// Runs with p < α.
    pub rejections: u64,
    /// rejections / N.
    pub fraction: f64,
    /// The [`INTERVAL_CONFIDENCE`] interval of Binomial(N, α): [F⁻¹(0.005), F⁻¹(0.995)].
    pub interval: [u64; 2],
    /// Whether the count lies in it.
    pub within: bool,
}

/// One test (a sampler and a statistic) over N seeded runs.
#[derive(Debug, Clone, Serialize)]
pub struct TestCalibration {
    /// The model's spec.
    pub model: Value,
    /// `chi2`, `ks_cos_theta` or `ks_phi`.
    pub test: String,
    /// Runs.
    pub runs: usize,
    /// Samples per run.
    pub samples: u64,
    /// Runs that failed a sanity check (no p-value): must be 0.
    pub sanity_failures: usize,
    /// The rejection counts at [`LEVELS`].
    pub levels: Vec<LevelCheck>,
    /// The KS statistic of the p-values against U(0, 1).
    pub uniformity_statistic: f64,
    /// Its p-value.
    pub uniformity_p_value: f64,
    /// The p-values, in run order (for the report's histogram and QQ plot).
    pub p_values: Vec<f64>,
    /// Wall time, seconds.
    pub seconds: f64,
}

impl TestCalibration {
    /// No sanity failure, every level within its interval, the p-values uniform.
    pub fn passed(&self) -> bool {
        self.sanity_failures == 0
            && self.levels.iter().all(|l| l.within)
            && self.uniformity_p_value >= UNIFORMITY_LEVEL
    }
}

/// The calibration of every test.
#[derive(Debug, Clone, Serialize)]
pub struct Calibration {
    /// The profile whose sample counts were used.
    pub profile: Profile,
    /// One entry per model and test.
    pub tests: Vec<TestCalibration>,
}

impl Calibration {
    /// Every test passed.
    pub fn passed(&self) -> bool {
        !self.tests.is_empty() && self.tests.iter().all(TestCalibration::passed)
    }
}

/// The [`INTERVAL_CONFIDENCE`] interval of Binomial(n, p): the smallest k with
/// F(k) ≥ 0.005 and the smallest with F(k) ≥ 0.995, F from statrs. (statrs 0.18's default
/// `inverse_cdf` for discrete distributions panics on an internal unwrap for Binomial; a
/// linear scan of the CDF is exact and cheap for the n of a calibration.)
pub fn binomial_interval(n: u64, p: f64) -> [u64; 2] {
    let tail = 0.5 * (1.0 - INTERVAL_CONFIDENCE);
    match Binomial::new(p, n) {
        Ok(b) => {
            let quantile = |q: f64| (0..=n).find(|&k| b.cdf(k) >= q).unwrap_or(n);
            [quantile(tail), quantile(1.0 - tail)]
        }
        Err(_) => [0, n],
    }
}

/// The level checks and the uniformity test of N p-values.
fn summarize(
    model: &Value,
    test: &str,
    samples: u64,
    p: Vec<Option<f64>>,
    seconds: f64,
) -> TestCalibration {
    let sanity_failures = p.iter().filter(|p| p.is_none()).count();
    let mut p_values: Vec<f64> = p.into_iter().flatten().collect();
    let n = p_values.len() as u64;
    let levels = LEVELS
        .iter()
        .map(|&alpha| {
            let rejections = p_values.iter().filter(|&&p| p < alpha).count() as u64;
            let interval = binomial_interval(n, alpha);
            LevelCheck {
                alpha,
                rejections,
                fraction: rejections as f64 / n.max(1) as f64,
                interval,
                within: n > 0 && interval[0] <= rejections && rejections <= interval[1],
            }
        })
        .collect();
    let mut sorted = p_values.clone();
    sorted.sort_by(f64::total_cmp);
    let (d, _) = ks_statistic(&sorted, &|x: f64| x.clamp(0.0, 1.0));
    let uniformity_p_value = if n > 0 { ks_p_value(d, n) } else { 0.0 };
    p_values.shrink_to_fit();
    TestCalibration {
        model: model.clone(),
        test: test.to_string(),
        runs: n as usize + sanity_failures,
        samples,
        sanity_failures,
        levels,
        uniformity_statistic: d,
        uniformity_p_value,
        p_values,
        seconds,
    }
}

/// Calibrates the chi-square test and the KS tests of both marginals of the sampler of each
/// spec (JSON) over `runs` seeded runs at `profile`'s sample counts. `progress` is told after
/// each test.
pub fn calibrate(
    specs: &[&str],
    runs: usize,
    profile: Profile,
    progress: Option<super::Progress<'_>>,
) -> Result<Calibration, String> {
    let mut tests = Vec::new();
    for text in specs {
        let spec: ModelSpec =
            serde_json::from_str(text).map_err(|e| format!("calibration model {text}: {e}"))?;
        let model = spec
            .build()
            .map_err(|e| format!("calibration model {text}: {e}"))?;
        let sampler = model
            .as_sampler()
            .ok_or_else(|| format!("calibration model {text} has no sampler"))?;
        let value = serde_json::to_value(&spec).unwrap_or(Value::Null);
        let kinks = spec.theta_kinks();
        let lobe = lobe::measure(&|m: Vec3| model.d(m) * m[2]);
        let seed = |i: usize| CALIBRATION_SEED.wrapping_add(i as u64);
        // Chi-square, as `sampling.chi2` runs it (R = 16).
        let samples = profile.chi2_samples();
        let t = Instant::now();
        let p: Vec<Option<f64>> = (0..runs)
            .into_par_iter()
            .map(|i| {
                let config = Chi2Config {
                    resolution: 16,
                    samples,
                    seed: seed(i),
                    alpha: LEVELS[0],
                };
                let r = chi2_test_batch_in(
                    &|u: &[[f64; 2]], out: &mut [Vec3]| sampler.sample_wm_batch(u, out),
                    &|m| sampler.pdf_wm(m),
                    &config,
                    CELL_RELATIVE_TOLERANCE,
                    Some(&lobe),
                    &kinks,
                );
                r.statistic.is_finite().then_some(r.p_value)
            })
            .collect();
        tests.push(summarize(
            &value,
            "chi2",
            samples,
            p,
            t.elapsed().as_secs_f64(),
        ));
        if let Some(f) = progress {
            f(&format!("calibrated chi2 of {text}: {runs} runs"));
        }
        // KS of both marginals, as `sampling.ks_marginals` runs them.
        let samples = profile.ks_samples(false);
        for marginal in [Marginal::CosTheta, Marginal::Phi] {
            let t = Instant::now();
            let p: Vec<Option<f64>> = (0..runs)
                .into_par_iter()
                .map(|i| {
                    let config = KsConfig {
                        samples,
                        seed: seed(i),
                        alpha: LEVELS[0],
                    };
                    let r = ks_test_lobe(
                        &|u| sampler.sample_wm(u),
                        &|m| sampler.pdf_wm(m),
                        marginal,
                        &lobe,
                        &kinks,
                        &config,
                    );
                    r.statistic.is_finite().then_some(r.p_value)
                })
                .collect();
            tests.push(summarize(
                &value,
                &format!("ks_{}", marginal.name()),
                samples,
                p,
                t.elapsed().as_secs_f64(),
            ));
            if let Some(f) = progress {
                f(&format!(
                    "calibrated ks_{} of {text}: {runs} runs",
                    marginal.name()
                ));
            }
        }
    }
    Ok(Calibration { profile, tests })
}

/// The BSDF calibrated: the reference GGX dielectric (η = 1.5, α = 0.3, visible normals).
pub const BSDF_MODEL: &str =
    r#"{"bsdf":"dielectric","eta":1.5,"ndf":{"family":"ggx","alpha":0.3}}"#;

/// Calibrates the whole-sphere chi-square of [`BSDF_MODEL`] as `bsdf.chi2` runs it, at the
/// oblique incidence and beyond the critical angle from inside, over `runs` seeded runs (the
/// expected masses integrated once per incidence: they do not depend on the seed).
pub fn calibrate_bsdf(
    runs: usize,
    profile: Profile,
    progress: Option<super::Progress<'_>>,
) -> Result<Vec<TestCalibration>, String> {
    use crate::check::bsdf::{incidences, pdf_at};
    use crate::oracle::chi2::sphere::{chi2_masses_about, sphere_chi2_against};
    use crate::oracle::lobe_centres::lobe_centres;
    let spec: mfh_reference::bsdf::BsdfSpec =
        serde_json::from_str(BSDF_MODEL).map_err(|e| format!("calibration BSDF: {e}"))?;
    let bsdf = spec.build().map_err(|e| format!("calibration BSDF: {e}"))?;
    let value = serde_json::to_value(&spec).unwrap_or(Value::Null);
    let samples = profile.chi2_samples();
    let resolution = crate::check::bsdf::CHI2_RESOLUTION;
    let mut out = Vec::new();
    for inc in incidences(bsdf.as_ref())
        .into_iter()
        .filter(|i| matches!(i.name, "oblique" | "total_internal_reflection"))
    {
        let t = Instant::now();
        let expected = chi2_masses_about(
            &pdf_at(bsdf.as_ref(), inc.wi),
            resolution,
            samples,
            &lobe_centres(inc.wi, bsdf.eta()),
        );
        let p: Vec<Option<f64>> = (0..runs)
            .into_par_iter()
            .map(|i| {
                let config = Chi2Config {
                    resolution,
                    samples,
                    seed: CALIBRATION_SEED.wrapping_add(i as u64),
                    alpha: LEVELS[0],
                };
                let r = sphere_chi2_against(
                    &|u: &[[f64; 3]], out: &mut Directions| bsdf.sample_wo_batch(inc.wi, u, out),
                    expected.clone(),
                    &config,
                );
                (!r.sanity_failure).then_some(r.p_value)
            })
            .collect();
        out.push(summarize(
            &value,
            &format!("bsdf_chi2_{}", inc.name),
            samples,
            p,
            t.elapsed().as_secs_f64(),
        ));
        if let Some(f) = progress {
            f(&format!("calibrated bsdf chi2 ({}): {runs} runs", inc.name));
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_binomial_interval_brackets_the_mean() {
        let [lo, hi] = binomial_interval(1000, 0.01);
        assert!(lo <= 10 && 10 <= hi, "[{lo}, {hi}]");
        // 99 %: about ±2.6 σ, σ = √(1000·0.01·0.99) ≈ 3.1.
        assert!(
            (2..=3).contains(&lo) && (17..=19).contains(&hi),
            "[{lo}, {hi}]"
        );
    }

    #[test]
    fn summarize_flags_a_miscalibrated_test() {
        let model = Value::Null;
        // Uniform p-values pass; p-values piled near 0 fail both the levels and uniformity.
        let uniform: Vec<Option<f64>> =
            (0..1000).map(|i| Some((i as f64 + 0.5) / 1000.0)).collect();
        assert!(summarize(&model, "t", 1, uniform, 0.0).passed());
        let low: Vec<Option<f64>> = (0..1000).map(|i| Some((i as f64 + 0.5) / 4000.0)).collect();
        let s = summarize(&model, "t", 1, low, 0.0);
        assert!(!s.passed());
        assert!(s.uniformity_p_value < 1e-10, "{}", s.uniformity_p_value);
        let sane: Vec<Option<f64>> = vec![None, Some(0.5)];
        assert!(!summarize(&model, "t", 1, sane, 0.0).passed());
    }
}
