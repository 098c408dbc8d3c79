//! Which holes a local map found: each robust hole matched to an obstacle of the truth
//! (issue #4 §4, "compare the maps against ground-truth geometry"; paper §"Local Mapping").
//!
//! A window is scored right when its (β0, β1) equal the truth's, but equal counts could
//! hide two errors that cancel: a noise loop counted where an obstacle was missed. This
//! check names the holes. A robust hole carries a representative cycle, a closed chain of
//! encounters ([`crate::mapping::local::Hole::cycle`]); drawn through the encounters' *true*
//! positions (the log's truth columns), it is a closed polygonal 1-cycle of the arena. It
//! *encircles* a point p when its winding number round p is odd: the ray from p towards
//! +x crosses an odd number of its edges (a cycle mod 2 meets every vertex an even number
//! of times, so the parity is well defined; an edge is crossed when its endpoints lie on
//! either side of the ray's line, one strictly above and one not, which counts a vertex
//! on the line once). A straight edge between two true positions can cut the corner of an
//! obstacle, so a cycle encircles a true hole ([`crate::eval::truth::TrueHole`]) when it
//! encircles more than half of the hole's sampled cells, not one chosen point.
//!
//! Each robust hole is then matched to the one true hole it encircles (none when it
//! encircles none or several). The map's holes are right ([`HoleCheck::right`]) when every
//! one is matched, no two to the same obstacle, and every true hole is matched: the map
//! found exactly the obstacles the truth holds.
//!
//! Cost: O(h · t · s · e) for h robust holes, t true holes of s samples and cycles of e
//! edges; a few thousand operations a window.

use super::truth::TrueHole;
use crate::mapping::local::LocalMap;
use serde::{Deserialize, Serialize};

/// The robust holes of one window matched to the holes of its truth (`summary.json`,
/// `windows[i].holes`).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct HoleCheck {
    /// A point inside each hole of the truth, metres ([`TrueHole::inside`]), in the order
    /// of [`crate::eval::truth::FreeSpace::holes_in_band`].
    pub truth: Vec<[f64; 2]>,
    /// Per robust hole of the map, in the order of `maps/window_<i>.json` (components,
    /// then each component's holes): the index into `truth` of the hole its cycle
    /// encircles at its events' true positions, or `null` when it encircles none or more
    /// than one.
    pub found: Vec<Option<usize>>,
}

impl HoleCheck {
    /// Whether the map found exactly the truth's holes: every robust hole encircles one
    /// true hole, no two the same one, and no true hole is left over.
    pub fn right(&self) -> bool {
        self.found.len() == self.truth.len() && self.matched() == self.truth.len()
    }

    /// Whether a global map found exactly the truth's holes: every local hole it kept
    /// encircles one true hole of the arena, no two the same one, and the true holes left
    /// over are as many as its `gluing_cycles` (holes no single window saw whole, which
    /// carry no cycle to match). With no gluing cycle this is [`HoleCheck::right`].
    pub fn right_with_gluing(&self, gluing_cycles: usize) -> bool {
        self.spurious() == 0 && self.found.len() + gluing_cycles == self.truth.len()
    }

    /// Number of true holes that some robust hole encircles.
    pub fn matched(&self) -> usize {
        let mut hit = vec![false; self.truth.len()];
        for &t in self.found.iter().flatten() {
            hit[t] = true;
        }
        hit.iter().filter(|&&h| h).count()
    }

    /// The true holes no robust hole encircles (indices into `truth`).
    pub fn missed(&self) -> Vec<usize> {
        (0..self.truth.len())
            .filter(|t| !self.found.contains(&Some(*t)))
            .collect()
    }

    /// Robust holes that encircle no true hole or several, or one already encircled by
    /// an earlier robust hole: the map's holes that are not obstacles of the truth.
    pub fn spurious(&self) -> usize {
        let mut seen = vec![false; self.truth.len()];
        let mut n = 0;
        for f in &self.found {
            match *f {
                Some(t) if !seen[t] => seen[t] = true,
                _ => n += 1,
            }
        }
        n
    }
}

/// Whether the closed edge chain `edges` over `points` winds an odd number of times round
/// `p` (parity of the crossings of the ray from `p` towards +x; see the module docs).
pub fn encircles(points: &[[f64; 2]], edges: &[(usize, usize)], p: [f64; 2]) -> bool {
    let mut odd = false;
    for &(a, b) in edges {
        let (u, v) = (points[a], points[b]);
        if (u[1] > p[1]) != (v[1] > p[1]) {
            let x = u[0] + (p[1] - u[1]) * (v[0] - u[0]) / (v[1] - u[1]);
            if x > p[0] {
                odd = !odd;
            }
        }
    }
    odd
}

/// The true holes (indices into `holes`) that the cycle `edges` over `points` encircles:
/// those with more than half of their samples encircled.
pub fn encircled(points: &[[f64; 2]], edges: &[(usize, usize)], holes: &[TrueHole]) -> Vec<usize> {
    holes
        .iter()
        .enumerate()
        .filter(|(_, h)| {
            let inside = h
                .samples
                .iter()
                .filter(|&&s| encircles(points, edges, s))
                .count();
            2 * inside > h.samples.len()
        })
        .map(|(i, _)| i)
        .collect()
}

/// Matches the robust holes of `map` to the true holes `holes` of its window, with
/// `truth` the true position of each of the window's events (indexed like `map.events`).
pub fn check(map: &LocalMap, truth: &[[f64; 2]], holes: &[TrueHole]) -> HoleCheck {
    let found = map
        .components
        .iter()
        .flat_map(|c| &c.holes)
        .map(|h| match encircled(truth, &h.cycle, holes).as_slice() {
            [t] => Some(*t),
            _ => None,
        })
        .collect();
    HoleCheck {
        truth: holes.iter().map(|h| h.inside).collect(),
        found,
    }
}

