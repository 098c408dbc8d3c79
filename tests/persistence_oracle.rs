//! The engine against a naive oracle written here: build every vertex, edge and triangle,
//! sort them into a simplexwise filtration, reduce the full boundary matrix over Z/2
//! (Edelsbrunner–Letscher–Zomorodian column reduction), read off the pairs. Random point
//! clouds and random symmetric dissimilarities (small integers, so ties and zeros abound).
//! Representative cycles are also checked to be non-trivial at their birth and trivial at
//! their death with linear algebra over Z/2.

mod persistence_common;

use persistence_common::{assert_same, bars, check_cycle};
use proptest::prelude::*;
use swarmmap::topology::DistanceMatrix;
use swarmmap::topology::PointCloud;
use swarmmap::topology::rips::{Diagram, RipsOptions, rips_matrix, rips_points};

/// Bars `(dim, birth, death)` of the 2-skeleton filtration restricted to values ≤ `t`.
fn oracle(n: usize, d: &dyn Fn(usize, usize) -> f64, t: f64) -> Vec<Vec<(f64, f64)>> {
    // (value, dim, vertices)
    let mut s: Vec<(f64, usize, Vec<usize>)> = (0..n).map(|i| (0.0, 0, vec![i])).collect();
    for i in 0..n {
        for j in i + 1..n {
            s.push((d(i, j), 1, vec![i, j]));
            for k in j + 1..n {
                s.push((d(i, j).max(d(i, k)).max(d(j, k)), 2, vec![i, j, k]));
            }
        }
    }
    s.retain(|x| x.0 <= t);
    s.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
    let pos: std::collections::HashMap<Vec<usize>, usize> = s
        .iter()
        .enumerate()
        .map(|(k, x)| (x.2.clone(), k))
        .collect();
    let mut cols: Vec<Vec<usize>> = s
        .iter()
        .map(|x| {
            let mut c: Vec<usize> = if x.1 == 0 {
                vec![]
            } else {
                (0..x.2.len())
                    .map(|drop| {
                        let f: Vec<usize> =
                            x.2.iter()
                                .enumerate()
                                .filter(|&(q, _)| q != drop)
                                .map(|(_, &v)| v)
                                .collect();
                        pos[&f]
                    })
                    .collect()
            };
            c.sort();
            c
        })
        .collect();
    let mut low_of = std::collections::HashMap::<usize, usize>::new();
    let mut paired = vec![false; s.len()];
    let mut out = vec![vec![], vec![]];
    for j in 0..s.len() {
        while let Some(&low) = cols[j].last() {
            match low_of.get(&low) {
                Some(&k) => {
                    let other = cols[k].clone();
                    cols[j] = xor(&cols[j], &other);
                }
                None => break,
            }
        }
        if let Some(&low) = cols[j].last() {
            low_of.insert(low, j);
            paired[low] = true;
            paired[j] = true;
            let dim = s[low].1;
            if s[j].0 > s[low].0 {
                out[dim].push((s[low].0, s[j].0));
            }
        }
    }
    for (k, x) in s.iter().enumerate() {
        if !paired[k] && x.1 < 2 && cols[k].is_empty() {
            out[x.1].push((x.0, f64::INFINITY));
        }
    }
    for v in &mut out {
        v.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.total_cmp(&y.1)));
    }
    out
}

fn xor(a: &[usize], b: &[usize]) -> Vec<usize> {
    let (mut i, mut j, mut o) = (0, 0, Vec::new());
    while i < a.len() || j < b.len() {
        if j == b.len() || (i < a.len() && a[i] < b[j]) {
            o.push(a[i]);
            i += 1;
        } else if i == a.len() || b[j] < a[i] {
            o.push(b[j]);
            j += 1;
        } else {
            i += 1;
            j += 1;
        }
    }
    o
}

/// Whether the edge set `z` is a Z/2 boundary of triangles with value ≤ `s`.
fn is_boundary(n: usize, d: &dyn Fn(usize, usize) -> f64, z: &[(usize, usize)], s: f64) -> bool {
    is_boundary_of(n, z, &|i, j, k| d(i, j).max(d(i, k)).max(d(j, k)) <= s)
}

