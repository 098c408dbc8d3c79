//! Free space for agent centres on a raster: a cell is free when its centre lies inside
//! the arena shrunk by the body radius and farther than the body radius from every
//! obstacle (the configuration space of a disc-shaped robot, Lozano-Pérez 1983).
//!
//! Cells are at most 2 cm, at most an eighth of the arena's sides and a quarter of the
//! window, and grow only when the arena would need more than four million cells.
//! Building a raster costs one exact clearance evaluation per cell and nearby obstacle
//! (each obstacle is evaluated on its bounding box only; a polygon row by row and edge by
//! edge, [`super::geometry::clear_obstacle_cells`]);
//! the queries are linear in the number of cells or columns. A raster approximates: gaps
//! narrower than a cell may be missed, so it serves sanity checks and summaries, never
//! the simulation itself.

use super::geometry::{CellBlock, clear_obstacle_cells};
use super::types::{Vec2, World};

/// Largest number of raster cells built for one world or one placement disc.
const MAX_CELLS: f64 = 4e6;
/// Largest raster cell side in metres (the finest resolution used).
const MAX_CELL: f64 = 0.02;

/// Free cells of a world for agents of a given body radius.
#[derive(Debug, Clone)]
pub struct FreeSpaceRaster {
    /// Cell width along x, metres.
    pub cx: f64,
    /// Cell height along y, metres.
    pub cy: f64,
    /// Columns along x.
    pub nx: usize,
    /// Rows along y.
    pub ny: usize,
    /// Column-major: `free[ix * ny + iy]`.
    free: Vec<bool>,
}

impl FreeSpaceRaster {
    /// Rasterises `world` for agents of body radius `body` metres.
    pub fn new(world: &World, body: f64) -> Self {
        let (w, h) = (world.arena.width, world.arena.height);
        let cell = MAX_CELL
            .min(w / 8.0)
            .min(h / 8.0)
            .min(world.leader.window / 4.0)
            .max((w * h / MAX_CELLS).sqrt());
        // Square cells bound nx · ny only when the arena is no more elongated than the cell
        // count: a 30 m × 10⁹ m arena would get 11.5 million, and one of 10⁻²⁰⁰ m × 30 m a
        // count no `usize` holds. The casts saturate; the clamps keep nx · ny ≤ MAX_CELLS
        // (cells then stretch along the long side).
        let max_cells = MAX_CELLS as usize;
        let nx = ((w / cell).ceil() as usize).clamp(1, max_cells);
        let ny = ((h / cell).ceil() as usize).clamp(1, max_cells / nx);
        let (cx, cy) = (w / nx as f64, h / ny as f64);
        // `World::is_free`, cell by cell, without visiting every obstacle for every cell:
        // its clearance is the least of the arena sides' and the obstacles', so a cell is
        // free when the sides leave it more than `body` and so does each obstacle. A cell
        // whose centre lies more than `body` outside an obstacle's bounding box is more than
        // `body` from the obstacle, so each obstacle is evaluated only on the cells of its
        // box grown by `body` (and one cell more, for rounding): the same cells come out
        // free, at a cost of O(cells + the boxes' cells) instead of O(cells · obstacles).
        let centre = |i: usize, c: f64| (i as f64 + 0.5) * c;
        let mut free = Vec::with_capacity(nx * ny);
        for ix in 0..nx {
            let x = centre(ix, cx);
            for iy in 0..ny {
                let y = centre(iy, cy);
                free.push(x.min(w - x).min(y).min(h - y) > body);
            }
        }
        for o in &world.obstacles {
            let (lo, hi) = o.bounding_box();
            let (Some((x0, x1)), Some((y0, y1))) = (
                cells_near(lo.0, hi.0, body, 0.0, cx, nx),
                cells_near(lo.1, hi.1, body, 0.0, cy, ny),
            ) else {
                continue;
            };
            let block = CellBlock {
                cols: (x0, x1),
                rows: (y0, y1),
                ny,
                cell: (cx, cy),
                origin: (0.0, 0.0),
            };
            clear_obstacle_cells(o, body, block, &mut free);
        }
        Self {
            cx,
            cy,
            nx,
            ny,
            free,
        }
    }

    /// Whether cell `(ix, iy)` is free.
    pub fn is_free(&self, ix: usize, iy: usize) -> bool {
        self.free[ix * self.ny + iy]
    }

