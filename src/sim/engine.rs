//! The simulation loop: agent behaviour, landmark upkeep, the leader, the contacts that
//! turn agents, and the log (its encounters come from the detector, `sensing.rs`, which
//! the loop hands each configuration).

use super::landmarks;
use super::params::{
    AgentState, SimError, SimOptions, SimOutput, SimStats, Trajectories, TrajectorySample,
};
use super::physics::{RawEvent, SIDES, Scene, SensorWorld};
use super::placement;
use super::sensing::{Detector, Sensing};
use crate::log::{AgentId, Encounter, EncounterLog, StaticInterval, StaticReason};
use crate::world::{ObstacleDistances, World};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::f64::consts::PI;
use std::time::Instant;

/// Half-width of the cone of headings an agent outside D(t) draws from, radians: the
/// leader's signal-strength gradient points along x, and the noise keeps returning agents
/// from queueing behind an obstacle in single file.
pub const RETURN_NOISE: f64 = PI / 3.0;

/// Mean run length while returning, metres: a returning agent re-senses the leader's
/// gradient this often, so that a turn away from an obstacle is a short detour rather
/// than a full random-walk run away from the leader.
pub const RETURN_RUN_LENGTH: f64 = 0.3;

/// Seconds of random walk a returning agent takes when its patience
/// (`swarm.return_patience`) runs out: about 6 m of walking, which carries it ≈ 3 m (root
/// mean square, √(2 λ L) for L = 6 m at λ = 1 m, less where it meets walls) from where it
/// was. A concave nook that opens away from the sweep (a disc touching
/// a wall, the inner corner of an L, the near side of a wall standing on a side) traps an
/// agent whose every return run points into it; a normal return takes seconds.
pub const RETURN_ESCAPE: f64 = 60.0;

/// Interval of the leader's track in `leader.csv`, seconds (rounded to whole steps).
pub const LEADER_INTERVAL: f64 = 1.0;

/// Draws for a heading that points away from every contact before falling back to the
/// mean of the contact normals.
const HEADING_TRIES: usize = 64;

/// Gap under which a body counts as touching what Rapier reported near it, metres: the
/// speculative contacts stop bodies at a gap of zero, up to f32 rounding.
const TOUCH_GAP: f64 = 1e-4;

/// A moving agent whose heading points into a wall or agent it still touches, by more
/// than this cosine, collides with it again (it was turned there by another contact or
/// by the end of a run, and would otherwise press into it until its next turn).
const PRESS_EPS: f64 = 1e-9;

/// A wall follower whose gap to its wall exceeds this many steps of travel has lost it
/// (pushed off, or round a corner too sharp to hug) and turns away.
const FOLLOW_LOST: f64 = 3.0;

/// A wall follower that moved less than this share of a step in each of two consecutive
/// steps is stuck (a nook it cannot turn) and turns away.
const FOLLOW_STUCK: f64 = 0.25;

/// Step of the central differences that give a followed wall's normal, metres: well
/// above the f32 spacing of the positions, so that in a concave nook of one polygon,
/// where the body touches two edges, the normal is their mean and the follower slides out
/// along the second edge instead of pressing into it.
const FOLLOW_NORMAL_STEP: f64 = 1e-4;

type P = (f64, f64);

/// What an agent's body can touch.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
enum Other {
    /// Another agent, with a larger index.
    Agent(u32),
    /// `World::obstacles[k]`.
    Obstacle(u32),
    /// Side `j` of the arena, in the order of [`side_gaps`] (left, right, bottom, top).
    Side(u8),
}

/// Wall following (the cockroach model's WF mode, Jeanson et al. 2003): the agent walks
/// along the boundary of `wall` in the direction `sense` until its run (`run_left`, drawn
/// with mean `swarm.wall_following_length`) is spent, then turns away from the wall.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Follow {
    /// `Other::Obstacle(k)` or `Other::Side(j)`.
    wall: Other,
    /// +1: the wall on the agent's left (anticlockwise round an obstacle, along the
    /// tangent `n` turned by +90°, `n` the wall's outward normal); −1: on its right.
    sense: f64,
    /// Started at this step (counted once in the statistics).
    fresh: bool,
    /// Position at the previous step, to tell a follower that makes no progress.
    last: P,
    /// Consecutive steps without progress.
    stalls: u8,
}

struct Agent {
    state: AgentState,
    /// Unit heading.
    heading: P,
    /// Metres left in the current run.
    run_left: f64,
    /// Walking seconds until the next spontaneous stop.
    stop_in: f64,
    /// Start of the current static interval (pause or landmark), seconds.
    static_since: f64,
    /// End of the current pause, seconds.
    pause_until: f64,
    /// Outward normals of the contacts of the last step (new touches, and touches the
    /// agent heads into), with what was touched.
    normals: Vec<(P, Other)>,
    /// The wall being followed, if any (`swarm.wall_following`).
    follow: Option<Follow>,
    /// While returning: when the agent last started following the gradient, seconds.
    return_since: f64,
    /// While returning: the current run is part of an escape (a random walk taken after
    /// `swarm.return_patience` seconds outside D(t)), which lasts until `escape_until`.
    escape: bool,
    escape_until: f64,
    /// Escapes taken since the agent left D(t); each lasts twice as long as the last.
    escapes: u32,
    /// Boxed: the generator's state and block buffer (≈ 300 bytes) would otherwise make
    /// the per-step passes over all agents stream through about four times more memory.
    rng: Box<ChaCha8Rng>,
}

