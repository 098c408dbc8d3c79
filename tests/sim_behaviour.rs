//! The motion model and the exploration rules, checked on recorded trajectories against
//! the parameters and the exact geometry (not against the simulator's own counters).

use swarmmap::log::StaticReason;
use swarmmap::sim::{AgentState, SimOptions, SimOutput, simulate};
use swarmmap::world::{Obstacle, Placement, World};

/// A world without a sweep: the leader stays at `start_x` and the run lasts `duration` s.
fn still_world(width: f64, height: f64, agents: usize, duration: f64) -> World {
    let mut w = World::empty("still", width, height);
    w.swarm.agents = agents;
    w.leader.window = width;
    w.leader.start_x = width / 2.0;
    w.leader.end_x = width / 2.0;
    w.simulation.dispersion_time = duration;
    w
}

fn run(world: &World, seed: u64, every: f64) -> SimOutput {
    simulate(world, &SimOptions::new(seed).with_trajectories(every)).expect("simulation runs")
}

/// Positions per agent, in time order, with states.
fn tracks(out: &SimOutput, agents: usize) -> Vec<Vec<(f64, f64, f64, AgentState)>> {
    let mut t = vec![Vec::new(); agents];
    for s in &out.trajectories.as_ref().expect("trajectories").samples {
        t[s.agent as usize].push((s.time, s.x, s.y, s.state));
    }
    t
}

#[test]
fn runs_are_exponential_with_mean_lambda_at_speed_v() {
    // Large empty arena, the whole of it inside D(t): no leader pull, few wall hits.
    let lambda = 0.3;
    let mut w = still_world(60.0, 60.0, 100, 300.0);
    w.swarm.mean_run_length = lambda;
    w.swarm.landmark_fraction = 0.0;
    w.swarm.stop_rate = 0.2;
    w.swarm.mean_stop_duration = 1.0;
    w.swarm.placement = Placement::Window;
    let dt = w.simulation.dt;
    let out = run(&w, 7, dt);
    let v = w.swarm.speed;

    let mut runs = Vec::new();
    let (mut dist, mut steps) = (0.0, 0usize);
    for track in tracks(&out, 100) {
        // Split each track into straight runs: a turn is a change of direction between two
        // consecutive moving steps (zero-length steps are pauses, which keep the heading).
        let mut current = 0.0;
        let mut last_dir: Option<(f64, f64)> = None;
        for win in track.windows(2) {
            let (a, b) = (win[0], win[1]);
            let d = (b.1 - a.1, b.2 - a.2);
            let len = d.0.hypot(d.1);
            if len < 1e-9 {
                continue;
            }
            dist += len;
            steps += 1;
            let dir = (d.0 / len, d.1 / len);
            if let Some(p) = last_dir {
                let cross = p.0 * dir.1 - p.1 * dir.0;
                let dot = p.0 * dir.0 + p.1 * dir.1;
                if cross.atan2(dot).abs() > 0.01 {
                    // Runs cut short by an arena side are not samples of the run length.
                    let near_side = a.1.min(60.0 - a.1).min(a.2).min(60.0 - a.2) < 0.02;
                    if !near_side {
                        runs.push(current);
                    }
                    current = 0.0;
                }
            }
            current += len;
            last_dir = Some(dir);
        }
        // The last run of a track is truncated by the end of the simulation: dropped.
    }
    let mean_run = runs.iter().sum::<f64>() / runs.len() as f64;
    let mean_speed = dist / (steps as f64 * dt);
    assert!(runs.len() > 5000, "only {} runs", runs.len());
    assert!(
        (mean_run / lambda - 1.0).abs() < 0.05,
        "mean run {mean_run} m vs λ = {lambda} m over {} runs",
        runs.len()
    );
    assert!(
        (mean_speed / v - 1.0).abs() < 0.05,
        "mean speed {mean_speed} m/s vs {v}"
    );
    // Exponential: the standard deviation equals the mean (within 10 %).
    let var = runs.iter().map(|r| (r - mean_run).powi(2)).sum::<f64>() / runs.len() as f64;
    assert!(
        (var.sqrt() / mean_run - 1.0).abs() < 0.1,
        "sd {}",
        var.sqrt()
    );

    // Pauses: exponential durations of mean 1 s, at rate 0.2 per walking second.
    let end = out.stats.simulated_time;
    let pauses: Vec<_> = out
        .log
        .static_intervals
        .iter()
        .filter(|s| s.reason == StaticReason::Pause)
        .collect();
    let complete: Vec<f64> = pauses
        .iter()
        .filter(|s| s.end < end)
        .map(|s| s.end - s.start)
        .collect();
    let mean_pause = complete.iter().sum::<f64>() / complete.len() as f64;
    assert!(
        (mean_pause / 1.0 - 1.0).abs() < 0.05,
        "mean pause {mean_pause} s over {} pauses",
        complete.len()
    );
    let paused: f64 = pauses.iter().map(|s| s.end - s.start).sum();
    let walking = 100.0 * end - paused;
    let rate = pauses.len() as f64 / walking;
    assert!((rate / 0.2 - 1.0).abs() < 0.05, "stop rate {rate} /s");
    // Paused agents do not move.
    let t = tracks(&out, 100);
    for s in &pauses {
        let tr = &t[s.agent as usize];
        let inside: Vec<_> = tr
            .iter()
            .filter(|p| p.0 >= s.start && p.0 < s.end)
            .collect();
        assert!(inside.iter().all(|p| p.3 == AgentState::Pause));
        assert!(
            inside
                .windows(2)
                .all(|w| w[0].1 == w[1].1 && w[0].2 == w[1].2)
        );
    }
}

