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
//!   relative to a tiny birth. A model may also carry `h1_crossing`: the largest share of
//!   the agents' time lines near the loop's void that may pass through it
//!   ([`super::crossing`]; none in the shipped models, docs/accuracy.md, step 37).
//!
//! The three thresholds are fitted by `swarmmap calibrate` on training worlds and shipped as
//! the default models in `assets/classifier.json`. σ makes them free of the metric's unit
//! but not of the sampling: each model also records the density it was fitted at (encounters
//! per vertex of the Rips complexes, [`Density`]), a method may carry several ([`Bank`]),
//! and each window is judged by the one fitted nearest its own density. The shipped file
//! holds one model per method (docs/accuracy.md, step 31, says why).

use serde::{Deserialize, Serialize};

/// The fitted thresholds of the classifier.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Classifier {
    /// A finite H0 class is robust if `death > h0_ratio · σ`.
    pub h0_ratio: f64,
    /// An H1 class is robust if `death / birth ≥ h1_ratio` …
    pub h1_ratio: f64,
    /// … and `death − birth ≥ h1_span · σ` …
    pub h1_span: f64,
    /// … and, when set, its crossing share ([`super::crossing`]) is at most this: few of
    /// the agents' time lines pass through its void. Absent in models fitted without it
    /// (every model fitted before docs/accuracy.md, step 37) and in those of methods that
    /// compute no share (`Paper`, the oracle): no such test.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub h1_crossing: Option<f64>,
    /// … and, when set, its split stability ([`super::stability`]) is at least this: both
    /// halves of the window's encounters show a loop at its place with a life of this many
    /// of their σ. Absent in models fitted without it: no such test.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub h1_stability: Option<f64>,
}

/// The shipped models, one bank per mapping method (`assets/classifier.json`), each model
/// with a note on what it was fitted on.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Models {
    #[serde(rename = "Paper", deserialize_with = "paper_bank")]
    pub paper: Bank,
    #[serde(rename = "Embedded", deserialize_with = "embedded_bank")]
    pub embedded: Bank,
    /// The truth-position oracle's models ([`crate::mapping::output::Fidelity::oracle`]):
    /// fitted on the same stage run on true positions, whose diagrams are far less noisy
    /// than those of estimated clouds (`swarmmap calibrate --oracle`).
    #[serde(rename = "Oracle", deserialize_with = "oracle_bank")]
    pub oracle: Bank,
}

fn paper_bank<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Bank, D::Error> {
    Bank::deserialize_named(d, "Paper")
}

fn embedded_bank<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Bank, D::Error> {
    Bank::deserialize_named(d, "Embedded")
}

fn oracle_bank<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Bank, D::Error> {
    Bank::deserialize_named(d, "Oracle")
}

/// A fitted classifier and its provenance.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Model {
    pub classifier: Classifier,
    /// How it was fitted (command, worlds, seeds) and its training accuracy.
    pub fitted_on: String,
    /// The sampling density of its training windows ([`Density`]); `None` in model files
    /// written before densities were recorded, which serve every window.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub events_per_point: Option<Density>,
    /// The leader's sweep speed of its training runs, m/s ([`Bank::for_sweep`]); `None` in
    /// model files written before sweeps were recorded, which count as fitted at the
    /// default sweep ([`DEFAULT_SWEEP`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub leader_speed: Option<f64>,
}

/// How much sparser than its training windows a window may be before `map` and `run` warn
/// that its model was not made for it ([`Bank::too_sparse_for`]): half again. The shipped
/// `Embedded` model's own training windows span a factor of 2.75 (4.39–12.08 encounters per
/// vertex); the bundled worlds' windows hold at least 4.39 (seeds 1–20 of scenario 2 and 3
/// and seed 1 of the others, fortieth session), and a log with a tenth of scenario 1's rows
/// holds about 1.1.
pub const DENSITY_MARGIN: f64 = 1.5;

/// The sweep a model without a recorded `leader_speed` was fitted at: the default leader
/// speed, that of every training world.
pub const DEFAULT_SWEEP: f64 = 0.005;

impl Model {
    /// The leader speed its training runs swept at, m/s.
    pub fn sweep(&self) -> f64 {
        self.leader_speed.unwrap_or(DEFAULT_SWEEP)
    }
}

/// Encounters per vertex of the Rips complexes over a model's training windows
/// ([`crate::mapping::local::LocalMap::events_per_point`]): the least, the median and the
/// most.
///
/// Why a model is tied to a density: the thresholds are scale-free in the metric's units
/// (σ), but not in the sampling. With twice the Rips points at the same sweep (2.8–4.2
/// encounters per point instead of 5.5–8.3), the diagrams hold many more short noise loops,
/// σ shrinks, and the model fitted at the sparser sampling shows false holes; a model
/// fitted at the denser sampling asks for a life of 8.75 σ instead of 4.25 σ
/// (docs/accuracy.md, step 28). A slower sweep with twice the points lands back at the sparser
/// density, where the first model serves (step 29). Density is not the whole regime,
/// though: half-speed windows at 5–6 encounters per vertex are judged badly by the model
/// fitted at that density at full speed (step 31), so a bank should hold models fitted at
/// one sweep speed.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Density {
    pub min: f64,
    pub median: f64,
    pub max: f64,
}

