//! Ground truth on hand-made worlds whose Betti numbers are known by inspection, checked at
//! three resolutions, plus randomised disc worlds against a closed-form count and the Euler
//! characteristic of the raster as an independent check of β1.

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use swarmmap::eval::truth::{FreeSpace, TruthError, overlap, window_band};
use swarmmap::world::{Obstacle, Placement, World};

const RESOLUTIONS: [f64; 3] = [0.005, 0.01, 0.02];

fn rect(x0: f64, y0: f64, x1: f64, y1: f64) -> Obstacle {
    Obstacle::Rect {
        min: (x0, y0),
        max: (x1, y1),
    }
}

fn disc(x: f64, y: f64, r: f64) -> Obstacle {
    Obstacle::Circle {
        center: (x, y),
        radius: r,
    }
}

fn wall(a: (f64, f64), b: (f64, f64), thickness: f64) -> Obstacle {
    Obstacle::Wall {
        from: a,
        to: b,
        thickness,
    }
}

/// A 10 m × 5 m arena with the given obstacles; agents start in the default disc of radius
/// 1 m around (1.5, 2.5).
fn world(obstacles: Vec<Obstacle>) -> World {
    let mut w = World::empty("t", 10.0, 5.0);
    w.obstacles = obstacles;
    w
}

/// Expected answers: global Betti numbers and `(x0, x1, betti)` for bands.
struct Case {
    name: &'static str,
    world: World,
    global: [usize; 2],
    bands: Vec<(f64, f64, [usize; 2])>,
}

