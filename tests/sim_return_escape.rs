//! Returning agents leave a nook that the leader's gradient keeps them in
//! (`swarm.return_patience`, README "Model"), checked on recorded trajectories against the
//! world's geometry; and a run in which nobody escapes is the paper's walk, draw for draw.

use swarmmap::sim::{AgentState, SimOptions, SimOutput, simulate};
use swarmmap::world::{Obstacle, Placement, World};

/// A disc touching the top side: the nook between them opens to the left, away from the
/// sweep, so an agent left behind there is driven into it by every return run.
fn nook_world() -> World {
    let mut w = World::empty("nook", 20.0, 4.0);
    w.obstacles.push(Obstacle::Circle {
        center: (4.0, 3.0),
        radius: 1.0,
    });
    w.swarm.agents = 60;
    w.swarm.detection_radius = 0.1;
    w.swarm.landmark_fraction = 0.3;
    w.swarm.placement = Placement::Window;
    w
}

/// In the nook: left of the disc, above its centre, within 1 m of the disc's left edge.
fn in_nook(x: f64, y: f64) -> bool {
    x > 2.9 && x < 4.0 && y > 3.3 && (x - 4.0).hypot(y - 3.0) > 0.99
}

fn run(world: &World, seed: u64) -> SimOutput {
    simulate(world, &SimOptions::new(seed).with_trajectories(10.0)).expect("simulation runs")
}

/// (returning agents in the nook at the last sample, agent-samples returning in the nook
/// over the whole run).
fn nook_use(out: &SimOutput) -> (usize, usize) {
    let samples = &out.trajectories.as_ref().expect("trajectories").samples;
    let last = samples.iter().map(|s| s.time).fold(f64::MIN, f64::max);
    let trapped =
        |s: &&swarmmap::sim::TrajectorySample| s.state == AgentState::Return && in_nook(s.x, s.y);
    let at_end = samples
        .iter()
        .filter(|s| s.time == last)
        .filter(trapped)
        .count();
    (at_end, samples.iter().filter(trapped).count())
}

#[test]
fn returning_agents_leave_a_nook_that_traps_them_without_the_escape() {
    for seed in [1, 2] {
        let mut never = nook_world();
        never.swarm.return_patience = 1e12;
        let trapped = run(&never, seed);
        let (end_never, total_never) = nook_use(&trapped);
        assert_eq!(trapped.stats.return_escapes, 0);
        // The trap is real: agents are still stuck in the nook when the sweep ends,
        // 3 000 s after the domain left it.
        assert!(
            end_never >= 5,
            "seed {seed}: only {end_never} agents trapped without the escape"
        );

        let escaped = run(&nook_world(), seed);
        let (end, total) = nook_use(&escaped);
        assert!(escaped.stats.return_escapes > 0, "seed {seed}");
        assert_eq!(end, 0, "seed {seed}: agents still in the nook at the end");
        assert!(
            total * 3 < total_never,
            "seed {seed}: {total} samples in the nook against {total_never} without the escape"
        );
    }
}

#[test]
fn a_run_without_escapes_is_unchanged_by_the_patience() {
    // The domain sweeps an open arena: returns take seconds, nobody runs out of patience.
    let mut w = World::empty("open", 8.0, 3.0);
    w.swarm.agents = 40;
    w.swarm.detection_radius = 0.1;
    w.swarm.landmark_fraction = 0.3;
    let a = run(&w, 3);
    assert!(a.stats.return_escapes == 0);
    w.swarm.return_patience = 1e12;
    let b = run(&w, 3);
    assert_eq!(a.log, b.log);
    assert_eq!(a.trajectories, b.trajectories);
}
