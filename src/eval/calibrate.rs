//! Fitting the robust-feature classifier (`swarmmap calibrate`; paper §"Topological
//! Feature Extraction", which classifies features "using statistical learning techniques").
//!
//! Training data: for every window of every training run, the persistence diagram of each
//! real component with its sampling scale, and the window's true (β0, β1). The model has
//! three thresholds (see [`crate::mapping::classify`]); we fit them by exhaustive search over
//! a grid, maximising the share of windows whose (β0, β1) both equal the truth, and break ties
//! towards the middle of the best plateau, which keeps the margin to either failure mode
//! (missing a hole, inventing one) as wide as the data allow. With three parameters and
//! thousands of windows, a grid is exact enough and cannot get stuck.
//!
//! The middle is taken in grid order (ratio, then span). When the best plateau falls into
//! separate pieces, that order, not a criterion, picks the piece: on the shipped pipeline's
//! training windows the best H1 score is reached both by death / birth ≥ 3.4 with any life
//! up to 3 σ and by a life of ≥ 3.75 σ with any ratio up to 1.5, and the middle of the 19
//! tied points lies on the first (docs/accuracy.md, step 23; `swarmmap calibrate
//! --landscape` writes the grid).
//!
//! With `--crossing` ([`FitOptions::crossing`]) the H1 grid also runs over a largest crossing
//! share ([`crate::mapping::crossing`]): no test, then 24 values (`h1_crossings`), each
//! with the lives from [`crate::mapping::crossing::CROSSING_MIN_SPAN`] σ. A crossing test is
//! kept only when it scores more than every rule without one, so on a tie the fit is the
//! plain one; otherwise the middle of the shares that reach the top is taken, then the
//! middle in (ratio, span) within it. The grid is scored column by column (one crossing
//! test and ratio, all spans at once, `Prepared::column`): a bar that passes at some span
//! passes at every smaller one.
//!
//! The two failure modes do not cost the same: a map that invents a hole in an empty room
//! misleads, and the acceptance target asks that an empty arena show no hole in ≥ 95 % of
//! windows. So the H1 search is constrained: among the training windows whose truth has no
//! hole, at most `max_false_holes` (default 2 %, a margin under the 5 % target for the gap
//! between training and unseen worlds) may show one; accuracy is maximised under that
//! constraint. Unconstrained (`1.0`), the Embedded model reached 80.9 % of the training
//! windows but false holes in 4.1 % of the hole-free ones there (`swarmmap calibrate --seeds 1..5
//! --max-false-holes 1`) and in 8.8 % of the evaluation's empty-arena windows.

use crate::mapping::classify::{Classifier, Feature, sampling_scale};
use crate::mapping::local::LocalMap;
use serde::Serialize;

/// One training window: its components' diagrams and its truth.
#[derive(Debug, Clone)]
pub struct Sample {
    /// Per component: its features.
    pub components: Vec<Vec<Feature>>,
    pub truth: [usize; 2],
}

impl Sample {
    /// The training sample of a local map with known truth.
    pub fn from_map(map: &LocalMap, truth: [usize; 2]) -> Self {
        Self {
            components: map
                .components
                .iter()
                .map(|c| {
                    c.diagram
                        .iter()
                        .map(|b| Feature {
                            crossing: b.crossing,
                            stability: b.stability,
                            ..Feature::bar(b.dim, b.birth, b.death.unwrap_or(f64::INFINITY))
                        })
                        .collect()
                })
                .collect(),
            truth,
        }
    }

    fn betti(&self, c: &Classifier) -> [usize; 2] {
        self.components.iter().fold([0, 0], |acc, f| {
            let b = c.betti(f);
            [acc[0] + b[0], acc[1] + b[1]]
        })
    }
}

/// The result of a fit.
#[derive(Debug, Clone, Serialize)]
pub struct Fit {
    pub classifier: Classifier,
    /// Share of training windows with both Betti numbers right.
    pub accuracy: f64,
    /// Share with β0 right, and with β1 right.
    pub b0_accuracy: f64,
    pub b1_accuracy: f64,
    pub windows: usize,
    /// Share of the training windows without a hole in which the fitted model reports one.
    pub false_holes: f64,
}

/// Default of [`FitOptions::max_false_holes`].
pub const MAX_FALSE_HOLES: f64 = 0.02;

/// What [`fit`] searches.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FitOptions {
    /// The largest share of the hole-free training windows that may show a hole (module
    /// docs; default [`MAX_FALSE_HOLES`]).
    pub max_false_holes: f64,
    /// Also search a largest crossing share (`h1_crossings`; `calibrate --crossing`).
    /// Off by default: on the training worlds it gains 4 of 450 windows and carries worse
    /// to unseen ones (docs/accuracy.md, step 37).
    pub crossing: bool,
    /// Also search a least split stability (`h1_stabilities`; `calibrate --stability`).
    /// The training windows' bars need stabilities: map them with
    /// `mapping.split_stability` (docs/accuracy.md, step 39).
    pub stability: bool,
}

