//! Global mapping: stitching consecutive local maps into a global topological map (paper
//! §"Global Mapping").
//!
//! # Connections between M_i and M_{i+1}
//!
//! S_{i,i+1} is the set of static agents with a static interval `[t^b, t^d]` that starts
//! no later than W_{i+1} begins and ends no earlier than W_i ends: they stood still through
//! the whole overlap, so both local maps saw them at one place. This is the paper's prose;
//! its equation writes `t^b ≤ t_i − Δt` and `t^d ≥ t_i + Δt`, twice the half-overlap
//! `Δt / 2` by which W_{i+1} begins before and W_i ends after `t_i` (W_i = [t_{i−1} − Δt/2,
//! t_i + Δt/2]), which would ask a landmark to stand through twice the overlap. We follow
//! the prose, which matches the stated purpose. E_S is the set of their
//! encounters while static, inside W_i ∪ W_{i+1}. All of one agent's E_S events lie at one
//! point (they are joined at zero cost), so the inter-domain point cloud is, per static
//! agent, that point together with its k nearest encounters in the encounter metric of
//! W_i ∪ W_{i+1} (the correspondence metric). Single linkage of the cloud, cut at c
//! (default 50 s, the paper's value), gives the clusters; each cluster is one connection.
//! The components of M_i and M_{i+1} that a cluster's events belong to are the components
//! the connection joins; a cluster touching several components of one map glues them all
//! (its events show them to be one region, joined through the other window) while still
//! counting as one connection. A cluster none of whose events lies in a component of one of the
//! two maps (that map judged them all noise, or holds no events at all) joins nothing and
//! is not counted: a connection is between the maps, and the global map's edges are its
//! joins and also-joins (in the 151 connections of 37 bundled runs checked in the fortieth session every
//! cluster joins, so their counts are as before).
//!
//! # The global map and its Betti numbers
//!
//! The global map is a multigraph G whose nodes are the components of all local maps
//! (each carrying its robust holes) and whose edges are the connections' joins (one per
//! connection) and also-joins (a connection's cluster touching several components of one
//! map glues each of them in, as a tree: it adds no cycle of its own, though with another
//! connection between the same regions it closes one, as any second connection does). Then
//! - β0 = the number of connected components of G: local components glued by
//!   connections are one region;
//! - β1 = (E − V + β0) + (the distinct local holes). The first term is the cycle rank of
//!   G: two connections between the same pair of regions, or a ring of regions around a
//!   long obstacle (scenario 2: one region splits into two branches around it and the
//!   branches rejoin), enclose an obstacle that no single window saw whole. A hole that a
//!   single window saw whole is a local hole; if it lies in the overlap of W_i and W_{i+1}
//!   both maps report it, and the pair is counted once (which local holes count at all:
//!   the next section). Two local holes of consecutive maps
//!   are the same hole when, drawn on one plane, either one's cycle encircles the other's
//!   void (the centroid of its death triangle). The plane: each map embeds its window on
//!   its own (classical MDS fixes it only up to a similarity), but the events of the
//!   overlap W_i ∩ W_{i+1} belong to both windows, so the similarity (Procrustes,
//!   reflections allowed) that carries M_{i+1}'s positions of the shared events onto M_i's
//!   carries M_{i+1}'s cycles into M_i's plane. A hole in the overlap is then one void
//!   that both cycles go round; two distinct holes are two voids at least an obstacle
//!   spacing apart, and a tight cycle ([`crate::topology::rips::tighten_cycle`]) goes round
//!   its own void only. Two components that share fewer than three events have no common
//!   plane; their holes are compared by time instead: the same hole when the central 80 %
//!   of their cycles' event times (10th to 90th percentile of the start times) overlap,
//!   since the leader moves monotonically and a cycle's events happened while it passed
//!   the hole (docs/accuracy.md, step 10). Time alone was the rule until step 30: it
//!   depends on the sweep speed, and at half speed the cycles of one obstacle seen by
//!   two windows missed each other by seconds (scenario 3 seed 5), while on the common
//!   plane every pair that is one obstacle encircles and no pair of two does (step 30).
//!
//! # Holes two windows see, and holes one window sees alone (docs/accuracy.md, step 32)
//!
//! A window alone keeps a loop as a hole only when its persistence passes the classifier
//! ([`crate::mapping::classify`]). But an obstacle in the overlap of two domains is seen by
//! both windows, at different times and through different encounters: two observations
//! of one place. So besides its robust holes each map offers its *candidates*, loops that
//! pass a weaker test ([`crate::mapping::classify::Classifier::candidate`]), and the
//! global map links the robust holes and candidates of consecutive maps that are the same
//! place: voids within [`SAME_VOID`] σ on the common plane (or, two robust holes, either
//! cycle round the other's void). A linked group two maps saw is one hole, whatever its
//! members' strength: a weak loop in each of two windows is an obstacle both missed
//! alone. A group one map saw is a hole when it is a robust hole and no neighbouring
//! window covers its place ([`COVER`]: the obstacles at the arena's ends, or beyond the
//! next domain, or cut by its edge), or when it is strong
//! ([`crate::mapping::classify::Classifier::strong`]). A robust but not strong hole at a
//! place the neighbour covers, where the neighbour's map holds encounters all round
//! ([`COVER_SECTORS`]) and no loop, is taken for noise of the one window.
//! The two observations are largely independent: the two windows embed their
//! encounters separately and share only the encounters of their time overlap.
//!
//! Why the terms do not double count: a hole wholly inside an overlap is inside both
//! domains, so the overlap's free space around it is one corridor, one connection, and G
//! gets no cycle from it; conversely an obstacle that no window contains whole splits some
//! overlaps into several corridors and appears only as a cycle of G.

