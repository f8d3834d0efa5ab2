//! Where samplers change regime, and how a failure is narrowed to a region: the incidences the
//! Jacobian checks sweep (near normal, log-spaced in the stretched tilt α tan θi; around the
//! critical angle on both sides; towards grazing; drawn per seed), the [`Density`] of a
//! sampling map u ↦ direction by Richardson-extrapolated central differences and its bounds
//! (measured in `check/step_ladder.rs`), and the bisection that narrows a failure found at some
//! incidences to the interval of θi where it holds (the record's [`Region`]).
//!
//! A Jacobian check is deterministic, cheap (tens of sampler calls a point) and local: it sees
//! a 1 % density error in a corner of the incidences that a chi-square over the whole sphere
//! dilutes, so it runs at many incidences where the chi-square runs at a handful.

use crate::precision::Precision;
use crate::random::Stream;
use crate::record::Region;
use mfh_reference::geometry::Vec3;

/// The stretched tilts t = α tan θi of the near-normal sweep: a quarter decade apart from 1e-6
/// to 1e-1. A sampler that switches its frame or its branch at a tilt t₀ is seen at the tilts
/// within its region; a quarter decade keeps one of them inside a region half a decade wide
/// even where the lobe's α is only known to a factor 1.5.
pub fn stretched_tilts() -> Vec<f64> {
    (0..=20)
        .map(|k| 10f64.powf(-6.0 + 0.25 * f64::from(k)))
        .collect()
}

/// The offsets (radians) from the critical angle, on both sides, of the critical sweep.
pub const CRITICAL_OFFSETS: [f64; 5] = [1e-4, 1e-3, 3e-3, 1e-2, 3e-2];

/// The cosines of the grazing sweep.
pub const GRAZING_COSINES: [f64; 3] = [0.1, 0.03, 0.01];

/// The polar angles of the oblique incidences.
pub const OBLIQUE_THETAS: [f64; 2] = [0.5, 1.0];

/// The incidences drawn per seed.
pub const DRAWN: usize = 4;

/// The azimuth of the fixed incidences: off the axes of an anisotropic lobe and of the grid's
/// column edges (as the BSDF checks' [`crate::check::bsdf::Incidence`]).
pub const PHI: f64 = 0.3;

/// One incidence of a sweep: its polar angle θi (from the side's normal), azimuth and what
/// regime put it there.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SweepPoint {
    /// θi, radians, measured from the normal on the incidence's side.
    pub theta: f64,
    /// The azimuth.
    pub phi: f64,
    /// `near_normal`, `critical`, `oblique`, `grazing` or `drawn`.
    pub regime: &'static str,
}

impl SweepPoint {
    /// The direction, in the upper hemisphere (`inside`: mirrored below).
    pub fn direction(&self, inside: bool) -> Vec3 {
        let (s, c) = self.theta.sin_cos();
        let z = if inside { -c } else { c };
        [s * self.phi.cos(), s * self.phi.sin(), z]
    }
}

/// The incidences of one side: near normal (tan θi = t/`alpha` over [`stretched_tilts`], those
/// not beyond the grazing ones, cos θi ≥ 0.01: at α 1e-7 the stretched tilts 1e-6 … 1e-1 are
/// cos θi 0.1 … 1e-6, where the sampler is in its grazing regime, not its near-normal one),
/// oblique, grazing, around `critical` (θc ± [`CRITICAL_OFFSETS`]) when the side has a critical
/// angle, and [`DRAWN`] drawn from `seed` (θi uniform in cos θ ∈ (0.01, 1), φ uniform), sorted
/// by θi.
pub fn sweep(alpha: f64, critical: Option<f64>, seed: Option<u64>) -> Vec<SweepPoint> {
    let mut out: Vec<SweepPoint> = stretched_tilts()
        .into_iter()
        .map(|t| SweepPoint {
            theta: (t / alpha).atan(),
            phi: PHI,
            regime: "near_normal",
        })
        .filter(|p| p.theta.cos() >= GRAZING_COSINES[2])
        .collect();
    for theta in OBLIQUE_THETAS {
        out.push(SweepPoint {
            theta,
            phi: PHI,
            regime: "oblique",
        });
    }
    for c in GRAZING_COSINES {
        out.push(SweepPoint {
            theta: c.acos(),
            phi: PHI,
            regime: "grazing",
        });
    }
    if let Some(tc) = critical {
        for d in CRITICAL_OFFSETS {
            for theta in [tc - d, tc + d] {
                if theta > 0.0 && theta.cos() > GRAZING_COSINES[2] {
                    out.push(SweepPoint {
                        theta,
                        phi: PHI,
                        regime: "critical",
                    });
                }
            }
        }
    }
    if let Some(seed) = seed {
        // Stream id: a constant of this sweep, so the draws depend on the seed alone.
        let mut rng = Stream::new(seed, 0x5eed_5eee);
        for _ in 0..DRAWN {
            let [a, b] = rng.pair();
            let c = 0.01 + 0.99 * a;
            out.push(SweepPoint {
                theta: c.acos(),
                phi: std::f64::consts::TAU * b,
                regime: "drawn",
            });
        }
    }
    out.sort_by(|a, b| a.theta.total_cmp(&b.theta));
    out
}

