//! Fidelity measures against closed forms and brute-force oracles.

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use swarmmap::eval::fidelity::{average_ranks, pearson, procrustes, procrustes_error, spearman};

/// Rank by definition, O(n²): 1 + (number smaller) + (number of equal others) / 2.
fn brute_ranks(x: &[f64]) -> Vec<f64> {
    x.iter()
        .map(|&v| {
            let less = x.iter().filter(|&&w| w < v).count() as f64;
            let equal = x.iter().filter(|&&w| w == v).count() as f64;
            1.0 + less + (equal - 1.0) / 2.0
        })
        .collect()
}

/// Pearson from the textbook single-pass formula, for comparison with the two-pass one.
fn brute_pearson(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len() as f64;
    let (sa, sb) = (a.iter().sum::<f64>(), b.iter().sum::<f64>());
    let sab: f64 = a.iter().zip(b).map(|(x, y)| x * y).sum();
    let saa: f64 = a.iter().map(|x| x * x).sum();
    let sbb: f64 = b.iter().map(|x| x * x).sum();
    (n * sab - sa * sb) / ((n * saa - sa * sa).sqrt() * (n * sbb - sb * sb).sqrt())
}

#[test]
fn spearman_without_ties_matches_the_closed_form() {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    for n in [2usize, 3, 5, 17, 200] {
        let a: Vec<f64> = (0..n).map(|_| rng.random::<f64>()).collect();
        let b: Vec<f64> = a.iter().map(|x| x + 0.3 * rng.random::<f64>()).collect();
        let (ra, rb) = (brute_ranks(&a), brute_ranks(&b));
        let d2: f64 = ra.iter().zip(&rb).map(|(x, y)| (x - y).powi(2)).sum();
        let nf = n as f64;
        let closed = 1.0 - 6.0 * d2 / (nf * (nf * nf - 1.0));
        assert!((spearman(&a, &b) - closed).abs() < 1e-12, "n = {n}");
    }
}

#[test]
fn spearman_with_ties_matches_pearson_on_brute_force_ranks() {
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    for trial in 0..50 {
        let n = rng.random_range(2..60usize);
        // Few distinct values: many ties.
        let a: Vec<f64> = (0..n).map(|_| rng.random_range(0..5u32) as f64).collect();
        let b: Vec<f64> = (0..n).map(|_| rng.random_range(0..7u32) as f64).collect();
        assert_eq!(average_ranks(&a), brute_ranks(&a));
        let want = brute_pearson(&brute_ranks(&a), &brute_ranks(&b));
        let got = spearman(&a, &b);
        if want.is_finite() {
            assert!((got - want).abs() < 1e-9, "trial {trial}: {got} vs {want}");
        } else {
            assert!(got.is_nan(), "trial {trial}: constant sample gives NaN");
        }
    }
    // Hand-computed: ranks [1, 2.5, 2.5, 4] against [1, 2, 3, 4] give √0.9.
    let rho = spearman(&[1.0, 2.0, 2.0, 3.0], &[10.0, 20.0, 30.0, 40.0]);
    assert!((rho - 0.9f64.sqrt()).abs() < 1e-12);
}

#[test]
fn spearman_is_rank_invariant_and_bounded() {
    let a = [0.5, 3.0, -1.0, 8.0, 2.0];
    let b: Vec<f64> = a.iter().map(|x: &f64| x.exp()).collect();
    assert!((spearman(&a, &b) - 1.0).abs() < 1e-12);
    let c: Vec<f64> = a.iter().map(|x| -x * x * x).collect();
    assert!((spearman(&a, &c) + 1.0).abs() < 1e-12);
    assert!((pearson(&a, &a) - 1.0).abs() < 1e-12);
}

#[test]
fn undefined_correlations_are_nan() {
    assert!(spearman(&[1.0, 2.0], &[1.0]).is_nan());
    assert!(spearman(&[1.0], &[1.0]).is_nan());
    assert!(spearman(&[], &[]).is_nan());
    assert!(spearman(&[1.0, 1.0, 1.0], &[1.0, 2.0, 3.0]).is_nan());
    assert!(spearman(&[1.0, f64::NAN, 3.0], &[1.0, 2.0, 3.0]).is_nan());
    assert!(pearson(&[1.0, f64::INFINITY], &[1.0, 2.0]).is_nan());
}

fn random_points(rng: &mut ChaCha8Rng, n: usize) -> Vec<[f64; 2]> {
    (0..n)
        .map(|_| [rng.random_range(0.0..10.0), rng.random_range(0.0..3.0)])
        .collect()
}

#[test]
fn similar_copies_fit_exactly() {
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    for trial in 0..40 {
        let n = rng.random_range(3..50usize);
        let truth = random_points(&mut rng, n);
        // est = any similarity (maybe reflecting) of the truth, in "seconds".
        let th: f64 = rng.random_range(0.0..std::f64::consts::TAU);
        let s: f64 = rng.random_range(0.1..100.0);
        let flip = trial % 2 == 1;
        let (tx, ty) = (rng.random_range(-50.0..50.0), rng.random_range(-50.0..50.0));
        let est: Vec<[f64; 2]> = truth
            .iter()
            .map(|p| {
                let y = if flip { -p[1] } else { p[1] };
                [
                    s * (th.cos() * p[0] - th.sin() * y) + tx,
                    s * (th.sin() * p[0] + th.cos() * y) + ty,
                ]
            })
            .collect();
        let fit = procrustes(&est, &truth).unwrap();
        assert!(fit.rms < 1e-9, "trial {trial}: rms {}", fit.rms);
        assert_eq!(fit.transform.is_reflection(), flip);
        assert!((fit.transform.scale - 1.0 / s).abs() < 1e-9 / s);
        for (e, t) in est.iter().zip(&truth) {
            let m = fit.transform.apply(*e);
            assert!((m[0] - t[0]).abs() < 1e-8 && (m[1] - t[1]).abs() < 1e-8);
        }
    }
}

