//! Timing of the simple-polygon check on big circles (`cargo bench -p pushbot-world --bench
//! polygon`): the 100 000-vertex circle of radius 0.4 m, whose neighbouring edges are 25 µm
//! apart, takes a few tens of milliseconds in a release build.

use criterion::{Criterion, criterion_group, criterion_main};
use pushbot_world::polygon::check_simple;

fn circle(n: usize, r: f64) -> Vec<[f64; 2]> {
    (0..n)
        .map(|i| {
            let a = std::f64::consts::TAU * i as f64 / n as f64;
            [0.6 + r * a.cos(), 0.45 + r * a.sin()]
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    for n in [20_000, 100_000] {
        let poly = circle(n, 0.4);
        c.bench_function(&format!("check_simple circle {n}"), |b| {
            b.iter(|| check_simple(std::hint::black_box(&poly)))
        });
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
