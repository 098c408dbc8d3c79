//! Landmark selection by MaxMin on the hop distance of the communication graph (paper
//! §"Exploration and Event Collection", after de Silva and Tenenbaum's MaxMin landmarks,
//! "Sparse multidimensional scaling using landmark points", 2004).
//!
//! The communication graph joins the agents inside D(t) whose centres are within the
//! communication radius. Each new landmark is drawn as follows: pick a connected component
//! with probability equal to its share of the agents (so a connected graph always picks
//! itself); if the component holds no landmark yet, pick one of its agents uniformly,
//! otherwise pick the agent whose hop distance to the nearest landmark is largest (ties
//! broken uniformly at random). Hop distances to the landmark set are kept by a
//! multi-source BFS, updated after each pick by a BFS from the new landmark that stops
//! where distances do not improve.
//!
//! Complexity: building the graph on a uniform grid of cell size the communication radius
//! (the agents sorted by cell, each run of neighbouring cells found by binary search, each
//! pair of agents tested once) costs O(n log n + E); each pick costs O(n) plus the pruned
//! BFS, at most O(n + E). The selection runs at every landmark replacement (about 4 200
//! times in a scenario 2 run), so the grid is a sorted vector rather than a hash map, the
//! adjacency is compressed rows (a few arrays, not a list per agent), and the distances
//! to the landmarks already standing come from one multi-source BFS rather than one BFS
//! per landmark (docs/speed.md, "Landmark selection": the landmark upkeep of a scenario 2
//! run took 1.15–1.40 s before, 0.68–0.73 s after, then 0.38–0.47 s with compressed rows
//! against 0.49–0.62 s, with byte-identical outputs).

use rand::RngExt;
use rand_chacha::ChaCha8Rng;
use std::collections::VecDeque;

/// Hop distance of an agent no landmark can reach.
const UNREACHED: u32 = u32::MAX;

/// The communication graph over a set of candidate agents.
struct Graph {
    /// Agent `i`'s neighbours, ascending, are `targets[offsets[i]..offsets[i + 1]]`.
    offsets: Vec<usize>,
    targets: Vec<u32>,
    component: Vec<u32>,
    component_sizes: Vec<usize>,
}

impl Graph {
    fn neighbours(&self, i: usize) -> &[u32] {
        &self.targets[self.offsets[i]..self.offsets[i + 1]]
    }
}

fn build_graph(positions: &[(f64, f64)], radius: f64) -> Graph {
    let n = positions.len();
    let key = |p: (f64, f64)| ((p.0 / radius).floor() as i64, (p.1 / radius).floor() as i64);
    // The agents sorted by grid cell (cell size the radius): the agents of a column of
    // three neighbouring cells are one contiguous run, found by two binary searches.
    let mut cells: Vec<((i64, i64), u32)> = positions
        .iter()
        .enumerate()
        .map(|(i, &p)| (key(p), i as u32))
        .collect();
    cells.sort_unstable();
    let r2 = radius * radius;
    let mut pairs: Vec<(u32, u32)> = Vec::new();
    // Each pair is tested once, from the earlier of its two places in `cells`: the later
    // agents of the same cell and the cell above it (one run), and the next column's three
    // cells (another run). The test is symmetric, (a − b)² = (b − a)² exactly.
    for (at, &((kx, ky), i)) in cells.iter().enumerate() {
        let p = positions[i as usize];
        let above = (kx, ky.saturating_add(1));
        let same_column = at + 1..cells.partition_point(|&(c, _)| c <= above);
        let next_column = kx.checked_add(1).map_or(0..0, |column| {
            let (low, high) = (
                (column, ky.saturating_sub(1)),
                (column, ky.saturating_add(1)),
            );
            cells.partition_point(|&(c, _)| c < low)..cells.partition_point(|&(c, _)| c <= high)
        });
        for run in [same_column, next_column] {
            for &(_, j) in &cells[run] {
                let q = positions[j as usize];
                if (p.0 - q.0).powi(2) + (p.1 - q.1).powi(2) <= r2 {
                    pairs.push((i, j));
                }
            }
        }
    }
    // Compressed rows, a few arrays instead of a list per agent; sorting each row makes
    // BFS order canonical, whatever order the cells were scanned in.
    let mut offsets = vec![0usize; n + 1];
    for &(i, j) in &pairs {
        offsets[i as usize + 1] += 1;
        offsets[j as usize + 1] += 1;
    }
    for i in 0..n {
        offsets[i + 1] += offsets[i];
    }
    let mut fill = offsets[..n].to_vec();
    let mut targets = vec![0u32; offsets[n]];
    for &(i, j) in &pairs {
        targets[fill[i as usize]] = j;
        fill[i as usize] += 1;
        targets[fill[j as usize]] = i;
        fill[j as usize] += 1;
    }
    for i in 0..n {
        targets[offsets[i]..offsets[i + 1]].sort_unstable();
    }
    let mut graph = Graph {
        offsets,
        targets,
        component: Vec::new(),
        component_sizes: Vec::new(),
    };
    let mut component = vec![u32::MAX; n];
    let mut component_sizes = Vec::new();
    let mut queue = VecDeque::new();
    for s in 0..n {
        if component[s] != u32::MAX {
            continue;
        }
        let c = component_sizes.len() as u32;
        component[s] = c;
        queue.push_back(s as u32);
        let mut size = 0;
        while let Some(u) = queue.pop_front() {
            size += 1;
            for &w in graph.neighbours(u as usize) {
                if component[w as usize] == u32::MAX {
                    component[w as usize] = c;
                    queue.push_back(w);
                }
            }
        }
        component_sizes.push(size);
    }
    graph.component = component;
    graph.component_sizes = component_sizes;
    graph
}

