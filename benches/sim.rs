//! Simulation speed at 100, 1 000 and 10 000 agents over short simulated spans, in the
//! paper's 30 m × 10 m arena with scenario 2's long obstacle, agents dispersed in the
//! leader's window (the densest part of a real run). Report: time per simulated second;
//! real-time factor = span / time. Spans are whole numbers of default steps (dt = 0.03 s):
//! 1 000, 200 and 20 steps; each sample includes placement and scene construction.
//!
//! Run: `cargo bench --bench sim`.

use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use std::time::Duration;
use swarmmap::sim::{SimOptions, simulate};
use swarmmap::world::{Obstacle, Placement, World};

fn world(agents: usize, span: f64) -> World {
    let mut w = World::empty("bench", 30.0, 10.0);
    w.obstacles.push(Obstacle::Rect {
        min: (9.0, 4.5),
        max: (21.0, 5.5),
    });
    w.swarm.agents = agents;
    w.swarm.placement = Placement::Window;
    // No sweep: the span is all dispersion, with landmarks selected at its end.
    w.leader.end_x = w.leader.start_x;
    w.simulation.dispersion_time = span;
    w
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("simulate");
    g.sample_size(10).warm_up_time(Duration::from_secs(1));
    for (agents, span) in [(100, 30.0), (1_000, 6.0), (10_000, 0.6)] {
        let w = world(agents, span);
        g.measurement_time(Duration::from_secs(if agents >= 10_000 { 20 } else { 8 }));
        g.bench_function(format!("{agents}_agents_{span}s"), |b| {
            b.iter(|| black_box(simulate(&w, &SimOptions::new(1)).map(|o| o.stats.steps)))
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