impl FitOptions {
    /// The persistence-only search under a false-hole cap.
    pub fn cap(max_false_holes: f64) -> Self {
        Self {
            max_false_holes,
            crossing: false,
            stability: false,
        }
    }
}

/// The grid of each threshold, its points rounded to 10⁻⁹ so that the model file reads
/// `3.8`, not `3.8000000000000003`.
fn grid(lo: f64, hi: f64, step: f64) -> Vec<f64> {
    let n = ((hi - lo) / step).round() as usize;
    (0..=n)
        .map(|k| ((lo + k as f64 * step) * 1e9).round() / 1e9)
        .collect()
}

/// The H1 grid of [`fit`]: death / birth from 1 to 8 in steps of 0.1.
fn h1_ratios() -> Vec<f64> {
    grid(1.0, 8.0, 0.1)
}

/// The H1 grid of [`fit`]: a life of 0 to 20 σ in steps of 0.25 σ.
fn h1_spans() -> Vec<f64> {
    grid(0.0, 20.0, 0.25)
}

/// The H1 grid of [`fit`]: no crossing test, then a largest crossing share
/// ([`crate::mapping::crossing`]) of 0.01 to 0.1 in steps of 0.005 and 0.12 to 0.2 in steps
/// of 0.02. With a share, the life grid starts at [`crate::mapping::crossing::CROSSING_MIN_SPAN`]
/// σ, above [`crate::mapping::crossing::CROSSING_FLOOR`]: a bar below the floor has no
/// share, so it would pass any share.
fn h1_crossings() -> Vec<Option<f64>> {
    std::iter::once(None)
        .chain(grid(0.01, 0.1, 0.005).into_iter().map(Some))
        .chain(grid(0.12, 0.2, 0.02).into_iter().map(Some))
        .collect()
}

/// The H1 grid of [`fit`]: no stability test, then a least split stability
/// ([`crate::mapping::stability`]) of 0.5 to 8 in steps of 0.25 (lives in σ of the halves).
/// With a stability, the life grid starts at [`crate::mapping::crossing::CROSSING_MIN_SPAN`]
/// σ, as with a crossing share and for the same reason.
fn h1_stabilities() -> Vec<Option<f64>> {
    std::iter::once(None)
        .chain(grid(0.5, 8.0, 0.25).into_iter().map(Some))
        .collect()
}

/// The tests beyond persistence of an H1 rule: its largest crossing share and its least
/// split stability (`None`: no such test).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Gates {
    crossing: Option<f64>,
    stability: Option<f64>,
}

impl Gates {
    fn any(&self) -> bool {
        self.crossing.is_some() || self.stability.is_some()
    }
}

/// The columns of [`fit`]'s H1 grid, in grid order (crossing, then stability, then ratio);
/// each column runs over its spans ([`Prepared::column`]).
fn h1_columns(options: FitOptions) -> Vec<(Gates, f64)> {
    let stabilities: Vec<Option<f64>> = h1_stabilities()
        .into_iter()
        .filter(|s| options.stability || s.is_none())
        .collect();
    h1_crossings()
        .into_iter()
        .filter(|c| options.crossing || c.is_none())
        .flat_map(|crossing| {
            stabilities.iter().map(move |&stability| Gates {
                crossing,
                stability,
            })
        })
        .flat_map(|g| h1_ratios().into_iter().map(move |r| (g, r)))
        .collect()
}

/// The spans of a column: all of [`h1_spans`], or, with a crossing or stability test,
/// those from [`crate::mapping::crossing::CROSSING_MIN_SPAN`].
fn column_spans(gates: Gates) -> Vec<f64> {
    let floor = crate::mapping::crossing::CROSSING_MIN_SPAN;
    h1_spans()
        .into_iter()
        .filter(|&s| !gates.any() || s >= floor)
        .collect()
}

/// The training windows with each component's sampling scale computed and its features
/// split by dimension once: the grid search judges every sample at every grid point.
struct Prepared<'a> {
    samples: &'a [Sample],
    scaled: Vec<Vec<(f64, [Vec<Feature>; 2])>>,
    /// Per sample and component: its H1 features with a life of at least
    /// [`crate::mapping::crossing::CROSSING_MIN_SPAN`] σ, the only ones a rule with a
    /// crossing or stability test can keep (the same expression as [`Classifier::robust`]
    /// at that span).
    long: Vec<Vec<Vec<Feature>>>,
    /// Indices of the samples whose truth has no hole.
    holeless: Vec<usize>,
}

