//! Monte Carlo estimates with standard errors: seeded, counter-based streams (one per chunk of
//! samples), reduced in chunk order, so that the estimate does not depend on the thread count.

use crate::random::{stream, uniform};
use rayon::prelude::*;

/// Samples per chunk: each chunk has its own random stream keyed by (seed, chunk index).
pub const CHUNK: u64 = 1 << 14;

/// A Monte Carlo estimate of a mean.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct McEstimate {
    /// The sample mean.
    pub mean: f64,
    /// Its standard error √(s²/n).
    pub standard_error: f64,
    /// Samples drawn.
    pub samples: u64,
}

/// Per-chunk running sums (count, mean, M2) merged by Chan et al.'s parallel update.
#[derive(Clone, Copy, Default)]
struct Moments {
    n: f64,
    mean: f64,
    m2: f64,
}

impl Moments {
    fn push(&mut self, x: f64) {
        self.n += 1.0;
        let d = x - self.mean;
        self.mean += d / self.n;
        self.m2 += d * (x - self.mean);
    }

    fn merge(self, o: Moments) -> Moments {
        if self.n == 0.0 {
            return o;
        }
        if o.n == 0.0 {
            return self;
        }
        let n = self.n + o.n;
        let d = o.mean - self.mean;
        Moments {
            n,
            mean: self.mean + d * o.n / n,
            m2: self.m2 + o.m2 + d * d * self.n * o.n / n,
        }
    }
}

/// The mean of `f(u)` over `samples` points u uniform in [0, 1)², with its standard error.
/// Chunks run in parallel; their moments are merged in chunk order.
pub fn estimate<F>(f: &F, samples: u64, seed: u64) -> McEstimate
where
    F: Fn([f64; 2]) -> f64 + Sync + ?Sized,
{
    let chunks = samples.div_ceil(CHUNK);
    let deadline = crate::deadline::current();
    let parts: Vec<Moments> = (0..chunks)
        .into_par_iter()
        .map(|chunk| {
            crate::deadline::check(deadline);
            let mut rng = stream(seed, chunk);
            let mut m = Moments::default();
            let end = ((chunk + 1) * CHUNK).min(samples);
            for _ in chunk * CHUNK..end {
                let u = [uniform(&mut rng), uniform(&mut rng)];
                m.push(f(u));
            }
            m
        })
        .collect();
    finish(parts, samples)
}

/// [`estimate`] for a batch integrand (`f(u, out)` writes f(u\[i\]) into out\[i\]): each chunk's
/// uniforms are drawn as [`estimate`] draws them and handed to `f` in one call, then pushed in
/// order, so the estimate is the scalar form's bit for bit (an external model pays one round
/// trip per chunk of [`CHUNK`] samples, not per sample).
pub fn estimate_batch<F>(f: &F, samples: u64, seed: u64) -> McEstimate
where
    F: Fn(&[[f64; 2]], &mut [f64]) + Sync + ?Sized,
{
    let chunks = samples.div_ceil(CHUNK);
    let deadline = crate::deadline::current();
    let parts: Vec<Moments> = (0..chunks)
        .into_par_iter()
        .map(|chunk| {
            crate::deadline::check(deadline);
            let mut rng = stream(seed, chunk);
            let end = ((chunk + 1) * CHUNK).min(samples);
            let u: Vec<[f64; 2]> = (chunk * CHUNK..end)
                .map(|_| [uniform(&mut rng), uniform(&mut rng)])
                .collect();
            let mut values = vec![0.0; u.len()];
            f(&u, &mut values);
            let mut m = Moments::default();
            for v in values {
                m.push(v);
            }
            m
        })
        .collect();
    finish(parts, samples)
}

fn finish(parts: Vec<Moments>, samples: u64) -> McEstimate {
    let all = parts.into_iter().fold(Moments::default(), Moments::merge);
    let variance = if all.n > 1.0 {
        all.m2 / (all.n - 1.0)
    } else {
        f64::NAN
    };
    McEstimate {
        mean: all.mean,
        standard_error: (variance / all.n).sqrt(),
        samples,
    }
}

/// The two-sided p-value of a z-score, 2Q(|z|) = erfc(|z|/√2).
pub fn two_sided_p(z: f64) -> f64 {
    libm::erfc(z.abs() / std::f64::consts::SQRT_2)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mean_and_standard_error_of_known_integrals() {
        // E[u1 u2] = 1/4, Var = 1/9 − 1/16 = 7/144.
        let e = estimate(&|u: [f64; 2]| u[0] * u[1], 200_000, 5);
        assert!((e.mean - 0.25).abs() < 5.0 * e.standard_error, "{e:?}");
        let se = (7.0 / 144.0 / 200_000.0f64).sqrt();
        assert!((e.standard_error / se - 1.0).abs() < 0.02, "{e:?} vs {se}");
    }

    #[test]
    fn the_estimate_does_not_depend_on_the_thread_count() {
        let f = |u: [f64; 2]| (u[0] * 7.0).sin() + u[1];
        let many = estimate(&f, 100_000, 11);
        let one = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap()
            .install(|| estimate(&f, 100_000, 11));
        assert_eq!(many, one);
        assert_ne!(estimate(&f, 100_000, 12).mean, many.mean);
    }

    #[test]
    fn the_batch_form_is_the_scalar_form_bit_for_bit() {
        let f = |u: [f64; 2]| (u[0] * 7.0).sin() + u[1];
        let batch = |u: &[[f64; 2]], out: &mut [f64]| {
            for (o, &u) in out.iter_mut().zip(u) {
                *o = f(u);
            }
        };
        assert_eq!(
            estimate(&f, 3 * CHUNK + 17, 4),
            estimate_batch(&batch, 3 * CHUNK + 17, 4)
        );
    }

    #[test]
    fn p_values_of_z_scores() {
        assert!((two_sided_p(0.0) - 1.0).abs() < 1e-15);
        assert!((two_sided_p(1.959_963_984_540_054) - 0.05).abs() < 1e-12);
        assert_eq!(two_sided_p(-3.0), two_sided_p(3.0));
    }
}