impl Density {
    /// The density range of some windows' densities (`None` if there are none, or none is
    /// positive and finite).
    pub fn of(values: &[f64]) -> Option<Self> {
        let mut v: Vec<f64> = values
            .iter()
            .copied()
            .filter(|x| x.is_finite() && *x > 0.0)
            .collect();
        if v.is_empty() {
            return None;
        }
        v.sort_by(f64::total_cmp);
        Some(Self {
            min: v[0],
            median: v[v.len() / 2],
            max: v[v.len() - 1],
        })
    }
}

/// The models of one method, each fitted at its own sweep speed and sampling density. A
/// run keeps the models fitted at the sweep nearest its leader's ([`Bank::for_sweep`]), and
/// each of its windows is judged by the one of them whose training windows' median density
/// is nearest its own, as a ratio (|ln d − ln median|; the first on a tie). In JSON a bank
/// is one model object, or an array of them, each with its `events_per_point`.
///
/// Why the sweep comes first: a slower sweep keeps the swarm longer round each part of the
/// arena, and windows of the same density then hold loops of another kind
/// (docs/accuracy.md, step 31: half-speed windows at the density of a full-speed model are judged
/// badly by it), so density alone cannot tell which model fits.
#[derive(Debug, Clone, PartialEq)]
pub struct Bank(pub Vec<Model>);

impl Serialize for Bank {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self.0.as_slice() {
            [one] => one.serialize(s),
            many => many.serialize(s),
        }
    }
}

impl<'de> Deserialize<'de> for Bank {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        Bank::deserialize_named(d, "bank")
    }
}

impl Bank {
    /// Reads the object or the array as it streams (not through an untagged enum, which
    /// buffers the value and loses the position and the reason of a fault inside it), and
    /// checks each model as soon as it is read ([`check_model`]) and the bank at its end
    /// ([`check_bank`]), so that a JSON reader reports the place of a model out of range:
    /// just after it. `name` is the bank's entry, for the messages.
    fn deserialize_named<'de, D: serde::Deserializer<'de>>(
        d: D,
        name: &'static str,
    ) -> Result<Self, D::Error> {
        use serde::de::Error;
        struct BankVisitor(&'static str);
        impl<'de> serde::de::Visitor<'de> for BankVisitor {
            type Value = Bank;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a model object or a list of model objects")
            }
            fn visit_map<A: serde::de::MapAccess<'de>>(self, map: A) -> Result<Bank, A::Error> {
                Ok(Bank(vec![CheckedModel(self.0).visit_map(map)?]))
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(self, mut seq: A) -> Result<Bank, A::Error> {
                let mut models = Vec::new();
                // Checked inside the element's own map visit, so that the reader places
                // a fault just after that model, not after the list's next token.
                while let Some(m) = seq.next_element_seed(CheckedModel(self.0))? {
                    models.push(m);
                }
                let bank = Bank(models);
                check_bank(self.0, &bank).map_err(A::Error::custom)?;
                Ok(bank)
            }
        }
        d.deserialize_any(BankVisitor(name))
    }
}

/// One model of a bank's list, checked by [`check_model`] as soon as its object is read.
struct CheckedModel(&'static str);

impl<'de> serde::de::DeserializeSeed<'de> for CheckedModel {
    type Value = Model;
    fn deserialize<D: serde::Deserializer<'de>>(self, d: D) -> Result<Model, D::Error> {
        d.deserialize_map(self)
    }
}

impl<'de> serde::de::Visitor<'de> for CheckedModel {
    type Value = Model;
    fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str("a model object")
    }
    fn visit_map<A: serde::de::MapAccess<'de>>(self, map: A) -> Result<Model, A::Error> {
        use serde::de::Error;
        let m = Model::deserialize(serde::de::value::MapAccessDeserializer::new(map))?;
        check_model(self.0, &m).map_err(A::Error::custom)?;
        Ok(m)
    }
}

/// Starts every message of [`check_model`] and [`check_bank`]: the entry's name, so that
/// [`Models::load`] tells a value out of range (whose message says how to fix it) from a
/// file that is not a model file at all.
fn entry_says(name: &str) -> String {
    format!("the {name} ")
}

/// A bank must hold a model, and the models of one sweep must all carry their densities.
fn check_bank(name: &str, bank: &Bank) -> Result<(), String> {
    let the = entry_says(name);
    if bank.0.is_empty() {
        return Err(format!(
            "{the}entry is an empty list; give at least one model"
        ));
    }
    for m in &bank.0 {
        let same = bank.for_sweep(m.sweep());
        if same.0.len() > 1 && same.0.iter().any(|m| m.events_per_point.is_none()) {
            return Err(format!(
                "{the}entry lists {} models fitted at the sweep of {} m/s but not every one \
                 has \"events_per_point\" ({{\"min\", \"median\", \"max\"}}), which picks \
                 the model of each window among them; models of one sweep need it on every \
                 one (calibrate writes it)",
                same.0.len(),
                m.sweep()
            ));
        }
    }
    Ok(())
}

