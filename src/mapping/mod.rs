//! Local and global mapping from encounter logs (paper §"Dynamic Topological Mapping").

pub mod bridge;
pub mod classify;
pub mod crossing;
pub mod dense;
pub mod encounter_graph;
pub mod local;
pub mod output;
pub mod pipeline;
pub mod stability;
pub mod stitch;
pub mod subsample;
pub mod synthetic;
pub mod timelines;
pub mod windows;
pub mod witness;
