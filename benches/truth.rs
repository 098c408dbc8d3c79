//! The ground truth's raster of a paper-sized arena (30 m × 10 m at 1 cm, 3 M cells, four
//! obstacles like scenario 2's): building it, and the Betti numbers of a 3 m band of it,
//! as each window's truth asks (`eval/truth.rs`). Run with `cargo bench --bench truth`.

use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use std::time::Duration;
use swarmmap::eval::truth::FreeSpace;
use swarmmap::world::{Obstacle, World};

fn arena() -> World {
    let rect = |x0, y0, x1, y1| Obstacle::Rect {
        min: (x0, y0),
        max: (x1, y1),
    };
    let mut w = World::empty("scenario-like", 30.0, 10.0);
    w.obstacles = vec![
        rect(6.0, 2.0, 8.0, 4.0),
        rect(6.0, 6.0, 8.0, 8.0),
        rect(11.0, 4.0, 22.0, 6.0),
        Obstacle::Circle {
            center: (25.0, 5.0),
            radius: 1.0,
        },
    ];
    w
}

fn bench(c: &mut Criterion) {
    let w = arena();
    let mut g = c.benchmark_group("truth");
    g.sample_size(10).warm_up_time(Duration::from_secs(1));
    g.bench_function("build_30x10_at_1cm", |b| {
        b.iter(|| FreeSpace::new(black_box(&w), 0.01).map(|f| f.global_betti()))
    });
    let fs = FreeSpace::new(&w, 0.01).expect("the arena rasterises");
    g.bench_function("band_3m", |b| {
        b.iter(|| fs.betti_in_band(black_box(10.0), black_box(13.0)))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
