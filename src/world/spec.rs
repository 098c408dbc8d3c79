//! The raw world spec: what a RON world file says, before any check. Every section and
//! every field is optional; `check()` (in `check.rs`) fills in the defaults and validates.
//!
//! Parsing uses `ron` with the `implicit_some` extension, so `agents: 100` is accepted for
//! an optional field, and `deny_unknown_fields` everywhere, so a misspelt field is an error
//! that lists the valid ones. Overrides (`--set swarm.detection_radius=0.03`) act on this
//! raw spec, so an overridden world is validated exactly like a written one.

use super::error::WorldError;
use super::types::Vec2;
use serde::Deserialize;
use serde::de::DeserializeOwned;

/// `arena: (width: 30.0, height: 10.0)`.
#[derive(Debug, Clone, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ArenaSpec {
    /// Metres along the sweep (default `30.0`).
    #[serde(default)]
    pub width: Option<f64>,
    /// Metres (default `10.0`).
    #[serde(default)]
    pub height: Option<f64>,
}

/// One obstacle as written.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum ObstacleSpec {
    /// `Rect(min: (x, y), max: (x, y))`, metres.
    Rect { min: Vec2, max: Vec2 },
    /// `Circle(center: (x, y), radius: r)`, metres.
    Circle { center: Vec2, radius: f64 },
    /// `Polygon(points: [(x, y), ...])`, metres, a simple polygon in either orientation.
    Polygon { points: Vec<Vec2> },
    /// `Wall(from: (x, y), to: (x, y), thickness: t)`, metres.
    Wall {
        from: Vec2,
        to: Vec2,
        thickness: f64,
    },
}

impl ObstacleSpec {
    /// Scales the obstacle by `f` about its own centre, keeping its shape and place: a
    /// circle's radius, a rectangle about its centre, a polygon about its area centroid (the
    /// mean of its vertices when its area is zero), a wall's length about its midpoint and
    /// its thickness. Used by `--set obstacles.scale=F`, to ask how small an obstacle a
    /// world's maps still resolve (docs/accuracy.md, step 41). Values are not checked here:
    /// the scaled world is validated like a written one.
    pub fn scale_about_centre(&mut self, f: f64) {
        let about = |p: &mut Vec2, c: Vec2| {
            *p = (c.0 + (p.0 - c.0) * f, c.1 + (p.1 - c.1) * f);
        };
        match self {
            Self::Circle { radius, .. } => *radius *= f,
            Self::Rect { min, max } => {
                let c = (0.5 * (min.0 + max.0), 0.5 * (min.1 + max.1));
                about(min, c);
                about(max, c);
            }
            Self::Polygon { points } => {
                let c = super::geometry::polygon_centroid(points);
                for p in points.iter_mut() {
                    about(p, c);
                }
            }
            Self::Wall {
                from,
                to,
                thickness,
            } => {
                let c = (0.5 * (from.0 + to.0), 0.5 * (from.1 + to.1));
                about(from, c);
                about(to, c);
                *thickness *= f;
            }
        }
    }
}

/// `placement: Disk(radius: 1.0)` or `placement: Window`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum PlacementSpec {
    /// Disc centred on the leader's start at mid-height; radius in metres (default `1.0`).
    Disk {
        #[serde(default)]
        radius: Option<f64>,
    },
    /// The whole initial window D(0).
    Window,
}

/// `swarm: (...)`; see the README, "World files", for units and defaults.
#[derive(Debug, Clone, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SwarmSpec {
    pub agents: Option<i64>,
    pub speed: Option<f64>,
    pub detection_radius: Option<f64>,
    pub landmark_fraction: Option<f64>,
    pub body_radius: Option<f64>,
    pub mean_run_length: Option<f64>,
    pub stop_rate: Option<f64>,
    pub mean_stop_duration: Option<f64>,
    pub comm_radius: Option<f64>,
    pub wall_following: Option<f64>,
    pub wall_following_length: Option<f64>,
    pub return_patience: Option<f64>,
    pub keep_surplus_landmarks: Option<bool>,
    pub placement: Option<PlacementSpec>,
}

/// `leader: (...)`.
#[derive(Debug, Clone, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct LeaderSpec {
    pub speed: Option<f64>,
    pub window: Option<f64>,
    pub start_x: Option<f64>,
    pub end_x: Option<f64>,
}

