//! Encounters from Rapier's sensor events against a brute-force oracle on the recorded
//! full-resolution trajectories, and their sensitivity to the time step.

use std::collections::HashMap;
use swarmmap::sim::{SimOptions, simulate};
use swarmmap::world::{Obstacle, Placement, World};

/// True contacts of each pair: `(start, end, samples within r_d)`.
type Contacts = HashMap<(u32, u32), Vec<(f64, f64, usize)>>;

/// A small, crowded arena so that encounters are frequent; no sweep.
fn crowded(width: f64, agents: usize, duration: f64) -> World {
    let mut w = World::empty("crowded", width, width);
    w.swarm.agents = agents;
    w.swarm.placement = Placement::Window;
    w.leader.window = width;
    w.leader.start_x = width / 2.0;
    w.leader.end_x = width / 2.0;
    w.simulation.dispersion_time = duration;
    w
}

#[test]
fn encounters_match_brute_force_centre_distances() {
    let mut w = crowded(1.5, 60, 120.0);
    w.obstacles.push(Obstacle::Circle {
        center: (0.75, 0.75),
        radius: 0.2,
    });
    // Landmarks and pauses too, so that static agents take part.
    w.swarm.stop_rate = 0.05;
    let dt = w.simulation.dt;
    let out = simulate(&w, &SimOptions::new(5).with_trajectories(dt)).expect("runs");
    let traj = out.trajectories.as_ref().expect("trajectories");
    let n = w.swarm.agents;
    let frames: Vec<_> = traj.samples.chunks(n).collect();
    let r_d = w.swarm.detection_radius;

    // Oracle: maximal runs of samples with centres within r_d; an interval ends at the
    // first sample where they are not (or at the final time).
    let mut truth: Contacts = HashMap::new();
    let mut open: HashMap<(u32, u32), (f64, usize)> = HashMap::new();
    for f in &frames {
        let t = f[0].time;
        for a in 0..n {
            for b in a + 1..n {
                let d = (f[a].x - f[b].x).hypot(f[a].y - f[b].y);
                let key = (a as u32, b as u32);
                if d < r_d {
                    open.entry(key).or_insert((t, 0)).1 += 1;
                } else if let Some((s, len)) = open.remove(&key) {
                    truth.entry(key).or_default().push((s, t, len));
                }
            }
        }
    }
    let end = frames.last().expect("frames")[0].time;
    for (key, (s, len)) in open {
        truth.entry(key).or_default().push((s, end, len));
    }

    let tol = dt * 1.0001;
    let mut recorded: HashMap<(u32, u32), Vec<(f64, f64)>> = HashMap::new();
    for e in &out.log.encounters {
        assert!(e.a < e.b && e.start <= e.end);
        recorded
            .entry((e.a, e.b))
            .or_default()
            .push((e.start, e.end));
        let matched = truth.get(&(e.a, e.b)).is_some_and(|v| {
            v.iter()
                .any(|&(s, t, _)| (s - e.start).abs() <= tol && (t - e.end).abs() <= tol)
        });
        assert!(
            matched,
            "encounter {e:?} has no true contact within one step"
        );
    }
    let mut long = 0;
    for (key, v) in &truth {
        for &(s, t, len) in v.iter().filter(|x| x.2 > 2) {
            long += 1;
            let found = recorded.get(key).is_some_and(|r| {
                r.iter()
                    .any(|&(a, b)| (a - s).abs() <= tol && (b - t).abs() <= tol)
            });
            assert!(
                found,
                "contact {key:?} over [{s}, {t}] ({len} samples) not recorded"
            );
        }
    }
    assert!(
        long > 100,
        "only {long} long contacts: the test is too weak"
    );
    // Sorted by (start, a, b).
    assert!(out.log.encounters.windows(2).all(|p| {
        (p[0].start, p[0].a, p[0].b)
            .partial_cmp(&(p[1].start, p[1].a, p[1].b))
            .is_some_and(|o| o.is_le())
    }));
}

#[test]
fn halving_the_time_step_changes_the_encounter_count_by_less_than_5_percent() {
    let base = crowded(2.5, 300, 400.0);
    let dt = base.simulation.dt;
    let mut counts = Vec::new();
    for (k, step) in [dt, dt / 2.0].into_iter().enumerate() {
        let mut w = base.clone();
        w.simulation.dt = step;
        let out = simulate(&w, &SimOptions::new(100 + k as u64)).expect("runs");
        counts.push(out.log.encounters.len() as f64);
    }
    let change = (counts[1] - counts[0]).abs() / counts[1];
    eprintln!("encounters at dt, dt/2: {counts:?}; change {change}");
    // Poisson noise of the difference is ~1.7 % at these counts; the bound is 5 %.
    assert!(counts[1] > 6000.0, "too few encounters: {counts:?}");
    assert!(change < 0.05, "counts {counts:?}: change {change}");
}
