//! `WorldSpec::check`: defaults, then every validation rule, then the validated [`World`].
//!
//! Rules, in order (each error names the field path, the value, the rule and a fix):
//! numbers finite and in range; obstacles well formed (rect `min < max`, positive radii and
//! thickness, walls of positive length, polygons with ≥ 3 distinct vertices, non-zero area
//! and no crossing edges — checked pairwise, O(n²) in the vertices) and inside the arena
//! (touching is allowed; a wall's centre line must be inside, its thickness may overhang);
//! swarm, leader, time step and mapping parameters consistent with each other (e.g.
//! `2·speed·dt ≤ r_d` so no encounter is stepped over, windows longer than their
//! overlap); finally free space for the agents, on a raster of at most 2 cm (see
//! `freespace.rs`): the initial placement area must hold the agents, and every window
//! D(t) the leader visits must contain free space.

use super::error::WorldError;
use super::freespace::FreeSpaceRaster;
use super::geometry::polygon_self_intersection;
use super::locate::locate;
use super::spec::{MethodSpec, ObstacleSpec, PlacementSpec, SpecOrigin, WorldSpec};
use super::types::*;

/// Largest number of agents accepted (memory for the simulation stays modest).
pub const MAX_AGENTS: usize = 1_000_000;

/// Longest side of an arena, metres: Rapier works in `f32`, whose spacing at 10 km is
/// about 1 mm, a tenth of the bundled worlds' detection radius.
pub const MAX_ARENA_SIDE: f64 = 10_000.0;
/// Largest number of time steps in one run (dispersion plus sweep over `dt`).
pub const MAX_STEPS: f64 = 1e9;
/// Largest number of windows.
pub const MAX_WINDOWS: usize = 10_000;

/// Builds errors that point at a field of the spec.
struct Ctx<'a> {
    origin: &'a SpecOrigin,
}

impl Ctx<'_> {
    fn err(&self, field: &str, problem: impl Into<String>, fix: impl Into<String>) -> WorldError {
        let name = if self.origin.name.is_empty() {
            "<world>"
        } else {
            self.origin.name.as_str()
        };
        let by_override = self.origin.overrides.iter().rev().find(|(p, _)| {
            // `obstacles.scale` rewrites every obstacle, so it answers for all of them.
            let p = if p == "obstacles.scale" {
                "obstacles"
            } else {
                p
            };
            field == p || field.starts_with(&format!("{p}.")) || field.starts_with(&format!("{p}["))
        });
        let location = if let Some((p, v)) = by_override {
            format!("{name} (--set {p}={v})")
        } else if let Some((line, col)) = self.origin.text.as_deref().and_then(|t| locate(t, field))
        {
            format!("{name}:{line}:{col}")
        } else {
            name.to_string()
        };
        WorldError::Invalid {
            location,
            field: field.to_string(),
            problem: problem.into(),
            fix: fix.into(),
        }
    }

    fn finite(&self, field: &str, v: f64, fix: &str) -> Result<f64, WorldError> {
        if v.is_finite() {
            Ok(v)
        } else {
            Err(self.err(
                field,
                format!("is {} (must be a finite number)", short(v)),
                fix,
            ))
        }
    }

    fn positive(&self, field: &str, v: f64, unit: &str, fix: &str) -> Result<f64, WorldError> {
        self.finite(field, v, fix)?;
        if v > 0.0 {
            Ok(v)
        } else {
            let unit = if unit.is_empty() {
                String::new()
            } else {
                format!(" {unit}")
            };
            Err(self.err(field, format!("is {} (must be > 0{unit})", given(v)), fix))
        }
    }

    fn non_negative(&self, field: &str, v: f64, unit: &str, fix: &str) -> Result<f64, WorldError> {
        self.finite(field, v, fix)?;
        if v >= 0.0 {
            Ok(v)
        } else {
            Err(self.err(field, format!("is {} (must be ≥ 0 {unit})", given(v)), fix))
        }
    }

    fn point(&self, field: &str, p: Vec2) -> Result<Vec2, WorldError> {
        if p.0.is_finite() && p.1.is_finite() {
            Ok(p)
        } else {
            Err(self.err(
                field,
                format!(
                    "is ({}, {}) (coordinates must be finite numbers)",
                    given(p.0),
                    given(p.1)
                ),
                "give finite coordinates in metres",
            ))
        }
    }

    fn count(
        &self,
        field: &str,
        v: i64,
        min: i64,
        max: usize,
        fix: &str,
    ) -> Result<usize, WorldError> {
        match usize::try_from(v) {
            Ok(n) if v >= min && n <= max => Ok(n),
            _ if v < min => Err(self.err(field, format!("is {v} (must be at least {min})"), fix)),
            _ => Err(self.err(field, format!("is {v} (must be at most {max})"), fix)),
        }
    }
}

/// Number of landmarks the fraction gives among `agents` agents: `round(fraction · agents)`.
pub fn landmark_count(fraction: f64, agents: usize) -> usize {
    // Rounding a finite, in-range product: the cast cannot truncate meaningfully.
    (fraction * agents as f64).round().max(0.0) as usize
}

fn fmt_pt(p: Vec2) -> String {
    format!("({}, {})", given(p.0), given(p.1))
}

