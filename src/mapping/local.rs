//! Local topological maps (paper §"Local Mapping"): from the encounters of one time window,
//! the encounter point cloud of its domain and its robust components and holes.
//!
//! Per window W_i:
//! 1. the encounters whose interval meets W_i, and the static intervals meeting it; with
//!    `mapping.after_landmarks`, an encounter that ends before the log's first
//!    landmark interval begins is left out ([`first_landmark_start`]): the paper records
//!    encounters once the landmarks are selected (§"Exploration and Event Collection"),
//!    and before any landmark nothing anchors the metric;
//! 2. the sparse encounter graph ([`super::encounter_graph`]) and its components; a
//!    component with fewer than `min_component` encounters (or a share below
//!    `min_share` of the window's) is noise — a few stray encounters, not a region;
//! 3. per real component, m representatives by density-aware MaxMin
//!    ([`super::subsample`]); their distance rows give the m × m encounter metric for
//!    Vietoris–Rips persistence (H0, H1) and, by landmark MDS, a 3-D embedding of every
//!    encounter of the component (the encounter point cloud); the `Embedded` method then
//!    moves the encounters of moving agents between the landmarks they lead to
//!    ([`super::bridge`]) and computes persistence on that cloud, each component on its
//!    share of the window's planar Rips points
//!    ([`super::dense::DenseParams::for_share`]), so that all are sampled alike;
//! 4. the classifier ([`super::classify`]) keeps the robust classes; (β0, β1) sum over
//!    components.
//!
//! Cost per window: O(m · (n + E) log n) for the shortest paths, O(m²) memory for the
//! metric, O(m · n) for the rows; never O(n²).

use super::classify::{Bank, Classifier, sampling_scale};
use super::encounter_graph::{Bridging, EncounterGraph};
use super::subsample::{SubsampleParams, subsample_with};
use super::windows::Window;
use crate::log::{Encounter, EncounterLog};
use crate::topology::DistanceMatrix;
use crate::topology::mds::landmark_mds;
use crate::topology::rips::{RipsOptions, rips_matrix, tighten_cycle};
use serde::Serialize;

/// Parameters of local mapping.
#[derive(Debug, Clone, PartialEq)]
pub struct LocalParams {
    /// How static intervals bridge time (default: the paper's rule).
    pub bridging: Bridging,
    /// Cost in seconds of a change of agent along a path (default: `0.0`, the paper's
    /// metric; [`super::encounter_graph`], "Agent switches").
    pub switch_cost: f64,
    /// Leave out the encounters that end before the first landmark interval begins
    /// ([`first_landmark_start`]; default: `false`).
    pub after_landmarks: bool,
    /// Weigh encounters along a time line by the time between their middles
    /// ([`EncounterGraph::build_timed`]; default: `false`, the paper's gap).
    pub midpoints: bool,
    /// Subsampling (default: m = 400).
    pub subsample: SubsampleParams,
    /// Smallest number of encounters of a real component (default: `20`).
    pub min_component: usize,
    /// Smallest share of the window's encounters of a real component (default: `0.02`).
    pub min_share: f64,
    /// The robust-feature classifiers, one per sampling density (default: the shipped
    /// models of the paper's method); each window is judged by the one fitted nearest its
    /// [`LocalMap::events_per_point`].
    pub classifier: Bank,
    /// Draw the representatives only from encounters with an agent that was a static
    /// landmark at the time (their position is that of the landmark, known exactly up to
    /// r_d), instead of from all encounters (default: `false`, the paper's choice).
    pub anchored: bool,
    /// Build the lazy witness complex of the representatives with this ν (witnesses: all
    /// encounters of the component) instead of the Vietoris–Rips complex (default: `None`).
    pub witness: Option<usize>,
    /// Compute persistence on the encounter point cloud (the MDS embedding) after a
    /// density filter, instead of on the metric (default: `None`).
    pub embedding_rips: Option<super::dense::DenseParams>,
    /// Place the encounters of moving agents between the landmarks their shortest paths
    /// lead to ([`super::bridge`]) instead of where landmark MDS puts them (default:
    /// `false`; the `Embedded` method sets it).
    pub bridge: bool,
    /// Then place them on their agents' time lines, pinned by the encounters with
    /// landmarks, with this floor τ in seconds ([`super::timelines`]; default: `None`).
    pub timelines: Option<f64>,
    /// Compute every H1 bar's split stability ([`super::stability`]) with the
    /// `embedding_rips` stage, even where the window's model has no stability test
    /// (default: `false`; a model with one always gets them).
    pub stability: bool,
}

