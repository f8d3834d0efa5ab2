//! The compass searches of the lobe measurement (`oracle/lobe.rs`), run in lockstep: each
//! round evaluates the four neighbours of every unfinished search in one batch. A search moves
//! exactly as it would alone (the same points in the same order, so the same mode bit for
//! bit); what changes is the number of calls. An external model pays a round trip per call:
//! the 34 start points of a BSDF's lobe centres, each climbed alone, cost an external child
//! ~38 000 requests of fewer than 64 directions in a ci audit (≈ 40 % of its wall time, measured
//! on the numpy dielectric child of `tools/hostile/`), where the lockstep costs one a round.

use super::lobe::{clean, direction, AZIMUTHS};
use mfh_reference::geometry::Vec3;
use std::f64::consts::{FRAC_PI_2, TAU};

/// Evaluates a batch of directions ahead of the scalar calls that will ask for them (a cache's
/// filler), or nothing.
pub type Prefetch<'a> = Option<&'a (dyn Fn(&[Vec3]) + Sync)>;

/// The most evaluations one search spends.
pub const CLIMB_EVALUATIONS: u64 = 400;

/// One compass search.
struct Search {
    v: f64,
    theta: f64,
    phi: f64,
    dt: f64,
    dp: f64,
    spent: u64,
    done: bool,
}

/// Compass searches for the mode of p from each of `starts` = (p, θ, φ): each moves to the
/// best of the four neighbours at (±Δθ, ±Δφ) while one is higher, else halves its steps,
/// until the neighbours differ from its centre by less than 1e-6 relative (the steps are then
/// ~1e-3 of the lobe's width) or [`CLIMB_EVALUATIONS`] are spent. The searches advance in
/// lockstep, each round's neighbours handed to `prefetch` in one batch first. Returns each
/// search's ((p, θ, φ), evaluations).
pub fn climb_many(
    p: &(dyn Fn(Vec3) -> f64 + Sync),
    prefetch: Prefetch<'_>,
    starts: &[(f64, f64, f64)],
    scale: f64,
) -> Vec<((f64, f64, f64), u64)> {
    let mut searches: Vec<Search> = starts
        .iter()
        .map(|&(v, theta, phi)| Search {
            v,
            theta,
            phi,
            dt: (0.3 * theta).max(0.1 * scale).min(0.5),
            dp: TAU / AZIMUTHS as f64,
            spent: 0,
            done: false,
        })
        .collect();
    loop {
        let active: Vec<usize> = (0..searches.len())
            .filter(|&i| !searches[i].done && searches[i].spent < CLIMB_EVALUATIONS)
            .collect();
        if active.is_empty() {
            break;
        }
        let candidates: Vec<[(f64, f64); 4]> = active
            .iter()
            .map(|&i| {
                let s = &searches[i];
                [
                    (s.theta + s.dt, s.phi),
                    ((s.theta - s.dt).max(0.0), s.phi),
                    (s.theta, (s.phi + s.dp).rem_euclid(TAU)),
                    (s.theta, (s.phi - s.dp).rem_euclid(TAU)),
                ]
                .map(|(t, f)| (t.min(FRAC_PI_2), f))
            })
            .collect();
        if let Some(fetch) = prefetch {
            let dirs: Vec<Vec3> = candidates
                .iter()
                .flatten()
                .map(|&(t, f)| direction(t, f))
                .collect();
            fetch(&dirs);
        }
        for (&i, round) in active.iter().zip(&candidates) {
            let s = &mut searches[i];
            let mut moved = false;
            let mut flat = true;
            for &(t, f) in round {
                let w = clean(p, t, f);
                s.spent += 1;
                if (w - s.v).abs() > 1e-6 * s.v {
                    flat = false;
                }
                if w > s.v {
                    (s.v, s.theta, s.phi) = (w, t, f);
                    moved = true;
                }
            }
            if !moved {
                if flat {
                    s.done = true;
                } else {
                    s.dt *= 0.5;
                    s.dp *= 0.5;
                }
            }
        }
    }
    searches
        .iter()
        .map(|s| ((s.v, s.theta, s.phi), s.spent))
        .collect()
}