fn exponential(rng: &mut ChaCha8Rng, mean: f64) -> f64 {
    // 1 - u is in (0, 1], so the logarithm is finite.
    -mean * (1.0 - rng.random::<f64>()).ln()
}

fn unit(angle: f64) -> P {
    (angle.cos(), angle.sin())
}

impl Agent {
    fn new(seed: u64, index: usize, world: &World) -> Self {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        // Stream 0 is the run's own (placement, landmarks); agents get their own streams so
        // that one agent's draws never shift another's.
        rng.set_stream(index as u64 + 1);
        let heading = unit(2.0 * PI * rng.random::<f64>());
        let run_left = exponential(&mut rng, world.swarm.mean_run_length);
        let stop_in = Self::draw_stop(&mut rng, world);
        Self {
            state: AgentState::Walk,
            heading,
            run_left,
            stop_in,
            static_since: 0.0,
            pause_until: 0.0,
            normals: Vec::new(),
            follow: None,
            return_since: 0.0,
            escape: false,
            escape_until: 0.0,
            escapes: 0,
            rng: Box::new(rng),
        }
    }

    fn draw_stop(rng: &mut ChaCha8Rng, world: &World) -> f64 {
        if world.swarm.stop_rate > 0.0 {
            exponential(rng, 1.0 / world.swarm.stop_rate)
        } else {
            f64::INFINITY
        }
    }

    /// A fresh heading for the agent's mode: isotropic while walking, towards `leader_x`
    /// within ±[`RETURN_NOISE`] while returning; away from every contact in `normals`.
    fn new_heading(&mut self, x: f64, leader_x: f64) {
        let returning = self.state == AgentState::Return && !self.escape;
        let base = if leader_x >= x { 0.0 } else { PI };
        let draw = |rng: &mut ChaCha8Rng| {
            if returning {
                unit(base + RETURN_NOISE * (2.0 * rng.random::<f64>() - 1.0))
            } else {
                unit(2.0 * PI * rng.random::<f64>())
            }
        };
        let away = |h: P, normals: &[(P, Other)]| {
            normals.iter().all(|(n, _)| h.0 * n.0 + h.1 * n.1 >= 0.0)
        };
        for _ in 0..HEADING_TRIES {
            let h = draw(&mut self.rng);
            if away(h, &self.normals) {
                self.heading = h;
                return;
            }
            // Mirroring across the contact plane keeps the draw uniform on the free side
            // when there is one contact.
            if let [(n, _)] = self.normals[..] {
                let d = h.0 * n.0 + h.1 * n.1;
                self.heading = (h.0 - 2.0 * d * n.0, h.1 - 2.0 * d * n.1);
                return;
            }
        }
        let s = self
            .normals
            .iter()
            .fold((0.0, 0.0), |s, (n, _)| (s.0 + n.0, s.1 + n.1));
        let len = s.0.hypot(s.1);
        if len > 0.0 {
            self.heading = (s.0 / len, s.1 / len);
        }
    }

    /// Draws the length of a new run for the agent's mode, metres.
    fn new_run(&mut self, world: &World) {
        let mean = if self.state == AgentState::Return && !self.escape {
            RETURN_RUN_LENGTH.min(world.swarm.mean_run_length)
        } else {
            world.swarm.mean_run_length
        };
        self.run_left = exponential(&mut self.rng, mean);
    }

    /// Before a returning agent's next run, at time `t`: after `swarm.return_patience`
    /// seconds of following the gradient without regaining D(t) the agent walks for
    /// [`RETURN_ESCAPE`] seconds as a walking agent does (isotropic headings, the walk's
    /// run length), then follows the gradient again, with the patience counted from the
    /// escape's end; each further escape before it regains D(t) lasts twice as long (up to
    /// 8 times), so that a nook it keeps returning to is left in the end. Either kind of
    /// run draws the same random numbers, so a run in which no agent escapes is unchanged.
    /// `true` when an escape starts.
    fn next_return_run(&mut self, t: f64, patience: f64) -> bool {
        if self.state != AgentState::Return {
            return false;
        }
        let start = t >= self.escape_until && t - self.return_since >= patience;
        if start {
            self.escape_until = t + RETURN_ESCAPE * f64::from(1u32 << self.escapes.min(3));
            self.escapes += 1;
            self.return_since = self.escape_until;
        }
        self.escape = t < self.escape_until;
        start
    }