fn cases() -> Vec<Case> {
    let mut split_window = world(vec![wall((5.0, 0.0), (5.0, 5.0), 0.1)]);
    split_window.leader.start_x = 5.0;
    split_window.swarm.placement = Placement::Window;
    let mut inside_ring = world(ring(5.0, 2.5, 1.0, 0.1));
    inside_ring.leader.start_x = 5.0;
    inside_ring.swarm.placement = Placement::Disk { radius: 0.5 };
    // Lanes beside a corridor that opens only at x = 7 m, ahead of a swarm that starts
    // inside it: no agent can enter them until the domain (3 m wide) reaches x = 7 m, and
    // by then it has left x < 4 m behind.
    let lanes = |from: f64, to: f64| {
        vec![
            wall((from, 2.0), (to, 2.0), 0.1),
            wall((from, 3.0), (to, 3.0), 0.1),
        ]
    };
    let mut corridor_ahead = world(lanes(0.0, 7.0));
    corridor_ahead.swarm.placement = Placement::Disk { radius: 0.4 };
    // The same lanes with the swarm placed over all of D(0): all three are entered at once.
    let mut corridor_window = corridor_ahead.clone();
    corridor_window.swarm.placement = Placement::Window;
    // Lanes that open behind the swarm (walls from x = 4 m to the right side): it reaches
    // all three from the open floor before the domain gets there.
    let mut corridor_behind = world(lanes(4.0, 10.0));
    corridor_behind.swarm.placement = Placement::Disk { radius: 0.4 };
    // The first case mirrored: a leftward sweep from x = 8.5 m, lanes open at x = 3 m.
    let mut corridor_leftward = world(lanes(3.0, 10.0));
    corridor_leftward.swarm.placement = Placement::Disk { radius: 0.4 };
    corridor_leftward.leader.start_x = 8.5;
    corridor_leftward.leader.end_x = 1.5;
    vec![
        Case {
            name: "lanes that open ahead of a leftward sweep",
            world: corridor_leftward,
            global: [1, 0],
            bands: vec![(6.5, 10.0, [1, 0]), (0.0, 5.5, [1, 0]), (3.5, 5.5, [3, 0])],
        },
        Case {
            name: "lanes that open ahead of the swarm",
            world: corridor_ahead,
            global: [1, 0],
            bands: vec![(0.0, 3.5, [1, 0]), (4.5, 10.0, [1, 0]), (4.5, 6.5, [3, 0])],
        },
        Case {
            name: "the same lanes, the swarm placed over D(0)",
            world: corridor_window,
            global: [1, 0],
            bands: vec![(0.0, 3.5, [3, 0]), (4.5, 6.5, [3, 0])],
        },
        Case {
            name: "lanes that open behind the swarm",
            world: corridor_behind,
            global: [1, 0],
            bands: vec![(5.0, 9.0, [3, 0]), (0.0, 3.5, [1, 0])],
        },
        Case {
            name: "empty arena",
            world: world(vec![]),
            global: [1, 0],
            bands: vec![(0.0, 3.0, [1, 0]), (4.0, 7.0, [1, 0]), (0.0, 10.0, [1, 0])],
        },
        Case {
            name: "one disc in the middle",
            world: world(vec![disc(5.0, 2.5, 1.0)]),
            global: [1, 1],
            bands: vec![
                (3.0, 7.0, [1, 1]),
                // Cut by the band's edge: not a hole.
                (5.0, 8.0, [1, 0]),
                (2.0, 4.5, [1, 0]),
                // Inside the disc's x-range: above and below are apart.
                (4.5, 5.5, [2, 0]),
                (0.0, 3.5, [1, 0]),
            ],
        },
        Case {
            name: "long rect touching nothing",
            world: world(vec![rect(3.0, 2.0, 7.0, 3.0)]),
            global: [1, 1],
            bands: vec![(2.0, 8.0, [1, 1]), (4.0, 6.0, [2, 0]), (2.0, 5.0, [1, 0])],
        },
        Case {
            name: "obstacle touching the top wall",
            world: world(vec![rect(4.0, 3.0, 6.0, 5.0)]),
            global: [1, 0],
            bands: vec![(3.0, 7.0, [1, 0]), (4.5, 5.5, [1, 0])],
        },
        Case {
            name: "obstacle 5 mm from the top wall (< 2 body radii)",
            world: world(vec![rect(4.0, 3.0, 6.0, 4.995)]),
            global: [1, 0],
            bands: vec![(3.0, 7.0, [1, 0])],
        },
        Case {
            name: "obstacle 0.3 m from the top wall",
            world: world(vec![rect(4.0, 3.0, 6.0, 4.7)]),
            global: [1, 1],
            bands: vec![(3.0, 7.0, [1, 1]), (4.5, 5.5, [2, 0])],
        },
        Case {
            name: "ring of four walls, unreachable inside",
            world: world(ring(5.0, 2.5, 1.0, 0.1)),
            global: [1, 1],
            bands: vec![(3.0, 7.0, [1, 1]), (4.5, 5.5, [2, 0]), (5.5, 8.0, [1, 0])],
        },
        Case {
            name: "agents start inside the ring",
            world: inside_ring,
            global: [1, 0],
            bands: vec![(3.0, 7.0, [1, 0]), (0.0, 3.0, [0, 0]), (4.5, 5.5, [1, 0])],
        },
        Case {
            name: "two overlapping obstacles make one hole",
            world: world(vec![disc(4.5, 2.5, 0.8), rect(5.0, 1.5, 7.0, 3.0)]),
            global: [1, 1],
            bands: vec![(3.0, 8.0, [1, 1]), (5.0, 6.0, [2, 0])],
        },
        Case {
            name: "two obstacles 0.5 m apart make two holes",
            world: world(vec![disc(3.5, 2.5, 0.8), rect(4.8, 1.5, 7.0, 3.0)]),
            global: [1, 2],
            bands: vec![(2.0, 8.0, [1, 2]), (2.0, 4.5, [1, 1]), (4.0, 8.0, [1, 1])],
        },
        Case {
            name: "two obstacles 6 mm apart (< 2 body radii) make one hole",
            world: world(vec![rect(3.0, 2.0, 4.0, 3.0), rect(4.006, 2.0, 6.0, 3.0)]),
            global: [1, 1],
            bands: vec![(2.0, 7.0, [1, 1]), (3.5, 4.5, [2, 0])],
        },
        Case {
            name: "wall splitting the arena, agents on the left",
            world: world(vec![wall((5.0, 0.0), (5.0, 5.0), 0.1)]),
            global: [1, 0],
            bands: vec![(0.0, 3.0, [1, 0]), (4.0, 6.0, [1, 0]), (6.0, 9.0, [0, 0])],
        },
        Case {
            name: "wall splitting the arena, agents on both sides",
            world: split_window,
            global: [2, 0],
            bands: vec![(4.0, 6.0, [2, 0]), (6.0, 9.0, [1, 0]), (0.0, 10.0, [2, 0])],
        },
        Case {
            name: "wall with a 6 mm gap at the top (closed)",
            world: world(vec![wall((5.0, 0.0), (5.0, 4.994), 0.002)]),
            global: [1, 0],
            bands: vec![(6.0, 9.0, [0, 0])],
        },
        Case {
            name: "wall with a 0.5 m gap at the top (open)",
            world: world(vec![wall((5.0, 0.0), (5.0, 4.5), 0.1)]),
            global: [1, 0],
            bands: vec![(6.0, 9.0, [1, 0]), (4.0, 6.0, [1, 0])],
        },
        Case {
            name: "non-convex slotted box, slot 0.5 m: the inside is reachable",
            world: world(vec![slotted_box(5.0, 2.5, 0.5)]),
            global: [1, 1],
            bands: vec![(3.0, 7.0, [1, 1]), (4.8, 5.2, [2, 0]), (3.5, 4.5, [2, 0])],
        },
        Case {
            name: "slotted box with a 6 mm slot: the inside is unreachable",
            world: world(vec![slotted_box(5.0, 2.5, 0.006)]),
            global: [1, 1],
            bands: vec![(3.0, 7.0, [1, 1]), (4.8, 5.2, [2, 0]), (3.5, 4.5, [1, 0])],
        },
    ]
}