/// A small world with every kind of obstacle, one touching a side, and a real sweep.
fn obstacle_world() -> World {
    let mut w = World::empty("obstacles", 12.0, 4.0);
    w.obstacles = vec![
        Obstacle::Rect {
            min: (4.0, 1.5),
            max: (8.0, 2.5),
        },
        Obstacle::Circle {
            center: (2.5, 3.0),
            radius: 0.4,
        },
        // Non-convex (an arrow head).
        Obstacle::Polygon {
            points: vec![(9.0, 0.5), (10.5, 1.0), (9.0, 1.5), (9.5, 1.0)],
        },
        Obstacle::Wall {
            from: (10.0, 4.0),
            to: (10.0, 2.5),
            thickness: 0.1,
        },
    ];
    w.swarm.agents = 100;
    w.leader.speed = 0.05;
    w.simulation.dispersion_time = 60.0;
    w
}

#[test]
fn agents_never_enter_obstacles_nor_leave_the_arena() {
    let w = obstacle_world();
    let out = run(&w, 3, w.simulation.dt);
    let r = w.swarm.body_radius;
    let mut worst = f64::INFINITY;
    for s in &out.trajectories.as_ref().expect("trajectories").samples {
        worst = worst.min(w.clearance((s.x, s.y)) - r);
    }
    // The body may sink into an obstacle by at most 0.2 mm (solver tolerance); it never
    // gets its centre inside.
    assert!(worst > -2e-4, "a body overlaps an obstacle by {} m", -worst);
    assert!(out.stats.collisions > 0);
}

/// The paper's speeds (leader 0.005 m/s, agents 0.1 m/s) on a 6 m arena: a 600 s sweep.
fn sweep_world() -> World {
    let mut w = obstacle_world();
    w.arena.width = 6.0;
    w.obstacles.truncate(2);
    w.leader.speed = 0.005;
    w.leader.end_x = 4.5;
    w
}

#[test]
fn landmark_fraction_holds_inside_the_leaders_domain() {
    let w = sweep_world();
    // Return episodes last a few seconds at most (the domain's edge moves 5 mm/s), so the
    // closing speed below is measured over 0.1 s samples: at 0.5 s a run had only 1 to 10
    // sample pairs in `return`, too few to measure anything.
    let every = 0.1;
    let out = run(&w, 11, every);
    let traj = out.trajectories.as_ref().expect("trajectories");
    let disp = w.simulation.dispersion_time;
    let mut checked = 0;
    let (mut towards, mut return_time) = (0.0, 0.0);
    let mut prev: Option<&[swarmmap::sim::TrajectorySample]> = None;
    for chunk in traj.samples.chunks(w.swarm.agents) {
        // Returning agents close in on the leader's x faster than the leader moves.
        if let Some(p) = prev {
            for (a, b) in p.iter().zip(chunk) {
                if a.state == AgentState::Return && b.state == AgentState::Return {
                    let dir = (w.leader_x(a.time) - a.x).signum();
                    towards += (b.x - a.x) * dir;
                    return_time += b.time - a.time;
                }
            }
        }
        prev = Some(chunk);
        let t = chunk[0].time;
        if t < disp - 1e-9 || t >= out.stats.simulated_time - 1e-9 {
            continue;
        }
        let (x0, x1) = w.domain(t);
        let inside: Vec<_> = chunk.iter().filter(|s| s.x >= x0 && s.x <= x1).collect();
        let landmarks = chunk
            .iter()
            .filter(|s| s.state == AgentState::Landmark)
            .count();
        let landmarks_inside = inside
            .iter()
            .filter(|s| s.state == AgentState::Landmark)
            .count();
        let target = (w.swarm.landmark_fraction * inside.len() as f64).round() as usize;
        assert_eq!(landmarks, landmarks_inside, "landmark outside D({t})");
        assert_eq!(landmarks, target, "at t = {t}: {} inside", inside.len());
        // Agents outside D(t) are returning (or paused).
        for s in chunk.iter().filter(|s| s.x < x0 || s.x > x1) {
            assert!(matches!(s.state, AgentState::Return | AgentState::Pause));
        }
        checked += 1;
    }
    assert!(checked > 100);
    let closing = towards / return_time;
    assert!(
        closing > w.leader.speed,
        "returning agents close in at {closing} m/s, the leader moves at {}",
        w.leader.speed
    );
    // The landmarks moved with the leader: some were released and replaced.
    assert!(out.stats.landmark_selections == 10);
    assert!(out.stats.landmark_replacements > 0);
    assert!(out.stats.landmark_releases_outside > 0);
    // Landmarks do not move during their static intervals.
    for iv in out
        .log
        .static_intervals
        .iter()
        .filter(|s| s.reason == StaticReason::Landmark)
    {
        let pts: Vec<_> = traj
            .samples
            .iter()
            .filter(|s| s.agent == iv.agent && s.time >= iv.start && s.time < iv.end)
            .collect();
        assert!(pts.windows(2).all(|p| p[0].x == p[1].x && p[0].y == p[1].y));
    }
}