/// Whether the edge set `z` is a Z/2 boundary of the triangles `keep` admits.
fn is_boundary_of(
    n: usize,
    z: &[(usize, usize)],
    keep: &dyn Fn(usize, usize, usize) -> bool,
) -> bool {
    let eid = |i: usize, j: usize| i * n + j;
    let mut basis = std::collections::HashMap::<usize, Vec<usize>>::new(); // pivot → vector
    let reduce = |mut v: Vec<usize>, basis: &std::collections::HashMap<usize, Vec<usize>>| {
        while let Some(&p) = v.last() {
            match basis.get(&p) {
                Some(b) => v = xor(&v, b),
                None => break,
            }
        }
        v
    };
    for i in 0..n {
        for j in i + 1..n {
            for k in j + 1..n {
                if keep(i, j, k) {
                    let mut b = vec![eid(i, j), eid(i, k), eid(j, k)];
                    b.sort();
                    let r = reduce(b, &basis);
                    if let Some(&p) = r.last() {
                        basis.insert(p, r);
                    }
                }
            }
        }
    }
    let mut v: Vec<usize> = z.iter().map(|&(i, j)| eid(i, j)).collect();
    v.sort();
    reduce(v, &basis).is_empty()
}

fn compare(n: usize, d: &dyn Fn(usize, usize) -> f64, got: &Diagram, t: f64) {
    let want = oracle(n, d, t);
    for (dim, want) in want.iter().enumerate() {
        // Oracle values are exact copies of the inputs, so only exact-tie noise can differ.
        assert_same(
            &bars(got, dim),
            want,
            1e-12,
            &format!("H{dim} (n = {n}, t = {t})"),
        );
    }
    for b in got.dim(1) {
        check_cycle(b, d);
        let z = b.cycle.as_ref().unwrap();
        assert!(
            !is_boundary(n, d, z, b.birth),
            "cycle of {b:?} is a boundary at its birth"
        );
        if b.death.is_finite() {
            assert!(
                is_boundary(n, d, z, b.death),
                "cycle of {b:?} survives its death"
            );
            // The death triangle: its longest edge is the death, and (where no other
            // triangle ties with it, so the order among equal values cannot matter) the
            // triangles before it together with it make the cycle a boundary.
            let [x, y, w] = b
                .death_triangle
                .expect("a finite H1 bar has a death triangle");
            let diam = |i: usize, j: usize, k: usize| d(i, j).max(d(i, k)).max(d(j, k));
            assert!(x < y && y < w && w < n, "{b:?}");
            assert_eq!(diam(x, y, w), b.death, "{b:?}");
            let mut ties = 0;
            for i in 0..n {
                for j in i + 1..n {
                    for k in j + 1..n {
                        ties += usize::from(diam(i, j, k) == b.death);
                    }
                }
            }
            if ties == 1 {
                assert!(
                    is_boundary_of(n, z, &|i, j, k| diam(i, j, k) < b.death
                        || [i, j, k] == [x, y, w]),
                    "{b:?}: the death triangle does not kill the cycle"
                );
            }
        } else {
            assert_eq!(b.death_triangle, None);
        }
    }
}

