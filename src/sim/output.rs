//! The files of a run. Each is rendered to bytes by its own function and written
//! atomically; numbers use fixed formats (`{:.6}` for seconds and metres) so that the same
//! run always gives the same bytes. Columns are documented in the README ("Output files").

use super::engine::{LEADER_INTERVAL, RETURN_NOISE};
use super::params::{SimError, SimOutput, Trajectories};
use crate::io::write_atomic;
use crate::log::EncounterLog;
use crate::world::{Obstacle, Placement, World};
use serde_json::{Value, json};
use std::fmt::Write as _;
use std::path::Path;

/// `encounters.csv`: `start,end,a,b,a_x,a_y,b_x,b_y`, sorted by `(start, a, b)`.
pub fn encounters_csv(log: &EncounterLog) -> Vec<u8> {
    let mut s = String::from("start,end,a,b,a_x,a_y,b_x,b_y\n");
    for e in &log.encounters {
        let _ = write!(s, "{:.6},{:.6},{},{}", e.start, e.end, e.a, e.b);
        match e.truth {
            Some([ax, ay, bx, by]) => {
                let _ = writeln!(s, ",{ax:.6},{ay:.6},{bx:.6},{by:.6}");
            }
            None => s.push_str(",,,,\n"),
        }
    }
    s.into_bytes()
}

/// `static_intervals.csv`: `agent,start,end,reason`, sorted by `(agent, start)`.
pub fn static_intervals_csv(log: &EncounterLog) -> Vec<u8> {
    let mut s = String::from("agent,start,end,reason\n");
    for iv in &log.static_intervals {
        let _ = writeln!(
            s,
            "{},{:.6},{:.6},{}",
            iv.agent,
            iv.start,
            iv.end,
            iv.reason.as_str()
        );
    }
    s.into_bytes()
}

/// `leader.csv`: `time,x`.
pub fn leader_csv(log: &EncounterLog) -> Vec<u8> {
    let mut s = String::from("time,x\n");
    for (t, x) in &log.leader {
        let _ = writeln!(s, "{t:.6},{x:.6}");
    }
    s.into_bytes()
}

/// `trajectories.csv`: `time,agent,x,y,state`, sorted by `(time, agent)`.
pub fn trajectories_csv(traj: &Trajectories) -> Vec<u8> {
    let mut s = String::from("time,agent,x,y,state\n");
    for p in &traj.samples {
        let _ = writeln!(
            s,
            "{:.6},{},{:.6},{:.6},{}",
            p.time,
            p.agent,
            p.x,
            p.y,
            p.state.as_str()
        );
    }
    s.into_bytes()
}

fn pt(p: (f64, f64)) -> Value {
    json!([p.0, p.1])
}

