//! Output files: format, atomic writing, and byte-for-byte determinism.

use sha2::{Digest, Sha256};
use std::path::Path;
use swarmmap::sim::{SimError, SimOptions, simulate, write_run};
use swarmmap::world::{Obstacle, World};

/// A small world with a real sweep: 30 agents, 100 s.
fn small_world() -> World {
    let mut w = World::empty("golden", 6.0, 3.0);
    w.obstacles.push(Obstacle::Rect {
        min: (2.5, 1.0),
        max: (3.5, 2.0),
    });
    w.swarm.agents = 30;
    w.swarm.stop_rate = 0.05;
    w.leader.window = 2.0;
    w.leader.start_x = 1.0;
    w.leader.end_x = 5.0;
    w.leader.speed = 0.05;
    w.simulation.dispersion_time = 20.0;
    w
}

/// SHA-256 over the files of a run, `meta.json` without its wall-time `timings`.
fn digest(dir: &Path) -> String {
    let mut h = Sha256::new();
    for name in [
        "encounters.csv",
        "static_intervals.csv",
        "leader.csv",
        "trajectories.csv",
    ] {
        h.update(name.as_bytes());
        h.update(std::fs::read(dir.join(name)).expect("file written"));
    }
    let meta: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("meta.json")).expect("meta")).expect("json");
    let mut meta = meta;
    let timings = meta
        .as_object_mut()
        .and_then(|m| m.remove("timings"))
        .expect("timings present");
    assert!(timings["wall_time_s"].as_f64().is_some());
    h.update(b"meta.json");
    h.update(serde_json::to_vec(&meta).expect("json"));
    h.finalize().iter().map(|b| format!("{b:02x}")).collect()
}

fn run_to(dir: &Path, world: &World, seed: u64) {
    let out = simulate(world, &SimOptions::new(seed).with_trajectories(1.0)).expect("runs");
    write_run(dir, world, &out).expect("written");
}

/// Golden hash of the outputs of `small_world()` with seed 42. A change means the
/// simulation's behaviour changed (motion model, event handling, Rapier version or its
/// parameters, RNG use) or an output format changed: check that the change is intended,
/// then update the constant and say why in the commit message.
///
/// Last changed: `meta.json` gained `swarm.return_patience` and the count
/// `return_escapes` (a format change only: this run has no escape, and its other files are
/// byte-identical to before). Before that: `meta.json` gained `mapping.switch_cost` (a
/// format change only). Before that: the arena's sides are tracked one by one and a
/// walker heading into a wall or agent it still touches collides again (both change the
/// trajectories; README, "The simulation", "Contacts"); `meta.json` gained
/// `swarm.wall_following`, `swarm.wall_following_length` and the counts `wall_follows`,
/// `presses`.
const GOLDEN: &str = "121905e4d36a058283f645c0ce85ee619c938262597730af03442ffe3daa389e";

#[test]
fn same_seed_same_bytes_and_golden_hash() {
    let w = small_world();
    let (a, b) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    run_to(a.path(), &w, 42);
    run_to(b.path(), &w, 42);
    let (da, db) = (digest(a.path()), digest(b.path()));
    assert_eq!(da, db, "two runs with the same seed differ");
    assert_eq!(
        da, GOLDEN,
        "golden hash changed (see the comment on GOLDEN)"
    );
}

#[test]
fn different_seeds_differ() {
    let w = small_world();
    let (a, b) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    run_to(a.path(), &w, 1);
    run_to(b.path(), &w, 2);
    for name in ["encounters.csv", "static_intervals.csv", "trajectories.csv"] {
        assert_ne!(
            std::fs::read(a.path().join(name)).unwrap(),
            std::fs::read(b.path().join(name)).unwrap(),
            "{name} is the same for seeds 1 and 2"
        );
    }
}

#[test]
fn files_have_the_documented_columns_and_order() {
    let w = small_world();
    let dir = tempfile::tempdir().unwrap();
    run_to(dir.path(), &w, 3);
    let read = |n: &str| std::fs::read_to_string(dir.path().join(n)).unwrap();
    let enc = read("encounters.csv");
    let mut lines = enc.lines();
    assert_eq!(lines.next(), Some("start,end,a,b,a_x,a_y,b_x,b_y"));
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert!(!rows.is_empty());
    for r in &rows {
        assert_eq!(r.len(), 8);
        let (s, e): (f64, f64) = (r[0].parse().unwrap(), r[1].parse().unwrap());
        let (a, b): (u32, u32) = (r[2].parse().unwrap(), r[3].parse().unwrap());
        assert!(s <= e && a < b);
        assert_eq!(r[0].split('.').nth(1).map(str::len), Some(6));
    }
    let st = read("static_intervals.csv");
    assert!(st.starts_with("agent,start,end,reason\n"));
    let reasons: Vec<&str> = st
        .lines()
        .skip(1)
        .map(|l| l.rsplit(',').next().unwrap())
        .collect();
    assert!(reasons.iter().all(|r| *r == "landmark" || *r == "pause"));
    assert!(reasons.contains(&"landmark") && reasons.contains(&"pause"));
    let leader = read("leader.csv");
    assert!(leader.starts_with("time,x\n"));
    let last: Vec<f64> = leader
        .lines()
        .last()
        .unwrap()
        .split(',')
        .map(|x| x.parse().unwrap())
        .collect();
    // The run ends at the first whole step at or after T (T / dt need not be whole).
    let (total, dt) = (w.total_duration(), w.simulation.dt);
    assert!(
        (last[0] - (total / dt).ceil() * dt).abs() < 1e-6,
        "{last:?}"
    );
    assert!(last[0] >= total - 1e-9 && last[0] < total + dt);
    assert!((last[1] - w.leader.end_x).abs() < 1e-9);
    let traj = read("trajectories.csv");
    assert!(traj.starts_with("time,agent,x,y,state\n"));
    // Samples every round(1 s / dt) steps (documented), from step 0 to the last step.
    let (steps, every) = ((total / dt).ceil() as usize, (1.0 / dt).round() as usize);
    assert_eq!(
        traj.lines().count() - 1,
        w.swarm.agents * (steps / every + 1)
    );
    let meta: serde_json::Value = serde_json::from_str(&read("meta.json")).unwrap();
    assert_eq!(meta["world"]["name"], "golden");
    assert_eq!(meta["seed"], 3);
    assert_eq!(meta["world"]["obstacles"][0]["Rect"]["min"][0], 2.5);
    assert_eq!(meta["counts"]["encounters"], rows.len());
    assert_eq!(meta["crate_version"], env!("CARGO_PKG_VERSION"));
    // No temporary file is left behind.
    let names: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names.len(), 5, "{names:?}");
}

#[test]
fn bad_parameters_are_errors_not_panics() {
    let mut w = small_world();
    w.simulation.dt = 0.0;
    let e = simulate(&w, &SimOptions::new(1)).unwrap_err();
    assert!(e.to_string().contains("simulation.dt"), "{e}");
    let w = small_world();
    let e = simulate(&w, &SimOptions::new(1).with_trajectories(-1.0)).unwrap_err();
    assert!(matches!(e, SimError::InvalidOption { .. }), "{e}");
    // No room for the agents: the start disc lies inside an obstacle.
    let mut w = small_world();
    w.obstacles.push(Obstacle::Rect {
        min: (0.0, 0.0),
        max: (2.2, 3.0),
    });
    let e = simulate(&w, &SimOptions::new(1)).unwrap_err();
    assert!(matches!(e, SimError::Placement { placed: 0, .. }), "{e}");
}
