//! The encounter graph and its shortest-path metric (paper §"Geometric Reconstruction",
//! eq. for w_ij and the static-agent rule).
//!
//! The paper's graph has one vertex per encounter E_i and, for every pair sharing an agent,
//! an edge of weight `w_ij = inf |t1 − t2|` over their time intervals, set to `0` when the
//! shared agent `s` was static during an interval T^k(s) that meets both T(E_i) and T(E_j).
//! (The paper writes the condition as T(E_i) ∩ T(E_j) ∩ T^k(s) ≠ ∅, one instant common to
//! all three; read literally it changes nothing, since two overlapping encounters already
//! weigh 0. Its intent, an agent standing still between two encounters keeps them at one
//! place, is what "meets both" builds: E_i = [0, 1] and E_j = [5, 6] of an agent static
//! through [0, 10] weigh 0 here and 4 by the literal formula. Under `Bridging::Paper` the
//! static intervals that bridge are the landmarks'; random stops (`pause`) do not, as
//! [`super::local`] passes them.)
//! Built literally that is a clique per agent: O(E²) edges.
//!
//! # The sparse graph, and why it has the same shortest paths
//!
//! Fix one agent and its encounters I_1, …, I_m sorted by start time. Let M_{k−1} be the
//! encounter among I_1..I_{k−1} with the latest end. We join I_k to M_{k−1} only, with weight
//! `max(0, s_k − e(M_{k−1}))`: a forest with m − 1 edges per agent.
//!
//! *Claim.* For intervals on a line with clique weights `gap(I, J)`, the shortest-path
//! distance between I and J is the total *uncovered* time between them: the length of the
//! part of the line between the two intervals that no interval of this agent covers.
//! - Lower bound: a hop from I to J costs their whole gap, which contains every uncovered
//!   point between them. A path from I to J must get past every uncovered point between
//!   them, and only a hop whose gap contains the point gets past it; together the hops'
//!   gaps cover the uncovered time, so the path costs at least that much.
//! - Upper bound: walking from I to J through the intervals in start order, consecutive
//!   overlapping intervals cost 0 and each crossing of an uncovered gap costs that gap.
//!
//! In the forest, an edge I_k → M_{k−1} has positive weight exactly when an uncovered gap
//! `(e(M_{k−1}), s_k)` precedes I_k, and it charges exactly that gap; every maximal busy
//! block of the time line is a zero-weight subtree and consecutive blocks are joined by one
//! edge weighted by the gap between them. The tree path between I and J therefore crosses
//! exactly the gaps between their blocks: the uncovered time. ∎ The test
//! `sparse_equals_clique` checks this against the literal clique on random logs.
//!
//! The static rule adds, for each static interval V of agent s, a virtual vertex joined
//! with weight 0 to every encounter of s whose interval meets V. Zero-weight stars and
//! zero-weight cliques have the same shortest paths, so the union with the forest gives the
//! paper's metric exactly, with O(E + Σ|encounters meeting V|) = O(E) edges.
//!
//! In [`Bridging::StaticTimeFree`] the static interval V also joins the agent's time line
//! as an interval of its own: time spent static costs nothing, so an encounter shortly
//! after a pause is close to the encounters during it (the agent had not moved). This is a
//! tighter upper bound on travel time than the paper's rule; it is one of the improvements
//! measured by `swarmmap eval`.
//!
//! # Agent switches
//!
//! A path of the paper's graph walks along one agent's time line and, at an encounter,
//! may switch to the other agent's line for free. Each switch moves the path's position by
//! up to r_d (the two agents were within r_d, not at one point), so a chain of quick
//! contacts crosses space at no cost in time: in a dense swarm shortest paths pick chains
//! whose offsets happen to line up, and the metric falls far below travel time
//! (docs/accuracy.md, step 13: at 200 agents, median metric × v ÷ true distance 0.41–0.58
//! between landmark sites). With a switch cost σ_s
//! ([`EncounterGraph::build_switching`]) each encounter becomes two halves, one on each
//! agent's line, joined by an edge of weight σ_s; the lines and static stars are built on
//! the halves exactly as above (the claim is per agent line, so the sparse forest still
//! has the clique's shortest paths; `sparse_equals_clique_with_switches` checks it), and an
//! encounter's distance to another is the smaller over their halves. Encounters sharing an
//! agent keep the paper's weight; every change of agent costs σ_s. With σ_s = r_d / v,
//! v × metric bounds the distance between the agents' positions from above: every second
//! of a line is at most v of travel and every switch at most r_d. σ_s = 0 is the paper's
//! graph, built without halves.
//!
//! # Encounter middles
//!
//! The paper's weight, the gap between two intervals, is the time between the end of one
//! encounter and the start of the next: the agent has already walked up to r_d past the
//! first partner and starts the second up to r_d before reaching it, so the gap falls short
//! of the walk between the two moments of closest approach by up to 2 r_d / v. With
//! `midpoints` ([`EncounterGraph::build_timed`]) an encounter stands on its agents' time
//! lines at the middle of its interval (for a straight pass, the moment of closest
//! approach), and two encounters of one agent weigh |m₁ − m₂|. The sparse argument is
//! unchanged: sorted by middle, consecutive gaps add up to the clique's weight
//! (`sparse_equals_clique_with_midpoints`). Static stars still join the encounters whose
//! intervals meet the static interval. docs/accuracy.md, step 25, measured the weight on
//! landmark sites (least middle-to-middle time between sites under 0.5 m apart: −0.03 m
//! median error, the interval gap −0.18 m).
//!
//! # Zero-weight groups
//!
//! Vertices joined by zero-weight edges (a static star and the encounters in it, a busy
//! block of one agent's time line under the paper's weight) are at distance 0 from each
//! other, so every shortest-path distance is the same for all of them. The graph is
//! stored with each such group merged into one node, the zero-weight edges gone and the
//! edges inside a group dropped. Nothing changes, bit for bit: Dijkstra's distance of a
//! vertex is the least, over paths, of the weights added in path order, `d + 0.0 = d`
//! exactly, and an edge inside a group only offers `d + w ≥ d` to a vertex already at
//! `d`; rounding is monotone, so the least sum over the merged graph's paths is the same
//! number (`merging_zero_weight_groups_keeps_every_distance_bit_for_bit` checks it against
//! Dijkstra on the unmerged graph). In scenario 2's third window (seed 1) the landmarks'
//! stars take 36 012 vertices down to 28 668 nodes; docs/speed.md has the timings.

