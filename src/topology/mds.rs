//! Placeholder until the topology engine lands (issue #3).