    /// Centre of cell `(ix, iy)` in metres.
    pub fn centre(&self, ix: usize, iy: usize) -> Vec2 {
        ((ix as f64 + 0.5) * self.cx, (iy as f64 + 0.5) * self.cy)
    }

    /// Free area in m².
    pub fn free_area(&self) -> f64 {
        self.free.iter().filter(|f| **f).count() as f64 * self.cx * self.cy
    }

    /// Free area (m²) of the columns whose centre lies in `[x0, x1]`.
    pub fn free_area_in_band(&self, x0: f64, x1: f64) -> f64 {
        (0..self.nx)
            .filter(|&ix| (x0..=x1).contains(&self.centre(ix, 0).0))
            .map(|ix| (0..self.ny).filter(|&iy| self.is_free(ix, iy)).count())
            .sum::<usize>() as f64
            * self.cx
            * self.cy
    }

    /// The first leader position x (sampled every cell width along the sweep, ends
    /// included) whose window `[x − l/2, x + l/2]` has no free column, if any.
    pub fn first_blocked_window(&self, world: &World) -> Option<f64> {
        let half = world.leader.window / 2.0;
        // prefix[i] = number of columns before i with at least one free cell.
        let mut prefix = vec![0usize; self.nx + 1];
        for ix in 0..self.nx {
            let any = (0..self.ny).any(|iy| self.is_free(ix, iy));
            prefix[ix + 1] = prefix[ix] + usize::from(any);
        }
        let (a, b) = (
            world.leader.start_x.min(world.leader.end_x),
            world.leader.start_x.max(world.leader.end_x),
        );
        let steps = ((b - a) / self.cx).ceil() as usize;
        (0..=steps)
            .map(|k| (a + k as f64 * self.cx).min(b))
            .find(|&x| {
                // Columns whose centre lies in [x − half, x + half].
                let lo = ((x - half) / self.cx - 0.5).ceil().max(0.0) as usize;
                let hi = (((x + half) / self.cx - 0.5).floor() + 1.0).clamp(0.0, self.nx as f64)
                    as usize;
                lo < hi && prefix[hi] == prefix[lo]
            })
    }

    /// Number of 4-connected components of free cells.
    pub fn components(&self) -> usize {
        let mut seen = vec![false; self.free.len()];
        let mut count = 0;
        let mut stack = Vec::new();
        for start in 0..self.free.len() {
            if !self.free[start] || seen[start] {
                continue;
            }
            count += 1;
            seen[start] = true;
            stack.push(start);
            while let Some(c) = stack.pop() {
                let (ix, iy) = (c / self.ny, c % self.ny);
                let mut visit = |n: usize| {
                    if self.free[n] && !seen[n] {
                        seen[n] = true;
                        stack.push(n);
                    }
                };
                if ix > 0 {
                    visit(c - self.ny);
                }
                if ix + 1 < self.nx {
                    visit(c + self.ny);
                }
                if iy > 0 {
                    visit(c - 1);
                }
                if iy + 1 < self.ny {
                    visit(c + 1);
                }
            }
        }
        count
    }

    /// Free area (m²) of the part of the disc of `radius` around `centre` where an agent
    /// of body radius `body` fits, sampled on its own grid (a 16th of the radius or
    /// finer, at most 2 cm, at most four million samples).
    ///
    /// A sample counts when it lies in the disc and `World::is_free(sample, body)` (for
    /// finite distances: a NaN one blocks the sample here and is ignored there); as in
    /// [`FreeSpaceRaster::new`], each obstacle is evaluated only on the samples near its
    /// bounding box, and a polygon by edges rather than sample by sample, so a traced
    /// outline of tens of thousands of vertices costs about what its edges do (the test
    /// `the_disc_area_equals_the_clearance_at_every_sample` compares it with `is_free`).
    pub fn disc_free_area(world: &World, centre: Vec2, radius: f64, body: f64) -> f64 {
        let cell = MAX_CELL
            .min(radius / 16.0)
            .max(2.0 * radius / MAX_CELLS.sqrt());
        let n = ((2.0 * radius / cell).ceil() as usize).max(1);
        let side = 2.0 * radius / n as f64;
        let origin = (centre.0 - radius, centre.1 - radius);
        let (w, h) = (world.arena.width, world.arena.height);
        let block = CellBlock {
            cols: (0, n - 1),
            rows: (0, n - 1),
            ny: n,
            cell: (side, side),
            origin,
        };
        let mut free = Vec::with_capacity(n * n);
        for i in 0..n {
            let x = block.x(i);
            for j in 0..n {
                let y = block.y(j);
                let inside = (x - centre.0).hypot(y - centre.1) <= radius;
                free.push(inside && x.min(w - x).min(y).min(h - y) > body);
            }
        }
        for o in &world.obstacles {
            let (lo, hi) = o.bounding_box();
            let (Some(cols), Some(rows)) = (
                cells_near(lo.0, hi.0, body, origin.0, side, n),
                cells_near(lo.1, hi.1, body, origin.1, side, n),
            ) else {
                continue;
            };
            clear_obstacle_cells(
                o,
                body,
                CellBlock {
                    cols,
                    rows,
                    ..block
                },
                &mut free,
            );
        }
        free.iter().filter(|f| **f).count() as f64 * side * side
    }
}