/// Four walls of `thickness` forming a closed square of half-side `half` around (cx, cy).
fn ring(cx: f64, cy: f64, half: f64, thickness: f64) -> Vec<Obstacle> {
    let c = [
        (cx - half, cy - half),
        (cx + half, cy - half),
        (cx + half, cy + half),
        (cx - half, cy + half),
    ];
    (0..4)
        .map(|k| wall(c[k], c[(k + 1) % 4], thickness))
        .collect()
}

/// A simple non-convex polygon: the outline of a 2 m × 2 m box with 0.3 m thick sides
/// around (cx, cy), open by a slot of width `gap` in the middle of its top side.
fn slotted_box(cx: f64, cy: f64, gap: f64) -> Obstacle {
    let (l, r, b, t) = (cx - 1.0, cx + 1.0, cy - 1.0, cy + 1.0);
    let w = 0.3;
    Obstacle::Polygon {
        points: vec![
            (l, b),
            (r, b),
            (r, t),
            (cx + gap / 2.0, t),
            (cx + gap / 2.0, t - w),
            (r - w, t - w),
            (r - w, b + w),
            (l + w, b + w),
            (l + w, t - w),
            (cx - gap / 2.0, t - w),
            (cx - gap / 2.0, t),
            (l, t),
        ],
    }
}

#[test]
fn hand_made_worlds_at_three_resolutions() {
    for case in cases() {
        for &h in &RESOLUTIONS {
            let fs = FreeSpace::new(&case.world, h).unwrap();
            assert_eq!(
                fs.global_betti(),
                case.global,
                "{} at {h} m: global",
                case.name
            );
            for &(x0, x1, want) in &case.bands {
                assert_eq!(
                    fs.betti_in_band(x0, x1),
                    want,
                    "{} at {h} m: band [{x0}, {x1}]",
                    case.name
                );
                assert_eq!(fs.components_in_band(x0, x1), want[0]);
                assert_eq!(fs.holes_in_band(x0, x1).len(), want[1]);
                assert_eq!(fs.label_band(x0, x1).count(), want[0]);
            }
            assert_eq!(euler_global(&fs), betti_chi(fs.global_betti()));
        }
    }
}

fn betti_chi(b: [usize; 2]) -> i64 {
    b[0] as i64 - b[1] as i64
}

/// Euler characteristic V − E + F of the cubical complex of the reachable cells (4-adjacency
/// edges, full 2 × 2 blocks) over columns `c0..=c1`: an independent count of β0 − β1.
fn euler(fs: &FreeSpace, c0: usize, c1: usize) -> i64 {
    let (_, ny) = fs.dims();
    let at = |i: usize, j: usize| i >= c0 && i <= c1 && fs.is_reachable_cell(i, j);
    let (mut v, mut e, mut f) = (0i64, 0i64, 0i64);
    for i in c0..=c1 {
        for j in 0..ny {
            if !at(i, j) {
                continue;
            }
            v += 1;
            let right = at(i + 1, j);
            let up = at(i, j + 1);
            e += right as i64 + up as i64;
            f += (right && up && at(i + 1, j + 1)) as i64;
        }
    }
    v - e + f
}

