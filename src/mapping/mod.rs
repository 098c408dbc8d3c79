//! Local and global mapping from encounter logs (paper §"Dynamic Topological Mapping").

pub mod classify;
pub mod encounter_graph;
pub mod subsample;
pub mod synthetic;
pub mod windows;
