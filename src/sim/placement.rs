//! Initial configuration: agents drawn uniformly (rejection sampling) in the free part of
//! the start region, at least a body diameter apart. A uniform grid of cell size one body
//! diameter makes each overlap test O(1), so placing n agents costs O(n) expected draws
//! while the region is far from full.

use super::params::SimError;
use crate::world::{Placement, World};
use rand::RngExt;
use rand_chacha::ChaCha8Rng;
use std::collections::HashMap;

/// Extra gap kept between a new agent and obstacles or other agents, metres, so that no
/// contact exists at `t = 0`.
pub const PLACEMENT_GAP: f64 = 1e-4;

/// Draws per agent before giving up.
const ATTEMPTS_PER_AGENT: usize = 10_000;

/// Places `world.swarm.agents` agents per `world.swarm.placement`.
pub(crate) fn place(world: &World, rng: &mut ChaCha8Rng) -> Result<Vec<(f64, f64)>, SimError> {
    let n = world.swarm.agents;
    let r = world.swarm.body_radius;
    let (w, h) = (world.arena.width, world.arena.height);
    // Bounding box of the region and a membership test.
    let cx = world.leader.start_x;
    let cy = h / 2.0;
    let (lo, hi, disk) = match world.swarm.placement {
        Placement::Disk { radius } => (
            ((cx - radius).max(0.0), (cy - radius).max(0.0)),
            ((cx + radius).min(w), (cy + radius).min(h)),
            Some(radius),
        ),
        Placement::Window => {
            let (x0, x1) = world.domain(0.0);
            ((x0, 0.0), (x1, h), None)
        }
    };
    let cell = 2.0 * r + PLACEMENT_GAP;
    let key = |p: (f64, f64)| ((p.0 / cell).floor() as i64, (p.1 / cell).floor() as i64);
    let mut grid: HashMap<(i64, i64), Vec<usize>> = HashMap::new();
    let mut placed: Vec<(f64, f64)> = Vec::with_capacity(n);
    let mut attempts = 0usize;
    let max_attempts = ATTEMPTS_PER_AGENT.saturating_mul(n.max(1));
    while placed.len() < n {
        if attempts >= max_attempts {
            return Err(SimError::Placement {
                placed: placed.len(),
                agents: n,
                attempts,
            });
        }
        attempts += 1;
        let p = (
            lo.0 + (hi.0 - lo.0) * rng.random::<f64>(),
            lo.1 + (hi.1 - lo.1) * rng.random::<f64>(),
        );
        if let Some(radius) = disk
            && (p.0 - cx).hypot(p.1 - cy) > radius
        {
            continue;
        }
        if !world.is_free(p, r + PLACEMENT_GAP) {
            continue;
        }
        let (kx, ky) = key(p);
        let overlaps = (-1..=1).any(|dx| {
            (-1..=1).any(|dy| {
                grid.get(&(kx + dx, ky + dy)).is_some_and(|ids| {
                    ids.iter().any(|&j| {
                        let q = placed[j];
                        (p.0 - q.0).hypot(p.1 - q.1) < cell
                    })
                })
            })
        });
        if overlaps {
            continue;
        }
        grid.entry((kx, ky)).or_default().push(placed.len());
        placed.push(p);
    }
    Ok(placed)
}