/// A model's thresholds, sweep and densities must lie in their ranges.
fn check_model(name: &str, m: &Model) -> Result<(), String> {
    let the = entry_says(name);
    let c = m.classifier;
    let ok = c.h0_ratio > 0.0
        && c.h0_ratio <= MAX_THRESHOLD
        && c.h1_ratio >= 1.0
        && c.h1_ratio <= MAX_THRESHOLD
        && c.h1_span >= 0.0
        && c.h1_span <= MAX_THRESHOLD;
    if !ok {
        return Err(format!(
            "{the}model's thresholds (h0_ratio {}, h1_ratio {}, h1_span {}) are out of \
             range; h0_ratio must be > 0, h1_ratio ≥ 1 and h1_span ≥ 0, all at most 1e12 \
             (fitted models stay below 100)",
            crate::world::given(c.h0_ratio),
            crate::world::given(c.h1_ratio),
            crate::world::given(c.h1_span)
        ));
    }
    if let Some(x) = c.h1_crossing
        && !(0.0..=1.0).contains(&x)
    {
        return Err(format!(
            "{the}model's h1_crossing is {}; it is the largest share of time lines that may \
             cross a hole, from 0 to 1 (or leave it out for no crossing test)",
            crate::world::given(x)
        ));
    }
    if let Some(x) = c.h1_stability
        && !(0.0..=MAX_THRESHOLD).contains(&x)
    {
        return Err(format!(
            "{the}model's h1_stability is {}; it is the least life, in σ, that both halves \
             of a window must give a hole, a number from 0 to 1e12 (or leave it out for no \
             stability test)",
            crate::world::given(x)
        ));
    }
    if let Some(v) = m.leader_speed
        && !(v.is_finite() && v > 0.0)
    {
        return Err(format!(
            "{the}model's leader_speed is {}; it is the sweep speed of its training runs in \
             m/s, positive and finite (or leave it out for the default sweep, \
             {DEFAULT_SWEEP} m/s)",
            crate::world::given(v)
        ));
    }
    if let Some(d) = m.events_per_point {
        let ok = [d.min, d.median, d.max]
            .iter()
            .all(|x| x.is_finite() && *x > 0.0)
            && d.min <= d.median
            && d.median <= d.max;
        if !ok {
            return Err(format!(
                "{the}model's events_per_point ({}, {}, {}) must be positive and finite with \
                 min ≤ median ≤ max",
                crate::world::given(d.min),
                crate::world::given(d.median),
                crate::world::given(d.max)
            ));
        }
    }
    Ok(())
}

impl Bank {
    /// A bank of one model fitted at no recorded density.
    pub fn single(classifier: Classifier) -> Self {
        Bank(vec![Model {
            classifier,
            fitted_on: String::new(),
            events_per_point: None,
            leader_speed: None,
        }])
    }

    /// The models fitted at the sweep nearest `speed` (m/s), as a ratio (|ln v − ln s|; on a
    /// tie the faster sweep). A speed that is not positive and finite counts as the default.
    pub fn for_sweep(&self, speed: f64) -> Bank {
        let speed = if speed.is_finite() && speed > 0.0 {
            speed
        } else {
            DEFAULT_SWEEP
        };
        let far = |s: f64| (speed / s).ln().abs();
        let Some(best) = self.0.iter().map(Model::sweep).reduce(|a, b| {
            let (fa, fb) = (far(a), far(b));
            // Within rounding of a tie (0.0025 between 0.005 and 0.00125): the faster.
            if (fa - fb).abs() <= 1e-9 {
                a.max(b)
            } else if fb < fa {
                b
            } else {
                a
            }
        }) else {
            return self.clone();
        };
        Bank(
            self.0
                .iter()
                .filter(|m| m.sweep() == best)
                .cloned()
                .collect(),
        )
    }

    /// The model a window of `events_per_point` encounters per Rips vertex is judged by.
    pub fn pick(&self, events_per_point: f64) -> &Model {
        if !(events_per_point.is_finite() && events_per_point > 0.0) {
            return self.first();
        }
        let far = |m: &Model| {
            m.events_per_point
                .map_or(f64::INFINITY, |d| (events_per_point / d.median).ln().abs())
        };
        // `min_by` keeps the first of equals: the first model on a tie.
        self.0
            .iter()
            .min_by(|a, b| far(a).total_cmp(&far(b)))
            .unwrap_or_else(|| self.first())
    }

    /// The training density of the model that judges a window of `events_per_point`
    /// encounters per Rips vertex, when that window is sparser than its training windows by
    /// more than [`DENSITY_MARGIN`] (below their least over the margin); `None` when it is
    /// not, or the model recorded no density. A model does not carry to sparser clouds:
    /// fitted at twice the density, it shows false holes there (docs/accuracy.md, steps 28
    /// and 31). Denser windows are not flagged: no such failure was measured (the bundled
    /// corridor's windows hold 38–52 encounters per vertex and map right).
    pub fn too_sparse_for(&self, events_per_point: f64) -> Option<Density> {
        let d = self.pick(events_per_point).events_per_point?;
        (events_per_point < d.min / DENSITY_MARGIN).then_some(d)
    }

    /// The first model (the only one of a bank of one).
    pub fn first(&self) -> &Model {
        &self.0[0]
    }