fn check_obstacle(
    ctx: &Ctx<'_>,
    i: usize,
    o: &ObstacleSpec,
    arena: &Arena,
) -> Result<Obstacle, WorldError> {
    let f = |s: &str| format!("obstacles[{i}].{s}");
    let obstacle = match o {
        ObstacleSpec::Rect { min, max } => {
            let min = ctx.point(&f("min"), *min)?;
            let max = ctx.point(&f("max"), *max)?;
            if !(min.0 < max.0 && min.1 < max.1) {
                return Err(ctx.err(
                    &f("max"),
                    format!(
                        "is {} but min is {} (need min.x < max.x and min.y < max.y)",
                        fmt_pt(max),
                        fmt_pt(min)
                    ),
                    "give the lower-left corner as min and the upper-right one as max, with a positive width and height",
                ));
            }
            Obstacle::Rect { min, max }
        }
        ObstacleSpec::Circle { center, radius } => {
            let center = ctx.point(&f("center"), *center)?;
            let radius = ctx.positive(
                &f("radius"),
                *radius,
                "metres",
                "give the circle a positive radius",
            )?;
            Obstacle::Circle { center, radius }
        }
        ObstacleSpec::Polygon { points } => {
            if points.len() < 3 {
                return Err(ctx.err(
                    &f("points"),
                    format!("has {} vertices (a polygon needs at least 3)", points.len()),
                    "list at least three vertices in order along the boundary, or use a Wall for a segment",
                ));
            }
            for (j, p) in points.iter().enumerate() {
                ctx.point(&f(&format!("points[{j}]")), *p)?;
            }
            if let Some((j, k)) = first_repeat(points) {
                return Err(ctx.err(
                    &f(&format!("points[{j}]")),
                    format!("repeats points[{k}] {} (vertices must be distinct)", fmt_pt(points[j])),
                    "remove the repeated vertex; the polygon closes itself, so do not repeat the first vertex at the end",
                ));
            }
            if collinear(points) {
                return Err(ctx.err(
                    &f("points"),
                    "has zero area (its vertices are collinear)",
                    "give the polygon some width, or use a Wall for a thin straight obstacle",
                ));
            }
            if let Some((a, b)) = polygon_self_intersection(points) {
                let n = points.len();
                return Err(ctx.err(
                    &f("points"),
                    format!(
                        "is self-intersecting: edge points[{a}]→points[{}] meets edge points[{b}]→points[{}]",
                        (a + 1) % n,
                        (b + 1) % n
                    ),
                    "list the vertices in order along the boundary (non-convex shapes are fine, crossing edges are not), or split it into several polygons",
                ));
            }
            Obstacle::Polygon {
                points: points.clone(),
            }
        }
        ObstacleSpec::Wall {
            from,
            to,
            thickness,
        } => {
            let from = ctx.point(&f("from"), *from)?;
            let to = ctx.point(&f("to"), *to)?;
            if from == to {
                return Err(ctx.err(
                    &f("to"),
                    format!(
                        "equals from {} (a wall needs a positive length)",
                        fmt_pt(from)
                    ),
                    "move one end, or use a Circle for a round pillar",
                ));
            }
            let thickness = ctx.positive(
                &f("thickness"),
                *thickness,
                "metres",
                "give the wall a positive thickness, e.g. 0.1",
            )?;
            Obstacle::Wall {
                from,
                to,
                thickness,
            }
        }
    };
    // A wall's centre line must be in the arena; its half-thickness may overhang a side.
    let (lo, hi) = match &obstacle {
        Obstacle::Wall { from, to, .. } => bbox(&[*from, *to]),
        other => other.bounding_box(),
    };
    let tol = 1e-9 * arena.width.max(arena.height);
    if lo.0 < -tol || lo.1 < -tol || hi.0 > arena.width + tol || hi.1 > arena.height + tol {
        let what = if matches!(obstacle, Obstacle::Wall { .. }) {
            "its centre line spans"
        } else {
            "spans"
        };
        return Err(ctx.err(
            &format!("obstacles[{i}]"),
            format!(
                "sticks out of the arena: {what} x {} to {}, y {} to {} m, but the arena is x 0 to {}, y 0 to {} m",
                given(lo.0),
                given(hi.0),
                given(lo.1),
                given(hi.1),
                given(arena.width),
                given(arena.height)
            ),
            "move or shrink it so it lies inside the arena (touching the sides is allowed)",
        ));
    }
    Ok(obstacle)
}

/// Whether all points lie on one line (within a tolerance relative to their spread).
fn collinear(points: &[Vec2]) -> bool {
    let p0 = points[0];
    let far = points.iter().copied().fold(p0, |f, p| {
        if (p.0 - p0.0).hypot(p.1 - p0.1) > (f.0 - p0.0).hypot(f.1 - p0.1) {
            p
        } else {
            f
        }
    });
    let d = (far.0 - p0.0, far.1 - p0.1);
    let len2 = d.0 * d.0 + d.1 * d.1;
    points.iter().all(|p| {
        let cross = d.0 * (p.1 - p0.1) - d.1 * (p.0 - p0.0);
        cross.abs() <= 1e-9 * len2
    })
}

/// A number the user gave, exactly as Rust reads it back, but as mantissa and exponent
/// (`1e300`, `2.5e-9`) far from the metres and seconds of a world instead of hundreds of
/// digits.
pub fn given(x: f64) -> String {
    if x == 0.0 || !x.is_finite() || (1e-6..1e9).contains(&x.abs()) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

/// Which way from a bound the values a check accepts lie: below an upper bound (`Down`),
/// above a lower one (`Up`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Inward {
    Down,
    Up,
}

