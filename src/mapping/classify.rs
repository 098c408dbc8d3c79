//! Robust classification of persistence features (paper §"Topological Feature
//! Extraction": "robust classification of topological features … using statistical learning
//! techniques as described in [Dirafzoon 2014]").
//!
//! The encounter metric is in seconds and its scale changes with the swarm's speed, the
//! detection radius and the window's length, so the rule must be scale-invariant. Every
//! diagram is measured against its own *sampling scale* σ: the median death of the finite
//! H0 bars, i.e. the typical distance at which a representative joins its neighbours.
//! - An H0 class is robust if it is essential (one per component of the encounter graph)
//!   or its death exceeds `h0_ratio · σ`: a cluster separated by much more than the
//!   sampling scale.
//! - An H1 class is robust if its multiplicative persistence `death / birth` is at least
//!   `h1_ratio` and its additive persistence `death − birth` is at least `h1_span · σ`.
//!   The ratio is the standard scale-free noise test for Rips diagrams (noise loops die
//!   shortly after they are born); the span rejects loops that are long-lived only
//!   relative to a tiny birth.
//!
//! The three thresholds are fitted by `swarmmap calibrate` on training worlds and shipped as
//! the default model in `assets/classifier.json`.

use serde::{Deserialize, Serialize};

/// The fitted thresholds of the classifier.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Classifier {
    /// A finite H0 class is robust if `death > h0_ratio · σ`.
    pub h0_ratio: f64,
    /// An H1 class is robust if `death / birth ≥ h1_ratio` …
    pub h1_ratio: f64,
    /// … and `death − birth ≥ h1_span · σ`.
    pub h1_span: f64,
}

/// The shipped models, one per mapping method (`assets/classifier.json`), with a note on
/// what each was fitted on.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Models {
    #[serde(rename = "Paper")]
    pub paper: Model,
    #[serde(rename = "Embedded")]
    pub embedded: Model,
    /// The truth-position oracle's model ([`crate::mapping::output::Fidelity::oracle`]):
    /// fitted on the same stage run on true positions, whose diagrams are far less noisy
    /// than those of estimated clouds (`swarmmap calibrate --oracle`).
    #[serde(rename = "Oracle")]
    pub oracle: Model,
}

/// A fitted classifier and its provenance.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Model {
    pub classifier: Classifier,
    /// How it was fitted (command, worlds, seeds) and its training accuracy.
    pub fitted_on: String,
}

/// The text of the shipped models.
pub const SHIPPED: &str = include_str!("../../assets/classifier.json");

/// The models this process maps with, when not the shipped ones ([`Models::use_instead`]).
static ACTIVE: std::sync::OnceLock<Models> = std::sync::OnceLock::new();

impl Models {
    /// The shipped models.
    pub fn shipped() -> Self {
        serde_json::from_str(SHIPPED).expect("assets/classifier.json is a valid model file")
    }

    /// The models every later mapping in this process uses: those given to
    /// [`Models::use_instead`] (the command line's `--model FILE`), else the shipped ones.
    pub fn active() -> Self {
        ACTIVE.get().cloned().unwrap_or_else(Self::shipped)
    }

    /// Maps with `models` instead of the shipped ones for the rest of the process. Call it
    /// once, before any mapping starts; a second call is refused (returns `false`).
    pub fn use_instead(models: Models) -> bool {
        ACTIVE.set(models).is_ok()
    }

    /// Reads a model file written by `swarmmap calibrate`. The error names the file, the
    /// line and column of a JSON fault, and what a model file holds.
    pub fn load(path: &std::path::Path) -> anyhow::Result<Self> {
        use anyhow::Context;
        let text = std::fs::read_to_string(path)
            .with_context(|| format!("cannot read the model file {}", path.display()))?;
        let models: Models = serde_json::from_str(&text).map_err(|e| {
            anyhow::anyhow!(
                "{}:{}:{}: not a model file: {e}; a model file is what `swarmmap calibrate \
                 --out FILE` writes: an object with \"Paper\", \"Embedded\" and \"Oracle\" \
                 entries, each {{\"classifier\": {{\"h0_ratio\", \"h1_ratio\", \"h1_span\"}}, \
                 \"fitted_on\"}} (see assets/classifier.json)",
                path.display(),
                e.line(),
                e.column()
            )
        })?;
        for (name, m) in [
            ("Paper", &models.paper),
            ("Embedded", &models.embedded),
            ("Oracle", &models.oracle),
        ] {
            let c = m.classifier;
            let ok = c.h0_ratio.is_finite()
                && c.h0_ratio > 0.0
                && c.h1_ratio.is_finite()
                && c.h1_ratio >= 1.0
                && c.h1_span.is_finite()
                && c.h1_span >= 0.0;
            if !ok {
                anyhow::bail!(
                    "{}: the {name} model's thresholds (h0_ratio {}, h1_ratio {}, h1_span {}) \
                     are out of range; h0_ratio must be > 0, h1_ratio ≥ 1 and h1_span ≥ 0, \
                     all finite",
                    path.display(),
                    c.h0_ratio,
                    c.h1_ratio,
                    c.h1_span
                );
            }
        }
        Ok(models)
    }

