//! Synthetic encounter logs without physics, for benchmarks and property tests of the
//! mapping stages: agents run-and-tumble in an empty rectangle (straight runs of
//! exponential length, reflection at the sides), the first `landmarks` agents stay put for
//! the whole log, and an encounter is every maximal run of steps during which two centres
//! are within the detection radius (found with a uniform grid, O(agents) per step).
//! Deterministic for a seed. Not a substitute for the Rapier simulator: no bodies, no
//! obstacles, no leader.

use crate::log::{Encounter, EncounterLog, StaticInterval, StaticReason};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Exp};
use std::collections::HashMap;

/// Parameters of a synthetic log.
#[derive(Debug, Clone, PartialEq)]
pub struct SyntheticParams {
    /// Number of agents (default: `100`).
    pub agents: usize,
    /// How many of them are static landmarks (default: `10`).
    pub landmarks: usize,
    /// Rectangle size in metres (default: `3.0 × 10.0`).
    pub width: f64,
    pub height: f64,
    /// Detection radius in metres (default: `0.05`).
    pub detection_radius: f64,
    /// Speed in m/s (default: `0.1`) and mean run length in metres (default: `1.0`).
    pub speed: f64,
    pub mean_run_length: f64,
    /// Time step in seconds (default: `0.1`).
    pub dt: f64,
    /// Seed (default: `1`).
    pub seed: u64,
}

impl Default for SyntheticParams {
    fn default() -> Self {
        Self {
            agents: 100,
            landmarks: 10,
            width: 3.0,
            height: 10.0,
            detection_radius: 0.05,
            speed: 0.1,
            mean_run_length: 1.0,
            dt: 0.1,
            seed: 1,
        }
    }
}

/// Simulates until at least `encounters` encounters have closed, and returns the log
/// (with truth columns).
pub fn synthetic_log(p: &SyntheticParams, encounters: usize) -> EncounterLog {
    let mut rng = ChaCha8Rng::seed_from_u64(p.seed);
    let run = Exp::new(1.0 / p.mean_run_length.max(1e-9)).expect("positive rate");
    let n = p.agents;
    let mut pos: Vec<(f64, f64)> = (0..n)
        .map(|_| {
            (
                rng.random_range(0.0..p.width),
                rng.random_range(0.0..p.height),
            )
        })
        .collect();
    let mut heading: Vec<f64> = (0..n)
        .map(|_| rng.random_range(0.0..std::f64::consts::TAU))
        .collect();
    let mut left: Vec<f64> = (0..n).map(|_| run.sample(&mut rng)).collect();
    let r = p.detection_radius;
    let mut open: HashMap<(u32, u32), (f64, [f64; 4])> = HashMap::new();
    let mut out = Vec::new();
    let mut grid: HashMap<(usize, usize), Vec<u32>> = HashMap::new();
    let mut t = 0.0;
    while out.len() < encounters {
        t += p.dt;
        for i in p.landmarks.min(n)..n {
            let step = p.speed * p.dt;
            left[i] -= step;
            if left[i] <= 0.0 {
                heading[i] = rng.random_range(0.0..std::f64::consts::TAU);
                left[i] = run.sample(&mut rng);
            }
            let (mut x, mut y) = (
                pos[i].0 + step * heading[i].cos(),
                pos[i].1 + step * heading[i].sin(),
            );
            if !(0.0..=p.width).contains(&x) {
                x = x.clamp(0.0, p.width);
                heading[i] = std::f64::consts::PI - heading[i];
            }
            if !(0.0..=p.height).contains(&y) {
                y = y.clamp(0.0, p.height);
                heading[i] = -heading[i];
            }
            pos[i] = (x, y);
        }
        grid.clear();
        for (i, &(x, y)) in pos.iter().enumerate() {
            let c = ((x / r) as usize, (y / r) as usize);
            grid.entry(c).or_default().push(i as u32);
        }
        let mut now: Vec<(u32, u32)> = Vec::new();
        for (&(cx, cy), members) in &grid {
            for dx in 0..=2usize {
                for dy in 0..=2usize {
                    // Out-of-range neighbours wrap to huge keys that are never present.
                    let (nx, ny) = ((cx + dx).wrapping_sub(1), (cy + dy).wrapping_sub(1));
                    let Some(others) = grid.get(&(nx, ny)) else {
                        continue;
                    };
                    for &a in members {
                        for &b in others {
                            if a < b {
                                let (pa, pb) = (pos[a as usize], pos[b as usize]);
                                if (pa.0 - pb.0).hypot(pa.1 - pb.1) <= r {
                                    now.push((a, b));
                                }
                            }
                        }
                    }
                }
            }
        }
        now.sort_unstable();
        now.dedup();
        for &(a, b) in &now {
            open.entry((a, b)).or_insert_with(|| {
                let (pa, pb) = (pos[a as usize], pos[b as usize]);
                (t, [pa.0, pa.1, pb.0, pb.1])
            });
        }
        let mut closed: Vec<(u32, u32)> = open
            .keys()
            .filter(|k| now.binary_search(k).is_err())
            .copied()
            .collect();
        closed.sort_unstable();
        for k in closed {
            let (start, truth) = open.remove(&k).expect("open pair");
            out.push(Encounter {
                start,
                end: t - p.dt,
                a: k.0,
                b: k.1,
                truth: Some(truth),
            });
        }
    }
    out.sort_by(|x, y| {
        x.start
            .total_cmp(&y.start)
            .then(x.a.cmp(&y.a))
            .then(x.b.cmp(&y.b))
    });
    let static_intervals = (0..p.landmarks.min(n) as u32)
        .map(|agent| StaticInterval {
            agent,
            start: 0.0,
            end: t,
            reason: StaticReason::Landmark,
        })
        .collect();
    EncounterLog {
        encounters: out,
        static_intervals,
        leader: Vec::new(),
    }
}

/// The Procrustes error of the `Embedded` cloud of one synthetic log (a 6 m square, 30
/// static landmarks among 100 agents, r_d = 10 cm, 4 000 steps of seed `seed`) mapped as one
/// window with `p`: the yardstick of the tests that compare placements of the moving
/// agents' encounters ([`super::bridge`], [`super::timelines`]).
#[cfg(test)]
pub(crate) fn square_embedding_error(p: &super::local::LocalParams, seed: u64) -> f64 {
    let log = synthetic_log(
        &SyntheticParams {
            landmarks: 30,
            width: 6.0,
            height: 6.0,
            detection_radius: 0.1,
            seed,
            ..Default::default()
        },
        4000,
    );
    let end = log.encounters.iter().map(|e| e.end).fold(0.0, f64::max);
    let w = super::windows::Window {
        index: 1,
        start: 0.0,
        end,
    };
    let map = super::local::local_map(&log, &w, p);
    super::pipeline::fidelity(&map, &log, 72f64.sqrt(), super::dense::EMBEDDED_POINTS)
        .procrustes
        .expect("truth columns")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn encounters_are_real_contacts_and_deterministic() {
        let p = SyntheticParams {
            agents: 40,
            landmarks: 4,
            width: 1.0,
            height: 1.0,
            ..Default::default()
        };
        let log = synthetic_log(&p, 200);
        assert!(log.encounters.len() >= 200);
        for e in &log.encounters {
            let t = e.truth.unwrap();
            assert!((t[0] - t[2]).hypot(t[1] - t[3]) <= p.detection_radius + 1e-12);
            assert!(e.end >= e.start && e.a < e.b);
        }
        assert_eq!(log, synthetic_log(&p, 200));
    }
}