impl Default for LocalParams {
    fn default() -> Self {
        Self {
            bridging: Bridging::Paper,
            switch_cost: 0.0,
            after_landmarks: false,
            midpoints: false,
            subsample: SubsampleParams::default(),
            min_component: 20,
            min_share: 0.02,
            classifier: Bank::single(Classifier::default()),
            anchored: false,
            witness: None,
            embedding_rips: None,
            bridge: false,
            timelines: None,
            stability: false,
        }
    }
}

impl LocalParams {
    /// The parameters a world's `mapping` section selects, with the models fitted at the
    /// default sweep ([`super::classify::DEFAULT_SWEEP`]; a log without a world).
    pub fn from_mapping(m: &crate::world::MappingParams) -> Self {
        Self::from_mapping_at(m, super::classify::DEFAULT_SWEEP)
    }

    /// The parameters a world's `mapping` section selects for a leader sweeping at `sweep`
    /// m/s: the models of the method fitted at the nearest sweep
    /// ([`super::classify::Bank::for_sweep`]), and the outlier filter's neighbour rank the
    /// section gives (`outlier_rank`), else the one scaled with the sweep
    /// ([`super::subsample::rank_for_sweep`]).
    pub fn from_mapping_at(m: &crate::world::MappingParams, sweep: f64) -> Self {
        let mut p = Self::default();
        p.subsample.m = m.subsample;
        p.subsample.k = m
            .outlier_rank
            .unwrap_or_else(|| super::subsample::rank_for_sweep(sweep));
        p.classifier = super::classify::Models::active()
            .get(m.method)
            .for_sweep(sweep);
        p.bridging = Bridging::Paper;
        p.switch_cost = m.switch_cost;
        p.after_landmarks = m.after_landmarks;
        p.midpoints = m.encounter_midpoints;
        if m.method == crate::world::MappingMethod::Embedded {
            p.anchored = true;
            p.embedding_rips = Some(super::dense::DenseParams::embedded_with(m.rips_points));
            p.bridge = true;
            if m.agent_timelines {
                p.timelines = Some(super::timelines::TIMELINE_FLOOR);
            }
            p.stability = m.split_stability;
        }
        p
    }
}

/// A bar of a component's diagram, with its robustness.
#[derive(Debug, Clone, Serialize)]
pub struct MapBar {
    pub dim: usize,
    pub birth: f64,
    /// `null` in JSON for an essential class.
    pub death: Option<f64>,
    pub robust: bool,
    /// For an H1 bar, the three representatives (indices into the window's `events`) of
    /// the triangle whose entry kills it, as for [`Hole::void`]: where the loop's void lies,
    /// robust or not (the global map weighs a hole two windows saw, `stitch`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub void: Option<[usize; 3]>,
    /// For an H1 bar of the `Embedded` method with a life of at least
    /// [`super::crossing::CROSSING_FLOOR`] σ, the share of the moving agents' time-line
    /// segments near its void that pass through it ([`super::crossing`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub crossing: Option<f64>,
    /// The split stability of an H1 bar with a life of at least
    /// [`super::stability::STABILITY_FLOOR`] σ, where computed ([`super::stability`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub stability: Option<f64>,
}

/// A robust hole: its bar and a representative cycle as encounters (indices into the
/// window's `events`, consecutive pairs joined by an edge of the metric): the tight loop
/// round the hole ([`tighten_cycle`]), or the engine's representative where none exists.
#[derive(Debug, Clone, Serialize)]
pub struct Hole {
    pub birth: f64,
    pub death: f64,
    /// Edges of the representative cycle, as pairs of indices into `events`.
    pub cycle: Vec<(usize, usize)>,
    /// The three representatives (indices into `events`) of the triangle whose entry
    /// kills the hole's class; its longest edge, of length `death`, spans the void itself,
    /// which the cycle, drawn through the bar's birth edge, can pass 1–3 m from
    /// (docs/accuracy.md, step 16). `null` only if the engine gave no death triangle.
    pub void: Option<[usize; 3]>,
}

/// One real component of a window's encounter graph.
#[derive(Debug, Clone, Serialize)]
pub struct Component {
    /// Indices into the window's `events`.
    pub events: Vec<usize>,
    /// Indices into the window's `events` of the representatives.
    pub representatives: Vec<usize>,
    /// Sampling scale σ of the diagram, seconds.
    pub scale: f64,
    pub diagram: Vec<MapBar>,
    /// (β0, β1) of this component.
    pub betti: [usize; 2],
    pub holes: Vec<Hole>,
    /// Loops too weak to be holes of this map alone but that pass the classifier's
    /// candidate test ([`super::classify::Classifier::candidate`]): the global map counts
    /// one when the previous or next window sees a loop at the same place (`stitch`).
    pub candidates: Vec<Hole>,
}