    /// Puts `model` in the bank: among the models of its sweep it replaces every one whose
    /// median density lies within its training range (or every one, if either side has no
    /// recorded density), and joins the others; models of other sweeps stay. The bank is
    /// kept in order of sweep, fastest first, then of median density.
    pub fn insert(&mut self, model: Model) {
        let Some(d) = model.events_per_point else {
            return self.replace_sweep(model);
        };
        let sweep = model.sweep();
        self.0.retain(|m| {
            m.sweep() != sweep
                || m.events_per_point
                    .is_some_and(|e| e.median < d.min || e.median > d.max)
        });
        self.0.push(model);
        self.sort();
    }

    /// Keeps only `model` among the models of its sweep (`calibrate --only`).
    pub fn replace_sweep(&mut self, model: Model) {
        let sweep = model.sweep();
        self.0.retain(|m| m.sweep() != sweep);
        self.0.push(model);
        self.sort();
    }

    fn sort(&mut self) {
        self.0.sort_by(|a, b| {
            let key = |m: &Model| m.events_per_point.map_or(0.0, |d| d.median);
            b.sweep()
                .total_cmp(&a.sweep())
                .then(key(a).total_cmp(&key(b)))
        });
    }
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
            // serde_json's message ends with the place, which goes in front instead.
            let message = e.to_string();
            let message = message
                .strip_suffix(&format!(" at line {} column {}", e.line(), e.column()))
                .unwrap_or(&message);
            let at = format!("{}:{}:{}", path.display(), e.line(), e.column());
            if ["Paper", "Embedded", "Oracle"]
                .iter()
                .any(|name| message.starts_with(&entry_says(name)))
            {
                // A value out of range: the message says what each value must be.
                anyhow::anyhow!("{at}: {message}")
            } else {
                anyhow::anyhow!(
                    "{at}: not a model file: {message}; a model file is what `swarmmap \
                     calibrate --out FILE` writes: an object with \"Paper\", \"Embedded\" and \
                     \"Oracle\" entries, each a model {{\"classifier\": {{\"h0_ratio\", \
                     \"h1_ratio\", \"h1_span\"}}, \"fitted_on\"}} or a list of models that also \
                     carry \"events_per_point\": {{\"min\", \"median\", \"max\"}}, and may \
                     carry \"leader_speed\" (m/s, the sweep they were fitted at; see \
                     assets/classifier.json)"
                )
            }
        })?;
        Ok(models)
    }

    /// The models of a method.
    pub fn get(&self, method: crate::world::MappingMethod) -> &Bank {
        match method {
            crate::world::MappingMethod::Paper => &self.paper,
            crate::world::MappingMethod::Embedded => &self.embedded,
        }
    }

    /// Mutable access to the models of a method.
    pub fn get_mut(&mut self, method: crate::world::MappingMethod) -> &mut Bank {
        match method {
            crate::world::MappingMethod::Paper => &mut self.paper,
            crate::world::MappingMethod::Embedded => &mut self.embedded,
        }
    }
}

impl Default for Classifier {
    /// The shipped model of the paper's method.
    fn default() -> Self {
        Models::shipped().paper.first().classifier
    }
}

/// A bar as the classifier sees it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Feature {
    pub dim: usize,
    pub birth: f64,
    pub death: f64,
    /// The crossing share of an H1 bar's void ([`super::crossing`]), where computed.
    pub crossing: Option<f64>,
    /// The split stability of an H1 bar ([`super::stability`]), where computed.
    pub stability: Option<f64>,
}

impl Feature {
    /// A bar without a crossing share or a stability.
    pub fn bar(dim: usize, birth: f64, death: f64) -> Self {
        Self {
            dim,
            birth,
            death,
            crossing: None,
            stability: None,
        }
    }
}