    /// Handles the contacts of the last step (`normals`) under wall following; `false`
    /// when they end the run with a turn, as in the paper's random walk.
    ///
    /// Only walls (obstacles, the arena's sides) are followed, and only by walking agents:
    /// an agent met ends the run. Touching the wall being followed is what following
    /// does; a different wall met (a concave corner where two obstacles, or an obstacle
    /// and a side, meet) is followed on in the same sense. Otherwise a wall hit starts
    /// following with probability `swarm.wall_following`, in the direction of the
    /// tangent nearer the agent's heading, for a length drawn with mean
    /// `swarm.wall_following_length`. No random number is drawn when the probability is
    /// 0, so the paper's random walk keeps its exact sequence of draws.
    fn wall_contact(&mut self, terrain: &Terrain<'_>, p: P) -> bool {
        let prob = terrain.world.swarm.wall_following;
        if prob <= 0.0 || self.state != AgentState::Walk {
            return false;
        }
        if self
            .normals
            .iter()
            .any(|(_, o)| matches!(o, Other::Agent(_)))
        {
            // The turn away from the agent met must also lead away from the wall being
            // followed (still touched, so no new contact reports it), or the agent would
            // press into the wall until its next run.
            if let Some(f) = self.follow.take()
                && let Some((_, n)) = wall_geometry(terrain, f.wall, p)
            {
                self.normals.push((n, f.wall));
            }
            return false;
        }
        if let Some(f) = &mut self.follow {
            // A different wall ahead (a concave corner) is followed on; one beside or
            // behind (a graze in a narrow passage) is not, or the follower would reverse.
            let ahead = wall_geometry(terrain, f.wall, p).map(|(_, n)| tangent(n, f.sense));
            if let Some(t) = ahead
                && let Some(&(_, o)) = self
                    .normals
                    .iter()
                    .find(|(m, o)| *o != f.wall && t.0 * m.0 + t.1 * m.1 < 0.0)
            {
                f.wall = o;
            }
            return true;
        }
        if self.rng.random::<f64>() >= prob {
            return false;
        }
        let Some(&(n, wall)) = self.normals.first() else {
            return false;
        };
        let t = tangent(n, 1.0);
        let along = self.heading.0 * t.0 + self.heading.1 * t.1;
        let sense = if along > 0.0 || (along == 0.0 && self.rng.random::<bool>()) {
            1.0
        } else {
            -1.0
        };
        self.follow = Some(Follow {
            wall,
            sense,
            fresh: true,
            last: p,
            stalls: 0,
        });
        self.run_left = exponential(&mut self.rng, terrain.world.swarm.wall_following_length);
        true
    }

    fn moving(&self) -> bool {
        matches!(self.state, AgentState::Walk | AgentState::Return)
    }
}

/// Outward unit normal of a signed distance `f` at `p`, by central differences.
fn gradient(f: impl Fn(P) -> f64, p: P) -> Option<P> {
    gradient_step(f, p, 1e-6)
}

/// [`gradient`] with central differences of step `h`.
fn gradient_step(f: impl Fn(P) -> f64, p: P, h: f64) -> Option<P> {
    let gx = f((p.0 + h, p.1)) - f((p.0 - h, p.1));
    let gy = f((p.0, p.1 + h)) - f((p.0, p.1 - h));
    let len = gx.hypot(gy);
    (len > 0.0 && len.is_finite()).then(|| (gx / len, gy / len))
}

/// The tangent of a wall with outward normal `n`, in the direction `sense` (±1).
fn tangent(n: P, sense: f64) -> P {
    (-sense * n.1, sense * n.0)
}

/// The heading of a wall follower: along the wall's tangent, turned towards the wall in
/// proportion to its `gap` (by up to 45° once the gap reaches a `step`), so that it stays
/// in contact round convex corners and curves; the physics stops it at contact.
fn follow_heading(n: P, sense: f64, gap: f64, step: f64) -> P {
    let t = tangent(n, sense);
    let c = (gap / step).clamp(0.0, 1.0);
    let h = (t.0 - c * n.0, t.1 - c * n.1);
    let len = h.0.hypot(h.1);
    (h.0 / len, h.1 / len)
}

/// The gap between a body at `p` and the followed `wall`, and the wall's outward normal
/// there (for a side, the normal pointing into the arena).
fn wall_geometry(terrain: &Terrain<'_>, wall: Other, p: P) -> Option<(f64, P)> {
    let world = terrain.world;
    let r = world.swarm.body_radius;
    match wall {
        Other::Obstacle(k) => {
            let k = k as usize;
            let d = terrain.distances.signed_distance(k, p)?;
            let n = gradient_step(
                |q| terrain.distances.signed_distance(k, q).unwrap_or(f64::NAN),
                p,
                FOLLOW_NORMAL_STEP,
            )?;
            Some((d - r, n))
        }
        Other::Side(j) => side_gaps(world, p, r).get(usize::from(j)).copied(),
        Other::Agent(_) => None,
    }
}

