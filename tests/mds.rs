//! Classical and landmark MDS against exact embeddings and a dense eigendecomposition.

use nalgebra::{DMatrix, SymmetricEigen};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use swarmmap::topology::mds::{
    Embedding, MdsError, MdsOptions, classical_mds, classical_mds_with, landmark_mds,
};
use swarmmap::topology::{DistanceMatrix, PointCloud};

fn random_points(n: usize, dim: usize, seed: u64) -> PointCloud {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let c: Vec<f64> = (0..n * dim).map(|_| rng.random_range(-5.0..5.0)).collect();
    PointCloud::new(dim, c).unwrap()
}

/// A random metric that is not Euclidean: entries uniform in [1, 2] satisfy the triangle
/// inequality but give B negative eigenvalues.
fn random_metric(n: usize, seed: u64) -> DistanceMatrix {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    DistanceMatrix::from_fn(n, |_, _| rng.random_range(1.0..2.0))
}

/// B = −½ J D² J built entry by entry, and its full spectrum, descending.
fn dense_spectrum(d: &DistanceMatrix) -> Vec<f64> {
    let n = d.len();
    let sq = DMatrix::from_fn(n, n, |i, j| d.get(i, j).powi(2));
    let r: Vec<f64> = (0..n).map(|i| sq.row(i).sum() / n as f64).collect();
    let g = r.iter().sum::<f64>() / n as f64;
    let b = DMatrix::from_fn(n, n, |i, j| -0.5 * (sq[(i, j)] - r[i] - r[j] + g));
    let mut ev: Vec<f64> = SymmetricEigen::new(b).eigenvalues.iter().copied().collect();
    ev.sort_by(|a, b| b.total_cmp(a));
    ev
}

fn max_distance_error(e: &Embedding, d: &DistanceMatrix) -> f64 {
    let n = d.len();
    let mut worst = 0.0f64;
    for i in 0..n {
        for j in i + 1..n {
            worst = worst.max((e.coords.dist(i, j) - d.get(i, j)).abs());
        }
    }
    worst
}

/// Orthogonal Procrustes: the least-squares rigid motion of the embedding onto the points,
/// returning the largest coordinate error after the fit.
fn procrustes_error(emb: &PointCloud, pts: &PointCloud) -> f64 {
    let (n, k, dim) = (pts.len(), emb.dim(), pts.dim());
    let centred = |c: &PointCloud, cols: usize| {
        let mut m = DMatrix::from_fn(n, cols, |i, j| c.point(i).get(j).copied().unwrap_or(0.0));
        for j in 0..cols {
            let mean = m.column(j).mean();
            m.column_mut(j).add_scalar_mut(-mean);
        }
        m
    };
    let cols = k.max(dim);
    let (x, y) = (centred(emb, cols), centred(pts, cols));
    let svd = (x.transpose() * &y).svd(true, true);
    let rot = svd.u.unwrap() * svd.v_t.unwrap();
    (x * rot - y).abs().max()
}

fn check_against_dense(d: &DistanceMatrix, k: usize, opts: &MdsOptions, mass_tol: f64) {
    let e = classical_mds_with(d, k, opts).unwrap();
    let ev = dense_spectrum(d);
    let radius = ev.iter().fold(0.0f64, |a, l| a.max(l.abs()));
    for c in 0..k {
        let want = ev.get(c).copied().unwrap_or(0.0);
        assert!(
            (e.eigenvalues[c] - want).abs() <= 1e-8 * radius,
            "n={} eigenvalue {c}: got {}, want {want}",
            d.len(),
            e.eigenvalues[c]
        );
    }
    let noise = 1e-9 * radius;
    let pos: f64 = ev.iter().filter(|&&l| l > noise).sum();
    let neg: f64 = ev.iter().filter(|&&l| l < -noise).map(|l| -l).sum();
    let kept: f64 = ev.iter().take(k).filter(|&&l| l > 0.0).sum();
    let clipped = ev.iter().take(k).filter(|&&l| l < -noise).count();
    assert_eq!(e.clipped, clipped, "clipped");
    assert!(
        (e.explained - kept / pos).abs() <= mass_tol,
        "explained {} vs {}",
        e.explained,
        kept / pos
    );
    assert!(
        (e.negative_mass - neg / (pos + neg)).abs() <= mass_tol,
        "negative mass {} vs {}",
        e.negative_mass,
        neg / (pos + neg)
    );
    // Coordinates realise the kept eigenvalues: column norms² equal max(λ, 0).
    for c in 0..k {
        let sq: f64 = (0..d.len()).map(|i| e.coords.point(i)[c].powi(2)).sum();
        assert!((sq - e.eigenvalues[c].max(0.0)).abs() <= 1e-8 * radius);
    }
}