use super::encounter_graph::EncounterGraph;
use super::local::{Hole, LocalMap, LocalParams};
use super::windows::Window;
use crate::eval::holes::encircles;
use crate::eval::{Similarity, procrustes};
use crate::log::{AgentId, EncounterLog, StaticReason};
use crate::topology::DistanceMatrix;
use crate::topology::linkage::{Dendrogram, UnionFind, single_linkage};
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

impl StitchParams {
    /// The stitching parameters of a world's `mapping` section.
    pub fn from_mapping(m: &crate::world::MappingParams) -> Self {
        Self {
            cutoff: m.cluster_cutoff,
            neighbours: m.neighbours,
        }
    }
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
    /// Number of connections: the clusters that join a component of each map (one per
    /// entry of `joins`).
    pub count: usize,
    /// Pairs `(component of M_i, component of M_{i+1})` joined, one per cluster that
    /// touches both maps.
    pub joins: Vec<(usize, usize)>,
    /// The further pairs a cluster glues when it touches several components of one map
    /// (its events, through W_{i+1}, show them to be one region): with the cluster's entry
    /// of `joins`, a spanning tree of the components it touches, so they become one region
    /// of the global map without a cycle of its own and without counting as connections.
    /// Written only when not empty.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub also_joins: Vec<(usize, usize)>,
}

/// The correspondence metric's distance between anchors no path joins (written as
/// `null` in the maps).
pub(crate) const UNREACHABLE: f64 = f64::MAX;

/// The clusters of `dendrogram` cut at `cutoff`, [`UNREACHABLE`] pairs kept apart.
fn cut(dendrogram: &Dendrogram, cutoff: f64) -> Vec<usize> {
    dendrogram.cut(cutoff.min(UNREACHABLE.next_down()))
}

/// Component pairs `(of M_i, of M_{i+1})`.
type Pairs = Vec<(usize, usize)>;

/// The pairs the clusters join, from the components each touches in M_i and M_{i+1}:
/// `joins`, one pair per cluster touching both maps (its first component of each), and
/// `also_joins`, the first component of each map paired with every further component the
/// cluster touches in the other, so that each cluster's pairs form a spanning tree of what
/// it touches (found by the forty-first session's review: only the first pair was kept, and
/// a cluster meeting two components of one map left one of them unglued, β0 one too high).
fn joins_of(touch: &[(BTreeSet<usize>, BTreeSet<usize>)]) -> (Pairs, Pairs) {
    let (mut joins, mut also) = (Vec::new(), Vec::new());
    for (a, b) in touch {
        let (Some(&a0), Some(&b0)) = (a.first(), b.first()) else {
            continue;
        };
        joins.push((a0, b0));
        also.extend(a.iter().skip(1).map(|&ak| (ak, b0)));
        also.extend(b.iter().skip(1).map(|&bk| (a0, bk)));
    }
    (joins, also)
}

