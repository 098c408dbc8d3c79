//! Tight representative cycles for H1 bars.
//!
//! The engine's representative of a bar ([`super::Bar::cycle`]) is the reduced boundary of
//! its death triangle: a correct cycle, but one that can wander far from the hole (on a
//! noisy cloud it often runs round most of the domain). For maps we want the loop that
//! hugs the hole. A bar born at scale `b` is created by its birth edge `(u, v)`, the
//! youngest edge of every representative: before `(u, v)` enters, `u` and `v` are already
//! joined by edges shorter than `b`, and any such path closed by `(u, v)` is a cycle of the
//! new class (two of them differ by a cycle of the complex before `b`, i.e. by older
//! classes, which is the freedom any representative at birth has). The shortest such path,
//! by summed edge length, gives the tightest loop: for a hole closed by a ring of points it
//! is the ring itself.
//!
//! The construction is that of the candidate cycles of Horton's minimum cycle basis
//! algorithm (J. D. Horton, "A polynomial-time algorithm to find the shortest cycle basis
//! of a graph", SIAM J. Comput. 16, 1987): an edge closed by a shortest path between its
//! ends, here restricted to the edges older than the birth edge.
//!
//! Cost: one dense Dijkstra over the `n` points, `O(n²)` distance evaluations, per bar.