/// The world as JSON, every parameter in force (defaults filled in).
pub fn world_json(world: &World) -> Value {
    let obstacles: Vec<Value> = world
        .obstacles
        .iter()
        .map(|o| match o {
            Obstacle::Rect { min, max } => json!({"Rect": {"min": pt(*min), "max": pt(*max)}}),
            Obstacle::Circle { center, radius } => {
                json!({"Circle": {"center": pt(*center), "radius": radius}})
            }
            Obstacle::Polygon { points } => {
                json!({"Polygon": {"points": points.iter().map(|p| pt(*p)).collect::<Vec<_>>()}})
            }
            Obstacle::Wall {
                from,
                to,
                thickness,
            } => json!({"Wall": {"from": pt(*from), "to": pt(*to), "thickness": thickness}}),
        })
        .collect();
    let s = &world.swarm;
    let placement = match s.placement {
        Placement::Disk { radius } => json!({"Disk": {"radius": radius}}),
        Placement::Window => json!("Window"),
    };
    let m = &world.mapping;
    let mut v = json!({
        "name": world.name,
        "arena": {"width": world.arena.width, "height": world.arena.height},
        "obstacles": obstacles,
        "swarm": {
            "agents": s.agents,
            "speed": s.speed,
            "detection_radius": s.detection_radius,
            "landmark_fraction": s.landmark_fraction,
            "body_radius": s.body_radius,
            "mean_run_length": s.mean_run_length,
            "stop_rate": s.stop_rate,
            "mean_stop_duration": s.mean_stop_duration,
            "comm_radius": s.comm_radius,
            "wall_following": s.wall_following,
            "wall_following_length": s.wall_following_length,
            "return_patience": s.return_patience,
            "placement": placement,
        },
        "leader": {
            "speed": world.leader.speed,
            "window": world.leader.window,
            "start_x": world.leader.start_x,
            "end_x": world.leader.end_x,
        },
        "simulation": {
            "dt": world.simulation.dt,
            "dispersion_time": world.simulation.dispersion_time,
        },
        "mapping": {
            "windows": m.windows,
            "overlap": m.overlap,
            "cluster_cutoff": m.cluster_cutoff,
            "subsample": m.subsample,
            "neighbours": m.neighbours,
            "method": format!("{:?}", m.method),
            "switch_cost": m.switch_cost,
        },
        "seed": world.seed,
    });
    // Written only when set, so that the runs of earlier builds keep their bytes.
    if m.after_landmarks {
        v["mapping"]["after_landmarks"] = json!(true);
    }
    if m.encounter_midpoints {
        v["mapping"]["encounter_midpoints"] = json!(true);
    }
    if m.agent_timelines {
        v["mapping"]["agent_timelines"] = json!(true);
    }
    if m.split_stability {
        v["mapping"]["split_stability"] = json!(true);
    }
    if let Some(k) = m.outlier_rank {
        v["mapping"]["outlier_rank"] = json!(k);
    }
    if m.rips_points != crate::mapping::dense::EMBEDDED_POINTS {
        v["mapping"]["rips_points"] = json!(m.rips_points);
    }
    if s.keep_surplus_landmarks {
        v["swarm"]["keep_surplus_landmarks"] = json!(true);
    }
    v
}

/// `meta.json`. Everything but the `timings` object is deterministic.
pub fn meta_json(world: &World, out: &SimOutput) -> Vec<u8> {
    let st = &out.stats;
    let mut files = vec![
        "encounters.csv",
        "static_intervals.csv",
        "leader.csv",
        "meta.json",
    ];
    if out.trajectories.is_some() {
        files.push("trajectories.csv");
    }
    let meta = json!({
        "format": META_FORMAT,
        "crate_version": env!("CARGO_PKG_VERSION"),
        "world": world_json(world),
        "seed": out.seed,
        "model": {
            "dt": out.dt,
            "return_noise_rad": RETURN_NOISE,
            "encounter_rule": "centres within detection_radius (two sensor balls of radius detection_radius / 2)",
            "physics": "rapier2d 0.36, 1 solver iteration, no CCD, length unit 0.01 m",
        },
        "durations": {
            "dispersion": world.simulation.dispersion_time,
            "sweep": world.sweep_duration(),
            "total": world.total_duration(),
            "simulated": st.simulated_time,
        },
        "outputs": {
            "files": files,
            "leader_interval": out.leader_interval,
            "leader_interval_requested": LEADER_INTERVAL,
            "trajectory_interval": out.trajectories.as_ref().map(|t| t.interval),
        },
        "counts": {
            "steps": st.steps,
            "encounters": st.encounters,
            "static_intervals": st.static_intervals,
            "pauses": st.pauses,
            "landmark_selections": st.landmark_selections,
            "landmark_replacements": st.landmark_replacements,
            "landmark_releases_outside": st.landmark_releases_outside,
            "landmark_releases_surplus": st.landmark_releases_surplus,
            "collisions": st.collisions,
            "wall_follows": st.wall_follows,
            "presses": st.presses,
            "return_escapes": st.return_escapes,
        },
        "timings": {
            "wall_time_s": st.wall_time_s,
            "physics_s": st.physics_time_s,
            "landmarks_s": st.landmark_time_s,
            "sensing_s": st.sensing_time_s,
        },
    });
    let mut bytes = serde_json::to_vec_pretty(&meta).unwrap_or_default();
    bytes.push(b'\n');
    bytes
}

fn write(dir: &Path, name: &str, bytes: &[u8]) -> Result<(), SimError> {
    let path = dir.join(name);
    write_atomic(&path, bytes).map_err(|source| SimError::Write { path, source })
}

/// The format tag of the `meta.json` files this build writes, and the only one
/// [`crate::pipeline`] reads.
pub const META_FORMAT: &str = "swarmmap-simulation/1";

