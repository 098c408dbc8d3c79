//! How fast a wall follower slides along a ring obstacle drawn as a circle or as polygons
//! of 12 to 5 000 vertices: one agent that follows every wall it meets, in a 4 m × 4 m
//! arena round a ring of radius 0.5 m, for 200 s (seed 1). Prints, over the trajectory
//! samples within 5 mm of a wall, the median and mean speed and the median and 90th
//! percentile gap. A sliding body should keep the walking speed, 0.1 m/s, whatever the
//! vertex count (`sim/physics.rs`, `ORIENTED_MIN_VERTICES`).
//!
//! Run: `cargo run --release --example wall_speed`.

use swarmmap::sim::{SimOptions, simulate};
use swarmmap::world::{Obstacle, Placement, World};

fn main() {
    let (c, r) = ((2.0, 2.0), 0.5);
    for n in [0usize, 12, 63, 720, 5000] {
        let mut w = World::empty("wall_speed", 4.0, 4.0);
        w.swarm.agents = 1;
        w.swarm.stop_rate = 0.0;
        w.swarm.landmark_fraction = 0.0;
        w.swarm.wall_following = 1.0;
        w.swarm.wall_following_length = 1e6;
        w.swarm.placement = Placement::Disk { radius: 0.8 };
        w.leader.window = 4.0;
        w.leader.start_x = 2.0;
        w.leader.end_x = 2.0;
        w.simulation.dispersion_time = 200.0;
        w.obstacles = vec![if n == 0 {
            Obstacle::Circle {
                center: c,
                radius: r,
            }
        } else {
            let points = (0..n)
                .map(|k| {
                    let a = std::f64::consts::TAU * k as f64 / n as f64;
                    (c.0 + r * a.cos(), c.1 + r * a.sin())
                })
                .collect();
            Obstacle::Polygon { points }
        }];
        let opts = SimOptions::new(1).with_trajectories(w.simulation.dt);
        let out = match simulate(&w, &opts) {
            Ok(out) => out,
            Err(e) => {
                eprintln!("{n} vertices: {e}");
                continue;
            }
        };
        let Some(tracks) = out.trajectories.as_ref() else {
            continue;
        };
        let (mut speeds, mut gaps) = (Vec::new(), Vec::new());
        for p in tracks.samples.windows(2) {
            let gap = w.clearance((p[1].x, p[1].y)) - w.swarm.body_radius;
            if gap < 0.005 {
                let step = (p[1].x - p[0].x).hypot(p[1].y - p[0].y);
                speeds.push(step / (p[1].time - p[0].time));
                gaps.push(gap);
            }
        }
        if speeds.is_empty() {
            println!("{n} vertices: never at a wall");
            continue;
        }
        speeds.sort_by(f64::total_cmp);
        gaps.sort_by(f64::total_cmp);
        let m = speeds.len();
        let shape = if n == 0 {
            "circle".to_string()
        } else {
            format!("{n} vertices")
        };
        println!(
            "{shape}: {m} samples at a wall, speed median {:.4} mean {:.4} m/s, gap median {:.2e} p90 {:.2e} m",
            speeds[m / 2],
            speeds.iter().sum::<f64>() / m as f64,
            gaps[m / 2],
            gaps[m * 9 / 10]
        );
    }
}
