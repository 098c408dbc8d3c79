//! Worlds: the arena, its obstacles and every parameter of a run (paper §"Problem
//! Statement", §"Simulation Results").
//!
//! A world file is RON. Reading is two-step: the text is parsed into a raw spec, which
//! `check()` turns into a validated [`World`]; the simulator accepts only a [`World`].

mod geometry;
mod types;

pub use geometry::{point_in_polygon, segment_distance};
pub use types::*;
