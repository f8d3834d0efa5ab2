//! Where a density's lobe is, measured from the density alone (no family name, no spec): the
//! oracles' quadratures place their cuts from this, so that a lobe of any width — GGX at
//! α = 1e-4, an anisotropy of 1:100, a Gaussian-slope lobe off the normal — is found and
//! resolved.
//!
//! Procedure ([`measure_density`]):
//!
//! 1. **A log-polar survey.** Along [`AZIMUTHS`] azimuths φ_k = 2πk/K, the mass per ln θ,
//!    h(θ) = p(θ, φ)·sin θ·θ (p the density with respect to solid angle, D·cos θ for an NDF),
//!    is evaluated on [`THETA_STEPS`] log-spaced θ from [`THETA_MIN`] to π/2. Its peak,
//!    refined by a parabola through the three grid values about it in ln θ, is the azimuth's
//!    θ scale: for GGX, Beckmann and STD of roughness α along the axes it is atan α to
//!    first order (h ∝ t²(1 + t²/(α²(γ−1)))^{−γ}, t = tan θ, peaks at t = α for every γ;
//!    Beckmann is γ → ∞).
//! 2. **The mode.** The survey point of largest p starts a compass search in (θ, φ) that climbs
//!    to the mode of p; a mode away from the pole (more than a tenth of the narrowest scale) is
//!    an off-axis lobe, e.g. Gaussian slopes with a mean. Its angular half-widths along θ and
//!    along the arc in φ are where p falls to e^{−1/2} of the mode (geometric probes, factor
//!    [`PROBE_FACTOR`], refined by bisection in ln width).
//! 3. **Cuts.** [`Lobe::polar_cuts`] and [`Lobe::azimuth_cuts`] turn the widths into the cut
//!    points of the oracles' quadratures (log-spaced about every scale, about the mode, and,
//!    for an anisotropic lobe, about its widest azimuth at the ratio narrowest/widest).
//!
//! Cost: K·S = 2048 density evaluations for the survey, at most a few hundred for the mode and
//! widths ([`Lobe::evaluations`] says how many). Non-finite or negative values count as 0 here
//! (the checks report them; the measurement must not stop on them).
//!
//! Limit: a lobe narrower than the survey's azimuthal spacing (2π/K along the arc) *and* so
//! narrow that p underflows to 0 at every survey point can be missed — the integrals then find a
//! mass far from 1 and the tests fail (never a silent pass). Pass `start_points` (e.g. a few sampled
//! normals) to [`measure_with`] to start the mode search there.

use super::lobe_climb::{climb_many, Prefetch};
use mfh_reference::Vec3;
use std::f64::consts::{FRAC_PI_2, PI, TAU};

/// Azimuths of the survey.
pub const AZIMUTHS: usize = 16;
/// Log-spaced polar angles of the survey along each azimuth.
pub const THETA_STEPS: usize = 128;
/// The smallest polar angle surveyed (radians): below α = 1e-4 by five decades.
pub const THETA_MIN: f64 = 1e-9;
/// The ratio of successive width probes about a mode.
pub const PROBE_FACTOR: f64 = 1.5;
/// The width assumed when the density is zero everywhere it was evaluated (the old
/// `lobe_width` fallback).
pub const FALLBACK_WIDTH: f64 = 0.3;
/// The multiples of a scale at which the polar integrals are cut (as the former fixed cuts
/// width × {10⁻³ … 10²}).
const SCALE_MULTIPLES: [f64; 9] = [1e-3, 1e-2, 0.1, 0.3, 1.0, 3.0, 10.0, 30.0, 100.0];
/// Multiples of a mode's half-width at which the integrals are cut on either side of it;
/// beyond the last, cuts every factor [`TAIL_RATIO`] out to the hemisphere's extent, so that a
/// near-delta lobe's power-law tail (GGX at α 1e-7: 2.4e-4 of its mass beyond 64 widths) is
/// integrated in pieces over which it varies by a bounded factor.
const MODE_MULTIPLES: [f64; 7] = [0.3, 1.0, 2.0, 4.0, 8.0, 16.0, 64.0];
/// The ratio of successive tail cuts beyond [`MODE_MULTIPLES`].
const TAIL_RATIO: f64 = 4.0;
/// The smallest half-width probed about a mode (radians): below the transmission lobe of
/// η = 1 ± 5e-5 at α = 1e-7 (≈ α·|η − 1| = 5e-12).
const WIDTH_PROBE_MIN: f64 = 1e-14;
/// The most further modes a measurement keeps ([`Lobe::extra_modes`]), the highest first.
pub const MAX_EXTRA_MODES: usize = 4;
/// The smallest cut spacing kept about a mode, as a fraction of its half-width.
const MODE_GAP: f64 = 0.1;