#[test]
fn procrustes_closed_form_cases() {
    // Square corners against a segment's ends: the y-coordinates stay unexplained, 1 m each.
    let truth = [[1.0, 1.0], [-1.0, 1.0], [-1.0, -1.0], [1.0, -1.0]];
    let est = [[1.0, 0.0], [-1.0, 0.0], [-1.0, 0.0], [1.0, 0.0]];
    assert!((procrustes_error(&est, &truth) - 1.0).abs() < 1e-12);
    // A collapsed estimate: every point goes to the centroid, rms = √(mean ‖y − ȳ‖²) = √2.
    let est = [[3.0, 3.0]; 4];
    let fit = procrustes(&est, &truth).unwrap();
    assert!((fit.rms - 2f64.sqrt()).abs() < 1e-12);
    assert_eq!(fit.transform.scale, 0.0);
    // One point always fits exactly; two distinct points too.
    assert_eq!(procrustes_error(&[[5.0, 1.0]], &[[0.0, 0.0]]), 0.0);
    assert!(procrustes_error(&[[0.0, 0.0], [1.0, 0.0]], &[[3.0, 4.0], [3.0, 9.0]]) < 1e-12);
    // Undefined inputs.
    assert!(procrustes_error(&[], &[]).is_nan());
    assert!(procrustes_error(&[[0.0, 0.0]], &[[0.0, 0.0], [1.0, 1.0]]).is_nan());
    assert!(procrustes_error(&[[f64::NAN, 0.0]], &[[0.0, 0.0]]).is_nan());
}

/// RMS of the best similarity found by brute force: a fine grid of angles for rotations and
/// reflections, each with the least-squares scale and translation computed directly.
fn brute_rms(est: &[[f64; 2]], truth: &[[f64; 2]]) -> f64 {
    let n = est.len() as f64;
    let mean = |s: &[[f64; 2]]| {
        let (a, b) = s.iter().fold((0.0, 0.0), |(a, b), p| (a + p[0], b + p[1]));
        [a / n, b / n]
    };
    let (ce, ct) = (mean(est), mean(truth));
    let mut best = f64::INFINITY;
    let steps = 20_000;
    for k in 0..steps {
        let th = std::f64::consts::TAU * k as f64 / steps as f64;
        let (c, s) = (th.cos(), th.sin());
        for q in [[[c, -s], [s, c]], [[c, s], [s, -c]]] {
            let rot: Vec<[f64; 2]> = est
                .iter()
                .map(|p| {
                    let x = [p[0] - ce[0], p[1] - ce[1]];
                    [
                        q[0][0] * x[0] + q[0][1] * x[1],
                        q[1][0] * x[0] + q[1][1] * x[1],
                    ]
                })
                .collect();
            let num: f64 = rot
                .iter()
                .zip(truth)
                .map(|(r, t)| r[0] * (t[0] - ct[0]) + r[1] * (t[1] - ct[1]))
                .sum();
            let den: f64 = rot.iter().map(|r| r[0] * r[0] + r[1] * r[1]).sum();
            let scale = (num / den).max(0.0);
            let ss: f64 = rot
                .iter()
                .zip(truth)
                .map(|(r, t)| {
                    (scale * r[0] + ct[0] - t[0]).powi(2) + (scale * r[1] + ct[1] - t[1]).powi(2)
                })
                .sum();
            best = best.min(ss);
        }
    }
    (best / n).sqrt()
}

#[test]
fn procrustes_matches_brute_force_on_unrelated_clouds() {
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    for trial in 0..8 {
        let n = rng.random_range(3..12usize);
        let est = random_points(&mut rng, n);
        let truth = random_points(&mut rng, n);
        let got = procrustes_error(&est, &truth);
        let want = brute_rms(&est, &truth);
        // The grid's angle error (≤ 1.6e-4 rad) costs O(θ²) in the residual.
        assert!(got <= want + 1e-12, "trial {trial}: {got} > {want}");
        assert!(
            want - got < 1e-6 * want.max(1.0),
            "trial {trial}: {got} vs {want}"
        );
    }
}

#[test]
fn isotropic_noise_gives_its_expected_magnitude() {
    // est = truth + N(0, σ²) per coordinate: the residual keeps 2n − 4 of the 2n degrees of
    // freedom, so the rms is σ √(2 (n − 2) / n) up to sampling error (≈ 1 % at n = 4000).
    let mut rng = ChaCha8Rng::seed_from_u64(9);
    let n = 4000;
    let sigma = 0.05;
    let truth = random_points(&mut rng, n);
    let mut gauss = || {
        // Box–Muller.
        let (u, v): (f64, f64) = (rng.random::<f64>().max(1e-300), rng.random());
        (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
    };
    let est: Vec<[f64; 2]> = truth
        .iter()
        .map(|p| [p[0] + sigma * gauss(), p[1] + sigma * gauss()])
        .collect();
    let rms = procrustes_error(&est, &truth);
    let expected = sigma * (2.0 * (n as f64 - 2.0) / n as f64).sqrt();
    assert!((rms / expected - 1.0).abs() < 0.04, "{rms} vs {expected}");
}