/// `simulation: (...)`.
#[derive(Debug, Clone, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SimulationSpec {
    pub dt: Option<f64>,
    pub dispersion_time: Option<f64>,
}

/// `method: Paper` or `method: Embedded`. Mirrors [`super::MappingMethod`]; a new method
/// needs a variant here.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
pub enum MethodSpec {
    Paper,
    Embedded,
}

/// `mapping: (...)`.
#[derive(Debug, Clone, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct MappingSpec {
    pub windows: Option<i64>,
    pub overlap: Option<f64>,
    pub cluster_cutoff: Option<f64>,
    pub subsample: Option<i64>,
    pub neighbours: Option<i64>,
    pub method: Option<MethodSpec>,
    pub switch_cost: Option<f64>,
    pub after_landmarks: Option<bool>,
    pub encounter_midpoints: Option<bool>,
    pub rips_points: Option<i64>,
    pub agent_timelines: Option<bool>,
    pub outlier_rank: Option<i64>,
    pub split_stability: Option<bool>,
}

/// Where a spec came from: used to say `file:line:col` in errors.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SpecOrigin {
    /// File name (or other label) shown in messages.
    pub name: String,
    /// The RON text, used to locate fields; `None` for specs built in code.
    pub text: Option<String>,
    /// `(path, value)` of every override applied, in order.
    pub overrides: Vec<(String, String)>,
    /// A world a run recorded (`meta.json`): its agents were placed, so the check does not
    /// ask again whether the placement area holds them (a bound tightened since would
    /// otherwise refuse to map or report a run made before).
    pub recorded: bool,
}

/// A world as written: every section and field optional. Turn it into a validated
/// [`super::World`] with [`WorldSpec::check`].
#[derive(Debug, Clone, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct WorldSpec {
    pub name: Option<String>,
    pub arena: Option<ArenaSpec>,
    pub obstacles: Option<Vec<ObstacleSpec>>,
    pub swarm: Option<SwarmSpec>,
    pub leader: Option<LeaderSpec>,
    pub simulation: Option<SimulationSpec>,
    pub mapping: Option<MappingSpec>,
    pub seed: Option<u64>,
    #[serde(skip)]
    pub origin: SpecOrigin,
}

fn ron_options() -> ron::Options {
    ron::Options::default().with_default_extension(ron::extensions::Extensions::IMPLICIT_SOME)
}

/// Levenshtein distance, for "did you mean" suggestions.
fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut prev = row[0];
        row[0] = i + 1;
        for (j, cb) in b.iter().enumerate() {
            let cur = row[j + 1];
            row[j + 1] = (prev + usize::from(ca != *cb)).min(row[j] + 1).min(cur + 1);
            prev = cur;
        }
    }
    row[b.len()]
}

/// " (did you mean `x`?)" when one candidate is close to `found`.
fn suggestion(found: &str, candidates: &[&str]) -> String {
    candidates
        .iter()
        .map(|c| (edit_distance(found, c), *c))
        .filter(|(d, c)| *d <= 2.max(c.len() / 3))
        .min()
        .map(|(_, c)| format!(" (did you mean `{c}`?)"))
        .unwrap_or_default()
}

