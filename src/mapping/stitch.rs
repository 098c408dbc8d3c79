//! Global mapping: stitching consecutive local maps into a global topological map (paper
//! §"Global Mapping").
//!
//! # Connections between M_i and M_{i+1}
//!
//! S_{i,i+1} is the set of static agents with a static interval `[t^b, t^d]` that starts
//! no later than W_{i+1} begins and ends no earlier than W_i ends: they stood still through
//! the whole overlap, so both local maps saw them at one place. E_S is the set of their
//! encounters while static, inside W_i ∪ W_{i+1}. All of one agent's E_S events lie at one
//! point (they are joined at zero cost), so the inter-domain point cloud is, per static
//! agent, that point together with its k nearest encounters in the encounter metric of
//! W_i ∪ W_{i+1} (the correspondence metric). Single linkage of the cloud, cut at c
//! (default 50 s, the paper's value), gives the clusters; each cluster is one connection.
//! The components of M_i and M_{i+1} that a cluster's events belong to are the components
//! the connection joins.
//!
//! # The global map and its Betti numbers
//!
//! The global map is a multigraph G whose nodes are the components of all local maps
//! (each carrying its robust holes) and whose edges are the connections. Then
//! - β0 = the number of connected components of G: local components glued by
//!   connections are one region;
//! - β1 = (E − V + β0) + (the distinct local holes). The first term is the cycle rank of
//!   G: two connections between the same pair of regions, or a ring of regions around a
//!   long obstacle (scenario 2: one region splits into two branches around it and the
//!   branches rejoin), enclose an obstacle that no single window saw whole. A hole that a
//!   single window saw whole is a local hole; if it lies in the overlap of W_i and W_{i+1}
//!   both maps report it, and the pair is counted once. Two local holes of consecutive maps
//!   are the same hole when the central 80 % of their cycles' event times (from the 10th
//!   to the 90th percentile of the start times of the cycle's events) overlap: a cycle's
//!   events happened around the hole while the leader passed it, and the leader moves
//!   monotonically, so time locates the hole along the sweep. The cycles are the tight
//!   loops round the holes ([`crate::topology::rips::tighten_cycle`]). Not the full span
//!   from the first to the last event: a few events far off in time stretch it, and the
//!   full spans of two distinct holes of consecutive maps overlapped in 8 of the 35 such
//!   pairs in the stored evaluation and training runs (README, "Accuracy", step 10), the
//!   central 80 % in none, while both pairs that were one hole still overlap.
//!
//! Why the terms do not double count: a hole wholly inside an overlap is inside both
//! domains, so the overlap's free space around it is one corridor, one connection, and G
//! gets no cycle from it; conversely an obstacle that no window contains whole splits some
//! overlaps into several corridors and appears only as a cycle of G.

use super::encounter_graph::EncounterGraph;
use super::local::{LocalMap, LocalParams};
use super::windows::Window;
use crate::log::{AgentId, EncounterLog, StaticReason};
use crate::topology::DistanceMatrix;
use crate::topology::linkage::single_linkage;
use rayon::prelude::*;
use serde::Serialize;
use std::collections::{BTreeMap, BTreeSet, HashMap};

/// Parameters of stitching.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StitchParams {
    /// Single-linkage cut-off c in the metric's units, seconds (default: `50.0`).
    pub cutoff: f64,
    /// Neighbours k added around each static agent (default: `5`).
    pub neighbours: usize,
}

/// One inter-domain point cloud and its clustering.
#[derive(Debug, Clone, Serialize)]
pub struct Connection {
    /// 1-based indices of the two windows.
    pub between: [usize; 2],
    /// The static agents S_{i,i+1}.
    pub static_agents: Vec<AgentId>,
    /// The cloud's points as encounter indices into the log.
    pub points: Vec<usize>,
    /// Cluster label of each point.
    pub labels: Vec<usize>,
    /// The correspondence metric on the cloud (condensed upper triangle).
    #[serde(skip)]
    pub metric: Option<DistanceMatrix>,
    /// Single-linkage merge heights (ascending).
    pub heights: Vec<f64>,
    /// Number of connections (clusters).
    pub count: usize,
    /// Pairs `(component of M_i, component of M_{i+1})` joined, one per cluster that
    /// touches both maps.
    pub joins: Vec<(usize, usize)>,
}