/// Gaps between a body of radius `r` at `p` and the arena's four sides, with the
/// inward normals of the sides.
fn side_gaps(world: &World, p: P, r: f64) -> [(f64, P); 4] {
    let (w, h) = (world.arena.width, world.arena.height);
    [
        (p.0 - r, (1.0, 0.0)),
        (w - p.0 - r, (-1.0, 0.0)),
        (p.1 - r, (0.0, 1.0)),
        (h - p.1 - r, (0.0, -1.0)),
    ]
}

fn check(world: &World, opts: &SimOptions) -> Result<(), SimError> {
    let s = &world.swarm;
    let positive: [(&'static str, f64); 11] = [
        ("simulation.dt", world.simulation.dt),
        ("swarm.detection_radius", s.detection_radius),
        ("swarm.body_radius", s.body_radius),
        ("swarm.mean_run_length", s.mean_run_length),
        ("swarm.mean_stop_duration", s.mean_stop_duration),
        ("swarm.comm_radius", s.comm_radius),
        ("swarm.wall_following_length", s.wall_following_length),
        ("swarm.return_patience", s.return_patience),
        ("leader.speed", world.leader.speed),
        ("arena.width", world.arena.width),
        ("arena.height", world.arena.height),
    ];
    for (field, value) in positive {
        if !(value.is_finite() && value > 0.0) {
            return Err(SimError::InvalidWorld {
                field,
                value,
                expected: "expected a finite number greater than 0",
            });
        }
    }
    let non_negative: [(&'static str, f64); 3] = [
        ("swarm.speed", s.speed),
        ("swarm.stop_rate", s.stop_rate),
        (
            "simulation.dispersion_time",
            world.simulation.dispersion_time,
        ),
    ];
    for (field, value) in non_negative {
        if !(value.is_finite() && value >= 0.0) {
            return Err(SimError::InvalidWorld {
                field,
                value,
                expected: "expected a finite number, 0 or more",
            });
        }
    }
    if !(0.0..=1.0).contains(&s.wall_following) {
        return Err(SimError::InvalidWorld {
            field: "swarm.wall_following",
            value: s.wall_following,
            expected: "expected a probability between 0 and 1",
        });
    }
    if !(0.0..=1.0).contains(&s.landmark_fraction) {
        return Err(SimError::InvalidWorld {
            field: "swarm.landmark_fraction",
            value: s.landmark_fraction,
            expected: "expected a fraction between 0 and 1",
        });
    }
    if !world.total_duration().is_finite() {
        return Err(SimError::InvalidWorld {
            field: "leader.end_x",
            value: world.leader.end_x,
            expected: "the sweep must have a finite duration",
        });
    }
    if let Some(i) = opts.trajectories
        && !(i.is_finite() && i > 0.0)
    {
        return Err(SimError::InvalidOption {
            option: "trajectories",
            value: i,
            expected: "expected an interval in seconds greater than 0",
        });
    }
    if let Some(i) = opts.trajectories
        && i > world.total_duration().max(1.0)
    {
        return Err(SimError::InvalidOption {
            option: "trajectories",
            value: i,
            expected: "expected an interval no longer than the run (its dispersion and sweep) \
                       or 1 s; a longer one records the start only",
        });
    }
    Ok(())
}

/// Number of whole steps of `dt` closest to `interval`, at least one.
fn steps_per(interval: f64, dt: f64) -> u64 {
    ((interval / dt).round() as u64).max(1)
}

/// The world with its obstacles' distance index: what wall contacts and wall following
/// measure (`ObstacleDistances`, bit for bit `Obstacle::signed_distance`).
struct Terrain<'w> {
    world: &'w World,
    distances: ObstacleDistances<'w>,
}

impl<'w> Terrain<'w> {
    fn new(world: &'w World) -> Self {
        Self {
            world,
            distances: ObstacleDistances::new(&world.obstacles),
        }
    }
}

/// Mutable state of a run besides the physics.
struct Run<'w> {
    world: &'w World,
    terrain: Terrain<'w>,
    agents: Vec<Agent>,
    /// Landmarks in the order they were chosen.
    landmarks: Vec<usize>,
    landmarks_started: bool,
    /// Pairs Rapier reports within the contact prediction distance, sorted, each with
    /// whether its bodies touch (gap below [`TOUCH_GAP`]). A few dozen at most in a dense
    /// swarm, walked every step: a sorted vector, not a tree.
    near: Vec<((u32, Other), bool)>,
    log: EncounterLog,
    stats: SimStats,
    rng: ChaCha8Rng,
}

