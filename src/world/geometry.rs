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
}
