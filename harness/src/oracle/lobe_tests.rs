use super::*;
use mfh_reference::{Model, ModelSpec};

fn model(json: &str) -> Box<dyn Model> {
    serde_json::from_str::<ModelSpec>(json)
        .unwrap()
        .build()
        .unwrap()
}

fn lobe_of(json: &str) -> Lobe {
    let m = model(json);
    let l = measure(&|v| m.d(v));
    eprintln!(
        "{json}: narrowest {:.4e} at φ {:.3}, widest {:.4e} at φ {:.3}, mode {:?}, {} evaluations",
        l.narrowest, l.narrowest_azimuth, l.widest, l.widest_azimuth, l.mode, l.evaluations
    );
    l
}

/// The θ in (0, π/2) where D(θ, φ)·cos θ·sin θ·θ peaks, by brute force over 2·10⁵ log-spaced
/// points (an independent argmax, not the survey's parabola).
fn brute_scale(m: &dyn Model, phi: f64) -> f64 {
    let n = 200_000;
    let (lo, hi) = (1e-10f64.ln(), FRAC_PI_2.ln());
    (0..n)
        .map(|i| (lo + (hi - lo) * i as f64 / (n - 1) as f64).exp())
        .map(|t| (t, m.d(direction(t, phi)) * t.cos() * t.sin() * t))
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .unwrap()
        .0
}

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a / b - 1.0).abs() <= rel
}

