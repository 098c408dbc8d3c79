//! The hole check (`swarmmap::eval::holes`) on a hand-made world: two discs in a band,
//! and robust holes whose cycles, at their events' true positions, go round one disc, both,
//! none, or clip the edge of one; plus the true holes of random disc worlds against the
//! discs that made them.

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use swarmmap::eval::holes::check;
use swarmmap::eval::truth::FreeSpace;
use swarmmap::mapping::local::{Component, Hole, LocalMap};
use swarmmap::world::{Obstacle, Placement, World};

fn disc(x: f64, y: f64, r: f64) -> Obstacle {
    Obstacle::Circle {
        center: (x, y),
        radius: r,
    }
}

/// A 10 m × 5 m arena whose whole area is reachable (the domain spans it).
fn world(obstacles: Vec<Obstacle>) -> World {
    let mut w = World::empty("holes", 10.0, 5.0);
    w.obstacles = obstacles;
    w.swarm.placement = Placement::Window;
    w.leader.window = 10.0;
    w.leader.start_x = 5.0;
    w
}

/// `k` points on a circle of radius `r` round `c`, and the edges of the closed loop
/// through them, numbered from `first`.
fn ring(c: [f64; 2], r: f64, k: usize, first: usize) -> (Vec<[f64; 2]>, Vec<(usize, usize)>) {
    let pts = (0..k)
        .map(|i| {
            let a = std::f64::consts::TAU * i as f64 / k as f64;
            [c[0] + r * a.cos(), c[1] + r * a.sin()]
        })
        .collect();
    let edges = (0..k).map(|i| (first + i, first + (i + 1) % k)).collect();
    (pts, edges)
}

/// A one-component map whose robust holes have the given cycles over events at `truth`.
fn map_with(truth_len: usize, cycles: Vec<Vec<(usize, usize)>>) -> LocalMap {
    LocalMap {
        index: 1,
        start: 0.0,
        end: 1.0,
        events: (0..truth_len).collect(),
        points: vec![[0.0; 3]; truth_len],
        noise: vec![false; truth_len],
        components: vec![Component {
            events: (0..truth_len).collect(),
            representatives: Vec::new(),
            scale: 1.0,
            diagram: Vec::new(),
            betti: [1, cycles.len()],
            holes: cycles
                .into_iter()
                .map(|cycle| Hole {
                    birth: 1.0,
                    death: 3.0,
                    cycle,
                    void: None,
                })
                .collect(),
            candidates: Vec::new(),
        }],
        betti: [1, 0],
        explained: 1.0,
        outlier_rank: 8,
        events_per_point: 1.0,
        classifier: swarmmap::mapping::classify::Classifier::default(),
        rows: Vec::new(),
    }
}

#[test]
fn cycles_are_matched_to_the_discs_they_go_round() {
    let w = world(vec![disc(3.0, 2.5, 0.5), disc(7.0, 2.5, 0.5)]);
    let fs = FreeSpace::new(&w, 0.01).unwrap();
    let holes = fs.holes_in_band(0.0, 10.0);
    assert_eq!(holes.len(), 2);
    for (h, c) in holes.iter().zip([3.0, 7.0]) {
        assert!(
            (h.inside[0] - c).hypot(h.inside[1] - 2.5) < 0.05,
            "{:?}",
            h.inside
        );
    }
    // Cycles: round disc 1; round disc 0; round both; round nothing (a loop in free
    // space); a loop whose centre is on disc 0's rim (it surrounds less than half of it).
    let mut pts = Vec::new();
    let mut cycles = Vec::new();
    for (c, r) in [
        ([7.0, 2.5], 0.8),
        ([3.0, 2.5], 0.7),
        ([5.0, 2.5], 2.4),
        ([5.0, 1.0], 0.4),
        ([3.6, 2.5], 0.5),
    ] {
        let (p, e) = ring(c, r, 12, pts.len());
        pts.extend(p);
        cycles.push(e);
    }
    let map = map_with(pts.len(), cycles);
    let h = check(&map, &pts, &holes);
    assert_eq!(h.found, vec![Some(1), Some(0), None, None, None]);
    assert_eq!(h.matched(), 2);
    assert!(h.missed().is_empty());
    assert_eq!(h.spurious(), 3);
    assert!(!h.right());
    // The loop round disc 0 alone misses disc 1; the first two loops are the truth.
    let two = map_with(pts.len(), vec![map.components[0].holes[1].cycle.clone()]);
    let h = check(&two, &pts, &holes);
    assert_eq!((h.found.clone(), h.missed()), (vec![Some(0)], vec![1]));
    let mut both = map.clone();
    both.components[0].holes.truncate(2);
    assert!(check(&both, &pts, &holes).right());
    // A band that holds only disc 0 has one hole; the loop round disc 1 then finds none.
    let left = fs.holes_in_band(0.0, 5.0);
    assert_eq!(left.len(), 1);
    assert_eq!(check(&both, &pts, &left).found, vec![None, Some(0)]);
}

#[test]
fn true_holes_of_random_disc_worlds_are_their_discs() {
    for seed in 0..12u64 {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut discs: Vec<(f64, f64, f64)> = Vec::new();
        let mut tries = 0;
        while discs.len() < 6 && tries < 10_000 {
            tries += 1;
            let r = rng.random_range(0.15..0.7);
            let x = rng.random_range(0.5 + r..9.5 - r);
            let y = rng.random_range(0.5 + r..4.5 - r);
            if discs
                .iter()
                .all(|&(a, b, s)| (x - a).hypot(y - b) > r + s + 0.3)
            {
                discs.push((x, y, r));
            }
        }
        let w = world(discs.iter().map(|&(x, y, r)| disc(x, y, r)).collect());
        let fs = FreeSpace::new(&w, 0.01).unwrap();
        let holes = fs.holes_in_band(0.0, 10.0);
        assert_eq!(holes.len(), discs.len(), "seed {seed}");
        assert_eq!(holes.len(), fs.betti_in_band(0.0, 10.0)[1]);
        let grown = fs.body_radius() + 0.02;
        // Each true hole is one disc, grown by the body radius: its point and samples lie
        // in that disc, and its area is the grown disc's to within the raster's rim.
        let mut used = vec![false; discs.len()];
        for h in &holes {
            let (k, &(x, y, r)) = discs
                .iter()
                .enumerate()
                .find(|(_, (x, y, r))| (h.inside[0] - x).hypot(h.inside[1] - y) < *r)
                .unwrap_or_else(|| panic!("seed {seed}: {:?} is in no disc", h.inside));
            assert!(!used[k], "seed {seed}: two holes in one disc");
            used[k] = true;
            assert!(!h.samples.is_empty());
            for s in &h.samples {
                assert!((s[0] - x).hypot(s[1] - y) < r + grown);
            }
            let area = std::f64::consts::PI * (r + fs.body_radius()).powi(2);
            let rim = std::f64::consts::TAU * (r + grown) * 0.02;
            assert!(
                (h.area - area).abs() < rim,
                "seed {seed}: {} vs {area}",
                h.area
            );
            // A ring of encounters just outside the grown disc goes round it.
            let (p, e) = ring([x, y], r + grown + 0.05, 16, 0);
            let map = map_with(p.len(), vec![e]);
            let one = check(&map, &p, &holes);
            assert_eq!(one.found.len(), 1);
            assert_eq!(one.truth[one.found[0].unwrap()], h.inside);
        }
    }
}
