//! Worlds: the arena, its obstacles and every parameter of a run (paper §"Problem
//! Statement", §"Simulation Results").
//!
//! A world file is RON (format in the README, "World files"). Reading is two-step, as in
//! linfa's checked parameters: [`parse_str`] turns the text into a raw [`WorldSpec`]
//! (every field optional, unknown fields rejected with the list of valid ones, syntax
//! errors at `file:line:col`); [`apply_override`] may then set fields by dotted path; and
//! [`WorldSpec::check`] fills in the paper's defaults and validates every rule into a
//! [`World`], the only type the simulator accepts. Semantic errors name the field path
//! and, when the field is in the text, its `file:line:col`.

mod check;
mod distance_index;
mod error;
mod freespace;
mod geometry;
mod locate;
mod spec;
mod summary;
mod types;

pub use check::{
    Inward, MAX_AGENTS, MAX_STEPS, MAX_WINDOWS, given, landmark_count, short, suggest,
};
pub use distance_index::{MIN_INDEXED_VERTICES, ObstacleDistances};
pub use error::WorldError;
pub use freespace::FreeSpaceRaster;
pub use geometry::{
    CellBlock, clear_obstacle_cells, point_in_polygon, polygon_area, polygon_self_intersection,
    segment_distance, segments_intersect,
};
pub use locate::locate;
pub use spec::{
    ArenaSpec, LeaderSpec, MappingSpec, MethodSpec, ObstacleSpec, PlacementSpec, SETTING_PATHS,
    SimulationSpec, SpecOrigin, SwarmSpec, WorldSpec, apply_assignment, apply_override, parse_str,
};
pub use types::*;