/// The global topological map.
#[derive(Debug, Clone, Serialize)]
pub struct GlobalMap {
    /// Nodes: `(window index, component index)`.
    pub nodes: Vec<(usize, usize)>,
    /// Edges between node indices, one per join.
    pub edges: Vec<(usize, usize)>,
    /// Local holes after merging duplicates: `(window index, component, hole index)` of the
    /// hole kept.
    pub holes: Vec<(usize, usize, usize)>,
    /// Cycle rank E − V + β0 of the gluing graph.
    pub gluing_cycles: usize,
    /// Global (β0, β1).
    pub betti: [usize; 2],
}

fn component_of_events(map: &LocalMap) -> HashMap<usize, usize> {
    let mut out = HashMap::new();
    for (c, comp) in map.components.iter().enumerate() {
        for &j in &comp.events {
            out.insert(map.events[j], c);
        }
    }
    out
}

/// Builds the inter-domain cloud between two consecutive windows and clusters it.
pub fn connect(
    log: &EncounterLog,
    wa: &Window,
    wb: &Window,
    ma: &LocalMap,
    mb: &LocalMap,
    local: &LocalParams,
    p: &StitchParams,
) -> Connection {
    let union = Window {
        index: wa.index,
        start: wa.start.min(wb.start),
        end: wa.end.max(wb.end),
    };
    let events: Vec<usize> = (0..log.encounters.len())
        .filter(|&i| union.meets(log.encounters[i].start, log.encounters[i].end))
        .collect();
    let enc: Vec<_> = events.iter().map(|&i| log.encounters[i].clone()).collect();
    let statics: Vec<_> = log
        .static_intervals
        .iter()
        .filter(|s| union.meets(s.start, s.end))
        .cloned()
        .collect();
    let graph = EncounterGraph::build_timed(
        &enc,
        &statics,
        local.bridging,
        local.switch_cost,
        local.midpoints,
    );
    // S_{i,i+1}: static through the whole overlap [start of W_{i+1}, end of W_i].
    let spanning: Vec<_> = statics
        .iter()
        .filter(|s| s.reason == StaticReason::Landmark && s.start <= wb.start && s.end >= wa.end)
        .collect();
    let mut anchors: BTreeMap<AgentId, Vec<usize>> = BTreeMap::new();
    for s in &spanning {
        for (k, e) in enc.iter().enumerate() {
            if (e.a == s.agent || e.b == s.agent) && e.start <= s.end && s.start <= e.end {
                anchors.entry(s.agent).or_default().push(k);
            }
        }
    }
    // The cloud: one point per static agent (its E_S events coincide) and its k nearest
    // other encounters.
    let mut cloud: Vec<usize> = Vec::new();
    let mut seen = BTreeSet::new();
    // One shortest-path run per anchor and per cloud point, each independent: in parallel,
    // collected in order. Each stops early ([`EncounterGraph::nearest`],
    // [`EncounterGraph::distances_to`]) with the distances a full run would give.
    let anchor_list: Vec<&Vec<usize>> = anchors.values().collect();
    let nearest: Vec<Vec<usize>> = anchor_list
        .par_iter()
        .map(|ks| graph.nearest(ks[0], p.neighbours))
        .collect();
    for (ks, near) in anchor_list.iter().zip(&nearest) {
        if seen.insert(ks[0]) {
            cloud.push(ks[0]);
        }
        for &j in near {
            if seen.insert(j) {
                cloud.push(j);
            }
        }
    }
    // The metric's entry (a, b), a < b, is the run from a's distance to b: each run needs
    // only the points after its own.
    let rows: Vec<Vec<f64>> = (0..cloud.len())
        .into_par_iter()
        .map(|a| graph.distances_to(cloud[a], &cloud[a + 1..]))
        .collect();
    // Unreachable pairs are infinitely far: they never merge below any finite cut-off.
    let metric = DistanceMatrix::from_fn(cloud.len(), |a, b| {
        let d = rows[a][b - a - 1];
        if d.is_finite() { d } else { f64::MAX }
    });
    let dendrogram = single_linkage(&metric);
    let labels = dendrogram.cut(p.cutoff);
    let count = labels.iter().copied().max().map_or(0, |m| m + 1);
    // Which components each cluster touches, through all E_S events of its anchors.
    let (ca, cb) = (component_of_events(ma), component_of_events(mb));
    let mut touch: Vec<(BTreeSet<usize>, BTreeSet<usize>)> = vec![Default::default(); count];
    for (point, &label) in cloud.iter().zip(&labels) {
        let anchor_events = anchors
            .values()
            .find(|ks| ks[0] == *point)
            .cloned()
            .unwrap_or_else(|| vec![*point]);
        for k in anchor_events {
            let li = events[k];
            if let Some(&c) = ca.get(&li) {
                touch[label].0.insert(c);
            }
            if let Some(&c) = cb.get(&li) {
                touch[label].1.insert(c);
            }
        }
    }
    let joins = touch
        .iter()
        .filter_map(|(a, b)| Some((*a.first()?, *b.first()?)))
        .collect();
    Connection {
        between: [wa.index, wb.index],
        static_agents: anchors.keys().copied().collect(),
        points: cloud.iter().map(|&k| events[k]).collect(),
        labels,
        heights: dendrogram.heights(),
        metric: Some(metric),
        count,
        joins,
    }
}

