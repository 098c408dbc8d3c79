//! What a simulation run takes besides the world, and what it returns.

use crate::log::{AgentId, EncounterLog};
use std::path::PathBuf;

/// Where [`SimOptions::with_prefixes`] offers a prefix: its cut's index and a function that
/// builds it (a copy of the log so far, so a sink that cannot take it now should not call it).
pub type PrefixSink<'a> = dyn Fn(usize, &dyn Fn() -> EncounterLog) + 'a;

/// Options of one run that are not part of the world.
#[derive(Clone, Copy)]
pub struct SimOptions<'a> {
    /// Seed of every random choice of the run (the CLI defaults it to the world's `seed`).
    pub seed: u64,
    /// Record agent positions every this many seconds of simulated time (rounded to a whole
    /// number of time steps, at least one); `None` records none (default: `None`).
    pub trajectories: Option<f64>,
    /// Called now and then with the fraction of the run done, in `[0, 1]`.
    pub progress: Option<&'a dyn Fn(f64)>,
    /// Cut times (ascending) and where to hand the log's prefixes: see
    /// [`SimOptions::with_prefixes`].
    pub prefixes: Option<(&'a [f64], &'a PrefixSink<'a>)>,
}

impl<'a> SimOptions<'a> {
    /// Options with the given seed, no trajectories and no progress reports.
    #[must_use]
    pub fn new(seed: u64) -> Self {
        Self {
            seed,
            trajectories: None,
            progress: None,
            prefixes: None,
        }
    }

    /// Records trajectories every `interval` seconds of simulated time.
    #[must_use]
    pub fn with_trajectories(mut self, interval: f64) -> Self {
        self.trajectories = Some(interval);
        self
    }

    /// Reports progress through `f`.
    #[must_use]
    pub fn with_progress(mut self, f: &'a dyn Fn(f64)) -> Self {
        self.progress = Some(f);
        self
    }

    /// Hands out the final log's prefixes while the run goes on: for each cut time `c` of
    /// `cuts` (ascending), the cut is settled at the first step time `t ≥ c` at which every
    /// encounter that started at or before `c` has ended; once the encounter detector
    /// (which runs a little behind the physics, on its own thread) has settled it,
    /// `f(k, build)` is called (`k` indexes `cuts`, in order); `build()` returns a log that
    /// holds
    /// - every encounter that started at or before `c`, exactly as the final log will have
    ///   it and in its order (so an index into it is an index into the final log);
    /// - every static interval that had started by `t`, as in the final log, except that
    ///   one running at `t` is cut off one time step after `t` (its true end lies at or
    ///   after that step): later than every encounter end in the prefix, as its true end is;
    /// - the leader's positions up to `t`.
    ///
    /// A cut that only the end of the run settles is not handed out: the final log serves.
    /// Anything that reads only the encounters that meet `[.., c]`, and of the static
    /// intervals only how their ends compare with those encounters' times, gives the same
    /// answer on the prefix as on the final log (the local maps and connections of windows
    /// ending at `c`, `crate::pipeline`).
    #[must_use]
    pub fn with_prefixes(mut self, cuts: &'a [f64], f: &'a PrefixSink<'a>) -> Self {
        self.prefixes = Some((cuts, f));
        self
    }
}

/// What an agent is doing, as it would report it to the leader.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum AgentState {
    /// Random walk inside D(t).
    Walk,
    /// A spontaneous stop of the random walk.
    Pause,
    /// Held static as a landmark.
    Landmark,
    /// Outside D(t), steering back towards the leader.
    Return,
}

impl AgentState {
    /// The name used in `trajectories.csv`.
    pub fn as_str(self) -> &'static str {
        match self {
            AgentState::Walk => "walk",
            AgentState::Pause => "pause",
            AgentState::Landmark => "landmark",
            AgentState::Return => "return",
        }
    }
}

/// One recorded position of one agent.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrajectorySample {
    /// Simulated time in seconds.
    pub time: f64,
    pub agent: AgentId,
    /// True position in metres.
    pub x: f64,
    pub y: f64,
    pub state: AgentState,
}

