//! The engine against reference diagrams computed by GUDHI 3.13 in float64 (cross-checked
//! with ripser.py and SciPy; see `tests/fixtures/persistence/README.md`).

mod persistence_common;

use std::path::PathBuf;

use persistence_common::{assert_same, bars, check_cycle};
use swarmmap::topology::rips::{Diagram, RipsOptions, rips_matrix, rips_points};
use swarmmap::topology::{DistanceMatrix, PointCloud};

const CASES: [&str; 7] = [
    "uniform2d_50",
    "circle_100",
    "two_circles_300",
    "torus3d_400",
    "grid_ties_144",
    "uniform3d_1000",
    "graph_metric_150",
];

fn fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/persistence")
        .join(name)
}

fn read_csv(name: &str, header: bool) -> Vec<Vec<f64>> {
    let text = std::fs::read_to_string(fixture(name)).unwrap();
    text.lines()
        .skip(usize::from(header))
        .filter(|l| !l.trim().is_empty())
        .map(|l| {
            l.split(',')
                .map(|x| x.trim().parse::<f64>().unwrap())
                .collect()
        })
        .collect()
}

enum Input {
    Points(PointCloud),
    Matrix(DistanceMatrix),
}

impl Input {
    fn load(case: &str) -> Self {
        if fixture(&format!("{case}.points.csv")).exists() {
            Input::Points(
                PointCloud::from_rows(&read_csv(&format!("{case}.points.csv"), false)).unwrap(),
            )
        } else {
            Input::Matrix(
                DistanceMatrix::from_full(&read_csv(&format!("{case}.dist.csv"), false)).unwrap(),
            )
        }
    }
    fn rips(&self, o: &RipsOptions) -> Diagram {
        match self {
            Input::Points(p) => rips_points(p, o),
            Input::Matrix(m) => rips_matrix(m, o),
        }
    }
    fn len(&self, i: usize, j: usize) -> f64 {
        match self {
            Input::Points(p) => p.dist(i, j),
            Input::Matrix(m) => m.get(i, j),
        }
    }
}

fn reference(case: &str, dim: usize) -> Vec<(f64, f64)> {
    let mut v: Vec<(f64, f64)> = read_csv(&format!("{case}.h{dim}.csv"), true)
        .into_iter()
        .map(|r| (r[0], r[1]))
        .collect();
    v.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.total_cmp(&y.1)));
    v
}

#[test]
fn every_reference_case_matches() {
    for case in CASES {
        let input = Input::load(case);
        let d = input.rips(&RipsOptions::default());
        for dim in 0..2 {
            assert_same(
                &bars(&d, dim),
                &reference(case, dim),
                1e-9,
                &format!("{case} H{dim}"),
            );
        }
        assert_eq!(d.dim(0).filter(|b| b.is_essential()).count(), 1, "{case}");
        assert_eq!(d.dim(1).filter(|b| b.is_essential()).count(), 0, "{case}");
    }
}

#[test]
fn h0_deaths_are_single_linkage_heights() {
    for case in CASES {
        let d = Input::load(case).rips(&RipsOptions {
            maxdim: 0,
            ..Default::default()
        });
        let mut deaths: Vec<f64> = d
            .dim(0)
            .map(|b| b.death)
            .filter(|x| x.is_finite())
            .collect();
        deaths.sort_by(f64::total_cmp);
        let mut heights: Vec<f64> = read_csv(&format!("{case}.single_linkage.csv"), true)
            .into_iter()
            .map(|r| r[0])
            .filter(|&h| h > 0.0)
            .collect();
        heights.sort_by(f64::total_cmp);
        assert_eq!(deaths.len(), heights.len(), "{case}");
        for (a, b) in deaths.iter().zip(&heights) {
            assert!(
                persistence_common::close(*a, *b, 1e-9),
                "{case}: {a} vs {b}"
            );
        }
    }
}

#[test]
fn representative_cycles_on_reference_cases() {
    for case in CASES {
        let input = Input::load(case);
        let plain = input.rips(&RipsOptions::default());
        let d = input.rips(&RipsOptions {
            cycles: true,
            ..Default::default()
        });
        // Asking for cycles does not change the bars.
        let strip = |d: &Diagram| -> Vec<(usize, f64, f64)> {
            d.bars.iter().map(|b| (b.dim, b.birth, b.death)).collect()
        };
        assert_eq!(strip(&plain), strip(&d), "{case}");
        for b in d.dim(1) {
            check_cycle(b, |i, j| input.len(i, j));
        }
        assert!(d.dim(0).all(|b| b.cycle.is_none()));
    }
}

#[test]
fn one_thread_and_many_threads_agree_bitwise() {
    let input = Input::load("torus3d_400");
    let one = input.rips(&RipsOptions {
        threads: 1,
        cycles: true,
        ..Default::default()
    });
    let two = input.rips(&RipsOptions {
        threads: 2,
        cycles: true,
        ..Default::default()
    });
    assert_eq!(one, two);
}

#[test]
fn explicit_large_threshold_equals_enclosing_radius() {
    let input = Input::load("two_circles_300");
    let a = input.rips(&RipsOptions::default());
    let b = input.rips(&RipsOptions {
        threshold: Some(1e9),
        ..Default::default()
    });
    assert_eq!(a, b);
}

#[test]
fn low_threshold_makes_circle_essential() {
    // circle_100: one big H1 bar; below its death it must come out essential, and H0
    // must split into the components of the threshold graph.
    let input = Input::load("circle_100");
    let full = input.rips(&RipsOptions::default());
    let big = full
        .dim(1)
        .max_by(|x, y| x.persistence().total_cmp(&y.persistence()))
        .unwrap()
        .clone();
    let t = 0.5 * (big.birth + big.death);
    let d = input.rips(&RipsOptions {
        threshold: Some(t),
        cycles: true,
        ..Default::default()
    });
    let ess: Vec<_> = d.dim(1).filter(|b| b.is_essential()).collect();
    assert_eq!(ess.len(), 1);
    assert_eq!(ess[0].birth, big.birth);
    check_cycle(ess[0], |i, j| input.len(i, j));
    let tiny = input.rips(&RipsOptions {
        threshold: Some(0.0),
        ..Default::default()
    });
    assert_eq!(tiny.dim(0).filter(|b| b.is_essential()).count(), 100);
}
