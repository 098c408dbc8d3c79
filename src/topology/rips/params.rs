//! Options of the Vietoris–Rips engine and the errors a checked run reports.

use thiserror::Error;

/// How to compute a Vietoris–Rips persistence diagram.
#[derive(Debug, Clone, PartialEq)]
pub struct RipsOptions {
    /// Highest homology dimension, 0 or 1 (default: `1`). Larger values are treated as 1.
    pub maxdim: usize,
    /// Largest edge length in the filtration, in the units of the input distances
    /// (default: `None`, the enclosing radius, which gives exactly the diagram of the full
    /// filtration because the complex is a cone from that scale on).
    pub threshold: Option<f64>,
    /// Compute a representative cycle for every H1 bar (default: `false`).
    pub cycles: bool,
    /// Worker threads; `0` uses all cores (default: `0`).
    pub threads: usize,
}

impl Default for RipsOptions {
    fn default() -> Self {
        Self {
            maxdim: 1,
            threshold: None,
            cycles: false,
            threads: 0,
        }
    }
}

impl RipsOptions {
    /// Validates the options: `maxdim` must be 0 or 1 and a threshold must be a finite,
    /// non-negative number.
    pub fn check(self) -> Result<Self, RipsError> {
        if self.maxdim > 1 {
            return Err(RipsError::MaxDim(self.maxdim));
        }
        if let Some(t) = self.threshold
            && !(t.is_finite() && t >= 0.0)
        {
            return Err(RipsError::Threshold(t));
        }
        Ok(self)
    }
}

/// A number as the command line's messages write it (as `world::given` does; the topology
/// engine depends on no other module): exactly, with an exponent outside 1e-6 ≤ |x| < 1e9
/// (`-1e300`, not hundreds of digits).
pub(crate) fn written(x: f64) -> String {
    if x == 0.0 || !x.is_finite() || (1e-6..1e9).contains(&x.abs()) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

/// What is wrong with a request for a persistence diagram.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum RipsError {
    #[error("homology dimension {0} is not supported; use --maxdim 0 or 1")]
    MaxDim(usize),
    #[error("threshold {} is not a finite non-negative distance", written(*.0))]
    Threshold(f64),
}
