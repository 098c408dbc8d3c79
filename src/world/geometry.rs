//! Exact planar geometry of worlds: distances from a point to obstacles, and the free
//! space an agent's centre may occupy (obstacles grown by the body radius, the arena
//! shrunk by it). The simulator, the ground truth and the report share these.

use super::types::{Obstacle, Vec2, World};

fn sub(a: Vec2, b: Vec2) -> Vec2 {
    (a.0 - b.0, a.1 - b.1)
}

fn dot(a: Vec2, b: Vec2) -> f64 {
    a.0 * b.0 + a.1 * b.1
}

fn norm(a: Vec2) -> f64 {
    a.0.hypot(a.1)
}

/// Distance from `p` to the segment `[a, b]`.
pub fn segment_distance(p: Vec2, a: Vec2, b: Vec2) -> f64 {
    let ab = sub(b, a);
    let len2 = dot(ab, ab);
    let t = if len2 > 0.0 {
        (dot(sub(p, a), ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    norm(sub(p, (a.0 + t * ab.0, a.1 + t * ab.1)))
}

/// Whether `p` lies inside the polygon (even–odd rule; works for non-convex simple polygons).
pub fn point_in_polygon(p: Vec2, poly: &[Vec2]) -> bool {
    let mut inside = false;
    let n = poly.len();
    for i in 0..n {
        let (a, b) = (poly[i], poly[(i + 1) % n]);
        if (a.1 > p.1) != (b.1 > p.1) {
            let x = a.0 + (p.1 - a.1) / (b.1 - a.1) * (b.0 - a.0);
            if p.0 < x {
                inside = !inside;
            }
        }
    }
    inside
}

/// A block of raster cells: columns `cols.0..=cols.1` and rows `rows.0..=rows.1` of a
/// column-major raster with `ny` rows, cell `(i, j)` centred at
/// `(origin.0 + (i + 0.5) · cell.0, origin.1 + (j + 0.5) · cell.1)`.
#[derive(Debug, Clone, Copy)]
pub struct CellBlock {
    /// Lower-left corner of the raster's cell `(0, 0)`, metres.
    pub origin: Vec2,
    /// First and last column.
    pub cols: (usize, usize),
    /// First and last row.
    pub rows: (usize, usize),
    /// Rows of the whole raster.
    pub ny: usize,
    /// Cell width and height, metres.
    pub cell: Vec2,
}

impl CellBlock {
    /// Centre of column `i`, metres.
    pub(crate) fn x(&self, i: usize) -> f64 {
        self.origin.0 + (i as f64 + 0.5) * self.cell.0
    }

    /// Centre of row `j`, metres.
    pub(crate) fn y(&self, j: usize) -> f64 {
        self.origin.1 + (j as f64 + 0.5) * self.cell.1
    }
}

/// Clears `free[i · ny + j]` for every cell of `block` whose centre `p` fails
/// `obstacle.signed_distance(p) > margin` (a NaN distance fails too); other cells keep
/// their value. Both rasters (the check's and the ground truth's) build their free cells
/// with it, each obstacle on its own bounding box grown by the margin.
///
/// A polygon with `margin ≥ 0` takes a faster path with the same result, bit for bit (the
/// same crossing and distance formulas): each row's inside test takes its edge crossings
/// once, and each edge is measured only on the cells near its own bounding box, so
/// O(rows · vertices + cells + Σ edges' box cells) instead of O(cells · vertices), which
/// matters for polygons of hundreds of vertices (a floor plan, a traced outline). "Bit for
/// bit" assumes what a checked world guarantees: finite vertices whose distance formula
/// rounds by far less than a cell. (With a vertex at 1e17 m, the rounding of
/// `segment_distance` alone exceeds a cell, and the cells near that edge may differ.)
pub fn clear_obstacle_cells(obstacle: &Obstacle, margin: f64, block: CellBlock, free: &mut [bool]) {
    if let Obstacle::Polygon { points } = obstacle
        && margin >= 0.0
    {
        clear_polygon_cells(points, margin, block, free);
        return;
    }
    let CellBlock {
        cols: (i0, i1),
        rows: (j0, j1),
        ny,
        ..
    } = block;
    for i in i0..=i1 {
        let x = block.x(i);
        for j in j0..=j1 {
            let c = i * ny + j;
            if free[c] {
                free[c] = obstacle.signed_distance((x, block.y(j))) > margin;
            }
        }
    }
}

/// [`clear_obstacle_cells`]'s path for a polygon, `margin ≥ 0`: a cell is blocked when its
/// centre is inside (even–odd, as `point_in_polygon`) or within `margin` of an edge.
fn clear_polygon_cells(points: &[Vec2], margin: f64, block: CellBlock, free: &mut [bool]) {
    let CellBlock {
        cols: (i0, i1),
        rows: (j0, j1),
        ny,
        cell: (cx, cy),
        origin,
    } = block;
    let n = points.len();
    if n == 0 || i0 > i1 || j0 > j1 {
        return;
    }
    let x = |i: usize| block.x(i);
    let y = |j: usize| block.y(j);
    // Inside (even–odd, as `point_in_polygon`): a centre is inside when an odd number of
    // the row's crossings lie strictly to its right.
    let mut crossings = Vec::new();
    for j in j0..=j1 {
        let py = y(j);
        crossings.clear();
        for k in 0..n {
            let (a, b) = (points[k], points[(k + 1) % n]);
            if (a.1 > py) != (b.1 > py) {
                let x = a.0 + (py - a.1) / (b.1 - a.1) * (b.0 - a.0);
                // `p.0 < NaN` is false: the per-point test never counts such a crossing.
                if !x.is_nan() {
                    crossings.push(x);
                }
            }
        }
        if crossings.is_empty() {
            continue;
        }
        crossings.sort_by(f64::total_cmp);
        let mut at_or_left = 0;
        for i in i0..=i1 {
            let px = x(i);
            while at_or_left < crossings.len() && crossings[at_or_left] <= px {
                at_or_left += 1;
            }
            if (crossings.len() - at_or_left) % 2 == 1 {
                free[i * ny + j] = false;
            }
        }
    }
    // Outside: within `margin` of some edge. A centre more than a cell outside an edge's
    // box grown by `margin` is farther than `margin` from the edge.
    // The box is also grown by the rounding of the cell centres, which grows with the
    // coordinates (cells far smaller than one ulp of them are a disc sampler's).
    let range = |lo: f64, hi: f64, o: f64, c: f64, first: usize, last: usize| {
        let slack = 1e-9 * (o.abs() + lo.abs().max(hi.abs()));
        let a = ((lo - margin - slack - o) / c - 0.5).floor() - 1.0;
        let b = ((hi + margin + slack - o) / c - 0.5).ceil() + 1.0;
        let a = a.max(first as f64);
        let b = b.min(last as f64);
        (a <= b).then_some((a as usize, b as usize))
    };
    for k in 0..n {
        let (a, b) = (points[k], points[(k + 1) % n]);
        let (Some((ia, ib)), Some((ja, jb))) = (
            range(a.0.min(b.0), a.0.max(b.0), origin.0, cx, i0, i1),
            range(a.1.min(b.1), a.1.max(b.1), origin.1, cy, j0, j1),
        ) else {
            continue;
        };
        for i in ia..=ib {
            let px = x(i);
            for j in ja..=jb {
                let c = i * ny + j;
                if free[c] && segment_distance((px, y(j)), a, b) <= margin {
                    free[c] = false;
                }
            }
        }
    }
}

/// Signed area of a polygon (shoelace formula), m²: positive when counter-clockwise.
pub fn polygon_area(poly: &[Vec2]) -> f64 {
    let n = poly.len();
    (0..n)
        .map(|i| {
            let (a, b) = (poly[i], poly[(i + 1) % n]);
            a.0 * b.1 - b.0 * a.1
        })
        .sum::<f64>()
        / 2.0
}

/// The area centroid of a simple polygon, in either orientation (shoelace formula, summed
/// relative to the first vertex so that a polygon far from the origin keeps its precision).
/// A polygon without area (fewer than three points, or all on one line within a relative
/// 1e-12 of its extent squared) gives the mean of its vertices; an empty list `(0, 0)`.
pub fn polygon_centroid(poly: &[Vec2]) -> Vec2 {
    let n = poly.len();
    if n == 0 {
        return (0.0, 0.0);
    }
    let o = poly[0];
    let (mut twice_area, mut cx, mut cy) = (0.0, 0.0, 0.0);
    for i in 0..n {
        let (p, q) = (sub(poly[i], o), sub(poly[(i + 1) % n], o));
        let cross = p.0 * q.1 - q.0 * p.1;
        twice_area += cross;
        cx += (p.0 + q.0) * cross;
        cy += (p.1 + q.1) * cross;
    }
    let extent = poly.iter().fold(0.0f64, |m, p| {
        m.max((p.0 - o.0).abs()).max((p.1 - o.1).abs())
    });
    if twice_area.abs() > 1e-12 * extent * extent && twice_area.is_finite() {
        (o.0 + cx / (3.0 * twice_area), o.1 + cy / (3.0 * twice_area))
    } else {
        let k = n as f64;
        (
            poly.iter().map(|p| p.0).sum::<f64>() / k,
            poly.iter().map(|p| p.1).sum::<f64>() / k,
        )
    }
}

/// Orientation of `c` relative to the directed line `a → b`: `1` left, `-1` right, `0`
/// collinear, within a tolerance that scales with the coordinates' magnitude and with the
/// two edges' lengths, as the cross product's rounding does: a small triangle far from the
/// origin keeps its orientation (with a tolerance of the magnitude squared alone, a 1 µm
/// triangle at x = 3 m was called collinear and then self-intersecting).
fn orientation(a: Vec2, b: Vec2, c: Vec2) -> i8 {
    let cross = (b.0 - a.0) * (c.1 - a.1) - (b.1 - a.1) * (c.0 - a.0);
    let scale = [a.0, a.1, b.0, b.1, c.0, c.1]
        .iter()
        .fold(1.0f64, |m, v| m.max(v.abs()));
    let lengths = (b.0 - a.0).hypot(b.1 - a.1) + (c.0 - a.0).hypot(c.1 - a.1);
    let eps = 1e-12 * scale * lengths;
    if cross > eps {
        1
    } else if cross < -eps {
        -1
    } else {
        0
    }
}

/// Whether `c`, known collinear with `[a, b]`, lies within the segment's bounding box.
fn on_segment(a: Vec2, b: Vec2, c: Vec2) -> bool {
    c.0 >= a.0.min(b.0) && c.0 <= a.0.max(b.0) && c.1 >= a.1.min(b.1) && c.1 <= a.1.max(b.1)
}

/// Whether the closed segments `[a, b]` and `[c, d]` share a point (touching counts).
pub fn segments_intersect(a: Vec2, b: Vec2, c: Vec2, d: Vec2) -> bool {
    let (o1, o2) = (orientation(a, b, c), orientation(a, b, d));
    let (o3, o4) = (orientation(c, d, a), orientation(c, d, b));
    if o1 != o2 && o3 != o4 && o1 != 0 && o2 != 0 && o3 != 0 && o4 != 0 {
        return true;
    }
    (o1 == 0 && on_segment(a, b, c))
        || (o2 == 0 && on_segment(a, b, d))
        || (o3 == 0 && on_segment(c, d, a))
        || (o4 == 0 && on_segment(c, d, b))
}

/// The first pair of edges `(i, j)` (edge `i` runs from vertex `i` to `i + 1`) of the
/// closed polygon that meet although they should not: non-adjacent edges that share a
/// point, or adjacent edges that fold back over each other. `None` for a simple polygon.
///
/// Only pairs whose bounding boxes overlap are tested (sweep and prune along x): edges
/// with disjoint boxes share no point, and the tolerance of the tests cannot make them
/// (a crossing needs both orientation tests strict, a touch needs the point inside the
/// other edge's box). So the answer is the all-pairs one, [`self_intersection_brute_force`]
/// (checked against it in the tests), at O(n log n + pairs tested): a 40 000-vertex outline
/// exported from a drawing is checked in a blink, not the half minute of all pairs.
pub fn polygon_self_intersection(poly: &[Vec2]) -> Option<(usize, usize)> {
    let n = poly.len();
    if n < 3 {
        return None;
    }
    let edge = |i: usize| (poly[i], poly[(i + 1) % n]);
    let boxes: Vec<(Vec2, Vec2)> = (0..n)
        .map(|i| {
            let (a, b) = edge(i);
            ((a.0.min(b.0), a.1.min(b.1)), (a.0.max(b.0), a.1.max(b.1)))
        })
        .collect();
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&p, &q| boxes[p].0.0.total_cmp(&boxes[q].0.0).then(p.cmp(&q)));
    let mut first: Option<(usize, usize)> = None;
    for (k, &e) in order.iter().enumerate() {
        let (lo, hi) = boxes[e];
        for &f in &order[k + 1..] {
            let (flo, fhi) = boxes[f];
            if flo.0 > hi.0 {
                break;
            }
            if flo.1 > hi.1 || lo.1 > fhi.1 {
                continue;
            }
            let pair = (e.min(f), e.max(f));
            if first.is_some_and(|best| best <= pair) {
                continue;
            }
            if edges_meet(poly, pair.0, pair.1) {
                first = Some(pair);
            }
        }
    }
    first
}

/// Whether edges `i < j` of the closed polygon meet although they should not (see
/// [`polygon_self_intersection`]).
fn edges_meet(poly: &[Vec2], i: usize, j: usize) -> bool {
    let n = poly.len();
    let edge = |i: usize| (poly[i], poly[(i + 1) % n]);
    let (a, b) = edge(i);
    let (c, d) = edge(j);
    let adjacent = j == i + 1 || (i == 0 && j == n - 1);
    if adjacent {
        // They share one vertex; they overlap only if the far vertex of one lies on the
        // other, collinear and inside it (a spike folding back).
        let (shared, p, q) = if j == i + 1 { (b, a, d) } else { (a, b, c) };
        orientation(p, shared, q) == 0
            && ((q.0 - shared.0) * (p.0 - shared.0) + (q.1 - shared.1) * (p.1 - shared.1)) > 0.0
    } else {
        segments_intersect(a, b, c, d)
    }
}

/// [`polygon_self_intersection`] by testing every pair of edges in order, O(n²): the oracle
/// of its tests.
#[cfg(test)]
fn self_intersection_brute_force(poly: &[Vec2]) -> Option<(usize, usize)> {
    let n = poly.len();
    if n < 3 {
        return None;
    }
    (0..n)
        .flat_map(|i| (i + 1..n).map(move |j| (i, j)))
        .find(|&(i, j)| edges_meet(poly, i, j))
}

impl Obstacle {
    /// Signed distance from `p` to the obstacle's solid, metres: positive outside,
    /// zero on the boundary, negative inside (minus the depth to the boundary).
    pub fn signed_distance(&self, p: Vec2) -> f64 {
        match self {
            Obstacle::Rect { min, max } => {
                let dx = (min.0 - p.0).max(p.0 - max.0);
                let dy = (min.1 - p.1).max(p.1 - max.1);
                if dx <= 0.0 && dy <= 0.0 {
                    dx.max(dy)
                } else {
                    dx.max(0.0).hypot(dy.max(0.0))
                }
            }
            Obstacle::Circle { center, radius } => norm(sub(p, *center)) - radius,
            Obstacle::Polygon { points } => {
                let n = points.len();
                let d = (0..n)
                    .map(|i| segment_distance(p, points[i], points[(i + 1) % n]))
                    .fold(f64::INFINITY, f64::min);
                if point_in_polygon(p, points) { -d } else { d }
            }
            Obstacle::Wall {
                from,
                to,
                thickness,
            } => segment_distance(p, *from, *to) - thickness / 2.0,
        }
    }

    /// Unsigned distance from `p` to the obstacle's solid, metres: zero inside or on it.
    pub fn distance(&self, p: Vec2) -> f64 {
        self.signed_distance(p).max(0.0)
    }

    /// Axis-aligned bounding box `(min, max)` of the solid.
    pub fn bounding_box(&self) -> (Vec2, Vec2) {
        match self {
            Obstacle::Rect { min, max } => (*min, *max),
            Obstacle::Circle { center, radius } => (
                (center.0 - radius, center.1 - radius),
                (center.0 + radius, center.1 + radius),
            ),
            Obstacle::Polygon { points } => points.iter().fold(
                (
                    (f64::INFINITY, f64::INFINITY),
                    (f64::NEG_INFINITY, f64::NEG_INFINITY),
                ),
                |(lo, hi), p| {
                    (
                        (lo.0.min(p.0), lo.1.min(p.1)),
                        (hi.0.max(p.0), hi.1.max(p.1)),
                    )
                },
            ),
            Obstacle::Wall {
                from,
                to,
                thickness,
            } => {
                let h = thickness / 2.0;
                (
                    (from.0.min(to.0) - h, from.1.min(to.1) - h),
                    (from.0.max(to.0) + h, from.1.max(to.1) + h),
                )
            }
        }
    }
}

impl World {
    /// Signed clearance of `p`: the distance to the nearest obstacle or arena side,
    /// negative inside an obstacle or outside the arena.
    pub fn clearance(&self, p: Vec2) -> f64 {
        let (w, h) = (self.arena.width, self.arena.height);
        let walls = p.0.min(w - p.0).min(p.1).min(h - p.1);
        self.obstacles
            .iter()
            .map(|o| o.signed_distance(p))
            .fold(walls, f64::min)
    }

    /// Whether a disc of radius `clearance` centred at `p` fits in the free space.
    pub fn is_free(&self, p: Vec2, clearance: f64) -> bool {
        self.clearance(p) > clearance
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};

    /// The per-cell test that `clear_polygon_cells` replaces.
    fn cells_one_by_one(points: &[Vec2], margin: f64, b: CellBlock, free: &mut [bool]) {
        let o = Obstacle::Polygon {
            points: points.to_vec(),
        };
        for i in b.cols.0..=b.cols.1 {
            for j in b.rows.0..=b.rows.1 {
                let c = i * b.ny + j;
                if free[c] {
                    let p = (
                        b.origin.0 + (i as f64 + 0.5) * b.cell.0,
                        b.origin.1 + (j as f64 + 0.5) * b.cell.1,
                    );
                    free[c] = o.signed_distance(p) > margin;
                }
            }
        }
    }

    #[test]
    fn polygon_cells_match_the_signed_distance_cell_by_cell() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let (nx, ny) = (160, 120);
        for case in 0..40 {
            let cell = if case % 2 == 0 {
                (0.02, 0.02)
            } else {
                (0.017, 0.023)
            };
            // A star-shaped polygon (non-convex) of 3 to 300 vertices about a random centre,
            // some with vertices on cell centres and axis-aligned edges.
            let vertices = [3, 4, 7, 40, 300][case % 5];
            let centre = (rng.random_range(0.5..2.7), rng.random_range(0.5..2.3));
            let mut points: Vec<Vec2> = (0..vertices)
                .map(|k| {
                    let a = std::f64::consts::TAU * k as f64 / vertices as f64;
                    let r = rng.random_range(0.2..1.2);
                    (centre.0 + r * a.cos(), centre.1 + r * a.sin())
                })
                .collect();
            if case % 4 == 1 {
                for p in &mut points {
                    p.0 = ((p.0 / cell.0).round() + 0.5) * cell.0;
                    p.1 = ((p.1 / cell.1).round() + 0.5) * cell.1;
                }
            }
            let margin = [0.0, 0.004, 0.0171, 0.2, -0.05][(case / 5) % 5];
            // Rasters anchored at the origin (the free-space rasters) and elsewhere (a
            // disc's samples, `FreeSpaceRaster::disc_free_area`).
            let origin = if case % 3 == 2 {
                (rng.random_range(-3.0..3.0), rng.random_range(-3.0..3.0))
            } else {
                (0.0, 0.0)
            };
            let block = CellBlock {
                cols: (rng.random_range(0..20), nx - 1 - rng.random_range(0..20)),
                rows: (rng.random_range(0..20), ny - 1 - rng.random_range(0..20)),
                ny,
                cell,
                origin,
            };
            // Some cells already blocked stay blocked.
            let start: Vec<bool> = (0..nx * ny).map(|_| rng.random_range(0..10) > 0).collect();
            let (mut fast, mut slow) = (start.clone(), start);
            let polygon = Obstacle::Polygon {
                points: points.clone(),
            };
            clear_obstacle_cells(&polygon, margin, block, &mut fast);
            cells_one_by_one(&points, margin, block, &mut slow);
            assert_eq!(fast, slow, "case {case}");
            assert!(
                fast.iter().any(|f| !f) && fast.iter().any(|f| *f),
                "case {case}"
            );
        }
    }

    #[test]
    fn polygon_centroids_match_closed_forms_and_survive_degenerate_input() {
        let near = |a: Vec2, b: Vec2, tol: f64| (a.0 - b.0).abs() < tol && (a.1 - b.1).abs() < tol;
        // A triangle's centroid is the mean of its vertices.
        let tri = [(0.0, 0.0), (3.0, 0.0), (0.0, 6.0)];
        assert!(near(polygon_centroid(&tri), (1.0, 2.0), 1e-12));
        // The same square far from the origin keeps its centre to a few ulp of 1e6.
        let sq = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)];
        let far: Vec<Vec2> = sq.iter().map(|p| (p.0 + 1e6, p.1 - 1e6)).collect();
        assert!(near(polygon_centroid(&far), (1e6 + 0.5, -1e6 + 0.5), 1e-9));
        // No area: the vertex mean; nothing: the origin.
        let line = [(0.0, 0.0), (1.0, 1.0), (3.0, 3.0)];
        assert!(near(polygon_centroid(&line), (4.0 / 3.0, 4.0 / 3.0), 1e-12));
        assert_eq!(polygon_centroid(&[(2.0, 4.0)]), (2.0, 4.0));
        assert_eq!(polygon_centroid(&[]), (0.0, 0.0));
    }

    #[test]
    fn distances_are_exact() {
        let r = Obstacle::Rect {
            min: (0.0, 0.0),
            max: (2.0, 1.0),
        };
        assert_eq!(r.signed_distance((3.0, 0.5)), 1.0);
        assert_eq!(r.signed_distance((1.0, 0.5)), -0.5);
        assert!((r.signed_distance((5.0, 5.0)) - 5.0).abs() < 1e-12);
        let c = Obstacle::Circle {
            center: (0.0, 0.0),
            radius: 1.0,
        };
        assert_eq!(c.signed_distance((3.0, 4.0)), 4.0);
        // Non-convex L-shaped polygon: the notch is outside.
        let l = Obstacle::Polygon {
            points: vec![
                (0.0, 0.0),
                (2.0, 0.0),
                (2.0, 1.0),
                (1.0, 1.0),
                (1.0, 2.0),
                (0.0, 2.0),
            ],
        };
        assert!(l.signed_distance((1.5, 1.5)) > 0.0);
        assert!((l.signed_distance((0.5, 0.5)) + 0.5).abs() < 1e-12);
        let w = Obstacle::Wall {
            from: (0.0, 0.0),
            to: (0.0, 4.0),
            thickness: 0.2,
        };
        assert!((w.signed_distance((1.0, 2.0)) - 0.9).abs() < 1e-12);
    }

    #[test]
    fn free_space_respects_arena_and_obstacles() {
        let mut w = World::empty("t", 10.0, 5.0);
        w.obstacles.push(Obstacle::Circle {
            center: (5.0, 2.5),
            radius: 1.0,
        });
        assert!(w.is_free((1.0, 1.0), 0.1));
        assert!(!w.is_free((0.05, 1.0), 0.1));
        assert!(!w.is_free((5.0, 3.45), 0.1));
        assert!(w.is_free((5.0, 3.7), 0.1));
    }

    /// Oracle for segment intersection on small integer coordinates: solve
    /// a + s(b − a) = c + t(d − c) exactly in i64 (Cramer's rule), with the collinear
    /// case settled by projecting onto the common line.
    fn intersect_oracle(a: (i64, i64), b: (i64, i64), c: (i64, i64), d: (i64, i64)) -> bool {
        let r = (b.0 - a.0, b.1 - a.1);
        let q = (d.0 - c.0, d.1 - c.1);
        let w = (c.0 - a.0, c.1 - a.1);
        let den = r.0 * q.1 - r.1 * q.0;
        if den != 0 {
            // s = (w × q) / den, t = (w × r) / den, both in [0, 1].
            let sn = w.0 * q.1 - w.1 * q.0;
            let tn = w.0 * r.1 - w.1 * r.0;
            let within = |n: i64| {
                if den > 0 {
                    0 <= n && n <= den
                } else {
                    den <= n && n <= 0
                }
            };
            return within(sn) && within(tn);
        }
        if w.0 * r.1 - w.1 * r.0 != 0 {
            return false; // parallel, distinct lines
        }
        // Collinear (or degenerate): compare intervals along the dominant axis, or points.
        let key = |p: (i64, i64)| if r.0 != 0 || q.0 != 0 { p.0 } else { p.1 };
        if r == (0, 0) && q == (0, 0) {
            return a == c;
        }
        if r == (0, 0) {
            let cross = (a.0 - c.0) * q.1 - (a.1 - c.1) * q.0;
            return cross == 0 && key(a) >= key(c).min(key(d)) && key(a) <= key(c).max(key(d));
        }
        if q == (0, 0) {
            let cross = (c.0 - a.0) * r.1 - (c.1 - a.1) * r.0;
            return cross == 0 && key(c) >= key(a).min(key(b)) && key(c) <= key(a).max(key(b));
        }
        key(a).max(key(b)) >= key(c).min(key(d)) && key(c).max(key(d)) >= key(a).min(key(b))
    }

    #[test]
    fn segment_intersection_matches_exact_oracle() {
        // Every segment pair on a 4 × 4 grid would be 65k² pairs; a deterministic
        // pseudo-random walk over them covers crossings, touchings and collinear overlaps.
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state % 4) as i64
        };
        // The grid as drawn, and shrunk to micrometres at x = 3 m (the tolerance must scale
        // with the segments, not with the coordinates alone).
        for (unit, at) in [(1.0, (0.0, 0.0)), (1e-6, (3.0, 1.0))] {
            for _ in 0..200_000 {
                let p: Vec<(i64, i64)> = (0..4).map(|_| (next(), next())).collect();
                let f = |q: (i64, i64)| (at.0 + q.0 as f64 * unit, at.1 + q.1 as f64 * unit);
                assert_eq!(
                    segments_intersect(f(p[0]), f(p[1]), f(p[2]), f(p[3])),
                    intersect_oracle(p[0], p[1], p[2], p[3]),
                    "{p:?} at unit {unit}"
                );
            }
        }
    }

    #[test]
    fn polygon_area_closed_forms() {
        let sq = [(0.0, 0.0), (2.0, 0.0), (2.0, 3.0), (0.0, 3.0)];
        assert_eq!(polygon_area(&sq), 6.0);
        let cw: Vec<Vec2> = sq.iter().rev().copied().collect();
        assert_eq!(polygon_area(&cw), -6.0);
        let l = [
            (0.0, 0.0),
            (2.0, 0.0),
            (2.0, 1.0),
            (1.0, 1.0),
            (1.0, 2.0),
            (0.0, 2.0),
        ];
        assert_eq!(polygon_area(&l), 3.0);
    }

    #[test]
    fn simple_polygons_are_recognised() {
        let l = [
            (0.0, 0.0),
            (2.0, 0.0),
            (2.0, 1.0),
            (1.0, 1.0),
            (1.0, 2.0),
            (0.0, 2.0),
        ];
        assert_eq!(polygon_self_intersection(&l), None);
        let tri = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0)];
        assert_eq!(polygon_self_intersection(&tri), None);
        // Bow tie: edge 0 (v0→v1) crosses edge 2 (v2→v3).
        let bow = [(0.0, 0.0), (2.0, 2.0), (2.0, 0.0), (0.0, 2.0)];
        assert_eq!(polygon_self_intersection(&bow), Some((0, 2)));
        // A vertex on a non-adjacent edge.
        let pinch = [(0.0, 0.0), (4.0, 0.0), (4.0, 4.0), (2.0, 0.0), (0.0, 4.0)];
        assert!(polygon_self_intersection(&pinch).is_some());
        // A spike folding back over its own edge, including across the closing vertex.
        let spike = [(1.0, 1.0), (3.0, 1.0), (2.0, 1.0), (2.0, 3.0)];
        assert!(polygon_self_intersection(&spike).is_some());
        let spike0 = [(2.0, 1.0), (2.0, 3.0), (1.0, 1.0), (3.0, 1.0)];
        assert!(polygon_self_intersection(&spike0).is_some());
        // Collinear consecutive vertices that continue straight on are fine.
        let straight = [(0.0, 0.0), (1.0, 0.0), (2.0, 0.0), (2.0, 1.0)];
        assert_eq!(polygon_self_intersection(&straight), None);
    }

    proptest::proptest! {
        /// Pruned by bounding boxes, the check finds the same first pair as testing every
        /// pair, on polygons drawn on a coarse grid (so that touching, collinear and
        /// repeated-edge cases are common) and scaled by an arbitrary factor.
        #[test]
        fn pruned_self_intersection_equals_all_pairs(
            grid in proptest::collection::vec((0i32..6, 0i32..6), 3..14),
            scale in 1e-3f64..1e3,
            shift in -50.0f64..50.0,
        ) {
            let poly: Vec<Vec2> = grid
                .iter()
                .map(|&(x, y)| (f64::from(x) * scale + shift, f64::from(y) * scale))
                .collect();
            proptest::prop_assert_eq!(
                polygon_self_intersection(&poly),
                self_intersection_brute_force(&poly)
            );
        }
    }

    #[test]
    fn a_long_outline_is_checked_whole() {
        // A 40 000-vertex star-shaped outline, simple; then one vertex moved across it.
        let n = 40_000;
        let mut poly: Vec<Vec2> = (0..n)
            .map(|i| {
                let t = std::f64::consts::TAU * i as f64 / n as f64;
                let r = 10.0 + if i % 2 == 0 { 0.5 } else { 0.0 };
                (15.0 + r * t.cos(), 15.0 + r * t.sin())
            })
            .collect();
        assert_eq!(polygon_self_intersection(&poly), None);
        poly[20_000] = (30.0, 15.0);
        // Its edge from vertex 19 999 now runs along y = 15 to x = 30 and crosses edge 0
        // (vertex 0 at (25.5, 15) to vertex 1): the first pair in order.
        assert_eq!(polygon_self_intersection(&poly), Some((0, 19_999)));
    }

    #[test]
    fn unsigned_distance_is_zero_inside() {
        let c = Obstacle::Circle {
            center: (0.0, 0.0),
            radius: 1.0,
        };
        assert_eq!(c.distance((0.5, 0.0)), 0.0);
        assert_eq!(c.distance((3.0, 0.0)), 2.0);
    }
}
