//! The bundled worlds: every one is valid, and the topology their comments promise (β0
//! components and β1 holes of the free space, globally and per window) is what an
//! independent raster computation of the free space finds.

use swarmmap::world::World;

const ALL: &[&str] = &[
    "scenario1",
    "scenario2",
    "scenario3",
    "empty",
    "corridor",
    "corridor_lanes",
    "pillars",
    "nonconvex",
    "touching",
];

fn load(name: &str) -> World {
    World::load(format!("worlds/{name}.ron")).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// (β0, β1) of the free space inside the band `x0 ≤ x ≤ x1` (full height), on a 5 cm
/// raster: β0 counts 4-connected free components, β1 counts 8-connected blocked
/// components that touch neither the band's nor the arena's border (the dual
/// connectivities make the two counts consistent on a grid).
fn betti(world: &World, x0: f64, x1: f64) -> (usize, usize) {
    let cell = 0.05;
    let nx = ((x1 - x0) / cell).round() as usize;
    let ny = (world.arena.height / cell).round() as usize;
    let free: Vec<bool> = (0..nx * ny)
        .map(|k| {
            let (ix, iy) = (k / ny, k % ny);
            world.is_free(
                (x0 + (ix as f64 + 0.5) * cell, (iy as f64 + 0.5) * cell),
                0.0,
            )
        })
        .collect();
    let components = |want: bool, diagonal: bool| -> (usize, usize) {
        let mut seen = vec![false; nx * ny];
        let (mut all, mut inner) = (0, 0);
        for s in 0..nx * ny {
            if free[s] != want || seen[s] {
                continue;
            }
            all += 1;
            let mut touches = false;
            let mut stack = vec![s];
            seen[s] = true;
            while let Some(c) = stack.pop() {
                let (ix, iy) = ((c / ny) as i64, (c % ny) as i64);
                if ix == 0 || iy == 0 || ix == nx as i64 - 1 || iy == ny as i64 - 1 {
                    touches = true;
                }
                for dx in -1i64..=1 {
                    for dy in -1i64..=1 {
                        if (dx == 0 && dy == 0) || (!diagonal && dx != 0 && dy != 0) {
                            continue;
                        }
                        let (jx, jy) = (ix + dx, iy + dy);
                        if jx < 0 || jy < 0 || jx >= nx as i64 || jy >= ny as i64 {
                            continue;
                        }
                        let n = (jx as usize) * ny + jy as usize;
                        if free[n] == want && !seen[n] {
                            seen[n] = true;
                            stack.push(n);
                        }
                    }
                }
            }
            if !touches {
                inner += 1;
            }
        }
        (all, inner)
    };
    (components(true, false).0, components(false, true).1)
}

fn per_window(world: &World) -> Vec<(usize, usize)> {
    world
        .window_spans()
        .into_iter()
        .map(|span| {
            let (x0, x1) = world.span_domain(span);
            betti(world, x0, x1)
        })
        .collect()
}

#[test]
fn every_bundled_world_is_valid() {
    for name in ALL {
        let w = load(name);
        assert_eq!(w.name, *name);
        assert_eq!((w.arena.width, w.arena.height), (30.0, 10.0));
    }
    assert!(std::path::Path::new("worlds/training").is_dir());
}

/// The paper's parameters, except the sensing, swarm size and method that the accuracy
/// campaign chose (docs/accuracy.md, steps 2 and 13): r_d = 10 cm, 30 % landmarks, 200
/// agents, the `Embedded` method with a switch cost of r_d / v = 1 s, c = 35.
#[test]
fn the_scenarios_use_the_papers_parameters_but_the_measured_sensing() {
    for (name, windows) in [("scenario1", 4), ("scenario2", 6), ("scenario3", 5)] {
        let w = load(name);
        assert_eq!(w.mapping.windows, windows, "{name}");
        assert_eq!(w.swarm.agents, 200);
        assert_eq!(
            w.mapping.switch_cost,
            w.swarm.detection_radius / w.swarm.speed
        );
        assert_eq!(w.swarm.landmark_fraction, 0.3);
        assert_eq!(w.swarm.detection_radius, 0.1);
        assert_eq!(w.mapping.method, swarmmap::world::MappingMethod::Embedded);
        assert_eq!(w.swarm.speed, 0.1);
        // Scenario 3's small obstacles need a slower sweep, and twice the planar Rips
        // points for its twice as many encounters (docs/accuracy.md, step 29).
        let (speed, rips) = if name == "scenario3" {
            (0.0025, 4800)
        } else {
            (0.005, 2400)
        };
        assert_eq!(w.leader.speed, speed, "{name}");
        assert_eq!(w.mapping.rips_points, rips, "{name}");
        assert_eq!(w.leader.window, 3.0);
        assert_eq!(w.mapping.cluster_cutoff, 35.0);
    }
}

/// The training worlds are mapped as the bundled worlds are, so that a model fitted on
/// them (`swarmmap calibrate`) is the model the bundled worlds need.
#[test]
fn training_worlds_sense_and_map_like_the_bundled_ones() {
    let s1 = load("scenario1");
    let mut n = 0;
    for entry in std::fs::read_dir("worlds/training").unwrap() {
        let path = entry.unwrap().path();
        let w = World::load(&path).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(w.swarm, s1.swarm, "{}", path.display());
        assert_eq!(w.mapping.method, s1.mapping.method);
        assert_eq!(w.mapping.switch_cost, s1.mapping.switch_cost);
        assert_eq!(w.mapping.cluster_cutoff, s1.mapping.cluster_cutoff);
        n += 1;
    }
    assert_eq!(n, 10);
}

#[test]
fn scenario_obstacles_keep_clear_of_walls_and_each_other() {
    for name in ["scenario1", "scenario2", "scenario3"] {
        let w = load(name);
        let boxes: Vec<_> = w.obstacles.iter().map(|o| o.bounding_box()).collect();
        for (i, (lo, hi)) in boxes.iter().enumerate() {
            assert!(
                lo.0 >= 1.0 && lo.1 >= 1.0,
                "{name} obstacle {i} near a wall"
            );
            assert!(
                hi.0 <= w.arena.width - 1.0 && hi.1 <= w.arena.height - 1.0,
                "{name} obstacle {i} near a wall"
            );
            for (j, (lo2, hi2)) in boxes.iter().enumerate().skip(i + 1) {
                let gap = (lo2.0 - hi.0)
                    .max(lo.0 - hi2.0)
                    .max(lo2.1 - hi.1)
                    .max(lo.1 - hi2.1);
                assert!(
                    gap >= 1.0,
                    "{name} obstacles {i} and {j} only {gap} m apart"
                );
            }
        }
    }
}

#[test]
fn scenario1_features_each_fit_one_window() {
    let w = load("scenario1");
    for o in &w.obstacles {
        let (lo, hi) = o.bounding_box();
        assert!(hi.0 - lo.0 <= 1.5 && hi.1 - lo.1 <= 1.5);
    }
    assert_eq!(betti(&w, 0.0, 30.0), (1, 3));
    assert_eq!(per_window(&w), vec![(1, 1), (1, 1), (1, 0), (1, 1)]);
}

#[test]
fn scenario2_long_obstacle_splits_the_middle_windows() {
    let w = load("scenario2");
    let (lo, hi) = w.obstacles[0].bounding_box();
    assert!(
        hi.0 - lo.0 > 2.0 * w.leader.window,
        "longer than any window"
    );
    assert_eq!(betti(&w, 0.0, 30.0), (1, 1));
    assert_eq!(
        per_window(&w),
        vec![(1, 0), (1, 0), (1, 0), (2, 0), (2, 0), (1, 0)]
    );
    // Stitching regions: D(t_i) at the window boundaries t_i = i·T/N; the last three see
    // the bar across the whole window, hence two connections.
    let n = w.mapping.windows;
    let stitch: Vec<usize> = (1..n)
        .map(|i| {
            let (x0, x1) = w.domain(i as f64 * w.total_duration() / n as f64);
            betti(&w, x0, x1).0
        })
        .collect();
    assert_eq!(stitch, vec![1, 1, 2, 2, 2]);
}

#[test]
fn scenario3_features_are_shared_by_consecutive_windows() {
    let w = load("scenario3");
    assert_eq!(betti(&w, 0.0, 30.0), (1, 6));
    assert_eq!(per_window(&w), vec![(1, 2); 5]);
    // Four of the six lie wholly inside two consecutive windows' domains.
    let domains: Vec<_> = w
        .window_spans()
        .into_iter()
        .map(|s| w.span_domain(s))
        .collect();
    let shared = w
        .obstacles
        .iter()
        .filter(|o| {
            let (lo, hi) = o.bounding_box();
            domains
                .iter()
                .filter(|(a, b)| lo.0 >= *a && hi.0 <= *b)
                .count()
                == 2
        })
        .count();
    assert_eq!(shared, 4);
}

/// The ground truth's (β0, β1) per window and over the arena: of the space the swarm can
/// reach by each window's end (README, "Ground truth"), on a 2 cm raster.
fn reachable_per_window(world: &World) -> (Vec<[usize; 2]>, [usize; 2]) {
    let truth = swarmmap::eval::truth::FreeSpace::new(world, 0.02).unwrap();
    let windows = world
        .window_spans()
        .into_iter()
        .map(|span| {
            let (x0, x1) = world.span_domain(span);
            truth.reached_by(world, span.1).betti_in_band(x0, x1)
        })
        .collect();
    (windows, truth.global_betti())
}

#[test]
fn the_other_worlds_have_the_topology_their_comments_state() {
    let w = load("empty");
    assert_eq!(betti(&w, 0.0, 30.0), (1, 0));
    assert_eq!(per_window(&w), vec![(1, 0); 4]);
    let w = load("corridor");
    assert_eq!(betti(&w, 0.0, 30.0), (1, 0));
    // The free space has three lanes in W1 and W2, but the swarm can walk only the
    // corridor there (README, "Ground truth"): the truth is one component per window.
    assert_eq!(per_window(&w), vec![(3, 0), (3, 0), (1, 0), (1, 0)]);
    assert_eq!(reachable_per_window(&w).0, vec![[1, 0]; 4]);
    // Placed over all of D(0), the swarm starts in every lane: three components in W1, W2.
    let w = load("corridor_lanes");
    let (reachable, global) = reachable_per_window(&w);
    assert_eq!(reachable, vec![[3, 0], [3, 0], [1, 0], [1, 0]]);
    assert_eq!(global, [1, 0]);
    assert_eq!(betti(&load("pillars"), 0.0, 30.0), (1, 24));
    let w = load("nonconvex");
    assert_eq!(betti(&w, 0.0, 30.0), (1, 2));
    // W1's band ends at x = 9.375 m, inside the U's pocket, whose entrance (x = 10.5 m) the
    // domain reaches only in W2: the free space of W1's band has two components, the space
    // the swarm can reach during W1 one (README, "Ground truth").
    assert_eq!(per_window(&w), vec![(2, 0), (1, 1), (1, 1), (1, 0)]);
    assert_eq!(
        reachable_per_window(&w),
        (vec![[1, 0], [1, 1], [1, 1], [1, 0]], [1, 2])
    );
    assert_eq!(betti(&load("touching"), 0.0, 30.0), (1, 1));
}

/// The speed benchmarks the README's "Speed" table runs: what they simulate is what the
/// table's real-time factors are computed from (60 s of 1 000 agents, 3 s of 10 000).
#[test]
fn the_speed_benchmarks_are_the_runs_the_readme_times() {
    for (file, agents, span) in [("k1", 1_000, 60.0), ("k10", 10_000, 3.0)] {
        let w = World::load(format!("worlds/bench/{file}.ron")).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(w.name, file);
        assert_eq!(w.swarm.agents, agents);
        assert_eq!(w.swarm.detection_radius, 0.01, "the paper's sensing");
        assert_eq!(w.leader.start_x, w.leader.end_x, "no sweep");
        assert_eq!(w.simulation.dispersion_time, span);
        assert_eq!(w.simulation.dt, 0.03);
    }
}
