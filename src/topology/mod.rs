//! The topology engine: the mathematics the mapping stages rest on, independent of the
//! simulator (paper §"Background", §"Geometric Reconstruction", §"Topological Feature
//! Extraction", §"Global Mapping").
//!
//! - [`distance`]: point clouds and condensed distance matrices, the engine's inputs.
//! - [`rips`]: Vietoris–Rips persistent homology in dimensions 0 and 1 over Z/2, with
//!   representative cycles for H1.
//! - [`linkage`]: single-linkage dendrograms and cuts (global map stitching).
//! - [`mds`]: classical and landmark multidimensional scaling (the encounter point cloud).

pub mod distance;
pub mod linkage;
pub mod mds;
pub mod rips;

pub use distance::{DistanceMatrix, MatrixError, PointCloud};
