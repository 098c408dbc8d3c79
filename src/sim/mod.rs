//! Placeholder until the simulator lands (issue #2).
