//! The Rapier 2D worlds of a run. The physics world holds fixed colliders for the arena's
//! sides and the obstacles and one rigid body with a solid ball per agent; an event handler
//! turns its collision events into contacts. The sensing world ([`SensorWorld`]) holds one
//! sensor ball per agent and only runs collision detection; its intersection events become
//! encounters (`sensing.rs`, on a thread of its own).
//!
//! Encounters come from sensor intersection: each agent's sensor ball has radius r_d / 2, so
//! two sensors intersect exactly when the centres are within r_d. Solids only see solids and
//! obstacles (collision groups 1 and 3) and sensors only sensors (group 2, in their own
//! world), so a sensor never reports an obstacle or another agent's body. Until the
//! forty-sixth session the sensor balls rode on the agents' bodies in the physics world;
//! taking them out made its steps about a third faster and changed no trajectory, bit for
//! bit, in every run compared (seeds 1 and 2 of every bundled world, scenario 2's
//! trajectories every second, the golden-hash tests): sensors never reach the solver.
//!
//! Timing: Rapier's narrow phase runs at the start of `PhysicsPipeline::step`, on the
//! positions the bodies have before the step integrates them. Every event handled during
//! the step that advances `t_k → t_{k+1}` therefore describes the configuration at `t_k`
//! (the centres crossed r_d during the previous step), and is stamped `t_k`. A final step
//! with `dt = 0` reports the configuration at the last time. The sensing world is given the
//! configuration at `t_k` (the bodies' f32 translations, exactly) and reports on it.
//!
//! Static agents (paused or landmarks) stay dynamic bodies with their translations locked:
//! a locked body has infinite effective mass, so moving agents bounce off it and never push
//! it, and its sensor still reports encounters.

use crate::world::{Obstacle, World, polygon_area};
use rapier2d::prelude::*;
use std::sync::Mutex;

/// Collider kinds, stored in the high bits of a collider's `user_data`.
const KIND_SOLID: u128 = 1 << 64;
const KIND_SENSOR: u128 = 2 << 64;
const KIND_OBSTACLE: u128 = 3 << 64;
const KIND_MASK: u128 = 0xff << 64;

const GROUP_SOLID: Group = Group::GROUP_1;
const GROUP_SENSOR: Group = Group::GROUP_2;
const GROUP_OBSTACLE: Group = Group::GROUP_3;

/// Thickness of the fixed slabs that bound the arena outside its sides, metres.
const SIDE_THICKNESS: f32 = 1.0;

/// Rapier scales its tolerances by `length_unit`, tuned for metre-sized bodies; ours are
/// millimetres, so every tolerance is set explicitly in metres below. The one tolerance
/// that cannot be set on its own is the broad phase's fat-AABB skin, `0.04 × length_unit`:
/// a leaf of the BVH is only updated once its collider has moved by more than the skin.
const SKIN_FACTOR: f32 = 0.04;
/// Broad-phase skin of dense swarms, metres. Rapier's BVH has two regimes: when at least
/// 1/16 of the leaves leave their fat AABB in a step, it updates them in place and runs
/// its incremental optimiser and a full refit every step; below that it relocates each
/// moved leaf by SAH re-insertion and refits only their ancestors. Dense swarms are
/// always in the first regime, where a small skin is best (fewer candidate pairs);
/// 0.5–1 cm measured equal, 1.5 cm and more slower (README, "Broad-phase skin").
const DENSE_SKIN: f64 = 0.01;
/// Sparse skin, in steps of travel at `speed`: fewer than 1/16 of the moving leaves
/// (1/25.6) leave their fat AABB per step, so the BVH stays in the re-insertion regime.
const SPARSE_SKIN_STEPS: f64 = 25.6;
/// Largest expected number of other colliders overlapping a leaf's fat AABB for which the
/// sparse skin pays; measured crossover between 6.7 and 13 agents/m² at the defaults.
const SPARSE_MAX_NEIGHBOURS: f64 = 0.3;
/// [`SPARSE_MAX_NEIGHBOURS`] for the sensing world, whose balls only ever need an
/// intersection test. Sensing time, skins 1 / 2 / 4 / 7.7 cm: scenario 2 (200 agents,
/// r_d = 10 cm, 0.43 expected neighbours at 7.7 cm) 5.4 / 5.5 / 4.2 / 4.0 s; `k1.ron` (1 000
/// agents, r_d = 1 cm, 0.90) 0.32 / 0.31 / 0.34 / 0.48 s; `k10.ron` (10 000, 9.0) 0.45 /
/// 0.61 / 0.98 / 1.92 s (forty-sixth session; scenario 2 the mean of two runs, the others
/// one run each; docs/speed.md).
const SENSING_MAX_NEIGHBOURS: f64 = 0.6;
/// Rapier's contacts are speculative: a pair gets a contact constraint once its gap is
/// below the prediction distance, and the solver then stops the bodies exactly at contact.
/// The distance must exceed what two agents close in one step (2 v dt), or they overlap
/// before the solver sees them; this is that multiple of v dt (with a margin for agents
/// pushed faster than v).
const PREDICTION_STEPS: f64 = 3.0;
/// Smallest prediction distance, metres.
const MIN_PREDICTION_DISTANCE: f64 = 2e-4;
/// Slop kept by the CCD clamp, metres (CCD is off; kept tiny for consistency).
const ALLOWED_LINEAR_ERROR: f32 = 5e-5;
/// A contact pair whose configuration moved less than this since its last full update
/// keeps its contact points, metres.
const CONTACT_RECYCLE_DISTANCE: f32 = 5e-4;
/// Fastest penetration recovery, m/s.
const MAX_CORRECTIVE_VELOCITY: f32 = 0.1;