/// The multiples of a mode's half-width at which it is cut: [`MODE_MULTIPLES`], then every
/// [`TAIL_RATIO`] up to `extent` / width.
fn mode_multiples(width: f64, extent: f64) -> Vec<f64> {
    let mut out = MODE_MULTIPLES.to_vec();
    let mut k = MODE_MULTIPLES[MODE_MULTIPLES.len() - 1];
    while width > 0.0 && k * width < extent {
        k *= TAIL_RATIO;
        out.push(k);
    }
    out
}

/// An off-axis mode of the density and its angular half-widths.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Mode {
    /// Polar angle of the mode (radians).
    pub theta: f64,
    /// Azimuth of the mode (radians, [0, 2π)).
    pub phi: f64,
    /// Half-width along θ: the smaller of the two distances where p falls to e^{−1/2}.
    pub width_theta: f64,
    /// Half-width along the arc in φ (radians of arc, sin θ·Δφ), likewise.
    pub width_arc: f64,
}

/// The measured lobe of a density on the upper hemisphere.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Lobe {
    /// The surveyed azimuths (radians).
    pub azimuths: Vec<f64>,
    /// The θ scale along each azimuth (where the mass per ln θ peaks); NaN where the density
    /// is zero along the whole azimuth.
    pub theta_scale: Vec<f64>,
    /// The smallest θ scale (radians).
    pub narrowest: f64,
    /// The azimuth of the smallest θ scale.
    pub narrowest_azimuth: f64,
    /// The largest θ scale (radians).
    pub widest: f64,
    /// The azimuth of the largest θ scale.
    pub widest_azimuth: f64,
    /// The mode of the density when it is away from the pole.
    pub mode: Option<Mode>,
    /// Further off-axis modes, climbed to from the start points ([`Options::start_points`]) that lead
    /// elsewhere than `mode` (a BSDF's ring of directions refracted through near-horizontal
    /// microfacets beside its refraction lobe, a lobe whose density is below the other's):
    /// the integrals are cut about each as about `mode`. At most [`MAX_EXTRA_MODES`].
    pub extra_modes: Vec<Mode>,
    /// Density evaluations spent.
    pub evaluations: u64,
}

/// Options of [`measure_with`]: both only speed up or guide the search; neither is needed for
/// a correct measurement of a lobe the survey can see.
#[derive(Debug, Clone, Copy, Default)]
pub struct Options<'a> {
    /// A width stated by the user (radians): the survey then spans hint × [10⁻³, 10³] with
    /// fewer points, and falls back to the full survey when a peak lands on that window's
    /// edge.
    pub hint: Option<f64>,
    /// Directions where the density is known to have mass (e.g. sampled normals): extra start
    /// points of the mode search.
    pub start_points: &'a [Vec3],
}

/// The direction at (θ, φ) about +z (φ from +x).
#[inline]
pub(super) fn direction(theta: f64, phi: f64) -> Vec3 {
    let (st, ct) = theta.sin_cos();
    let (sp, cp) = phi.sin_cos();
    [st * cp, st * sp, ct.max(0.0)]
}

/// (θ, φ) of a unit direction, φ in [0, 2π).
fn angles(m: Vec3) -> (f64, f64) {
    let theta = m[0].hypot(m[1]).atan2(m[2]);
    let phi = m[1].atan2(m[0]).rem_euclid(TAU);
    (theta, if phi < TAU { phi } else { 0.0 })
}

/// Measures the lobe of an NDF D from D alone (the density D·cos θ).
pub fn measure(d: &(dyn Fn(Vec3) -> f64 + Sync)) -> Lobe {
    measure_density(&|m: Vec3| d(m) * m[2])
}

