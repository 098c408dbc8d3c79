//! Evaluation against ground truth (issue #4 §4, issue #5 §2).
//!
//! - [`truth`]: the true Betti numbers of the reachable free space in a window's domain, the
//!   true number of connections between consecutive windows, and the true global Betti
//!   numbers, from a cached raster of the world ([`FreeSpace`]).
//! - [`fidelity`]: rank correlation of the encounter metric with true distances
//!   ([`spearman`]) and the Procrustes error of the embedding ([`procrustes_error`]).

//! - [`campaign`]: `swarmmap eval`, many worlds × parameters × seeds in parallel.

pub mod calibrate;
pub mod campaign;
pub mod fidelity;
pub mod truth;

pub use fidelity::{Procrustes, Similarity, procrustes, procrustes_error, spearman};
pub use truth::{BandComponents, DEFAULT_RESOLUTION, FreeSpace, TruthError, overlap, window_band};
