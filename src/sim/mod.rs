//! The swarm simulation (paper §"Problem Statement", §"Motion Model of the Biobotic
//! Swarm", §"Exploration and Event Collection"): a Rapier 2D scene in which the agents
//! random-walk inside the leader's domain D(t) and record their encounters.
//!
//! **Motion model.** Each agent walks in straight runs at speed v_m whose lengths are
//! exponential with mean λ (`swarm.mean_run_length`), turning isotropically between runs,
//! after Jeanson et al., "A model of animal movements in a bounded space" (J. Theor. Biol.,
//! 2003). A contact with an obstacle, an arena side or another agent ends the run: the agent
//! draws a new heading uniformly among those pointing away from every contact it has just
//! made. Spontaneous stops form a Poisson process of rate `swarm.stop_rate` per walking
//! second and last an exponential time of mean `swarm.mean_stop_duration`; they are logged
//! as `pause` static intervals. An agent whose centre leaves D(t) enters the `return` mode:
//! its headings are drawn within ±60° of the direction of the leader's x (the
//! signal-strength gradient) until it is back inside.
//!
//! **Exploration.** Agents start uniformly in the free part of `swarm.placement` near the
//! leader's start and disperse for `simulation.dispersion_time`. Then, at every step, the
//! number of landmarks is held at round(`landmark_fraction` × agents inside D(t)): landmarks
//! that fall out of D(t) resume walking, surplus landmarks (newest first) are released
//! (unless `swarm.keep_surplus_landmarks`: the paper releases a landmark only when it leaves
//! D(t); agents crossing D(t)'s edges make the target flicker, and with the default every
//! flicker releases a landmark and picks another a moment later), and missing ones are chosen by MaxMin on the hop distance of the communication graph
//! (`landmarks.rs`). The leader then sweeps from `start_x` to `end_x` at `leader.speed`; the
//! run ends when it arrives.
//!
//! **Encounters** come from Rapier's sensor events in a sensing world of their own
//! (`physics.rs`), run on a second thread that follows the physics step by step
//! (`sensing.rs`); an encounter starts at the first step time at which the centres are
//! within r_d and ends at the first step time at which they are not (or at the final time).
//! Times are multiples of `simulation.dt`.
//!
//! **Cost.** Each step is one Rapier step of the physics world, O(n log n) for n agents
//! (BVH broad phase, a handful of contacts per agent), plus O(n) bookkeeping, and beside it
//! one collision-detection pass of the sensing world, also O(n log n); landmark selection
//! costs O(n + E) on the communication graph and runs only when the landmark count falls
//! short.
//!
//! **Randomness.** One ChaCha8 stream per agent (stream `i + 1` of the seed) drives its
//! walk; stream 0 drives placement and landmark selection. Events are sorted before they
//! are applied, so a run is a pure function of the world and the seed.

mod engine;
mod landmarks;
mod output;
mod params;
mod physics;
mod placement;
mod sensing;
pub use placement::PLACEMENT_GAP;

pub use engine::{LEADER_INTERVAL, RETURN_ESCAPE, RETURN_NOISE, simulate};
pub use output::{
    META_FORMAT, encounters_csv, leader_csv, meta_json, prepare_out_dir, static_intervals_csv,
    trajectories_csv, world_json, write_run,
};
pub use params::{
    AgentState, PrefixSink, SimError, SimOptions, SimOutput, SimStats, Trajectories,
    TrajectorySample,
};