/// Measures the lobe of a density with respect to solid angle (e.g. a pdf_wm).
pub fn measure_density(p: &(dyn Fn(Vec3) -> f64 + Sync)) -> Lobe {
    measure_with(p, &Options::default())
}

/// [`measure_density`] with a hint and start points.
pub fn measure_with(p: &(dyn Fn(Vec3) -> f64 + Sync), options: &Options<'_>) -> Lobe {
    measure_prefetched(p, None, options)
}

/// [`measure_with`] whose mode searches hand each round's points to `prefetch` first.
fn measure_prefetched(
    p: &(dyn Fn(Vec3) -> f64 + Sync),
    prefetch: Prefetch<'_>,
    options: &Options<'_>,
) -> Lobe {
    if let Some(h) = options.hint.filter(|h| h.is_finite() && *h > 0.0) {
        let lo = (h * 1e-3).max(THETA_MIN);
        let hi = (h * 1e3).min(FRAC_PI_2);
        let lobe = survey(p, prefetch, (lo, hi, 48), options.start_points);
        // A scale on the window's edge (or none at all) may be a lobe outside it.
        let ratio = (hi / lo).powf(1.0 / 47.0);
        let inside = lobe.theta_scale.iter().all(|&s| {
            s.is_nan() || ((lo * ratio * 1.01..=hi / ratio / 1.01).contains(&s) || hi >= FRAC_PI_2)
        });
        if inside && lobe.theta_scale.iter().any(|s| s.is_finite()) {
            return lobe;
        }
        let mut full = survey(
            p,
            prefetch,
            (THETA_MIN, FRAC_PI_2, THETA_STEPS),
            options.start_points,
        );
        full.evaluations += lobe.evaluations;
        return full;
    }
    survey(
        p,
        prefetch,
        (THETA_MIN, FRAC_PI_2, THETA_STEPS),
        options.start_points,
    )
}

/// [`measure_with`] for a batch density (`p(m, out)` writes p(m\[i\]) into out\[i\]): the survey
/// grids are evaluated first in one call each, then the measurement runs on those values, its
/// mode searches a round at a time in one call (`oracle/lobe_climb.rs`), its widths one point
/// per call — the same lobe bit for bit, while an external model pays a few hundred round
/// trips rather than tens of thousands.
pub fn measure_with_batch(p: &(dyn Fn(&[Vec3], &mut [f64]) + Sync), options: &Options<'_>) -> Lobe {
    let mut grids = vec![(THETA_MIN, FRAC_PI_2, THETA_STEPS)];
    if let Some(h) = options.hint.filter(|h| h.is_finite() && *h > 0.0) {
        grids.push(((h * 1e-3).max(THETA_MIN), (h * 1e3).min(FRAC_PI_2), 48));
    }
    let mut known = std::collections::HashMap::new();
    for (lo, hi, steps) in grids {
        let dirs: Vec<Vec3> = survey_azimuths()
            .iter()
            .flat_map(|&phi| {
                survey_thetas(lo, hi, steps)
                    .into_iter()
                    .map(move |t| direction(t, phi))
            })
            .collect();
        let mut values = vec![0.0; dirs.len()];
        p(&dirs, &mut values);
        known.extend(dirs.iter().map(|m| m.map(f64::to_bits)).zip(values));
    }
    let known = std::sync::Mutex::new(known);
    let scalar = |m: Vec3| {
        let cached = known
            .lock()
            .expect("not poisoned")
            .get(&m.map(f64::to_bits))
            .copied();
        cached.unwrap_or_else(|| {
            let mut v = [0.0];
            p(&[m], &mut v);
            v[0]
        })
    };
    // The mode searches' points, a round at a time, in one call each.
    let prefetch = |dirs: &[Vec3]| {
        let mut values = vec![0.0; dirs.len()];
        p(dirs, &mut values);
        let mut known = known.lock().expect("not poisoned");
        known.extend(dirs.iter().map(|m| m.map(f64::to_bits)).zip(values));
    };
    measure_prefetched(&scalar, Some(&prefetch), options)
}

/// The survey's polar angles: `steps` log-spaced in [lo, hi].
fn survey_thetas(lo: f64, hi: f64, steps: usize) -> Vec<f64> {
    let log_lo = lo.ln();
    let step = (hi.ln() - log_lo) / (steps - 1) as f64;
    (0..steps)
        .map(|i| {
            if i + 1 == steps {
                hi
            } else {
                (log_lo + step * i as f64).exp()
            }
        })
        .collect()
}