/// The global topological map.
#[derive(Debug, Clone, Serialize)]
pub struct GlobalMap {
    /// Nodes: `(window index, component index)`.
    pub nodes: Vec<(usize, usize)>,
    /// Edges between node indices, one per join.
    pub edges: Vec<(usize, usize)>,
    /// The distinct holes of the local maps: `(window index, component, hole)` of the one
    /// kept for each, `hole` indexing the component's robust holes and then its candidates
    /// ([`crate::mapping::local::Component::mark`]).
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
    // Unreachable pairs are infinitely far, stored as `f64::MAX`: they never merge, whatever
    // the cut-off (the largest float passes the world check, and would merge them).
    let metric = DistanceMatrix::from_fn(cloud.len(), |a, b| {
        let d = rows[a][b - a - 1];
        if d.is_finite() { d } else { UNREACHABLE }
    });
    let dendrogram = single_linkage(&metric);
    let labels = cut(&dendrogram, p.cutoff);
    let clusters = labels.iter().copied().max().map_or(0, |m| m + 1);
    // Which components each cluster touches, through all E_S events of its anchors.
    let (ca, cb) = (component_of_events(ma), component_of_events(mb));
    let mut touch: Vec<(BTreeSet<usize>, BTreeSet<usize>)> = vec![Default::default(); clusters];
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
    let (joins, also_joins) = joins_of(&touch);
    // Only the clusters that join the two maps are connections between them.
    let count = joins.len();
    Connection {
        between: [wa.index, wb.index],
        static_agents: anchors.keys().copied().collect(),
        points: cloud.iter().map(|&k| events[k]).collect(),
        labels,
        heights: dendrogram.heights(),
        metric: Some(metric),
        count,
        joins,
        also_joins,
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

/// Fewest events two components must share before their planes are aligned.
const MIN_SHARED: usize = 3;

/// The similarity that carries component `cb` of `mb` onto component `ca` of `ma` on the
/// plane of their first two MDS axes, fitted (Procrustes, reflections allowed) on the
/// events both components hold; `None` when they share fewer than [`MIN_SHARED`].
fn common_plane(ma: &LocalMap, ca: usize, mb: &LocalMap, cb: usize) -> Option<Similarity> {
    let at: HashMap<usize, [f64; 2]> = ma.components[ca]
        .events
        .iter()
        .map(|&j| (ma.events[j], [ma.points[j][0], ma.points[j][1]]))
        .collect();
    let (mut est, mut target) = (Vec::new(), Vec::new());
    for &j in &mb.components[cb].events {
        if let Some(&p) = at.get(&mb.events[j]) {
            est.push([mb.points[j][0], mb.points[j][1]]);
            target.push(p);
        }
    }
    if est.len() < MIN_SHARED {
        return None;
    }
    procrustes(&est, &target).map(|p| p.transform)
}

/// A hole drawn on a plane: its cycle's vertices, the cycle's edges over them, and the
/// centre of its void (the death triangle's centroid; the cycle's centroid when the
/// engine gave no death triangle). `None` for a hole without a cycle.
fn drawn(map: &LocalMap, hole: &Hole, place: impl Fn([f64; 2]) -> [f64; 2]) -> Option<Drawn> {
    let at = |j: usize| place([map.points[j][0], map.points[j][1]]);
    let mut vertex: BTreeMap<usize, usize> = BTreeMap::new();
    let mut points = Vec::new();
    let mut index = |j: usize| {
        *vertex.entry(j).or_insert_with(|| {
            points.push(at(j));
            points.len() - 1
        })
    };
    let edges: Vec<(usize, usize)> = hole
        .cycle
        .iter()
        .map(|&(a, b)| (index(a), index(b)))
        .collect();
    if edges.is_empty() {
        return None;
    }
    // A similarity carries the mean of points to the mean of their images.
    let centre = place(void_centre(map, hole)?);
    Some(Drawn {
        points,
        edges,
        centre,
    })
}

/// See [`drawn`].
struct Drawn {
    points: Vec<[f64; 2]>,
    edges: Vec<(usize, usize)>,
    centre: [f64; 2],
}

/// Whether hole `b` of M_{i+1} is hole `a` of M_i. With the two components' common plane
/// (`plane` carries M_{i+1}'s onto M_i's): when either cycle encircles the other's void.
/// Without one (they share too few events): when the central times of their cycles
/// overlap ([`central_times`]).
fn same_hole(
    (ma, a): (&LocalMap, &Hole),
    (mb, b): (&LocalMap, &Hole),
    plane: Option<&Similarity>,
    log: &EncounterLog,
) -> bool {
    if let Some(f) = plane
        && let (Some(da), Some(db)) = (drawn(ma, a, |p| p), drawn(mb, b, |p| f.apply(p)))
    {
        return encircles(&da.points, &da.edges, db.centre)
            || encircles(&db.points, &db.edges, da.centre);
    }
    match (
        central_times(ma, log, &a.cycle),
        central_times(mb, log, &b.cycle),
    ) {
        (Some((alo, ahi)), Some((blo, bhi))) => blo <= ahi && alo <= bhi,
        _ => false,
    }
}

/// Two voids of consecutive maps, on a common plane, are one hole when they lie within
/// this many sampling scales σ of each other (σ of the earlier map's component). Over
/// scenario 3's seeds 1–20, the voids of one obstacle seen by two windows lie 0.3–15 σ
/// apart (median 4), those of two obstacles 48 σ or more, and a noise loop's void lies
/// within 19 σ of another window's loop in only 5 % of pairs (docs/accuracy.md, step 32).
pub const SAME_VOID: f64 = 12.0;

/// A neighbouring window covers a place of another map's plane when at least this share of
/// its component's events lie within [`SAME_VOID`] σ of the place carried onto its own
/// plane. An obstacle outside the neighbour's domain has none there; one inside it, a few
/// per cent (step 32).
pub const COVER: f64 = 0.01;

/// ... and when those events lie all round the place: in every one of this many equal
/// angular sectors about it (an event exactly at the place has no direction and fills
/// none). A place at the edge of the neighbour's domain (an obstacle the neighbour's band
/// cuts) has the neighbour's events on one side only, and the neighbour could not have seen
/// a loop there. So has a place within [`SAME_VOID`] σ of the arena's top or bottom side:
/// a loop there that one window alone holds is judged by that window's test alone.
pub const COVER_SECTORS: usize = 8;

/// One loop of a local map that the global map weighs: a robust hole or a candidate
/// ([`crate::mapping::local::Component::mark`] indexing).
#[derive(Debug, Clone, Copy)]
struct Mark {
    map: usize,
    component: usize,
    index: usize,
    robust: bool,
}

impl Mark {
    fn hole<'a>(&self, maps: &'a [LocalMap]) -> &'a Hole {
        maps[self.map].components[self.component]
            .mark(self.index)
            .expect("marks index holes and candidates")
    }
}