impl Run<'_> {
    fn close_static(&mut self, i: usize, t: f64, reason: StaticReason) {
        self.log.static_intervals.push(StaticInterval {
            agent: i as AgentId,
            start: self.agents[i].static_since,
            end: t,
            reason,
        });
    }

    /// Starts a new run for an agent that resumes walking.
    fn resume(&mut self, i: usize, p: P, leader_x: f64) {
        let a = &mut self.agents[i];
        a.state = AgentState::Walk;
        a.normals.clear();
        a.follow = None;
        a.new_heading(p.0, leader_x);
        a.new_run(self.world);
    }

    /// Mode changes at time `t` for agent `i` at `p`, before the step.
    fn update_agent(&mut self, i: usize, p: P, t: f64, domain: P, leader_x: f64) {
        let inside = p.0 >= domain.0 && p.0 <= domain.1;
        match self.agents[i].state {
            AgentState::Pause if t >= self.agents[i].pause_until => {
                self.close_static(i, t, StaticReason::Pause);
                self.agents[i].state = AgentState::Walk;
            }
            AgentState::Landmark if !inside => {
                self.close_static(i, t, StaticReason::Landmark);
                self.landmarks.retain(|&l| l != i);
                self.stats.landmark_releases_outside += 1;
                self.resume(i, p, leader_x);
            }
            _ => {}
        }
        let world = self.world;
        let a = &mut self.agents[i];
        if !a.moving() {
            a.normals.clear();
            if let Some(f) = &mut a.follow {
                // A pause keeps the follow; progress is measured from where it resumes.
                f.last = p;
            }
            return;
        }
        if !inside && a.state == AgentState::Walk {
            // Returning agents follow the leader's gradient, not walls.
            a.state = AgentState::Return;
            a.follow = None;
            a.return_since = t;
            a.escape = false;
            a.escape_until = t;
            a.escapes = 0;
            a.new_heading(p.0, leader_x);
            a.new_run(world);
        } else if inside && a.state == AgentState::Return {
            a.state = AgentState::Walk;
            a.escape = false;
        }
        if !a.normals.is_empty() {
            if !a.wall_contact(&self.terrain, p) {
                // A contact ends the run: turn away and draw a new run length.
                a.follow = None;
                if a.next_return_run(t, world.swarm.return_patience) {
                    self.stats.return_escapes += 1;
                }
                a.new_heading(p.0, leader_x);
                a.new_run(world);
                self.stats.collisions += 1;
            } else if a.follow.is_some_and(|f| f.fresh) {
                self.stats.wall_follows += 1;
            }
            a.normals.clear();
        }
        if let Some(f) = &mut a.follow {
            let step = world.swarm.speed * world.simulation.dt;
            let moved = (p.0 - f.last.0).hypot(p.1 - f.last.1);
            f.stalls = if !f.fresh && moved < FOLLOW_STUCK * step {
                f.stalls.saturating_add(1)
            } else {
                0
            };
            // One short step is normal (arriving in a corner, before the next wall is
            // taken on); two in a row is a nook the follower cannot turn.
            let stuck = f.stalls >= 2;
            f.fresh = false;
            f.last = p;
            let f = *f;
            match wall_geometry(&self.terrain, f.wall, p) {
                Some((gap, n)) if a.run_left > 0.0 && gap <= FOLLOW_LOST * step && !stuck => {
                    a.heading = follow_heading(n, f.sense, gap, step);
                }
                wall => {
                    // The followed length is spent, the wall was lost, or the follower
                    // made no progress (a nook it cannot turn): turn away from the wall
                    // and start a new random-walk run.
                    a.follow = None;
                    if let Some((_, n)) = wall {
                        a.normals.push((n, f.wall));
                    }
                    a.new_heading(p.0, leader_x);
                    a.normals.clear();
                    a.new_run(world);
                }
            }
        } else if a.run_left <= 0.0 {
            if a.next_return_run(t, world.swarm.return_patience) {
                self.stats.return_escapes += 1;
            }
            a.new_heading(p.0, leader_x);
            a.new_run(world);
        }
        if a.state == AgentState::Walk && a.stop_in <= 0.0 {
            a.state = AgentState::Pause;
            a.static_since = t;
            a.pause_until = t + exponential(&mut a.rng, world.swarm.mean_stop_duration);
            a.stop_in = Agent::draw_stop(&mut a.rng, world);
            self.stats.pauses += 1;
        }
    }

    /// Holds round(fraction × agents inside D(t)) landmarks among the agents inside D(t)
    /// (at least that many with `keep_surplus_landmarks`, which releases none for a surplus).
    fn upkeep_landmarks(&mut self, pos: &[P], t: f64, domain: P, leader_x: f64) {
        let is_inside = |p: &P| p.0 >= domain.0 && p.0 <= domain.1;
        // Counted without allocating: the candidates are only listed when a pick is due.
        let n_inside = pos.iter().filter(|p| is_inside(p)).count();
        let target = (self.world.swarm.landmark_fraction * n_inside as f64).round() as usize;
        while self.landmarks.len() > target && !self.world.swarm.keep_surplus_landmarks {
            // Release the newest: the older landmarks keep their MaxMin spread.
            let Some(i) = self.landmarks.pop() else { break };
            self.close_static(i, t, StaticReason::Landmark);
            self.stats.landmark_releases_surplus += 1;
            self.resume(i, pos[i], leader_x);
        }
        if self.landmarks.len() < target {
            let inside: Vec<usize> = (0..pos.len()).filter(|&i| is_inside(&pos[i])).collect();
            let cand: Vec<P> = inside.iter().map(|&i| pos[i]).collect();
            let flags: Vec<bool> = inside
                .iter()
                .map(|&i| self.agents[i].state == AgentState::Landmark)
                .collect();
            let need = target - self.landmarks.len();
            let picks = landmarks::select(
                &cand,
                &flags,
                self.world.swarm.comm_radius,
                need,
                &mut self.rng,
            );
            for k in picks {
                let i = inside[k];
                if self.agents[i].state == AgentState::Pause {
                    self.close_static(i, t, StaticReason::Pause);
                }
                let a = &mut self.agents[i];
                a.state = AgentState::Landmark;
                a.static_since = t;
                self.landmarks.push(i);
                if self.landmarks_started {
                    self.stats.landmark_replacements += 1;
                } else {
                    self.stats.landmark_selections += 1;
                }
            }
        }
        self.landmarks_started = true;
    }

    /// Applies the contact events of a configuration (sensor events go to the detector,
    /// `sensing.rs`).
    fn handle_events(&mut self, events: &[RawEvent]) {
        for &ev in events {
            match ev {
                RawEvent::Sensor { .. } => {}
                RawEvent::AgentContact { a, b, started } => {
                    self.set_near((a, Other::Agent(b)), started);
                }
                RawEvent::ObstacleContact {
                    a,
                    obstacle,
                    started,
                } => {
                    let other = if obstacle > SIDES - 4 {
                        Other::Side((SIDES - obstacle) as u8)
                    } else {
                        Other::Obstacle(obstacle)
                    };
                    self.set_near((a, other), started);
                }
            }
        }
    }

    fn set_near(&mut self, pair: (u32, Other), started: bool) {
        match (self.near.binary_search_by_key(&pair, |e| e.0), started) {
            (Err(k), true) => self.near.insert(k, (pair, false)),
            (Ok(k), false) => {
                self.near.remove(k);
            }
            _ => {}
        }
    }

    /// Finds the near pairs whose bodies have just come to touch at `pos` and gives each
    /// moving agent involved the outward normal of the contact, from the exact geometry;
    /// likewise for a continuing touch that a moving agent heads into (a press), except a
    /// follower's own wall. Otherwise normals are not computed: the gap alone decides.
    fn detect_touches(&mut self, pos: &[P]) {
        let world = self.world;
        let r = world.swarm.body_radius;
        for ((a, other), touching) in &mut self.near {
            let (a, other) = (*a, *other);
            let pa = pos[a as usize];
            let gap = match other {
                Other::Agent(b) => {
                    let pb = pos[b as usize];
                    (pa.0 - pb.0).hypot(pa.1 - pb.1) - 2.0 * r
                }
                Other::Obstacle(k) => {
                    match self.terrain.distances.signed_distance(k as usize, pa) {
                        Some(d) => d - r,
                        None => continue,
                    }
                }
                Other::Side(j) => match side_gaps(world, pa, r).get(usize::from(j)) {
                    Some(s) => s.0,
                    None => continue,
                },
            };
            if gap > TOUCH_GAP {
                *touching = false;
                continue;
            }
            let fresh = !std::mem::replace(touching, true);
            // A continuing touch matters only to a moving agent heading into it (turned
            // there by another contact or a run's end): skip the normals otherwise. A
            // follower steers into its own wall on purpose, so that touch is skipped too
            // (its normal is computed where it steers).
            let heading_in =
                |ag: &Agent, n: P| ag.heading.0 * n.0 + ag.heading.1 * n.1 < -PRESS_EPS;
            if !fresh {
                let idle = match other {
                    Other::Agent(b) => {
                        !self.agents[a as usize].moving() && !self.agents[b as usize].moving()
                    }
                    wall => {
                        let ag = &self.agents[a as usize];
                        !ag.moving() || ag.follow.is_some_and(|f| f.wall == wall)
                    }
                };
                if idle {
                    continue;
                }
            }
            let mut normals: [Option<(usize, P, Other)>; 4] = [None; 4];
            match other {
                Other::Agent(b) => {
                    let pb = pos[b as usize];
                    let d = (pa.0 - pb.0, pa.1 - pb.1);
                    let len = d.0.hypot(d.1);
                    if len > 0.0 {
                        let n = (d.0 / len, d.1 / len);
                        normals[0] = Some((a as usize, n, Other::Agent(b)));
                        normals[1] = Some((b as usize, (-n.0, -n.1), Other::Agent(a)));
                    }
                }
                Other::Obstacle(k) => {
                    let d = &self.terrain.distances;
                    if (k as usize) < world.obstacles.len() {
                        normals[0] =
                            gradient(|q| d.signed_distance(k as usize, q).unwrap_or(f64::NAN), pa)
                                .map(|n| (a as usize, n, Other::Obstacle(k)));
                    }
                }
                Other::Side(j) => {
                    if let Some(&(_, n)) = side_gaps(world, pa, r).get(usize::from(j)) {
                        normals[0] = Some((a as usize, n, Other::Side(j)));
                    }
                }
            }
            for (i, n, o) in normals.into_iter().flatten() {
                if self.agents[i].moving() && (fresh || heading_in(&self.agents[i], n)) {
                    if !fresh {
                        self.stats.presses += 1;
                    }
                    self.agents[i].normals.push((n, o));
                }
            }
        }
    }
}