/// The survey's azimuths.
fn survey_azimuths() -> Vec<f64> {
    (0..AZIMUTHS)
        .map(|k| TAU * k as f64 / AZIMUTHS as f64)
        .collect()
}

/// The density, 0 where it is not a finite non-negative number.
pub(super) fn clean(p: &(dyn Fn(Vec3) -> f64 + Sync), theta: f64, phi: f64) -> f64 {
    let v = p(direction(theta, phi));
    if v.is_finite() && v > 0.0 {
        v
    } else {
        0.0
    }
}

/// The survey over `steps` log-spaced θ in [lo, hi] at [`AZIMUTHS`] azimuths, then the mode.
fn survey(
    p: &(dyn Fn(Vec3) -> f64 + Sync),
    prefetch: Prefetch<'_>,
    (lo, hi, steps): (f64, f64, usize),
    start_points: &[Vec3],
) -> Lobe {
    let mut evaluations = 0u64;
    let log_lo = lo.ln();
    let step = (hi.ln() - log_lo) / (steps - 1) as f64;
    let thetas = survey_thetas(lo, hi, steps);
    let azimuths = survey_azimuths();
    let mut theta_scale = Vec::with_capacity(AZIMUTHS);
    let mut peak_mass = Vec::with_capacity(AZIMUTHS);
    // The largest density seen, and where: the start of the mode search.
    let mut best = (0.0f64, 0.0f64, 0.0f64);
    for &phi in &azimuths {
        let values: Vec<f64> = thetas.iter().map(|&t| clean(p, t, phi)).collect();
        evaluations += steps as u64;
        let h: Vec<f64> = values
            .iter()
            .zip(&thetas)
            .map(|(v, t)| v * t.sin() * t)
            .collect();
        for (&v, &t) in values.iter().zip(&thetas) {
            if v > best.0 {
                best = (v, t, phi);
            }
        }
        let (i, &top) = h
            .iter()
            .enumerate()
            .max_by(|a, b| a.1.total_cmp(b.1))
            .expect("steps ≥ 2");
        peak_mass.push(top);
        if !(top > 0.0) {
            theta_scale.push(f64::NAN);
            continue;
        }
        // A parabola through ln h at the three points about the peak, in ln θ.
        let mut log_theta = log_lo + step * i as f64;
        if i > 0 && i + 1 < steps && h[i - 1] > 0.0 && h[i + 1] > 0.0 {
            let (a, b, c) = (h[i - 1].ln(), h[i].ln(), h[i + 1].ln());
            let curvature = a - 2.0 * b + c;
            if curvature < 0.0 {
                log_theta += step * (0.5 * (a - c) / curvature).clamp(-0.5, 0.5);
            }
        }
        theta_scale.push(log_theta.exp().min(FRAC_PI_2));
    }
    // Azimuths with negligible mass (an off-axis lobe seen from the far side) do not set the
    // widths.
    let heaviest = peak_mass.iter().copied().fold(0.0, f64::max);
    let mut narrowest = (f64::INFINITY, 0.0);
    let mut widest = (0.0f64, 0.0);
    for ((&s, &m), &phi) in theta_scale.iter().zip(&peak_mass).zip(&azimuths) {
        if s.is_finite() && m >= 1e-6 * heaviest {
            if s < narrowest.0 {
                narrowest = (s, phi);
            }
            if s > widest.0 {
                widest = (s, phi);
            }
        }
    }
    if !narrowest.0.is_finite() {
        narrowest = (FALLBACK_WIDTH, 0.0);
        widest = (FALLBACK_WIDTH, 0.0);
    }
    let starts: Vec<(f64, f64)> = start_points
        .iter()
        .filter(|m| m.iter().all(|c| c.is_finite()) && m[2] >= 0.0)
        .map(|&m| angles(m))
        .collect();
    if let Some(fetch) = prefetch {
        let dirs: Vec<Vec3> = starts.iter().map(|&(t, f)| direction(t, f)).collect();
        fetch(&dirs);
    }
    for &(t, phi) in &starts {
        let v = clean(p, t, phi);
        evaluations += 1;
        if v > best.0 {
            best = (v, t, phi);
        }
    }
    let mut mode = None;
    if best.0 > 0.0 {
        let (found, spent) = climb_many(p, prefetch, &[best], narrowest.0)[0];
        evaluations += spent;
        let (m, spent) = widths(p, prefetch, found);
        evaluations += spent;
        if off_pole(&m, narrowest.0) {
            mode = Some(m);
        }
    }
    // The start points that climb elsewhere: further modes.
    let mut extra_modes: Vec<Mode> = Vec::new();
    let mut starts: Vec<(f64, f64, f64)> = starts
        .iter()
        .map(|&(t, phi)| (clean(p, t, phi), t, phi))
        .filter(|s| s.0 > 0.0)
        .collect();
    evaluations += start_points.len() as u64;
    starts.sort_by(|a, b| b.0.total_cmp(&a.0));
    // All climbed at once (one call a round for an external model), then taken in order as
    // one at a time would: the first MAX_EXTRA_MODES that lead to a new mode.
    let climbs = climb_many(p, prefetch, &starts, narrowest.0);
    evaluations += climbs.iter().map(|c| c.1).sum::<u64>();
    for (found, _) in climbs {
        if extra_modes.len() >= MAX_EXTRA_MODES {
            break;
        }
        let known = mode
            .iter()
            .chain(&extra_modes)
            .any(|k| same_mode(k, found.1, found.2));
        if known {
            continue;
        }
        let (m, spent) = widths(p, prefetch, found);
        evaluations += spent;
        if off_pole(&m, narrowest.0) {
            extra_modes.push(m);
        }
    }
    Lobe {
        azimuths,
        theta_scale,
        narrowest: narrowest.0,
        narrowest_azimuth: narrowest.1,
        widest: widest.0,
        widest_azimuth: widest.1,
        mode,
        extra_modes,
        evaluations,
    }
}

