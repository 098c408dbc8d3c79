//! Wall following (`swarm.wall_following`, the cockroach model's WF mode), checked on
//! recorded trajectories against the exact geometry of the walls, not against the
//! simulator's own state.

use swarmmap::sim::{AgentState, SimOptions, SimOutput, simulate};
use swarmmap::world::{Obstacle, World};

/// A world without a sweep: the leader stays at the centre, D(t) is the whole arena, and
/// nobody stops or becomes a landmark.
fn still_world(width: f64, height: f64, agents: usize, duration: f64) -> World {
    let mut w = World::empty("wf", width, height);
    w.swarm.agents = agents;
    w.swarm.stop_rate = 0.0;
    w.swarm.landmark_fraction = 0.0;
    w.swarm.wall_following = 1.0;
    w.leader.window = width;
    w.leader.start_x = width / 2.0;
    w.leader.end_x = width / 2.0;
    w.simulation.dispersion_time = duration;
    w
}

fn run(world: &World, seed: u64) -> SimOutput {
    let opts = SimOptions::new(seed).with_trajectories(world.simulation.dt);
    simulate(world, &opts).expect("simulation runs")
}

/// Per agent, in time order: (time, x, y, state).
fn tracks(out: &SimOutput, agents: usize) -> Vec<Vec<(f64, f64, f64, AgentState)>> {
    let mut t = vec![Vec::new(); agents];
    for s in &out.trajectories.as_ref().expect("trajectories").samples {
        t[s.agent as usize].push((s.time, s.x, s.y, s.state));
    }
    t
}

/// Gap between the body and the nearest wall, metres.
fn gap(w: &World, x: f64, y: f64) -> f64 {
    w.clearance((x, y)) - w.swarm.body_radius
}

/// At the wall: within this gap, metres (a follower is steered back within one step).
const AT_WALL: f64 = 1e-3;

#[test]
fn a_follower_hugs_the_arena_and_turns_its_corners() {
    let mut w = still_world(2.0, 2.0, 1, 400.0);
    w.swarm.wall_following_length = 1e6;
    let out = run(&w, 7);
    assert!(out.stats.wall_follows >= 1);
    let track = &tracks(&out, 1)[0];
    let first = track
        .iter()
        .position(|&(_, x, y, _)| gap(&w, x, y) < AT_WALL)
        .expect("the agent reaches a wall");
    let step = w.swarm.speed * w.simulation.dt;
    let along = &track[first..];
    let worst = along
        .iter()
        .map(|&(_, x, y, _)| gap(&w, x, y))
        .fold(0.0, f64::max);
    assert!(
        worst < step,
        "a follower left its wall by {worst} m (one step is {step} m)"
    );
    // It keeps walking at v (it does not press into a corner) ...
    let path: f64 = along
        .windows(2)
        .map(|p| (p[1].1 - p[0].1).hypot(p[1].2 - p[0].2))
        .sum();
    let time = along.last().unwrap().0 - along[0].0;
    assert!(
        path > 0.95 * w.swarm.speed * time,
        "walked {path} m in {time} s"
    );
    // ... and goes round all four corners.
    for corner in [(0.0, 0.0), (2.0, 0.0), (2.0, 2.0), (0.0, 2.0)] {
        let near = along
            .iter()
            .any(|&(_, x, y, _)| (x - corner.0).abs() < 0.02 && (y - corner.1).abs() < 0.02);
        assert!(near, "never turned the corner at {corner:?}");
    }
}

#[test]
fn a_follower_goes_round_an_obstacle_without_entering_it() {
    let (c, radius) = ((2.0, 2.0), 0.5);
    follows_round(Obstacle::Circle { center: c, radius }, c, radius);
}

#[test]
fn a_follower_goes_round_a_polygon_of_many_vertices_without_entering_it() {
    // The same disc as a 720-gon (within 5 µm of the circle), wound either way: the
    // simulator measures it through its distance index (`world::ObstacleDistances`) and
    // makes it a one-sided polyline (64 vertices or more). Double-sided, the follower
    // turned 30.1 rad where 32.4 were due (seed 1): the corners dragged it.
    let (c, radius) = ((2.0, 2.0), 0.5);
    let mut points: Vec<(f64, f64)> = (0..720)
        .map(|k| {
            let a = std::f64::consts::TAU * f64::from(k) / 720.0;
            (c.0 + radius * a.cos(), c.1 + radius * a.sin())
        })
        .collect();
    follows_round(
        Obstacle::Polygon {
            points: points.clone(),
        },
        c,
        radius,
    );
    points.reverse();
    follows_round(Obstacle::Polygon { points }, c, radius);
}