impl Inward {
    fn round(self, x: f64) -> f64 {
        match self {
            Inward::Down => x.floor(),
            Inward::Up => x.ceil(),
        }
    }

    fn step(self, x: f64) -> f64 {
        match self {
            Inward::Down => x.next_down(),
            Inward::Up => x.next_up(),
        }
    }
}

/// A bound to suggest in a message, as short as the check lets it be: [`short`] (rounded
/// to nearest) where the check `accepts` that value, else rounded `inward` to 6
/// significant digits where it accepts that, else exactly ([`given`]) the bound or, where
/// even that is refused, the nearest value inward that is not. Either way a user who copies
/// the number gets a value the check accepts.
pub fn suggest(bound: f64, inward: Inward, accepts: impl Fn(f64) -> bool) -> String {
    let nearest = short(bound);
    if nearest.parse::<f64>().is_ok_and(&accepts) {
        return nearest;
    }
    rounded_within(bound, inward, accepts)
}

/// A decimal number's text without trailing zeros after its point (nor a bare point).
fn trim_zeros(s: &str) -> &str {
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.')
    } else {
        s
    }
}

fn rounded_within(bound: f64, inward: Inward, inside: impl Fn(f64) -> bool) -> String {
    if bound.is_normal() {
        // The decimal exponent as Rust writes it (`{:e}`), not `log10().floor()`, which
        // can be one off next to a power of ten.
        let sci = format!("{bound:e}");
        let (mantissa, e) = sci
            .split_once('e')
            .and_then(|(m, e)| Some((m.parse::<f64>().ok()?, e.parse::<i32>().ok()?)))
            .unwrap_or((bound, 0));
        let s = if (1e-6..1e9).contains(&bound.abs()) {
            let digits = (5 - e).max(0);
            let scale = 10f64.powi(digits);
            let text = format!(
                "{:.*}",
                digits as usize,
                inward.round(bound * scale) / scale
            );
            trim_zeros(&text).to_string()
        } else {
            // Mantissa and exponent, as `short` writes them; a mantissa rounded up to 10
            // moves to the next exponent.
            let rounded = inward.round(mantissa * 1e5) / 1e5;
            let (m, e) = if rounded.abs() >= 10.0 {
                (rounded / 10.0, e + 1)
            } else {
                (rounded, e)
            };
            format!("{}e{e}", trim_zeros(&format!("{m:.5}")))
        };
        if s.parse::<f64>().is_ok_and(&inside) {
            return s;
        }
    }
    // Exactly, or the nearest value inward that the check accepts (a bound computed in
    // floating point, a subnormal one above all, may itself fall just outside).
    let mut v = bound;
    for _ in 0..64 {
        if inside(v) {
            return given(v);
        }
        v = inward.step(v);
    }
    given(bound)
}

/// A computed number compared in a message with `other`: [`short`], unless that would
/// read the same as `other` as written ([`given`]) or rounded ([`short`]); then exactly.
fn apart(x: f64, other: f64) -> String {
    let s = short(x);
    if s == given(other) || s == short(other) {
        given(x)
    } else {
        s
    }
}

/// A computed number, rounded to 6 significant digits for messages (mantissa and exponent
/// far from 1).
pub fn short(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    if !(1e-6..1e9).contains(&x.abs()) {
        // Far from the metres and seconds of a world: mantissa and exponent, not hundreds
        // of digits.
        let s = format!("{x:.5e}");
        let (m, e) = s.split_once('e').unwrap_or((&s, "0"));
        return format!("{}e{e}", trim_zeros(m));
    }
    let digits = (5 - x.abs().log10().floor() as i32).max(0) as usize;
    trim_zeros(&format!("{x:.digits$}")).to_string()
}

fn bbox(points: &[Vec2]) -> (Vec2, Vec2) {
    points.iter().fold(
        (
            (f64::INFINITY, f64::INFINITY),
            (f64::NEG_INFINITY, f64::NEG_INFINITY),
        ),
        |(lo, hi), p| {
            (
                (lo.0.min(p.0), lo.1.min(p.1)),
                (hi.0.max(p.0), hi.1.max(p.1)),
            )
        },
    )
}