/// Whether a mode is off the pole: by a tenth of the narrowest scale `scale`, or by more than
/// twice its own θ half-width (a lobe 2e-7 wide at θ 1e-3, where the survey saw nothing and
/// the scale is the fallback's; the half-width towards the pole is at most θ, so a climb that
/// stops near the pole of a lobe centred there is not a mode).
fn off_pole(m: &Mode, scale: f64) -> bool {
    m.theta > 0.1 * scale || m.theta > 2.0 * m.width_theta
}

/// Whether (θ, φ) lies within the half-widths of the mode `k` (twice its widths, so that two
/// climbs to one mode that stop a step apart are one mode).
fn same_mode(k: &Mode, theta: f64, phi: f64) -> bool {
    let d_phi = (phi - k.phi).rem_euclid(TAU);
    let d_phi = d_phi.min(TAU - d_phi);
    (theta - k.theta).abs() <= 2.0 * k.width_theta && d_phi * k.theta.sin() <= 2.0 * k.width_arc
}

/// The half-widths of the mode `at` = (p, θ, φ): along ±θ and ±arc, where p falls below
/// e^{−1/2}·p(mode), probed geometrically from [`WIDTH_PROBE_MIN`] then bisected in ln width 8
/// times. With `prefetch`, the four ladders of probes (83 points each) go in one call and the
/// bisections a step of all four at a time: 9 calls, not ~360.
fn widths(
    p: &(dyn Fn(Vec3) -> f64 + Sync),
    prefetch: Prefetch<'_>,
    at: (f64, f64, f64),
) -> (Mode, u64) {
    let (v, theta, phi) = at;
    let level = v * (-0.5f64).exp();
    let sin = theta.sin().max(1e-300);
    // The four directions from the mode, as the point at distance w along each (None: beyond
    // the hemisphere in θ, where the density counts 0).
    let along = |k: usize, w: f64| -> Option<(f64, f64)> {
        match k {
            0 | 1 => {
                let t = if k == 0 { theta + w } else { theta - w };
                (0.0..=FRAC_PI_2).contains(&t).then_some((t, phi))
            }
            2 => Some((theta, phi + w / sin)),
            _ => Some((theta, phi - w / sin)),
        }
    };
    let value = |k: usize, w: f64| along(k, w).map_or(0.0, |(t, f)| clean(p, t, f));
    let fetch = |points: &[(usize, f64)]| {
        if let Some(fetch) = prefetch {
            let dirs: Vec<Vec3> = points
                .iter()
                .filter_map(|&(k, w)| along(k, w))
                .map(|(t, f)| direction(t, f))
                .collect();
            fetch(&dirs);
        }
    };
    // The geometric probes, all four ladders in one call, then each walked out until p falls
    // below the level (or past π).
    let mut ladder = vec![WIDTH_PROBE_MIN * PROBE_FACTOR];
    while ladder[ladder.len() - 1] <= PI {
        ladder.push(ladder[ladder.len() - 1] * PROBE_FACTOR);
    }
    let probes: Vec<(usize, f64)> = (0..4)
        .flat_map(|k| ladder.iter().map(move |&w| (k, w)))
        .collect();
    fetch(&probes);
    let mut spent = probes.len() as u64;
    let mut bracket = [(WIDTH_PROBE_MIN, WIDTH_PROBE_MIN); 4];
    for (k, b) in bracket.iter_mut().enumerate() {
        let mut below = WIDTH_PROBE_MIN;
        let mut above;
        loop {
            above = below * PROBE_FACTOR;
            if value(k, above) < level || above > PI {
                break;
            }
            below = above;
        }
        *b = (below, above);
    }
    // Bisection in ln width, the four in lockstep: a call a step.
    for _ in 0..8 {
        let mids: Vec<(usize, f64)> = (0..4)
            .map(|k| (k, (bracket[k].0 * bracket[k].1).sqrt()))
            .collect();
        fetch(&mids);
        spent += 4;
        for (k, mid) in mids {
            if value(k, mid) < level {
                bracket[k].1 = mid;
            } else {
                bracket[k].0 = mid;
            }
        }
    }
    let half = |k: usize| (bracket[k].0 * bracket[k].1).sqrt();
    (
        Mode {
            theta,
            phi,
            width_theta: half(0).min(half(1)).min(FRAC_PI_2),
            width_arc: half(2).min(half(3)).min(PI),
        },
        spent,
    )
}

