//! Vietoris–Rips persistent homology in dimensions 0 and 1 over Z/2 (issue #3 §1; paper
//! §"Background" and §"Topological Feature Extraction": the bars of the encounter point
//! cloud are the holes of the environment).
//!
//! The algorithm is of the Ripser class (U. Bauer, "Ripser: efficient computation of
//! Vietoris–Rips persistence barcodes", J. Appl. Comput. Topol. 5, 2021): persistent
//! *cohomology* with clearing, an implicit coboundary over simplices named by the
//! combinatorial number system, apparent and emergent pairs, the enclosing radius as the
//! default threshold and union–find-equivalent spanning trees for H0. `engine.rs` documents
//! the stages and their cost, `cycles.rs` the representative cycles of H1 bars, `tight.rs`
//! the tight loop round a hole that maps draw ([`tighten_cycle`]).
//!
//! In short, for `n` points: `O(n²)` time for H0, and for H1 `O(n²)` vertex probes on
//! generic inputs plus the reduction of the few edges not in an apparent pair; memory
//! `2n²` bytes (an apex table of one `u32` per edge) plus `8n²` for a distance-matrix
//! input. Two- and three-dimensional point clouds need no distance matrix at all.
//!
//! ```
//! use swarmmap::topology::PointCloud;
//! use swarmmap::topology::rips::{rips_points, RipsOptions};
//! // Four corners of a unit square: one hole, born at 1 and filled at √2.
//! let p = PointCloud::from_rows(&[[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]).unwrap();
//! let d = rips_points(&p, &RipsOptions::default());
//! let h1: Vec<_> = d.dim(1).collect();
//! assert_eq!(h1.len(), 1);
//! assert_eq!((h1[0].birth, h1[0].death), (1.0, 2f64.sqrt()));
//! assert_eq!(d.betti_at(0, 0.5), 4);
//! ```

mod column;
mod cycles;
mod diagram;
mod engine;
mod metric;
mod params;
mod tight;

pub use diagram::{Bar, Diagram};
pub(crate) use params::written;
pub use params::{RipsError, RipsOptions};
pub use tight::tighten_cycle;

use crate::topology::{DistanceMatrix, PointCloud};
use metric::{Full, Metric, Points};

/// The persistence diagram of the Vietoris–Rips filtration of Euclidean point distances.
///
/// Options are used as given: `maxdim > 1` is treated as 1, a NaN threshold as none, a
/// negative one as "no edges". Use [`RipsOptions::check`] to reject such values instead.
pub fn rips_points(points: &PointCloud, opts: &RipsOptions) -> Diagram {
    match points.dim() {
        2 => run(&Points::<2>::new(points).expect("dimension checked"), opts),
        3 => run(&Points::<3>::new(points).expect("dimension checked"), opts),
        _ => run(&Full::squared_from_points(points), opts),
    }
}

/// The persistence diagram of the Vietoris–Rips filtration of a distance matrix (any
/// symmetric non-negative dissimilarity; the triangle inequality is not needed).
pub fn rips_matrix(d: &DistanceMatrix, opts: &RipsOptions) -> Diagram {
    run(&Full::from_matrix(d), opts)
}

fn run<M: Metric>(m: &M, opts: &RipsOptions) -> Diagram {
    let work = || diagram(m, opts);
    if opts.threads == 0 {
        return work();
    }
    match rayon::ThreadPoolBuilder::new()
        .num_threads(opts.threads)
        .build()
    {
        Ok(pool) => pool.install(work),
        Err(_) => work(),
    }
}

fn diagram<M: Metric>(m: &M, opts: &RipsOptions) -> Diagram {
    if m.len() == 0 {
        return Diagram::default();
    }
    let t = match opts.threshold {
        Some(t) if t < 0.0 => -1.0,
        Some(t) if t >= 0.0 => m.threshold_value(t),
        _ => engine::enclosing(m),
    };
    let raw = engine::compute(m, t, opts.maxdim >= 1);
    let mut bars = Vec::with_capacity(raw.tree.len() + raw.components + raw.pairs.len());
    let bar = |dim, birth, death| Bar {
        dim,
        birth,
        death,
        cycle: None,
        death_triangle: None,
    };
    bars.extend(
        raw.tree
            .iter()
            .map(|e| bar(0, 0.0, m.to_distance(e.value()))),
    );
    bars.extend((0..raw.components).map(|_| bar(0, 0.0, f64::INFINITY)));
    let mut reps = if opts.cycles && opts.maxdim >= 1 {
        cycles::representatives(m, &raw)
    } else {
        Default::default()
    };
    for p in &raw.pairs {
        let birth = m.to_distance(p.birth.value());
        let death = p.death.map_or(f64::INFINITY, |t| m.to_distance(t.value()));
        if death <= birth {
            continue;
        }
        let mut b = bar(1, birth, death);
        b.death_triangle = p.death.map(|t| {
            let mut v = [t.a as usize, t.b as usize, t.c as usize];
            v.sort_unstable();
            v
        });
        if opts.cycles {
            b.cycle = reps.remove(&p.birth).map(|c| {
                let mut c: Vec<_> = c.iter().map(|e| (e.b as usize, e.a as usize)).collect();
                c.sort_unstable();
                c
            });
        }
        bars.push(b);
    }
    Diagram::new(bars)
}
