//! Classical MDS of uniform points in the unit cube into k = 3 (issue #3 target: n = 5 000
//! under 2 s), and landmark MDS with 200 landmarks. Run with `cargo bench --bench mds`.

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::hint::black_box;
use std::time::Duration;
use swarmmap::topology::mds::{classical_mds, landmark_mds};
use swarmmap::topology::{DistanceMatrix, PointCloud};

fn cube(n: usize, seed: u64) -> PointCloud {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    PointCloud::new(3, (0..3 * n).map(|_| rng.random::<f64>()).collect()).expect("finite")
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("classical_mds_k3");
    g.sample_size(10).warm_up_time(Duration::from_secs(1));
    for n in [1000usize, 2000, 5000] {
        let d = DistanceMatrix::from_points(&cube(n, 1));
        g.bench_with_input(BenchmarkId::from_parameter(n), &d, |b, d| {
            b.iter(|| classical_mds(black_box(d), 3).expect("mds"))
        });
    }
    g.finish();

    let mut g = c.benchmark_group("landmark_mds_k3_200_landmarks");
    g.sample_size(10).warm_up_time(Duration::from_secs(1));
    let n = 20_000;
    let pts = cube(n, 2);
    let landmarks: Vec<usize> = (0..200).map(|i| i * (n / 200)).collect();
    let rows: Vec<Vec<f64>> = landmarks
        .iter()
        .map(|&l| (0..n).map(|j| pts.dist(l, j)).collect())
        .collect();
    g.bench_function(BenchmarkId::from_parameter(n), |b| {
        b.iter(|| landmark_mds(black_box(&landmarks), black_box(&rows), 3).expect("lmds"))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