#[test]
fn walkers_never_press_into_a_wall_they_touch() {
    // Runs never end on their own here, so an agent turned towards a wall it already
    // touches (in a corner, after leaving the other side; or by another contact) would
    // press into it, sliding or stuck, for the rest of the run unless that counts as a
    // collision. A departing agent leaves the wall by v dt sin θ per step.
    let mut w = still_world(2.0, 2.0, 30, 600.0);
    w.swarm.mean_run_length = 1e6;
    w.swarm.stop_rate = 0.0;
    w.swarm.landmark_fraction = 0.0;
    let out = run(&w, 11, w.simulation.dt);
    let r = w.swarm.body_radius;
    let gap = |x: f64, y: f64| w.clearance((x, y)) - r;
    let mut longest = 0;
    for track in tracks(&out, 30) {
        let mut pressing = 0;
        for p in track.windows(2) {
            let (g0, g1) = (gap(p[0].1, p[0].2), gap(p[1].1, p[1].2));
            let walking = p[0].3 == AgentState::Walk && p[1].3 == AgentState::Walk;
            if walking && g0 < 1e-4 && g1 < 1e-4 && (g1 - g0).abs() < 1e-6 {
                pressing += 1;
                longest = longest.max(pressing);
            } else {
                pressing = 0;
            }
        }
    }
    assert!(
        longest <= 3,
        "an agent pressed into a wall for {longest} steps"
    );
}

#[test]
fn kept_surplus_landmarks_are_released_only_when_they_leave_the_domain() {
    // Agents crossing D(t)'s edges move the count asked for by one now and then; by
    // default the newest landmark is released at once (and replaced a moment later); with
    // `keep_surplus_landmarks` only the domain's trailing edge releases landmarks.
    let mut w = sweep_world();
    // The bundled worlds' 30 %: the count asked for, round(0.3 × agents inside), changes
    // as soon as two of the 100 agents are outside.
    w.swarm.landmark_fraction = 0.3;
    let every = 0.1;
    let default = run(&w, 11, every);
    assert!(default.stats.landmark_releases_surplus > 0);
    w.swarm.keep_surplus_landmarks = true;
    let out = run(&w, 11, every);
    assert_eq!(out.stats.landmark_releases_surplus, 0);
    assert!(out.stats.landmark_releases_outside > 0);
    let most = (w.swarm.landmark_fraction * w.swarm.agents as f64).round() as usize;
    let traj = out.trajectories.as_ref().expect("trajectories");
    let disp = w.simulation.dispersion_time;
    let mut checked = 0;
    for chunk in traj.samples.chunks(w.swarm.agents) {
        let t = chunk[0].time;
        if t < disp - 1e-9 || t >= out.stats.simulated_time - 1e-9 {
            continue;
        }
        let (x0, x1) = w.domain(t);
        let inside: Vec<_> = chunk.iter().filter(|s| s.x >= x0 && s.x <= x1).collect();
        let landmarks: Vec<_> = chunk
            .iter()
            .filter(|s| s.state == AgentState::Landmark)
            .collect();
        let target = (w.swarm.landmark_fraction * inside.len() as f64).round() as usize;
        assert!(
            landmarks.iter().all(|s| s.x >= x0 && s.x <= x1),
            "landmark outside D({t})"
        );
        assert!(
            landmarks.len() >= target,
            "at t = {t}: {} < {target}",
            landmarks.len()
        );
        assert!(
            landmarks.len() <= most,
            "at t = {t}: {} > {most}",
            landmarks.len()
        );
        checked += 1;
    }
    assert!(checked > 100);
    // Every landmark interval that ends before the run does ends with its agent behind the
    // domain's trailing edge (the sweep goes to +x); a static agent stands where it was.
    let end = out.stats.simulated_time;
    let mut released = 0;
    for iv in out
        .log
        .static_intervals
        .iter()
        .filter(|s| s.reason == StaticReason::Landmark && s.end < end - 1e-9)
    {
        let Some(at) = traj
            .samples
            .iter()
            .find(|s| s.agent == iv.agent && s.time >= iv.start && s.time < iv.end)
        else {
            continue; // shorter than the sampling interval
        };
        let (x0, _) = w.domain(iv.end);
        assert!(
            at.x < x0 + 1e-9,
            "landmark {} released at t = {} at x = {}, inside D(t) from {x0}",
            iv.agent,
            iv.end,
            at.x
        );
        released += 1;
    }
    assert!(released > 0);
}