/// The step in u of the central differences for a map computed in `precision`, and the
/// relative disagreement between the step and half of it beyond which a point is unresolved
/// (see `check/jacobian.rs` for the derivation: f64 steps 1e-4/5e-5, round-off ≈ 2e-12 and
/// truncation O(h⁴) after extrapolation; f32 steps 4e-3/2e-3 at ε₃₂^(1/3)).
pub fn stencil(precision: Precision) -> (f64, f64) {
    match precision {
        Precision::F64 => (1e-4, 1e-3),
        Precision::F32 => (4e-3, 1e-2),
    }
}

/// The quasi-random points (u₁, u₂) of a Jacobian check: a golden-ratio lattice of `n` points
/// kept 2.5 steps from the square's edges (the stencil reaches 1 step out), so that the
/// corners of u that map near the horizon of a warped disk are measured too.
pub fn points(n: usize, step: f64) -> Vec<[f64; 2]> {
    let margin = 2.5 * step;
    let span = 1.0 - 2.0 * margin;
    let golden = 0.618_033_988_749_894_9;
    (0..n)
        .map(|i| {
            let i = i as f64;
            [
                margin + span * (i + 0.5) / n as f64,
                margin + span * (i * golden).fract(),
            ]
        })
        .collect()
}

/// The three central-difference densities 1/|∂w/∂u₁ × ∂w/∂u₂| at one point, with steps h,
/// h/2 and h/4. The Richardson extrapolation (4 D(h/4) − D(h/2))/3 cancels the h² error of the
/// two finer ones; the same extrapolation of the two coarser ones differs from it by about its
/// own error (16 × the finer pair's, where the map is smooth at the step's scale), which is what
/// the point is allowed for it: a spread |D(h) − D(h/2)| alone is no bound where the map is not
/// yet in its asymptotic regime at h (measured: the η 0.1, α 1e4 dielectric from inside at
/// θi 1.541, whose densities at h = 1e-4, 5e-5, 2.5e-5 … 3e-6 are 778.35238, 778.35271,
/// 778.35121 … 778.350568 for a pdf of 778.350566: the first pair's spread, 4e-7, is 7 × below
/// the error of its extrapolation, 2.9e-6).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Density {
    /// With step h.
    pub coarse: f64,
    /// With step h/2.
    pub fine: f64,
    /// With step h/4.
    pub finest: f64,
    /// A bound on the extrapolated density's relative rounding error ([`rounding_bound`]).
    pub rounding: f64,
    /// The relative difference of the extrapolated density from the next finer step's (h/2,
    /// h/4, h/8), where it was measured (`check/step_ladder.rs`), else 0.
    pub finer: f64,
}

/// The ulps of each component of a sampled direction that the rounding bound allows at the
/// least: a map computed in float32 is a chain of a few dozen operations, each direction
/// component within a few ulps of its exact value (the reference GGX's f32 visible sampler
/// measured ≤ 3). A map that amplifies its intermediate rounding (a refraction near the critical
/// angle at η 10: 1 − η² sin² θ cancels) is allowed what its measured noise shows
/// ([`NOISE_DIVISOR`]).
pub const DIRECTION_ULPS: f64 = 8.0;