impl<'a> Prepared<'a> {
    fn new(samples: &'a [Sample]) -> Self {
        let scaled: Vec<Vec<(f64, [Vec<Feature>; 2])>> = samples
            .iter()
            .map(|s| {
                s.components
                    .iter()
                    .map(|f| {
                        let by_dim = |d: usize| f.iter().filter(|x| x.dim == d).copied().collect();
                        (sampling_scale(f), [by_dim(0), by_dim(1)])
                    })
                    .collect()
            })
            .collect();
        let floor = crate::mapping::crossing::CROSSING_MIN_SPAN;
        let long = scaled
            .iter()
            .map(|comps| {
                comps
                    .iter()
                    .map(|(sigma, fs)| {
                        fs[1]
                            .iter()
                            .filter(|f| f.death - f.birth >= floor * sigma)
                            .copied()
                            .collect()
                    })
                    .collect()
            })
            .collect();
        let holeless = (0..samples.len())
            .filter(|&k| samples[k].truth[1] == 0)
            .collect();
        Self {
            samples,
            scaled,
            long,
            holeless,
        }
    }

    /// Samples whose Betti number of dimension `dim` under `pick` equals the truth.
    fn count(&self, pick: &dyn Fn(&Feature, f64) -> bool, dim: usize) -> usize {
        self.samples
            .iter()
            .zip(&self.scaled)
            .filter(|(s, comps)| {
                let b: usize = comps
                    .iter()
                    .map(|(sigma, fs)| fs[dim].iter().filter(|f| pick(f, *sigma)).count())
                    .sum();
                b == s.truth[dim]
            })
            .count()
    }

    /// One column of the H1 grid: for the rules with these gates and ratio and each
    /// of `spans` (ascending), the samples whose β1 equals the truth and the hole-free
    /// samples that show a hole, as judging every sample with [`Classifier::robust`] would.
    /// A bar passing at some span passes at every smaller one, so each bar is placed once
    /// by bisection on the rule itself: O(bars · log spans + samples · spans), not
    /// O(bars · spans).
    fn column(&self, gates: Gates, ratio: f64, spans: &[f64]) -> Vec<(usize, usize)> {
        let rule = |h1_span: f64| Classifier {
            h0_ratio: 0.0,
            h1_ratio: ratio,
            h1_span,
            h1_crossing: gates.crossing,
            h1_stability: gates.stability,
        };
        let rules: Vec<Classifier> = spans.iter().map(|&s| rule(s)).collect();
        let mut out = vec![(0, 0); spans.len()];
        let mut passing = vec![0usize; spans.len() + 1];
        for (k, s) in self.samples.iter().enumerate() {
            passing.iter_mut().for_each(|p| *p = 0);
            for (c, (sigma, fs)) in self.scaled[k].iter().enumerate() {
                let bars = if gates.any() {
                    &self.long[k][c]
                } else {
                    &fs[1]
                };
                for f in bars {
                    // The number of leading spans at which `f` passes.
                    let n = rules.partition_point(|r| r.robust(f, *sigma));
                    passing[n] += 1;
                }
            }
            // β1 at span i: the bars passing at more than i spans.
            let mut b1 = 0;
            for i in (0..spans.len()).rev() {
                b1 += passing[i + 1];
                out[i].0 += usize::from(b1 == s.truth[1]);
                out[i].1 += usize::from(s.truth[1] == 0 && b1 > 0);
            }
        }
        out
    }

    /// Hole-free samples in which `c` shows a hole.
    fn false_holes(&self, c: &Classifier) -> usize {
        self.holeless
            .iter()
            .filter(|&&k| {
                self.scaled[k]
                    .iter()
                    .any(|(sigma, fs)| fs[1].iter().any(|f| c.robust(f, *sigma)))
            })
            .count()
    }

    /// Share of the hole-free samples in which `c` shows a hole (0 if there are none).
    fn false_share(&self, c: &Classifier) -> f64 {
        if self.holeless.is_empty() {
            return 0.0;
        }
        self.false_holes(c) as f64 / self.holeless.len() as f64
    }
}

/// One point of the H1 grid that [`fit`] searches, with what it scores on the training
/// windows (`swarmmap calibrate --landscape`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct LandscapePoint {
    pub h1_ratio: f64,
    pub h1_span: f64,
    /// The largest crossing share, or `None`: no crossing test.
    pub h1_crossing: Option<f64>,
    /// The least split stability, or `None`: no stability test.
    pub h1_stability: Option<f64>,
    /// Training windows whose β1 this rule gets right.
    pub b1_right: usize,
    /// Hole-free training windows in which it shows a hole.
    pub false_holes: usize,
    /// Their share of the hole-free training windows (0 if there are none), the quantity
    /// [`fit`]'s cap bounds.
    pub false_share: f64,
}

/// Every point of [`fit`]'s H1 grid with its score, in grid order (ratio, then span; with
/// `options.crossing` / `options.stability`, the rules without such a test first, then
/// those of each share and stability): the landscape the fit maximises over, to see
/// whether its optimum is a broad plateau or one of several near-equal peaks.
pub fn h1_landscape(samples: &[Sample], options: FitOptions) -> Vec<LandscapePoint> {
    use rayon::prelude::*;
    let prepared = Prepared::new(samples);
    let holeless = prepared.holeless.len();
    h1_columns(options)
        .par_iter()
        .flat_map_iter(|&(gates, h1_ratio)| {
            let spans = column_spans(gates);
            let scores = prepared.column(gates, h1_ratio, &spans);
            spans
                .into_iter()
                .zip(scores)
                .map(move |(h1_span, (b1_right, false_holes))| LandscapePoint {
                    h1_ratio,
                    h1_span,
                    h1_crossing: gates.crossing,
                    h1_stability: gates.stability,
                    b1_right,
                    false_holes,
                    false_share: if holeless == 0 {
                        0.0
                    } else {
                        false_holes as f64 / holeless as f64
                    },
                })
        })
        .collect()
}

