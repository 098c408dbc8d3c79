//! Single linkage against SciPy's reference merge heights and against brute-force oracles.

use proptest::prelude::*;
use swarmmap::topology::linkage::{Dendrogram, single_linkage, single_linkage_edges};
use swarmmap::topology::{DistanceMatrix, PointCloud};

const FIXTURES: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/linkage");

fn read_rows(path: &str) -> Vec<Vec<f64>> {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{path}: {e}"));
    text.lines()
        .filter(|l| !l.trim().is_empty())
        .filter(|l| l.trim().parse::<f64>().is_ok() || l.contains(','))
        .map(|l| {
            l.split(',')
                .map(|x| x.trim().parse::<f64>().unwrap())
                .collect()
        })
        .collect()
}

fn load_case(name: &str) -> DistanceMatrix {
    let pts = format!("{FIXTURES}/{name}.points.csv");
    if std::path::Path::new(&pts).exists() {
        DistanceMatrix::from_points(&PointCloud::from_rows(&read_rows(&pts)).unwrap())
    } else {
        DistanceMatrix::from_full(&read_rows(&format!("{FIXTURES}/{name}.dist.csv"))).unwrap()
    }
}

#[test]
fn heights_match_scipy_reference_for_every_case() {
    let cases = [
        "uniform2d_50",
        "circle_100",
        "two_circles_300",
        "torus3d_400",
        "grid_ties_144",
        "uniform3d_1000",
        "graph_metric_150",
    ];
    for name in cases {
        let d = load_case(name);
        let want: Vec<f64> = read_rows(&format!("{FIXTURES}/{name}.single_linkage.csv"))
            .into_iter()
            .map(|r| r[0])
            .collect();
        let dg = single_linkage(&d);
        let got = dg.heights();
        assert_eq!(got.len(), d.len() - 1, "{name}: merge count");
        assert_eq!(got.len(), want.len(), "{name}: reference length");
        for (k, (g, w)) in got.iter().zip(&want).enumerate() {
            assert!(
                (g - w).abs() <= 1e-9 * w.abs().max(1e-300),
                "{name}: merge {k}: got {g}, want {w}"
            );
        }
        check_structure(&dg);
        assert_eq!(dg.merges.last().map(|m| m.size), Some(d.len()), "{name}");
    }
}

/// SciPy invariants: a < b, children exist before the merge, sizes add up, heights sorted.
fn check_structure(dg: &Dendrogram) {
    let n = dg.n;
    let mut size: Vec<usize> = vec![1; n];
    let mut used = vec![false; n + dg.merges.len()];
    for (k, m) in dg.merges.iter().enumerate() {
        assert!(m.a < m.b && m.b < n + k, "merge {k}: {m:?}");
        assert!(!used[m.a] && !used[m.b], "merge {k} reuses a cluster");
        used[m.a] = true;
        used[m.b] = true;
        assert_eq!(m.size, size[m.a] + size[m.b]);
        size.push(m.size);
        if k > 0 {
            assert!(dg.merges[k - 1].height <= m.height);
        }
    }
}

/// Connected components of the graph "d(i, j) <= t", labelled by first appearance.
fn brute_force_cut(d: &DistanceMatrix, t: f64) -> Vec<usize> {
    let n = d.len();
    let mut label = vec![usize::MAX; n];
    let mut next = 0;
    for s in 0..n {
        if label[s] != usize::MAX {
            continue;
        }
        let mut stack = vec![s];
        label[s] = next;
        while let Some(i) = stack.pop() {
            for (j, l) in label.iter_mut().enumerate() {
                if *l == usize::MAX && d.get(i, j) <= t {
                    *l = next;
                    stack.push(j);
                }
            }
        }
        next += 1;
    }
    label
}

/// Naive agglomerative single linkage: repeatedly join the two closest clusters, O(n³).
fn naive_heights(d: &DistanceMatrix) -> Vec<f64> {
    let n = d.len();
    let mut cl: Vec<usize> = (0..n).collect();
    let mut heights = Vec::new();
    for _ in 1..n {
        let mut best = (f64::INFINITY, 0, 0);
        for i in 0..n {
            for j in 0..n {
                if cl[i] != cl[j] && d.get(i, j) < best.0 {
                    best = (d.get(i, j), cl[i], cl[j]);
                }
            }
        }
        heights.push(best.0);
        for c in cl.iter_mut() {
            if *c == best.2 {
                *c = best.1;
            }
        }
    }
    heights
}

fn matrix_strategy() -> impl Strategy<Value = DistanceMatrix> {
    // Values from a small integer set force many exact ties.
    (1usize..14).prop_flat_map(|n| {
        prop::collection::vec(0u8..6, n * (n - 1) / 2).prop_map(move |v| {
            DistanceMatrix::from_condensed(n, v.into_iter().map(|x| x as f64 * 0.5).collect())
                .unwrap()
        })
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn cuts_match_brute_force_union_find(d in matrix_strategy()) {
        let dg = single_linkage(&d);
        check_structure(&dg);
        prop_assert_eq!(dg.heights(), naive_heights(&d));
        for t in [-1.0, 0.0, 0.5, 1.0, 1.25, 1.5, 2.0, 2.5, 10.0] {
            let want = brute_force_cut(&d, t);
            prop_assert_eq!(dg.cut(t), want.clone());
            prop_assert_eq!(dg.n_clusters(t), want.iter().max().map_or(0, |m| m + 1));
        }
    }

    #[test]
    fn edge_list_variant_agrees_on_complete_graphs(d in matrix_strategy()) {
        let n = d.len();
        let mut edges = Vec::new();
        for i in 0..n {
            for j in i + 1..n {
                edges.push((j, i, d.get(i, j)));
            }
        }
        edges.reverse();
        let sparse = single_linkage_edges(n, &edges).unwrap();
        check_structure(&sparse);
        let dense = single_linkage(&d);
        prop_assert_eq!(sparse.heights(), dense.heights());
        for t in [0.0, 0.5, 1.0, 1.5, 2.0, 2.5] {
            prop_assert_eq!(sparse.cut(t), dense.cut(t));
        }
    }
}
