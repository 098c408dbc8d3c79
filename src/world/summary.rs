//! Loading a world from a file, the time windows of the mapping (paper §"Dynamic
//! Topological Mapping", eq. for W_i), and the short summary `swarmmap check` prints.

use super::check::{given, landmark_count, short};
use super::error::WorldError;
use super::freespace::FreeSpaceRaster;
use super::spec::{WorldSpec, parse_str};
use super::types::{Obstacle, Placement, World};
use std::fmt::Write as _;
use std::path::Path;

impl WorldSpec {
    /// Reads and parses a world file (not yet checked; apply overrides, then `check`).
    pub fn load(path: impl AsRef<Path>) -> Result<WorldSpec, WorldError> {
        let path = path.as_ref();
        let bytes = std::fs::read(path).map_err(|source| WorldError::Read {
            path: path.display().to_string(),
            source,
        })?;
        let text = String::from_utf8(bytes).map_err(|e| {
            // Where the first byte that is not UTF-8 lies, as line:col.
            let good = &e.as_bytes()[..e.utf8_error().valid_up_to()];
            let before = String::from_utf8_lossy(good);
            let line = before.matches('\n').count() + 1;
            let col = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
            WorldError::Syntax {
                origin: path.display().to_string(),
                line,
                col,
                message: "this byte is not UTF-8 text; save the world file as UTF-8 (it is \
                          read as UTF-8 whatever the editor's default)"
                    .into(),
            }
        })?;
        parse_str(&text, &path.display().to_string())
    }
}

impl World {
    /// Reads, parses and checks a world file.
    pub fn load(path: impl AsRef<Path>) -> Result<World, WorldError> {
        WorldSpec::load(path)?.check()
    }

    /// Parses and checks RON `text`; `name` labels error positions (`name:line:col`)
    /// and is the default world name (its file stem).
    pub fn from_str_named(text: &str, name: &str) -> Result<World, WorldError> {
        parse_str(text, name)?.check()
    }

    /// The mapping's time windows `W_i = [t_{i−1} − Δt/2, t_i + Δt/2]`, `i = 1..N`, with
    /// `t_i = i·T/N` evenly spaced over the whole run `[0, T]` (T = dispersion + sweep)
    /// and clipped to it, so that they cover `[0, T]` (paper §"Dynamic Topological
    /// Mapping"). Seconds.
    pub fn window_spans(&self) -> Vec<(f64, f64)> {
        crate::mapping::windows::windows(
            0.0,
            self.total_duration(),
            self.mapping.windows.max(1),
            self.mapping.overlap,
        )
        .iter()
        .map(|w| (w.start, w.end))
        .collect()
    }

    /// The x-range in metres covered by D(t) over the time span `(t0, t1)`: the union of
    /// the windows the leader passes through.
    pub fn span_domain(&self, span: (f64, f64)) -> (f64, f64) {
        let (a, b) = (self.domain(span.0), self.domain(span.1));
        (a.0.min(b.0), a.1.max(b.1))
    }