/// Polygons of this many vertices or more are one-sided polylines
/// (`PolylineFlags::ORIENTED`). A double-sided polyline pushes a body sideways at each
/// convex corner it slides past, which drags wall followers along fine outlines (one
/// agent circling a 0.5 m ring for 200 s at 0.1 m/s, median speed at the wall: a circle
/// 0.1000 m/s; 12, 63, 720 and 5 000 vertices 0.1000, 0.1000, 0.0948 and 0.0923 m/s
/// double-sided, 0.1000 m/s at every count one-sided, the 12- and 63-gons measured in a
/// scratch build with this threshold at 3; `cargo run --release --example wall_speed`). The bundled and training worlds' polygons (3 to 6 vertices) stay
/// double-sided so that their runs, and the classifier fitted on them, are unchanged;
/// making every polygon one-sided needs those re-measured (README, "Model").
pub(crate) const ORIENTED_MIN_VERTICES: usize = 64;

/// Obstacle index of the arena's first side; side `j` (left, right, bottom, top) is
/// `SIDES - j`.
pub(crate) const SIDES: u32 = u32::MAX;

/// A raw event, decoded from collider handles to agent indices.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub(crate) enum RawEvent {
    /// Sensors of `a < b` started (`true`) or stopped (`false`) intersecting.
    Sensor { a: u32, b: u32, started: bool },
    /// The solid bodies of agents `a < b` came within the contact prediction distance
    /// (`started`) or left it.
    AgentContact { a: u32, b: u32, started: bool },
    /// Agent `a` came within the prediction distance of obstacle `obstacle` (an index into
    /// `World::obstacles`; `SIDES - j` for side `j` of the arena) or left it.
    ObstacleContact {
        a: u32,
        obstacle: u32,
        started: bool,
    },
}

/// Collects events during a step. Rapier's handler takes `&self`, hence the mutex; it is
/// never contended (the pipeline runs single-threaded without the `parallel` feature).
#[derive(Default)]
struct Collector {
    events: Mutex<Vec<RawEvent>>,
}

fn decode(data: u128) -> (u128, u32) {
    (data & KIND_MASK, (data & 0xffff_ffff) as u32)
}

