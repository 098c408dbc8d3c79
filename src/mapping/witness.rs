//! The lazy witness complex (de Silva & Carlsson, "Topological estimation using witness
//! complexes", SPBG 2004) on the encounter metric.
//!
//! Landmarks are the representatives; witnesses are all encounters of the component. For a
//! witness w let m_ν(w) be its distance to its ν-th nearest landmark (m_0 = 0). The edge
//! (l_1, l_2) enters at `min_w max(d(w, l_1), d(w, l_2)) − m_ν(w)`, and the complex is the
//! flag complex of those edges. With ν = 2, at scale 0 the edges are those of pairs of
//! landmarks that are some witness's two nearest: the witness complex approximates the
//! Delaunay complex of the landmarks restricted to where encounters happen, so an obstacle
//! (a region with no encounters) is a hole born at ≈ 0 even when landmarks are as sparse
//! as the obstacle is large.
//!
//! Each witness only votes for pairs among its `K` nearest landmarks (K = 12): farther
//! pairs enter later than pairs witnessed this way anyway, except across regions with no
//! witnesses at all, which are exactly the holes; those pairs enter last, at the largest
//! witnessed value. Cost O(n · m log m + n · K²) for n witnesses and m landmarks.

use crate::topology::DistanceMatrix;

/// Witness votes per witness: pairs among its `K` nearest landmarks.
const K: usize = 12;

/// Edge weights of the lazy witness complex; `rows[i][j]` is the distance from landmark
/// `i` to encounter `j`, and `witnesses` are the encounter indices used as witnesses.
pub fn lazy_witness(rows: &[Vec<f64>], witnesses: &[usize], nu: usize) -> DistanceMatrix {
    let m = rows.len();
    let mut w = DistanceMatrix::from_fn(m, |_, _| f64::INFINITY);
    let mut near: Vec<(f64, usize)> = Vec::with_capacity(m);
    for &j in witnesses {
        near.clear();
        near.extend((0..m).map(|i| (rows[i][j], i)).filter(|x| x.0.is_finite()));
        if near.len() < 2 {
            continue;
        }
        let k = K.min(near.len());
        near.select_nth_unstable_by(k - 1, |a, b| a.0.total_cmp(&b.0));
        near[..k].sort_by(|a, b| a.0.total_cmp(&b.0));
        let m_nu = if nu == 0 {
            0.0
        } else {
            near[(nu - 1).min(k - 1)].0
        };
        for a in 0..k {
            for b in a + 1..k {
                let (i, l) = (near[a].1, near[b].1);
                let v = (near[a].0.max(near[b].0) - m_nu).max(0.0);
                if v < w.get(i, l) {
                    w.set(i, l, v);
                }
            }
        }
    }
    let cap = w
        .condensed()
        .iter()
        .copied()
        .filter(|v| v.is_finite())
        .fold(0.0, f64::max);
    DistanceMatrix::from_fn(m, |a, b| {
        let v = w.get(a, b);
        if v.is_finite() { v } else { cap }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::topology::rips::{RipsOptions, rips_matrix};

    /// Eight landmarks on a ring of radius 1 and witnesses only on the ring: the witness
    /// complex sees the hole from scale 0, although the landmarks' Rips complex fills it as
    /// soon as the diameter's edges enter.
    #[test]
    fn a_ring_of_witnesses_has_a_hole() {
        let land: Vec<(f64, f64)> = (0..8)
            .map(|k| {
                let a = k as f64 * std::f64::consts::TAU / 8.0;
                (a.cos(), a.sin())
            })
            .collect();
        let wit: Vec<(f64, f64)> = (0..400)
            .map(|k| {
                let a = k as f64 * std::f64::consts::TAU / 400.0;
                (a.cos(), a.sin())
            })
            .collect();
        let rows: Vec<Vec<f64>> = land
            .iter()
            .map(|l| wit.iter().map(|w| (l.0 - w.0).hypot(l.1 - w.1)).collect())
            .collect();
        let all: Vec<usize> = (0..wit.len()).collect();
        let m = lazy_witness(&rows, &all, 2);
        let d = rips_matrix(&m, &RipsOptions::default());
        let h1: Vec<_> = d.dim(1).collect();
        assert_eq!(h1.len(), 1, "{h1:?}");
        assert!(h1[0].birth < 0.1 && h1[0].death > 0.5, "{:?}", h1[0]);
    }
}