/// Decimated trajectories of every agent, sorted by `(time, agent)`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Trajectories {
    /// Sampling interval actually used, seconds (a whole number of time steps).
    pub interval: f64,
    pub samples: Vec<TrajectorySample>,
}

/// Counters and timings of a run. Everything but the wall times is deterministic.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SimStats {
    /// Physics steps taken.
    pub steps: u64,
    /// Simulated time in seconds (a whole number of steps, `>= world.total_duration()`).
    pub simulated_time: f64,
    /// Encounters recorded.
    pub encounters: usize,
    /// Static intervals recorded (landmark and pause).
    pub static_intervals: usize,
    /// Spontaneous stops started.
    pub pauses: usize,
    /// Landmarks chosen by the first selection after dispersion.
    pub landmark_selections: usize,
    /// Landmarks chosen later to keep the fraction (replacements of released ones).
    pub landmark_replacements: usize,
    /// Landmarks released because they fell out of D(t).
    pub landmark_releases_outside: usize,
    /// Landmarks released because fewer agents were inside D(t).
    pub landmark_releases_surplus: usize,
    /// Contacts (agent–agent, agent–obstacle or agent–side, presses included) that
    /// triggered a new heading.
    pub collisions: usize,
    /// Wall hits that started wall following (`swarm.wall_following`).
    pub wall_follows: usize,
    /// Continuing touches reported again because the agent was heading into them (turned
    /// there by another contact, the end of a run or a landmark's release): a turn, or
    /// under wall following the start or switch of a follow.
    pub presses: usize,
    /// Escapes (random walks of [`RETURN_ESCAPE`](super::RETURN_ESCAPE) seconds) of
    /// returning agents that had not regained D(t) for `swarm.return_patience` seconds.
    pub return_escapes: usize,
    /// Wall time of the whole run, seconds (not deterministic).
    pub wall_time_s: f64,
    /// Wall time inside the Rapier step, seconds (not deterministic).
    pub physics_time_s: f64,
    /// Wall time of landmark selection, seconds (not deterministic).
    pub landmark_time_s: f64,
    /// Wall time of encounter detection (the sensing world, on its own thread), seconds
    /// (not deterministic).
    pub sensing_time_s: f64,
}

/// The result of [`simulate`](super::simulate).
#[derive(Debug, Clone, PartialEq)]
pub struct SimOutput {
    /// Seed the run used.
    pub seed: u64,
    /// Time step the run used, seconds.
    pub dt: f64,
    /// Interval of `leader.csv` samples, seconds.
    pub leader_interval: f64,
    pub log: EncounterLog,
    pub trajectories: Option<Trajectories>,
    pub stats: SimStats,
}

/// Why a run could not be done or written.
#[derive(Debug, thiserror::Error)]
pub enum SimError {
    /// A world parameter the simulator depends on is out of range (a validated world never
    /// has one; hand-built worlds may).
    #[error("world parameter `{field}` is {}: {expected}", crate::world::given(*value))]
    InvalidWorld {
        field: &'static str,
        value: f64,
        expected: &'static str,
    },
    /// A run option is out of range.
    #[error("option `{option}` is {}: {expected}", crate::world::given(*value))]
    InvalidOption {
        option: &'static str,
        value: f64,
        expected: &'static str,
    },
    /// The agents could not be placed without overlapping obstacles or each other.
    #[error(
        "could not place agent {placed} of {agents} in the free part of the start region \
         after {attempts} tries; enlarge `swarm.placement` or move obstacles away from the \
         leader's start"
    )]
    Placement {
        placed: usize,
        agents: usize,
        attempts: usize,
    },
    /// The physics produced a non-finite position (a bug, reported rather than propagated).
    #[error("agent {agent} reached a non-finite position at t = {time} s")]
    NonFinite { agent: AgentId, time: f64 },
    /// An output file could not be written.
    #[error("cannot write {}: {source}", path.display())]
    Write {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
}