/// The rounding of one direction component is bounded by the largest fourth difference of the
/// stencil's five points along u₁ and along u₂ (−h, −h/2, 0, h/2, h), divided by this: a map
/// smooth at the step's scale contributes w⁗·(h/2)⁴ to it, far below its rounding (≈ 1e-18
/// at the η 10, α 1e-7 corner, whose rounding is ≈ 1e-14), so the fourth difference is its
/// rounding noise, free of extra evaluations. Of errors bounded by E it is at most 16 E; of
/// independent errors of standard deviation s it is ≈ 8.4 s (√70 s), so that the largest of the
/// six (2 axes × 3 components) is ≳ 8 s and a half of it ≳ 4 s bounds the errors of the eight
/// stencil directions. (A probe of the map at c ± 64 ε, tried first, sees no noise where the
/// map's derivatives are small: its directions move by less than an ulp, all rounded alike.)
pub const NOISE_DIVISOR: f64 = 2.0;

/// The relative rounding error of a central-difference density from directions each of whose
/// components is within `e` of its exact value: each component of a column a = (p − q)/(2h) is
/// off by ≤ 2e/(2h), so a by a vector δa of length ≤ √3·e/h, and |a × b| by ≤ |δa||b| + |a||δb|;
/// the density 1/|a × b| by ≤ r = √3·e/h·(|a| + |b|)/|a × b| to first order at step h (for
/// orthogonal columns √3·e/h·(1/|a| + 1/|b|); columns nearly parallel, a map that shears u,
/// amplify it by |a||b|/|a × b|: 3 150 for GGX α 1e4 refracting into η 0.1 at cos θi 0.03,
/// whose densities at step 1.25e-5 are off by 3e-6 where the orthogonal bound says 6.5e-7).
/// The steps h/2 and h/4 double and quadruple r, and the extrapolation (4 D(h/4) − D(h/2))/3
/// weighs the two errors 4/3 and 1/3: ≤ (16r + 2r)/3 = 6r. Negligible for an f64 map of
/// ε-accurate directions (~1e-8 at |a| = 1e-3), it is what limits a float32 map at tiny
/// roughness, whose derivatives are of the order of α: at α = 0.001 and step 4e-3, r reaches
/// ~0.1. `a`, `b` and `cross` are |a|, |b| and |a × b| at step h.
pub fn rounding_bound(e: f64, h: f64, (a, b, cross): (f64, f64, f64)) -> f64 {
    6.0 * 3f64.sqrt() * e / h * (a + b) / cross
}

impl Density {
    /// The extrapolated density.
    pub fn value(&self) -> f64 {
        (4.0 * self.finest - self.fine) / 3.0
    }

    /// The larger of |D(h) − D(h/2)| and |D(h/2) − D(h/4)|, relative: the size of the
    /// extrapolated term; a point where it is large has a kink or a branch within its stencil.
    pub fn spread(&self) -> f64 {
        ((self.coarse - self.fine) / self.fine)
            .abs()
            .max(((self.fine - self.finest) / self.finest).abs())
    }

    /// Whether the point's densities can be judged: its [`spread`] is at most `unresolved` and
    /// they converge as h² (the differences D(h) − D(h/2) and D(h/2) − D(h/4) in a ratio
    /// within [2, 8] of the asymptotic 4), or differ by no more than twice their rounding
    /// bound. A point whose densities wander instead (its map not yet smooth at the step's
    /// scale, or its rounding beyond the bound: GGX α 1e4 refracting into η 0.1 at step 6e-6,
    /// whose differences are in a ratio of 50) says nothing at this step; the step ladder
    /// (`check/step_ladder.rs`) measures it at others.
    ///
    /// [`spread`]: Density::spread
    pub fn resolved(&self, unresolved: f64) -> bool {
        let first = self.coarse - self.fine;
        let second = self.fine - self.finest;
        let ratio = first / second;
        self.spread() <= unresolved
            && (self.spread() <= 2.0 * self.rounding || (2.0..=8.0).contains(&ratio))
    }

    /// The error of the extrapolation, relative: its difference from the coarser pair's.
    pub fn extrapolation(&self) -> f64 {
        let coarser = (4.0 * self.fine - self.coarse) / 3.0;
        ((coarser - self.value()) / self.value()).abs()
    }