#[test]
fn planar_points_are_recovered_up_to_a_rigid_motion() {
    // n = 60 takes the exhaustive path, n = 500 the iterative one.
    for (n, seed) in [(60, 1), (500, 2)] {
        let pts = random_points(n, 2, seed);
        let d = DistanceMatrix::from_points(&pts);
        for k in [2, 3] {
            let e = classical_mds(&d, k).unwrap();
            assert!(max_distance_error(&e, &d) < 1e-9, "n={n} k={k}");
            assert!(procrustes_error(&e.coords, &pts) < 1e-9, "n={n} k={k}");
            assert_eq!(e.clipped, 0);
            assert!((e.explained - 1.0).abs() < 1e-12, "{}", e.explained);
            assert!(e.negative_mass < 1e-12);
            if k == 3 {
                assert!(e.eigenvalues[2].abs() < 1e-9 * e.eigenvalues[0]);
            }
        }
        // k = 1 keeps λ1 / (λ1 + λ2) of the variance.
        let e = classical_mds(&d, 1).unwrap();
        let full = classical_mds(&d, 2).unwrap();
        let share = full.eigenvalues[0] / (full.eigenvalues[0] + full.eigenvalues[1]);
        assert!((e.explained - share).abs() < 1e-9);
    }
}

#[test]
fn eigenvalues_match_dense_reference_on_random_inputs() {
    let exact = MdsOptions::default();
    // Force the iterative solver (and the stochastic masses) on small inputs too.
    let iterative = MdsOptions {
        exact_below: 0,
        ..MdsOptions::default()
    };
    for (case, n) in [3usize, 5, 12, 40, 90].into_iter().enumerate() {
        let seed = 10 + case as u64;
        let metric = random_metric(n, seed);
        let euclid = DistanceMatrix::from_points(&random_points(n, 5, seed));
        for d in [&metric, &euclid] {
            for k in [1, 3, 6] {
                check_against_dense(d, k, &exact, 1e-9);
                check_against_dense(d, k, &iterative, 0.08);
            }
        }
    }
}

#[test]
fn non_euclidean_beyond_exact_limit() {
    // n − 1 > exact_below: iterative eigenpairs, estimated masses (8 probes).
    let d = random_metric(260, 7);
    check_against_dense(&d, 3, &MdsOptions::default(), 0.05);
    let e = classical_mds(&d, 3).unwrap();
    assert!(!e.spectrum_exact);
    assert!(e.negative_mass > 0.1, "{}", e.negative_mass);
    let forced = classical_mds_with(
        &d,
        3,
        &MdsOptions {
            exact_below: 1000,
            ..MdsOptions::default()
        },
    )
    .unwrap();
    assert!(forced.spectrum_exact);
    check_against_dense(
        &d,
        3,
        &MdsOptions {
            exact_below: 1000,
            ..MdsOptions::default()
        },
        1e-9,
    );
}

#[test]
fn negative_top_eigenvalues_are_clipped_and_counted() {
    // Four points with d = 1 except d(0,1) = d(2,3) = 2 is not Euclidean; k = 3 reaches the
    // negative part of the spectrum.
    let d = DistanceMatrix::from_condensed(4, vec![2.0, 1.0, 1.0, 1.0, 1.0, 2.0]).unwrap();
    let ev = dense_spectrum(&d);
    assert!(ev.iter().any(|&l| l < -1e-6), "{ev:?}");
    check_against_dense(&d, 3, &MdsOptions::default(), 1e-12);
    let e = classical_mds(&d, 4).unwrap();
    assert!(e.clipped >= 1);
    for c in 0..4 {
        if e.eigenvalues[c] <= 0.0 {
            assert!((0..4).all(|i| e.coords.point(i)[c] == 0.0));
        }
    }
}

#[test]
fn repeated_eigenvalues_of_a_regular_polygon() {
    let n = 24;
    let rows: Vec<Vec<f64>> = (0..n)
        .map(|i| {
            let t = std::f64::consts::TAU * i as f64 / n as f64;
            vec![t.cos(), t.sin()]
        })
        .collect();
    let pts = PointCloud::from_rows(&rows).unwrap();
    let d = DistanceMatrix::from_points(&pts);
    for opts in [
        MdsOptions::default(),
        MdsOptions {
            exact_below: 0,
            ..MdsOptions::default()
        },
    ] {
        let e = classical_mds_with(&d, 3, &opts).unwrap();
        // Σ|x|² = n for unit-circle points, split equally on the two axes.
        assert!((e.eigenvalues[0] - n as f64 / 2.0).abs() < 1e-9);
        assert!((e.eigenvalues[1] - n as f64 / 2.0).abs() < 1e-9);
        assert!(e.eigenvalues[2].abs() < 1e-9);
        assert!(max_distance_error(&e, &d) < 1e-9);
    }
}