    /// The model of a method.
    pub fn get(&self, method: crate::world::MappingMethod) -> &Model {
        match method {
            crate::world::MappingMethod::Paper => &self.paper,
            crate::world::MappingMethod::Embedded => &self.embedded,
        }
    }

    /// Mutable access to the model of a method.
    pub fn get_mut(&mut self, method: crate::world::MappingMethod) -> &mut Model {
        match method {
            crate::world::MappingMethod::Paper => &mut self.paper,
            crate::world::MappingMethod::Embedded => &mut self.embedded,
        }
    }
}

impl Default for Classifier {
    /// The shipped model of the paper's method.
    fn default() -> Self {
        Models::shipped().paper.classifier
    }
}

/// A bar as the classifier sees it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Feature {
    pub dim: usize,
    pub birth: f64,
    pub death: f64,
}

/// The features of a persistence diagram, one per bar, in the diagram's order.
pub fn features(diagram: &crate::topology::rips::Diagram) -> Vec<Feature> {
    diagram
        .bars
        .iter()
        .map(|b| Feature {
            dim: b.dim,
            birth: b.birth,
            death: b.death,
        })
        .collect()
}

/// The sampling scale σ of a diagram: the median finite H0 death (0 if there is none).
pub fn sampling_scale(features: &[Feature]) -> f64 {
    let mut d: Vec<f64> = features
        .iter()
        .filter(|f| f.dim == 0 && f.death.is_finite())
        .map(|f| f.death)
        .collect();
    if d.is_empty() {
        return 0.0;
    }
    d.sort_by(f64::total_cmp);
    d[d.len() / 2]
}

impl Classifier {
    /// Whether each feature is robust, given the diagram's sampling scale `sigma`.
    pub fn robust(&self, f: &Feature, sigma: f64) -> bool {
        match f.dim {
            0 => f.death.is_infinite() || f.death > self.h0_ratio * sigma,
            1 => {
                f.death.is_finite()
                    && f.birth > 0.0
                    && f.death / f.birth >= self.h1_ratio
                    && f.death - f.birth >= self.h1_span * sigma
                    || f.birth == 0.0 && f.death > self.h1_span * sigma
            }
            _ => false,
        }
    }

    /// (β0, β1): the number of robust classes in each dimension.
    pub fn betti(&self, features: &[Feature]) -> [usize; 2] {
        let sigma = sampling_scale(features);
        let mut b = [0, 0];
        for f in features {
            if f.dim < 2 && self.robust(f, sigma) {
                b[f.dim] += 1;
            }
        }
        b
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn f(dim: usize, birth: f64, death: f64) -> Feature {
        Feature { dim, birth, death }
    }

    #[test]
    fn the_rule_is_scale_invariant() {
        let c = Classifier {
            h0_ratio: 5.0,
            h1_ratio: 2.0,
            h1_span: 3.0,
        };
        let diagram = vec![
            f(0, 0.0, 1.0),
            f(0, 0.0, 1.0),
            f(0, 0.0, 1.2),
            f(0, 0.0, 8.0),
            f(0, 0.0, f64::INFINITY),
            f(1, 2.0, 2.5),
            f(1, 2.0, 9.0),
        ];
        assert_eq!(c.betti(&diagram), [2, 1]);
        let scaled: Vec<Feature> = diagram
            .iter()
            .map(|x| f(x.dim, 37.0 * x.birth, 37.0 * x.death))
            .collect();
        assert_eq!(c.betti(&scaled), [2, 1]);
    }

    #[test]
    fn shipped_model_loads() {
        let m = Models::shipped();
        for c in [m.paper.classifier, m.embedded.classifier] {
            assert!(c.h0_ratio > 0.0 && c.h1_ratio >= 1.0 && c.h1_span >= 0.0);
        }
    }
}