/// The shortest cycle through the birth edge of `cycle` (the representative of an H1 bar
/// over points `0..n` with pairwise distances `dist`): the birth edge, i.e. the longest
/// edge of `cycle`, closed by the shortest path between its ends over edges strictly
/// shorter than it. Edges as `(i, j)` with `i < j`, sorted. `None`, and the caller keeps
/// `cycle`, when `cycle` is empty, has an edge out of range or of non-finite length, has
/// several edges of the longest length (then which of them is the birth edge depends on
/// the filtration's tie order, and closing the wrong one can give a boundary), or no such
/// path exists.
pub fn tighten_cycle(
    n: usize,
    dist: impl Fn(usize, usize) -> f64,
    cycle: &[(usize, usize)],
) -> Option<Vec<(usize, usize)>> {
    let mut birth_edge = None;
    let mut birth = f64::NEG_INFINITY;
    let mut tied = false;
    for &(a, b) in cycle {
        if a >= n || b >= n || a == b {
            return None;
        }
        let d = dist(a, b);
        if !d.is_finite() {
            return None;
        }
        if d > birth {
            (birth_edge, birth, tied) = (Some((a, b)), d, false);
        } else if d == birth {
            tied = true;
        }
    }
    let (u, v) = birth_edge?;
    if tied {
        return None;
    }
    let mut d = vec![f64::INFINITY; n];
    let mut prev = vec![usize::MAX; n];
    let mut done = vec![false; n];
    d[u] = 0.0;
    loop {
        let mut x = usize::MAX;
        let mut dx = f64::INFINITY;
        for (i, (&di, &fin)) in d.iter().zip(&done).enumerate() {
            if !fin && di < dx {
                dx = di;
                x = i;
            }
        }
        if x == usize::MAX || x == v {
            break;
        }
        done[x] = true;
        for y in 0..n {
            if done[y] {
                continue;
            }
            let w = dist(x, y);
            if w < birth && dx + w < d[y] {
                d[y] = dx + w;
                prev[y] = x;
            }
        }
    }
    if !d[v].is_finite() {
        return None;
    }
    let mut edges = vec![(u.min(v), u.max(v))];
    let mut x = v;
    while x != u {
        let p = prev[x];
        edges.push((p.min(x), p.max(x)));
        x = p;
    }
    edges.sort_unstable();
    Some(edges)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::topology::PointCloud;
    use crate::topology::rips::{Diagram, RipsOptions, rips_points};

    /// The Rips diagram of `p` with representative cycles.
    fn diagram(p: &[[f64; 2]]) -> Diagram {
        let rows: Vec<Vec<f64>> = p.iter().map(|q| q.to_vec()).collect();
        rips_points(
            &PointCloud::from_rows(&rows).unwrap(),
            &RipsOptions {
                cycles: true,
                ..Default::default()
            },
        )
    }

    /// A 64-bit linear congruential generator (Knuth's MMIX constants) from `seed`.
    fn lcg(mut seed: u64) -> impl FnMut() -> u64 {
        move || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            seed
        }
    }

    fn euclid(p: &[[f64; 2]]) -> impl Fn(usize, usize) -> f64 + '_ {
        |a, b| (p[a][0] - p[b][0]).hypot(p[a][1] - p[b][1])
    }

    /// Every vertex of a Z/2 cycle has even degree; a simple loop has degree 2 throughout.
    fn is_simple_loop(edges: &[(usize, usize)]) -> bool {
        let mut deg = std::collections::HashMap::new();
        for &(a, b) in edges {
            *deg.entry(a).or_insert(0) += 1;
            *deg.entry(b).or_insert(0) += 1;
        }
        deg.values().all(|&k| k == 2) && deg.len() == edges.len()
    }

    /// Winding number of a loop (as an edge set) around `c`, by walking it.
    fn winding(p: &[[f64; 2]], edges: &[(usize, usize)], c: [f64; 2]) -> i64 {
        let mut adj: std::collections::HashMap<usize, Vec<usize>> = Default::default();
        for &(a, b) in edges {
            adj.entry(a).or_default().push(b);
            adj.entry(b).or_default().push(a);
        }
        let start = edges[0].0;
        let (mut prev, mut cur) = (start, adj[&start][0]);
        let angle = |i: usize| (p[i][1] - c[1]).atan2(p[i][0] - c[0]);
        let mut total = 0.0;
        let mut a0 = angle(start);
        loop {
            let a1 = angle(cur);
            let mut da = a1 - a0;
            while da > std::f64::consts::PI {
                da -= 2.0 * std::f64::consts::PI;
            }
            while da < -std::f64::consts::PI {
                da += 2.0 * std::f64::consts::PI;
            }
            total += da;
            a0 = a1;
            if cur == start {
                break;
            }
            let next = if adj[&cur][0] == prev {
                adj[&cur][1]
            } else {
                adj[&cur][0]
            };
            prev = cur;
            cur = next;
        }
        (total / (2.0 * std::f64::consts::PI)).round() as i64
    }

    /// A ring of 24 points round the origin (radius 1) inside a filled square of side 6
    /// sampled on a 0.5 grid outside radius 2: one small hole with a wide void, where
    /// Rips' representative may run round the void's edge. The tight cycle is the ring.
    fn ring_in_plate() -> Vec<[f64; 2]> {
        let mut p: Vec<[f64; 2]> = (0..24)
            .map(|k| {
                let t = k as f64 * std::f64::consts::TAU / 24.0;
                [t.cos(), t.sin()]
            })
            .collect();
        for i in -6..=6 {
            for j in -6..=6 {
                let q = [i as f64 * 0.5, j as f64 * 0.5];
                if q[0].hypot(q[1]) > 2.0 {
                    p.push(q);
                }
            }
        }
        p
    }

    #[test]
    fn the_tight_cycle_of_a_ring_is_the_ring() {
        let p = ring_in_plate();
        let d = diagram(&p);
        let bar = d
            .dim(1)
            .max_by(|a, b| a.persistence().total_cmp(&b.persistence()))
            .unwrap();
        let cycle = bar.cycle.as_ref().unwrap();
        let tight = tighten_cycle(p.len(), euclid(&p), cycle).unwrap();
        assert!(is_simple_loop(&tight), "{tight:?}");
        assert_eq!(winding(&p, &tight, [0.0, 0.0]).abs(), 1);
        // The ring's 24 edges, and nothing but ring points.
        assert_eq!(tight.len(), 24, "{tight:?}");
        assert!(tight.iter().all(|&(a, b)| a < 24 && b < 24));
        let len = |c: &[(usize, usize)]| c.iter().map(|&(a, b)| euclid(&p)(a, b)).sum::<f64>();
        assert!(len(&tight) <= len(cycle) + 1e-9);
    }

    /// Brute force: on small random clouds the tight cycle's length equals the shortest
    /// path found by Floyd–Warshall over the edges shorter than the birth edge, plus it.
    #[test]
    fn matches_floyd_warshall_on_small_clouds() {
        let mut next = lcg(7);
        let mut rnd = || (next() >> 11) as f64 / (1u64 << 53) as f64;
        let mut checked = 0;
        for _ in 0..40 {
            let n = 20;
            let p: Vec<[f64; 2]> = (0..n).map(|_| [rnd(), rnd()]).collect();
            let d = diagram(&p);
            for bar in d.dim(1) {
                let Some(cycle) = bar.cycle.as_ref() else {
                    continue;
                };
                let dist = euclid(&p);
                let (u, v) = *cycle
                    .iter()
                    .max_by(|a, b| dist(a.0, a.1).total_cmp(&dist(b.0, b.1)))
                    .unwrap();
                let b = dist(u, v);
                assert!((b - bar.birth).abs() < 1e-12, "{b} vs {}", bar.birth);
                let mut fw = vec![vec![f64::INFINITY; n]; n];
                for (i, row) in fw.iter_mut().enumerate() {
                    for (j, x) in row.iter_mut().enumerate() {
                        if i == j {
                            *x = 0.0;
                        } else if dist(i, j) < b {
                            *x = dist(i, j);
                        }
                    }
                }
                for k in 0..n {
                    for i in 0..n {
                        for j in 0..n {
                            let via = fw[i][k] + fw[k][j];
                            if via < fw[i][j] {
                                fw[i][j] = via;
                            }
                        }
                    }
                }
                let tight = tighten_cycle(n, &dist, cycle).unwrap();
                let len: f64 = tight.iter().map(|&(a, c)| dist(a, c)).sum();
                assert!(
                    (len - (fw[u][v] + b)).abs() < 1e-9,
                    "{len} vs {}",
                    fw[u][v] + b
                );
                assert!(is_simple_loop(&tight));
                assert!(tight.contains(&(u.min(v), u.max(v))));
                checked += 1;
            }
        }
        assert!(checked >= 10, "only {checked} bars");
    }

    /// Whether the Z/2 chain `cycle` is a boundary in the Rips complex of `p` at `scale`
    /// (every triangle of diameter ≤ `scale`), by Gaussian elimination over Z/2.
    fn is_boundary(p: &[[f64; 2]], cycle: &[(usize, usize)], scale: f64) -> bool {
        use std::collections::{BTreeMap, HashMap};
        let n = p.len();
        let d = euclid(p);
        let edges: Vec<(usize, usize)> = (0..n)
            .flat_map(|a| (a + 1..n).map(move |b| (a, b)))
            .filter(|&(a, b)| d(a, b) <= scale)
            .collect();
        let index: HashMap<(usize, usize), usize> =
            edges.iter().enumerate().map(|(k, &e)| (e, k)).collect();
        let words = edges.len().div_ceil(64);
        let vector = |es: &[(usize, usize)]| {
            let mut v = vec![0u64; words];
            for e in es {
                let k = index[e];
                v[k / 64] ^= 1 << (k % 64);
            }
            v
        };
        let low = |v: &[u64]| {
            v.iter()
                .enumerate()
                .find(|(_, w)| **w != 0)
                .map(|(i, w)| i * 64 + w.trailing_zeros() as usize)
        };
        // Reduced triangle boundaries, keyed by their lowest set bit.
        let mut basis: BTreeMap<usize, Vec<u64>> = BTreeMap::new();
        let reduce = |mut v: Vec<u64>, basis: &BTreeMap<usize, Vec<u64>>| {
            while let Some(l) = low(&v) {
                match basis.get(&l) {
                    Some(b) => v.iter_mut().zip(b).for_each(|(x, y)| *x ^= y),
                    None => break,
                }
            }
            v
        };
        for a in 0..n {
            for b in a + 1..n {
                for c in b + 1..n {
                    if d(a, b) <= scale && d(a, c) <= scale && d(b, c) <= scale {
                        let v = reduce(vector(&[(a, b), (a, c), (b, c)]), &basis);
                        if let Some(l) = low(&v) {
                            basis.insert(l, v);
                        }
                    }
                }
            }
        }
        low(&reduce(vector(cycle), &basis)).is_none()
    }

    /// Points on a small integer grid tie at many lengths, so a bar's representative often
    /// has several edges of the birth length. Every tight cycle returned is a cycle of the
    /// bar's class at its birth (not a boundary there), and ties give `None`.
    #[test]
    fn tight_cycles_are_never_boundaries_even_with_ties() {
        let mut next = lcg(11);
        let mut rnd = |m: u64| (next() >> 33) % m;
        let (mut some, mut none) = (0, 0);
        for _ in 0..120 {
            let mut p: Vec<[f64; 2]> = Vec::new();
            while p.len() < 14 {
                let q = [rnd(5) as f64, rnd(5) as f64];
                if !p.contains(&q) {
                    p.push(q);
                }
            }
            let d = diagram(&p);
            for bar in d.dim(1).filter(|b| b.death.is_finite()) {
                let Some(cycle) = bar.cycle.as_ref() else {
                    continue;
                };
                assert!(!is_boundary(&p, cycle, bar.birth), "engine cycle {cycle:?}");
                match tighten_cycle(p.len(), euclid(&p), cycle) {
                    Some(tight) => {
                        some += 1;
                        assert!(is_simple_loop(&tight));
                        assert!(
                            !is_boundary(&p, &tight, bar.birth),
                            "{tight:?} is a boundary at {}",
                            bar.birth
                        );
                    }
                    None => none += 1,
                }
            }
        }
        assert!(some >= 20 && none >= 5, "{some} tightened, {none} left");
    }

    #[test]
    fn degenerate_inputs_give_none() {
        assert_eq!(tighten_cycle(3, |_, _| 1.0, &[]), None);
        // All edges tie at the birth length.
        assert_eq!(
            tighten_cycle(3, |_, _| 1.0, &[(0, 1), (0, 2), (1, 2)]),
            None
        );
        // Out of range, a loop edge, a NaN length.
        assert_eq!(tighten_cycle(3, |_, _| 1.0, &[(0, 1), (1, 5)]), None);
        assert_eq!(tighten_cycle(3, |_, _| 1.0, &[(0, 0)]), None);
        let nan = |a: usize, b: usize| if a + b == 1 { f64::NAN } else { 1.0 };
        assert_eq!(tighten_cycle(3, nan, &[(0, 1), (0, 2), (1, 2)]), None);
    }
}
