//! Mapping one window of a synthetic log (issue #4 §6): targets 10⁴ encounters under 2 s and
//! 10⁵ under 20 s, cost linear in encounters for a fixed subsample size m.
//!
//! The `local_map_scaling` group holds the swarm fixed (300 agents, 30 landmarks) and grows
//! the window's encounters from 12 500 to 100 000, reporting throughput (encounters/s):
//! a flat throughput is linear cost. `cargo bench --bench mapping -- scaling` runs it alone.
//!
//! The `shortest_paths` group times the single-source runs that dominate the mapping on
//! the graph the bundled worlds build (`cargo bench --bench mapping -- shortest_paths`).
//!
//! The `maxmin_lookahead` group times 400 farthest-point picks on that graph with and
//! without rows guessed ahead on the spare cores (`cargo bench --bench mapping --
//! maxmin_lookahead`; the same picks either way, `subsample::maxmin_with`).
//!
//! `cargo bench --bench mapping`

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use swarmmap::log::EncounterLog;
use swarmmap::mapping::encounter_graph::{Bridging, EncounterGraph};
use swarmmap::mapping::local::{LocalParams, local_map};
use swarmmap::mapping::subsample::maxmin_with;
use swarmmap::mapping::synthetic::{SyntheticParams, synthetic_log};
use swarmmap::mapping::windows::Window;

/// One window over the whole log.
fn whole(log: &EncounterLog) -> Window {
    let (start, end) = log.span().expect("non-empty log");
    Window {
        index: 1,
        start,
        end,
    }
}

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
        let w = whole(&log);
        let params = LocalParams::default();
        g.bench_function(format!("{n}_encounters"), |bch| {
            bch.iter(|| local_map(&log, &w, &params))
        });
    }
    g.finish();
}

fn scaling(c: &mut Criterion) {
    let mut g = c.benchmark_group("local_map_scaling");
    g.sample_size(10);
    let p = SyntheticParams {
        agents: 300,
        landmarks: 30,
        ..Default::default()
    };
    let params = LocalParams::default();
    for n in [12_500usize, 25_000, 50_000, 100_000] {
        let log = synthetic_log(&p, n);
        let w = whole(&log);
        g.throughput(Throughput::Elements(n as u64));
        g.bench_function(format!("{n}_encounters_300_agents"), |bch| {
            bch.iter(|| local_map(&log, &w, &params))
        });
    }
    g.finish();
}

/// The encounter graph the bundled worlds map with (a switch cost of 1 s, encounter
/// middles, the paper's static stars) on 25 000 synthetic encounters of 300 agents, 90 of
/// them landmarks (30 %, as in the bundled worlds).
fn bundled_graph() -> EncounterGraph {
    let p = SyntheticParams {
        agents: 300,
        landmarks: 90,
        ..Default::default()
    };
    let log = synthetic_log(&p, 25_000);
    EncounterGraph::build_timed(
        &log.encounters,
        &log.static_intervals,
        Bridging::Paper,
        1.0,
        true,
    )
}

/// Twenty single-source shortest-path runs on [`bundled_graph`].
fn shortest_paths(c: &mut Criterion) {
    let mut g = c.benchmark_group("shortest_paths");
    g.sample_size(10);
    let graph = bundled_graph();
    let n = graph.encounters();
    g.bench_function("25000_encounters_20_sources", |bch| {
        bch.iter(|| {
            (0..20)
                .map(|k| graph.distances_from(k * n / 20)[0])
                .sum::<f64>()
        })
    });
    g.finish();
}

/// Four hundred farthest-point picks (m's default) over every encounter of
/// [`bundled_graph`], each needing its own single-source run, computed one after
/// another (`lookahead_0`) or with one guessed row beside each needed one (`lookahead_1`),
/// on criterion's rayon pool (one thread per core).
fn maxmin_lookahead(c: &mut Criterion) {
    let mut g = c.benchmark_group("maxmin_lookahead");
    g.sample_size(10);
    let graph = bundled_graph();
    let members: Vec<usize> = (0..graph.encounters()).collect();
    for lookahead in [0, 1] {
        g.bench_function(format!("400_picks_lookahead_{lookahead}"), |bch| {
            bch.iter(|| {
                maxmin_with(&graph, &members, 400, &|| lookahead)
                    .picks
                    .len()
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench, scaling, shortest_paths, maxmin_lookahead);
criterion_main!(benches);