impl Component {
    /// Hole `h` of this component, counting its robust holes first and then its
    /// candidates (the indexing of [`super::stitch::GlobalMap::holes`]).
    pub fn mark(&self, h: usize) -> Option<&Hole> {
        mark(&self.holes, &self.candidates, h)
    }
}

/// Item `h` of `holes` followed by `candidates`: how [`super::stitch::GlobalMap::holes`]
/// indexes a component's loops, in memory and as read back from `maps/`.
pub fn mark<'a, H>(holes: &'a [H], candidates: &'a [H], h: usize) -> Option<&'a H> {
    holes
        .get(h)
        .or_else(|| candidates.get(h.checked_sub(holes.len())?))
}

/// The local map of one window.
#[derive(Debug, Clone, Serialize)]
pub struct LocalMap {
    pub index: usize,
    pub start: f64,
    pub end: f64,
    /// Indices into the log's encounters of the window's events.
    pub events: Vec<usize>,
    /// 3-D encounter point cloud, one point per event (NaN-free; events of noise
    /// components sit at the origin and are flagged in `noise`).
    pub points: Vec<[f64; 3]>,
    /// Whether each event belongs to a noise component.
    pub noise: Vec<bool>,
    pub components: Vec<Component>,
    /// Estimated (β0, β1).
    pub betti: [usize; 2],
    /// Share of the MDS spectrum carried by the 3 kept dimensions (mean over components).
    pub explained: f64,
    /// The window's sampling density: its real components' encounters per vertex of their
    /// Rips complexes (0 when it has none). The classifier's thresholds are fitted at a
    /// density ([`super::classify::Bank`]); this one picks the model the window is judged by.
    pub events_per_point: f64,
    /// The thresholds the window was judged by: the model of `LocalParams::classifier`
    /// fitted nearest `events_per_point`.
    pub classifier: Classifier,
    /// The outlier filter's configured neighbour rank k the representatives were picked
    /// with (`LocalParams::subsample.k`: `mapping.outlier_rank`, else scaled with the
    /// sweep, [`super::subsample::rank_for_sweep`]).
    pub outlier_rank: usize,
    /// Distance rows from each component's representatives, kept for fidelity and
    /// stitching: `(event index, row over the window's events)`.
    #[serde(skip)]
    pub rows: Vec<(usize, Vec<f64>)>,
}

/// Distances between the vertices of a component's Rips complex.
enum VertexMetric {
    /// Points of the embedded cloud, compared on their first `dims` coordinates.
    Coords(Vec<[f64; 3]>, usize),
    /// An explicit matrix (the encounter metric or the witness metric).
    Matrix(DistanceMatrix),
}

impl VertexMetric {
    fn len(&self) -> usize {
        match self {
            Self::Coords(p, _) => p.len(),
            Self::Matrix(m) => m.len(),
        }
    }

    fn dist(&self, a: usize, b: usize) -> f64 {
        match self {
            Self::Coords(p, dims) => super::dense::dist(&p[a], &p[b], *dims),
            Self::Matrix(m) => m.get(a, b),
        }
    }
}

/// The start of the first landmark interval that begins by the end of `window`, or `None`
/// if no landmark has been selected by then.
///
/// The paper's swarm disperses first and records encounters only once the landmarks are
/// selected (§"Exploration and Event Collection"). A simulated log also holds the
/// dispersion's encounters; nothing static bridges time among them, so the metric cannot
/// place them: in window 1 of scenario 1 (seeds 1–2) they are 27 % of the events and their
/// embedded positions err by 1.5–1.6 m (median), against 0.5–0.75 m for later ones, and
/// the window's rank correlation is 0.56–0.58 with them and 0.94–0.95 without
/// (docs/accuracy.md, step 20). Only intervals that begin by the window's end count, so a window
/// is mapped alike from the whole log and from its prefix up to the window's end
/// ([`crate::pipeline`], mapping alongside the simulation).
pub fn first_landmark_start(log: &EncounterLog, window: &Window) -> Option<f64> {
    log.static_intervals
        .iter()
        .filter(|s| s.reason == crate::log::StaticReason::Landmark && s.start <= window.end)
        .map(|s| s.start)
        .min_by(f64::total_cmp)
}