/// Lowers `dist` by a BFS from `source`, visiting only vertices whose distance improves.
fn relax_from(graph: &Graph, dist: &mut [u32], source: usize) {
    relax_from_all(graph, dist, [source]);
}

/// Lowers `dist` by one BFS from all of `sources` at once (each at distance 0), visiting
/// only vertices whose distance improves: the same distances as a [`relax_from`] from each
/// source in turn, in one pass.
fn relax_from_all(graph: &Graph, dist: &mut [u32], sources: impl IntoIterator<Item = usize>) {
    let mut queue = VecDeque::new();
    for source in sources {
        dist[source] = 0;
        queue.push_back(source as u32);
    }
    while let Some(u) = queue.pop_front() {
        let du = dist[u as usize];
        for &w in graph.neighbours(u as usize) {
            if dist[w as usize] > du + 1 {
                dist[w as usize] = du + 1;
                queue.push_back(w);
            }
        }
    }
}

/// Chooses `count` new landmarks among `positions` (the agents inside D(t)), of which those
/// flagged in `is_landmark` already are landmarks. Returns indices into `positions`, in the
/// order chosen; fewer than `count` only if every candidate becomes a landmark.
pub(crate) fn select(
    positions: &[(f64, f64)],
    is_landmark: &[bool],
    radius: f64,
    count: usize,
    rng: &mut ChaCha8Rng,
) -> Vec<usize> {
    let n = positions.len();
    if count == 0 || n == 0 {
        return Vec::new();
    }
    let graph = build_graph(positions, radius);
    let mut landmark = is_landmark.to_vec();
    let mut dist = vec![UNREACHED; n];
    let mut has_landmark = vec![false; graph.component_sizes.len()];
    for i in (0..n).filter(|&i| landmark[i]) {
        has_landmark[graph.component[i] as usize] = true;
    }
    relax_from_all(&graph, &mut dist, (0..n).filter(|&i| landmark[i]));
    // Non-landmark agents left per component, to skip exhausted components.
    let mut free = vec![0usize; graph.component_sizes.len()];
    for i in (0..n).filter(|&i| !landmark[i]) {
        free[graph.component[i] as usize] += 1;
    }
    let mut chosen = Vec::with_capacity(count);
    while chosen.len() < count {
        let weight: usize = (0..free.len())
            .filter(|&c| free[c] > 0)
            .map(|c| graph.component_sizes[c])
            .sum();
        if weight == 0 {
            break;
        }
        let mut ticket = rng.random_range(0..weight);
        let mut comp = 0;
        for c in (0..free.len()).filter(|&c| free[c] > 0) {
            if ticket < graph.component_sizes[c] {
                comp = c;
                break;
            }
            ticket -= graph.component_sizes[c];
        }
        let members = (0..n).filter(|&i| graph.component[i] as usize == comp && !landmark[i]);
        let pick = if has_landmark[comp] {
            // MaxMin: farthest (in hops) from the landmarks; reservoir-sample among ties.
            let mut best = None;
            let mut best_d = 0;
            let mut ties = 0u32;
            for i in members {
                let d = dist[i];
                if best.is_none() || d > best_d {
                    best = Some(i);
                    best_d = d;
                    ties = 1;
                } else if d == best_d {
                    ties += 1;
                    if rng.random_range(0..ties) == 0 {
                        best = Some(i);
                    }
                }
            }
            best
        } else {
            let members: Vec<usize> = members.collect();
            (!members.is_empty()).then(|| members[rng.random_range(0..members.len())])
        };
        let Some(pick) = pick else { break };
        landmark[pick] = true;
        has_landmark[comp] = true;
        free[comp] -= 1;
        relax_from(&graph, &mut dist, pick);
        chosen.push(pick);
    }
    chosen
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    /// Brute-force hop distances by Floyd–Warshall on a small graph.
    fn hops(positions: &[(f64, f64)], radius: f64) -> Vec<Vec<u32>> {
        let n = positions.len();
        let mut d = vec![vec![UNREACHED; n]; n];
        for i in 0..n {
            d[i][i] = 0;
            for j in 0..n {
                let (p, q) = (positions[i], positions[j]);
                if i != j && (p.0 - q.0).hypot(p.1 - q.1) <= radius {
                    d[i][j] = 1;
                }
            }
        }
        for k in 0..n {
            for i in 0..n {
                for j in 0..n {
                    if d[i][k] != UNREACHED && d[k][j] != UNREACHED {
                        d[i][j] = d[i][j].min(d[i][k] + d[k][j]);
                    }
                }
            }
        }
        d
    }

    /// The grid finds exactly the pairs within the radius (boundary included), as a scan of
    /// all pairs does, with points on cell edges, negative coordinates and duplicates.
    #[test]
    fn the_grid_finds_every_pair_within_the_radius() {
        let mut rng = ChaCha8Rng::seed_from_u64(9);
        for radius in [0.3, 1.0, 2.5] {
            let mut positions: Vec<(f64, f64)> = (0..150)
                .map(|_| (rng.random_range(-3.0..6.0), rng.random_range(-2.0..4.0)))
                .collect();
            // On cell edges, exactly one radius apart, and a duplicate.
            positions.extend([(0.0, 0.0), (radius, 0.0), (0.0, radius), (radius, radius)]);
            positions.push(positions[3]);
            let graph = build_graph(&positions, radius);
            for (i, p) in positions.iter().enumerate() {
                let want: Vec<u32> = (0..positions.len())
                    .filter(|&j| {
                        let q = positions[j];
                        j != i && (p.0 - q.0).powi(2) + (p.1 - q.1).powi(2) <= radius * radius
                    })
                    .map(|j| j as u32)
                    .collect();
                assert_eq!(graph.neighbours(i), want, "radius {radius}, agent {i}");
            }
        }
    }

    /// One BFS from every landmark at once, and a pruned BFS from each landmark in turn,
    /// both give each agent's hop distance to its nearest landmark (Floyd–Warshall on the
    /// same graph), on random graphs with several components.
    #[test]
    fn one_multi_source_bfs_equals_a_bfs_per_source() {
        let mut rng = ChaCha8Rng::seed_from_u64(21);
        for _ in 0..200 {
            let n = rng.random_range(1..80);
            let positions: Vec<(f64, f64)> = (0..n)
                .map(|_| (rng.random_range(0.0..8.0), rng.random_range(0.0..3.0)))
                .collect();
            let radius = rng.random_range(0.3..1.5);
            let graph = build_graph(&positions, radius);
            let d = hops(&positions, radius);
            let sources: Vec<usize> = (0..n).filter(|_| rng.random_bool(0.2)).collect();
            let want: Vec<u32> = (0..n)
                .map(|i| sources.iter().map(|&s| d[i][s]).min().unwrap_or(UNREACHED))
                .collect();
            let mut one_by_one = vec![UNREACHED; n];
            for &s in &sources {
                relax_from(&graph, &mut one_by_one, s);
            }
            let mut at_once = vec![UNREACHED; n];
            relax_from_all(&graph, &mut at_once, sources.iter().copied());
            assert_eq!(at_once, want);
            assert_eq!(one_by_one, want);
        }
    }

    #[test]
    fn maxmin_picks_are_farthest_from_previous_landmarks() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let positions: Vec<(f64, f64)> = (0..60)
            .map(|_| (rng.random::<f64>() * 6.0, rng.random::<f64>() * 2.0))
            .collect();
        let radius = 0.7;
        let d = hops(&positions, radius);
        let chosen = select(&positions, &[false; 60], radius, 8, &mut rng);
        assert_eq!(chosen.len(), 8);
        for k in 1..chosen.len() {
            let comp_of = |i: usize| (0..60).filter(|&j| d[i][j] != UNREACHED).min();
            let c = comp_of(chosen[k]);
            let prev: Vec<usize> = chosen[..k]
                .iter()
                .copied()
                .filter(|&l| comp_of(l) == c)
                .collect();
            if prev.is_empty() {
                continue;
            }
            let to_prev = |i: usize| prev.iter().map(|&l| d[i][l]).min().unwrap_or(UNREACHED);
            let best = (0..60)
                .filter(|&i| comp_of(i) == c && !chosen[..k].contains(&i))
                .map(to_prev)
                .max();
            assert_eq!(Some(to_prev(chosen[k])), best, "pick {k} is not MaxMin");
        }
    }

    #[test]
    fn components_get_landmarks_in_proportion_to_their_size() {
        // Two far-apart clusters of 30 and 10 agents: over many draws of one landmark,
        // the big cluster is picked about 75 % of the time.
        let mut positions = Vec::new();
        for i in 0..30 {
            positions.push((0.01 * i as f64, 0.0));
        }
        for i in 0..10 {
            positions.push((10.0 + 0.01 * i as f64, 0.0));
        }
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let trials = 4000;
        let big = (0..trials)
            .filter(|_| select(&positions, &[false; 40], 0.1, 1, &mut rng)[0] < 30)
            .count();
        let share = big as f64 / trials as f64;
        assert!((share - 0.75).abs() < 0.03, "share {share}");
    }

    #[test]
    fn every_candidate_can_become_a_landmark() {
        let positions = [(0.0, 0.0), (5.0, 0.0), (5.5, 0.0)];
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let mut chosen = select(&positions, &[false, true, false], 1.0, 5, &mut rng);
        chosen.sort_unstable();
        assert_eq!(chosen, vec![0, 2]);
    }
}