fn list(items: &[&str]) -> String {
    items
        .iter()
        .map(|s| format!("`{s}`"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// A user-facing message (what and how to fix) for a ron error.
fn explain(code: &ron::Error) -> String {
    use ron::Error as E;
    match code {
        E::NoSuchStructField {
            expected, found, ..
        } => format!(
            "unknown field `{found}`{}; the valid fields here are {}",
            suggestion(found, expected),
            list(expected)
        ),
        E::NoSuchEnumVariant {
            expected, found, ..
        } => format!(
            "unknown variant `{found}`{}; the valid variants here are {}",
            suggestion(found, expected),
            list(expected)
        ),
        E::MissingStructField { field, outer } => match outer {
            Some(o) => format!("{o} needs the field `{field}`; add `{field}: ...`"),
            None => format!("missing field `{field}`; add `{field}: ...`"),
        },
        E::DuplicateStructField { field, .. } => {
            format!("the field `{field}` is given twice; keep only one")
        }
        E::Eof => "unexpected end of the file; a closing bracket is probably missing".into(),
        E::ExpectedInteger => "a whole number is expected here (counts and the seed are \
             written as digits, e.g. `agents: 100`, not in quotes or words)"
            .into(),
        E::ExpectedFloat => "a number is expected here (e.g. `0.1`, `1e-3`; not in quotes)".into(),
        E::ExpectedComma => "expected a comma here, between the previous entry and this one".into(),
        E::IntegerOutOfBounds => "this whole number is out of range for its field (a count or \
             a seed cannot be negative, and a seed is below 2^64; the README's World files \
             section gives each field's range)"
            .into(),
        other => format!("{other} (see the README's World files section for the format)"),
    }
}

/// What ron's "expected a comma" means at `line:col` of `text` (1-based), where the text
/// there tells more: the file ended (a closing bracket is missing), or a variant that takes
/// no arguments was given some (`Window()`, `Paper(1)`). (Found by the forty-first
/// session's review: both read "expected a comma here", the first past the file's end.)
fn comma_expected(text: &str, line: usize, col: usize) -> String {
    let row = text.lines().nth(line.saturating_sub(1)).unwrap_or("");
    let before: String = row.chars().take(col.saturating_sub(1)).collect();
    let rest = text
        .lines()
        .skip(line.saturating_sub(1))
        .enumerate()
        .map(|(k, l)| {
            if k == 0 {
                l.chars().skip(col.saturating_sub(1)).collect()
            } else {
                l.to_string()
            }
        })
        .collect::<Vec<String>>()
        .join("\n");
    // A closer of the wrong kind: `(… 4.0]`.
    let prefix: String = text
        .lines()
        .take(line.saturating_sub(1))
        .map(|l| format!("{l}\n"))
        .chain(std::iter::once(before.clone()))
        .collect();
    let wanted = match open_brackets(&prefix).last() {
        Some('(') => Some(')'),
        Some('[') => Some(']'),
        _ => None,
    };
    if let (Some(wanted), Some(found @ (')' | ']'))) = (wanted, rest.chars().next())
        && wanted != found
    {
        return format!(
            "this `{found}` closes a bracket opened with the other kind; close it with `{wanted}`"
        );
    }
    // Nothing but closing brackets to the end, fewer than the file opens: it ends before
    // its brackets close.
    if rest
        .chars()
        .all(|c| c.is_whitespace() || c == ')' || c == ']')
        && !open_brackets(text).is_empty()
    {
        return "unexpected end of the file; a closing bracket `)` or `]` is probably missing"
            .into();
    }
    let variant: String = before
        .trim_end()
        .chars()
        .rev()
        .take_while(|c| c.is_alphanumeric() || *c == '_')
        .collect::<Vec<char>>()
        .into_iter()
        .rev()
        .collect();
    if rest.starts_with('(') && variant.starts_with(|c: char| c.is_ascii_uppercase()) {
        return format!(
            "`{variant}` takes nothing in brackets here; write `{variant}` alone (the README's \
             World files section gives each variant's form)"
        );
    }
    "expected a comma here, between the previous entry and this one".into()
}

/// The brackets `text` leaves open, innermost last, outside strings and comments.
fn open_brackets(text: &str) -> Vec<char> {
    let mut open = Vec::new();
    let mut chars = text.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '"' => {
                while let Some(d) = chars.next() {
                    match d {
                        '\\' => {
                            chars.next();
                        }
                        '"' => break,
                        _ => {}
                    }
                }
            }
            '/' if chars.peek() == Some(&'/') => {
                for d in chars.by_ref() {
                    if d == '\n' {
                        break;
                    }
                }
            }
            '/' if chars.peek() == Some(&'*') => {
                chars.next();
                let mut last = ' ';
                for d in chars.by_ref() {
                    if last == '*' && d == '/' {
                        break;
                    }
                    last = d;
                }
            }
            '(' | '[' | '{' => open.push(c),
            ')' | ']' | '}' => {
                open.pop();
            }
            _ => {}
        }
    }
    open
}

/// What ron's suggestion of a raw identifier means: `found` stood where a field name was
/// expected.
fn not_a_field_name(found: &str) -> String {
    let word = found.chars().next().is_some_and(char::is_alphabetic);
    if word && found.contains('.') {
        format!(
            "`{found}` is not a field name: a dotted path is for --set; in a file write the \
             section, e.g. `swarm: (agents: 10)`"
        )
    } else if word && found.contains('-') {
        format!(
            "`{found}` is not a field name: field names join words with `_`, e.g. \
             `detection_radius`"
        )
    } else {
        "a `field: value` pair is expected here, not a bare value (e.g. `Disk(radius: 1.0)`; \
         the README's World files section gives each variant's fields)"
            .into()
    }
}

/// Parses RON `text` into a raw spec; `origin_name` (usually the file name) prefixes
/// error positions: `worlds/x.ron:12:5: unknown field ...`.
pub fn parse_str(text: &str, origin_name: &str) -> Result<WorldSpec, WorldError> {
    // A byte-order mark (some Windows editors write one) is not part of the RON text.
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut spec: WorldSpec = ron_options().from_str(text).map_err(|e| {
        let (line, col) = (e.span.start.line, e.span.start.col);
        // `agents: 10.5`: ron reads the integer 10, then stops at the `.`.
        let at = text.lines().nth(line.saturating_sub(1)).map(|l| {
            let mut chars = l.chars().skip(col.saturating_sub(2));
            (chars.next(), chars.next())
        });
        let fraction = matches!(at, Some((Some(d), Some('.'))) if d.is_ascii_digit());
        WorldError::Syntax {
            origin: origin_name.to_string(),
            line,
            col,
            message: if matches!(e.code, ron::Error::ExpectedComma) && fraction {
                "a whole number is expected here, not a fraction (counts and the seed are \
                     integers, e.g. `agents: 100`)"
                    .into()
            } else if matches!(e.code, ron::Error::ExpectedComma) {
                comma_expected(text, line, col)
            } else if let ron::Error::SuggestRawIdentifier(found) = &e.code {
                not_a_field_name(found)
            } else {
                explain(&e.code)
            },
        }
    })?;
    spec.origin = SpecOrigin {
        name: origin_name.to_string(),
        text: Some(text.to_string()),
        overrides: Vec::new(),
        recorded: false,
    };
    Ok(spec)
}

/// Every path accepted by [`apply_override`], besides `obstacles[i]`.
pub const SETTING_PATHS: &[&str] = &[
    "name",
    "seed",
    "arena",
    "arena.width",
    "arena.height",
    "obstacles",
    "obstacles.scale",
    "swarm",
    "swarm.agents",
    "swarm.speed",
    "swarm.detection_radius",
    "swarm.landmark_fraction",
    "swarm.body_radius",
    "swarm.mean_run_length",
    "swarm.stop_rate",
    "swarm.mean_stop_duration",
    "swarm.comm_radius",
    "swarm.wall_following",
    "swarm.wall_following_length",
    "swarm.return_patience",
    "swarm.keep_surplus_landmarks",
    "swarm.placement",
    "leader",
    "leader.speed",
    "leader.window",
    "leader.start_x",
    "leader.end_x",
    "simulation",
    "simulation.dt",
    "simulation.dispersion_time",
    "mapping",
    "mapping.windows",
    "mapping.overlap",
    "mapping.cluster_cutoff",
    "mapping.subsample",
    "mapping.neighbours",
    "mapping.method",
    "mapping.switch_cost",
    "mapping.after_landmarks",
    "mapping.encounter_midpoints",
    "mapping.rips_points",
    "mapping.agent_timelines",
    "mapping.split_stability",
    "mapping.outlier_rank",
];

/// Parses `value` as RON of the slot's type and stores it. As in a world file, the value
/// may be written bare or as `Some(…)`; `None` clears the slot, so the setting takes its
/// default (or, for a section, every setting of the section does).
fn put<T: DeserializeOwned>(
    slot: &mut Option<T>,
    path: &str,
    value: &str,
) -> Result<(), WorldError> {
    *slot = ron_options()
        .from_str(value)
        .map_err(|e| bad_value(path, value, &e.code))?;
    Ok(())
}

fn bad_value(path: &str, value: &str, code: &ron::Error) -> WorldError {
    WorldError::BadSetting {
        path: path.to_string(),
        value: value.to_string(),
        message: format!(
            "the value does not parse: {}; write it as in a world file, e.g. `0.5`, `100`, `Window`, `(width: 20.0)`",
            explain(code)
        ),
    }
}

impl WorldSpec {
    /// Sets one field by dotted path, e.g. `("swarm.detection_radius", "0.03")`,
    /// `("mapping.windows", "6")`, `("seed", "4")`, `("obstacles[1]", "Circle(center: (5.0, 5.0), radius: 1.0)")`.
    /// `value` is RON of the field's type (a bare word is accepted for `name`). A section
    /// path (`swarm`) replaces the whole section. Unknown paths are an error listing the
    /// valid ones.
    pub fn set(&mut self, path: &str, value: &str) -> Result<(), WorldError> {
        let p = path.trim();
        let v = value.trim();
        match p {
            "name" => {
                // As the other settings (`None` clears it: the file's stem; `Some("x")`), and
                // a bare word is a name too; a quoted one must be a whole RON string.
                let quoted = v.starts_with('"')
                    || (v.starts_with('r') && v[1..].trim_start_matches('#').starts_with('"'));
                match ron_options().from_str::<Option<String>>(v) {
                    Ok(name) => self.name = name,
                    Err(e) if quoted => {
                        return Err(WorldError::BadSetting {
                            path: path.to_string(),
                            value: value.to_string(),
                            message: format!(
                                "a quoted name must be one whole string ({}): close the quote, \
                                 e.g. `name=\"my world\"`, or give a bare word, e.g. `name=lab-7`",
                                explain(&e.code)
                            ),
                        });
                    }
                    Err(_) => self.name = Some(v.to_string()),
                }
            }
            "seed" => put(&mut self.seed, p, v)?,
            "arena" => put(&mut self.arena, p, v)?,
            "arena.width" => put(&mut self.arena.get_or_insert_default().width, p, v)?,
            "arena.height" => put(&mut self.arena.get_or_insert_default().height, p, v)?,
            "obstacles" => put(&mut self.obstacles, p, v)?,
            "obstacles.scale" => {
                let mut factor: Option<f64> = None;
                put(&mut factor, p, v)?;
                match factor.filter(|f| f.is_finite() && *f > 0.0) {
                    Some(f) => {
                        for o in self.obstacles.iter_mut().flatten() {
                            o.scale_about_centre(f);
                        }
                    }
                    None => {
                        return Err(WorldError::BadSetting {
                            path: path.to_string(),
                            value: value.to_string(),
                            message: "the factor must be a finite number > 0, e.g. `1.25` (a quarter larger) or `0.5` (half the size)".into(),
                        });
                    }
                }
            }
            "swarm" => put(&mut self.swarm, p, v)?,
            "leader" => put(&mut self.leader, p, v)?,
            "simulation" => put(&mut self.simulation, p, v)?,
            "mapping" => put(&mut self.mapping, p, v)?,
            _ if p.starts_with("obstacles[") => {
                let index = p
                    .strip_prefix("obstacles[")
                    .and_then(|r| r.strip_suffix(']'))
                    .and_then(|i| i.parse::<usize>().ok());
                let count = self.obstacles.as_ref().map_or(0, Vec::len);
                if p.contains("].") {
                    return Err(WorldError::BadSetting {
                        path: path.to_string(),
                        value: value.to_string(),
                        message: "an obstacle is set whole, not field by field: e.g. \
                                  `obstacles[0]=Circle(center: (3.0, 2.0), radius: 0.5)`, or \
                                  `obstacles.scale=1.25` to grow every obstacle"
                            .into(),
                    });
                }
                let Some(i) = index.filter(|i| *i < count) else {
                    let message = if count == 0 {
                        "the world has no obstacles, so there is no `obstacles[i]` to change; \
                         set the whole list instead, e.g. `obstacles=[Circle(center: (3.0, 2.0), radius: 0.5)]`"
                            .to_string()
                    } else {
                        format!(
                            "the world has {count} obstacle(s), so use `obstacles[i]` with i from 0 to {}, or set the whole `obstacles` list",
                            count - 1
                        )
                    };
                    return Err(WorldError::BadSetting {
                        path: path.to_string(),
                        value: value.to_string(),
                        message,
                    });
                };
                let mut one = None;
                put(&mut one, p, v)?;
                let Some(o) = one else {
                    return Err(WorldError::BadSetting {
                        path: path.to_string(),
                        value: value.to_string(),
                        message:
                            "an obstacle cannot be `None`; to remove obstacles, set the whole \
                                  `obstacles` list, e.g. `obstacles=[]`"
                                .into(),
                    });
                };
                if let Some(list) = self.obstacles.as_mut() {
                    list[i] = o;
                }
            }
            _ => {
                let (section, field) = p.split_once('.').unwrap_or((p, ""));
                match section {
                    "swarm" => {
                        let s = self.swarm.get_or_insert_default();
                        match field {
                            "agents" => put(&mut s.agents, p, v)?,
                            "speed" => put(&mut s.speed, p, v)?,
                            "detection_radius" => put(&mut s.detection_radius, p, v)?,
                            "landmark_fraction" => put(&mut s.landmark_fraction, p, v)?,
                            "body_radius" => put(&mut s.body_radius, p, v)?,
                            "mean_run_length" => put(&mut s.mean_run_length, p, v)?,
                            "stop_rate" => put(&mut s.stop_rate, p, v)?,
                            "mean_stop_duration" => put(&mut s.mean_stop_duration, p, v)?,
                            "comm_radius" => put(&mut s.comm_radius, p, v)?,
                            "wall_following" => put(&mut s.wall_following, p, v)?,
                            "wall_following_length" => put(&mut s.wall_following_length, p, v)?,
                            "return_patience" => put(&mut s.return_patience, p, v)?,
                            "keep_surplus_landmarks" => put(&mut s.keep_surplus_landmarks, p, v)?,
                            "placement" => put(&mut s.placement, p, v)?,
                            _ => return Err(unknown_setting(path)),
                        }
                    }
                    "leader" => {
                        let s = self.leader.get_or_insert_default();
                        match field {
                            "speed" => put(&mut s.speed, p, v)?,
                            "window" => put(&mut s.window, p, v)?,
                            "start_x" => put(&mut s.start_x, p, v)?,
                            "end_x" => put(&mut s.end_x, p, v)?,
                            _ => return Err(unknown_setting(path)),
                        }
                    }
                    "simulation" => {
                        let s = self.simulation.get_or_insert_default();
                        match field {
                            "dt" => put(&mut s.dt, p, v)?,
                            "dispersion_time" => put(&mut s.dispersion_time, p, v)?,
                            _ => return Err(unknown_setting(path)),
                        }
                    }
                    "mapping" => {
                        let s = self.mapping.get_or_insert_default();
                        match field {
                            "windows" => put(&mut s.windows, p, v)?,
                            "overlap" => put(&mut s.overlap, p, v)?,
                            "cluster_cutoff" => put(&mut s.cluster_cutoff, p, v)?,
                            "subsample" => put(&mut s.subsample, p, v)?,
                            "neighbours" => put(&mut s.neighbours, p, v)?,
                            "method" => put(&mut s.method, p, v)?,
                            "switch_cost" => put(&mut s.switch_cost, p, v)?,
                            "after_landmarks" => put(&mut s.after_landmarks, p, v)?,
                            "encounter_midpoints" => put(&mut s.encounter_midpoints, p, v)?,
                            "rips_points" => put(&mut s.rips_points, p, v)?,
                            "agent_timelines" => put(&mut s.agent_timelines, p, v)?,
                            "split_stability" => put(&mut s.split_stability, p, v)?,
                            "outlier_rank" => put(&mut s.outlier_rank, p, v)?,
                            _ => return Err(unknown_setting(path)),
                        }
                    }
                    _ => return Err(unknown_setting(path)),
                }
            }
        }
        self.origin.overrides.push((p.to_string(), v.to_string()));
        Ok(())
    }
}

fn unknown_setting(path: &str) -> WorldError {
    let mut valid: Vec<&str> = SETTING_PATHS.to_vec();
    valid.push("obstacles[i]");
    let hint = suggestion(path.trim(), SETTING_PATHS);
    WorldError::UnknownSetting {
        path: format!("{}{hint}", path.trim()),
        valid: valid.join(", "),
    }
}

/// Sets one field of `spec` by dotted path (see [`WorldSpec::set`]); used by `--set`.
pub fn apply_override(spec: &mut WorldSpec, path: &str, value: &str) -> Result<(), WorldError> {
    spec.set(path, value)
}

/// Applies `PATH=VALUE` (as typed after `--set`) to `spec`.
pub fn apply_assignment(spec: &mut WorldSpec, assignment: &str) -> Result<(), WorldError> {
    match assignment.split_once('=') {
        Some((path, value)) => spec.set(path, value),
        None => Err(WorldError::NoValue {
            given: assignment.to_string(),
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn edit_distance_is_levenshtein() {
        assert_eq!(edit_distance("kitten", "sitting"), 3);
        assert_eq!(edit_distance("", "abc"), 3);
        assert_eq!(edit_distance("abc", "abc"), 0);
        assert_eq!(
            suggestion("detection_radiu", &["detection_radius", "speed"]),
            " (did you mean `detection_radius`?)"
        );
        assert_eq!(suggestion("zzz", &["detection_radius", "speed"]), "");
    }

    #[test]
    fn every_listed_path_is_settable() {
        for path in SETTING_PATHS {
            let mut spec = WorldSpec::default();
            // A value of the wrong shape must fail as a bad value, never as an unknown path.
            match spec.set(path, "\"definitely not valid\" )") {
                Err(WorldError::BadSetting { .. }) => {}
                other => panic!("{path}: {other:?}"),
            }
        }
    }

    fn near(a: Vec2, b: Vec2) -> bool {
        (a.0 - b.0).abs() < 1e-12 && (a.1 - b.1).abs() < 1e-12
    }

    #[test]
    fn obstacles_scale_about_their_own_centres() {
        let mut spec = parse_str(
            "(obstacles: [Circle(center: (2.5, 7.0), radius: 0.4), \
             Rect(min: (5.9, 2.6), max: (6.7, 3.4)), \
             Polygon(points: [(0.0, 0.0), (3.0, 0.0), (0.0, 3.0)]), \
             Wall(from: (1.0, 1.0), to: (5.0, 1.0), thickness: 0.2)])",
            "t.ron",
        )
        .unwrap();
        spec.set("obstacles.scale", "1.5").unwrap();
        let o = spec.obstacles.as_ref().unwrap();
        match &o[0] {
            ObstacleSpec::Circle { center, radius } => {
                assert_eq!(*center, (2.5, 7.0));
                assert!((radius - 0.6).abs() < 1e-12);
            }
            other => panic!("{other:?}"),
        }
        match &o[1] {
            ObstacleSpec::Rect { min, max } => {
                assert!(
                    near(*min, (5.7, 2.4)) && near(*max, (6.9, 3.6)),
                    "{min:?} {max:?}"
                );
            }
            other => panic!("{other:?}"),
        }
        // The triangle's centroid (1, 1) stays; each vertex moves 1.5 times as far from it.
        match &o[2] {
            ObstacleSpec::Polygon { points } => {
                let want = [(-0.5, -0.5), (4.0, -0.5), (-0.5, 4.0)];
                assert_eq!(points.len(), want.len());
                for (p, w) in points.iter().zip(want) {
                    assert!(near(*p, w), "{points:?}");
                }
            }
            other => panic!("{other:?}"),
        }
        match &o[3] {
            ObstacleSpec::Wall {
                from,
                to,
                thickness,
            } => {
                assert!(near(*from, (0.0, 1.0)) && near(*to, (6.0, 1.0)));
                assert!((thickness - 0.3).abs() < 1e-12);
            }
            other => panic!("{other:?}"),
        }
        assert_eq!(
            spec.origin.overrides,
            vec![("obstacles.scale".to_string(), "1.5".to_string())]
        );
    }

    #[test]
    fn a_polygon_keeps_its_area_centroid_and_scales_its_area() {
        use super::super::geometry::{polygon_area, polygon_centroid};
        // An L of two rectangles, [0,3]×[0,1] and [0,1]×[1,3]: area 5, centroid
        // ((3·1.5 + 2·0.5) / 5, (3·0.5 + 2·2) / 5) = (1.1, 1.1) by decomposition; the same
        // in either orientation.
        let l = vec![
            (0.0, 0.0),
            (3.0, 0.0),
            (3.0, 1.0),
            (1.0, 1.0),
            (1.0, 3.0),
            (0.0, 3.0),
        ];
        let mut clockwise = l.clone();
        clockwise.reverse();
        for poly in [l, clockwise] {
            assert!(near(polygon_centroid(&poly), (1.1, 1.1)), "{poly:?}");
            let mut o = ObstacleSpec::Polygon {
                points: poly.clone(),
            };
            o.scale_about_centre(0.5);
            let ObstacleSpec::Polygon { points } = o else {
                unreachable!()
            };
            assert!((polygon_area(&points).abs() - 5.0 * 0.25).abs() < 1e-12);
            assert!(near(polygon_centroid(&points), (1.1, 1.1)));
        }
    }

    #[test]
    fn set_takes_some_and_none_as_a_world_file_does() {
        let mut spec = parse_str("(swarm: (agents: 50), mapping: (windows: 3))", "t.ron").unwrap();
        spec.set("swarm.agents", "Some(10)").unwrap();
        assert_eq!(spec.swarm.as_ref().unwrap().agents, Some(10));
        spec.set("arena", "Some((width: 20.0))").unwrap();
        assert_eq!(spec.arena.as_ref().unwrap().width, Some(20.0));
        // `None` clears a setting, which then takes its default.
        spec.set("swarm.agents", "None").unwrap();
        assert_eq!(spec.swarm.as_ref().unwrap().agents, None);
        spec.set("mapping", "None").unwrap();
        assert_eq!(spec.mapping, None);
        match spec.set("swarm.agents", "Some(ten)") {
            Err(WorldError::BadSetting { message, .. }) => {
                assert!(message.contains("does not parse"), "{message}")
            }
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn a_name_is_a_bare_word_or_a_whole_string() {
        let mut spec = WorldSpec::default();
        spec.set("name", "lab-7").unwrap();
        assert_eq!(spec.name.as_deref(), Some("lab-7"));
        spec.set("name", "\"two words\"").unwrap();
        assert_eq!(spec.name.as_deref(), Some("two words"));
        spec.set("name", "Some(\"lab 8\")").unwrap();
        assert_eq!(spec.name.as_deref(), Some("lab 8"));
        spec.set("name", "r#1").unwrap();
        assert_eq!(spec.name.as_deref(), Some("r#1"));
        spec.set("name", "\"None\"").unwrap();
        assert_eq!(spec.name.as_deref(), Some("None"));
        for bad in ["\"abc", "\"a\" b", "r\"x", "r#\"x"] {
            match spec.set("name", bad) {
                Err(WorldError::BadSetting { message, .. }) => {
                    assert!(message.contains("close the quote"), "{bad}: {message}")
                }
                other => panic!("{bad}: {other:?}"),
            }
            assert_eq!(spec.name.as_deref(), Some("None"), "{bad}");
        }
        // `None` clears it, as any setting: the world is then named after its file.
        spec.set("name", "None").unwrap();
        assert_eq!(spec.name, None);
    }

    #[test]
    fn an_obstacle_cannot_be_set_to_none() {
        let mut spec = parse_str(
            "(obstacles: [Circle(center: (2.0, 2.0), radius: 0.5)])",
            "t.ron",
        )
        .unwrap();
        let before = spec.obstacles.clone();
        match spec.set("obstacles[0]", "None") {
            Err(WorldError::BadSetting { message, .. }) => {
                assert!(message.contains("obstacles=[]"), "{message}")
            }
            other => panic!("{other:?}"),
        }
        assert_eq!(spec.obstacles, before);
    }

    #[test]
    fn a_bad_scale_is_refused_and_changes_nothing() {
        let text = "(obstacles: [Circle(center: (2.0, 2.0), radius: 0.5)])";
        for (bad, why) in [
            ("0", "must be a finite number > 0"),
            ("-1.5", "must be a finite number > 0"),
            ("inf", "must be a finite number > 0"),
            ("NaN", "must be a finite number > 0"),
            ("big", "does not parse"),
            ("\"1.5\"", "does not parse"),
        ] {
            let mut spec = parse_str(text, "t.ron").unwrap();
            let before = spec.obstacles.clone();
            match spec.set("obstacles.scale", bad) {
                Err(WorldError::BadSetting { message, .. }) => {
                    assert!(message.contains(why), "{bad}: {message}");
                }
                other => panic!("{bad}: {other:?}"),
            }
            assert_eq!(spec.obstacles, before, "{bad}");
            assert!(spec.origin.overrides.is_empty(), "{bad}");
        }
        // A world without obstacles scales to itself.
        let mut empty = WorldSpec::default();
        empty.set("obstacles.scale", "2").unwrap();
        assert_eq!(empty.obstacles, None);
    }
}