use crate::log::{AgentId, Encounter, StaticInterval};
use std::collections::HashMap;

/// How static intervals bridge time in the metric.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Bridging {
    /// The paper's rule: two encounters of `s` both meeting one static interval are at 0.
    Paper,
    /// The paper's rule, and static time itself is free along the agent's time line.
    StaticTimeFree,
}

/// A weighted undirected graph in compressed sparse row form, built on the vertices
/// `0..encounters` (encounters in the order given), with a switch cost
/// `encounters..2 · encounters` (their second halves: agent `b`'s side; vertex `i` is then
/// agent `a`'s side), then virtual static-interval vertices; stored with every set of
/// vertices joined by zero-weight edges merged into one node (module docs, "Zero-weight
/// groups").
#[derive(Debug, Clone)]
pub struct EncounterGraph {
    encounters: usize,
    /// Whether every encounter is split into two halves joined by the switch cost.
    halves: bool,
    /// The node of each encounter vertex (`encounters` or `2 · encounters` of them).
    node_of: Vec<u32>,
    /// The encounters with a vertex in each node, ascending: node `u` holds
    /// `members[member_offsets[u]..member_offsets[u + 1]]`.
    member_offsets: Vec<usize>,
    members: Vec<u32>,
    offsets: Vec<usize>,
    targets: Vec<u32>,
    weights: Vec<f64>,
}

/// An interval on one agent's time line: an encounter vertex or a static vertex.
#[derive(Clone, Copy)]
struct Item {
    start: f64,
    end: f64,
    vertex: u32,
    /// Whether this item takes part in the time-line forest.
    on_line: bool,
}

impl EncounterGraph {
    /// Builds the sparse graph of `encounters` with the static intervals `statics`
    /// (those that meet no encounter are ignored).
    pub fn build(encounters: &[Encounter], statics: &[StaticInterval], bridging: Bridging) -> Self {
        Self::build_switching(encounters, statics, bridging, 0.0)
    }

    /// [`EncounterGraph::build`] with a cost of `switch` seconds for every change of agent
    /// along a path (module docs, "Agent switches"); `0` gives the paper's graph exactly.
    /// A negative or non-finite `switch` is treated as `0`.
    pub fn build_switching(
        encounters: &[Encounter],
        statics: &[StaticInterval],
        bridging: Bridging,
        switch: f64,
    ) -> Self {
        Self::build_timed(encounters, statics, bridging, switch, false)
    }

    /// [`EncounterGraph::build_switching`] that, with `midpoints`, weighs two encounters
    /// along an agent's time line by the time between their middles instead of the gap
    /// between their intervals (module docs, "Encounter middles"). Static intervals bridge
    /// as before: an encounter belongs to a static star when its *interval* meets it.
    pub fn build_timed(
        encounters: &[Encounter],
        statics: &[StaticInterval],
        bridging: Bridging,
        switch: f64,
        midpoints: bool,
    ) -> Self {
        let (halves, vertices, edges) =
            Self::timed_edges(encounters, statics, bridging, switch, midpoints);
        Self::from_edges(encounters.len(), halves, vertices, &edges)
    }

    /// The vertices and edges of [`Self::build_timed`]'s graph before zero-weight groups are
    /// merged: whether encounters are split into halves, the number of vertices, and the
    /// edges `(u, v, weight)`.
    fn timed_edges(
        encounters: &[Encounter],
        statics: &[StaticInterval],
        bridging: Bridging,
        switch: f64,
        midpoints: bool,
    ) -> (bool, usize, Vec<(u32, u32, f64)>) {
        let n = encounters.len();
        let halves = switch.is_finite() && switch > 0.0;
        let mut lines: HashMap<AgentId, Vec<Item>> = HashMap::new();
        for (i, e) in encounters.iter().enumerate() {
            for (side, agent) in [e.a, e.b].into_iter().enumerate() {
                let vertex = if halves && side == 1 { n + i } else { i };
                lines.entry(agent).or_default().push(Item {
                    start: e.start,
                    end: e.end,
                    vertex: vertex as u32,
                    on_line: true,
                });
            }
        }
        let mut edges: Vec<(u32, u32, f64)> = Vec::with_capacity(3 * n);
        let encounter_vertices = if halves { 2 * n } else { n };
        if halves {
            edges.extend((0..n).map(|i| (i as u32, (n + i) as u32, switch)));
        }
        let mut next_vertex = encounter_vertices as u32;
        // Static intervals sorted by agent then start, so vertex numbering is deterministic.
        let mut statics: Vec<&StaticInterval> = statics.iter().collect();
        statics.sort_by(|x, y| x.agent.cmp(&y.agent).then(x.start.total_cmp(&y.start)));
        for s in statics {
            let Some(line) = lines.get_mut(&s.agent) else {
                continue;
            };
            let members: Vec<u32> = line
                .iter()
                .filter(|it| it.on_line && (it.vertex as usize) < encounter_vertices)
                .filter(|it| it.start <= s.end && s.start <= it.end)
                .map(|it| it.vertex)
                .collect();
            let free_time = bridging == Bridging::StaticTimeFree;
            if members.is_empty() && !free_time {
                continue;
            }
            let v = next_vertex;
            next_vertex += 1;
            edges.extend(members.iter().map(|&m| (v, m, 0.0)));
            line.push(Item {
                start: s.start,
                end: s.end,
                vertex: v,
                on_line: free_time,
            });
        }
        let mut agents: Vec<_> = lines.into_iter().collect();
        agents.sort_by_key(|(a, _)| *a);
        for (_, mut line) in agents {
            line.retain(|it| it.on_line);
            if midpoints {
                for it in line
                    .iter_mut()
                    .filter(|it| (it.vertex as usize) < encounter_vertices)
                {
                    let mid = 0.5 * (it.start + it.end);
                    it.start = mid;
                    it.end = mid;
                }
            }
            line.sort_by(|x, y| x.start.total_cmp(&y.start).then(x.vertex.cmp(&y.vertex)));
            let mut latest: Option<Item> = None;
            for it in line {
                if let Some(m) = latest {
                    edges.push((it.vertex, m.vertex, (it.start - m.end).max(0.0)));
                    if it.end > m.end {
                        latest = Some(it);
                    }
                } else {
                    latest = Some(it);
                }
            }
        }
        (halves, next_vertex as usize, edges)
    }

