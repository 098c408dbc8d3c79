//! The whole run of `worlds/scenario2.ron` (seed 1, bundled defaults): simulation, local
//! maps, stitching and evaluation against the truth, in memory (no files, no report), the
//! way `swarmmap run` does it, mapping alongside the simulation, and after it for
//! comparison (issue #5's target: under 15 s on the project's 2-core machine).
//!
//! Run: `cargo bench --bench run` (about six minutes: ten samples of each).

use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use std::path::Path;
use std::time::Duration;
use swarmmap::pipeline::{Alongside, RunOptions, run_world};
use swarmmap::world::WorldSpec;

fn bench(c: &mut Criterion) {
    let world = WorldSpec::load(Path::new("worlds/scenario2.ron"))
        .and_then(|s| s.check())
        .expect("the bundled world loads");
    let mut g = c.benchmark_group("run");
    g.sample_size(10)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(180));
    for (name, alongside) in [
        ("scenario2_seed1_alongside", Alongside::Free),
        ("scenario2_seed1_after", Alongside::Off),
    ] {
        g.bench_function(name, |b| {
            b.iter(|| {
                let opts = RunOptions {
                    seed: 1,
                    out: None,
                    trajectories: None,
                    progress: None,
                    alongside,
                };
                black_box(run_world(&world, &opts).map(|(_, m)| m.global.betti))
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