/// Matches the local holes a global map kept (`global.holes`, after merging the holes
/// two consecutive maps share) to the true holes `holes` of the whole arena
/// ([`crate::eval::truth::FreeSpace::holes_in_band`] over its width); `None` without the
/// log's truth columns.
pub fn check_global(
    maps: &[LocalMap],
    global: &crate::mapping::stitch::GlobalMap,
    log: &crate::log::EncounterLog,
    holes: &[TrueHole],
) -> Option<HoleCheck> {
    let mut positions: std::collections::HashMap<usize, Vec<[f64; 2]>> = Default::default();
    let mut found = Vec::with_capacity(global.holes.len());
    for &(window, c, h) in &global.holes {
        let map = maps.iter().find(|m| m.index == window)?;
        let truth = match positions.entry(window) {
            std::collections::hash_map::Entry::Occupied(e) => e.into_mut(),
            std::collections::hash_map::Entry::Vacant(e) => {
                e.insert(crate::mapping::pipeline::true_positions(map, log)?)
            }
        };
        let cycle = &map.components.get(c)?.mark(h)?.cycle;
        found.push(match encircled(truth, cycle, holes).as_slice() {
            [t] => Some(*t),
            _ => None,
        });
    }
    Some(HoleCheck {
        truth: holes.iter().map(|h| h.inside).collect(),
        found,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A square cycle of side 2 round the origin, as four points and four edges.
    fn square(c: [f64; 2], r: f64) -> (Vec<[f64; 2]>, Vec<(usize, usize)>) {
        let p = vec![
            [c[0] - r, c[1] - r],
            [c[0] + r, c[1] - r],
            [c[0] + r, c[1] + r],
            [c[0] - r, c[1] + r],
        ];
        (p, vec![(0, 1), (1, 2), (2, 3), (3, 0)])
    }

    fn hole_at(c: [f64; 2], r: f64) -> TrueHole {
        // A 4 × 4 lattice of samples filling the square [c − r, c + r]².
        let samples = (0..16)
            .map(|k| {
                let (i, j) = ((k / 4) as f64, (k % 4) as f64);
                [
                    c[0] - r + (i + 0.5) * r / 2.0,
                    c[1] - r + (j + 0.5) * r / 2.0,
                ]
            })
            .collect();
        TrueHole {
            inside: c,
            area: 4.0 * r * r,
            samples,
        }
    }

    #[test]
    fn parity_of_a_square_and_of_a_figure_of_two_loops() {
        let (p, e) = square([0.0, 0.0], 1.0);
        assert!(encircles(&p, &e, [0.0, 0.0]));
        assert!(encircles(&p, &e, [0.9, -0.9]));
        assert!(!encircles(&p, &e, [1.5, 0.0]));
        assert!(!encircles(&p, &e, [-1.5, 0.0]));
        // A point level with a vertex: the vertex is counted once, not twice.
        assert!(encircles(&p, &e, [0.0, -1.0 + 1e-12]));
        assert!(!encircles(&p, &e, [-2.0, 1.0]));
        // Two disjoint squares as one cycle mod 2: each encircles its own centre only.
        let (mut q, mut f) = square([5.0, 0.0], 1.0);
        let off = p.len();
        q.splice(0..0, p.iter().copied());
        f = f.into_iter().map(|(a, b)| (a + off, b + off)).collect();
        f.extend(e.iter().copied());
        assert!(encircles(&q, &f, [0.0, 0.0]));
        assert!(encircles(&q, &f, [5.0, 0.0]));
        assert!(!encircles(&q, &f, [2.5, 0.0]));
    }

    #[test]
    fn a_cycle_encircles_the_holes_most_of_whose_cells_it_surrounds() {
        let holes = [hole_at([0.0, 0.0], 0.5), hole_at([3.0, 0.0], 0.5)];
        let (p, e) = square([0.0, 0.0], 1.0);
        assert_eq!(encircled(&p, &e, &holes), vec![0]);
        // A loop round both obstacles encircles both.
        let (p, e) = square([1.5, 0.0], 2.5);
        assert_eq!(encircled(&p, &e, &holes), vec![0, 1]);
        // A loop through the middle of the first hole surrounds half its cells, not more.
        let (p, e) = square([-0.75, 0.0], 0.8);
        assert_eq!(encircled(&p, &e, &holes), Vec::<usize>::new());
    }

    #[test]
    fn right_needs_every_hole_found_once_and_nothing_else() {
        let h = |found: Vec<Option<usize>>| HoleCheck {
            truth: vec![[0.0, 0.0], [3.0, 0.0]],
            found,
        };
        assert!(h(vec![Some(1), Some(0)]).right());
        let twice = h(vec![Some(0), Some(0)]);
        assert!(!twice.right());
        assert_eq!(
            (twice.matched(), twice.missed(), twice.spurious()),
            (1, vec![1], 1)
        );
        let noise = h(vec![Some(0), None]);
        assert!(!noise.right());
        assert_eq!((noise.missed(), noise.spurious()), (vec![1], 1));
        let short = h(vec![Some(1)]);
        assert!(!short.right());
        assert_eq!((short.missed(), short.spurious()), (vec![0], 0));
        assert!(HoleCheck::default().right());
        // A global map: one hole found by a window, one closed by the gluing graph.
        let glued = h(vec![Some(1)]);
        assert!(glued.right_with_gluing(1));
        assert!(!glued.right_with_gluing(0));
        assert!(!h(vec![Some(1), None]).right_with_gluing(0));
        assert!(h(vec![Some(1), Some(0)]).right_with_gluing(0));
    }
}