/// Fits the three thresholds on `samples`. β0 and β1 are decided by disjoint parameters
/// (`h0_ratio`; `h1_ratio` and `h1_span`), so they are fitted separately and combined; the
/// reported accuracy is that of the combination. The H1 thresholds are searched only where at
/// most `max_false_holes` of the windows without a true hole show one (see the module docs);
/// `None` if no sample is given or no grid point meets the constraint.
pub fn fit(samples: &[Sample], options: FitOptions) -> Option<Fit> {
    let max_false_holes = options.max_false_holes;
    if samples.is_empty() {
        return None;
    }
    let prepared = Prepared::new(samples);
    let count = |pick: &dyn Fn(&Feature, f64) -> bool, dim: usize| prepared.count(pick, dim);
    let base = Classifier {
        h0_ratio: 0.0,
        h1_ratio: 0.0,
        h1_span: 0.0,
        h1_crossing: None,
        h1_stability: None,
    };
    let best_middle = |scores: Vec<(Vec<f64>, usize)>| -> Vec<f64> {
        let top = scores.iter().map(|s| s.1).max().unwrap_or(0);
        let winners: Vec<&Vec<f64>> = scores.iter().filter(|s| s.1 == top).map(|s| &s.0).collect();
        winners[winners.len() / 2].clone()
    };
    let h0: Vec<(Vec<f64>, usize)> = grid(1.0, 100.0, 0.25)
        .into_iter()
        .map(|r| {
            let c = Classifier {
                h0_ratio: r,
                ..base
            };
            (vec![r], count(&|f, s| c.robust(f, s), 0))
        })
        .collect();
    let h0_ratio = best_middle(h0)[0];
    let false_share = |c: &Classifier| prepared.false_share(c);
    let h1: Vec<(Classifier, usize)> = h1_landscape(samples, options)
        .into_iter()
        .filter(|p| p.false_share <= max_false_holes + 1e-12)
        .map(|p| {
            let c = Classifier {
                h1_ratio: p.h1_ratio,
                h1_span: p.h1_span,
                h1_crossing: p.h1_crossing,
                h1_stability: p.h1_stability,
                ..base
            };
            (c, p.b1_right)
        })
        .collect();
    let top = h1.iter().map(|s| s.1).max()?;
    let winners: Vec<&Classifier> = h1.iter().filter(|s| s.1 == top).map(|s| &s.0).collect();
    // A crossing or stability test only where it scores more than none (then the old
    // fit, unchanged); else the middle of the gates (crossing share, then stability, in
    // grid order) that reach the top, and within them the middle in (ratio, span) order.
    let gates = |c: &Classifier| Gates {
        crossing: c.h1_crossing,
        stability: c.h1_stability,
    };
    let plain: Vec<&Classifier> = winners
        .iter()
        .copied()
        .filter(|c| !gates(c).any())
        .collect();
    let best = if plain.is_empty() {
        let mut values: Vec<Gates> = winners.iter().map(|c| gates(c)).collect();
        values.dedup();
        let x = values[values.len() / 2];
        let at: Vec<&Classifier> = winners.iter().copied().filter(|c| gates(c) == x).collect();
        at[at.len() / 2]
    } else {
        plain[plain.len() / 2]
    };
    let classifier = Classifier { h0_ratio, ..*best };
    let n = samples.len() as f64;
    let (mut ok, mut ok0, mut ok1) = (0, 0, 0);
    for s in samples {
        let b = s.betti(&classifier);
        ok += usize::from(b == s.truth);
        ok0 += usize::from(b[0] == s.truth[0]);
        ok1 += usize::from(b[1] == s.truth[1]);
    }
    Some(Fit {
        classifier,
        accuracy: ok as f64 / n,
        b0_accuracy: ok0 as f64 / n,
        b1_accuracy: ok1 as f64 / n,
        windows: samples.len(),
        false_holes: false_share(&classifier),
    })
}

/// One fold of a cross-validation: the model fitted without one group of training windows,
/// judged on that group.
#[derive(Debug, Clone, Serialize)]
pub struct Fold {
    /// The group held out (a seed or a world).
    pub held_out: String,
    /// The model fitted on the other groups.
    pub classifier: Classifier,
    /// Held-out windows, and how many of them the model gets right (both Betti numbers).
    pub windows: usize,
    pub right: usize,
    /// Held-out windows without a true hole, and in how many of them the model shows one.
    pub holeless: usize,
    pub false_holes: usize,
}