/// Agents start in the free ring round a disc-like obstacle centred at `c`; every one that
/// reaches it before the arena's sides must circle it, always the same way, hugging it.
fn follows_round(obstacle: Obstacle, c: (f64, f64), radius: f64) {
    let mut w = still_world(4.0, 4.0, 1, 200.0);
    w.swarm.wall_following_length = 1e6;
    w.swarm.placement = swarmmap::world::Placement::Disk { radius: 0.8 };
    w.obstacles = vec![obstacle];
    let step = w.swarm.speed * w.simulation.dt;
    let mut circlers = 0;
    for seed in 1..=8 {
        let out = run(&w, seed);
        let track = &tracks(&out, 1)[0];
        let Some(first) = track
            .iter()
            .position(|&(_, x, y, _)| gap(&w, x, y) < AT_WALL)
        else {
            continue;
        };
        let along = &track[first..];
        for &(t, x, y, _) in along {
            let g = gap(&w, x, y);
            assert!(g > -2e-4, "seed {seed}: the body sinks {} m at t = {t}", -g);
            assert!(g < step, "seed {seed}: left its wall by {g} m at t = {t}");
        }
        let (_, x0, y0, _) = along[0];
        if ((x0 - c.0).hypot(y0 - c.1) - radius) > 0.1 {
            continue; // it follows the arena's sides
        }
        circlers += 1;
        // Unwrapped angle about the centre: monotone, about v t / r radians.
        let mut turned = 0.0;
        let mut sign = 0.0;
        for p in along.windows(2) {
            let a0 = (p[0].2 - c.1).atan2(p[0].1 - c.0);
            let a1 = (p[1].2 - c.1).atan2(p[1].1 - c.0);
            let mut d = a1 - a0;
            if d > std::f64::consts::PI {
                d -= 2.0 * std::f64::consts::PI;
            } else if d < -std::f64::consts::PI {
                d += 2.0 * std::f64::consts::PI;
            }
            if sign == 0.0 && d != 0.0 {
                sign = d.signum();
            }
            assert!(d * sign >= 0.0, "seed {seed}: the follower turned back");
            turned += d.abs();
        }
        let time = along.last().unwrap().0 - along[0].0;
        let expected = w.swarm.speed * time / (radius + w.swarm.body_radius);
        assert!(
            (turned - expected).abs() < 0.05 * expected,
            "seed {seed}: turned {turned} rad round the disc, expected {expected}"
        );
    }
    assert!(
        circlers >= 2,
        "only {circlers} of 8 seeds reached the disc first"
    );
}

#[test]
fn followed_lengths_are_exponential_with_the_mean_set() {
    // Runs never end on their own (λ huge), so an agent leaves a wall only when its
    // followed length is spent (or, rarely, when it meets another agent).
    let mut w = still_world(6.0, 6.0, 10, 6000.0);
    w.swarm.mean_run_length = 1e6;
    w.swarm.wall_following_length = 0.5;
    let out = run(&w, 3);
    let mut lengths = Vec::new();
    for track in tracks(&out, 10) {
        let mut current: Option<f64> = None;
        for p in track.windows(2) {
            // Following: at the wall and moving along it. An agent that has turned away
            // moves off it (by v dt sin θ per step), which a grazing departure does too
            // slowly to leave the 1 mm band soon: its runs never end here.
            let (g0, g1) = (gap(&w, p[0].1, p[0].2), gap(&w, p[1].1, p[1].2));
            let at = g0 < AT_WALL && g1 < AT_WALL && (g1 - g0).abs() < 1e-5;
            match (at, current) {
                (true, _) => {
                    *current.get_or_insert(0.0) += (p[1].1 - p[0].1).hypot(p[1].2 - p[0].2);
                }
                (false, Some(l)) => {
                    lengths.push(l);
                    current = None;
                }
                (false, None) => {}
            }
        }
    }
    let n = lengths.len() as f64;
    assert!(n > 400.0, "only {n} wall segments");
    let mean = lengths.iter().sum::<f64>() / n;
    let sd = (lengths.iter().map(|l| (l - mean).powi(2)).sum::<f64>() / n).sqrt();
    // Four standard errors: the mean's is mean/√n, the coefficient of variation's
    // √(2/n) for an exponential (its fourth central moment is 9 σ⁴).
    assert!(
        (mean - 0.5).abs() < 4.0 * 0.5 / n.sqrt(),
        "mean followed length {mean} m over {n} segments, set 0.5 m"
    );
    assert!(
        (sd / mean - 1.0).abs() < 4.0 * (2.0 / n).sqrt(),
        "coefficient of variation {} over {n} segments (an exponential has 1)",
        sd / mean
    );
}

#[test]
fn no_wall_following_leaves_the_random_walk_unchanged() {
    // Probability 0 draws no random number: the run is the paper's random walk exactly,
    // whatever the followed length.
    let mut a = still_world(3.0, 3.0, 20, 120.0);
    a.swarm.wall_following = 0.0;
    let mut b = a.clone();
    b.swarm.wall_following_length = 7.0;
    let (oa, ob) = (run(&a, 5), run(&b, 5));
    assert_eq!(oa.log, ob.log);
    assert_eq!(oa.stats.wall_follows, 0);
}

#[test]
fn a_follower_turns_out_of_a_nook_of_one_polygon() {
    // An L-shaped obstacle: at its inner corner the body touches two edges of the same
    // polygon. A follower must slide out along the second edge (or give up and turn),
    // never press into it for the rest of its follow.
    let mut w = still_world(4.0, 4.0, 1, 300.0);
    w.swarm.wall_following_length = 1e6;
    w.swarm.mean_run_length = 1e6;
    w.swarm.placement = swarmmap::world::Placement::Disk { radius: 0.4 };
    w.obstacles = vec![Obstacle::Polygon {
        points: vec![
            (1.5, 1.5),
            (2.5, 1.5),
            (2.5, 1.8),
            (1.8, 1.8),
            (1.8, 2.5),
            (1.5, 2.5),
        ],
    }];
    let step = w.swarm.speed * w.simulation.dt;
    let r = w.swarm.body_radius;
    let nook = (1.8 + r, 1.8 + r);
    let mut visits = 0;
    for seed in 1..=6 {
        let out = run(&w, seed);
        let track = &tracks(&out, 1)[0];
        let stalled = track
            .windows(2)
            .filter(|p| (p[1].1 - p[0].1).hypot(p[1].2 - p[0].2) < 0.25 * step)
            .count();
        assert!(stalled <= 5, "seed {seed}: stalled for {stalled} steps");
        if track
            .iter()
            .any(|&(_, x, y, _)| (x - nook.0).hypot(y - nook.1) < 0.01)
        {
            visits += 1;
        }
    }
    assert!(visits >= 2, "only {visits} of 6 followers reached the nook");
}
