//! The encounter log: what the swarm records (paper §"Sensing and Communication", eq. for
//! E_i = [t_0, t_1, ID¹, ID²]) and what every mapping stage reads.
//!
//! A log comes from the simulator or from a real experiment. The mapping reads only the
//! coordinate-free columns; the ground-truth columns (true positions at the start of an
//! encounter) are optional and read only by evaluation.

/// Agent identifier (index into the swarm).
pub type AgentId = u32;

/// One encounter: agents `a < b` had their centres within r_d during `[start, end]`.
#[derive(Debug, Clone, PartialEq)]
pub struct Encounter {
    /// Start time in seconds.
    pub start: f64,
    /// End time in seconds (`>= start`).
    pub end: f64,
    pub a: AgentId,
    pub b: AgentId,
    /// Ground truth, if known: the true positions of `a` and `b` at `start`, metres.
    pub truth: Option<[f64; 4]>,
}

/// Why an agent was static.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StaticReason {
    /// Held static as a landmark (MaxMin selection).
    Landmark,
    /// A spontaneous stop of the random walk.
    Pause,
}

impl StaticReason {
    /// The name used in `static_intervals.csv`.
    pub fn as_str(self) -> &'static str {
        match self {
            StaticReason::Landmark => "landmark",
            StaticReason::Pause => "pause",
        }
    }
}

/// An interval `[start, end]` during which `agent` did not move.
#[derive(Debug, Clone, PartialEq)]
pub struct StaticInterval {
    pub agent: AgentId,
    pub start: f64,
    pub end: f64,
    pub reason: StaticReason,
}

/// A complete log: encounters sorted by `(start, a, b)`, static intervals sorted by
/// `(agent, start)`, and the leader's track as `(time, x)` samples.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct EncounterLog {
    pub encounters: Vec<Encounter>,
    pub static_intervals: Vec<StaticInterval>,
    pub leader: Vec<(f64, f64)>,
}
