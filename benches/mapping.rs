//! Mapping one window of a synthetic log (issue #4 §6): targets 10⁴ encounters under 2 s and
//! 10⁵ under 20 s, cost linear in encounters for a fixed subsample size m.
//!
//! `cargo bench --bench mapping`

use criterion::{Criterion, criterion_group, criterion_main};
use swarmmap::mapping::local::{LocalParams, local_map};
use swarmmap::mapping::synthetic::{SyntheticParams, synthetic_log};
use swarmmap::mapping::windows::Window;

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("local_map");
    g.sample_size(10);
    for (n, agents) in [(10_000usize, 200usize), (100_000, 500)] {
        let p = SyntheticParams {
            agents,
            landmarks: agents / 10,
            ..Default::default()
        };
        let log = synthetic_log(&p, n);
        let (a, b) = log.span().expect("non-empty log");
        let w = Window {
            index: 1,
            start: a,
            end: b,
        };
        let params = LocalParams::default();
        g.bench_function(format!("{n}_encounters"), |bch| {
            bch.iter(|| local_map(&log, &w, &params))
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