#[test]
fn lobe_isotropic_widths_from_1e_4_to_2() {
    for family in [
        r#""family":"ggx""#,
        r#""family":"beckmann""#,
        r#""family":"std","gamma":2.5"#,
        r#""family":"std","gamma":3"#,
    ] {
        for alpha in [1e-4, 1e-3, 1e-2, 0.3, 1.0, 2.0] {
            let json = format!(r#"{{{family},"alpha":{alpha}}}"#);
            let l = lobe_of(&json);
            let m = model(&json);
            let want = brute_scale(m.as_ref(), 0.0);
            // Small α: the peak is at tan θ = α (module documentation).
            if alpha <= 1e-2 {
                assert!(close(want, alpha, 1e-3), "{json}: brute {want}");
            }
            // The parabola in ln θ is good to 2 % where the survey's steps (18 % in θ) are
            // small against the peak's width; near the horizon (α ≥ 1, a peak at θ ≈ 1.2–1.3
            // with the grid 0.2 rad apart) to 10 %, enough to place cuts.
            let rel = if want < 0.5 { 0.02 } else { 0.1 };
            assert!(close(l.narrowest, want, rel), "{json}: {l:?} vs {want}");
            assert!(close(l.widest, want, rel), "{json}: {l:?} vs {want}");
            assert!(l.anisotropy() < 1.05);
            // GGX and STD at α = 2 have D cos θ peaked near the horizon (a ring): a mode there.
            // (Beckmann α = 1: D cos θ ∝ e^{−tan²θ}/cos³θ peaks at cos²θ = 2/3.)
            if alpha <= 0.3 {
                assert!(l.mode.is_none(), "{json}: {:?}", l.mode);
            } else if let Some(m) = l.mode {
                assert!(m.theta > 0.5, "{json}: {m:?}");
            }
            assert!(l.evaluations <= 3000, "{}", l.evaluations);
        }
    }
}

#[test]
fn lobe_anisotropic_1_to_100() {
    for (family, ax, ay) in [
        (r#""family":"ggx""#, 1e-4, 1e-2),
        (r#""family":"beckmann""#, 1e-2, 1.0),
        (r#""family":"std","gamma":2.5"#, 2.0, 0.02),
    ] {
        let json = format!(r#"{{{family},"alpha_x":{ax},"alpha_y":{ay}}}"#);
        let l = lobe_of(&json);
        let m = model(&json);
        let (nx, ny) = (
            brute_scale(m.as_ref(), 0.0),
            brute_scale(m.as_ref(), FRAC_PI_2),
        );
        let (narrow, wide) = (nx.min(ny), nx.max(ny));
        let rel = |w: f64| if w < 0.5 { 0.02 } else { 0.1 };
        assert!(close(l.narrowest, narrow, rel(narrow)), "{json}: {l:?}");
        assert!(close(l.widest, wide, rel(wide)), "{json}: {l:?}");
        let (narrow_phi, wide_phi) = if nx < ny {
            (0.0, FRAC_PI_2)
        } else {
            (FRAC_PI_2, 0.0)
        };
        // Up to the half-turn symmetry of the lobe.
        assert!(
            ((l.narrowest_azimuth - narrow_phi).rem_euclid(PI)).abs() < 1e-12,
            "{l:?}"
        );
        assert!(
            ((l.widest_azimuth - wide_phi).rem_euclid(PI)).abs() < 1e-12,
            "{l:?}"
        );
        let phi = l.azimuth_cuts();
        // Cuts about the widest azimuth at the ratio narrowest/widest.
        let ratio = l.narrowest / l.widest;
        assert!(
            phi.iter()
                .any(|p| (p - (l.widest_azimuth + ratio)).abs() < 1e-12),
            "{phi:?}"
        );
        let theta = l.polar_cuts(FRAC_PI_2);
        // (Cuts closer than 1e-3 relative are merged.)
        assert!(theta.iter().any(|t| close(*t, l.narrowest, 1e-3)));
        assert!(theta.iter().any(|t| close(*t, l.widest, 1e-3)));
        assert!(theta.windows(2).all(|w| w[1] > w[0]));
    }
}

#[test]
fn lobe_off_axis_gaussian_slopes() {
    // Slopes N((0.5, −0.2), diag(0.01, 0.0004)): the mode of D cos θ is near tan θ = |s̄|,
    // φ = atan2(0.2, −0.5) (the slope sign of document 002 eq 11: m ∝ (−s̄x, −s̄y, 1)).
    let json = r#"{"family":"gaussian_slopes","mean":[0.5,-0.2],"cov":[[0.01,0.0],[0.0,0.0004]]}"#;
    let l = lobe_of(json);
    let m = model(json);
    let mode = l.mode.expect("off-axis");
    // The independent argmax of D·cos θ on a fine (θ, φ) grid about the expected mode.
    let mut best = (0.0, 0.0, 0.0);
    for i in 0..400 {
        for j in 0..400 {
            let t = 0.3 + 0.3 * f64::from(i) / 400.0;
            let f = (mode.phi - 0.2) + 0.4 * f64::from(j) / 400.0;
            let v = m.d(direction(t, f)) * t.cos();
            if v > best.0 {
                best = (v, t, f);
            }
        }
    }
    assert!((mode.theta - best.1).abs() < 2e-3, "{mode:?} {best:?}");
    assert!((mode.phi - best.2).abs() < 2e-3, "{mode:?} {best:?}");
    let slope = 0.5f64.hypot(0.2);
    assert!((mode.theta - slope.atan()).abs() < 0.05, "{mode:?}");
    // σ of 0.02–0.1 in slope, × cos²θ in angle: half-widths between 0.01 and 0.1 rad.
    assert!(
        (0.005..0.1).contains(&mode.width_theta) && (0.005..0.1).contains(&mode.width_arc),
        "{mode:?}"
    );
    // The density at the mode ± width is e^{−1/2} of the peak, to the bisection's 5 %.
    let at = |t: f64, f: f64| m.d(direction(t, f)) * t.cos();
    let peak = at(mode.theta, mode.phi);
    let r = at(mode.theta, mode.phi + mode.width_arc / mode.theta.sin()) / peak;
    assert!(
        (r / (-0.5f64).exp() - 1.0).abs() < 0.1 || r > (-0.5f64).exp(),
        "{r}"
    );
    let theta = l.polar_cuts(FRAC_PI_2);
    assert!(theta.iter().any(|t| (t - mode.theta).abs() < 1e-12));
    let phi = l.azimuth_cuts();
    assert!(phi.iter().any(|p| (p - mode.phi).abs() < 1e-12));
    assert!(l.evaluations <= 4000, "{}", l.evaluations);
}

#[test]
fn lobe_piecewise_linear_and_degenerate_densities() {
    // A piecewise-linear profile whose mass per ln θ peaks near 0.5 (D constant to 0.5, then
    // falling to 0 at 1.0).
    let json = r#"{"family":"piecewise_linear","x":{"theta":[0.0,0.5,1.0,1.5707963267948966],"value":[2.0,2.0,0.0,0.0]}}"#;
    let l = lobe_of(json);
    let m = model(json);
    let want = brute_scale(m.as_ref(), 0.0);
    assert!(close(l.narrowest, want, 0.05), "{l:?} {want}");
    // Zero, NaN and negative densities: the fallback width, no panic.
    for p in [
        &(|_: Vec3| 0.0) as &(dyn Fn(Vec3) -> f64 + Sync),
        &|_: Vec3| f64::NAN,
        &|_: Vec3| -1.0,
    ] {
        let l = measure_density(p);
        assert_eq!(l.narrowest, FALLBACK_WIDTH);
        assert!(l.mode.is_none());
    }
    let iso = Lobe::isotropic(0.01);
    assert_eq!(iso.width(), 0.01);
    assert_eq!(iso.azimuth_cuts(), vec![0.0, 0.5 * PI, PI, 1.5 * PI, TAU]);
    assert_eq!(Lobe::isotropic(f64::NAN).width(), FALLBACK_WIDTH);
}

#[test]
fn lobe_hint_speeds_up_and_never_misleads() {
    let m = model(r#"{"family":"ggx","alpha":1e-3}"#);
    let full = measure(&|v| m.d(v));
    let p = |v: Vec3| m.d(v) * v[2];
    let hinted = measure_with(
        &p,
        &Options {
            hint: Some(1e-3),
            start_points: &[],
        },
    );
    assert!(close(hinted.narrowest, full.narrowest, 0.02), "{hinted:?}");
    assert!(hinted.evaluations < full.evaluations);
    // A wrong hint (1e-7, four decades off) falls back to the full survey.
    let wrong = measure_with(
        &p,
        &Options {
            hint: Some(1e-7),
            start_points: &[],
        },
    );
    assert!(close(wrong.narrowest, full.narrowest, 1e-12), "{wrong:?}");
}

#[test]
fn lobe_start_points_find_a_lobe_the_survey_misses() {
    // A narrow off-axis lobe (slope σ = 1e-3) half-way between two surveyed azimuths: p
    // underflows to 0 at every survey point; one start point in the lobe finds it.
    let json = r#"{"family":"gaussian_slopes","mean":[0.4,0.08],"cov":[[1e-6,0.0],[0.0,1e-6]]}"#;
    let m = model(json);
    let p = |v: Vec3| m.d(v) * v[2];
    let blind = measure_density(&p);
    let centre = {
        let n = [-0.4, -0.08, 1.0];
        let len = (0.4f64 * 0.4 + 0.08 * 0.08 + 1.0).sqrt();
        [n[0] / len, n[1] / len, n[2] / len]
    };
    let seeded = measure_with(
        &p,
        &Options {
            hint: None,
            start_points: &[centre],
        },
    );
    eprintln!("blind {:?}\nseeded {:?}", blind.mode, seeded.mode);
    let mode = seeded.mode.expect("found from the start point");
    assert!(
        (mode.theta - 0.4f64.hypot(0.08).atan()).abs() < 1e-3,
        "{mode:?}"
    );
    assert!(mode.width_theta < 2e-3 && mode.width_arc < 2e-3, "{mode:?}");
}