    fn from_edges(
        encounters: usize,
        halves: bool,
        vertices: usize,
        edges: &[(u32, u32, f64)],
    ) -> Self {
        // Merge the vertices joined by zero-weight edges (union-find with path halving);
        // nodes are numbered in the order of their first vertex, so the layout follows the
        // vertices' and is deterministic.
        let mut parent: Vec<u32> = (0..vertices as u32).collect();
        let find = |parent: &mut [u32], mut x: u32| {
            while parent[x as usize] != x {
                parent[x as usize] = parent[parent[x as usize] as usize];
                x = parent[x as usize];
            }
            x
        };
        for &(a, b, w) in edges {
            if w == 0.0 {
                let (ra, rb) = (find(&mut parent, a), find(&mut parent, b));
                if ra != rb {
                    parent[ra.max(rb) as usize] = ra.min(rb);
                }
            }
        }
        let mut node = vec![u32::MAX; vertices];
        let mut nodes = 0u32;
        for v in 0..vertices as u32 {
            let r = find(&mut parent, v);
            if node[r as usize] == u32::MAX {
                node[r as usize] = nodes;
                nodes += 1;
            }
            node[v as usize] = node[r as usize];
        }
        let nodes = nodes as usize;
        // The remaining edges between distinct nodes, in compressed sparse row form.
        let kept = || {
            edges.iter().filter_map(|&(a, b, w)| {
                let (x, y) = (node[a as usize], node[b as usize]);
                (w != 0.0 && x != y).then_some((x, y, w))
            })
        };
        let (offsets, adjacent) = compressed_rows(nodes, || {
            kept().flat_map(|(x, y, w)| [(x, (y, w)), (y, (x, w))])
        });
        let (targets, weights) = adjacent.into_iter().unzip();
        let encounter_vertices = if halves { 2 * encounters } else { encounters };
        let node_of = node[..encounter_vertices].to_vec();
        // Each node's encounters, ascending, each once (an encounter's two halves may share
        // a node).
        let (member_offsets, members) = compressed_rows(nodes, || {
            (0..encounters).flat_map(|i| {
                let first = node_of[i];
                let second = halves.then(|| node_of[encounters + i]);
                let second = second.filter(|&s| s != first);
                std::iter::once(first)
                    .chain(second)
                    .map(move |u| (u, i as u32))
            })
        });
        Self {
            encounters,
            halves,
            node_of,
            member_offsets,
            members,
            offsets,
            targets,
            weights,
        }
    }

    /// Number of encounter vertices.
    pub fn encounters(&self) -> usize {
        self.encounters
    }

    /// Number of nodes: the vertices (encounter halves and virtual static vertices
    /// included) once those joined by zero-weight edges are merged.
    pub fn vertices(&self) -> usize {
        self.offsets.len() - 1
    }

    /// Number of undirected edges between distinct nodes (zero-weight edges merged away).
    pub fn edges(&self) -> usize {
        self.targets.len() / 2
    }

    /// Shortest-path distances (seconds) from encounter `source` to every encounter
    /// (`f64::INFINITY` where unreachable). Dijkstra with a monotone radix heap
    /// (`RadixHeap`): O(E + V · 16) rather than a binary heap's O((V + E) log V), and
    /// cache-friendly, which keeps the cost per encounter flat as windows grow. The result
    /// does not depend on the order in which equal keys pop (each distance is the minimum
    /// over its neighbours' final distances), so it is deterministic.
    pub fn distances_from(&self, source: usize) -> Vec<f64> {
        let dist = self.dijkstra(source, |_, _| true);
        let n = self.encounters;
        if self.halves {
            let (a, b) = self.node_of.split_at(n);
            a.iter()
                .zip(b)
                .map(|(&x, &y)| dist[x as usize].min(dist[y as usize]))
                .collect()
        } else {
            self.node_of.iter().map(|&x| dist[x as usize]).collect()
        }
    }

    /// Dijkstra from encounter `source` (both halves): calls `settled(u, d)` as each node
    /// `u` pops at its final distance `d`, stops as soon as that returns `false`, and returns
    /// the distances of every node (final for those popped).
    fn dijkstra(&self, source: usize, mut settled: impl FnMut(usize, f64) -> bool) -> Vec<f64> {
        let mut dist = vec![f64::INFINITY; self.vertices()];
        let mut heap = RadixHeap::new();
        let n = self.encounters;
        // An encounter is both of its halves: either agent's side can start a path.
        let sources = [Some(source), self.halves.then_some(n + source)];
        for v in sources.into_iter().flatten() {
            let u = self.node_of[v] as usize;
            if dist[u] == 0.0 {
                continue;
            }
            dist[u] = 0.0;
            // Non-negative f64 bit patterns order like the numbers, so u64 keys are exact.
            heap.push(0f64.to_bits(), u as u32);
        }
        while let Some((bits, u)) = heap.pop() {
            let d = f64::from_bits(bits);
            let u = u as usize;
            if d > dist[u] {
                continue;
            }
            if !settled(u, d) {
                break;
            }
            for k in self.offsets[u]..self.offsets[u + 1] {
                let v = self.targets[k] as usize;
                let nd = d + self.weights[k];
                if nd < dist[v] {
                    dist[v] = nd;
                    heap.push(nd.to_bits(), v as u32);
                }
            }
        }
        dist
    }

