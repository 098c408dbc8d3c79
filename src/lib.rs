//! # swarmmap
//!
//! Topological maps of unknown environments from nothing but the encounters of a
//! stochastic robot swarm, after Dirafzoon, Bozkurt and Lobaton, "Dynamic Topological
//! Mapping with Biobotic Swarms" (IPSN 2015).
//!
//! The pipeline is a sequence of stages, each a module with one input type and one
//! output type (see `ARCHITECTURE.md`):
//!
//! | stage | module | input | output |
//! |---|---|---|---|
//! | world | [`world`] | RON text | [`world::World`] |
//! | simulation | [`sim`] | [`world::World`], seed | [`log::EncounterLog`] |
//! | topology engine | [`topology`] | point clouds, distance matrices | diagrams, dendrograms, embeddings |
//! | report | [`report`] | a run directory | SVG figures and a self-contained `index.html` |

pub mod eval;
pub mod io;
pub mod log;
pub mod mapping;
pub mod pipeline;
pub mod report;
pub mod sim;
pub mod topology;
pub mod world;