impl EventHandler for Collector {
    fn handle_collision_event(
        &self,
        _bodies: &RigidBodySet,
        colliders: &ColliderSet,
        event: CollisionEvent,
        _contact_pair: Option<&ContactPair>,
    ) {
        let (Some(c1), Some(c2)) = (
            colliders.get(event.collider1()),
            colliders.get(event.collider2()),
        ) else {
            return;
        };
        let (k1, i1) = decode(c1.user_data);
        let (k2, i2) = decode(c2.user_data);
        let (a, b) = (i1.min(i2), i1.max(i2));
        let ev = match (k1, k2) {
            (KIND_SENSOR, KIND_SENSOR) if i1 != i2 => RawEvent::Sensor {
                a,
                b,
                started: event.started(),
            },
            (KIND_SOLID, KIND_SOLID) if i1 != i2 => RawEvent::AgentContact {
                a,
                b,
                started: event.started(),
            },
            (KIND_SOLID, KIND_OBSTACLE) => RawEvent::ObstacleContact {
                a: i1,
                obstacle: i2,
                started: event.started(),
            },
            (KIND_OBSTACLE, KIND_SOLID) => RawEvent::ObstacleContact {
                a: i2,
                obstacle: i1,
                started: event.started(),
            },
            _ => return,
        };
        if let Ok(mut events) = self.events.lock() {
            events.push(ev);
        }
    }

    fn handle_contact_force_event(
        &self,
        _dt: Real,
        _bodies: &RigidBodySet,
        _colliders: &ColliderSet,
        _contact_pair: &ContactPair,
        _total_force_magnitude: Real,
    ) {
    }

    fn handle_soft_body_tear_event(&self, _soft_bodies: &SoftBodySet, _event: &SoftBodyTearEvent) {}
}

/// One Rapier world: its sets, pipeline and event collector.
struct Rapier {
    params: IntegrationParameters,
    pipeline: PhysicsPipeline,
    islands: IslandManager,
    broad_phase: BroadPhaseBvh,
    narrow_phase: NarrowPhase,
    bodies: RigidBodySet,
    colliders: ColliderSet,
    impulse_joints: ImpulseJointSet,
    multibody_joints: MultibodyJointSet,
    soft_bodies: SoftBodySet,
    ccd: CCDSolver,
    collector: Collector,
}

impl Rapier {
    fn new(params: IntegrationParameters, bodies: RigidBodySet, colliders: ColliderSet) -> Self {
        Self {
            params,
            pipeline: PhysicsPipeline::new(),
            islands: IslandManager::new(),
            broad_phase: BroadPhaseBvh::new(),
            narrow_phase: NarrowPhase::new(),
            bodies,
            colliders,
            impulse_joints: ImpulseJointSet::new(),
            multibody_joints: MultibodyJointSet::new(),
            soft_bodies: SoftBodySet::new(),
            ccd: CCDSolver::new(),
            collector: Collector::default(),
        }
    }

    /// One pipeline step of `params.dt` seconds; appends its events to `out`, sorted.
    fn step(&mut self, out: &mut Vec<RawEvent>) {
        self.pipeline.step(
            Vector::ZERO,
            &self.params,
            &mut self.islands,
            &mut self.broad_phase,
            &mut self.narrow_phase,
            &mut self.bodies,
            &mut self.colliders,
            &mut self.impulse_joints,
            &mut self.multibody_joints,
            &mut self.soft_bodies,
            &mut self.ccd,
            &(),
            &self.collector,
        );
        if let Ok(mut events) = self.collector.events.lock() {
            events.sort_unstable();
            out.append(&mut events);
        }
    }
}

/// A broad-phase skin for `world` at step `dt`, metres: [`SPARSE_SKIN_STEPS`] steps of
/// travel when a fat AABB of that skin round a ball of `radius` is expected to overlap at
/// most `max_neighbours` others (`per_agent` colliders per agent; agents are held in D(t),
/// so the density is agents / (l × height)), else [`DENSE_SKIN`].
fn skin_for(world: &World, dt: f64, per_agent: f64, radius: f64, max_neighbours: f64) -> f64 {
    let sparse = SPARSE_SKIN_STEPS * world.swarm.speed * dt;
    let area = world.leader.window.min(world.arena.width) * world.arena.height;
    let density = world.swarm.agents as f64 / area;
    let side = 2.0 * (sparse + radius);
    let neighbours = per_agent * density * side * side;
    if sparse > DENSE_SKIN && neighbours <= max_neighbours {
        sparse
    } else {
        DENSE_SKIN
    }
}