    /// Dijkstra from encounter `source` that calls `visit(j, d)` once per reached encounter
    /// `j`, in order of its distance `d` (the same distance as [`Self::distances_from`]'s:
    /// an encounter's distance is final when the first of its vertices pops), and stops
    /// as soon as `visit` returns `false`.
    fn settle_from(&self, source: usize, mut visit: impl FnMut(usize, f64) -> bool) {
        let mut reached = vec![false; self.encounters];
        self.dijkstra(source, |u, d| {
            let held = &self.members[self.member_offsets[u]..self.member_offsets[u + 1]];
            for &encounter in held {
                let encounter = encounter as usize;
                if reached[encounter] {
                    continue;
                }
                reached[encounter] = true;
                if !visit(encounter, d) {
                    return false;
                }
            }
            true
        });
    }

    /// Shortest-path distances from encounter `source` to each of `targets` (encounter
    /// indices), as [`Self::distances_from`] gives them, stopping once every target is
    /// reached: a stitching cloud's points lie close together in a large graph.
    pub fn distances_to(&self, source: usize, targets: &[usize]) -> Vec<f64> {
        // The first place of each target in `targets` (a dense array: this is looked up for
        // every encounter the run settles).
        let mut first = vec![u32::MAX; self.encounters];
        let mut left = 0usize;
        for (k, &t) in targets.iter().enumerate() {
            if first[t] == u32::MAX {
                first[t] = k as u32;
                left += 1;
            }
        }
        let mut out = vec![f64::INFINITY; targets.len()];
        if left > 0 {
            self.settle_from(source, |j, d| {
                if first[j] != u32::MAX {
                    out[first[j] as usize] = d;
                    left -= 1;
                }
                left > 0
            });
        }
        for (k, &t) in targets.iter().enumerate() {
            out[k] = out[first[t] as usize];
        }
        out
    }

    /// The `k` encounters nearest to `source` at a positive finite distance, nearest
    /// first, ties by index: the first `k` of all encounters sorted by
    /// ([`Self::distances_from`], index), without running Dijkstra over the whole graph.
    pub fn nearest(&self, source: usize, k: usize) -> Vec<usize> {
        let mut found: Vec<(f64, usize)> = Vec::new();
        if k == 0 {
            return Vec::new();
        }
        self.settle_from(source, |j, d| {
            if d <= 0.0 {
                return true;
            }
            // After k, only ties with the k-th distance can still be among the first k.
            if found.len() >= k && d > found[k - 1].0 {
                return false;
            }
            found.push((d, j));
            true
        });
        found.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
        found.truncate(k);
        found.into_iter().map(|(_, j)| j).collect()
    }

    /// Connected components of the encounter vertices: a label per encounter, labels
    /// numbered by first appearance.
    pub fn components(&self) -> Vec<usize> {
        let nv = self.vertices();
        let mut label = vec![usize::MAX; nv];
        let mut next = 0;
        let mut stack = Vec::new();
        for s in 0..nv {
            if label[s] != usize::MAX {
                continue;
            }
            label[s] = next;
            stack.push(s);
            while let Some(u) = stack.pop() {
                for k in self.offsets[u]..self.offsets[u + 1] {
                    let v = self.targets[k] as usize;
                    if label[v] == usize::MAX {
                        label[v] = next;
                        stack.push(v);
                    }
                }
            }
            next += 1;
        }
        // Renumber by first appearance among encounter vertices only.
        let mut map = HashMap::new();
        self.node_of[..self.encounters]
            .iter()
            .map(|&u| &label[u as usize])
            .map(|l| {
                let k = map.len();
                *map.entry(*l).or_insert(k)
            })
            .collect()
    }
}

/// Compressed sparse rows: `entries` (called twice, to count and then to fill) yields
/// `(row, value)` pairs; returns each row's start in the values (`rows + 1` offsets) and the
/// values, each row's in the order given.
fn compressed_rows<T: Copy + Default, I: Iterator<Item = (u32, T)>>(
    rows: usize,
    entries: impl Fn() -> I,
) -> (Vec<usize>, Vec<T>) {
    let mut offsets = vec![0usize; rows + 1];
    for (row, _) in entries() {
        offsets[row as usize + 1] += 1;
    }
    for i in 0..rows {
        offsets[i + 1] += offsets[i];
    }
    let mut fill = offsets.clone();
    let mut values = vec![T::default(); offsets[rows]];
    for (row, value) in entries() {
        values[fill[row as usize]] = value;
        fill[row as usize] += 1;
    }
    (offsets, values)
}