/// The final log's order of encounters: by start, then agents.
fn encounter_order(x: &Encounter, y: &Encounter) -> std::cmp::Ordering {
    x.start
        .total_cmp(&y.start)
        .then(x.a.cmp(&y.a))
        .then(x.b.cmp(&y.b))
}

/// The final log's order of static intervals: by agent, then start and end.
fn static_order(x: &StaticInterval, y: &StaticInterval) -> std::cmp::Ordering {
    x.agent
        .cmp(&y.agent)
        .then(x.start.total_cmp(&y.start))
        .then(x.end.total_cmp(&y.end))
}

impl Run<'_> {
    /// A cut's prefix of the log ([`SimOptions::with_prefixes`]) as it stood at time `t` (a
    /// step time not after the current one), given the encounters that started at or
    /// before the cut; static intervals running at `t` end one step later.
    ///
    /// The detector settles a cut behind the loop, so the state at `t` is rebuilt from the
    /// present one: the static intervals closed by `t` are those that end at or before it
    /// (every interval is closed at the time of the step that closes it), those running at
    /// `t` are the ones that began by `t` and are still running or ended later, and the
    /// leader's track is cut at `t`.
    fn prefix(&self, t: f64, dt: f64, encounters: &[Encounter]) -> EncounterLog {
        let cut_off = t + dt;
        let mut static_intervals: Vec<StaticInterval> = Vec::new();
        for s in &self.log.static_intervals {
            if s.end <= t {
                static_intervals.push(s.clone());
            } else if s.start <= t {
                static_intervals.push(StaticInterval {
                    end: cut_off,
                    ..s.clone()
                });
            }
        }
        for (i, a) in self.agents.iter().enumerate() {
            let reason = match a.state {
                AgentState::Pause => StaticReason::Pause,
                AgentState::Landmark => StaticReason::Landmark,
                _ => continue,
            };
            if a.static_since <= t {
                static_intervals.push(StaticInterval {
                    agent: i as AgentId,
                    start: a.static_since,
                    end: cut_off,
                    reason,
                });
            }
        }
        let encounters = encounters.to_vec();
        let leader = self
            .log
            .leader
            .iter()
            .take_while(|&&(time, _)| time <= t)
            .copied()
            .collect();
        // As the files will hold it, then in the files' order.
        let mut log = EncounterLog {
            encounters,
            static_intervals,
            leader,
        }
        .as_written();
        log.encounters.sort_by(encounter_order);
        log.static_intervals.sort_by(static_order);
        log
    }
}