/// Share of a cycle's event times cut off at each end before two holes' times are compared.
const TIME_TAIL: f64 = 0.1;

/// The `q`-quantile of sorted `v` (linear interpolation between order statistics).
fn quantile(v: &[f64], q: f64) -> f64 {
    let pos = q * (v.len() - 1) as f64;
    let (lo, hi) = (pos.floor() as usize, pos.ceil() as usize);
    v[lo] + (pos - lo as f64) * (v[hi] - v[lo])
}

/// The central `1 − 2 TIME_TAIL` of the start times of a cycle's events (each event once),
/// seconds; `None` for an empty cycle.
fn central_times(
    map: &LocalMap,
    log: &EncounterLog,
    cycle: &[(usize, usize)],
) -> Option<(f64, f64)> {
    let mut events: Vec<usize> = cycle.iter().flat_map(|&(a, b)| [a, b]).collect();
    events.sort_unstable();
    events.dedup();
    let mut times: Vec<f64> = events
        .iter()
        .map(|&j| log.encounters[map.events[j]].start)
        .collect();
    if times.is_empty() {
        return None;
    }
    times.sort_by(f64::total_cmp);
    Some((
        quantile(&times, TIME_TAIL),
        quantile(&times, 1.0 - TIME_TAIL),
    ))
}