fn euler_global(fs: &FreeSpace) -> i64 {
    euler(fs, 0, fs.dims().0 - 1)
}

#[test]
fn empty_arena_area_matches_closed_form() {
    let w = world(vec![]);
    let fs = FreeSpace::new(&w, 0.01).unwrap();
    let r = w.swarm.body_radius;
    let exact = (10.0 - 2.0 * r) * (5.0 - 2.0 * r);
    // The inner raster loses at most a strip of about 2 cells along the boundary.
    let perimeter = 2.0 * (10.0 + 5.0);
    let area = fs.reachable_area();
    assert!(
        area <= exact && exact - area < perimeter * 0.012,
        "{area} vs {exact}"
    );
}

#[test]
fn ring_pocket_is_not_space() {
    let fs = FreeSpace::new(&world(ring(5.0, 2.5, 1.0, 0.1)), 0.01).unwrap();
    assert!(!fs.is_reachable((5.0, 2.5)));
    assert_eq!(fs.component_of((5.0, 2.5)), None);
    assert_eq!(fs.component_of((1.0, 1.0)), Some(0));
    let band = fs.label_band(3.0, 7.0);
    assert_eq!(band.component_of((5.0, 2.5)), None);
    // Area: the arena minus the ring and its pocket (2.1 m square), within the raster's loss.
    let expected = (10.0 - 0.008) * (5.0 - 0.008) - 2.108f64.powi(2);
    let perimeter = 30.0 + 4.0 * 2.108;
    let area = fs.reachable_area();
    assert!(
        area <= expected && expected - area < perimeter * 0.012,
        "{area} vs {expected}"
    );
}

#[test]
fn components_are_labelled_consistently() {
    let fs = FreeSpace::new(&world(vec![rect(3.0, 2.0, 7.0, 3.0)]), 0.01).unwrap();
    let band = fs.label_band(4.0, 6.0);
    assert_eq!(band.count(), 2);
    let (above, below) = (band.component_of((5.0, 4.0)), band.component_of((5.0, 1.0)));
    assert!(above.is_some() && below.is_some() && above != below);
    // Labels follow the first cell in column-major order: bottom first.
    assert_eq!(below, Some(0));
    // A point just inside the obstacle snaps to the nearest side; deep inside gives None.
    assert_eq!(band.component_of((5.0, 3.005)), above);
    assert_eq!(band.component_of((5.0, 1.995)), below);
    assert_eq!(band.component_of((5.0, 2.5)), None);
    // Outside the band, or non-finite: None.
    assert_eq!(band.component_of((2.0, 4.0)), None);
    assert_eq!(band.component_of((f64::NAN, 4.0)), None);
    // Globally the two sides are one component.
    assert_eq!(fs.component_of((5.0, 4.0)), fs.component_of((5.0, 1.0)));
}

#[test]
fn window_domains_and_overlaps() {
    let mut w = World::empty("t", 30.0, 10.0);
    // Leader at 1.5 m during 300 s of dispersion, then 0.005 m/s.
    assert_eq!(window_band(&w, 0.0, 300.0), (0.0, 3.0));
    let (a, b) = window_band(&w, 100.0, 500.0);
    assert!((a - 0.0).abs() < 1e-12 && (b - 4.0).abs() < 1e-12);
    let (a, b) = window_band(&w, 700.0, 1100.0);
    assert!((a - 2.0).abs() < 1e-12 && (b - 7.0).abs() < 1e-12);
    assert_eq!(overlap((0.0, 4.0), (1.0, 6.0)), Some((1.0, 4.0)));
    assert_eq!(overlap((0.0, 1.0), (2.0, 6.0)), None);
    // A right-to-left sweep gives the same hull.
    w.leader.start_x = 28.5;
    w.leader.end_x = 1.5;
    let (a, b) = window_band(&w, 700.0, 1100.0);
    assert!((a - 23.0).abs() < 1e-12 && (b - 28.0).abs() < 1e-12);
}