/// Runs the swarm through the whole sweep of `world` (dispersion, then the leader from
/// `start_x` to `end_x`) and returns the encounter log.
///
/// Deterministic: the same world and options give the same output, wall times aside.
pub fn simulate(world: &World, opts: &SimOptions) -> Result<SimOutput, SimError> {
    let wall = Instant::now();
    check(world, opts)?;
    let dt = world.simulation.dt;
    let n_agents = world.swarm.agents;
    let total = world.total_duration();
    // Whole steps covering the run; the tolerance absorbs rounding in total / dt.
    let n_steps = ((total / dt) * (1.0 - 1e-12)).ceil().max(0.0) as u64;
    let end_time = n_steps as f64 * dt;
    let dispersion = world.simulation.dispersion_time;
    let eps = dt * 1e-6;

    let mut rng = ChaCha8Rng::seed_from_u64(opts.seed);
    let start = placement::place(world, &mut rng)?;
    let mut scene = Scene::new(world, &start, dt);
    let cuts = opts.prefixes.map_or(&[][..], |(cuts, _)| cuts);
    let mut sensing = Sensing::start(
        Detector::new(SensorWorld::new(world, &start, dt), dt, n_steps, cuts),
        n_agents,
    );
    let mut run = Run {
        world,
        terrain: Terrain::new(world),
        agents: (0..n_agents)
            .map(|i| Agent::new(opts.seed, i, world))
            .collect(),
        landmarks: Vec::new(),
        landmarks_started: false,
        near: Vec::new(),
        log: EncounterLog::default(),
        stats: SimStats::default(),
        rng,
    };
    let traj_every = opts.trajectories.map(|i| steps_per(i, dt));
    let mut traj = traj_every.map(|k| Trajectories {
        interval: k as f64 * dt,
        samples: Vec::new(),
    });
    let leader_every = steps_per(LEADER_INTERVAL, dt);
    let progress_every = (n_steps / 200).max(1);

    let mut pos: Vec<P> = start;
    let mut events = Vec::new();
    let mut physics_time = 0.0;
    let mut landmark_time = 0.0;
    for k in 0..=n_steps {
        let t = k as f64 * dt;
        if let Some(i) = scene.read_positions(&mut pos) {
            return Err(SimError::NonFinite {
                agent: i as AgentId,
                time: t,
            });
        }
        let last = k == n_steps;
        sensing.push(k, &pos, last);
        let domain = world.domain(t);
        let leader_x = world.leader_x(t);
        if !last {
            run.detect_touches(&pos);
            for (i, &p) in pos.iter().enumerate() {
                run.update_agent(i, p, t, domain, leader_x);
            }
            if t >= dispersion - eps {
                let t0 = Instant::now();
                run.upkeep_landmarks(&pos, t, domain, leader_x);
                landmark_time += t0.elapsed().as_secs_f64();
            }
        }
        if let (Some(every), Some(traj)) = (traj_every, traj.as_mut())
            && k % every == 0
        {
            for (i, &p) in pos.iter().enumerate() {
                traj.samples.push(TrajectorySample {
                    time: t,
                    agent: i as AgentId,
                    x: p.0,
                    y: p.1,
                    state: run.agents[i].state,
                });
            }
        }
        if k % leader_every == 0 || last {
            run.log.leader.push((t, leader_x));
        }
        if !last {
            // Moving agents also spend the step's length of their run (and, walking, the
            // step's time to their next stop) here: the step ahead changes no agent's state.
            let step_len = world.swarm.speed * dt;
            for (i, a) in run.agents.iter_mut().enumerate() {
                let vel = a.moving().then_some((
                    a.heading.0 * world.swarm.speed,
                    a.heading.1 * world.swarm.speed,
                ));
                scene.set_motion(i, vel);
                if a.moving() {
                    a.run_left -= step_len;
                    if a.state == AgentState::Walk {
                        a.stop_in -= dt;
                    }
                }
            }
        }
        let t0 = Instant::now();
        events.clear();
        scene.step(if last { 0.0 } else { dt }, &mut events);
        physics_time += t0.elapsed().as_secs_f64();
        run.handle_events(&events);
        if last {
            break;
        }
        if let Some((_, hand_out)) = opts.prefixes {
            for s in sensing.settled() {
                hand_out(s.cut, &|| run.prefix(s.step as f64 * dt, dt, &s.encounters));
            }
        }
        if let Some(report) = opts.progress
            && k % progress_every == 0
        {
            report(k as f64 / n_steps.max(1) as f64);
        }
    }

    // Cuts settled before the end but heard of only now are handed out as they stood.
    let (detected, late) = sensing.finish();
    if let Some((_, hand_out)) = opts.prefixes {
        for s in late {
            hand_out(s.cut, &|| run.prefix(s.step as f64 * dt, dt, &s.encounters));
        }
    }
    run.log.encounters = detected.encounters;
    // Close what is still open at the final time.
    let mut still_open = detected.open;
    still_open.sort_unstable_by_key(|&((a, b), _)| (a, b));
    for ((a, b), (start, truth)) in still_open {
        run.log.encounters.push(Encounter {
            start,
            end: end_time,
            a,
            b,
            truth: Some(truth),
        });
    }
    for i in 0..n_agents {
        match run.agents[i].state {
            AgentState::Pause => run.close_static(i, end_time, StaticReason::Pause),
            AgentState::Landmark => run.close_static(i, end_time, StaticReason::Landmark),
            _ => {}
        }
    }
    // Rounded as the files write it before sorting, so the order is the files' order too.
    let mut log = run.log.as_written();
    log.encounters.sort_by(encounter_order);
    log.static_intervals.sort_by(static_order);
    if let Some(report) = opts.progress {
        report(1.0);
    }
    let mut stats = run.stats;
    stats.steps = n_steps;
    stats.simulated_time = end_time;
    stats.encounters = log.encounters.len();
    stats.static_intervals = log.static_intervals.len();
    stats.physics_time_s = physics_time;
    stats.sensing_time_s = detected.busy_s;
    stats.landmark_time_s = landmark_time;
    stats.wall_time_s = wall.elapsed().as_secs_f64();
    Ok(SimOutput {
        seed: opts.seed,
        dt,
        leader_interval: leader_every as f64 * dt,
        log,
        // Rounded like the log, as `trajectories.csv` holds them.
        trajectories: traj.map(|mut traj| {
            let mut buf = String::new();
            for p in &mut traj.samples {
                for x in [&mut p.time, &mut p.x, &mut p.y] {
                    *x = crate::log::written(*x, &mut buf);
                }
            }
            traj
        }),
        stats,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn no_wall_following_draws_no_random_number() {
        // The paper's random walk must keep its exact sequence of draws when wall
        // following is off: a wall hit is then a plain turn, decided without the rng.
        let mut world = World::empty("w", 4.0, 4.0);
        world.swarm.wall_following = 0.0;
        let mut a = Agent::new(3, 0, &world);
        a.normals.push(((0.0, 1.0), Other::Side(2)));
        let before = a.rng.clone();
        assert!(!a.wall_contact(&Terrain::new(&world), (1.0, 0.004)));
        assert_eq!(*a.rng, *before);
        // With a positive probability the same hit draws.
        world.swarm.wall_following = 0.5;
        let _ = a.wall_contact(&Terrain::new(&world), (1.0, 0.004));
        assert_ne!(*a.rng, *before);
    }
}