/// The centre of a hole's void on its map's plane (the death triangle's centroid; the
/// cycle's vertices' centroid when the engine gave no death triangle).
fn void_centre(map: &LocalMap, hole: &Hole) -> Option<[f64; 2]> {
    let mut points: Vec<usize> = match hole.void {
        Some(v) => v.to_vec(),
        None => hole.cycle.iter().flat_map(|&(a, b)| [a, b]).collect(),
    };
    points.sort_unstable();
    points.dedup();
    if points.is_empty() {
        return None;
    }
    let n = points.len() as f64;
    let (x, y) = points.iter().fold((0.0, 0.0), |(x, y), &j| {
        (x + map.points[j][0], y + map.points[j][1])
    });
    Some([x / n, y / n])
}

/// The distinct holes of the global map, as marks of the local maps ([`GlobalMap::holes`]).
///
/// The marks of every map (its robust holes and its candidates) are linked to those of the
/// next map that are the same hole: on the two components' common plane, when their voids
/// lie within [`SAME_VOID`] σ, or (two robust holes) when either's cycle encircles the
/// other's void ([`same_hole`]); without a common plane, by the times of their cycles. Each
/// linked group is then one hole of the global map when
/// - two maps saw it (their marks are two observations of one place: robust or candidate,
///   each is evidence), or
/// - one map saw it as a robust hole and no neighbouring map covers its place
///   ([`COVER`], [`COVER_SECTORS`]: an obstacle at the arena's end, outside the other
///   domains or cut by their edges), or
/// - one map saw it as a strong hole ([`crate::mapping::classify::Classifier::strong`]) though a neighbour that
///   covers its place saw no loop there.
///
/// A robust hole that a neighbour covers but does not see, and that is not strong, is
/// taken for noise: the neighbour's map holds the encounters round that place and no loop.
/// The group's hole is its first robust mark (the first candidate if none is robust).
fn global_holes(maps: &[LocalMap], log: &EncounterLog) -> Vec<(usize, usize, usize)> {
    let mut marks = Vec::new();
    for (k, m) in maps.iter().enumerate() {
        for (c, comp) in m.components.iter().enumerate() {
            let robust = comp.holes.len();
            for index in 0..robust + comp.candidates.len() {
                marks.push(Mark {
                    map: k,
                    component: c,
                    index,
                    robust: index < robust,
                });
            }
        }
    }
    let centres: Vec<Option<[f64; 2]>> = marks
        .iter()
        .map(|m| void_centre(&maps[m.map], m.hole(maps)))
        .collect();
    // Common planes, fitted when first needed: (map, component) carried onto (map,
    // component).
    let mut planes: HashMap<[usize; 4], Option<Similarity>> = HashMap::new();
    let mut plane = |(k, c): (usize, usize), (j, cj): (usize, usize)| {
        *planes
            .entry([k, c, j, cj])
            .or_insert_with(|| common_plane(&maps[j], cj, &maps[k], c))
    };
    let mut sets = UnionFind::new(marks.len());
    for (x, a) in marks.iter().enumerate() {
        for (y, b) in marks.iter().enumerate() {
            if b.map != a.map + 1 {
                continue;
            }
            let (ma, mb) = (&maps[a.map], &maps[b.map]);
            let onto_a = plane((b.map, b.component), (a.map, a.component));
            let near = match (onto_a, centres[x], centres[y]) {
                (Some(f), Some(ca), Some(cb)) => {
                    let q = f.apply(cb);
                    let sigma = ma.components[a.component].scale;
                    (q[0] - ca[0]).hypot(q[1] - ca[1]) <= SAME_VOID * sigma
                }
                _ => false,
            };
            let same = near
                || (onto_a.is_none() || a.robust && b.robust)
                    && same_hole((ma, a.hole(maps)), (mb, b.hole(maps)), onto_a.as_ref(), log);
            if same {
                sets.union(x, y);
            }
        }
    }
    // Whether map `j` covers the place `at` of component `c` of map `k`.
    let mut covers = |k: usize, c: usize, j: usize, at: [f64; 2]| {
        let nb = &maps[j];
        (0..nb.components.len()).any(|cj| {
            let Some(f) = plane((k, c), (j, cj)) else {
                return false;
            };
            let comp = &nb.components[cj];
            let q = f.apply(at);
            let reach = SAME_VOID * comp.scale;
            let mut near = 0;
            let mut sectors = [false; COVER_SECTORS];
            for &e in &comp.events {
                let (dx, dy) = (nb.points[e][0] - q[0], nb.points[e][1] - q[1]);
                let d = dx.hypot(dy);
                if d <= reach {
                    near += 1;
                    if d == 0.0 {
                        continue;
                    }
                    let turn = dy.atan2(dx) / std::f64::consts::TAU + 0.5;
                    let s = ((turn * COVER_SECTORS as f64) as usize).min(COVER_SECTORS - 1);
                    sectors[s] = true;
                }
            }
            !comp.events.is_empty()
                && near as f64 >= COVER * comp.events.len() as f64
                && sectors.iter().all(|&s| s)
        })
    };
    let mut groups: BTreeMap<usize, Vec<usize>> = BTreeMap::new();
    for x in 0..marks.len() {
        groups.entry(sets.find(x)).or_default().push(x);
    }
    let mut holes = Vec::new();
    for members in groups.values() {
        let first = members
            .iter()
            .copied()
            .find(|&x| marks[x].robust)
            .unwrap_or(members[0]);
        let seen_by = members
            .iter()
            .map(|&x| marks[x].map)
            .collect::<BTreeSet<_>>()
            .len();
        let kept = if seen_by >= 2 {
            true
        } else {
            let m = marks[first];
            let map = &maps[m.map];
            let hole = m.hole(maps);
            let sigma = map.components[m.component].scale;
            let covered = centres[first].is_some_and(|at| {
                [m.map.checked_sub(1), Some(m.map + 1)]
                    .into_iter()
                    .flatten()
                    .filter(|&j| j < maps.len())
                    .any(|j| covers(m.map, m.component, j, at))
            });
            m.robust && (!covered || map.classifier.strong(hole.birth, hole.death, sigma))
        };
        if kept {
            let m = marks[first];
            holes.push((maps[m.map].index, m.component, m.index));
        }
    }
    holes.sort_unstable();
    holes
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
        for &(a, b) in conn.joins.iter().chain(&conn.also_joins) {
            if let (Some(&x), Some(&y)) = (
                node_of.get(&(conn.between[0], a)),
                node_of.get(&(conn.between[1], b)),
            ) {
                edges.push((x, y));
            }
        }
    }
    // β0 by union–find over the gluing graph.
    let mut sets = UnionFind::new(nodes.len());
    for &(a, b) in &edges {
        sets.union(a, b);
    }
    let b0 = (0..nodes.len()).filter(|&x| sets.find(x) == x).count();
    let gluing_cycles = (edges.len() + b0).saturating_sub(nodes.len());
    let holes = global_holes(maps, log);
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
    /// into the log), all at one point of the plane (so no two maps have a common plane
    /// and holes are compared by time).
    fn map_with_hole(index: usize, events: Vec<usize>) -> LocalMap {
        let n = events.len();
        planar_map(index, events, vec![[0.0; 2]; n], &[(0..n).collect()])
    }

    /// One connection between W_1 and W_2, joining their first components.
    fn one_join() -> Connection {
        Connection {
            between: [1, 2],
            static_agents: Vec::new(),
            points: Vec::new(),
            labels: Vec::new(),
            metric: None,
            heights: Vec::new(),
            count: 1,
            joins: vec![(0, 0)],
            also_joins: Vec::new(),
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
        let join = one_join();
        let g = global_map(&[m1.clone(), distinct], std::slice::from_ref(&join), &log);
        assert_eq!(g.betti, [1, 2]);
        let g = global_map(&[m1, same], std::slice::from_ref(&join), &log);
        assert_eq!(g.betti, [1, 1]);
    }

    /// A map of window `index` holding the log's `events` at the plane points `at` (one
    /// component, sampling scale σ = 0.1), with one strong hole (life 10 σ) per loop of
    /// `loops` (indices into `events`).
    fn planar_map(
        index: usize,
        events: Vec<usize>,
        at: Vec<[f64; 2]>,
        loops: &[Vec<usize>],
    ) -> LocalMap {
        planar_map_with(index, events, at, loops, 2.0, &[])
    }

    /// A loop through `l` with life `death − 1`.
    fn loop_hole(l: &[usize], death: f64) -> Hole {
        Hole {
            birth: 1.0,
            death,
            cycle: (0..l.len()).map(|k| (l[k], l[(k + 1) % l.len()])).collect(),
            void: None,
        }
    }

    /// [`planar_map`] whose holes die at `death` and which also holds a candidate per loop
    /// of `weak`.
    fn planar_map_with(
        index: usize,
        events: Vec<usize>,
        at: Vec<[f64; 2]>,
        loops: &[Vec<usize>],
        death: f64,
        weak: &[Vec<usize>],
    ) -> LocalMap {
        let n = events.len();
        let holes = loops
            .iter()
            .map(|l| loop_hole(l, death))
            .collect::<Vec<_>>();
        LocalMap {
            index,
            start: 0.0,
            end: 0.0,
            events,
            points: at.iter().map(|p| [p[0], p[1], 0.0]).collect(),
            noise: vec![false; n],
            components: vec![Component {
                events: (0..n).collect(),
                representatives: (0..n).collect(),
                scale: 0.1,
                diagram: Vec::new(),
                betti: [1, holes.len()],
                holes,
                candidates: weak.iter().map(|l| loop_hole(l, 1.5)).collect(),
            }],
            betti: [1, 1],
            explained: 1.0,
            events_per_point: 1.0,
            outlier_rank: 8,
            // The shipped Embedded model's thresholds: a hole is strong from a life of
            // 1.25 · 4.25 · σ = 0.53.
            classifier: crate::mapping::classify::Classifier {
                h0_ratio: 57.5,
                h1_ratio: 2.3,
                h1_span: 4.25,
                h1_crossing: None,
                h1_stability: None,
            },
            rows: Vec::new(),
        }
    }

    /// 40 events on a lattice of spacing 2: x −6..8, y −4..4.
    fn lattice() -> Vec<[f64; 2]> {
        (0..40)
            .map(|k| [(k % 8) as f64 * 2.0 - 6.0, (k / 8) as f64 * 2.0 - 4.0])
            .collect()
    }

    /// Ten events on a circle of radius `r` round `c`.
    fn ring(c: [f64; 2], r: f64) -> Vec<[f64; 2]> {
        (0..10)
            .map(|k| {
                let a = std::f64::consts::TAU * k as f64 / 10.0;
                [c[0] + r * a.cos(), c[1] + r * a.sin()]
            })
            .collect()
    }

    /// Two maps that share events are compared on a common plane: M_2's plane is M_1's
    /// reflected, turned, scaled and moved, and a hole of M_2 drawn round the same place
    /// as M_1's hole is that hole even though the times of their cycles are far apart
    /// (M_1's loop at 100–190 s, M_2's at 2 000–2 090 s), while a hole round another place
    /// is another hole although its loop's times meet M_1's.
    #[test]
    fn holes_of_maps_that_share_events_are_matched_on_their_common_plane() {
        // The log: 0..40 a shared lattice (t = 1 000–1 390), 40..50 M_1's loop round the
        // origin (t = 100–190), 50..60 M_2's loop round the origin (t = 2 000–2 090),
        // 60..70 M_2's loop round (8, 0) (t = 150–240).
        let mut times: Vec<f64> = (0..40).map(|k| 1000.0 + 10.0 * k as f64).collect();
        times.extend((0..10).map(|k| 100.0 + 10.0 * k as f64));
        times.extend((0..10).map(|k| 2000.0 + 10.0 * k as f64));
        times.extend((0..10).map(|k| 150.0 + 10.0 * k as f64));
        let log = log(&times);
        let lattice = lattice();
        // M_2's plane: x ↦ 3 · R(40°) · (x, −y) + (5, −2).
        let (c, s) = (40f64.to_radians().cos(), 40f64.to_radians().sin());
        let other = |p: [f64; 2]| {
            [
                3.0 * (c * p[0] + s * p[1]) + 5.0,
                3.0 * (s * p[0] - c * p[1]) - 2.0,
            ]
        };
        let first = planar_map(
            1,
            (0..50).collect(),
            lattice
                .iter()
                .copied()
                .chain(ring([0.0, 0.0], 1.0))
                .collect(),
            &[(40..50).collect()],
        );
        let second = |loop_events: std::ops::Range<usize>, centre: [f64; 2]| {
            planar_map(
                2,
                (0..40).chain(loop_events).collect(),
                lattice
                    .iter()
                    .copied()
                    .chain(ring(centre, 1.3))
                    .map(other)
                    .collect(),
                &[(40..50).collect()],
            )
        };
        let join = one_join();
        let joins = std::slice::from_ref(&join);
        let same = second(50..60, [0.0, 0.0]);
        assert_eq!(
            global_map(&[first.clone(), same], joins, &log).betti,
            [1, 1]
        );
        let elsewhere = second(60..70, [8.0, 0.0]);
        assert_eq!(global_map(&[first, elsewhere], joins, &log).betti, [1, 2]);
    }

    /// The log and the maps of the tests below: a lattice of events 0..40 that both maps
    /// hold (t = 1 000–1 390; M_2's plane is M_1's turned and scaled), rings of ten events
    /// each round the origin (40..50 in M_1, 50..60 in M_2) and round (30, 0) (60..70, in
    /// M_1 only, outside M_2's lattice).
    fn two_maps(
        holes: [&[Vec<usize>]; 2],
        weak: [&[Vec<usize>]; 2],
        death: f64,
    ) -> (EncounterLog, LocalMap, LocalMap) {
        let times: Vec<f64> = (0..70).map(|k| 1000.0 + 10.0 * k as f64).collect();
        let lattice = lattice();
        let other = |p: [f64; 2]| [-2.0 * p[1] + 1.0, 2.0 * p[0] - 3.0];
        let first = planar_map_with(
            1,
            (0..50).chain(60..70).collect(),
            lattice
                .iter()
                .copied()
                .chain(ring([0.0, 0.0], 1.0))
                .chain(ring([30.0, 0.0], 1.0))
                .collect(),
            holes[0],
            death,
            weak[0],
        );
        let mut second = planar_map_with(
            2,
            (0..40).chain(50..60).collect(),
            lattice
                .iter()
                .copied()
                .chain(ring([0.0, 0.0], 1.0))
                .map(other)
                .collect(),
            holes[1],
            death,
            weak[1],
        );
        // Its plane is M_1's scaled by 2, and so is its σ: [`SAME_VOID`] σ then reaches
        // the ring round the origin, M_2's events all round that place.
        second.components[0].scale = 0.2;
        (log(&times), first, second)
    }

    /// Anchors no path joins stay apart even at the largest cut-off the world check lets
    /// through (found by the forty-first session's review: `f64::MAX` merged them).
    #[test]
    fn unreachable_anchors_never_merge() {
        let metric =
            DistanceMatrix::from_fn(3, |a, b| if (a, b) == (0, 1) { 2.0 } else { UNREACHABLE });
        let dendrogram = single_linkage(&metric);
        for cutoff in [2.0, 1e300, f64::MAX] {
            let labels = cut(&dendrogram, cutoff);
            assert_eq!(labels[0], labels[1]);
            assert_ne!(labels[0], labels[2], "cut-off {cutoff}");
        }
    }

    /// A cluster that touches two components of one map glues both to the other map's
    /// component, as one region and one connection, with no cycle (found by the forty-first
    /// session's review: the second component stayed unglued, global β0 one too high).
    #[test]
    fn a_cluster_touching_two_components_of_one_map_glues_both() {
        let set = |v: &[usize]| v.iter().copied().collect::<BTreeSet<usize>>();
        // Cluster 0 touches components 0 and 1 of M_i and component 0 of M_{i+1}; cluster 1
        // touches M_i's 2 and M_{i+1}'s 1 and 2; cluster 2 touches only M_i (joins nothing).
        let touch = vec![
            (set(&[0, 1]), set(&[0])),
            (set(&[2]), set(&[1, 2])),
            (set(&[3]), set(&[])),
        ];
        let (joins, also) = joins_of(&touch);
        assert_eq!(joins, vec![(0, 0), (2, 1)]);
        assert_eq!(also, vec![(1, 0), (2, 2)]);

        let log = log(&[0.0, 1.0, 2.0, 3.0]);
        let mut m1 = planar_map(1, vec![0, 1], vec![[0.0; 2]; 2], &[]);
        let mut second = m1.components[0].clone();
        second.events = vec![1];
        m1.components[0].events = vec![0];
        m1.components.push(second);
        let m2 = planar_map(2, vec![2, 3], vec![[0.0; 2]; 2], &[]);
        let mut conn = one_join();
        let maps = [m1, m2];
        assert_eq!(
            global_map(&maps, std::slice::from_ref(&conn), &log).betti,
            [2, 0]
        );
        conn.also_joins = vec![(1, 0)];
        let g = global_map(&maps, std::slice::from_ref(&conn), &log);
        assert_eq!((g.betti, g.gluing_cycles), ([1, 0], 0));
    }

    /// Two candidates (loops too weak for either map alone) that two windows see round
    /// one place are one hole of the global map; one candidate alone is none.
    #[test]
    fn a_loop_two_windows_see_weakly_is_one_hole() {
        let join = one_join();
        let joins = std::slice::from_ref(&join);
        let round_origin_1 = vec![(40..50).collect::<Vec<_>>()];
        let round_origin_2 = vec![(40..50).collect::<Vec<_>>()];
        let (log, m1, m2) = two_maps([&[], &[]], [&round_origin_1, &round_origin_2], 2.0);
        let g = global_map(&[m1, m2], joins, &log);
        assert_eq!(g.betti, [1, 1]);
        // The hole kept is M_1's candidate, indexed after its (no) robust holes.
        assert_eq!(g.holes, vec![(1, 0, 0)]);
        let (log, m1, m2) = two_maps([&[], &[]], [&round_origin_1, &[]], 2.0);
        assert_eq!(global_map(&[m1, m2], joins, &log).betti, [1, 0]);
    }

    /// A place at the edge of the neighbour's cloud is not covered: the neighbour holds
    /// events on one side of it only (an obstacle its domain cuts), so it could not have
    /// seen a loop there, and a robust hole of the other map stands on its own. The same
    /// place with the neighbour's events all round it is covered.
    #[test]
    fn a_neighbour_with_events_on_one_side_only_does_not_cover() {
        let join = one_join();
        let joins = std::slice::from_ref(&join);
        // M_1: the lattice (x −6..8) and a ring round (9, 0), just beyond its right edge,
        // held as a robust hole that is not strong; M_2: the lattice only, on M_1's plane.
        let times: Vec<f64> = (0..60).map(|k| 1000.0 + 10.0 * k as f64).collect();
        let log = log(&times);
        let weak_life = 1.0 + 0.4;
        let first = planar_map_with(
            1,
            (0..50).collect(),
            lattice().into_iter().chain(ring([9.0, 0.0], 1.0)).collect(),
            &[(40..50).collect()],
            weak_life,
            &[],
        );
        // [`SAME_VOID`] σ = 1.2: the lattice point (8, 0) is the one event of M_2 near the
        // place, on its −x side.
        let second = planar_map_with(2, (0..40).collect(), lattice(), &[], 1.0, &[]);
        let g = global_map(&[first.clone(), second], joins, &log);
        assert_eq!(g.betti, [1, 1], "one-sided events do not cover");
        // M_2 with events all round (9, 0) (its own copy of the ring's events): covered,
        // and the weak hole M_2 does not see is dropped.
        let all_round = planar_map_with(
            2,
            (0..50).collect(),
            lattice().into_iter().chain(ring([9.0, 0.0], 1.0)).collect(),
            &[],
            1.0,
            &[],
        );
        assert_eq!(global_map(&[first, all_round], joins, &log).betti, [1, 0]);
    }

    /// A robust hole that the next window covers (its lattice lies round the place) but
    /// sees no loop at is noise unless it is strong; one the next window does not cover
    /// stands on its own.
    #[test]
    fn a_hole_the_neighbour_covers_without_a_loop_must_be_strong() {
        let join = one_join();
        let joins = std::slice::from_ref(&join);
        let round_origin = vec![(40..50).collect::<Vec<_>>()];
        let far = vec![(50..60).collect::<Vec<_>>()];
        // σ = 0.1 and h1_span 4.25: strong from a life of 0.53.
        let weak_life = 1.0 + 0.4;
        let (log, m1, m2) = two_maps([&round_origin, &[]], [&[], &[]], weak_life);
        assert_eq!(global_map(&[m1, m2], joins, &log).betti, [1, 0]);
        let (log, m1, m2) = two_maps([&round_origin, &[]], [&[], &[]], 2.0);
        assert_eq!(global_map(&[m1, m2], joins, &log).betti, [1, 1]);
        let (log, m1, m2) = two_maps([&far, &[]], [&[], &[]], weak_life);
        assert_eq!(global_map(&[m1, m2], joins, &log).betti, [1, 1]);
        // A candidate of M_2 round the origin confirms M_1's weak hole.
        let (log, m1, m2) = two_maps([&round_origin, &[]], [&[], &round_origin], weak_life);
        assert_eq!(global_map(&[m1, m2], joins, &log).betti, [1, 1]);
    }
}
