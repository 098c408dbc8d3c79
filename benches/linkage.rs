//! Single linkage (Prim on the condensed matrix) of uniform points in the unit square.
//! Run with `cargo bench --bench linkage`.

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::hint::black_box;
use std::time::Duration;
use swarmmap::topology::linkage::single_linkage;
use swarmmap::topology::{DistanceMatrix, PointCloud};

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("single_linkage");
    g.sample_size(10).warm_up_time(Duration::from_secs(1));
    for n in [1000usize, 5000] {
        let mut rng = ChaCha8Rng::seed_from_u64(n as u64);
        let pts =
            PointCloud::new(2, (0..2 * n).map(|_| rng.random::<f64>()).collect()).expect("finite");
        let d = DistanceMatrix::from_points(&pts);
        g.bench_with_input(BenchmarkId::from_parameter(n), &d, |b, d| {
            b.iter(|| single_linkage(black_box(d)))
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
