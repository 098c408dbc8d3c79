//! Worlds: the arena, its obstacles and every parameter of a run (paper §"Problem
//! Statement", §"Simulation Results").
//!
//! A world file is RON. Reading is two-step: the text is parsed into a raw spec, which
//! `check()` turns into a validated [`World`]; the simulator accepts only a [`World`].

mod types;

pub use types::*;