impl Lobe {
    /// A lobe at the pole of the stated width along every azimuth (the compatibility path of
    /// callers that still read a width from a spec; no measurement).
    pub fn isotropic(width: f64) -> Self {
        let width = if width.is_finite() && width > 0.0 {
            width.min(FRAC_PI_2)
        } else {
            FALLBACK_WIDTH
        };
        Self {
            azimuths: vec![0.0],
            theta_scale: vec![width],
            narrowest: width,
            narrowest_azimuth: 0.0,
            widest: width,
            widest_azimuth: 0.0,
            mode: None,
            extra_modes: Vec::new(),
            evaluations: 0,
        }
    }

    /// The narrowest width: what `check::lobe_width` used to read from the spec.
    pub fn width(&self) -> f64 {
        self.narrowest
    }

    /// widest / narrowest (1 for an isotropic lobe).
    pub fn anisotropy(&self) -> f64 {
        self.widest / self.narrowest
    }

    /// Polar cut points strictly inside (0, `theta_max`), with 0 and `theta_max` added: the
    /// narrowest scale × {10⁻³ … 1}, geometric steps of at most 3 up to the widest, the widest ×
    /// {1 … 10²}, and the mode ± its θ half-width × {0.3 … 64}. Sorted, without points
    /// closer than 1e-3 relative.
    pub fn polar_cuts(&self, theta_max: f64) -> Vec<f64> {
        let mut cuts = vec![0.0, theta_max];
        // Below the narrowest scale and above the widest, the former fixed multiples; between
        // them geometric steps of at most 3 (not every multiple of every scale: each cut costs
        // every inner integral a piece).
        cuts.extend(
            SCALE_MULTIPLES
                .iter()
                .filter(|&&k| k <= 1.0)
                .map(|k| k * self.narrowest),
        );
        let steps = (self.widest / self.narrowest).ln() / 3f64.ln();
        let steps = steps.ceil().max(0.0) as usize;
        for i in 1..steps {
            cuts.push(
                self.narrowest * (self.widest / self.narrowest).powf(i as f64 / steps as f64),
            );
        }
        cuts.extend(
            SCALE_MULTIPLES
                .iter()
                .filter(|&&k| k >= 1.0)
                .map(|k| k * self.widest),
        );
        let mut finest = f64::INFINITY;
        for m in self.mode.iter().chain(&self.extra_modes) {
            cuts.push(m.theta);
            for k in mode_multiples(m.width_theta, theta_max) {
                cuts.push(m.theta - k * m.width_theta);
                cuts.push(m.theta + k * m.width_theta);
            }
            finest = finest.min(MODE_GAP * m.width_theta);
        }
        tidy(cuts, 0.0, theta_max, finest)
    }