/// The sensing world: a second Rapier world that holds one sensor ball of radius r_d / 2
/// per agent (collider `i` is agent `i`'s) and only runs collision detection. Its balls
/// have no body (Rapier counts them as fixed, hence `FIXED_FIXED`) and are moved to the
/// agents' positions before each detection.
///
/// Kept apart from [`Scene`] so that it can run on its own thread (`sensing.rs`): sensors
/// never act on the motion, and the physics world without them steps about a third faster
/// with the same trajectories, bit for bit, in every run compared (docs/speed.md,
/// "Forty-sixth session").
pub(crate) struct SensorWorld {
    rapier: Rapier,
    /// Where each ball is now; only the balls that moved are set again.
    at: Vec<Vector>,
    /// Each ball's handle, in agent order.
    balls: Vec<ColliderHandle>,
}

impl SensorWorld {
    /// One sensor ball per agent of `world`, at `positions`.
    pub(crate) fn new(world: &World, positions: &[(f64, f64)], dt: f64) -> Self {
        let radius = world.swarm.detection_radius / 2.0;
        let skin = skin_for(world, dt, 1.0, radius, SENSING_MAX_NEIGHBOURS) as f32;
        let params = IntegrationParameters {
            dt: 0.0,
            length_unit: skin / SKIN_FACTOR,
            normalized_prediction_distance: 0.0,
            ..IntegrationParameters::default()
        };
        let groups = InteractionGroups::new(GROUP_SENSOR, GROUP_SENSOR, InteractionTestMode::And);
        let radius = radius as f32;
        let mut colliders = ColliderSet::new();
        let at: Vec<Vector> = positions.iter().map(|p| v(p.0, p.1)).collect();
        let balls = at
            .iter()
            .enumerate()
            .map(|(i, &p)| {
                colliders.insert(
                    ColliderBuilder::ball(radius)
                        .sensor(true)
                        .translation(p)
                        .collision_groups(groups)
                        .active_collision_types(ActiveCollisionTypes::FIXED_FIXED)
                        .active_events(ActiveEvents::COLLISION_EVENTS)
                        .user_data(KIND_SENSOR | i as u128),
                )
            })
            .collect();
        Self {
            rapier: Rapier::new(params, RigidBodySet::new(), colliders),
            at,
            balls,
        }
    }

    /// Moves the balls to `positions` (one per agent, as [`Scene::read_positions`] gives
    /// them) and appends the sensor events of that configuration to `out`, sorted.
    pub(crate) fn detect(&mut self, positions: &[(f64, f64)], out: &mut Vec<RawEvent>) {
        for ((p, at), &h) in positions.iter().zip(&mut self.at).zip(&self.balls) {
            // Exact: the positions are the physics world's f32 translations widened.
            let p = v(p.0, p.1);
            if *at != p {
                *at = p;
                if let Some(ball) = self.rapier.colliders.get_mut(h) {
                    ball.set_translation(p);
                }
            }
        }
        self.rapier.step(out);
    }
}

/// The physics world of a run: the agents' bodies (agent `i` is `agents[i]`), their solid
/// balls, and the obstacles.
pub(crate) struct Scene {
    rapier: Rapier,
    agents: Vec<RigidBodyHandle>,
}

fn v(x: f64, y: f64) -> Vector {
    Vector::new(x as f32, y as f32)
}