/// Removes an earlier run in `dir` before a new log replaces it: first what was derived
/// from its log (`summary.json`, the report in `report/`, the maps in `maps/`: each
/// window's and connection's file, `connections.json`, `global.json`) and its
/// `trajectories.csv`, then its `meta.json` (a complete `meta.json` means a complete run),
/// then the rest of its log (`encounters.csv`, `static_intervals.csv`, `leader.csv`). Left
/// in place, an interrupted write would leave a mix: the new encounters beside the old
/// metadata, trajectories or report, read as one run. In this order a removal that fails
/// or is interrupted leaves either a directory still marked as the old run (the next run
/// into it removes the rest) or only the three log files every run writes anew. Only
/// when `dir` holds a swarmmap run (its `meta.json` says so: these names are common
/// enough that a user's own directory may hold them), and only those files of
/// swarmmap's; anything else in `dir` stays.
fn remove_derived(dir: &Path) -> std::io::Result<()> {
    use crate::io::{is_numbered_map, remove_stale};
    let ours = std::fs::read(dir.join("meta.json"))
        .ok()
        .and_then(|b| serde_json::from_slice::<serde_json::Value>(&b).ok())
        .and_then(|v| {
            v.get("format")?
                .as_str()
                .map(|f| f.starts_with("swarmmap-simulation/"))
        })
        .unwrap_or(false);
    if !ours {
        return Ok(());
    }
    let none = std::collections::BTreeSet::new();
    remove_stale(dir, &none, |n| n == "summary.json")?;
    crate::report::remove_report(dir)?;
    remove_stale(&dir.join("maps"), &none, |n| {
        matches!(n, "connections.json" | "global.json") || is_numbered_map(n)
    })?;
    remove_stale(dir, &none, |n| n == "trajectories.csv")?;
    remove_stale(dir, &none, |n| n == "meta.json")?;
    remove_stale(dir, &none, |n| {
        matches!(n, "encounters.csv" | "static_intervals.csv" | "leader.csv")
    })
}

/// Whether files can be written into `dir`, asked before a simulation (or a fit) that may
/// take hours produces them: `dir`, or else the nearest of its ancestors that exists (where
/// it would be created), must be a directory in which a file can be made. The test file is
/// unnamed (`tempfile::tempfile_in`: nothing to leave behind if interrupted), and nothing
/// is created or touched: a command refused later for another reason leaves no directory.
pub fn prepare_out_dir(dir: &Path) -> Result<(), SimError> {
    let fail = |source| SimError::Write {
        path: dir.to_path_buf(),
        source,
    };
    let existing = dir
        .ancestors()
        .find(|a| a.exists())
        .filter(|a| !a.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    if !existing.is_dir() {
        let what = if existing == dir {
            "it is a file, not a directory; give --out a new or existing directory".to_string()
        } else {
            format!(
                "{} is a file, not a directory; give --out a path inside a directory",
                existing.display()
            )
        };
        return Err(fail(std::io::Error::other(what)));
    }
    tempfile::tempfile_in(existing).map(drop).map_err(fail)
}

/// Writes the run's files into `dir` (created if missing), each atomically:
/// `encounters.csv`, `static_intervals.csv`, `leader.csv`, `meta.json`, and
/// `trajectories.csv` when trajectories were recorded.
pub fn write_run(dir: &Path, world: &World, out: &SimOutput) -> Result<(), SimError> {
    prepare_out_dir(dir)?;
    std::fs::create_dir_all(dir).map_err(|source| SimError::Write {
        path: dir.to_path_buf(),
        source,
    })?;
    remove_derived(dir).map_err(|source| SimError::Write {
        path: dir.to_path_buf(),
        source,
    })?;
    write(dir, "encounters.csv", &encounters_csv(&out.log))?;
    write(dir, "static_intervals.csv", &static_intervals_csv(&out.log))?;
    write(dir, "leader.csv", &leader_csv(&out.log))?;
    if let Some(traj) = &out.trajectories {
        write(dir, "trajectories.csv", &trajectories_csv(traj))?;
    }
    // Last, so that a complete meta.json means a complete run.
    write(dir, "meta.json", &meta_json(world, out))
}
