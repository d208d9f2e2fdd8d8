//! `pushbot bench knn`: how fast a regression query is at a given strategy size.

use std::time::Instant;

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::regression::{KernelParams, PushStrategy};
use super::sample::Sample;

/// What one knn benchmark run measured.
#[derive(Debug, Clone, serde::Serialize)]
pub struct KnnBench {
    /// Samples in the strategy.
    pub samples: usize,
    /// Queries timed (general and special case each).
    pub queries: usize,
    /// Time to build the k-d trees, ms.
    pub build_ms: f64,
    /// Mean time of a general-case query, µs.
    pub general_us: f64,
    /// Mean time of a special-case query, µs.
    pub special_us: f64,
    /// Mean time of a general-case query by linear scan over all samples, µs (for reference).
    pub linear_us: f64,
}

/// Random samples shaped like pushes of a 10 cm object by a 4 cm robot.
pub fn synthetic_samples(n: usize, seed: u64) -> Vec<Sample> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..n)
        .map(|_| {
            let a: f64 = rng.random_range(-std::f64::consts::PI..std::f64::consts::PI);
            let d: f64 = rng.random_range(0.09..0.12);
            let push: f64 = rng.random_range(0.005..0.05);
            let dev: f64 = rng.random_range(-0.6..0.6);
            Sample {
                p: [d * a.cos(), d * a.sin()],
                r: [-push * (a + dev).cos(), -push * (a + dev).sin()],
                s: [
                    -0.7 * push * (a + 0.5 * dev).cos(),
                    -0.7 * push * (a + 0.5 * dev).sin(),
                ],
                theta: rng.random_range(-0.3..0.3),
            }
        })
        .collect()
}

/// Time `queries` general and special queries against `n` synthetic samples.
pub fn run(n: usize, queries: usize, seed: u64) -> KnnBench {
    let samples = synthetic_samples(n, seed);
    let t = Instant::now();
    let strat = PushStrategy::new(samples.iter().copied(), KernelParams::default());
    let build_ms = t.elapsed().as_secs_f64() * 1e3;
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0xabcd);
    let qs: Vec<([f64; 2], [f64; 2])> = (0..queries.max(1))
        .map(|_| {
            let a: f64 = rng.random_range(-std::f64::consts::PI..std::f64::consts::PI);
            let b: f64 = rng.random_range(-std::f64::consts::PI..std::f64::consts::PI);
            ([0.1 * a.cos(), 0.1 * a.sin()], [b.cos(), b.sin()])
        })
        .collect();
    let mut sink = 0.0;
    let t = Instant::now();
    for (p, dir) in &qs {
        sink += strat.general(*p, *dir).map_or(0.0, |r| r[0]);
    }
    let general_us = t.elapsed().as_secs_f64() * 1e6 / qs.len() as f64;
    let t = Instant::now();
    for (_, dir) in &qs {
        sink += strat.special(*dir).map_or(0.0, |r| r.p[0]);
    }
    let special_us = t.elapsed().as_secs_f64() * 1e6 / qs.len() as f64;
    // Linear reference: the paper's "foreach sample" loop.
    let linear_n = qs.len().min(200);
    let off = strat.offset();
    let t = Instant::now();
    for (p, dir) in qs.iter().take(linear_n) {
        let q = [p[0], p[1], off * dir[0], off * dir[1]];
        let mut best = [(f64::INFINITY, 0usize); 5];
        for (i, s) in samples.iter().enumerate() {
            let d = (s.p[0] - q[0]).powi(2)
                + (s.p[1] - q[1]).powi(2)
                + (s.s[0] - q[2]).powi(2)
                + (s.s[1] - q[3]).powi(2);
            if d < best[4].0 {
                best[4] = (d, i);
                best.sort_by(|a, b| a.0.total_cmp(&b.0));
            }
        }
        sink += best[0].0;
    }
    let linear_us = t.elapsed().as_secs_f64() * 1e6 / linear_n as f64;
    std::hint::black_box(sink);
    KnnBench {
        samples: n,
        queries: qs.len(),
        build_ms,
        general_us,
        special_us,
        linear_us,
    }
}