/// Builds the local map of `window` from `log`.
pub fn local_map(log: &EncounterLog, window: &Window, p: &LocalParams) -> LocalMap {
    local_map_with(log, window, p, &|| 0)
}

/// [`local_map`] whose farthest-point selection computes up to `lookahead()` guessed rows
/// beside each needed one on the current rayon pool ([`super::subsample::maxmin_with`]):
/// the same map, sooner when cores would otherwise be idle (one window mapped alone).
pub fn local_map_with(
    log: &EncounterLog,
    window: &Window,
    p: &LocalParams,
    lookahead: &(dyn Fn() -> usize + Sync),
) -> LocalMap {
    let recorded_from = if p.after_landmarks {
        first_landmark_start(log, window).unwrap_or(f64::NEG_INFINITY)
    } else {
        f64::NEG_INFINITY
    };
    let events: Vec<usize> = log
        .encounters
        .iter()
        .enumerate()
        .filter(|(_, e)| window.meets(e.start, e.end) && e.end >= recorded_from)
        .map(|(i, _)| i)
        .collect();
    let enc: Vec<Encounter> = events.iter().map(|&i| log.encounters[i].clone()).collect();
    let statics: Vec<_> = log
        .static_intervals
        .iter()
        .filter(|s| window.meets(s.start, s.end))
        .filter(|s| {
            p.bridging == Bridging::StaticTimeFree || s.reason == crate::log::StaticReason::Landmark
        })
        .cloned()
        .collect();
    let graph = EncounterGraph::build_timed(&enc, &statics, p.bridging, p.switch_cost, p.midpoints);
    // Whether an encounter involves an agent that was a landmark at the time: its position
    // is the landmark's. Landmark intervals are indexed by agent, so this is O(E · k) for
    // k intervals per agent, not O(E · all intervals).
    let mut landmark_of: std::collections::HashMap<u32, Vec<(f64, f64)>> =
        std::collections::HashMap::new();
    for s in statics
        .iter()
        .filter(|s| s.reason == crate::log::StaticReason::Landmark)
    {
        landmark_of
            .entry(s.agent)
            .or_default()
            .push((s.start, s.end));
    }
    let anchored: Vec<bool> = enc
        .iter()
        .map(|e| {
            [e.a, e.b].iter().any(|agent| {
                landmark_of.get(agent).is_some_and(|v| {
                    v.iter()
                        .any(|&(start, end)| start <= e.end && e.start <= end)
                })
            })
        })
        .collect();
    let labels = graph.components();
    let n = enc.len();
    let mut groups: Vec<Vec<usize>> = Vec::new();
    for (i, &l) in labels.iter().enumerate() {
        if l >= groups.len() {
            groups.resize(l + 1, Vec::new());
        }
        groups[l].push(i);
    }
    let min_size = p
        .min_component
        .max((p.min_share * n as f64).ceil() as usize);
    let mut points = vec![[0.0; 3]; n];
    let mut noise = vec![true; n];
    let mut components = Vec::new();
    let mut rows_out = Vec::new();
    let mut explained = Vec::new();
    let groups: Vec<Vec<usize>> = groups
        .into_iter()
        .filter(|g| g.len() >= min_size.max(3))
        .collect();
    let mapped: usize = groups.iter().map(Vec::len).sum();
    // Each real component's diagram, vertices (as events) and vertex metric; classified
    // once the window's density is known.
    let mut raw = Vec::new();
    for members in groups {
        // A component with too few encounters with landmarks (a log without landmark
        // intervals, or a region no landmark reached) is embedded from all its encounters,
        // as the paper's method does: dropping it would lose a real component.
        let landmark_encounters: Vec<usize> = if p.anchored {
            members.iter().copied().filter(|&j| anchored[j]).collect()
        } else {
            Vec::new()
        };
        let candidates = if landmark_encounters.len() >= 3 {
            landmark_encounters
        } else {
            members.clone()
        };
        let mut sub = subsample_with(&graph, &candidates, &p.subsample, lookahead);
        if sub.picks.len() < 3 && candidates.len() < members.len() {
            // The landmark encounters stand at fewer than three places (one landmark
            // interval: they are one point of the metric), too few to span a plane: the
            // component is embedded from all its encounters, as without landmarks.
            sub = subsample_with(&graph, &members, &p.subsample, lookahead);
        }
        // Embed every member of the component from the representatives' rows.
        let rows: Vec<Vec<f64>> = sub
            .rows
            .iter()
            .map(|r| members.iter().map(|&j| r[j]).collect())
            .collect();
        let local_picks: Vec<usize> = sub
            .picks
            .iter()
            .map(|p| members.binary_search(p).unwrap_or(0))
            .collect();
        if let Ok(emb) = landmark_mds(&local_picks, &rows, 3) {
            explained.push(emb.explained);
            for (k, &j) in members.iter().enumerate() {
                let c = emb.coords.point(k);
                points[j] = [
                    c.first().copied().unwrap_or(0.0),
                    c.get(1).copied().unwrap_or(0.0),
                    c.get(2).copied().unwrap_or(0.0),
                ];
            }
            if p.bridge {
                super::bridge::place_between_landmarks(
                    &mut points,
                    &members,
                    &sub.picks,
                    &sub.rows,
                    super::bridge::EXIT_CANDIDATES,
                );
            }
            // Pinned by fewer than 3 landmark encounters, a component's time lines would
            // collapse onto them: it keeps the embedding's places, as it keeps its
            // representatives above.
            let landmark_count = members.iter().filter(|&&j| anchored[j]).count();
            if let Some(floor) = p.timelines.filter(|_| landmark_count >= 3) {
                super::timelines::place_on_timelines(&mut points, &enc, &members, &anchored, floor);
            }
        }
        let opts = RipsOptions {
            maxdim: 1,
            threshold: None,
            cycles: true,
            threads: 0,
        };
        // The diagram, its vertices as events, and the distances between its vertices (for
        // the holes' tight cycles).
        let (diagram, reps, vertex_metric) = match (&p.embedding_rips, p.witness) {
            (Some(er), _) => {
                let coords: Vec<[f64; 3]> = members.iter().map(|&j| points[j]).collect();
                let er = er.for_share(members.len() as f64 / mapped as f64);
                let (diagram, picks) =
                    super::dense::dense_rips(&coords, &er, &opts).expect("finite embedding");
                let picked = picks.iter().map(|&k| coords[k]).collect();
                let metric = VertexMetric::Coords(picked, er.dims.clamp(2, 3));
                (diagram, picks.iter().map(|&k| members[k]).collect(), metric)
            }
            (None, Some(nu)) => {
                let metric = super::witness::lazy_witness(&sub.rows, &members, nu);
                let diagram = rips_matrix(&metric, &opts);
                (diagram, sub.picks.clone(), VertexMetric::Matrix(metric))
            }
            (None, None) => {
                let m = sub.picks.len();
                let metric = DistanceMatrix::from_fn(m, |a, b| sub.rows[a][sub.picks[b]]);
                let diagram = rips_matrix(&metric, &opts);
                (diagram, sub.picks.clone(), VertexMetric::Matrix(metric))
            }
        };
        for &j in &members {
            noise[j] = false;
        }
        rows_out.extend(sub.picks.iter().copied().zip(sub.rows));
        // The moving agents' time lines on the plane, for the bars' crossing shares: an
        // agent is moving at an encounter unless it is a landmark then.
        let lines = p.embedding_rips.is_some().then(|| {
            super::crossing::TimeLines::new(&points, &enc, &members, |agent, j| {
                !landmark_of.get(&agent).is_some_and(|v| {
                    v.iter()
                        .any(|&(start, end)| start <= enc[j].end && enc[j].start <= end)
                })
            })
        });
        raw.push((members, diagram, reps, vertex_metric, lines));
    }
    let vertices: usize = raw.iter().map(|r| r.2.len()).sum();
    let events_per_point = if vertices == 0 {
        0.0
    } else {
        mapped as f64 / vertices as f64
    };
    let classifier = p.classifier.pick(events_per_point).classifier;
    for (members, diagram, reps, vertex_metric, lines) in raw {
        let mut features = super::classify::features(&diagram);
        let sigma = sampling_scale(&features);
        // The long H1 bars' crossing shares and, where asked or judged by, their split
        // stabilities: one floor for both (`STABILITY_FLOOR` is `CROSSING_FLOOR`).
        let floor = super::stability::STABILITY_FLOOR * sigma;
        let long = |f: &super::classify::Feature| {
            f.dim == 1 && f.death.is_finite() && f.death - f.birth >= floor
        };
        let halves = p
            .embedding_rips
            .as_ref()
            .filter(|_| p.stability || classifier.h1_stability.is_some())
            .filter(|_| features.iter().any(long))
            .map(|er| {
                let coords: Vec<[f64; 3]> = members.iter().map(|&j| points[j]).collect();
                let er = er.for_share(members.len() as f64 / mapped as f64);
                super::stability::component_halves(&enc, &members, &coords, &er)
            });
        if lines.is_some() || halves.is_some() {
            let plane = |k: usize| [points[reps[k]][0], points[reps[k]][1]];
            for (bar, f) in diagram.bars.iter().zip(features.iter_mut()) {
                if !long(f) {
                    continue;
                }
                if let Some(t) = bar.death_triangle {
                    let (centre, r) = super::crossing::void_disc(t.map(plane), f.death);
                    if let Some(lines) = &lines {
                        f.crossing = lines.share(centre, r);
                    }
                    if let Some(halves) = &halves {
                        f.stability = Some(super::stability::stability(halves, centre, r, sigma));
                    }
                }
            }
        }
        let mut betti = [0, 0];
        let mut bars = Vec::new();
        let mut holes = Vec::new();
        let candidate_rule = classifier.candidate();
        // The loop that hugs the hole, not the engine's representative, which can run round
        // most of the domain: the global map tells holes apart by their cycles (`stitch`),
        // and the report draws them.
        let hole = |bar: &crate::topology::rips::Bar, f: &super::classify::Feature| Hole {
            birth: f.birth,
            death: f.death,
            cycle: bar
                .cycle
                .as_ref()
                .map(|c| {
                    let n = vertex_metric.len();
                    let tight = tighten_cycle(n, |a, b| vertex_metric.dist(a, b), c);
                    tight
                        .as_deref()
                        .unwrap_or(c)
                        .iter()
                        .map(|&(x, y)| (reps[x], reps[y]))
                        .collect()
                })
                .unwrap_or_default(),
            void: bar.death_triangle.map(|t| t.map(|x| reps[x])),
        };
        let mut candidates = Vec::new();
        for (bar, f) in diagram.bars.iter().zip(&features) {
            let robust = classifier.robust(f, sigma);
            if robust && f.dim < 2 {
                betti[f.dim] += 1;
            }
            if robust && f.dim == 1 {
                holes.push(hole(bar, f));
            } else if f.dim == 1 && candidate_rule.robust(f, sigma) {
                candidates.push(hole(bar, f));
            }
            bars.push(MapBar {
                dim: f.dim,
                birth: f.birth,
                death: f.death.is_finite().then_some(f.death),
                robust,
                void: if f.dim == 1 {
                    bar.death_triangle.map(|t| t.map(|x| reps[x]))
                } else {
                    None
                },
                crossing: f.crossing,
                stability: f.stability,
            });
        }
        components.push(Component {
            events: members,
            representatives: reps,
            scale: sigma,
            diagram: bars,
            betti,
            holes,
            candidates,
        });
    }
    let betti = components
        .iter()
        .fold([0, 0], |acc, c| [acc[0] + c.betti[0], acc[1] + c.betti[1]]);
    let explained = if explained.is_empty() {
        0.0
    } else {
        explained.iter().sum::<f64>() / explained.len() as f64
    };
    LocalMap {
        index: window.index,
        start: window.start,
        end: window.end,
        events,
        points,
        noise,
        components,
        betti,
        explained,
        events_per_point,
        classifier,
        outlier_rank: p.subsample.k,
        rows: rows_out,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mapping::synthetic::{SyntheticParams, synthetic_log};
    use crate::world::{MappingMethod, MappingParams};

    /// One window over the whole log, and the `Embedded` method's parameters.
    fn whole_log_embedded(log: &EncounterLog) -> (Window, LocalParams) {
        let span = log.span().unwrap();
        let window = Window {
            index: 1,
            start: span.0,
            end: span.1,
        };
        let params = LocalParams::from_mapping(&MappingParams {
            method: MappingMethod::Embedded,
            ..MappingParams::default()
        });
        (window, params)
    }

    /// The `Embedded` method anchors its cloud on encounters with landmarks. A log without
    /// landmark intervals (a real experiment that logged none) must still map every region
    /// of the window as a component, embedded from all its encounters, not lose it: before
    /// the fallback, every window of such a log came out with β0 = 0.
    #[test]
    fn a_log_without_landmarks_keeps_its_components() {
        let log = synthetic_log(&SyntheticParams::default(), 3000);
        let (window, params) = whole_log_embedded(&log);
        let anchored = local_map(&log, &window, &params);
        assert_eq!(anchored.components.len(), 1);
        assert_eq!(anchored.betti[0], 1);

        let mut bare = log.clone();
        bare.static_intervals.clear();
        let map = local_map(&bare, &window, &params);
        assert_eq!(map.components.len(), 1, "the region is one component");
        assert_eq!(map.betti[0], 1);
        let c = &map.components[0];
        assert!(c.representatives.len() >= 3);
        // Every event of the component is placed, at finite coordinates off the origin
        // where noise sits.
        assert!(
            c.events
                .iter()
                .all(|&j| !map.noise[j] && map.points[j].iter().all(|x| x.is_finite()))
        );
        assert!(c.events.iter().any(|&j| map.points[j] != [0.0; 3]));
    }

    /// A component whose landmark encounters all stand at one place (a single landmark
    /// interval: a real log that recorded one) is embedded from all its encounters: from
    /// that one place, MaxMin picked the same spot twice and landmark MDS put every event
    /// at the origin (found by the forty-first session's review).
    #[test]
    fn a_component_anchored_at_one_place_is_embedded_from_all_its_encounters() {
        let mut log = synthetic_log(&SyntheticParams::default(), 3000);
        let (window, params) = whole_log_embedded(&log);
        let first = log
            .static_intervals
            .iter()
            .position(|s| s.reason == crate::log::StaticReason::Landmark)
            .unwrap();
        log.static_intervals = vec![log.static_intervals[first].clone()];
        let map = local_map(&log, &window, &params);
        assert_eq!(map.components.len(), 1);
        let c = &map.components[0];
        assert!(c.representatives.len() >= 3, "{:?}", c.representatives);
        let mut places: Vec<[u64; 3]> = c
            .events
            .iter()
            .map(|&j| map.points[j].map(f64::to_bits))
            .collect();
        places.sort_unstable();
        places.dedup();
        assert!(
            places.len() * 2 > c.events.len(),
            "{} places for {} events",
            places.len(),
            c.events.len()
        );
    }

    /// With `after_landmarks`, encounters that end before the first landmark is selected
    /// are not mapped (the paper's swarm records encounters once its landmarks stand); a
    /// window that ends before any landmark is selected maps all of its encounters.
    #[test]
    fn encounters_before_the_first_landmark_are_left_out() {
        let mut log = synthetic_log(&SyntheticParams::default(), 3000);
        let (window, mut params) = whole_log_embedded(&log);
        params.after_landmarks = true;
        let from = 0.5 * (window.start + window.end);
        // Landmarks are selected at `from`: intervals before it go, those across it start there.
        log.static_intervals.retain(|s| s.end >= from);
        for s in &mut log.static_intervals {
            s.start = s.start.max(from);
        }
        assert_eq!(first_landmark_start(&log, &window), Some(from));
        let map = local_map(&log, &window, &params);
        let expected: Vec<usize> = (0..log.encounters.len())
            .filter(|&i| log.encounters[i].end >= from)
            .collect();
        assert!(expected.len() < log.encounters.len() && !expected.is_empty());
        assert_eq!(map.events, expected);
        // Off (the default), every encounter of the window is mapped.
        params.after_landmarks = false;
        let all = local_map(&log, &window, &params);
        assert_eq!(all.events, (0..log.encounters.len()).collect::<Vec<_>>());
        params.after_landmarks = true;

        let early = Window {
            index: 1,
            start: window.start,
            end: from - 1.0,
        };
        assert_eq!(first_landmark_start(&log, &early), None);
        let map = local_map(&log, &early, &params);
        let expected: Vec<usize> = (0..log.encounters.len())
            .filter(|&i| early.meets(log.encounters[i].start, log.encounters[i].end))
            .collect();
        assert_eq!(map.events, expected);
    }

    /// Two regions that no agent joins are two components, and each gets planar Rips
    /// points in proportion to its share of the window's encounters
    /// ([`super::super::dense::DenseParams::for_share`]): a component is sampled at the
    /// density of a one-component window, not at twice it because it is half the window.
    #[test]
    fn components_share_the_points_by_their_encounters() {
        let big = synthetic_log(&SyntheticParams::default(), 6000);
        let small = synthetic_log(
            &SyntheticParams {
                seed: 2,
                ..SyntheticParams::default()
            },
            3000,
        );
        let offset = 1000;
        let mut log = big.clone();
        log.encounters
            .extend(small.encounters.iter().cloned().map(|mut e| {
                e.a += offset;
                e.b += offset;
                e
            }));
        log.static_intervals
            .extend(small.static_intervals.iter().cloned().map(|mut s| {
                s.agent += offset;
                s
            }));
        log.encounters.sort_by(|x, y| {
            x.start
                .total_cmp(&y.start)
                .then(x.a.cmp(&y.a))
                .then(x.b.cmp(&y.b))
        });
        log.static_intervals
            .sort_by(|x, y| x.agent.cmp(&y.agent).then(x.start.total_cmp(&y.start)));
        let (window, params) = whole_log_embedded(&log);
        let map = local_map(&log, &window, &params);
        assert_eq!(map.components.len(), 2);
        let mapped: usize = map.components.iter().map(|c| c.events.len()).sum();
        for c in &map.components {
            let share = c.events.len() as f64 / mapped as f64;
            let expected = (super::super::dense::EMBEDDED_POINTS as f64 * share).round();
            assert_eq!(
                c.representatives.len() as f64,
                expected,
                "{} of {mapped} events",
                c.events.len()
            );
        }
    }

    /// Split stabilities are computed only when asked for (`mapping.split_stability`) or
    /// when the window's model has a stability test, and then for exactly the H1 bars with
    /// a life of at least `STABILITY_FLOOR` σ; a model's stability test gates robustness.
    #[test]
    fn stabilities_are_computed_when_asked_or_judged_by() {
        let log = synthetic_log(&SyntheticParams::default(), 3000);
        let (window, mut params) = whole_log_embedded(&log);
        let stable_bars = |map: &LocalMap| -> Vec<Option<f64>> {
            map.components
                .iter()
                .flat_map(|c| c.diagram.iter().map(|b| b.stability))
                .collect()
        };
        let plain = local_map(&log, &window, &params);
        assert!(stable_bars(&plain).iter().all(Option::is_none));

        params.stability = true;
        let asked = local_map(&log, &window, &params);
        let floor = super::super::stability::STABILITY_FLOOR;
        let mut with = 0;
        for c in &asked.components {
            for b in &c.diagram {
                let long = b.dim == 1
                    && b.void.is_some()
                    && b.death.is_some_and(|d| d - b.birth >= floor * c.scale);
                assert_eq!(b.stability.is_some(), long, "{b:?}");
                assert!(b.stability.is_none_or(|x| x.is_finite() && x >= 0.0));
                with += usize::from(long);
            }
        }
        assert!(with > 0, "some loop is long enough to get a stability");
        // The stabilities change nothing else.
        assert_eq!(asked.betti, plain.betti);
        assert_eq!(asked.points, plain.points);

        // A model with a stability test gets them without being asked, and keeps only the
        // bars that pass it: none, at a stability no loop reaches.
        params.stability = false;
        let mut c = params.classifier.first().classifier;
        c.h1_ratio = 1.0;
        c.h1_span = 1.0;
        params.classifier = Bank::single(c);
        let loose = local_map(&log, &window, &params);
        assert!(
            loose.betti[1] > 0,
            "a lenient persistence rule keeps some loop"
        );
        c.h1_stability = Some(1e6);
        params.classifier = Bank::single(c);
        let gated = local_map(&log, &window, &params);
        assert_eq!(stable_bars(&gated), stable_bars(&asked));
        assert_eq!(gated.betti[1], 0);
    }

    #[test]
    fn rips_points_sets_the_embedded_methods_planar_points() {
        let mut m = crate::world::MappingParams {
            method: crate::world::MappingMethod::Embedded,
            ..Default::default()
        };
        let shipped = LocalParams::from_mapping(&m)
            .embedding_rips
            .expect("Embedded");
        assert_eq!(shipped.m, super::super::dense::EMBEDDED_POINTS);
        m.rips_points = 2400;
        let p = LocalParams::from_mapping(&m)
            .embedding_rips
            .expect("Embedded");
        assert_eq!(p, super::super::dense::DenseParams::embedded_with(2400));
        m.method = crate::world::MappingMethod::Paper;
        assert!(LocalParams::from_mapping(&m).embedding_rips.is_none());
    }

    /// The outlier rank scales with the sweep unless the mapping settings fix it.
    #[test]
    fn outlier_rank_follows_the_sweep_unless_set() {
        let mut m = crate::world::MappingParams::default();
        for (sweep, k) in [(0.005, 8), (0.0025, 16), (0.02, 2)] {
            assert_eq!(LocalParams::from_mapping_at(&m, sweep).subsample.k, k);
        }
        m.outlier_rank = Some(12);
        for sweep in [0.005, 0.0025, 0.02] {
            assert_eq!(LocalParams::from_mapping_at(&m, sweep).subsample.k, 12);
        }
    }
}