#[test]
fn degenerate_queries_and_bad_parameters() {
    let w = world(vec![]);
    for bad in [0.0, -0.01, f64::NAN, f64::INFINITY] {
        assert!(matches!(
            FreeSpace::new(&w, bad),
            Err(TruthError::BadResolution(_))
        ));
    }
    assert!(matches!(
        FreeSpace::new(&w, 1e-5),
        Err(TruthError::TooManyCells { .. })
    ));
    let fs = FreeSpace::new(&w, 0.02).unwrap();
    assert_eq!(fs.betti_in_band(6.0, 5.0), [0, 0]);
    assert_eq!(fs.betti_in_band(f64::NAN, 5.0), [0, 0]);
    assert_eq!(fs.betti_in_band(-3.0, -1.0), [0, 0]);
    assert_eq!(fs.betti_in_band(-3.0, 30.0), [1, 0]);
    assert_eq!(fs.label_band(6.0, 5.0).component_of((5.5, 2.0)), None);
}

/// Random well-separated discs away from the walls: globally one component and one hole
/// per disc; in a band, a hole per disc wholly inside it and one extra component per disc
/// spanning the band's whole width.
#[test]
fn random_separated_discs() {
    let (width, height) = (10.0, 5.0);
    for seed in 0..24u64 {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let target = rng.random_range(1..=8usize);
        let mut discs: Vec<(f64, f64, f64)> = Vec::new();
        let mut tries = 0;
        while discs.len() < target && tries < 10_000 {
            tries += 1;
            let r = rng.random_range(0.1..0.7);
            let x = rng.random_range(0.5 + r..width - 0.5 - r);
            let y = rng.random_range(0.5 + r..height - 0.5 - r);
            if discs
                .iter()
                .all(|&(a, b, s)| (x - a).hypot(y - b) > r + s + 0.3)
            {
                discs.push((x, y, r));
            }
        }
        let mut w = World::empty("discs", width, height);
        w.obstacles = discs.iter().map(|&(x, y, r)| disc(x, y, r)).collect();
        // Seed the whole arena so every free part counts.
        w.swarm.placement = Placement::Window;
        w.leader.window = width;
        w.leader.start_x = width / 2.0;
        let h = [0.01, 0.02][seed as usize % 2];
        let fs = FreeSpace::new(&w, h).unwrap();
        assert_eq!(fs.global_betti(), [1, discs.len()], "seed {seed}");
        assert_eq!(euler_global(&fs), 1 - discs.len() as i64);

        let grown = fs.body_radius() + 0.05;
        let (mut checked, mut tries) = (0, 0);
        while checked < 12 && tries < 10_000 {
            tries += 1;
            let x0 = rng.random_range(0.0..width);
            let x1 = rng.random_range(x0..width);
            // Skip bands whose edge is too close to a disc's edge to call.
            let ambiguous = discs.iter().any(|&(x, _, r)| {
                [x - r, x + r]
                    .iter()
                    .any(|e| (e - x0).abs() < grown || (e - x1).abs() < grown)
            });
            if ambiguous || x1 - x0 < 0.1 {
                continue;
            }
            checked += 1;
            let holes = discs
                .iter()
                .filter(|&&(x, _, r)| x - r > x0 && x + r < x1)
                .count();
            let spanning = discs
                .iter()
                .filter(|&&(x, _, r)| x - r < x0 && x + r > x1)
                .count();
            assert_eq!(
                fs.betti_in_band(x0, x1),
                [1 + spanning, holes],
                "seed {seed}, band [{x0}, {x1}], discs {discs:?}"
            );
            let h = fs.resolution();
            let c0 = (x0 / h - 0.5).ceil() as usize;
            let c1 = (x1 / h - 0.5).floor() as usize;
            assert_eq!(euler(&fs, c0, c1), 1 + spanning as i64 - holes as i64);
        }
    }
}