impl WorldSpec {
    /// Fills in the defaults and validates every rule, giving the [`World`] the
    /// simulator and the mapping stages accept.
    pub fn check(self) -> Result<World, WorldError> {
        let ctx = Ctx {
            origin: &self.origin,
        };

        // Name: explicit, else the file's stem.
        let name = match &self.name {
            Some(n) => n.clone(),
            None => std::path::Path::new(&self.origin.name)
                .file_stem()
                .and_then(|s| s.to_str())
                .filter(|s| !s.is_empty())
                .unwrap_or("world")
                .to_string(),
        };
        if name.trim().is_empty() || name.chars().any(char::is_control) {
            return Err(ctx.err(
                "name",
                format!("is {name:?} (must be non-empty, without control characters)"),
                "give the world a short printable name, e.g. \"scenario1\"",
            ));
        }

        // Arena.
        let a = self.arena.clone().unwrap_or_default();
        let arena = Arena {
            width: ctx.positive(
                "arena.width",
                a.width.unwrap_or(30.0),
                "metres",
                "give the arena a positive width, e.g. 30.0",
            )?,
            height: ctx.positive(
                "arena.height",
                a.height.unwrap_or(10.0),
                "metres",
                "give the arena a positive height, e.g. 10.0",
            )?,
        };
        for (field, v) in [("arena.width", arena.width), ("arena.height", arena.height)] {
            if v > MAX_ARENA_SIDE {
                return Err(ctx.err(
                    field,
                    format!("is {} m, more than {MAX_ARENA_SIDE} m: the physics engine works in single precision, which cannot place centimetre-sized agents that far from the origin", given(v)),
                    "use an arena of at most 10 km a side (the paper's is 30 m × 10 m)",
                ));
            }
        }

        // Obstacles.
        let obstacles = self
            .obstacles
            .iter()
            .flatten()
            .enumerate()
            .map(|(i, o)| check_obstacle(&ctx, i, o, &arena))
            .collect::<Result<Vec<_>, _>>()?;

        // Swarm.
        let d = SwarmParams::default();
        let s = self.swarm.clone().unwrap_or_default();
        let agents = ctx.count(
            "swarm.agents",
            s.agents.unwrap_or(d.agents as i64),
            1,
            MAX_AGENTS,
            "use 1 to 1 000 000 agents (the paper uses 100)",
        )?;
        let speed = ctx.positive(
            "swarm.speed",
            s.speed.unwrap_or(d.speed),
            "m/s",
            "give the agents a positive walking speed (the paper's v_m is 0.1)",
        )?;
        let detection_radius = ctx.positive(
            "swarm.detection_radius",
            s.detection_radius.unwrap_or(d.detection_radius),
            "metres",
            "give a positive detection radius (the paper's r_d is 0.01)",
        )?;
        let diagonal = arena.width.hypot(arena.height);
        if detection_radius > diagonal {
            return Err(ctx.err(
                "swarm.detection_radius",
                format!(
                    "is {} m, more than the arena's diagonal ({} m): every pair of agents would be in contact all the time",
                    given(detection_radius),
                    apart(diagonal, detection_radius)
                ),
                "use a detection radius well below the arena's size (the paper's r_d is 0.01 m)",
            ));
        }
        let landmark_fraction = ctx.finite(
            "swarm.landmark_fraction",
            s.landmark_fraction.unwrap_or(d.landmark_fraction),
            "use a fraction in [0, 1), e.g. 0.1",
        )?;
        if !(0.0..1.0).contains(&landmark_fraction) {
            return Err(ctx.err(
                "swarm.landmark_fraction",
                format!(
                    "is {} (must be in [0, 1): a share of the agents, and some must keep walking)",
                    given(landmark_fraction)
                ),
                "use a fraction such as the paper's 0.1",
            ));
        }
        let landmarks = landmark_count(landmark_fraction, agents);
        if landmark_fraction > 0.0 && landmarks >= agents {
            return Err(ctx.err(
                "swarm.landmark_fraction",
                format!("is {landmark_fraction}, which makes {landmarks} landmark(s) out of {agents} agent(s) and leaves none walking"),
                "lower the fraction or add agents, so that at least one agent keeps walking",
            ));
        }
        let body_radius = ctx.positive(
            "swarm.body_radius",
            s.body_radius.unwrap_or(d.body_radius),
            "metres",
            "give the agents a positive body radius below half the detection radius",
        )?;
        if body_radius >= detection_radius / 2.0 {
            return Err(ctx.err(
                "swarm.body_radius",
                format!(
                    "is {} m, not below half the detection radius ({} m): two bodies keep their centres at least {} m apart, so they could never come within r_d = {} m and no encounter would ever be recorded",
                    given(body_radius),
                    given(detection_radius / 2.0),
                    short(2.0 * body_radius),
                    given(detection_radius)
                ),
                "use a body radius below r_d / 2 (the default is 0.004 with r_d = 0.01), or raise swarm.detection_radius",
            ));
        }
        let mean_run_length = ctx.positive(
            "swarm.mean_run_length",
            s.mean_run_length.unwrap_or(d.mean_run_length),
            "metres",
            "give a positive mean run length λ, e.g. 1.0",
        )?;
        let stop_rate = ctx.non_negative(
            "swarm.stop_rate",
            s.stop_rate.unwrap_or(d.stop_rate),
            "per second",
            "use 0 for no spontaneous stops, or a positive rate such as 0.01",
        )?;
        let mean_stop_duration = ctx.positive(
            "swarm.mean_stop_duration",
            s.mean_stop_duration.unwrap_or(d.mean_stop_duration),
            "seconds",
            "give a positive mean stop duration, e.g. 5.0 (set stop_rate to 0 to disable stops)",
        )?;
        let comm_radius = ctx.positive(
            "swarm.comm_radius",
            s.comm_radius.unwrap_or(d.comm_radius),
            "metres",
            "give a positive communication radius, e.g. 1.0",
        )?;
        let wall_following = ctx.finite(
            "swarm.wall_following",
            s.wall_following.unwrap_or(d.wall_following),
            "use a probability in [0, 1], e.g. 0.5",
        )?;
        if !(0.0..=1.0).contains(&wall_following) {
            return Err(ctx.err(
                "swarm.wall_following",
                format!("is {} (must be a probability in [0, 1])", given(wall_following)),
                "use 0 for the paper's pure random walk, 1 to follow every wall hit, or a value between",
            ));
        }
        let wall_following_length = ctx.positive(
            "swarm.wall_following_length",
            s.wall_following_length.unwrap_or(d.wall_following_length),
            "metres",
            "give a positive mean length followed along a wall, e.g. 1.0",
        )?;
        let return_patience = ctx.positive(
            "swarm.return_patience",
            s.return_patience.unwrap_or(d.return_patience),
            "seconds",
            "give a positive patience in seconds, e.g. 300.0 (1e12 never escapes)",
        )?;
        let placement = match s.placement.clone() {
            None => d.placement.clone(),
            Some(PlacementSpec::Window) => Placement::Window,
            Some(PlacementSpec::Disk { radius }) => Placement::Disk {
                radius: ctx.positive(
                    "swarm.placement.radius",
                    radius.unwrap_or(1.0),
                    "metres",
                    "give the placement disc a positive radius, e.g. 1.0, or use `Window`",
                )?,
            },
        };
        let swarm = SwarmParams {
            agents,
            speed,
            detection_radius,
            landmark_fraction,
            body_radius,
            mean_run_length,
            stop_rate,
            mean_stop_duration,
            comm_radius,
            wall_following,
            wall_following_length,
            return_patience,
            keep_surplus_landmarks: s.keep_surplus_landmarks.unwrap_or(d.keep_surplus_landmarks),
            placement,
        };

        // Leader.
        let l = self.leader.clone().unwrap_or_default();
        let lspeed = ctx.positive(
            "leader.speed",
            l.speed.unwrap_or(0.005),
            "m/s",
            "give the leader a positive sweep speed (the paper's is 0.005)",
        )?;
        let window = ctx.positive(
            "leader.window",
            l.window.unwrap_or(3.0),
            "metres",
            "give a positive window length l (the paper's is 3.0)",
        )?;
        if window > arena.width {
            return Err(ctx.err(
                "leader.window",
                format!(
                    "is {} m, longer than the arena ({} m wide)",
                    given(window),
                    given(arena.width)
                ),
                "use a window no longer than arena.width (the paper uses 3 m in a 30 m arena)",
            ));
        }
        let (xlo, xhi) = (window / 2.0, arena.width - window / 2.0);
        let tol = 1e-9 * arena.width;
        let sweep_end = |field: &str, v: Option<f64>, default: f64| {
            let x = ctx.finite(field, v.unwrap_or(default), "give an x in metres")?;
            if x < xlo - tol || x > xhi + tol {
                // Rounded unless that makes the two ends, or an end and x, read the same.
                let range = if short(xlo) == short(xhi) {
                    (given(xlo), given(xhi))
                } else {
                    (apart(xlo, x), apart(xhi, x))
                };
                return Err(ctx.err(
                    field,
                    format!("is {} m, outside [window/2, width − window/2] = [{}, {}] m, so D(t) would stick out of the arena", given(x), range.0, range.1),
                    format!(
                        "use an x between {} and {}, or leave it out for the default",
                        suggest(xlo, Inward::Up, |v| v >= xlo - tol && v <= xhi + tol),
                        suggest(xhi, Inward::Down, |v| v >= xlo - tol && v <= xhi + tol)
                    ),
                ));
            }
            Ok(x.clamp(xlo, xhi))
        };
        let start_x = sweep_end("leader.start_x", l.start_x, xlo)?;
        let end_x = sweep_end("leader.end_x", l.end_x, xhi)?;
        let leader = LeaderParams {
            speed: lspeed,
            window,
            start_x,
            end_x,
        };

        // Time stepping.
        let sd = SimulationParams::default();
        let sim = self.simulation.clone().unwrap_or_default();
        let dt = ctx.positive(
            "simulation.dt",
            sim.dt.unwrap_or(sd.dt),
            "seconds",
            "give a positive time step, e.g. 0.02",
        )?;
        // A relative tolerance keeps the boundary case `dt = r_d / (2·speed)` valid.
        if 2.0 * speed * dt > detection_radius * (1.0 + 1e-9) {
            return Err(ctx.err(
                "simulation.dt",
                format!(
                    "is {} s: two agents walking at {} m/s towards each other close {} m per step, more than the detection radius {} m, so encounters could be stepped over unseen",
                    given(dt),
                    given(speed),
                    apart(2.0 * speed * dt, detection_radius),
                    given(detection_radius)
                ),
                format!(
                    "set simulation.dt ≤ r_d / (2·speed) = {} s (a world that sets no dt gets the default), or lower swarm.speed, or raise swarm.detection_radius",
                    suggest(detection_radius / (2.0 * speed), Inward::Down, |v| {
                        2.0 * speed * v <= detection_radius * (1.0 + 1e-9)
                    })
                ),
            ));
        }
        let dispersion_time = ctx.non_negative(
            "simulation.dispersion_time",
            sim.dispersion_time.unwrap_or(sd.dispersion_time),
            "seconds",
            "use 0 to start the sweep at once, or a positive time such as 300",
        )?;
        let simulation = SimulationParams {
            dt,
            dispersion_time,
        };

        // Mapping.
        let md = MappingParams::default();
        let m = self.mapping.clone().unwrap_or_default();
        let windows = ctx.count(
            "mapping.windows",
            m.windows.unwrap_or(md.windows as i64),
            1,
            MAX_WINDOWS,
            "use 1 to 10 000 windows (the paper uses 4 to 6)",
        )?;
        let overlap = ctx.non_negative(
            "mapping.overlap",
            m.overlap.unwrap_or(md.overlap),
            "seconds",
            "use a non-negative overlap Δt shorter than one window",
        )?;
        let cluster_cutoff = ctx.positive(
            "mapping.cluster_cutoff",
            m.cluster_cutoff.unwrap_or(md.cluster_cutoff),
            "",
            "use a positive cut-off (the paper's c is 50)",
        )?;
        let subsample = ctx.count(
            "mapping.subsample",
            m.subsample.unwrap_or(md.subsample as i64),
            1,
            usize::MAX,
            "use at least one representative encounter per window, e.g. 400",
        )?;
        let neighbours = ctx.count(
            "mapping.neighbours",
            m.neighbours.unwrap_or(md.neighbours as i64),
            0,
            usize::MAX,
            "use a non-negative number of neighbours, e.g. 5",
        )?;
        let switch_cost = ctx.non_negative(
            "mapping.switch_cost",
            m.switch_cost.unwrap_or(md.switch_cost),
            "seconds",
            "use 0 (the paper's metric) or a positive cost per change of agent, e.g. detection_radius / speed",
        )?;
        let rips_points = ctx.count(
            "mapping.rips_points",
            m.rips_points.unwrap_or(md.rips_points as i64),
            crate::mapping::dense::MIN_COMPONENT_POINTS as i64,
            100_000,
            "use 50 to 100000 points, e.g. 1200 (the Embedded method's default)",
        )?;
        let outlier_rank = m
            .outlier_rank
            .map(|k| {
                ctx.count(
                    "mapping.outlier_rank",
                    k,
                    1,
                    crate::mapping::subsample::MAX_RANK,
                    "use a neighbour rank from 1 to 800, or leave it out to scale it with the \
                     leader's sweep (8 at the paper's 0.005 m/s)",
                )
            })
            .transpose()?;
        let method = match m.method {
            None | Some(MethodSpec::Paper) => MappingMethod::Paper,
            Some(MethodSpec::Embedded) => MappingMethod::Embedded,
        };
        let mapping = MappingParams {
            windows,
            overlap,
            cluster_cutoff,
            subsample,
            neighbours,
            method,
            switch_cost,
            after_landmarks: m.after_landmarks.unwrap_or(md.after_landmarks),
            encounter_midpoints: m.encounter_midpoints.unwrap_or(md.encounter_midpoints),
            rips_points,
            agent_timelines: m.agent_timelines.unwrap_or(md.agent_timelines),
            split_stability: m.split_stability.unwrap_or(md.split_stability),
            outlier_rank,
        };

        let world = World {
            name,
            arena,
            obstacles,
            swarm,
            leader,
            simulation,
            mapping,
            seed: self.seed.unwrap_or(1),
        };

        // Durations. (start_x and end_x are the clamped or default ends: computed, so
        // written short.)
        if !world.sweep_duration().is_finite() {
            return Err(ctx.err(
                "leader.speed",
                format!(
                    "is {} m/s, so the sweep from x = {} to {} m would never end",
                    given(world.leader.speed),
                    short(start_x),
                    short(end_x)
                ),
                "give the leader a speed such as the paper's 0.005 m/s",
            ));
        }
        let total = world.total_duration();
        if total.is_infinite() {
            // Each part is finite, their sum is not: blame the larger.
            let (field, value) = if dispersion_time >= world.sweep_duration() {
                (
                    "simulation.dispersion_time",
                    format!("{} s", given(dispersion_time)),
                )
            } else {
                ("leader.speed", format!("{} m/s", given(world.leader.speed)))
            };
            return Err(ctx.err(
                field,
                format!(
                    "is {value}, so the run (dispersion {} s plus a sweep of {} s) would last \
                     longer than any time a number can hold",
                    given(dispersion_time),
                    short(world.sweep_duration())
                ),
                "shorten the dispersion or speed up the leader",
            ));
        }
        if total.is_nan() || total <= 0.0 {
            return Err(ctx.err(
                "leader.end_x",
                format!(
                    "is {} m and the run lasts {total} s (dispersion {} s plus the sweep from x = {} m)",
                    short(end_x),
                    given(dispersion_time),
                    short(start_x)
                ),
                "give the sweep a positive length (end_x ≠ start_x) or a positive simulation.dispersion_time",
            ));
        }
        if total / dt > MAX_STEPS {
            return Err(ctx.err(
                "simulation.dt",
                format!(
                    "is {} s, so the {} s run needs {:.3e} steps (at most {MAX_STEPS:e} allowed)",
                    given(dt),
                    if total < 1e9 {
                        short(total)
                    } else {
                        format!("{total:.3e}")
                    },
                    total / dt
                ),
                "use a larger time step, a faster leader or a shorter sweep",
            ));
        }
        let window_duration = total / windows as f64;
        if overlap >= window_duration {
            return Err(ctx.err(
                "mapping.overlap",
                format!(
                    "is {} s, not shorter than one window ({} s = {} s run / {windows} windows)",
                    given(overlap),
                    short(window_duration),
                    short(total)
                ),
                format!(
                    "use an overlap Δt below {} s, or fewer windows",
                    suggest(window_duration, Inward::Down, |v| v <= window_duration)
                ),
            ));
        }

        check_free_space(&ctx, &world)?;
        Ok(world)
    }
}