fn opts(t: Option<f64>) -> RipsOptions {
    RipsOptions {
        maxdim: 1,
        threshold: t,
        cycles: true,
        threads: 1,
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 300, ..ProptestConfig::default() })]

    #[test]
    fn random_points_match_oracle(
        pts in prop::collection::vec((0.0f64..1.0, 0.0f64..1.0), 1..11),
        cut in 0.0f64..1.2,
        use_cut in any::<bool>(),
    ) {
        let rows: Vec<[f64; 2]> = pts.iter().map(|&(x, y)| [x, y]).collect();
        let p = PointCloud::from_rows(&rows).unwrap();
        let t = use_cut.then_some(cut);
        let got = rips_points(&p, &opts(t));
        compare(p.len(), &|i, j| p.dist(i, j), &got, t.unwrap_or(f64::INFINITY));
    }

    #[test]
    fn integer_grid_points_with_ties_match_oracle(
        pts in prop::collection::vec((0i32..4, 0i32..4, 0i32..2), 1..11),
    ) {
        let rows: Vec<[f64; 3]> = pts.iter().map(|&(x, y, z)| [x as f64, y as f64, z as f64]).collect();
        let p = PointCloud::from_rows(&rows).unwrap();
        let got = rips_points(&p, &opts(None));
        compare(p.len(), &|i, j| p.dist(i, j), &got, f64::INFINITY);
    }

    #[test]
    fn random_metrics_with_ties_match_oracle(
        n in 1usize..10,
        vals in prop::collection::vec(0u8..5, 45),
        cut in 0u8..5,
        use_cut in any::<bool>(),
    ) {
        let mut k = 0;
        let m = DistanceMatrix::from_fn(n, |_, _| { k += 1; f64::from(vals[k - 1]) });
        let t = use_cut.then_some(f64::from(cut));
        let got = rips_matrix(&m, &opts(t));
        compare(n, &|i, j| m.get(i, j), &got, t.unwrap_or(f64::INFINITY));
    }

    #[test]
    fn random_real_metrics_match_oracle(
        n in 1usize..10,
        vals in prop::collection::vec(0.0f64..1.0, 45),
    ) {
        let mut k = 0;
        let m = DistanceMatrix::from_fn(n, |_, _| { k += 1; vals[k - 1] });
        let got = rips_matrix(&m, &opts(None));
        compare(n, &|i, j| m.get(i, j), &got, f64::INFINITY);
    }
}

#[test]
fn degenerate_inputs() {
    let empty = PointCloud::new(2, vec![]).unwrap();
    assert!(rips_points(&empty, &RipsOptions::default()).bars.is_empty());
    let one = PointCloud::from_rows(&[[0.5, 0.5]]).unwrap();
    let d = rips_points(&one, &RipsOptions::default());
    assert_eq!(d.bars.len(), 1);
    assert!(d.bars[0].is_essential());
    // All points equal: one essential H0 class, nothing else.
    let same = PointCloud::from_rows(&[[1.0, 1.0]; 5]).unwrap();
    let d = rips_points(&same, &RipsOptions::default());
    assert_eq!(d.bars.len(), 1);
}

/// Two rings far apart: each hole's death triangle spans its own ring's void; it need not
/// contain the centre (Rips triangles overlap in the plane), but it is not a triangle of
/// neighbours on the ring, nor one across both rings.
#[test]
fn death_triangles_lie_in_their_voids() {
    let mut rows = Vec::new();
    let ring = |rows: &mut Vec<[f64; 2]>, cx: f64, r: f64, m: usize| {
        for i in 0..m {
            let a = std::f64::consts::TAU * i as f64 / m as f64;
            // A fixed wobble of the radius, so no two triangles tie.
            let rr = r * (1.0 + 0.03 * ((7 * i) as f64).sin());
            rows.push([cx + rr * a.cos(), rr * a.sin()]);
        }
    };
    ring(&mut rows, 0.0, 1.0, 24);
    ring(&mut rows, 5.0, 0.6, 16);
    let p = PointCloud::from_rows(&rows).unwrap();
    let got = rips_points(&p, &opts(None));
    let holes: Vec<_> = got.dim(1).filter(|b| b.death / b.birth > 2.0).collect();
    assert_eq!(holes.len(), 2, "{:?}", got.dim(1).collect::<Vec<_>>());
    let mut centres = Vec::new();
    for b in holes {
        let t = b.death_triangle.unwrap();
        let c = t.iter().fold([0.0, 0.0], |c, &v| {
            [c[0] + rows[v][0] / 3.0, c[1] + rows[v][1] / 3.0]
        });
        let (cx, r) = if t[0] < 24 { (0.0, 1.0) } else { (5.0, 0.6) };
        assert!(
            t.iter().all(|&v| (v < 24) == (t[0] < 24)),
            "{t:?} spans both rings"
        );
        // It spans the void: its longest edge (the death) is a chord of at least a radius,
        // against a spacing of 0.26 radii between neighbours on the ring, and its centroid
        // is well inside the ring, where three neighbours' would sit on it.
        assert!(b.death >= r, "{b:?}");
        assert!(
            (c[0] - cx).hypot(c[1]) < 0.8 * r,
            "centroid {c:?} of {t:?} is not in the void of the ring at x = {cx}"
        );
        centres.push(cx);
    }
    centres.sort_by(f64::total_cmp);
    assert_eq!(centres, [0.0, 5.0]);
}
