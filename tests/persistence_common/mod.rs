//! Helpers shared by the persistence tests: comparing diagrams and checking cycles.

#![allow(dead_code)] // each test binary uses a different subset of the helpers

use swarmmap::topology::rips::{Bar, Diagram};

/// Sorted `(birth, death)` of the bars of dimension `d` whose persistence is at least
/// `1e-9` relative (the reference data drop rounding-noise bars the same way).
pub fn bars(d: &Diagram, dim: usize) -> Vec<(f64, f64)> {
    let mut v: Vec<(f64, f64)> = d
        .dim(dim)
        .map(|b| (b.birth, b.death))
        .filter(|&(b, x)| significant(b, x))
        .collect();
    v.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.total_cmp(&y.1)));
    v
}

pub fn significant(birth: f64, death: f64) -> bool {
    death == f64::INFINITY || death - birth > 1e-9 * death.abs().max(birth.abs()).max(1e-300)
}

pub fn close(a: f64, b: f64, rel: f64) -> bool {
    a == b || (a - b).abs() <= rel * a.abs().max(b.abs())
}

/// Asserts two sorted bar lists are equal as multisets to `rel` relative tolerance.
pub fn assert_same(got: &[(f64, f64)], want: &[(f64, f64)], rel: f64, what: &str) {
    assert_eq!(
        got.len(),
        want.len(),
        "{what}: {} bars, expected {}\n got {got:?}\nwant {want:?}",
        got.len(),
        want.len()
    );
    for (g, w) in got.iter().zip(want) {
        assert!(
            close(g.0, w.0, rel) && close(g.1, w.1, rel),
            "{what}: bar {g:?} differs from {w:?}\n got {got:?}\nwant {want:?}"
        );
    }
}

/// Checks the representative cycle of an H1 bar: a Z/2 cycle (even degrees), every edge
/// no longer than the birth, one edge exactly as long (both to 1e-12 relative).
pub fn check_cycle(bar: &Bar, len: impl Fn(usize, usize) -> f64) {
    let c = bar.cycle.as_ref().expect("H1 bar without a cycle");
    assert!(!c.is_empty(), "empty cycle for {bar:?}");
    let mut deg = std::collections::HashMap::<usize, usize>::new();
    let mut seen = std::collections::HashSet::new();
    let mut hit = false;
    for &(i, j) in c {
        assert!(i < j, "edge ({i}, {j}) not ordered");
        assert!(seen.insert((i, j)), "edge ({i}, {j}) repeated");
        *deg.entry(i).or_default() += 1;
        *deg.entry(j).or_default() += 1;
        let l = len(i, j);
        assert!(
            l <= bar.birth * (1.0 + 1e-12) + 1e-300,
            "edge ({i}, {j}) of length {l} is longer than the birth {}",
            bar.birth
        );
        hit |= close(l, bar.birth, 1e-12);
    }
    assert!(deg.values().all(|d| d % 2 == 0), "not a cycle: {c:?}");
    assert!(hit, "no edge of length {} in {c:?}", bar.birth);
}