/// Glues local maps through their connections into the global map.
pub fn global_map(maps: &[LocalMap], connections: &[Connection], log: &EncounterLog) -> GlobalMap {
    let mut nodes = Vec::new();
    let mut node_of = HashMap::new();
    for m in maps {
        for c in 0..m.components.len() {
            node_of.insert((m.index, c), nodes.len());
            nodes.push((m.index, c));
        }
    }
    let mut edges = Vec::new();
    for conn in connections {
        for &(a, b) in &conn.joins {
            if let (Some(&x), Some(&y)) = (
                node_of.get(&(conn.between[0], a)),
                node_of.get(&(conn.between[1], b)),
            ) {
                edges.push((x, y));
            }
        }
    }
    // β0 by union–find over the gluing graph.
    let mut parent: Vec<usize> = (0..nodes.len()).collect();
    fn find(p: &mut [usize], x: usize) -> usize {
        let mut r = x;
        while p[r] != r {
            r = p[r];
        }
        let mut y = x;
        while p[y] != r {
            let next = p[y];
            p[y] = r;
            y = next;
        }
        r
    }
    for &(a, b) in &edges {
        let (ra, rb) = (find(&mut parent, a), find(&mut parent, b));
        if ra != rb {
            parent[ra.max(rb)] = ra.min(rb);
        }
    }
    let b0 = (0..nodes.len())
        .filter(|&x| find(&mut parent, x) == x)
        .count();
    let gluing_cycles = (edges.len() + b0).saturating_sub(nodes.len());
    // Local holes, merging a hole of M_{i+1} with one of M_i when the central parts of
    // their cycles' event times overlap.
    let mut holes: Vec<(usize, usize, usize)> = Vec::new();
    let mut previous: Vec<(f64, f64)> = Vec::new();
    for m in maps {
        let mut current = Vec::new();
        for (c, comp) in m.components.iter().enumerate() {
            for (h, hole) in comp.holes.iter().enumerate() {
                let span = central_times(m, log, &hole.cycle);
                let duplicate = span.is_some_and(|(lo, hi)| {
                    previous.iter().any(|&(plo, phi)| lo <= phi && plo <= hi)
                });
                if let Some(s) = span {
                    current.push(s);
                }
                if !duplicate {
                    holes.push((m.index, c, h));
                }
            }
        }
        previous = current;
    }
    GlobalMap {
        betti: [b0, gluing_cycles + holes.len()],
        nodes,
        edges,
        holes,
        gluing_cycles,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::log::Encounter;
    use crate::mapping::local::{Component, Hole};

    /// A log with one encounter per entry of `times`.
    fn log(times: &[f64]) -> EncounterLog {
        EncounterLog {
            encounters: times
                .iter()
                .map(|&t| Encounter {
                    start: t,
                    end: t,
                    a: 0,
                    b: 1,
                    truth: None,
                })
                .collect(),
            static_intervals: Vec::new(),
            leader: Vec::new(),
        }
    }

    /// Window `index` whose only component has one hole, a loop through `events` (indices
    /// into the log).
    fn map_with_hole(index: usize, events: Vec<usize>) -> LocalMap {
        let n = events.len();
        let cycle = (0..n)
            .map(|k| (k.min((k + 1) % n), k.max((k + 1) % n)))
            .collect();
        LocalMap {
            index,
            start: 0.0,
            end: 0.0,
            events,
            points: vec![[0.0; 3]; n],
            noise: vec![false; n],
            components: vec![Component {
                events: (0..n).collect(),
                representatives: (0..n).collect(),
                scale: 1.0,
                diagram: Vec::new(),
                betti: [1, 1],
                holes: vec![Hole {
                    birth: 1.0,
                    death: 2.0,
                    cycle,
                    void: None,
                }],
            }],
            betti: [1, 1],
            explained: 1.0,
            rows: Vec::new(),
        }
    }

    #[test]
    fn quantiles_interpolate_between_order_statistics() {
        let v = [0.0, 10.0, 20.0, 30.0, 40.0];
        assert_eq!(quantile(&v, 0.0), 0.0);
        assert_eq!(quantile(&v, 1.0), 40.0);
        assert_eq!(quantile(&v, 0.5), 20.0);
        assert!((quantile(&v, 0.1) - 4.0).abs() < 1e-12);
        assert_eq!(quantile(&[7.0], 0.9), 7.0);
    }

    /// Two holes of consecutive windows, connected once: one hole each, M_1's loop at
    /// t = 100–190 plus one event at 1 500, M_2's at 2 000–2 090 plus one at 1 400. Their
    /// full spans overlap (1 400–1 500) only through the two stray events, so they are two
    /// holes; a loop of M_2 at 150–240 is the same hole as M_1's.
    #[test]
    fn holes_are_told_apart_by_the_central_times_of_their_cycles() {
        let mut times: Vec<f64> = (0..10).map(|k| 100.0 + 10.0 * k as f64).collect();
        times.push(1500.0); // 10
        times.extend((0..10).map(|k| 2000.0 + 10.0 * k as f64)); // 11..21
        times.push(1400.0); // 21
        times.extend((0..10).map(|k| 150.0 + 10.0 * k as f64)); // 22..32
        let log = log(&times);
        let m1 = map_with_hole(1, (0..11).collect());
        let distinct = map_with_hole(2, (11..22).collect());
        let same = map_with_hole(2, (22..32).collect());
        let join = Connection {
            between: [1, 2],
            static_agents: Vec::new(),
            points: Vec::new(),
            labels: Vec::new(),
            metric: None,
            heights: Vec::new(),
            count: 1,
            joins: vec![(0, 0)],
        };
        let g = global_map(&[m1.clone(), distinct], std::slice::from_ref(&join), &log);
        assert_eq!(g.betti, [1, 2]);
        let g = global_map(&[m1, same], std::slice::from_ref(&join), &log);
        assert_eq!(g.betti, [1, 1]);
    }
}