fn obstacle_collider(o: &Obstacle) -> Option<ColliderBuilder> {
    Some(match o {
        Obstacle::Rect { min, max } => ColliderBuilder::cuboid(
            ((max.0 - min.0) / 2.0) as f32,
            ((max.1 - min.1) / 2.0) as f32,
        )
        .translation(v((min.0 + max.0) / 2.0, (min.1 + max.1) / 2.0)),
        Obstacle::Circle { center, radius } => {
            ColliderBuilder::ball(*radius as f32).translation(v(center.0, center.1))
        }
        // A closed polyline is the polygon's exact boundary; agents start outside it and
        // move far less than their radius per step, so they never reach the inside.
        Obstacle::Polygon { points } => {
            let n = points.len() as u32;
            if n < 3 {
                return None;
            }
            let mut vertices: Vec<Vector> = points.iter().map(|p| v(p.0, p.1)).collect();
            let indices = (0..n).map(|i| [i, (i + 1) % n]).collect();
            if points.len() < ORIENTED_MIN_VERTICES {
                ColliderBuilder::polyline(vertices, Some(indices))
            } else {
                // One-sided: Rapier then clamps contact normals to the outside, which must
                // lie on the right of each edge (counter-clockwise winding).
                if polygon_area(points) < 0.0 {
                    vertices.reverse();
                }
                ColliderBuilder::polyline_with_flags(
                    vertices,
                    Some(indices),
                    PolylineFlags::ORIENTED,
                )
            }
        }
        // A thick segment is exactly a capsule.
        Obstacle::Wall {
            from,
            to,
            thickness,
        } => ColliderBuilder::capsule_from_endpoints(
            v(from.0, from.1),
            v(to.0, to.1),
            (*thickness / 2.0) as f32,
        ),
    })
}

impl Scene {
    /// Builds the scene with one agent at each of `positions`.
    pub(crate) fn new(world: &World, positions: &[(f64, f64)], dt: f64) -> Self {
        let prediction = Self::prediction_distance(world, dt) as f32;
        let skin = Self::broad_phase_skin(world, dt) as f32;
        let params = IntegrationParameters {
            dt: dt as f32,
            length_unit: skin / SKIN_FACTOR,
            normalized_prediction_distance: prediction * SKIN_FACTOR / skin,
            normalized_allowed_linear_error: ALLOWED_LINEAR_ERROR * SKIN_FACTOR / skin,
            normalized_contact_recycle_distance: CONTACT_RECYCLE_DISTANCE * SKIN_FACTOR / skin,
            normalized_max_corrective_velocity: MAX_CORRECTIVE_VELOCITY * SKIN_FACTOR / skin,
            normalized_max_linear_velocity: 1e4,
            // Agents are set to their walking velocity every step and only need to not
            // overlap: one iteration suffices, and CCD is useless at 3 mm per step.
            num_solver_iterations: 1,
            max_ccd_substeps: 0,
            ..IntegrationParameters::default()
        };
        let mut bodies = RigidBodySet::new();
        let mut colliders = ColliderSet::new();
        let obstacle_groups =
            InteractionGroups::new(GROUP_OBSTACLE, GROUP_SOLID, InteractionTestMode::And);
        let fixed = bodies.insert(RigidBodyBuilder::fixed());
        let (w, h) = (world.arena.width as f32, world.arena.height as f32);
        let t = SIDE_THICKNESS;
        let sides = [
            (w / 2.0, -t / 2.0, w / 2.0 + t, t / 2.0),
            (w / 2.0, h + t / 2.0, w / 2.0 + t, t / 2.0),
            (-t / 2.0, h / 2.0, t / 2.0, h / 2.0 + t),
            (w + t / 2.0, h / 2.0, t / 2.0, h / 2.0 + t),
        ];
        // Each side its own index below SIDES, in the order of the engine's `side_gaps`
        // (left, right, bottom, top), so that touching one side is tracked apart from another.
        for ((cx, cy, hx, hy), j) in sides.into_iter().zip([2u32, 3, 0, 1]) {
            colliders.insert_with_parent(
                ColliderBuilder::cuboid(hx, hy)
                    .translation(Vector::new(cx, cy))
                    .collision_groups(obstacle_groups)
                    .friction(0.0)
                    .user_data(KIND_OBSTACLE | u128::from(SIDES - j)),
                fixed,
                &mut bodies,
            );
        }
        for (k, o) in world.obstacles.iter().enumerate() {
            if let Some(c) = obstacle_collider(o) {
                colliders.insert_with_parent(
                    c.collision_groups(obstacle_groups)
                        .friction(0.0)
                        .user_data(KIND_OBSTACLE | k as u128),
                    fixed,
                    &mut bodies,
                );
            }
        }
        let solid_groups = InteractionGroups::new(
            GROUP_SOLID,
            GROUP_SOLID | GROUP_OBSTACLE,
            InteractionTestMode::And,
        );
        let body_radius = world.swarm.body_radius as f32;
        let mut agents = Vec::with_capacity(positions.len());
        for (i, p) in positions.iter().enumerate() {
            let handle = bodies.insert(
                RigidBodyBuilder::dynamic()
                    .translation(v(p.0, p.1))
                    .lock_rotations()
                    .gravity_scale(0.0)
                    .can_sleep(false)
                    .user_data(i as u128),
            );
            colliders.insert_with_parent(
                ColliderBuilder::ball(body_radius)
                    .density(1.0)
                    .friction(0.0)
                    .restitution(0.0)
                    .collision_groups(solid_groups)
                    .active_events(ActiveEvents::COLLISION_EVENTS)
                    .user_data(KIND_SOLID | i as u128),
                handle,
                &mut bodies,
            );
            agents.push(handle);
        }
        Self {
            rapier: Rapier::new(params, bodies, colliders),
            agents,
        }
    }