/// A monotone priority queue of `(key, vertex)` (Ahuja, Mehlhorn, Orlin & Tarjan 1990):
/// keys pushed are never below the last key popped, as in Dijkstra with non-negative
/// weights. The radix is 16: level 0 holds the keys equal to the last minimum; a key whose
/// highest hexadecimal digit differing from it is digit `h` lies on level `h + 1`, in the
/// bin of its own digit there. Every key of a lower level, or of a lower digit on the same
/// level, is smaller, so the first non-empty bin (found from two bit masks) holds the
/// minimum. A push is an append; a pop from an empty level 0 takes the first non-empty
/// bin, makes its minimum the new last key and spreads its entries over lower levels.
/// Each entry moves down at most 16 times (a radix of 2 has 64 levels and a scan of 65
/// bins per refill: on scenario 2's last window, 110 000 moves per run instead of 182 000;
/// docs/speed.md, "A radix-16 heap").
struct RadixHeap {
    last: u64,
    /// Bit `l` set when a bin of level `l` (1 + the hexadecimal digit where keys first
    /// differ from `last`; level 0: equal to `last`) holds an entry.
    levels: u32,
    /// Bit `d` of `digits[l]` set when bin (`l`, `d`) holds an entry (`digits[0]` is kept in
    /// step but never read: level 0 has the one bin of keys equal to `last`).
    digits: [u16; LEVELS],
    bins: Vec<Vec<(u64, u32)>>,
}

/// Levels of [`RadixHeap`]: equal to `last`, or first differing at one of 16 hex digits.
const LEVELS: usize = 17;

impl RadixHeap {
    fn new() -> Self {
        Self {
            last: 0,
            levels: 0,
            digits: [0; LEVELS],
            bins: vec![Vec::new(); LEVELS * 16],
        }
    }

    /// Level and digit of `key` relative to `last`.
    #[inline]
    fn place(&self, key: u64) -> (usize, usize) {
        let x = key ^ self.last;
        if x == 0 {
            return (0, 0);
        }
        let h = (63 - x.leading_zeros() as usize) / 4;
        (h + 1, ((key >> (4 * h)) & 15) as usize)
    }

    #[inline]
    fn push(&mut self, key: u64, v: u32) {
        debug_assert!(key >= self.last, "radix heap keys must be monotone");
        let (l, d) = self.place(key);
        self.bins[l * 16 + d].push((key, v));
        self.levels |= 1 << l;
        self.digits[l] |= 1 << d;
    }