    /// A short human-readable summary: arena, obstacles, swarm, sweep, windows.
    pub fn summary(&self) -> String {
        let mut s = String::new();
        let kinds = ["Rect", "Circle", "Polygon", "Wall"];
        let mut counts = [0usize; 4];
        for o in &self.obstacles {
            counts[match o {
                Obstacle::Rect { .. } => 0,
                Obstacle::Circle { .. } => 1,
                Obstacle::Polygon { .. } => 2,
                Obstacle::Wall { .. } => 3,
            }] += 1;
        }
        let by_kind: Vec<String> = kinds
            .iter()
            .zip(counts)
            .filter(|(_, c)| *c > 0)
            .map(|(k, c)| format!("{c} {k}"))
            .collect();
        let sw = &self.swarm;
        let landmarks = landmark_count(sw.landmark_fraction, sw.agents);
        let placement = match sw.placement {
            Placement::Disk { radius } => format!("a disc of radius {} m", given(radius)),
            Placement::Window => "the initial window".to_string(),
        };
        let raster = FreeSpaceRaster::new(self, sw.body_radius);
        let area = self.arena.width * self.arena.height;
        let _ = writeln!(s, "world      {}", self.name);
        let _ = writeln!(
            s,
            "arena      {} m × {} m (x along the sweep), free for agent centres: {:.1} % in {} connected region(s) ({:.0} mm raster)",
            given(self.arena.width),
            given(self.arena.height),
            100.0 * raster.free_area() / area,
            raster.components(),
            1000.0 * raster.cx.max(raster.cy)
        );
        let _ = writeln!(
            s,
            "obstacles  {}{}",
            self.obstacles.len(),
            if by_kind.is_empty() {
                String::new()
            } else {
                format!(" ({})", by_kind.join(", "))
            }
        );
        let _ = writeln!(
            s,
            "swarm      {} agent{}, {} landmark{} ({} %), r_d = {} m, v_m = {} m/s, body radius {} m, placed in {}",
            sw.agents,
            if sw.agents == 1 { "" } else { "s" },
            landmarks,
            if landmarks == 1 { "" } else { "s" },
            short(100.0 * sw.landmark_fraction),
            given(sw.detection_radius),
            given(sw.speed),
            given(sw.body_radius),
            placement
        );
        let l = &self.leader;
        let _ = writeln!(
            s,
            "leader     sweeps x {} → {} m at {} m/s, window l = {} m",
            given(l.start_x),
            given(l.end_x),
            given(l.speed),
            given(l.window)
        );
        let _ = writeln!(
            s,
            "time       dispersion {} s + sweep {} s = {} s, dt = {} s ({} steps)",
            given(self.simulation.dispersion_time),
            given(self.sweep_duration()),
            given(self.total_duration()),
            given(self.simulation.dt),
            (self.total_duration() / self.simulation.dt).ceil()
        );
        let _ = writeln!(
            s,
            "windows    {} with overlap Δt = {} s:",
            self.mapping.windows,
            given(self.mapping.overlap)
        );
        for (i, span) in self.window_spans().iter().enumerate() {
            let (x0, x1) = self.span_domain(*span);
            let _ = writeln!(
                s,
                "  W{:<3} t {:>9.1} – {:>9.1} s   D covers x {:>6.2} – {:>6.2} m",
                i + 1,
                span.0,
                span.1,
                x0,
                x1
            );
        }
        let m = &self.mapping;
        let _ = writeln!(
            s,
            "mapping    {:?} method, switch cost {} s, c = {}, m = {}, outlier rank {}, k = {}; {}; {}{}",
            m.method,
            given(m.switch_cost),
            given(m.cluster_cutoff),
            m.subsample,
            match m.outlier_rank {
                Some(k) => k.to_string(),
                None => format!(
                    "{} (from the sweep)",
                    crate::mapping::subsample::rank_for_sweep(self.leader.speed)
                ),
            },
            m.neighbours,
            if m.after_landmarks {
                "encounters after the first landmark"
            } else {
                "every encounter"
            },
            if m.encounter_midpoints {
                "weights between encounter middles"
            } else {
                "the paper's interval-gap weights"
            },
            if m.method == super::MappingMethod::Embedded {
                format!(
                    "; {} planar Rips points{}{}",
                    m.rips_points,
                    if m.agent_timelines {
                        "; encounters placed on their agents' time lines"
                    } else {
                        ""
                    },
                    if m.split_stability {
                        "; split stability of every loop"
                    } else {
                        ""
                    }
                )
            } else {
                String::new()
            }
        );
        let _ = write!(s, "seed       {}", self.seed);
        s
    }

    /// What a valid world will not do that its author likely wants (printed by `swarmmap
    /// check` as warnings; `run` and `map` say the same of the run's log afterwards).
    pub fn warnings(&self) -> Vec<String> {
        let sw = &self.swarm;
        let mut out = Vec::new();
        if sw.agents < 2 {
            out.push(
                "1 agent meets no one: the run will record no encounters and every map will \
                 be empty; give swarm.agents at least 2"
                    .to_string(),
            );
        } else if landmark_count(sw.landmark_fraction, sw.agents) == 0 {
            out.push(format!(
                "no agent will be a landmark, even with every agent inside the leader's \
                 domain (round(swarm.landmark_fraction × agents) = round({} × {}) = 0; \
                 the simulator counts only the agents inside it): no static agent bridges \
                 time or stands through the \
                 windows' overlaps, so consecutive local maps cannot be stitched; raise \
                 swarm.landmark_fraction (the paper's is 0.1) or swarm.agents",
                given(sw.landmark_fraction),
                sw.agents
            ));
        }
        out
    }
}