/// Held-out estimates of a fit's accuracy ([`cross_validate`]).
#[derive(Debug, Clone, Serialize)]
pub struct CrossValidation {
    pub folds: Vec<Fold>,
    /// Share of all windows right when each is judged by the model fitted without its group.
    pub accuracy: f64,
    /// Share of the hole-free windows in which that model shows a hole.
    pub false_holes: f64,
    pub windows: usize,
    pub holeless: usize,
}

/// Leave-one-group-out cross-validation of [`fit`]: for every group (in order of first
/// appearance in `groups`, one label per sample), fit on the samples of the other groups
/// under the same false-hole cap and judge the held-out samples. Grouping by seed says how
/// well the thresholds carry to new runs of the same worlds; grouping by world, to layouts
/// the fit has never seen (the position of the evaluation scenarios). In-sample accuracy
/// overstates both: the grid search picks the thresholds that suit its own windows.
///
/// Errors if there are fewer than two groups, or if some fold has no classifier within the
/// cap.
pub fn cross_validate(
    samples: &[Sample],
    groups: &[String],
    options: FitOptions,
) -> Result<CrossValidation, String> {
    let max_false_holes = options.max_false_holes;
    assert_eq!(samples.len(), groups.len(), "one group label per sample");
    let mut labels: Vec<&String> = Vec::new();
    for g in groups {
        if !labels.contains(&g) {
            labels.push(g);
        }
    }
    if labels.len() < 2 {
        return Err(format!(
            "cross-validation needs at least two groups of training windows, got {}",
            labels.len()
        ));
    }
    let mut folds = Vec::with_capacity(labels.len());
    for label in labels {
        let in_fold = |k: &usize| groups[*k] == *label;
        let held: Vec<&Sample> = (0..samples.len())
            .filter(in_fold)
            .map(|k| &samples[k])
            .collect();
        let train: Vec<Sample> = (0..samples.len())
            .filter(|k| !in_fold(k))
            .map(|k| samples[k].clone())
            .collect();
        let f = fit(&train, options).ok_or_else(|| {
            format!(
                "without {label}, no classifier shows false holes in at most {max_false_holes} \
                 of the training windows without a hole"
            )
        })?;
        let mut fold = Fold {
            held_out: label.clone(),
            classifier: f.classifier,
            windows: held.len(),
            right: 0,
            holeless: 0,
            false_holes: 0,
        };
        for s in held {
            let b = s.betti(&f.classifier);
            fold.right += usize::from(b == s.truth);
            if s.truth[1] == 0 {
                fold.holeless += 1;
                fold.false_holes += usize::from(b[1] > 0);
            }
        }
        folds.push(fold);
    }
    let windows: usize = folds.iter().map(|f| f.windows).sum();
    let holeless: usize = folds.iter().map(|f| f.holeless).sum();
    let right: usize = folds.iter().map(|f| f.right).sum();
    let shown: usize = folds.iter().map(|f| f.false_holes).sum();
    Ok(CrossValidation {
        accuracy: right as f64 / windows as f64,
        false_holes: if holeless == 0 {
            0.0
        } else {
            shown as f64 / holeless as f64
        },
        windows,
        holeless,
        folds,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn f(dim: usize, birth: f64, death: f64) -> Feature {
        Feature::bar(dim, birth, death)
    }

    /// Windows whose real holes have ratio 4 and noise ratio ≤ 2: the fit must separate them.
    #[test]
    fn fit_separates_signal_from_noise() {
        let noise = |k: f64| {
            let mut v: Vec<Feature> = (0..20).map(|i| f(0, 0.0, 1.0 + 0.01 * i as f64)).collect();
            v.push(f(0, 0.0, f64::INFINITY));
            v.push(f(1, 1.0, 1.5 + 0.1 * k));
            v.push(f(1, 2.0, 3.0));
            v
        };
        let mut samples = Vec::new();
        for k in 0..5 {
            let mut with_hole = noise(k as f64);
            with_hole.push(f(1, 1.0, 4.0 + k as f64));
            samples.push(Sample {
                components: vec![with_hole],
                truth: [1, 1],
            });
            samples.push(Sample {
                components: vec![noise(k as f64)],
                truth: [1, 0],
            });
        }
        let fit = fit(&samples, FitOptions::cap(1.0)).unwrap();
        assert_eq!(fit.accuracy, 1.0, "{fit:?}");
        assert_eq!(fit.false_holes, 0.0);
        assert!(fit.classifier.h1_ratio > 2.0 && fit.classifier.h1_ratio <= 4.0);
    }

    /// Every point of `land` scores what judging each of `samples` with its rule gives.
    fn scores_like_the_rule(samples: &[Sample], land: &[LandscapePoint]) {
        let holeless: Vec<&Sample> = samples.iter().filter(|s| s.truth[1] == 0).collect();
        for p in land {
            let c = Classifier {
                h0_ratio: 1e9,
                h1_ratio: p.h1_ratio,
                h1_span: p.h1_span,
                h1_crossing: p.h1_crossing,
                h1_stability: p.h1_stability,
            };
            let right = samples
                .iter()
                .filter(|s| s.betti(&c)[1] == s.truth[1])
                .count();
            let shown = holeless.iter().filter(|s| s.betti(&c)[1] > 0).count();
            assert_eq!(p.b1_right, right, "{p:?}");
            assert_eq!(p.false_holes, shown, "{p:?}");
            assert_eq!(p.false_share, shown as f64 / holeless.len() as f64, "{p:?}");
        }
    }

    /// The landscape scores every grid point as judging each window one by one would, and
    /// the fit's thresholds lie on its best point within the cap.
    #[test]
    fn the_landscape_is_the_grid_the_fit_maximises_over() {
        let mut samples = Vec::new();
        for k in 0..6 {
            let mut v: Vec<Feature> = (0..20).map(|i| f(0, 0.0, 1.0 + 0.01 * i as f64)).collect();
            v.push(f(0, 0.0, f64::INFINITY));
            v.push(f(1, 1.0, 1.5 + 0.4 * k as f64));
            let hole = k % 2 == 0;
            if hole {
                v.push(f(1, 0.5, 2.0 + 0.5 * k as f64));
            }
            samples.push(Sample {
                components: vec![v],
                truth: [1, usize::from(hole)],
            });
        }
        let plain = FitOptions::cap(1.0);
        let land = h1_landscape(&samples, plain);
        assert_eq!(land.len(), h1_ratios().len() * h1_spans().len());
        let gates = |crossing, stability| Gates {
            crossing,
            stability,
        };
        let with: usize = h1_crossings()
            .into_iter()
            .map(|c| h1_ratios().len() * column_spans(gates(c, None)).len())
            .sum();
        let crossing = FitOptions {
            crossing: true,
            ..plain
        };
        assert_eq!(h1_landscape(&samples, crossing).len(), with);
        let both: usize = h1_crossings()
            .into_iter()
            .flat_map(|c| h1_stabilities().into_iter().map(move |s| (c, s)))
            .map(|(c, s)| h1_ratios().len() * column_spans(gates(c, s)).len())
            .sum();
        let all = FitOptions {
            stability: true,
            ..crossing
        };
        assert_eq!(h1_landscape(&samples, all).len(), both);
        scores_like_the_rule(&samples, &land);
        for cap in [0.0, 0.34, 1.0] {
            let fit = fit(&samples, FitOptions::cap(cap)).unwrap();
            let best = land
                .iter()
                .filter(|p| p.false_share <= cap + 1e-12)
                .map(|p| p.b1_right)
                .max()
                .unwrap();
            let at = land
                .iter()
                .find(|p| {
                    p.h1_ratio == fit.classifier.h1_ratio
                        && p.h1_span == fit.classifier.h1_span
                        && p.h1_crossing == fit.classifier.h1_crossing
                })
                .unwrap();
            assert_eq!(at.b1_right, best, "cap {cap}: {fit:?}");
            assert_eq!(fit.b1_accuracy, best as f64 / samples.len() as f64);
        }
    }

    /// Twelve windows whose H1 bars have lives on both sides of 1 σ and a gate value
    /// `value(window, bar)` (or none) set on each by `gate`; every third window has a hole.
    fn gated_windows(
        gate: fn(Feature, Option<f64>) -> Feature,
        value: impl Fn(usize, usize) -> Option<f64>,
    ) -> Vec<Sample> {
        (0..12)
            .map(|k| {
                let mut v: Vec<Feature> =
                    (0..20).map(|i| f(0, 0.0, 1.0 + 0.01 * i as f64)).collect();
                v.push(f(0, 0.0, f64::INFINITY));
                v.push(gate(f(1, 1.0, 1.4 + 0.35 * k as f64), value(k, 0)));
                v.push(gate(f(1, 0.5, 0.9 + 0.02 * k as f64), value(k, 1)));
                v.push(gate(f(1, 1.0, 1.5 + 0.05 * k as f64), None));
                if k % 3 == 0 {
                    v.push(gate(f(1, 0.8, 3.0 + 0.5 * k as f64), value(k, 2)));
                }
                Sample {
                    components: vec![v],
                    truth: [1, usize::from(k % 3 == 0)],
                }
            })
            .collect()
    }

    /// With crossing shares on the bars (shares on both sides of every grid value) every
    /// point of the crossing grid scores what judging each window with
    /// `Classifier::robust` gives.
    #[test]
    fn the_crossing_landscape_scores_like_the_rule() {
        let samples = gated_windows(
            |b, crossing| Feature { crossing, ..b },
            |k, j| Some(0.004 + 0.0173 * ((k * 5 + j * 3) % 13) as f64),
        );
        let options = FitOptions {
            crossing: true,
            ..FitOptions::cap(1.0)
        };
        let land = h1_landscape(&samples, options);
        scores_like_the_rule(&samples, &land);
        let with_test = land.iter().filter(|p| p.h1_crossing.is_some()).count();
        let gated = Gates {
            crossing: Some(0.1),
            stability: None,
        };
        assert_eq!(
            with_test,
            24 * h1_ratios().len() * column_spans(gated).len()
        );
    }

    /// The same with split stabilities (on both sides of every grid value, some bars
    /// without one): every point of the stability grid scores what judging each window
    /// with `Classifier::robust` gives.
    #[test]
    fn the_stability_landscape_scores_like_the_rule() {
        let samples = gated_windows(
            |b, stability| Feature { stability, ..b },
            |k, j| Some(0.3 + 0.61 * ((k * 5 + j * 3) % 14) as f64),
        );
        let options = FitOptions {
            stability: true,
            ..FitOptions::cap(1.0)
        };
        let land = h1_landscape(&samples, options);
        scores_like_the_rule(&samples, &land);
        let gated = Gates {
            crossing: None,
            stability: Some(1.0),
        };
        let with_test = land.iter().filter(|p| p.h1_stability.is_some()).count();
        assert_eq!(
            with_test,
            31 * h1_ratios().len() * column_spans(gated).len()
        );
        assert!(land.iter().all(|p| p.h1_crossing.is_none()));
    }

    /// A hole-free window holds a noise loop (ratio 5.5) between the two real holes (ratios
    /// 5 and 6): no threshold gets all four windows right, 3 of 4 at best either way. With
    /// no false hole allowed, the fit must pick thresholds that reject the loop.
    #[test]
    fn the_false_hole_constraint_holds_on_the_training_windows() {
        let base = || -> Vec<Feature> {
            let mut v: Vec<Feature> = (0..20).map(|i| f(0, 0.0, 1.0 + 0.01 * i as f64)).collect();
            v.push(f(0, 0.0, f64::INFINITY));
            v
        };
        let with = |extra: &[Feature]| {
            let mut v = base();
            v.extend_from_slice(extra);
            v
        };
        let samples = vec![
            Sample {
                components: vec![with(&[f(1, 1.0, 6.0)])],
                truth: [1, 1],
            },
            Sample {
                components: vec![with(&[f(1, 1.0, 5.0)])],
                truth: [1, 1],
            },
            Sample {
                components: vec![with(&[f(1, 1.0, 5.5)])],
                truth: [1, 0],
            },
            Sample {
                components: vec![with(&[])],
                truth: [1, 0],
            },
        ];
        let free = fit(&samples, FitOptions::cap(1.0)).unwrap();
        assert_eq!(free.accuracy, 0.75, "{free:?}");
        // Unconstrained, the middle of the best plateau keeps the loop: the cap must bite.
        assert!(free.false_holes > 0.0, "{free:?}");
        let strict = fit(&samples, FitOptions::cap(0.0)).unwrap();
        assert_eq!(strict.false_holes, 0.0, "{strict:?}");
        // Only the 6.0 hole survives a threshold above the 5.5 loop.
        assert_eq!(strict.accuracy, 0.75, "{strict:?}");
        for s in &samples[2..] {
            assert_eq!(s.betti(&strict.classifier)[1], 0);
        }
    }
    /// Two groups whose noise and signal overlap across groups (group A: hole ratio 3,
    /// noise 2; group B: hole 5, noise 3.5). Each group alone is separable, so the in-sample
    /// fit on both gets 3 of 4 windows right; held out, each group is judged by thresholds
    /// fitted on the other: B's noise loop passes A's thresholds (a false hole) and A's hole
    /// fails B's, so exactly 2 of 4 windows are right and 1 of the 2 hole-free ones shows a
    /// hole (worked out by hand for every point of each fold's best plateau).
    #[test]
    fn cross_validation_judges_each_group_by_the_others_fit() {
        let window = |birth: f64, death: f64, truth: usize| {
            let mut v: Vec<Feature> = (0..20).map(|i| f(0, 0.0, 1.0 + 0.01 * i as f64)).collect();
            v.push(f(0, 0.0, f64::INFINITY));
            v.push(f(1, birth, death));
            Sample {
                components: vec![v],
                truth: [1, truth],
            }
        };
        let samples = vec![
            window(1.0, 3.0, 1),
            window(1.0, 2.0, 0),
            window(1.0, 5.0, 1),
            window(1.0, 3.5, 0),
        ];
        let groups: Vec<String> = ["A", "A", "B", "B"].map(String::from).to_vec();
        let all = fit(&samples, FitOptions::cap(1.0)).unwrap();
        assert_eq!(all.accuracy, 0.75, "{all:?}");
        let cv = cross_validate(&samples, &groups, FitOptions::cap(1.0)).unwrap();
        assert_eq!(cv.folds.len(), 2);
        assert_eq!(cv.folds[0].held_out, "A");
        assert_eq!(
            (cv.folds[0].right, cv.folds[0].false_holes),
            (1, 0),
            "{cv:?}"
        );
        assert_eq!(
            (cv.folds[1].right, cv.folds[1].false_holes),
            (1, 1),
            "{cv:?}"
        );
        assert_eq!((cv.accuracy, cv.false_holes), (0.5, 0.5));
        assert_eq!((cv.windows, cv.holeless), (4, 2));
    }

    /// Copies of one separable group: every fold's model separates the held-out copy too.
    #[test]
    fn cross_validation_of_consistent_groups_is_exact() {
        let window = |death: f64, truth: usize| {
            let mut v: Vec<Feature> = (0..20).map(|i| f(0, 0.0, 1.0 + 0.01 * i as f64)).collect();
            v.push(f(0, 0.0, f64::INFINITY));
            v.push(f(1, 1.0, 1.6));
            v.push(f(1, 1.0, death));
            Sample {
                components: vec![v],
                truth: [1, truth],
            }
        };
        let mut samples = Vec::new();
        let mut groups = Vec::new();
        for g in 0..3 {
            samples.push(window(6.0, 1));
            samples.push(window(1.8, 0));
            groups.extend([format!("seed {g}"), format!("seed {g}")]);
        }
        let cv = cross_validate(&samples, &groups, FitOptions::cap(0.0)).unwrap();
        assert_eq!(cv.folds.len(), 3);
        assert_eq!((cv.accuracy, cv.false_holes), (1.0, 0.0), "{cv:?}");
        let one = cross_validate(&samples[..2], &groups[..2], FitOptions::cap(0.0));
        assert!(one.unwrap_err().contains("at least two groups"));
    }

    /// Eight windows, every other one with a hole, each holding one loop of death / birth 4
    /// and a life of 3 σ, its gate value (set by `gate`) `hole` where the window has a hole
    /// and `noise` where it has none.
    fn one_loop_windows(
        gate: fn(Feature, Option<f64>) -> Feature,
        hole: Option<f64>,
        noise: Option<f64>,
    ) -> Vec<Sample> {
        (0..8)
            .map(|k| {
                let with_hole = k % 2 == 0;
                let mut v: Vec<Feature> =
                    (0..20).map(|i| f(0, 0.0, 1.0 + 0.01 * i as f64)).collect();
                v.push(f(0, 0.0, f64::INFINITY));
                v.push(gate(f(1, 1.0, 4.0), if with_hole { hole } else { noise }));
                Sample {
                    components: vec![v],
                    truth: [1, usize::from(with_hole)],
                }
            })
            .collect()
    }

    /// Real holes and noise loops with the same persistence (ratio 4, a life of 3 σ) but
    /// crossing shares of 0.01 and 0.3: no (ratio, span) rule gets more than the hole-free
    /// or the holed windows right, a crossing test gets all. The fit must take one between
    /// the two shares; without shares (the same bars, `crossing: None`) it must take none.
    #[test]
    fn a_crossing_test_is_fitted_only_where_it_separates() {
        let gate = |b, crossing| Feature { crossing, ..b };
        let samples = one_loop_windows(gate, Some(0.01), Some(0.3));
        let options = FitOptions {
            max_false_holes: 0.0,
            crossing: true,
            stability: false,
        };
        // Not asked for, no crossing test.
        assert_eq!(
            fit(&samples, FitOptions::cap(0.0))
                .unwrap()
                .classifier
                .h1_crossing,
            None
        );
        let fit = fit(&samples, options).unwrap();
        assert_eq!(fit.accuracy, 1.0, "{fit:?}");
        let max = fit.classifier.h1_crossing.expect("a crossing test");
        assert!((0.01..0.3).contains(&max), "{max}");
        // The middle of the grid's shares that separate them: all 24 do (0.01 to 0.2), and
        // the 13th is 0.07.
        assert_eq!(max, 0.07);
        // Without shares no rule separates them; the plain rule that shows no false hole
        // (cap 0) is kept, as before the crossing test existed.
        let plain = one_loop_windows(gate, None, None);
        let fit = super::fit(&plain, options).unwrap();
        assert_eq!(fit.classifier.h1_crossing, None);
        assert_eq!(fit.false_holes, 0.0);
    }

    /// Real holes and noise loops with the same persistence (ratio 4, a life of 3 σ) but
    /// stabilities of 6 and 1: only a stability test gets every window right. The fit must
    /// take one between them; without stabilities it must take none.
    #[test]
    fn a_stability_test_is_fitted_only_where_it_separates() {
        let gate = |b, stability| Feature { stability, ..b };
        let samples = one_loop_windows(gate, Some(6.0), Some(1.0));
        let options = FitOptions {
            stability: true,
            ..FitOptions::cap(0.0)
        };
        assert_eq!(
            fit(&samples, FitOptions::cap(0.0))
                .unwrap()
                .classifier
                .h1_stability,
            None
        );
        let fit = fit(&samples, options).unwrap();
        assert_eq!(fit.accuracy, 1.0, "{fit:?}");
        assert_eq!(fit.classifier.h1_crossing, None);
        // The stabilities that separate them: 1.25 to 6 (20 grid values); the middle one,
        // the 11th, is 3.75.
        assert_eq!(fit.classifier.h1_stability, Some(3.75));
        let plain = one_loop_windows(gate, None, None);
        let fit = super::fit(&plain, options).unwrap();
        assert_eq!(fit.classifier.h1_stability, None);
        assert_eq!(fit.false_holes, 0.0);
    }
}
