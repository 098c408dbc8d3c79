//! The validated world and its parameter groups. Every default is the paper's value
//! where the paper gives one (§"Simulation Results"); the others are justified in the
//! README ("World files").

/// A 2-D point or vector in metres.
pub type Vec2 = (f64, f64);

/// The rectangular arena `[0, width] × [0, height]`; the leader sweeps along x.
#[derive(Debug, Clone, PartialEq)]
pub struct Arena {
    /// Width in metres, along the sweep (paper: `30.0`).
    pub width: f64,
    /// Height in metres (paper: `10.0`).
    pub height: f64,
}

/// A static obstacle. Obstacles may overlap each other and touch the arena's sides.
#[derive(Debug, Clone, PartialEq)]
pub enum Obstacle {
    /// Axis-aligned rectangle.
    Rect { min: Vec2, max: Vec2 },
    /// Disc.
    Circle { center: Vec2, radius: f64 },
    /// Simple polygon (possibly non-convex), vertices in order.
    Polygon { points: Vec<Vec2> },
    /// Thick segment: the set of points within `thickness / 2` of the segment.
    Wall {
        from: Vec2,
        to: Vec2,
        thickness: f64,
    },
}

/// How agents are placed at `t = 0`.
#[derive(Debug, Clone, PartialEq)]
pub enum Placement {
    /// Uniformly in the free part of a disc of `radius` metres centred on the leader's
    /// start at mid-height (default, radius `1.0`).
    Disk { radius: f64 },
    /// Uniformly in the free part of the initial domain D(0).
    Window,
}

/// The swarm of ground agents (paper §"Motion Model", §"Sensing and Communication").
#[derive(Debug, Clone, PartialEq)]
pub struct SwarmParams {
    /// Number of agents (default: `100`).
    pub agents: usize,
    /// Random-walk speed v_m in m/s (default: `0.1`).
    pub speed: f64,
    /// Detection radius r_d in metres: an encounter is two centres within r_d (default: `0.01`).
    pub detection_radius: f64,
    /// Share of the agents inside D(t) held static as landmarks (default: `0.1`).
    pub landmark_fraction: f64,
    /// Radius of an agent's solid body in metres (default: `0.004`; must be below r_d / 2
    /// so that two agents can come within r_d before their bodies touch).
    pub body_radius: f64,
    /// Mean run length λ of the random walk in metres (default: `1.0`).
    pub mean_run_length: f64,
    /// Rate of spontaneous stops while walking, per second (default: `0.01`).
    pub stop_rate: f64,
    /// Mean duration of a spontaneous stop in seconds (default: `5.0`).
    pub mean_stop_duration: f64,
    /// Communication radius in metres used for the hop graph of landmark selection
    /// (default: `1.0`).
    pub comm_radius: f64,
    /// Probability that a walking agent's collision with an obstacle or the arena's side
    /// starts wall following instead of a turn (default: `0.0`, the paper's pure random
    /// walk; the cockroach model it cites has both, Jeanson et al. 2003).
    pub wall_following: f64,
    /// Mean length followed along a wall before the agent turns away, metres
    /// (exponentially distributed; default: `1.0`).
    pub wall_following_length: f64,
    /// Seconds a returning agent (outside D(t)) follows the leader's gradient without
    /// regaining D(t) before it walks at random for a while to leave a nook the gradient
    /// keeps it in (default: `300.0`; a very large value disables the escape).
    pub return_patience: f64,
    /// Keep the landmarks when D(t) holds fewer agents than their count asks for, instead
    /// of releasing the newest (default: `false`). A landmark is then released only when
    /// it leaves D(t) (the paper's rule), and shortfalls are still filled; the count stays
    /// at most `round(landmark_fraction × agents)`.
    pub keep_surplus_landmarks: bool,
    /// Initial placement (default: `Disk(radius: 1.0)`).
    pub placement: Placement,
}

impl Default for SwarmParams {
    fn default() -> Self {
        Self {
            agents: 100,
            speed: 0.1,
            detection_radius: 0.01,
            landmark_fraction: 0.1,
            body_radius: 0.004,
            mean_run_length: 1.0,
            stop_rate: 0.01,
            mean_stop_duration: 5.0,
            comm_radius: 1.0,
            wall_following: 0.0,
            wall_following_length: 1.0,
            return_patience: 300.0,
            keep_surplus_landmarks: false,
            placement: Placement::Disk { radius: 1.0 },
        }
    }
}

/// The leading agent and its domain D(t): the full-height band `[x(t) − l/2, x(t) + l/2]`.
#[derive(Debug, Clone, PartialEq)]
pub struct LeaderParams {
    /// Sweep speed along x in m/s (default: `0.005`).
    pub speed: f64,
    /// Window length l in metres (default: `3.0`).
    pub window: f64,
    /// x where the sweep starts, metres (default: `window / 2`).
    pub start_x: f64,
    /// x where the sweep ends, metres (default: `width − window / 2`).
    pub end_x: f64,
}

/// Time stepping.
#[derive(Debug, Clone, PartialEq)]
pub struct SimulationParams {
    /// Physics time step in seconds (default: `0.03`; see the README, "The simulation" / "Time step").
    pub dt: f64,
    /// Dispersion time in seconds before the leader starts (default: `300.0`).
    pub dispersion_time: f64,
}

impl Default for SimulationParams {
    fn default() -> Self {
        Self {
            dt: 0.03,
            dispersion_time: 300.0,
        }
    }
}