/// The cells `first..=last` of a raster row or column of `n` cells of size `cell` starting
/// at `origin` whose centres may lie within `grow` of `[lo, hi]`: one cell more on each
/// side, and more by the rounding of the centres, which grows with the coordinates (a disc
/// of 1e-12 m at x = 5 km has samples closer together than one ulp of x). `None` when the
/// range is empty. Only a pruning: the cells inside are still tested one by one.
fn cells_near(
    lo: f64,
    hi: f64,
    grow: f64,
    origin: f64,
    cell: f64,
    n: usize,
) -> Option<(usize, usize)> {
    let slack = 1e-9 * (origin.abs() + lo.abs().max(hi.abs()));
    let first = ((lo - grow - slack - origin) / cell - 0.5).floor() - 1.0;
    let last = ((hi + grow + slack - origin) / cell - 0.5).ceil() + 1.0;
    // Saturating casts; a box wholly outside the raster gives an empty range.
    let first = first.max(0.0) as usize;
    let last = last.min(n as f64 - 1.0).max(-1.0);
    (last >= 0.0 && first as f64 <= last).then_some((first, last as usize))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::world::Obstacle;
    use rand::{RngExt, SeedableRng};

    /// The pruned construction frees exactly the cells whose centres `World::is_free`
    /// frees, on random worlds of every obstacle kind, some reaching past the arena.
    /// A 6 m × 4 m arena with 40 obstacles of every kind, some reaching past its sides.
    fn random_world(rng: &mut rand_chacha::ChaCha8Rng) -> World {
        let mut world = World::empty("r", 6.0, 4.0);
        let mut p = || (rng.random_range(-0.5..6.5), rng.random_range(-0.5..4.5));
        for k in 0..40 {
            let (a, b, c) = (p(), p(), p());
            world.obstacles.push(match k % 4 {
                0 => Obstacle::Circle {
                    center: a,
                    radius: 0.05 + (b.0 / 20.0).abs(),
                },
                1 => Obstacle::Rect {
                    min: a,
                    max: (a.0 + (b.0 / 10.0).abs(), a.1 + (b.1 / 10.0).abs()),
                },
                2 => Obstacle::Polygon {
                    points: vec![a, (a.0 + 0.4, a.1 + 0.1), (a.0 + c.0 / 20.0, a.1 + 0.5)],
                },
                _ => Obstacle::Wall {
                    from: a,
                    to: (a.0 + b.0 / 8.0, a.1 + b.1 / 8.0),
                    thickness: 0.05,
                },
            });
        }
        world
    }

    /// The disc's area sample by sample through `World::is_free` (the code it replaced).
    fn disc_free_area_one_by_one(world: &World, centre: Vec2, radius: f64, body: f64) -> f64 {
        let cell = MAX_CELL
            .min(radius / 16.0)
            .max(2.0 * radius / MAX_CELLS.sqrt());
        let n = ((2.0 * radius / cell).ceil() as usize).max(1);
        let side = 2.0 * radius / n as f64;
        let mut free = 0usize;
        for i in 0..n {
            let x = centre.0 - radius + (i as f64 + 0.5) * side;
            for j in 0..n {
                let y = centre.1 - radius + (j as f64 + 0.5) * side;
                let inside = (x - centre.0).hypot(y - centre.1) <= radius;
                if inside && world.is_free((x, y), body) {
                    free += 1;
                }
            }
        }
        free as f64 * side * side
    }

    #[test]
    fn the_disc_area_equals_the_clearance_at_every_sample() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
        for case in 0..24 {
            let mut world = random_world(&mut rng);
            if case % 4 == 2 {
                // A traced outline: a wavy star of 500 vertices.
                let c = (rng.random_range(1.0..5.0), rng.random_range(1.0..3.0));
                let points = (0..500)
                    .map(|k| {
                        let a = std::f64::consts::TAU * f64::from(k) / 500.0;
                        let r = 0.6 + 0.15 * (17.0 * a).sin();
                        (c.0 + r * a.cos(), c.1 + r * a.sin())
                    })
                    .collect();
                world.obstacles.push(Obstacle::Polygon { points });
            }
            let centre = (rng.random_range(-0.5..6.5), rng.random_range(-0.5..4.5));
            let radius = [0.03, 0.4, 1.5, 5.0][case % 4];
            let body = [0.004, 0.03, 0.2][case % 3];
            let fast = FreeSpaceRaster::disc_free_area(&world, centre, radius, body);
            let slow = disc_free_area_one_by_one(&world, centre, radius, body);
            assert_eq!(fast, slow, "case {case}");
        }
        // Found in review: a disc of 1e-12 m at x = 5 km, whose samples are closer
        // together than the rounding of their centres, beside a rectangle one ulp away.
        let mut world = World::empty("t", 10_000.0, 10.0);
        let x = f64::from_bits(5000f64.to_bits() + 1);
        world.obstacles.push(Obstacle::Rect {
            min: (x, 0.0),
            max: (x + 1.0, 10.0),
        });
        let (centre, radius, body) = ((5000.0, 5.0), 1e-12, 1e-14);
        assert_eq!(
            FreeSpaceRaster::disc_free_area(&world, centre, radius, body),
            disc_free_area_one_by_one(&world, centre, radius, body)
        );
    }

    #[test]
    fn the_raster_equals_the_clearance_at_every_cell_centre() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        for case in 0..12 {
            let world = random_world(&mut rng);
            let body = [0.004, 0.03, 0.2][case % 3];
            let r = FreeSpaceRaster::new(&world, body);
            assert!(r.nx * r.ny > 10_000);
            for ix in 0..r.nx {
                for iy in 0..r.ny {
                    assert_eq!(
                        r.is_free(ix, iy),
                        world.is_free(r.centre(ix, iy), body),
                        "case {case}, cell ({ix}, {iy})"
                    );
                }
            }
        }
    }

    #[test]
    fn elongated_arenas_stay_within_the_cell_budget() {
        // Both shapes overflowed or exceeded the budget before the counts were clamped.
        for (w, h) in [(30.0, 1e9), (30.0, 1e300), (1e300, 30.0), (30.0, 1e-200)] {
            let mut world = World::empty("t", w, h);
            world.leader.window = w;
            let r = FreeSpaceRaster::new(&world, 0.0);
            assert!(
                r.nx * r.ny <= MAX_CELLS as usize,
                "{w} × {h}: {} × {}",
                r.nx,
                r.ny
            );
            assert!(r.nx >= 1 && r.ny >= 1);
            assert!((r.cx * r.nx as f64 - w).abs() <= 1e-9 * w);
            assert!((r.cy * r.ny as f64 - h).abs() <= 1e-9 * h);
        }
    }

    #[test]
    fn free_area_of_empty_arena_is_the_shrunk_rectangle() {
        let w = World::empty("t", 4.0, 2.0);
        let r = FreeSpaceRaster::new(&w, 0.1);
        // Closed form: (4 − 0.2)(2 − 0.2); the raster errs by at most a cell row per side.
        let exact = 3.8 * 1.8;
        assert!((r.free_area() - exact).abs() < 2.0 * (3.8 + 1.8) * 0.02);
        assert_eq!(r.components(), 1);
        assert_eq!(r.first_blocked_window(&w), None);
    }

    #[test]
    fn disc_area_matches_pi_r_squared() {
        let w = World::empty("t", 10.0, 10.0);
        let a = FreeSpaceRaster::disc_free_area(&w, (5.0, 5.0), 1.0, 0.004);
        assert!((a - std::f64::consts::PI).abs() < 0.02, "{a}");
    }

    #[test]
    fn a_full_height_block_blocks_windows_and_splits_space() {
        let mut w = World::empty("t", 30.0, 10.0);
        w.obstacles.push(Obstacle::Rect {
            min: (10.0, 0.0),
            max: (15.0, 10.0),
        });
        let r = FreeSpaceRaster::new(&w, 0.004);
        assert_eq!(r.components(), 2);
        let x = r.first_blocked_window(&w).expect("blocked");
        // The first window entirely inside [10, 15] is centred at 11.5 (l = 3 m).
        assert!((x - 11.5).abs() <= 0.021, "{x}");
    }
}