/// A paper-sized arena (30 m × 10 m at 1 cm, 3 M cells) has the truth its four obstacles
/// give, and every 3 m band of it one component at least. (Its speed, the brief's target of
/// well under a second to build and milliseconds a band, is measured by `cargo bench
/// --bench truth`, not here.)
#[test]
fn paper_sized_arena_has_its_truth() {
    let mut w = World::empty("scenario-like", 30.0, 10.0);
    w.obstacles = vec![
        rect(6.0, 2.0, 8.0, 4.0),
        rect(6.0, 6.0, 8.0, 8.0),
        rect(11.0, 4.0, 22.0, 6.0),
        disc(25.0, 5.0, 1.0),
    ];
    let fs = FreeSpace::new(&w, 0.01).unwrap();
    assert_eq!(fs.global_betti(), [1, 4]);
    for k in 0..27 {
        let x0 = f64::from(k);
        assert!(fs.betti_in_band(x0, x0 + 3.0)[0] >= 1, "band at {x0}");
    }
}

/// A U-shaped obstacle (outer x 4–6 m, y 1.5–3.5 m, arms 0.3 m thick) whose pocket opens
/// towards `+x` (or `−x`): three rectangles.
fn u_shape(open_right: bool) -> Vec<Obstacle> {
    let (back, arms) = if open_right {
        (rect(4.0, 1.5, 4.3, 3.5), (4.0, 6.0))
    } else {
        (rect(5.7, 1.5, 6.0, 3.5), (4.0, 6.0))
    };
    vec![
        back,
        rect(arms.0, 1.5, arms.1, 1.8),
        rect(arms.0, 3.2, arms.1, 3.5),
    ]
}

/// A window's truth is R as it stood at the window's end: a pocket of the window's band
/// whose entrance the domain reaches only later is no space the window can map
/// (`worlds/nonconvex.ron`'s W1), while over the whole run it is part of R.
#[test]
fn a_pocket_that_opens_ahead_counts_once_the_domain_reaches_its_entrance() {
    for &h in &RESOLUTIONS {
        for open_right in [true, false] {
            let mut w = world(u_shape(open_right));
            if !open_right {
                // The mirror image: a leftward sweep from x = 8.5 m, the pocket opening at
                // x = 4 m.
                w.leader.start_x = 8.5;
                w.leader.end_x = 1.5;
            }
            let fs = FreeSpace::new(&w, h).unwrap();
            let at = |lead: f64| {
                // The time at which the domain's leading edge (1.5 m ahead of the leader)
                // stands at `lead`.
                let travelled = if open_right { lead - 3.0 } else { 7.0 - lead };
                w.simulation.dispersion_time + travelled / w.leader.speed
            };
            let name = if open_right { "rightward" } else { "leftward" };
            // The band up to x = 5 m (from x = 5 m leftward): the pocket's inner part is
            // cut off by the band's edge; its entrance (x = 6 m, or 4 m) is still ahead.
            let (t1, band1) = if open_right {
                (at(5.0), (0.0, 5.0))
            } else {
                (at(5.0), (5.0, 10.0))
            };
            let early = fs.reached_by(&w, t1);
            assert_eq!(
                early.betti_in_band(band1.0, band1.1),
                [1, 0],
                "{name} at {h} m"
            );
            assert_eq!(early.components_in_band(band1.0, band1.1), 1);
            assert_eq!(early.label_band(band1.0, band1.1).count(), 1);
            assert!(early.holes_in_band(band1.0, band1.1).is_empty());
            // All of R holds the pocket: a second component in the same band.
            assert_eq!(
                fs.betti_in_band(band1.0, band1.1),
                [2, 0],
                "{name} at {h} m"
            );
            // Once the leading edge has passed the entrance the pocket is reached, and the
            // U, wholly inside the band, is a hole.
            let (t2, band2) = if open_right {
                (at(6.5), (0.0, 6.5))
            } else {
                (at(3.5), (3.5, 10.0))
            };
            let later = fs.reached_by(&w, t2);
            assert_eq!(
                later.betti_in_band(band2.0, band2.1),
                [1, 1],
                "{name} at {h} m"
            );
            assert_eq!(later.holes_in_band(band2.0, band2.1).len(), 1);
            assert_eq!(fs.betti_in_band(band2.0, band2.1), [1, 1]);
            // At the end of the run, and after it, R is all of R.
            for t in [w.total_duration(), w.total_duration() + 1.0] {
                assert_eq!(fs.reached_by(&w, t).betti_in_band(0.0, 10.0), [1, 1]);
                assert_eq!(fs.reached_by(&w, t).betti_in_band(band1.0, band1.1), [2, 0]);
            }
            assert_eq!(fs.global_betti(), [1, 1]);
        }
    }
}