#[test]
fn degenerate_inputs_do_not_panic() {
    let zero = DistanceMatrix::zeros(50);
    let e = classical_mds(&zero, 3).unwrap();
    assert_eq!(e.eigenvalues, vec![0.0; 3]);
    assert!(e.coords.coords().iter().all(|&x| x == 0.0));
    assert_eq!((e.clipped, e.explained, e.negative_mass), (0, 1.0, 0.0));
    // All points on a line: rank 1.
    let line = PointCloud::new(1, (0..30).map(|i| i as f64).collect()).unwrap();
    let d = DistanceMatrix::from_points(&line);
    let e = classical_mds(&d, 3).unwrap();
    assert!(max_distance_error(&e, &d) < 1e-9);
    // Duplicated points and n < k + 1.
    let dup = DistanceMatrix::from_condensed(3, vec![0.0, 1.0, 1.0]).unwrap();
    let e = classical_mds(&dup, 5).unwrap();
    assert!(max_distance_error(&e, &dup) < 1e-12);
    assert_eq!(e.eigenvalues.len(), 5);
}

#[test]
fn same_input_same_bytes() {
    let d = random_metric(300, 3);
    let a = classical_mds(&d, 3).unwrap();
    let b = classical_mds(&d, 3).unwrap();
    assert_eq!(a, b);
}

fn full_rows(d: &DistanceMatrix) -> Vec<Vec<f64>> {
    (0..d.len())
        .map(|i| (0..d.len()).map(|j| d.get(i, j)).collect())
        .collect()
}

#[test]
fn landmark_mds_with_every_point_a_landmark_is_classical_mds() {
    for d in [
        random_metric(40, 5),
        DistanceMatrix::from_points(&random_points(70, 3, 6)),
    ] {
        let all: Vec<usize> = (0..d.len()).collect();
        let lm = landmark_mds(&all, &full_rows(&d), 3).unwrap();
        let cl = classical_mds(&d, 3).unwrap();
        assert_eq!(lm.eigenvalues, cl.eigenvalues);
        assert_eq!((lm.clipped, lm.explained), (cl.clipped, cl.explained));
        let err = lm
            .coords
            .coords()
            .iter()
            .zip(cl.coords.coords())
            .fold(0.0f64, |a, (x, y)| a.max((x - y).abs()));
        assert!(err < 1e-9, "{err}");
    }
}

#[test]
fn landmark_mds_recovers_planar_points_from_few_landmarks() {
    let pts = random_points(400, 2, 8);
    let d = DistanceMatrix::from_points(&pts);
    let landmarks = [3usize, 50, 177, 260, 399];
    let rows: Vec<Vec<f64>> = landmarks
        .iter()
        .map(|&l| (0..pts.len()).map(|j| pts.dist(l, j)).collect())
        .collect();
    for k in [2, 3] {
        let e = landmark_mds(&landmarks, &rows, k).unwrap();
        assert!(max_distance_error(&e, &d) < 1e-8, "k={k}");
        assert!(procrustes_error(&e.coords, &pts) < 1e-8, "k={k}");
    }
}

#[test]
fn landmark_mds_rejects_bad_input() {
    let rows = vec![vec![0.0, 1.0, 2.0], vec![1.0, 0.0, 1.5]];
    assert_eq!(landmark_mds(&[], &[], 2), Err(MdsError::NoLandmarks));
    assert_eq!(
        landmark_mds(&[0, 1], &rows, 0),
        Err(MdsError::ZeroDimension)
    );
    assert!(matches!(
        landmark_mds(&[0], &rows, 2),
        Err(MdsError::RowCount { .. })
    ));
    assert!(matches!(
        landmark_mds(&[0, 3], &rows, 2),
        Err(MdsError::LandmarkOutOfRange { landmark: 3, .. })
    ));
    let ragged = vec![vec![0.0, 1.0, 2.0], vec![1.0, 0.0]];
    assert!(matches!(
        landmark_mds(&[0, 1], &ragged, 2),
        Err(MdsError::RowLength { row: 1, .. })
    ));
    let neg = vec![vec![0.0, 1.0, -2.0], vec![1.0, 0.0, 1.5]];
    assert!(matches!(
        landmark_mds(&[0, 1], &neg, 2),
        Err(MdsError::BadDistance { row: 0, col: 2, .. })
    ));
    let asym = vec![vec![0.0, 1.0, 2.0], vec![1.2, 0.0, 1.5]];
    assert!(matches!(
        landmark_mds(&[0, 1], &asym, 2),
        Err(MdsError::Asymmetric { .. })
    ));
}