/// Which local-mapping method to run (issue #4 adds improved methods).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MappingMethod {
    /// The paper's method exactly (§"Geometric Reconstruction"): Rips on the encounter
    /// metric of m MaxMin representatives.
    Paper,
    /// Representatives anchored at static landmarks, the encounter point cloud embedded by
    /// landmark MDS, and Rips on its density-filtered plane (see `mapping::local`).
    Embedded,
}

/// Parameters of the mapping stages (paper §"Dynamic Topological Mapping").
#[derive(Debug, Clone, PartialEq)]
pub struct MappingParams {
    /// Number of windows N (default: `4`).
    pub windows: usize,
    /// Overlap Δt between consecutive windows in seconds (default: `300.0`).
    pub overlap: f64,
    /// Single-linkage cut-off c for stitching, in the metric's units (default: `50.0`).
    pub cluster_cutoff: f64,
    /// Number of representative encounters m per window (default: `400`).
    pub subsample: usize,
    /// Neighbours k added around each static encounter in the inter-domain cloud (default: `5`).
    pub neighbours: usize,
    /// Local-mapping method (default: `Paper`).
    pub method: MappingMethod,
    /// Cost in seconds of every change of agent along a path of the encounter graph
    /// (`mapping::encounter_graph`, "Agent switches"; default: `0.0`, the paper's metric).
    pub switch_cost: f64,
    /// Map only the encounters that end once the first landmark is selected, as the paper
    /// records them (`mapping::local::first_landmark_start`; default: `false`, every
    /// encounter of the log, the dispersion's included).
    pub after_landmarks: bool,
    /// Along an agent's time line, weigh two encounters by the time between their middles
    /// (the moments of closest approach) instead of the gap between their intervals
    /// (`mapping::encounter_graph`, "Encounter middles"; default: `false`, the paper's
    /// weight).
    pub encounter_midpoints: bool,
    /// Points of the planar Vietoris–Rips complex of the `Embedded` method and of the
    /// truth-position oracle, MaxMin-picked from a window's events and shared among its
    /// components (`mapping::dense`; default: `1200`).
    pub rips_points: usize,
    /// The `Embedded` method places the encounters of moving agents on their agents' time
    /// lines, pinned by the encounters with landmarks (`mapping::timelines`), after the
    /// bridge between exit landmarks (default: `false`).
    pub agent_timelines: bool,
    /// The `Embedded` method computes every H1 bar's split stability
    /// (`mapping::stability`) even when the window's model has no stability test (a model
    /// with one always gets them; default: `false`). For fitting one: `swarmmap calibrate
    /// --stability`.
    pub split_stability: bool,
    /// Neighbour rank k of the subsampling's outlier filter (`mapping::subsample`; default:
    /// `None`, k scaled with the leader's sweep: `subsample::rank_for_sweep`, 8 at the
    /// paper's 0.005 m/s).
    pub outlier_rank: Option<usize>,
}

impl Default for MappingParams {
    fn default() -> Self {
        Self {
            windows: 4,
            overlap: 300.0,
            cluster_cutoff: 50.0,
            subsample: 400,
            neighbours: 5,
            method: MappingMethod::Paper,
            switch_cost: 0.0,
            after_landmarks: false,
            encounter_midpoints: false,
            rips_points: crate::mapping::dense::EMBEDDED_POINTS,
            agent_timelines: false,
            split_stability: false,
            outlier_rank: None,
        }
    }
}

/// A validated world: every number finite and in range, every obstacle inside the arena.
#[derive(Debug, Clone, PartialEq)]
pub struct World {
    /// Name, used in outputs.
    pub name: String,
    pub arena: Arena,
    pub obstacles: Vec<Obstacle>,
    pub swarm: SwarmParams,
    pub leader: LeaderParams,
    pub simulation: SimulationParams,
    pub mapping: MappingParams,
    /// Seed of every random choice (default: `1`).
    pub seed: u64,
}

impl World {
    /// An obstacle-free arena with every other parameter at its default; handy in tests.
    pub fn empty(name: &str, width: f64, height: f64) -> Self {
        let window = 3.0f64.min(width);
        Self {
            name: name.to_string(),
            arena: Arena { width, height },
            obstacles: Vec::new(),
            swarm: SwarmParams::default(),
            leader: LeaderParams {
                speed: 0.005,
                window,
                start_x: window / 2.0,
                end_x: width - window / 2.0,
            },
            simulation: SimulationParams::default(),
            mapping: MappingParams::default(),
            seed: 1,
        }
    }

    /// Duration of the sweep in seconds, dispersion excluded.
    pub fn sweep_duration(&self) -> f64 {
        (self.leader.end_x - self.leader.start_x).abs() / self.leader.speed
    }

    /// Total simulated time in seconds: dispersion plus sweep.
    pub fn total_duration(&self) -> f64 {
        self.simulation.dispersion_time + self.sweep_duration()
    }

    /// Leader x at time `t` (held at `start_x` during dispersion).
    pub fn leader_x(&self, t: f64) -> f64 {
        let s = (t - self.simulation.dispersion_time).max(0.0) * self.leader.speed;
        let (a, b) = (self.leader.start_x, self.leader.end_x);
        if b >= a {
            (a + s).min(b)
        } else {
            (a - s).max(b)
        }
    }

    /// The domain D(t) as `(x_min, x_max)`, clipped to the arena; it spans the full height.
    pub fn domain(&self, t: f64) -> (f64, f64) {
        let x = self.leader_x(t);
        let h = self.leader.window / 2.0;
        ((x - h).max(0.0), (x + h).min(self.arena.width))
    }
}
