//! Representative cycles for H1 bars, from the cohomology pairs ("involuted" persistence,
//! after Čufar & Virk, "Fast computation of persistent homology representatives with
//! involuted persistent homology", 2021).
//!
//! Cohomology and homology give the same pairs (de Silva, Morozov & Vejdemo-Johansson,
//! 2011). For a finite bar `(σ, τ)` the canonical homology representative is the reduced
//! boundary column `R_τ` of the death triangle: a cycle whose youngest edge is `σ`. It is
//! obtained by reducing `∂τ` from its youngest edge down: while that edge `e` is paired (by
//! the cohomology computation) with a triangle `τ_e` older than `τ`, add `R_{τ_e}`. For an
//! apparent pair `R_{τ_e} = ∂τ_e` (three edges); the few other death triangles are reduced
//! first, oldest first, and memoised. So only the death triangles of the reduced pairs are
//! ever touched, never the full boundary matrix. Each step removes the youngest edge, so a
//! reduction costs `O(s log s)` for `s` edges swept, a small region around the hole.
//!
//! Essential bars (only below the enclosing radius, i.e. with a user threshold) get the
//! fundamental cycle of their birth edge in the spanning forest of older edges.

use std::collections::{BinaryHeap, HashMap, VecDeque};

use super::engine::{Edge, Raw, TREE, Tri, canonical, pop_pivot};
use super::metric::Metric;

/// Finds, for every H1 pair of `raw` with nonzero length, a representative cycle; keyed
/// by birth edge. Pairs whose reduction fails an internal consistency check are left out.
pub(crate) fn representatives<M: Metric>(m: &M, raw: &Raw) -> HashMap<Edge, Vec<Edge>> {
    let by_edge: HashMap<Edge, Tri> = raw.reduced.iter().map(|(t, e)| (*e, *t)).collect();
    let paired = |e: &Edge| -> Option<(Tri, bool)> {
        let k = raw.apex[e.index()];
        if k < TREE {
            Some((
                Tri::new(e.value(), e.a as usize, e.b as usize, k as usize),
                true,
            ))
        } else {
            by_edge.get(e).map(|t| (*t, false))
        }
    };
    let facets = |t: &Tri| {
        let (a, b, c) = (t.a as usize, t.b as usize, t.c as usize);
        [
            Edge::new(m.value(a, b), a, b),
            Edge::new(m.value(a, c), a, c),
            Edge::new(m.value(b, c), b, c),
        ]
    };
    let nonzero = |e: &Edge, t: &Tri| m.to_distance(t.value()) > m.to_distance(e.value());

    // Reduced death triangles, oldest first (`Tri`'s order is "greater = older").
    let mut deaths: Vec<(Tri, Edge)> = raw.reduced.iter().map(|(t, e)| (*t, *e)).collect();
    deaths.sort_unstable_by_key(|x| std::cmp::Reverse(x.0));
    let last = deaths.iter().rposition(|(t, e)| nonzero(e, t));
    let mut memo: HashMap<Tri, Vec<Edge>> = HashMap::new();
    let mut out = HashMap::new();
    let mut heap = BinaryHeap::new();
    for &(tau, sigma) in deaths.iter().take(last.map_or(0, |l| l + 1)) {
        heap.clear();
        heap.extend(facets(&tau));
        let mut ok = false;
        while let Some(low) = pop_pivot(&mut heap) {
            match paired(&low) {
                Some((t2, apparent)) if t2 > tau => {
                    if apparent {
                        heap.extend(facets(&t2));
                    } else if let Some(r) = memo.get(&t2) {
                        heap.extend(r.iter().copied());
                    } else {
                        break;
                    }
                }
                _ => {
                    ok = low == sigma;
                    break;
                }
            }
        }
        if !ok {
            continue;
        }
        let mut r: Vec<Edge> = heap.drain().collect();
        canonical(&mut r);
        if nonzero(&sigma, &tau) {
            out.insert(sigma, r.clone());
        }
        memo.insert(tau, r);
    }
    // Essential classes: fundamental cycles in the forest of older tree edges.
    let n = m.len();
    let mut adj: Vec<Vec<Edge>> = vec![Vec::new(); n];
    for e in &raw.tree {
        adj[e.a as usize].push(*e);
        adj[e.b as usize].push(*e);
    }
    for p in raw.pairs.iter().filter(|p| p.death.is_none()) {
        let s = p.birth;
        if let Some(path) = forest_path(&adj, s.b as usize, s.a as usize, &s) {
            let mut c = path;
            c.push(s);
            canonical(&mut c);
            out.insert(s, c);
        }
    }
    out
}

/// The path from `from` to `to` through forest edges older than `limit` (breadth first).
fn forest_path(adj: &[Vec<Edge>], from: usize, to: usize, limit: &Edge) -> Option<Vec<Edge>> {
    let mut prev: Vec<Option<Edge>> = vec![None; adj.len()];
    let mut seen = vec![false; adj.len()];
    let mut q = VecDeque::from([from]);
    seen[from] = true;
    while let Some(u) = q.pop_front() {
        if u == to {
            let mut path = Vec::new();
            let mut x = to;
            while x != from {
                let e = prev[x]?;
                path.push(e);
                x = if e.a as usize == x {
                    e.b as usize
                } else {
                    e.a as usize
                };
            }
            return Some(path);
        }
        for e in &adj[u] {
            if e >= limit {
                continue;
            }
            let w = if e.a as usize == u {
                e.b as usize
            } else {
                e.a as usize
            };
            if !seen[w] {
                seen[w] = true;
                prev[w] = Some(*e);
                q.push_back(w);
            }
        }
    }
    None
}