    /// What a point's error is allowed beyond the tolerance: the [`extrapolation`]'s error (or
    /// the difference from the finer step's extrapolation, [`Density::finer`], if larger) and
    /// the rounding bound.
    ///
    /// [`extrapolation`]: Density::extrapolation
    pub fn allowance(&self) -> f64 {
        self.extrapolation().max(self.finer) + self.rounding
    }
}

/// A sampling map in batch: `out[k]` the direction of `u[k]` (u₀, u₁, u₂), None where it fails.
pub type BatchMap<'m> = dyn FnMut(&[[f64; 3]], &mut [Option<Vec3>]) + 'm;

/// |a|, |b| and |a × b| of two columns.
pub fn column_lengths((a, b): ([f64; 3], [f64; 3])) -> (f64, f64, f64) {
    let norm = |v: [f64; 3]| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    let x = [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ];
    (norm(a), norm(b), norm(x))
}

/// What one incidence of a sweep measured: the worst relative error of the stated pdf against
/// the map's density over the resolved points, in excess of the points' own allowance.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AtIncidence {
    /// θi.
    pub theta: f64,
    /// The worst |stated − density| / density over the resolved points.
    pub worst: f64,
    /// The worst error beyond the point's own extrapolation spread ([`Density::spread`]): what
    /// is judged against the tolerance.
    pub excess: f64,
    /// Whether `excess` exceeds the tolerance (or a point is not a direction or a density).
    pub fails: bool,
    /// Points resolved / measured.
    pub resolved: usize,
    /// Points measured.
    pub measured: usize,
}

impl AtIncidence {
    /// Nothing measured yet at θi `theta`, of `measured` points.
    pub fn new(theta: f64, measured: usize) -> Self {
        AtIncidence {
            theta,
            worst: 0.0,
            excess: 0.0,
            fails: false,
            resolved: 0,
            measured,
        }
    }

    /// Counts one resolved point: its relative error and its excess over its allowance.
    pub fn add(&mut self, error: f64, excess: f64) {
        self.resolved += 1;
        self.worst = self.worst.max(error);
        if !(excess <= self.excess) {
            self.excess = excess;
        }
    }
}

/// The verdict of a Jacobian sweep: an error (it cannot judge) when fewer than the fraction
/// `need` of the `measured` points had a smooth map within the stencil, else fail or pass.
pub fn verdict(resolved: usize, measured: usize, need: f64, fails: bool) -> crate::record::Verdict {
    use crate::record::Verdict;
    if (resolved as f64) < need * measured as f64 {
        Verdict::Error {
            message: format!(
                "only {resolved} of {measured} points had a smooth sampling map within the \
                 finite-difference stencil (need {:.0} %)",
                100.0 * need
            ),
        }
    } else if fails {
        Verdict::Fail
    } else {
        Verdict::Pass
    }
}

/// Bisection steps of [`narrow`] on each side of a failing run.
pub const NARROW_STEPS: usize = 8;

/// Narrows the failures of a sweep (`at`, sorted by θ) to the region around the worst failing
/// incidence: the run of failing incidences that contains it, each end refined by
/// [`NARROW_STEPS`] bisections in θ towards the neighbouring passing incidence (`measure`
/// re-measures at any θ). None when nothing fails. `what` and `context` word the sentence:
/// "density off by up to 1.1 % for θi ∈ [0, 0.089] rad at α 0.05".
pub fn narrow(
    at: &[AtIncidence],
    measure: &mut dyn FnMut(f64) -> AtIncidence,
    what: &str,
    context: &str,
) -> Option<Region> {
    let worst = at
        .iter()
        .enumerate()
        .filter(|(_, a)| a.fails)
        .max_by(|a, b| a.1.worst.total_cmp(&b.1.worst))?
        .0;
    let mut lo = worst;
    while lo > 0 && at[lo - 1].fails {
        lo -= 1;
    }
    let mut hi = worst;
    while hi + 1 < at.len() && at[hi + 1].fails {
        hi += 1;
    }
    let mut largest = at[lo..=hi].iter().map(|a| a.worst).fold(0.0, f64::max);
    let mut refine = |failing: f64, passing: f64, largest: &mut f64| {
        let (mut f, mut p) = (failing, passing);
        for _ in 0..NARROW_STEPS {
            let mid = 0.5 * (f + p);
            let m = measure(mid);
            if m.fails {
                f = mid;
                *largest = largest.max(m.worst);
            } else {
                p = mid;
            }
        }
        f
    };
    let from = if lo > 0 {
        refine(at[lo].theta, at[lo - 1].theta, &mut largest)
    } else {
        at[lo].theta
    };
    let to = if hi + 1 < at.len() {
        refine(at[hi].theta, at[hi + 1].theta, &mut largest)
    } else {
        at[hi].theta
    };
    let failing = at.iter().filter(|a| a.fails).count();
    Some(Region {
        quantity: "theta_i".into(),
        from,
        to,
        worst: largest,
        at: at[worst].theta,
        failing_incidences: failing,
        incidences: at.len(),
        text: format!(
            "{what} off by up to {} for θi ∈ [{from:.3e}, {to:.3e}] rad {context} \
             ({failing} of {} incidences fail)",
            percent(largest),
            at.len()
        ),
    })
}

