//! How sure a campaign's figures are: a Wilson score interval for the share of independent
//! runs that are right, and the exact McNemar test for two settings run on the same seeds.
//!
//! Issue #5 asks for the global map to be right on at least 18 of 20 seeds. Twenty runs
//! measure a rate only roughly (15 of 20 is compatible with a true rate anywhere from about
//! 53 % to 89 %), and docs/accuracy.md compares settings whose figures differ by one or two
//! seeds. These two closed forms say how much such differences mean.
//!
//! - **Wilson score interval** (Wilson 1927; Brown, Cai & DasGupta 2001 recommend it over
//!   the normal interval for small n): the set of rates p that a two-sided z test would not
//!   reject at the observed k of n, `(p̂ + z²/2n ± z √(p̂(1−p̂)/n + z²/4n²)) / (1 + z²/n)`.
//!   It stays inside [0, 1] and is not degenerate at k = 0 or k = n.
//! - **Exact McNemar test** (McNemar 1947, in its exact binomial form): two settings run on
//!   the same seeds agree on most seeds; only the discordant ones carry evidence. With b
//!   seeds right under the first setting only and c under the second only, under the null
//!   hypothesis (no difference) each discordant seed is either way with probability ½, so
//!   the two-sided p-value is `min(1, 2 · P(X ≤ min(b, c)))`, X ~ Binomial(b + c, ½).
//!
//! Only per-run outcomes (a run's global map) are independent draws; the windows of one run
//! share its swarm and its embedding, so no interval is given for window shares.
//! Checked against SciPy's `binomtest` and statsmodels' `proportion_confint(method =
//! "wilson")` (the tests below).

/// The two-sided 95 % normal quantile, z with Φ(z) = 0.975.
pub const Z95: f64 = 1.959_963_984_540_054;

/// The Wilson score interval `(low, high)` for `k` successes in `n` independent trials at
/// normal quantile `z` (e.g. [`Z95`]); `None` when `n` is 0 or `k > n`.
pub fn wilson(k: usize, n: usize, z: f64) -> Option<(f64, f64)> {
    if n == 0 || k > n {
        return None;
    }
    let (k, n) = (k as f64, n as f64);
    let p = k / n;
    let z2 = z * z;
    let denom = 1.0 + z2 / n;
    let centre = (p + z2 / (2.0 * n)) / denom;
    let half = z / denom * (p * (1.0 - p) / n + z2 / (4.0 * n * n)).sqrt();
    Some(((centre - half).max(0.0), (centre + half).min(1.0)))
}

/// The two-sided p-value of the exact McNemar test: `b` pairs where only the first setting
/// succeeded, `c` where only the second did. 1 when there is no discordant pair.
pub fn mcnemar_exact(b: usize, c: usize) -> f64 {
    let n = b + c;
    let m = b.min(c);
    if n == 0 || 2 * m >= n {
        return 1.0;
    }
    // ln of each term C(n, i) / 2ⁿ, summed in log space so that large n cannot underflow.
    let ln2n = n as f64 * std::f64::consts::LN_2;
    let mut ln_choose = 0.0_f64;
    let mut terms = Vec::with_capacity(m + 1);
    for i in 0..=m {
        if i > 0 {
            ln_choose += ((n - i + 1) as f64).ln() - (i as f64).ln();
        }
        terms.push(ln_choose - ln2n);
    }
    let top = terms.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let tail = top + terms.iter().map(|t| (t - top).exp()).sum::<f64>().ln();
    (2.0 * tail.exp()).min(1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() <= 1e-12 * b.abs().max(1e-300) || (a - b).abs() < 1e-15
    }

    /// statsmodels 0.14 `proportion_confint(k, n, alpha=0.05, method="wilson")`.
    #[test]
    fn wilson_matches_statsmodels() {
        let cases = [
            (15, 20, 0.531_299_122_381_255_9, 0.888_138_298_592_334_4),
            (18, 20, 0.698_966_354_771_512_7, 0.972_133_518_786_231_8),
            (20, 20, 0.838_874_841_947_180_4, 1.0),
            (0, 20, 0.0, 0.161_125_158_052_819_4),
            (0, 1, 0.0, 0.793_450_685_622_762_7),
            (1, 1, 0.206_549_314_377_237_4, 1.0),
            (7, 13, 0.291_437_957_145_060_04, 0.767_939_321_904_616_9),
            (123, 400, 0.264_287_397_731_303_9, 0.354_374_835_587_400_3),
        ];
        for (k, n, lo, hi) in cases {
            let (l, h) = wilson(k, n, Z95).unwrap();
            assert!(
                close(l, lo) && close(h, hi),
                "{k}/{n}: ({l}, {h}) vs ({lo}, {hi})"
            );
        }
        assert_eq!(wilson(0, 0, Z95), None);
        assert_eq!(wilson(3, 2, Z95), None);
    }

    /// SciPy 1.x `binomtest(b, b + c, 0.5).pvalue` (two-sided).
    #[test]
    fn mcnemar_matches_scipy() {
        let cases = [
            (0, 4, 0.125),
            (1, 4, 0.375),
            (3, 3, 1.0),
            (0, 0, 1.0),
            (2, 9, 0.065_429_687_5),
            (10, 30, 0.002_221_433_773_229_364_3),
            (0, 1, 1.0),
            (600, 500, 0.002_819_544_991_436_428_4),
        ];
        for (b, c, p) in cases {
            let got = mcnemar_exact(b, c);
            assert!((got - p).abs() <= 1e-9 * p, "b={b} c={c}: {got} vs {p}");
            assert_eq!(got, mcnemar_exact(c, b), "symmetric in b and c");
        }
    }

    /// Brute force on small n: the doubled lower tail, summed over exact integer binomials.
    #[test]
    fn mcnemar_matches_brute_force() {
        for n in 1..=30_usize {
            for b in 0..=n {
                let c = n - b;
                let m = b.min(c) as u64;
                let mut choose = 1_u128;
                let mut tail = 0_u128;
                for i in 0..=m {
                    if i > 0 {
                        choose = choose * (n as u128 - i as u128 + 1) / i as u128;
                    }
                    tail += choose;
                }
                let want = (2.0 * tail as f64 / 2f64.powi(n as i32)).min(1.0);
                assert!((mcnemar_exact(b, c) - want).abs() < 1e-12, "b={b} c={c}");
            }
        }
    }

    /// The interval holds the point estimate and narrows as n grows at a fixed share.
    #[test]
    fn wilson_contains_the_share_and_narrows() {
        let mut width = 1.0;
        for n in [10, 20, 40, 80, 160] {
            let (l, h) = wilson(3 * n / 4, n, Z95).unwrap();
            assert!(l < 0.75 && 0.75 < h);
            assert!(h - l < width);
            width = h - l;
        }
    }
}