/// Most of the placement area the agents' bodies may cover. Placement draws each agent
/// uniformly among the free spots left (random sequential addition), which jams at 54.7 %
/// of the plane covered by discs (Feder, J. Theor. Biol. 1980; Hinrichsen, Feder & Jøssang,
/// J. Stat. Phys. 1986) and needs ever more draws before: 45 % leaves room (found by the
/// forty-first session's review: the bound of one (2 · body)² square per agent, 78.5 %
/// covered, let `check` pass a swarm that `simulate` failed to place after 11 s).
pub const PLACEMENT_COVER: f64 = 0.45;

/// Free space for the agents: the placement area must hold them, and every window the
/// leader visits must contain some free space.
fn check_free_space(ctx: &Ctx<'_>, world: &World) -> Result<(), WorldError> {
    let body = world.swarm.body_radius;
    // Each body keeps placement's gap to the next.
    let reach = body + crate::sim::PLACEMENT_GAP / 2.0;
    let need = if ctx.origin.recorded {
        // A run's world: its agents were placed (module docs of `SpecOrigin::recorded`).
        0.0
    } else {
        world.swarm.agents as f64 * std::f64::consts::PI * reach * reach / PLACEMENT_COVER
    };
    let (xs, h) = (world.leader.start_x, world.arena.height);
    let half = world.leader.window / 2.0;
    match world.swarm.placement {
        Placement::Disk { radius } => {
            let free = FreeSpaceRaster::disc_free_area(world, (xs, h / 2.0), radius, body);
            if free <= 0.0 {
                return Err(ctx.err(
                    "swarm.placement",
                    format!("is a disc of radius {} m around ({}, {}) with no free space for an agent of body radius {} m", given(radius), given(xs), short(h / 2.0), given(body)),
                    "enlarge the disc, use `Window`, or move leader.start_x or the obstacles",
                ));
            }
            if free < need {
                return Err(ctx.err(
                    "swarm.placement",
                    format!("is a disc of radius {} m around ({}, {}) with only {free:.4} m² of free space, less than the {need:.4} m² that {} agents of body radius {} m need (their bodies may cover at most 45 % of it)", given(radius), given(xs), short(h / 2.0), world.swarm.agents, given(body)),
                    "enlarge the disc, use `Window`, or use fewer agents",
                ));
            }
        }
        Placement::Window => {}
    }
    let raster = FreeSpaceRaster::new(world, body);
    if let Placement::Window = world.swarm.placement {
        let free = raster.free_area_in_band(xs - half, xs + half);
        if free < need.max(f64::MIN_POSITIVE) {
            return Err(ctx.err(
                "swarm.placement",
                format!("is the initial window x {} to {} m, which has {free:.4} m² of free space, less than the {need:.4} m² that {} agents of body radius {} m need (their bodies may cover at most 45 % of it)", short(xs - half), short(xs + half), world.swarm.agents, given(body)),
                "clear space in the first window, move leader.start_x, widen leader.window, or use fewer agents",
            ));
        }
    }
    if let Some(x) = raster.first_blocked_window(world) {
        let blockers: Vec<String> = world
            .obstacles
            .iter()
            .enumerate()
            .filter(|(_, o)| {
                let (lo, hi) = o.bounding_box();
                hi.0 >= x - half && lo.0 <= x + half
            })
            .map(|(i, _)| format!("obstacles[{i}]"))
            .collect();
        return Err(ctx.err(
            "obstacles",
            format!(
                "leave no free space for an agent of body radius {} m in the leader's window around x = {x:.2} m (D(t) = x {:.2} to {:.2} m); it is blocked by {}",
                given(body),
                x - half,
                x + half,
                if blockers.is_empty() { "the arena's sides".to_string() } else { blockers.join(", ") }
            ),
            format!("open a gap wider than 2·swarm.body_radius = {} m somewhere in that window, or move the obstacles", short(2.0 * body)),
        ));
    }
    Ok(())
}

