//! Signed distance to a many-vertex polygon, as the simulator asks it at every touch and
//! wall-following step: `ObstacleDistances::signed_distance` (the index) against the full
//! scan of `Obstacle::signed_distance`, on wavy rings of 200, 2 000 and 40 000 vertices
//! (radius 1 m ± 20 %, 40 waves), at 1 000 seeded points within 5 cm of the boundary,
//! outside it, where agents touch it. Report: time per 1 000 queries.
//!
//! Run: `cargo bench --bench obstacle_distance`.

use criterion::{Criterion, criterion_group, criterion_main};
use rand::{RngExt, SeedableRng};
use std::hint::black_box;
use std::time::Duration;
use swarmmap::world::{Obstacle, ObstacleDistances};

fn ring(n: usize) -> Vec<(f64, f64)> {
    (0..n)
        .map(|k| {
            let a = std::f64::consts::TAU * k as f64 / n as f64;
            let r = 1.0 + 0.2 * (40.0 * a).sin();
            (5.0 + r * a.cos(), 5.0 + r * a.sin())
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("polygon_distance");
    g.sample_size(10)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(3));
    for n in [200, 2_000, 40_000] {
        let obstacles = [Obstacle::Polygon { points: ring(n) }];
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
        // Outside the ring, 5 mm to 5 cm radially beyond it at each angle.
        let queries: Vec<(f64, f64)> = (0..1000)
            .map(|_| {
                let a = rng.random_range(0.0..std::f64::consts::TAU);
                let r = 1.0 + 0.2 * (40.0 * a).sin() + rng.random_range(0.005..0.05);
                (5.0 + r * a.cos(), 5.0 + r * a.sin())
            })
            .collect();
        let index = ObstacleDistances::new(&obstacles);
        g.bench_function(format!("index_{n}_vertices_1000_queries"), |b| {
            b.iter(|| {
                queries
                    .iter()
                    .map(|&q| index.signed_distance(0, q).unwrap_or(0.0))
                    .sum::<f64>()
            })
        });
        g.bench_function(format!("full_scan_{n}_vertices_1000_queries"), |b| {
            b.iter(|| {
                queries
                    .iter()
                    .map(|&q| black_box(&obstacles[0]).signed_distance(q))
                    .sum::<f64>()
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