/// A relative error as a percentage with two significant digits.
fn percent(e: f64) -> String {
    if e.is_finite() {
        format!("{:.2} %", 100.0 * e)
    } else {
        format!("{e}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_near_normal_sweep_spans_the_stretched_tilts() {
        let s = sweep(0.05, None, Some(7));
        let near: Vec<_> = s.iter().filter(|p| p.regime == "near_normal").collect();
        assert_eq!(near.len(), 21);
        let t: Vec<f64> = near.iter().map(|p| 0.05 * p.theta.tan()).collect();
        assert!((t[0] / 1e-6 - 1.0).abs() < 1e-12 && (t[20] / 1e-1 - 1.0).abs() < 1e-12);
        assert!(s.windows(2).all(|w| w[0].theta <= w[1].theta));
        assert_eq!(s.iter().filter(|p| p.regime == "drawn").count(), DRAWN);
        // Drawn per seed: another seed, other incidences; the same seed, the same.
        assert_eq!(s, sweep(0.05, None, Some(7)));
        assert_ne!(s, sweep(0.05, None, Some(8)));
        // At α 1e-7 the stretched tilts below 1e-5 only (tan θi < 100): cos θi ≥ 0.01.
        let tiny = sweep(1e-7, None, None);
        let near: Vec<_> = tiny.iter().filter(|p| p.regime == "near_normal").collect();
        assert_eq!(near.len(), 4, "{near:?}");
        assert!(tiny.iter().all(|p| p.theta.cos() >= 0.01 - 1e-15));
    }

    #[test]
    fn the_critical_sweep_lies_on_both_sides() {
        let tc = (1.0f64 / 1.5).asin();
        let s = sweep(0.3, Some(tc), None);
        let c: Vec<f64> = s
            .iter()
            .filter(|p| p.regime == "critical")
            .map(|p| p.theta - tc)
            .collect();
        assert_eq!(c.len(), 10);
        assert_eq!(c.iter().filter(|d| **d < 0.0).count(), 5);
    }

    #[test]
    fn narrowing_finds_the_edge_of_a_failing_interval() {
        // A defect for θ < 0.089: the region's end within 2⁻⁸ of the gap it was bracketed in.
        let f = |theta: f64| AtIncidence {
            theta,
            worst: if theta < 0.089 { 0.011 } else { 1e-9 },
            excess: if theta < 0.089 { 0.011 } else { 0.0 },
            fails: theta < 0.089,
            resolved: 1,
            measured: 1,
        };
        let at: Vec<_> = [0.001, 0.01, 0.05, 0.1, 0.5].into_iter().map(f).collect();
        let r = narrow(&at, &mut |t| f(t), "density", "at α 0.05").unwrap();
        assert_eq!(r.from, 0.001);
        assert!(r.to < 0.089 && r.to > 0.089 - 0.05 / 256.0, "{}", r.to);
        assert!(r.text.contains("1.10 %"), "{}", r.text);
        assert_eq!(r.failing_incidences, 3);
        assert!(narrow(&at[3..], &mut |t| f(t), "density", "").is_none());
    }
}

#[cfg(test)]
mod kill_tests;