/// The first vertex `j` that repeats an earlier one, with the first such earlier `k`
/// (`points[j] == points[k]`, `k < j`): what a scan of every pair in order finds, in
/// O(n log n) by sorting (a polygon exported from a drawing can have tens of thousands
/// of vertices).
fn first_repeat(points: &[(f64, f64)]) -> Option<(usize, usize)> {
    // `+ 0.0` makes -0.0 equal to 0.0 under `total_cmp`, as it is under `==`.
    let key = |i: usize| (points[i].0 + 0.0, points[i].1 + 0.0);
    let mut order: Vec<usize> = (0..points.len()).collect();
    order.sort_by(|&p, &q| {
        let (a, b) = (key(p), key(q));
        a.0.total_cmp(&b.0)
            .then(a.1.total_cmp(&b.1))
            .then(p.cmp(&q))
    });
    // Within a run of equal points (sorted by index) the second is its first repeat.
    order
        .windows(2)
        .filter(|w| key(w[0]) == key(w[1]))
        .map(|w| (w[1], w[0]))
        .fold(None, |best: Option<(usize, usize)>, (j, k)| match best {
            Some((bj, _)) if bj <= j => best,
            _ => Some((j, k)),
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    proptest::proptest! {
        /// Sorting finds the repeat a scan of every pair in order finds (-0.0 = 0.0 too).
        #[test]
        fn first_repeat_equals_the_pairwise_scan(
            grid in proptest::collection::vec((-2i32..3, -2i32..3), 0..12),
        ) {
            let points: Vec<(f64, f64)> = grid
                .iter()
                .map(|&(x, y)| (if x == 0 { -0.0 } else { f64::from(x) }, f64::from(y) * 0.5))
                .collect();
            let brute = (0..points.len())
                .find_map(|j| (0..j).find(|&k| points[j] == points[k]).map(|k| (j, k)));
            proptest::prop_assert_eq!(first_repeat(&points), brute);
        }
    }

    #[test]
    fn short_rounds_to_six_significant_digits() {
        assert_eq!(short(0.01 / (2.0 * 0.1)), "0.05");
        assert_eq!(short(2.0 * 0.1 * 0.06), "0.012");
        assert_eq!(short(1425.0), "1425");
        assert_eq!(short(28.5), "28.5");
        assert_eq!(short(0.0), "0");
        assert_eq!(short(1.0 / 3.0), "0.333333");
        assert_eq!(short(1e300), "1e300");
        assert_eq!(short(-2.5e39), "-2.5e39");
        assert_eq!(short(1.234567e-9), "1.23457e-9");
    }

    #[test]
    fn given_keeps_every_digit_but_writes_far_numbers_with_an_exponent() {
        assert_eq!(given(0.0), "0");
        assert_eq!(given(0.1), "0.1");
        assert_eq!(given(1.0 / 3.0), "0.3333333333333333");
        assert_eq!(given(30.000000001), "30.000000001");
        assert_eq!(given(123456789.0), "123456789");
        assert_eq!(given(1e9), "1e9");
        assert_eq!(given(1234567890.5), "1.2345678905e9");
        assert_eq!(given(1e300), "1e300");
        assert_eq!(given(-2.5e39), "-2.5e39");
        assert_eq!(given(1.234567e-9), "1.234567e-9");
        assert_eq!(given(f64::INFINITY), "inf");
        for x in [1e300, -7.25e-200, 3.0e16, 1.0 / 3.0, 5e-7] {
            assert_eq!(given(x).parse::<f64>().unwrap(), x, "{x} reads back");
        }
    }

    #[test]
    fn bounds_are_rounded_towards_the_side_the_check_accepts() {
        let at_most = |x: f64| suggest(x, Inward::Down, |v| v <= x);
        let at_least = |x: f64| suggest(x, Inward::Up, |v| v >= x);
        assert_eq!(at_most(0.01 / (2.0 * 0.3)), "0.0166666");
        assert_eq!(at_least(0.01 / (2.0 * 0.3)), "0.0166667");
        assert_eq!(at_most(28.5), "28.5");
        assert_eq!(at_least(1.5), "1.5");
        assert_eq!(at_most(2.0 / 3.0), "0.666666");
        assert_eq!(at_least(2.0 / 3.0), "0.666667");
        assert_eq!(at_most(5e-202), "5e-202");
        assert_eq!(at_most(0.1 / (2.0 * 1e200)), "5e-202");
        assert_eq!(at_least(2.0 / 3.0 * 1e300), "6.66667e299");
        assert_eq!(at_most(2.0 / 3.0 * 1e300), "6.66666e299");
        // Nearest first where the check accepts it: 0.01 / 0.2 is 0.049999999999999996 in
        // f64, and the time-step check accepts 0.05 within its tolerance.
        let (r_d, v) = (0.01, 0.1);
        assert_eq!(
            suggest(r_d / (2.0 * v), Inward::Down, |x| 2.0 * v * x
                <= r_d * (1.0 + 1e-9)),
            "0.05"
        );
        // Next to a power of ten the rounded mantissa moves to the next exponent.
        assert_eq!(at_least(9.999991e-7), "1e-6");
        assert_eq!(at_most(9.999999999999997e-7), "9.99999e-7");
        assert_eq!(at_least(0.0009999995), "0.001");
        assert_eq!(at_most(0.0009999995), "0.000999999");
        // A subnormal bound is written exactly, or stepped inward until it is accepted.
        let tiny = 5.17e-321;
        assert!(at_most(tiny).parse::<f64>().unwrap() <= tiny);
        assert_eq!(
            suggest(tiny, Inward::Down, |v| v < tiny),
            given(tiny.next_down())
        );
        for x in [
            1.0 / 3.0,
            2.0 / 7.0,
            1234.56789,
            0.05,
            9.99999999,
            1e-6 * 1.2345678,
            1.0 / 3.0 * 1e-250,
            7.0 / 3.0 * 1e250,
            -2.0 / 3.0,
            f64::MIN_POSITIVE,
        ] {
            assert!(at_most(x).parse::<f64>().unwrap() <= x, "{x}");
            assert!(at_least(x).parse::<f64>().unwrap() >= x, "{x}");
        }
    }

    #[test]
    fn apart_rounds_unless_the_two_would_read_the_same() {
        assert_eq!(apart(41.23105625617661, 45.0), "41.2311");
        assert_eq!(apart(0.6000000000000001, 0.1), "0.6");
        assert_eq!(apart(0.0100000002, 0.01), "0.0100000002");
        assert_eq!(apart(10000.0000001, 10000.0), "10000.0000001");
    }

    #[test]
    fn collinearity() {
        assert!(collinear(&[(1.0, 1.0), (2.0, 2.0), (3.0, 3.0)]));
        assert!(collinear(&[(2.0, 2.0), (1.0, 1.0), (3.0, 3.0), (1.5, 1.5)]));
        assert!(!collinear(&[(1.0, 1.0), (2.0, 2.0), (3.0, 3.1)]));
    }

    #[test]
    fn landmark_count_rounds() {
        assert_eq!(landmark_count(0.1, 100), 10);
        assert_eq!(landmark_count(0.1, 4), 0);
        assert_eq!(landmark_count(0.5, 1), 1);
        assert_eq!(landmark_count(0.0, 7), 0);
    }
}