/// The features of a persistence diagram, one per bar, in the diagram's order.
pub fn features(diagram: &crate::topology::rips::Diagram) -> Vec<Feature> {
    diagram
        .bars
        .iter()
        .map(|b| Feature::bar(b.dim, b.birth, b.death))
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

/// Largest threshold a model file may hold (ratios, and lives in σ): fitted ones stay
/// below 100, and 1e9 already makes every feature noise (the tests' way of asking for
/// no hole); near `f64::MAX` the report's axes never finished.
pub const MAX_THRESHOLD: f64 = 1e12;

/// The candidate test's share of the H1 thresholds: a loop with `death / birth ≥ 0.85 ·
/// h1_ratio` and `death − birth ≥ 0.75 · h1_span · σ` is a candidate, a hole that counts in
/// the global map once a neighbouring window sees one at the same place
/// ([`crate::mapping::stitch`]). Two windows see an obstacle of their overlap at different
/// times, from different encounters, so their loops are two observations: each may be
/// weaker than one window's alone must be (docs/accuracy.md, step 32).
pub const CANDIDATE_SHARE: [f64; 2] = [0.85, 0.75];

/// The strong test's multiple of `h1_span`: a robust hole that a neighbouring window
/// covers without seeing any loop there stays a hole of the global map only when
/// `death − birth ≥ 1.25 · h1_span · σ` ([`crate::mapping::stitch`]).
pub const STRONG_SPAN: f64 = 1.25;

impl Classifier {
    /// The candidate test ([`CANDIDATE_SHARE`]) as a classifier; its H0 rule is this one's.
    pub fn candidate(&self) -> Self {
        Self {
            h1_ratio: CANDIDATE_SHARE[0] * self.h1_ratio,
            h1_span: CANDIDATE_SHARE[1] * self.h1_span,
            ..*self
        }
    }

    /// Whether a robust H1 class of life `death − birth` is strong on a diagram of sampling
    /// scale `sigma` ([`STRONG_SPAN`]).
    pub fn strong(&self, birth: f64, death: f64, sigma: f64) -> bool {
        death - birth >= STRONG_SPAN * self.h1_span * sigma
    }

    /// Whether each feature is robust, given the diagram's sampling scale `sigma`.
    pub fn robust(&self, f: &Feature, sigma: f64) -> bool {
        match f.dim {
            0 => f.death.is_infinite() || f.death > self.h0_ratio * sigma,
            1 => {
                let crossed =
                    matches!((self.h1_crossing, f.crossing), (Some(max), Some(x)) if x > max);
                let unstable =
                    matches!((self.h1_stability, f.stability), (Some(min), Some(x)) if x < min);
                !crossed
                    && !unstable
                    && (f.death.is_finite()
                        && f.birth > 0.0
                        && f.death / f.birth >= self.h1_ratio
                        && f.death - f.birth >= self.h1_span * sigma
                        // Born at 0 (coinciding points), the ratio is infinite: the life
                        // decides, at the same bound as above.
                        || f.birth == 0.0 && f.death >= self.h1_span * sigma)
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
        Feature::bar(dim, birth, death)
    }

    /// H0 ratio 5, H1 ratio 2 and span 3, no crossing or stability test.
    fn ratio_2_span_3() -> Classifier {
        Classifier {
            h0_ratio: 5.0,
            h1_ratio: 2.0,
            h1_span: 3.0,
            h1_crossing: None,
            h1_stability: None,
        }
    }

    #[test]
    fn the_rule_is_scale_invariant() {
        let c = ratio_2_span_3();
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

    /// A bar born at 0 is judged by its life alone, with the bound the other bars meet
    /// (`≥`; found by the forty-first session's review: it was `>`).
    #[test]
    fn a_bar_born_at_zero_is_judged_by_its_life() {
        let c = ratio_2_span_3();
        assert!(c.robust(&f(1, 0.0, 6.0), 2.0));
        assert!(c.robust(&f(1, 3.0, 9.0), 2.0));
        assert!(!c.robust(&f(1, 0.0, 5.9), 2.0));
    }

    #[test]
    fn shipped_model_loads() {
        let m = Models::shipped();
        for bank in [&m.paper, &m.embedded, &m.oracle] {
            assert!(!bank.0.is_empty());
            for model in &bank.0 {
                let c = model.classifier;
                assert!(c.h0_ratio > 0.0 && c.h1_ratio >= 1.0 && c.h1_span >= 0.0);
            }
            if bank.0.len() > 1 {
                assert!(bank.0.iter().all(|m| m.events_per_point.is_some()));
            }
        }
    }

    fn model(h1_ratio: f64, density: Option<[f64; 3]>) -> Model {
        Model {
            classifier: Classifier {
                h0_ratio: 50.0,
                h1_ratio,
                h1_span: 1.0,
                h1_crossing: None,
                h1_stability: None,
            },
            fitted_on: format!("ratio {h1_ratio}"),
            events_per_point: density.map(|[min, median, max]| Density { min, median, max }),
            leader_speed: None,
        }
    }

    /// A window is judged by the model whose median density is nearest its own as a
    /// ratio: 4.5 is nearer 3.4 than 6.8 in ratio (1.32 against 1.51) though nearer 6.8
    /// in difference.
    #[test]
    fn a_window_takes_the_model_nearest_its_density_as_a_ratio() {
        let bank = Bank(vec![
            model(2.0, Some([2.8, 3.4, 4.2])),
            model(3.0, Some([5.5, 6.8, 8.3])),
        ]);
        let ratio = |d: f64| bank.pick(d).classifier.h1_ratio;
        assert_eq!(ratio(1.0), 2.0);
        assert_eq!(ratio(3.4), 2.0);
        assert_eq!(ratio(4.5), 2.0);
        assert_eq!(ratio(5.0), 3.0);
        assert_eq!(ratio(40.0), 3.0);
        // Undefined densities (a window without components) take the first model.
        assert_eq!(ratio(0.0), 2.0);
        assert_eq!(ratio(f64::NAN), 2.0);
        // A bank of one serves every density.
        let one = Bank(vec![model(5.0, None)]);
        assert_eq!(one.pick(0.1).classifier.h1_ratio, 5.0);
        assert_eq!(one.pick(100.0).classifier.h1_ratio, 5.0);
    }

    /// A refit at the same sampling replaces the model; a fit at another joins the bank,
    /// kept in order of density; a model without a density replaces the whole bank.
    #[test]
    fn inserting_replaces_the_same_sampling_and_adds_another() {
        let mut bank = Bank(vec![model(3.0, Some([5.5, 6.8, 8.3]))]);
        bank.insert(model(2.0, Some([2.8, 3.4, 4.2])));
        assert_eq!(bank.0.len(), 2);
        assert_eq!(bank.0[0].classifier.h1_ratio, 2.0);
        bank.insert(model(3.5, Some([5.0, 7.0, 9.0])));
        let ratios: Vec<f64> = bank.0.iter().map(|m| m.classifier.h1_ratio).collect();
        assert_eq!(ratios, [2.0, 3.5]);
        bank.insert(model(9.0, None));
        assert_eq!(bank.0.len(), 1);
        // A density-free model in the bank gives way to the first fit with a density.
        bank.insert(model(2.5, Some([1.0, 2.0, 3.0])));
        assert_eq!(bank.0.len(), 1);
        assert_eq!(bank.0[0].classifier.h1_ratio, 2.5);
    }

    fn swept(h1_ratio: f64, density: [f64; 3], sweep: Option<f64>) -> Model {
        Model {
            leader_speed: sweep,
            ..model(h1_ratio, Some(density))
        }
    }

    /// A run keeps the models of the sweep nearest its leader's, as a ratio; a model
    /// without a recorded sweep counts as fitted at the default; on a tie the faster sweep
    /// wins; density then picks among the kept models only.
    #[test]
    fn a_run_takes_the_models_of_the_nearest_sweep() {
        let bank = Bank(vec![
            swept(2.0, [5.0, 6.0, 7.0], None),
            swept(3.0, [2.8, 3.4, 4.2], Some(DEFAULT_SWEEP)),
            swept(5.0, [5.5, 6.3, 7.0], Some(0.00125)),
        ]);
        let ratios = |speed: f64| -> Vec<f64> {
            let b = bank.for_sweep(speed);
            b.0.iter().map(|m| m.classifier.h1_ratio).collect()
        };
        assert_eq!(ratios(0.005), [2.0, 3.0]);
        assert_eq!(ratios(0.01), [2.0, 3.0]);
        assert_eq!(ratios(0.001), [5.0]);
        assert_eq!(ratios(0.0015), [5.0]);
        // 0.0025 is a factor 2 from both: the faster sweep.
        assert_eq!(ratios(0.0025), [2.0, 3.0]);
        assert_eq!(ratios(0.0024), [5.0]);
        // Not a speed: the default sweep.
        assert_eq!(ratios(0.0), [2.0, 3.0]);
        assert_eq!(ratios(f64::NAN), [2.0, 3.0]);
        // At the same density, the sweep decides.
        assert_eq!(bank.for_sweep(0.00125).pick(6.0).classifier.h1_ratio, 5.0);
        assert_eq!(bank.for_sweep(0.005).pick(6.3).classifier.h1_ratio, 2.0);
    }

    /// A fit at another sweep joins the bank whatever its density; a refit at a sweep
    /// replaces only that sweep's models of its density, and `--only` only that sweep's.
    #[test]
    fn inserting_keeps_the_models_of_other_sweeps() {
        let mut bank = Bank(vec![swept(2.3, [5.5, 6.8, 8.3], None)]);
        bank.insert(swept(4.0, [5.0, 6.5, 8.0], Some(0.00125)));
        let ratios = |b: &Bank| -> Vec<f64> { b.0.iter().map(|m| m.classifier.h1_ratio).collect() };
        assert_eq!(ratios(&bank), [2.3, 4.0]);
        bank.insert(swept(4.5, [6.0, 6.6, 7.0], Some(0.00125)));
        assert_eq!(ratios(&bank), [2.3, 4.5]);
        bank.insert(swept(3.0, [2.8, 3.4, 4.2], Some(DEFAULT_SWEEP)));
        // Fastest sweep first, then density.
        assert_eq!(ratios(&bank), [3.0, 2.3, 4.5]);
        bank.replace_sweep(swept(4.9, [1.0, 2.0, 3.0], Some(0.00125)));
        assert_eq!(ratios(&bank), [3.0, 2.3, 4.9]);
        bank.replace_sweep(swept(2.0, [1.0, 2.0, 3.0], None));
        assert_eq!(ratios(&bank), [2.0, 4.9]);
    }

    #[test]
    fn density_of_windows_ignores_empty_ones() {
        let d = Density::of(&[4.0, 0.0, 2.0, f64::NAN, 3.0]).unwrap();
        assert_eq!((d.min, d.median, d.max), (2.0, 3.0, 4.0));
        assert!(Density::of(&[0.0]).is_none());
    }

    /// A bank is one model object or an array; one model is written back as an object,
    /// so model files written before banks existed load and round-trip unchanged.
    #[test]
    fn a_bank_reads_and_writes_both_json_forms() {
        let one: Bank = serde_json::from_str(
            r#"{"classifier": {"h0_ratio": 50, "h1_ratio": 2, "h1_span": 1}, "fitted_on": "x"}"#,
        )
        .unwrap();
        assert_eq!(one.0.len(), 1);
        assert!(one.0[0].events_per_point.is_none());
        let text = serde_json::to_string(&one).unwrap();
        assert!(text.starts_with('{') && !text.contains("events_per_point"));
        let two = Bank(vec![
            model(2.0, Some([2.8, 3.4, 4.2])),
            model(3.0, Some([5.5, 6.8, 8.3])),
        ]);
        let text = serde_json::to_string(&two).unwrap();
        assert!(text.starts_with('['));
        assert_eq!(serde_json::from_str::<Bank>(&text).unwrap(), two);
    }

    /// The crossing test keeps an H1 bar only if its share is at most `h1_crossing`; a
    /// bar without a share, or a model without the test, judges by persistence alone.
    #[test]
    fn the_crossing_test_gates_h1_only() {
        let mut c = Classifier {
            h0_ratio: 5.0,
            h1_ratio: 2.0,
            h1_span: 3.0,
            h1_crossing: Some(0.05),
            h1_stability: None,
        };
        let with = |x: Option<f64>| Feature {
            crossing: x,
            ..f(1, 1.0, 5.0)
        };
        assert!(c.robust(&with(Some(0.05)), 1.0));
        assert!(!c.robust(&with(Some(0.0500001)), 1.0));
        assert!(c.robust(&with(None), 1.0));
        // Persistence must pass too.
        assert!(!c.robust(
            &Feature {
                crossing: Some(0.0),
                ..f(1, 1.0, 1.9)
            },
            1.0
        ));
        // H0 ignores it.
        assert!(c.robust(
            &Feature {
                crossing: Some(1.0),
                ..f(0, 0.0, 6.0)
            },
            1.0
        ));
        // The candidate rule keeps the test.
        assert_eq!(c.candidate().h1_crossing, Some(0.05));
        c.h1_crossing = None;
        assert!(c.robust(&with(Some(0.9)), 1.0));
        // Written only when set, so model files without it read and write unchanged.
        assert!(!serde_json::to_string(&c).unwrap().contains("crossing"));
    }

    /// The stability test keeps an H1 bar only if its stability is at least
    /// `h1_stability`; a bar without one, or a model without the test, judges by
    /// persistence alone.
    #[test]
    fn the_stability_test_gates_h1_only() {
        let mut c = Classifier {
            h0_ratio: 5.0,
            h1_ratio: 2.0,
            h1_span: 3.0,
            h1_crossing: None,
            h1_stability: Some(2.5),
        };
        let with = |x: Option<f64>| Feature {
            stability: x,
            ..f(1, 1.0, 5.0)
        };
        assert!(c.robust(&with(Some(2.5)), 1.0));
        assert!(!c.robust(&with(Some(2.4999999)), 1.0));
        assert!(c.robust(&with(None), 1.0));
        // Persistence must pass too.
        assert!(!c.robust(
            &Feature {
                stability: Some(9.0),
                ..f(1, 1.0, 1.9)
            },
            1.0
        ));
        // H0 ignores it.
        assert!(c.robust(
            &Feature {
                stability: Some(0.0),
                ..f(0, 0.0, 6.0)
            },
            1.0
        ));
        // The candidate rule keeps the test.
        assert_eq!(c.candidate().h1_stability, Some(2.5));
        c.h1_stability = None;
        assert!(c.robust(&with(Some(0.0)), 1.0));
        assert!(!serde_json::to_string(&c).unwrap().contains("stability"));
    }

    #[test]
    fn a_stability_below_0_is_refused() {
        let mut m = Models::shipped();
        m.embedded.0[0].classifier.h1_stability = Some(-1.0);
        let err = load_text(&serde_json::to_string(&m).unwrap())
            .unwrap_err()
            .to_string();
        assert!(err.contains("h1_stability is -1"), "{err}");
        m.embedded.0[0].classifier.h1_stability = Some(3.25);
        assert_eq!(load_text(&serde_json::to_string(&m).unwrap()).unwrap(), m);
    }

    /// A threshold near `f64::MAX` made every feature noise and the report's figures
    /// never finish their axes: refused, with the bound.
    #[test]
    fn a_huge_threshold_is_refused() {
        for field in 0..4 {
            let mut m = Models::shipped();
            let c = &mut m.paper.0[0].classifier;
            match field {
                0 => c.h0_ratio = 1e308,
                1 => c.h1_ratio = 1e13,
                2 => c.h1_span = 1e308,
                _ => c.h1_stability = Some(1e308),
            }
            let err = load_text(&serde_json::to_string(&m).unwrap())
                .unwrap_err()
                .to_string();
            assert!(err.contains("1e12"), "{field}: {err}");
        }
        let mut m = Models::shipped();
        m.paper.0[0].classifier.h1_span = MAX_THRESHOLD;
        assert_eq!(load_text(&serde_json::to_string(&m).unwrap()).unwrap(), m);
    }

    #[test]
    fn a_crossing_share_outside_0_to_1_is_refused() {
        let mut m = Models::shipped();
        m.embedded.0[0].classifier.h1_crossing = Some(1.5);
        let err = load_text(&serde_json::to_string(&m).unwrap())
            .unwrap_err()
            .to_string();
        assert!(err.contains("h1_crossing is 1.5"), "{err}");
        m.embedded.0[0].classifier.h1_crossing = Some(0.04);
        assert_eq!(load_text(&serde_json::to_string(&m).unwrap()).unwrap(), m);
    }

    fn load_text(text: &str) -> anyhow::Result<Models> {
        let file = tempfile::NamedTempFile::new().unwrap();
        std::fs::write(file.path(), text).unwrap();
        Models::load(file.path())
    }

    #[test]
    fn a_list_of_models_must_say_where_each_was_fitted() {
        let mut m = Models::shipped();
        m.embedded = Bank(vec![model(2.0, Some([2.8, 3.4, 4.2])), model(3.0, None)]);
        let err = load_text(&serde_json::to_string(&m).unwrap())
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("Embedded") && err.contains("events_per_point"),
            "{err}"
        );
        m.embedded = Bank(vec![model(2.0, Some([4.2, 3.4, 2.8]))]);
        let err = load_text(&serde_json::to_string(&m).unwrap())
            .unwrap_err()
            .to_string();
        assert!(err.contains("min ≤ median ≤ max"), "{err}");
        m.embedded = Bank(Vec::new());
        let err = load_text(&serde_json::to_string(&m).unwrap())
            .unwrap_err()
            .to_string();
        assert!(err.contains("empty list"), "{err}");
        m.embedded = Bank(vec![
            model(2.0, Some([2.8, 3.4, 4.2])),
            model(3.0, Some([5.5, 6.8, 8.3])),
        ]);
        let back = load_text(&serde_json::to_string(&m).unwrap()).unwrap();
        assert_eq!(back, m);
        // Density picks among the models of one sweep only: a density-free model of
        // another sweep may stand beside them.
        m.embedded
            .0
            .push(swept(4.0, [1.0, 1.0, 1.0], Some(0.00125)));
        m.embedded.0[2].events_per_point = None;
        let back = load_text(&serde_json::to_string(&m).unwrap()).unwrap();
        assert_eq!(back, m);
        m.embedded.0[2].leader_speed = Some(0.0);
        let err = load_text(&serde_json::to_string(&m).unwrap())
            .unwrap_err()
            .to_string();
        assert!(err.contains("leader_speed is 0"), "{err}");
    }

    /// A fault inside a bank's list is reported at its own line, with what was expected
    /// there (an untagged enum would report the entry's end and "did not match any variant").
    #[test]
    fn a_fault_inside_a_bank_keeps_its_place() {
        let text = "{\n\"Paper\": [\n  {\"classifier\": 1}\n]\n}";
        let e = serde_json::from_str::<Models>(text).unwrap_err();
        assert_eq!(e.line(), 3, "{e}");
        assert!(e.to_string().contains("invalid type: integer `1`"), "{e}");
        let e = serde_json::from_str::<Models>("{\"Paper\": 7}").unwrap_err();
        assert!(
            e.to_string()
                .contains("a model object or a list of model objects"),
            "{e}"
        );
    }

    /// A window is too sparse for a model below its training windows' least density over
    /// the margin, and never for a model without a recorded density.
    #[test]
    fn too_sparse_is_below_the_least_density_over_the_margin() {
        let mut model = Models::shipped().embedded.first().clone();
        let d = model
            .events_per_point
            .expect("the shipped Embedded model records its density");
        let bank = Bank(vec![model.clone()]);
        assert_eq!(bank.too_sparse_for(d.min / DENSITY_MARGIN * 0.99), Some(d));
        assert_eq!(bank.too_sparse_for(d.min / DENSITY_MARGIN * 1.01), None);
        assert_eq!(bank.too_sparse_for(d.max * 10.0), None);
        model.events_per_point = None;
        assert_eq!(Bank(vec![model]).too_sparse_for(1e-3), None);
    }

    /// A model out of range is reported just after it, in a list or alone, and the message
    /// gives the place once (found by the fortieth session's review: it named only the file).
    #[test]
    fn a_model_out_of_range_is_reported_at_its_place() {
        let model = |ratio: f64, median: f64| {
            format!(
                "{{\"classifier\": {{\"h0_ratio\": 1, \"h1_ratio\": {ratio}, \"h1_span\": 0}}, \
                 \"fitted_on\": \"x\", \"events_per_point\": {{\"min\": 1, \"median\": {median}, \
                 \"max\": 9}}}}"
            )
        };
        let file = |second: f64, embedded: f64| {
            format!(
                "{{\n\"Paper\": [\n{},\n{}\n],\n\"Embedded\": {},\n\"Oracle\": {}\n}}",
                model(2.0, 2.0),
                model(second, 5.0),
                model(embedded, 2.0),
                model(2.0, 2.0)
            )
        };
        // The second model of the Paper list (line 4) is out of range.
        let err = load_text(&file(0.5, 2.0)).unwrap_err().to_string();
        assert!(
            err.contains(":4:")
                && err.contains("the Paper model's thresholds (h0_ratio 1, h1_ratio 0.5"),
            "{err}"
        );
        assert!(!err.contains("at line"), "{err}");
        // The Embedded entry, a model alone (line 6), is out of range.
        let err = load_text(&file(2.0, 0.25)).unwrap_err().to_string();
        assert!(
            err.contains(":6:") && err.contains("the Embedded model's"),
            "{err}"
        );
        let text = file(2.0, 2.0);
        assert!(load_text(&text).is_ok());
    }
}
