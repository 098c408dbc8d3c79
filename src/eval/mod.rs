//! Evaluation against ground truth (issue #4 §4, issue #5 §2).
//!
//! - [`truth`]: the true Betti numbers of the reachable free space in a window's domain, the
//!   true number of connections between consecutive windows, and the true global Betti
//!   numbers, from a cached raster of the world ([`FreeSpace`]).
//! - [`fidelity`]: rank correlation of the encounter metric with true distances
//!   ([`spearman`]) and the Procrustes error of the embedding ([`procrustes_error`]).
//! - [`holes`]: which obstacles of the truth a window's robust holes encircle.
//! - [`campaign`]: `swarmmap eval`, many worlds × parameters × seeds in parallel.
//! - [`stats`]: how sure a campaign's figures are (Wilson intervals, the exact McNemar test).

pub mod calibrate;
pub mod campaign;
pub mod fidelity;
pub mod holes;
pub mod stats;
pub mod truth;

pub use fidelity::{Procrustes, Similarity, procrustes, procrustes_error, spearman};
pub use holes::HoleCheck;
pub use truth::{
    BandComponents, DEFAULT_RESOLUTION, FreeSpace, TrueHole, TruthError, overlap, window_band,
};