    fn pop(&mut self) -> Option<(u64, u32)> {
        if self.levels & 1 == 0 {
            if self.levels == 0 {
                return None;
            }
            let l = self.levels.trailing_zeros() as usize;
            let d = self.digits[l].trailing_zeros() as usize;
            let i = l * 16 + d;
            let mut bin = std::mem::take(&mut self.bins[i]);
            self.digits[l] &= !(1 << d);
            if self.digits[l] == 0 {
                self.levels &= !(1 << l);
            }
            self.last = bin.iter().map(|e| e.0).min()?;
            for &(key, v) in &bin {
                self.push(key, v);
            }
            // Keep the emptied buffer's capacity for the next time this bin fills.
            bin.clear();
            if self.bins[i].is_empty() {
                self.bins[i] = bin;
            }
        }
        let out = self.bins[0].pop();
        if self.bins[0].is_empty() {
            self.levels &= !1;
            self.digits[0] = 0;
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::log::StaticReason;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// The radix heap pops exactly what a sorted multiset would, under monotone use:
    /// interleaved pushes (never below the last pop, ties included) and pops.
    #[test]
    fn radix_heap_pops_in_key_order() {
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let mut heap = RadixHeap::new();
        let mut oracle: Vec<(u64, u32)> = Vec::new();
        let mut last = 0f64;
        for step in 0..20_000u32 {
            if rng.random_range(0..3) > 0 || oracle.is_empty() {
                // Ties with the last key are frequent, as in Dijkstra's zero-weight edges.
                let key = if rng.random_range(0..4) == 0 {
                    last
                } else {
                    last + rng.random_range(0.0..100.0)
                };
                heap.push(key.to_bits(), step);
                oracle.push((key.to_bits(), step));
            } else {
                let (k, _) = heap.pop().unwrap();
                let min = oracle.iter().map(|e| e.0).min().unwrap();
                assert_eq!(k, min);
                let at = oracle.iter().position(|e| e.0 == k).unwrap();
                oracle.swap_remove(at);
                last = f64::from_bits(k);
            }
        }
        while let Some((k, _)) = heap.pop() {
            assert_eq!(k, oracle.iter().map(|e| e.0).min().unwrap());
            let at = oracle.iter().position(|e| e.0 == k).unwrap();
            oracle.swap_remove(at);
        }
        assert!(oracle.is_empty());
    }

    /// The same on raw keys whose gaps span every hexadecimal digit, up to `u64::MAX`:
    /// each level and digit of the radix-16 bins, and ties, are exercised.
    #[test]
    fn radix_heap_pops_in_key_order_on_every_level() {
        let mut rng = ChaCha8Rng::seed_from_u64(12);
        let mut heap = RadixHeap::new();
        let mut oracle: std::collections::BinaryHeap<std::cmp::Reverse<u64>> =
            std::collections::BinaryHeap::new();
        let mut last = 0u64;
        for step in 0..50_000u32 {
            if rng.random_range(0..3) > 0 || oracle.is_empty() {
                let gap = rng.random::<u64>() >> rng.random_range(0..64);
                let key = if rng.random_range(0..5) == 0 {
                    last
                } else {
                    last.saturating_add(gap)
                };
                heap.push(key, step);
                oracle.push(std::cmp::Reverse(key));
            } else {
                let (k, _) = heap.pop().unwrap();
                assert_eq!(k, oracle.pop().unwrap().0);
                last = k;
            }
        }
        while let Some((k, _)) = heap.pop() {
            assert_eq!(k, oracle.pop().unwrap().0);
        }
        assert!(oracle.is_empty());
        // The top digit's bins, and the vertices carried with their keys.
        let mut heap = RadixHeap::new();
        for (key, v) in [
            (u64::MAX, 1),
            (u64::MAX - 1, 2),
            (1 << 63, 3),
            (u64::MAX, 4),
        ] {
            heap.push(key, v);
        }
        assert_eq!(heap.pop(), Some((1 << 63, 3)));
        assert_eq!(heap.pop(), Some((u64::MAX - 1, 2)));
        let mut top = [heap.pop().unwrap(), heap.pop().unwrap()];
        top.sort_unstable();
        assert_eq!(top, [(u64::MAX, 1), (u64::MAX, 4)]);
        assert_eq!(heap.pop(), None);
    }

    fn gap(x: &Encounter, y: &Encounter) -> f64 {
        (x.start.max(y.start) - x.end.min(y.end)).max(0.0)
    }

    fn meets(a: (f64, f64), b: (f64, f64)) -> bool {
        a.0 <= b.1 && b.0 <= a.1
    }

    /// The paper's clique edges: `(i, j, s, w)` for every ordered pair of encounters sharing
    /// agent `s`, with the paper's weight (0 when `s` was static during an interval meeting
    /// both).
    fn clique_edges(
        enc: &[Encounter],
        statics: &[StaticInterval],
        weight: fn(&Encounter, &Encounter) -> f64,
    ) -> Vec<(usize, usize, u32, f64)> {
        let mut edges = Vec::new();
        for (i, x) in enc.iter().enumerate() {
            for (j, y) in enc.iter().enumerate() {
                if i == j {
                    continue;
                }
                for s in [x.a, x.b] {
                    if s != y.a && s != y.b {
                        continue;
                    }
                    let bridged = statics.iter().any(|st| {
                        st.agent == s
                            && meets((x.start, x.end), (st.start, st.end))
                            && meets((y.start, y.end), (st.start, st.end))
                    });
                    edges.push((i, j, s, if bridged { 0.0 } else { weight(x, y) }));
                }
            }
        }
        edges
    }

    fn floyd_warshall(d: &mut [Vec<f64>]) {
        let n = d.len();
        for k in 0..n {
            for i in 0..n {
                for j in 0..n {
                    let via = d[i][k] + d[k][j];
                    if via < d[i][j] {
                        d[i][j] = via;
                    }
                }
            }
        }
    }

    /// The paper's graph built literally (a clique per agent), then Floyd–Warshall.
    fn clique_metric(enc: &[Encounter], statics: &[StaticInterval]) -> Vec<Vec<f64>> {
        clique_metric_by(enc, statics, gap)
    }

    /// The time between two encounters' middles.
    fn middle_gap(x: &Encounter, y: &Encounter) -> f64 {
        (0.5 * (x.start + x.end) - 0.5 * (y.start + y.end)).abs()
    }

    fn clique_metric_by(
        enc: &[Encounter],
        statics: &[StaticInterval],
        weight: fn(&Encounter, &Encounter) -> f64,
    ) -> Vec<Vec<f64>> {
        let n = enc.len();
        let mut d = vec![vec![f64::INFINITY; n]; n];
        for (i, row) in d.iter_mut().enumerate() {
            row[i] = 0.0;
        }
        for (i, j, _, w) in clique_edges(enc, statics, weight) {
            d[i][j] = d[i][j].min(w);
        }
        floyd_warshall(&mut d);
        d
    }

    fn random_log(seed: u64, n: usize, agents: u32) -> (Vec<Encounter>, Vec<StaticInterval>) {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let enc = (0..n)
            .map(|_| {
                let a = rng.random_range(0..agents);
                let mut b = rng.random_range(0..agents - 1);
                if b >= a {
                    b += 1;
                }
                let start: f64 = rng.random_range(0.0..100.0);
                // Some exact ties and zero-length intervals on purpose.
                let start = if rng.random_bool(0.2) {
                    start.round()
                } else {
                    start
                };
                let len = if rng.random_bool(0.2) {
                    0.0
                } else {
                    rng.random_range(0.0..15.0)
                };
                Encounter {
                    start,
                    end: start + len,
                    a: a.min(b),
                    b: a.max(b),
                    truth: None,
                }
            })
            .collect();
        let statics = (0..agents / 2)
            .map(|k| {
                let start: f64 = rng.random_range(0.0..90.0);
                StaticInterval {
                    agent: k * 2,
                    start,
                    end: start + rng.random_range(0.0..30.0),
                    reason: StaticReason::Landmark,
                }
            })
            .collect();
        (enc, statics)
    }

    /// The early-stopping runs give exactly (bit for bit) what the full run gives: the
    /// distances to chosen targets, and the k nearest by (distance, index), on graphs with
    /// and without switch costs and middles, under both bridgings (so with nodes that hold
    /// many encounters), zero-length encounters, exact ties and unreachable parts.
    #[test]
    fn early_stopping_runs_match_the_full_run() {
        let graphs = [Bridging::Paper, Bridging::StaticTimeFree]
            .into_iter()
            .flat_map(|b| [(b, 0.0), (b, 1.5)])
            .flat_map(|(b, switch)| [(b, switch, false), (b, switch, true)]);
        for (bridging, switch, midpoints) in graphs {
            for seed in 0..15 {
                let (enc, statics) = random_log(100 + seed, 60, 8);
                let g = EncounterGraph::build_timed(&enc, &statics, bridging, switch, midpoints);
                let mut rng = ChaCha8Rng::seed_from_u64(seed);
                for source in 0..enc.len() {
                    let full = g.distances_from(source);
                    let targets: Vec<usize> = (0..rng.random_range(0..12))
                        .map(|_| rng.random_range(0..enc.len()))
                        .collect();
                    let got = g.distances_to(source, &targets);
                    for (t, d) in targets.iter().zip(&got) {
                        let case = format!("{bridging:?} {switch} {midpoints} seed {seed}");
                        assert_eq!(full[*t].to_bits(), d.to_bits(), "{case} {source}->{t}");
                    }
                    for k in [0, 1, 5, 80] {
                        let mut want: Vec<usize> = (0..enc.len())
                            .filter(|&j| full[j].is_finite() && full[j] > 0.0)
                            .collect();
                        want.sort_by(|&x, &y| full[x].total_cmp(&full[y]).then(x.cmp(&y)));
                        want.truncate(k);
                        assert_eq!(
                            g.nearest(source, k),
                            want,
                            "{bridging:?} {switch} {midpoints} seed {seed} source {source} k {k}"
                        );
                    }
                }
            }
        }
    }

    /// Asserts that the sparse graph's distances are the clique's, `label` naming the case.
    fn assert_same_metric(g: &EncounterGraph, want: &[Vec<f64>], label: &str) {
        for (i, row) in want.iter().enumerate() {
            let got = g.distances_from(i);
            for (j, w) in row.iter().enumerate() {
                assert!(
                    (got[j] - w).abs() <= 1e-9 || (got[j].is_infinite() && w.is_infinite()),
                    "{label}: d({i},{j}) sparse {} clique {}",
                    got[j],
                    w
                );
            }
        }
    }

    #[test]
    fn sparse_equals_clique() {
        for seed in 0..40 {
            let (enc, statics) = random_log(seed, 40, 6);
            let g = EncounterGraph::build(&enc, &statics, Bridging::Paper);
            let want = clique_metric(&enc, &statics);
            assert_same_metric(&g, &want, &format!("seed {seed}"));
            assert!(g.edges() <= 2 * enc.len() + enc.len() * 2);
        }
    }

    /// With encounter middles, the sparse forest still has the clique's shortest paths
    /// (module docs, "Encounter middles"): each pair of encounters sharing an agent weighs
    /// the time between their middles, or 0 through a static interval both meet.
    #[test]
    fn sparse_equals_clique_with_midpoints() {
        for seed in 0..40 {
            let (enc, statics) = random_log(seed, 40, 6);
            let g = EncounterGraph::build_timed(&enc, &statics, Bridging::Paper, 0.0, true);
            let want = clique_metric_by(&enc, &statics, middle_gap);
            assert_same_metric(&g, &want, &format!("seed {seed}, middles"));
        }
    }

    /// Two encounters of one agent, [0, 2] and [5, 9]: the paper's weight is the gap 3 s,
    /// the middles' weight 7 − 1 = 6 s.
    #[test]
    fn midpoints_weigh_the_middles() {
        let e = |start, end, a, b| Encounter {
            start,
            end,
            a,
            b,
            truth: None,
        };
        let enc = [e(0.0, 2.0, 0, 1), e(5.0, 9.0, 0, 2)];
        let paper = EncounterGraph::build_timed(&enc, &[], Bridging::Paper, 0.0, false);
        let mid = EncounterGraph::build_timed(&enc, &[], Bridging::Paper, 0.0, true);
        assert_eq!(paper.distances_from(0)[1], 3.0);
        assert_eq!(mid.distances_from(0)[1], 6.0);
    }

    /// The split graph built literally: both halves of every encounter, a clique per agent
    /// on its halves with the paper's weights, the switch edge inside each encounter; then
    /// Floyd–Warshall, and an encounter's distance the smaller over its halves.
    fn clique_metric_with_switches(
        enc: &[Encounter],
        statics: &[StaticInterval],
        switch: f64,
    ) -> Vec<Vec<f64>> {
        let n = enc.len();
        let half = |i: usize, agent: u32| if enc[i].a == agent { i } else { n + i };
        let mut d = vec![vec![f64::INFINITY; 2 * n]; 2 * n];
        for i in 0..n {
            d[i][i] = 0.0;
            d[n + i][n + i] = 0.0;
            d[i][n + i] = switch;
            d[n + i][i] = switch;
        }
        for (i, j, s, w) in clique_edges(enc, statics, gap) {
            let (u, v) = (half(i, s), half(j, s));
            d[u][v] = d[u][v].min(w);
        }
        floyd_warshall(&mut d);
        (0..n)
            .map(|i| {
                (0..n)
                    .map(|j| {
                        [d[i][j], d[i][n + j], d[n + i][j], d[n + i][n + j]]
                            .into_iter()
                            .fold(f64::INFINITY, f64::min)
                    })
                    .collect()
            })
            .collect()
    }

    #[test]
    fn sparse_equals_clique_with_switches() {
        for seed in 0..30 {
            let (enc, statics) = random_log(seed, 30, 6);
            for switch in [0.5, 3.0] {
                let g = EncounterGraph::build_switching(&enc, &statics, Bridging::Paper, switch);
                let want = clique_metric_with_switches(&enc, &statics, switch);
                assert_same_metric(&g, &want, &format!("seed {seed}, switch {switch}"));
            }
            // A zero switch cost is the paper's graph itself.
            let paper = EncounterGraph::build(&enc, &statics, Bridging::Paper);
            let zero = EncounterGraph::build_switching(&enc, &statics, Bridging::Paper, 0.0);
            assert_eq!(paper.vertices(), zero.vertices());
            for i in 0..enc.len() {
                assert_eq!(paper.distances_from(i), zero.distances_from(i));
            }
        }
    }

    /// A chain of quick contacts: agent 0 meets 1 at t = 0, 1 meets 2 at t = 0.1, 2 meets 3
    /// at t = 0.2. Free switches make the ends 0.2 s apart; the path changes agent once (1 →
    /// 2 at the middle encounter), so with σ_s = 1 s they are 1.2 s apart, while two
    /// encounters on one agent's line keep the paper's weight.
    #[test]
    fn every_change_of_agent_costs_the_switch() {
        let e = |a, b, t| Encounter {
            start: t,
            end: t,
            a,
            b,
            truth: None,
        };
        let enc = vec![e(0, 1, 0.0), e(1, 2, 0.1), e(2, 3, 0.2), e(0, 4, 5.0)];
        let free = EncounterGraph::build(&enc, &[], Bridging::Paper);
        assert!((free.distances_from(0)[2] - 0.2).abs() < 1e-12);
        let g = EncounterGraph::build_switching(&enc, &[], Bridging::Paper, 1.0);
        let d = g.distances_from(0);
        assert!((d[1] - 0.1).abs() < 1e-12, "shared agent 1: no switch");
        assert!((d[2] - 1.2).abs() < 1e-12, "one switch (1 → 2): {}", d[2]);
        assert!((d[3] - 5.0).abs() < 1e-12, "shared agent 0: no switch");
        assert_eq!(g.distances_from(2)[0], d[2], "symmetric");
        assert_eq!(free.components(), g.components());
    }

    #[test]
    fn static_time_is_free_only_when_asked() {
        // Agent 0 meets 1 at [0,1], is static over [1,50], meets 2 at [60,61].
        let enc = vec![
            Encounter {
                start: 0.0,
                end: 1.0,
                a: 0,
                b: 1,
                truth: None,
            },
            Encounter {
                start: 60.0,
                end: 61.0,
                a: 0,
                b: 2,
                truth: None,
            },
        ];
        let st = vec![StaticInterval {
            agent: 0,
            start: 1.0,
            end: 50.0,
            reason: StaticReason::Pause,
        }];
        let paper = EncounterGraph::build(&enc, &st, Bridging::Paper);
        assert_eq!(paper.distances_from(0)[1], 59.0);
        let free = EncounterGraph::build(&enc, &st, Bridging::StaticTimeFree);
        assert_eq!(free.distances_from(0)[1], 10.0);
    }

    /// Dijkstra on the graph as built, before zero-weight groups are merged (a binary heap
    /// over every vertex): each encounter's distance, the smaller over its halves.
    fn unmerged_distances(
        n: usize,
        (halves, vertices, edges): &(bool, usize, Vec<(u32, u32, f64)>),
        source: usize,
    ) -> Vec<f64> {
        use std::cmp::Reverse;
        let mut adjacency = vec![Vec::new(); *vertices];
        for &(a, b, w) in edges {
            adjacency[a as usize].push((b as usize, w));
            adjacency[b as usize].push((a as usize, w));
        }
        let mut dist = vec![f64::INFINITY; *vertices];
        let mut heap = std::collections::BinaryHeap::new();
        for v in [Some(source), halves.then_some(n + source)]
            .into_iter()
            .flatten()
        {
            dist[v] = 0.0;
            heap.push(Reverse((0f64.to_bits(), v)));
        }
        while let Some(Reverse((bits, u))) = heap.pop() {
            let d = f64::from_bits(bits);
            if d > dist[u] {
                continue;
            }
            for &(v, w) in &adjacency[u] {
                if d + w < dist[v] {
                    dist[v] = d + w;
                    heap.push(Reverse(((d + w).to_bits(), v)));
                }
            }
        }
        (0..n)
            .map(|i| match halves {
                true => dist[i].min(dist[n + i]),
                false => dist[i],
            })
            .collect()
    }

    /// Merging the vertices joined by zero-weight edges changes no distance, bit for bit,
    /// and no component, on logs full of zero-weight edges: static stars, overlapping
    /// intervals under the paper's weight, zero-length and tied encounters, static time
    /// made free, with and without switch costs and middles; and, with every time scaled
    /// by 10⁻³⁰⁰, on weights that are tiny but not zero, which must not be merged.
    #[test]
    fn merging_zero_weight_groups_keeps_every_distance_bit_for_bit() {
        let mut merged_some = false;
        for (seed, scale) in (0..40).flat_map(|seed| [(seed, 1.0), (seed, 1e-300)]) {
            let (mut enc, mut statics) = random_log(300 + seed, 50, 7);
            for e in &mut enc {
                (e.start, e.end) = (e.start * scale, e.end * scale);
            }
            for s in &mut statics {
                (s.start, s.end) = (s.start * scale, s.end * scale);
            }
            for bridging in [Bridging::Paper, Bridging::StaticTimeFree] {
                for switch in [0.0, 1.5] {
                    for midpoints in [false, true] {
                        let raw = EncounterGraph::timed_edges(
                            &enc, &statics, bridging, switch, midpoints,
                        );
                        let g = EncounterGraph::build_timed(
                            &enc, &statics, bridging, switch, midpoints,
                        );
                        merged_some |= g.vertices() < raw.1;
                        let label =
                            format!("seed {seed} × {scale} {bridging:?} {switch} {midpoints}");
                        let labels = g.components();
                        for source in 0..enc.len() {
                            let want = unmerged_distances(enc.len(), &raw, source);
                            let got = g.distances_from(source);
                            let bits =
                                |d: &[f64]| d.iter().map(|d| d.to_bits()).collect::<Vec<_>>();
                            assert_eq!(bits(&got), bits(&want), "{label}, source {source}");
                            // Two encounters share a component exactly when one reaches the
                            // other.
                            for (j, d) in want.iter().enumerate() {
                                let same = labels[j] == labels[source];
                                assert_eq!(same, d.is_finite(), "{label}, {source} and {j}");
                            }
                        }
                    }
                }
            }
        }
        assert!(
            merged_some,
            "the logs must have zero-weight groups to merge"
        );
    }

    #[test]
    fn components_follow_shared_agents() {
        let e = |a, b, t| Encounter {
            start: t,
            end: t,
            a,
            b,
            truth: None,
        };
        let enc = vec![e(0, 1, 0.0), e(2, 3, 1.0), e(1, 4, 2.0), e(3, 5, 3.0)];
        let g = EncounterGraph::build(&enc, &[], Bridging::Paper);
        assert_eq!(g.components(), vec![0, 1, 0, 1]);
        assert_eq!(g.distances_from(0)[2], 2.0);
        assert!(g.distances_from(0)[1].is_infinite());
    }
}