    /// [`Lobe::polar_cuts`] with the polar angles `kinks` strictly inside (0, `theta_max`)
    /// added exactly (where a density has a kink for every azimuth, e.g. the breakpoints of a
    /// piecewise-linear profile: an integral cut there meets only smooth pieces), sorted,
    /// exact duplicates removed (a kink close to a lobe cut keeps both: a thin piece costs one
    /// more rule, a kink moved by 1e-3 would cost the quadrature its smoothness).
    pub fn polar_cuts_with(&self, theta_max: f64, kinks: &[f64]) -> Vec<f64> {
        let mut polar = self.polar_cuts(theta_max);
        polar.extend(kinks.iter().copied().filter(|t| *t > 0.0 && *t < theta_max));
        polar.sort_by(f64::total_cmp);
        polar.dedup();
        polar
    }

    /// Azimuthal cut points in [0, 2π] (both ends included): the quadrants; for an anisotropic
    /// lobe (widest/narrowest > 1.5) the widest and narrowest azimuths and their opposites, with
    /// cuts about the widest at ± (narrowest/widest) × {0.3 … 30} (where the lobe's azimuthal
    /// extent is at polar angles between the two scales); about an off-axis mode, ± its arc
    /// half-width / sin θ × {0.3 … 64}.
    pub fn azimuth_cuts(&self) -> Vec<f64> {
        let mut cuts = vec![0.0, 0.5 * PI, PI, 1.5 * PI, TAU];
        if self.anisotropy() > 1.5 {
            let ratio = self.narrowest / self.widest;
            for centre in [self.widest_azimuth, self.widest_azimuth + PI] {
                cuts.push(centre);
                for k in [0.3, 1.0, 3.0, 10.0, 30.0] {
                    if k * ratio < 0.5 {
                        cuts.push(centre - k * ratio);
                        cuts.push(centre + k * ratio);
                    }
                }
            }
            cuts.push(self.narrowest_azimuth);
            cuts.push(self.narrowest_azimuth + PI);
        }
        let mut finest = f64::INFINITY;
        for m in self.mode.iter().chain(&self.extra_modes) {
            let half = m.width_arc / m.theta.sin().max(1e-300);
            cuts.push(m.phi);
            for k in mode_multiples(half, PI) {
                if k * half < PI {
                    cuts.push(m.phi - k * half);
                    cuts.push(m.phi + k * half);
                }
            }
            finest = finest.min(MODE_GAP * half);
        }
        let wrapped = cuts
            .into_iter()
            .map(|c| if c == TAU { c } else { c.rem_euclid(TAU) })
            .collect();
        tidy(wrapped, 0.0, TAU, finest)
    }
}

/// Sorts `cuts`, keeps those in [lo, hi] (the ends included), and drops points closer than
/// 1e-3 relative, or `finest` if that is smaller (a mode's cuts are as fine as its width:
/// a lobe 2e-7 wide at θ 0.9 fell between cuts 1e-3 apart), to the one kept before them, with
/// a floor of 1e-15 absolute.
fn tidy(mut cuts: Vec<f64>, lo: f64, hi: f64, finest: f64) -> Vec<f64> {
    cuts.retain(|c| c.is_finite() && *c > lo && *c < hi);
    cuts.push(lo);
    cuts.push(hi);
    cuts.sort_by(f64::total_cmp);
    let mut out: Vec<f64> = Vec::with_capacity(cuts.len());
    for c in cuts {
        match out.last() {
            Some(&last) if c - last <= (1e-3 * c.abs()).min(finest).max(1e-15) => {
                if c == hi {
                    *out.last_mut().expect("not empty") = hi;
                }
            }
            _ => out.push(c),
        }
    }
    if out.len() == 1 {
        out.push(hi);
    }
    out
}

#[cfg(test)]
#[path = "lobe_tests.rs"]
mod tests;