    /// Broad-phase skin for `world` at step `dt`, metres: [`SPARSE_SKIN_STEPS`] steps of
    /// travel when the swarm is sparse enough that such fat AABBs rarely overlap, else
    /// [`DENSE_SKIN`]. The rule still counts the sensor ball that rode on each body until
    /// the forty-sixth session (two colliders per agent, the larger radius): the skin shapes
    /// Rapier's tolerances and so the trajectories, which stay as they were.
    pub(crate) fn broad_phase_skin(world: &World, dt: f64) -> f64 {
        let radius = world
            .swarm
            .body_radius
            .max(world.swarm.detection_radius / 2.0);
        skin_for(world, dt, 2.0, radius, SPARSE_MAX_NEIGHBOURS)
    }

    /// Gap below which Rapier reports a contact pair (and creates speculative contacts),
    /// metres.
    pub(crate) fn prediction_distance(world: &World, dt: f64) -> f64 {
        (PREDICTION_STEPS * world.swarm.speed * dt).max(MIN_PREDICTION_DISTANCE)
    }

    /// Writes every agent's position (metres) into `out` (one slot per agent) and returns
    /// the first agent whose position is not finite, if any.
    pub(crate) fn read_positions(&self, out: &mut [(f64, f64)]) -> Option<usize> {
        let mut bad = None;
        for (i, (slot, &h)) in out.iter_mut().zip(&self.agents).enumerate() {
            let t = self.rapier.bodies[h].translation();
            if bad.is_none() && !(t.x.is_finite() && t.y.is_finite()) {
                bad = Some(i);
            }
            *slot = (f64::from(t.x), f64::from(t.y));
        }
        bad
    }

    /// Sets agent `i` moving with velocity `vel` (m/s), or static (translations locked)
    /// when `vel` is `None`.
    pub(crate) fn set_motion(&mut self, i: usize, vel: Option<(f64, f64)>) {
        let handle = self.agents[i];
        // `IndexMut` on the body set flags the body as modified by the user, which costs it
        // a pass of Rapier's change tracking (islands, colliders, NaN checks) in the next
        // step: look first, and borrow mutably only to change something.
        let body = &self.rapier.bodies[handle];
        let locked = body.is_translation_locked();
        match vel {
            Some((vx, vy)) => {
                let target = v(vx, vy);
                if locked || body.linvel() != target {
                    let body = &mut self.rapier.bodies[handle];
                    if locked {
                        body.lock_translations(false, true);
                    }
                    body.set_linvel(target, true);
                }
            }
            None => {
                if !locked {
                    let body = &mut self.rapier.bodies[handle];
                    body.lock_translations(true, true);
                    body.set_linvel(Vector::ZERO, true);
                }
            }
        }
    }

    /// Advances by `dt` seconds (`0` only runs collision detection) and appends the events
    /// seen at the configuration before the step to `out`, in a deterministic order.
    pub(crate) fn step(&mut self, dt: f64, out: &mut Vec<RawEvent>) {
        self.rapier.params.dt = dt as f32;
        self.rapier.step(out);
    }
}
