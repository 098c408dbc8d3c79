//! Criterion benches of the Vietoris–Rips engine on seeded uniform points in the unit
//! square (H0 + H1, one thread), at several sizes. `cargo bench --bench rips`.

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use swarmmap::topology::PointCloud;
use swarmmap::topology::rips::{RipsOptions, rips_points};

fn uniform(n: usize, seed: u64) -> PointCloud {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let coords: Vec<f64> = (0..2 * n).map(|_| rng.random::<f64>()).collect();
    PointCloud::new(2, coords).expect("finite coordinates")
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("rips_uniform2d_h1");
    g.sample_size(10);
    for n in [250, 500, 1000, 2000] {
        let p = uniform(n, 42);
        for threads in [1, 2] {
            let opts = RipsOptions {
                threads,
                ..RipsOptions::default()
            };
            g.bench_with_input(
                BenchmarkId::new(format!("threads{threads}"), n),
                &p,
                |b, p| b.iter(|| rips_points(p, &opts)),
            );
        }
    }
    let p = uniform(1000, 7);
    let opts = RipsOptions {
        cycles: true,
        threads: 1,
        ..RipsOptions::default()
    };
    g.bench_function("cycles/1000", |b| b.iter(|| rips_points(&p, &opts)));
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
