//! Criterion benches of the Vietoris–Rips engine (H0 + H1): seeded uniform points in the
//! unit square at several sizes, and a real window's planar cloud whose obstacle makes one
//! long bar (`benches/data/t_lshape_w4_9600.csv`, every 8th point; the cohomology column of
//! that bar dominates). `cargo bench --bench rips`.

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

/// Every `step`-th point of `benches/data/t_lshape_w4_9600.csv` (`x,y` rows, no header).
fn lshape(step: usize) -> PointCloud {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/benches/data/t_lshape_w4_9600.csv"
    );
    let text = std::fs::read_to_string(path).expect("benches/data/t_lshape_w4_9600.csv");
    let coords: Vec<f64> = text
        .lines()
        .step_by(step)
        .flat_map(|l| l.split(','))
        .map(|x| x.trim().parse::<f64>().expect("a number"))
        .collect();
    PointCloud::new(2, coords).expect("finite coordinates")
}

fn long_bar(c: &mut Criterion) {
    let mut g = c.benchmark_group("rips_lshape_window_h1");
    g.sample_size(10);
    let p = lshape(8);
    let opts = RipsOptions {
        threads: 1,
        ..RipsOptions::default()
    };
    g.bench_function(BenchmarkId::from_parameter(p.len()), |b| {
        b.iter(|| rips_points(&p, &opts))
    });
    g.finish();
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

criterion_group!(benches, bench, long_bar);
criterion_main!(benches);
