//! Ground truth: the Betti numbers (β0, β1) of the free space the swarm can actually
//! reach, inside a vertical band of the arena or over all of it (issue #4 §4, issue #5 §2;
//! paper §"Problem Statement", §"Local Mapping", §"Global Mapping").
//!
//! # What is counted
//!
//! - **Free space F.** The positions of an agent's *centre*: points at clearance strictly
//!   greater than the body radius r, i.e. the arena shrunk by r minus every obstacle grown
//!   by r. A passage narrower than 2r is closed.
//! - **Reachable free space R.** The part of F that the swarm can walk into while it stays
//!   in the moving domain D(t) (the motion model turns back every agent that leaves it): the
//!   points of F joined, inside D(0), to the initial placement region (`swarm.placement`:
//!   the disc of its radius around `(leader.start_x, height / 2)`, or D(0) itself for
//!   `Window`), and then every point joined inside some D(t) to what was reachable before.
//!   A pocket that no agent can enter (the inside of a ring obstacle) is not space the swarm
//!   can map, so the ring with its pocket counts as one solid obstacle; likewise a lane that
//!   opens only ahead of the swarm, and only where the domain has already passed it (the
//!   lanes beside `worlds/corridor.ron`'s corridor, which no agent enters before x = 17 m),
//!   is not counted. Computed on the raster by a flood fill that follows the domain's
//!   leading edge column by column (`swept`): each cell enters once, and records the step at
//!   which it did. On every other bundled and training world R is the whole of F's
//!   components that meet the placement, as it was before this rule (ninth session; README,
//!   "Ground truth").
//! - **R by a time t** ([`FreeSpace::reached_by`]): the part of R the sweep has entered by
//!   t. R only grows, and a cell enters it when the domain's leading edge reaches a place
//!   from which the swarm can walk to it inside D(t).
//! - **A window's truth.** The domain of window W_i = [a, b] is the band
//!   D_i = ∪_{t∈W_i} D(t) = [domain(a).0, domain(b).1] (the leader moves monotonically; see
//!   [`window_band`]). β0 is the number of components of R(b) ∩ D_i, R as it stood at the
//!   window's end: free space of the band that the swarm can enter only later (a pocket
//!   whose entrance lies ahead of D(t) throughout the window, like the U of
//!   `worlds/nonconvex.ron` in its W1) holds no encounter of the window. β1 counts the holes
//!   that lie wholly inside the band: bounded components of the complement of R(b) ∩ D_i
//!   that touch neither the band's left or right edge nor the arena's top or bottom wall. An
//!   obstacle cut by the band's edge, or touching (within 2r of) a wall, is part of the
//!   outside, not a hole: the swarm cannot walk around it inside the band. (Space not yet
//!   entered by b reaches the band's leading edge, since it can only be entered from beyond
//!   it, so it never closes a hole that R does not have.)
//! - **Connections between windows i and i+1.** The number of components of R(b) inside the
//!   overlap band D_i ∩ D_{i+1} ([`overlap`]), b the end of W_i and of the overlap: each is
//!   a corridor through which the two local maps are glued.
//! - **Global truth.** (β0, β1) of R over the whole arena.
//!
//! # Method: a cached raster
//!
//! The arena is cut into square cells of side h (the resolution, default
//! [`DEFAULT_RESOLUTION`] = 1 cm). A cell is *free* when the whole closed cell lies in F:
//! clearance is 1-Lipschitz, so it suffices that the clearance at the cell centre exceeds
//! r + h/√2. This inner approximation has a one-sided guarantee: every 4-path of free cells
//! is a path in F, so the raster never invents a passage and never loses an obstacle, however
//! thin. Its only error is to close passages narrower than about 2r + 2.5 h (≈ 4 cm at the
//! default), or to cut off parts of F thinner than that; the bundled worlds have no gap
//! under 0.5 m, and the tests check that 0.5, 1 and 2 cm give the same answers.
//!
//! Free cells are 4-connected and the complement is 8-connected. This is the dual pair of
//! digital topology for which the digital Jordan curve theorem holds (Rosenfeld, "Connectivity
//! in digital pictures", J. ACM 1970; Kong & Rosenfeld, "Digital topology: introduction and
//! survey", CVGIP 1989): the bounded 8-components of the complement are exactly the holes of
//! the 4-connected foreground, and β0 − β1 equals the Euler characteristic V − E + F of the
//! cubical complex (cells, 4-adjacencies, full 2 × 2 blocks), which the tests use as an
//! independent check. For a band query the band is padded with a ring of "outside" cells:
//! a complement component that reaches the band's first or last column or row is connected to
//! that ring and is therefore not a hole.
//!
//! # Cost
//!
//! Cells are stored column-major, so a band is one contiguous slice. Construction rasterises
//! each obstacle over its own bounding box: O(n_cells + Σ bbox cells) for discs,
//! rectangles and walls; a polygon's cells take one pass of each row over its edges and
//! each edge's distance only near that edge (`world::clear_obstacle_cells`) rather than
//! every edge at every cell of its box; it then labels the components of F once by flood fill (O(n_cells)); a 30 m × 10 m arena at
//! 1 cm (3 M cells) with four obstacles takes about 0.15 s in a release build. A band query
//! labels only the band's cells, O(band cells) with a fresh scratch buffer (so [`FreeSpace`]
//! is `Sync` and can be shared by parallel evaluation): 3–5 ms for a 3 m band (test
//! `paper_sized_arena_is_fast` in `tests/truth.rs` prints both).

use thiserror::Error;

use crate::world::{CellBlock, Placement, Vec2, World, clear_obstacle_cells};

/// Default raster resolution in metres (`0.01`, i.e. 1 cm).
pub const DEFAULT_RESOLUTION: f64 = 0.01;

/// The resolution of a world's truth ([`FreeSpace::for_world`]): [`DEFAULT_RESOLUTION`],
/// or, on an arena of more than [`MAX_CELLS`] square centimetres (20 000 m², e.g. 3 000 m
/// × 10 m), the finest square cell that keeps the raster within [`MAX_CELLS`] cells (found
/// by the forty-first session's review: such an arena could be simulated but its runs
/// neither evaluated nor mapped). Passages narrower than about 2 · body radius + 2.5 ·
/// resolution then count as closed.
pub fn resolution_for(width: f64, height: f64) -> f64 {
    let cells = |h: f64| (width / h).ceil() * (height / h).ceil();
    let mut h = DEFAULT_RESOLUTION
        .max((width * height / MAX_CELLS as f64).sqrt())
        .max(width.max(height) / MAX_CELLS as f64);
    // The ceilings can add a row and a column: steps of 1 % find a side that fits, and
    // halving the last step brings it to the finest that does.
    let first = h;
    for _ in 0..1000 {
        if cells(h) <= MAX_CELLS as f64 {
            break;
        }
        h *= 1.01;
    }
    if h > first {
        let mut too_fine = h / 1.01;
        for _ in 0..50 {
            let mid = 0.5 * (too_fine + h);
            if cells(mid) <= MAX_CELLS as f64 {
                h = mid;
            } else {
                too_fine = mid;
            }
        }
    }
    h
}

/// Largest raster accepted by [`FreeSpace::new`], in cells (`200_000_000`, about 1 GB).
pub const MAX_CELLS: usize = 200_000_000;

/// How far [`FreeSpace::component_of`] and [`BandComponents::component_of`] look for a
/// reachable cell around a point that falls on a non-free cell, in cells (`3`).
pub const SNAP_CELLS: usize = 3;

const NONE: u32 = u32::MAX;

/// Errors building a [`FreeSpace`].
#[derive(Debug, Error, Clone, PartialEq)]
pub enum TruthError {
    /// The resolution is not a positive finite number.
    #[error("raster resolution must be a positive number of metres, got {0} (try 0.01)")]
    BadResolution(f64),
    /// The arena's size is not a positive finite number.
    #[error("arena must have a positive finite size, got {width} m × {height} m")]
    BadArena { width: f64, height: f64 },
    /// The raster would be too large.
    #[error(
        "a {width} m × {height} m arena at {resolution} m resolution needs {cells} cells, \
         more than the limit of {max}; use a coarser resolution"
    )]
    TooManyCells {
        width: f64,
        height: f64,
        resolution: f64,
        cells: f64,
        max: usize,
    },
}

/// The reachable free space of a world, rasterised once; answers band queries fast.
///
/// See the module documentation for the semantics and the method.
#[derive(Debug, Clone)]
pub struct FreeSpace {
    resolution: f64,
    body_radius: f64,
    /// Number of columns (along x).
    nx: usize,
    /// Number of rows (along y).
    ny: usize,
    /// Column-major: cell `(i, j)` (column i, row j) is at `i * ny + j`.
    reach: Vec<bool>,
    /// When each cell of R entered it: the number of columns the domain's leading edge had
    /// advanced past its start (0 for the dispersion's flood); `NONE` off R.
    entered: Vec<u32>,
    /// The leading edge's column at t = 0, and whether it moves right (else left).
    lead_start: usize,
    rightward: bool,
    /// Label of the reachable component of each cell (`NONE` off R).
    comp: Vec<u32>,
    components: usize,
    holes: usize,
}

/// One hole of the reachable free space inside a band ([`FreeSpace::holes_in_band`]): an
/// obstacle (grown by the body radius, with any pocket no agent can enter) that the swarm
/// can walk round inside the band.
#[derive(Debug, Clone, PartialEq)]
pub struct TrueHole {
    /// The hole's cell centre nearest the mean of its cells (metres): a point to name it by,
    /// inside it for every convex or L-shaped obstacle.
    pub inside: [f64; 2],
    /// Its area, m².
    pub area: f64,
    /// Up to [`HOLE_SAMPLES`] of its cell centres, spread evenly over its cells in
    /// column-major order: a cycle encircles the hole when it encircles most of them.
    pub samples: Vec<[f64; 2]>,
}

/// How many cell centres of a hole [`TrueHole::samples`] keeps.
pub const HOLE_SAMPLES: usize = 32;

/// The components of R ∩ band, labelled; built by [`FreeSpace::label_band`].
#[derive(Debug, Clone)]
pub struct BandComponents {
    resolution: f64,
    /// First column of the band.
    c0: usize,
    ncols: usize,
    ny: usize,
    labels: Vec<u32>,
    count: usize,
}

impl FreeSpace {
    /// Rasterises the reachable free space of `world` at `resolution` metres per cell
    /// (use [`DEFAULT_RESOLUTION`], 1 cm, unless the world has passages narrower than about
    /// 2 · body radius + 2.5 · resolution).
    pub fn new(world: &World, resolution: f64) -> Result<Self, TruthError> {
        if !(resolution.is_finite() && resolution > 0.0) {
            return Err(TruthError::BadResolution(resolution));
        }
        let (width, height) = (world.arena.width, world.arena.height);
        if !(width.is_finite() && height.is_finite() && width > 0.0 && height > 0.0) {
            return Err(TruthError::BadArena { width, height });
        }
        let (fx, fy) = ((width / resolution).ceil(), (height / resolution).ceil());
        if fx * fy > MAX_CELLS as f64 {
            return Err(TruthError::TooManyCells {
                width,
                height,
                resolution,
                cells: fx * fy,
                max: MAX_CELLS,
            });
        }
        // Both are at least 1 and their product fits, so the casts are exact.
        let (nx, ny) = ((fx as usize).max(1), (fy as usize).max(1));
        let h = resolution;
        let r = world.swarm.body_radius.max(0.0);
        // A cell is free when its centre has clearance > r + h/√2 (the whole cell is in F).
        let margin = r + h * std::f64::consts::FRAC_1_SQRT_2;
        let centre = |k: usize| (k as f64 + 0.5) * h;

        let col_ok: Vec<bool> = (0..nx)
            .map(|i| {
                let x = centre(i);
                x > margin && width - x > margin
            })
            .collect();
        let row_ok: Vec<bool> = (0..ny)
            .map(|j| {
                let y = centre(j);
                y > margin && height - y > margin
            })
            .collect();
        let mut free = vec![false; nx * ny];
        for (i, &c) in col_ok.iter().enumerate() {
            if c {
                for (j, &rw) in row_ok.iter().enumerate() {
                    free[i * ny + j] = rw;
                }
            }
        }
        for obstacle in &world.obstacles {
            let (lo, hi) = obstacle.bounding_box();
            let Some((i0, i1)) = index_range(lo.0 - margin, hi.0 + margin, h, nx) else {
                continue;
            };
            let Some((j0, j1)) = index_range(lo.1 - margin, hi.1 + margin, h, ny) else {
                continue;
            };
            let block = CellBlock {
                cols: (i0, i1),
                rows: (j0, j1),
                ny,
                cell: (h, h),
                origin: (0.0, 0.0),
            };
            // A NaN distance blocks the cell: never free by accident.
            clear_obstacle_cells(obstacle, margin, block, &mut free);
        }

        // The free cells of the placement region; R grows from them (`swept`).
        let mut seeds: Vec<usize> = Vec::new();
        let mut mark = |i: usize, j: usize| {
            if free[i * ny + j] {
                seeds.push(i * ny + j);
            }
        };
        match world.swarm.placement {
            Placement::Disk { radius } => {
                let c = (world.leader.start_x, height / 2.0);
                let rad = radius.max(0.0);
                if let (Some((i0, i1)), Some((j0, j1))) = (
                    index_range(c.0 - rad - h, c.0 + rad + h, h, nx),
                    index_range(c.1 - rad - h, c.1 + rad + h, h, ny),
                ) {
                    for i in i0..=i1 {
                        for j in j0..=j1 {
                            // Distance from the disc centre to the closed cell.
                            let dx = (i as f64 * h - c.0).max(c.0 - (i + 1) as f64 * h);
                            let dy = (j as f64 * h - c.1).max(c.1 - (j + 1) as f64 * h);
                            if dx.max(0.0).hypot(dy.max(0.0)) <= rad {
                                mark(i, j);
                            }
                        }
                    }
                }
            }
            Placement::Window => {
                let (a, b) = world.domain(0.0);
                // Columns whose cells meet [a, b].
                let i0 = (a / h).floor().max(0.0);
                let i1 = ((b / h).ceil() - 1.0).min(nx as f64 - 1.0);
                if i0 <= i1 {
                    for i in i0 as usize..=i1 as usize {
                        for j in 0..ny {
                            mark(i, j);
                        }
                    }
                }
            }
        }
        let sweep = swept(&free, &seeds, world, h, nx, ny);
        let reach: Vec<bool> = sweep.entered.iter().map(|&e| e != NONE).collect();
        let (comp, components) = label_4(&reach, nx, ny);
        let holes = count_holes_8(&reach, nx, ny);
        Ok(Self {
            resolution,
            body_radius: r,
            nx,
            ny,
            reach,
            entered: sweep.entered,
            lead_start: sweep.lead_start,
            rightward: sweep.rightward,
            comp,
            components,
            holes,
        })
    }

    /// [`FreeSpace::new`] at [`resolution_for`] the world's arena: [`DEFAULT_RESOLUTION`]
    /// (1 cm) unless the arena is too large for [`MAX_CELLS`] cells of it.
    pub fn for_world(world: &World) -> Result<Self, TruthError> {
        Self::new(world, resolution_for(world.arena.width, world.arena.height))
    }

    /// Cell side in metres.
    pub fn resolution(&self) -> f64 {
        self.resolution
    }

    /// Agent body radius used to grow the obstacles, metres.
    pub fn body_radius(&self) -> f64 {
        self.body_radius
    }

    /// Raster size `(columns along x, rows along y)`.
    pub fn dims(&self) -> (usize, usize) {
        (self.nx, self.ny)
    }

    /// Whether cell `(i, j)` (column `i` from x = 0, row `j` from y = 0) is reachable free
    /// space; `false` outside the raster.
    pub fn is_reachable_cell(&self, i: usize, j: usize) -> bool {
        i < self.nx && j < self.ny && self.reach[i * self.ny + j]
    }

    /// Whether the cell containing `p` (metres) is reachable free space (no snapping).
    pub fn is_reachable(&self, p: Vec2) -> bool {
        self.cell_of(p)
            .is_some_and(|(i, j)| self.reach[i * self.ny + j])
    }

    /// Area of the reachable free space in m² (cells × h²).
    pub fn reachable_area(&self) -> f64 {
        self.reach.iter().filter(|&&b| b).count() as f64 * self.resolution * self.resolution
    }

    /// True global (β0, β1): of R over the whole arena.
    pub fn global_betti(&self) -> [usize; 2] {
        [self.components, self.holes]
    }

    /// The global component of R that contains `p` (metres), numbered `0..β0` in the order
    /// of their first cell (column-major); a point on a non-reachable cell snaps to the
    /// nearest reachable cell within [`SNAP_CELLS`] cells; `None` if there is none.
    pub fn component_of(&self, p: Vec2) -> Option<usize> {
        snap(p, self.resolution, self.nx, self.ny, |k| self.comp[k])
    }

    /// R as it stood at time `t` of the run (seconds): the cells the swarm could have walked
    /// into by then, while staying in the moving domain. A window's truth and the truth of
    /// the connections at its end are taken at the window's end: free space that only opens
    /// to the swarm later (a pocket of the window's band whose entrance D(t) reaches after
    /// the window) is no space the window's encounters can map. `world` must be the world
    /// this raster was built from.
    pub fn reached_by(&self, world: &World, t: f64) -> Reached<'_> {
        if t >= world.total_duration() {
            return self.reached();
        }
        let (a, b) = world.domain(t);
        let h = self.resolution;
        // The leading edge has passed the columns whose centres it has reached, as in `swept`.
        let step = if self.rightward {
            let lead = ((b / h - 0.5).floor().max(0.0) as usize).min(self.nx - 1);
            lead.saturating_sub(self.lead_start)
        } else {
            let lead = ((a / h - 0.5).ceil().max(0.0) as usize).min(self.nx - 1);
            self.lead_start.saturating_sub(lead)
        };
        Reached {
            fs: self,
            step: u32::try_from(step).unwrap_or(NONE - 1),
        }
    }

    /// All of R, as the sweep leaves it: the global truth's space.
    pub fn reached(&self) -> Reached<'_> {
        Reached {
            fs: self,
            step: NONE - 1,
        }
    }

    /// True (β0, β1) of R ∩ [x0, x1] × [0, height] (x in metres; the band holds the columns
    /// whose centres lie in [x0, x1]; an empty or non-finite band gives `[0, 0]`).
    pub fn betti_in_band(&self, x0: f64, x1: f64) -> [usize; 2] {
        self.reached().betti_in_band(x0, x1)
    }

    /// Number of components of R ∩ [x0, x1] × [0, height] (β0 of the band).
    pub fn components_in_band(&self, x0: f64, x1: f64) -> usize {
        self.reached().components_in_band(x0, x1)
    }

    /// Labels the components of R ∩ [x0, x1] × [0, height], for matching points to them.
    pub fn label_band(&self, x0: f64, x1: f64) -> BandComponents {
        self.reached().label_band(x0, x1)
    }

    /// The holes of R ∩ [x0, x1] × [0, height] ([`Reached::holes_in_band`]).
    pub fn holes_in_band(&self, x0: f64, x1: f64) -> Vec<TrueHole> {
        self.reached().holes_in_band(x0, x1)
    }

    /// The columns whose centres lie in [x0, x1], or `None` if there are none.
    fn columns(&self, x0: f64, x1: f64) -> Option<(usize, usize)> {
        index_range(x0, x1, self.resolution, self.nx)
    }

    fn cell_of(&self, p: Vec2) -> Option<(usize, usize)> {
        cell_of(p, self.resolution, self.nx, self.ny)
    }
}

/// R as it stood at one moment of the sweep ([`FreeSpace::reached_by`], or all of it:
/// [`FreeSpace::reached`]); answers the same band queries as [`FreeSpace`].
#[derive(Debug, Clone, Copy)]
pub struct Reached<'a> {
    fs: &'a FreeSpace,
    /// Cells that entered R at this step of the sweep or before are in it.
    step: u32,
}

impl Reached<'_> {
    /// The band's columns `c0..=c1` of this R: a slice of the raster when it is all of R
    /// there, else a copy with the later cells cleared.
    fn band(&self, c0: usize, c1: usize) -> std::borrow::Cow<'_, [bool]> {
        let range = c0 * self.fs.ny..(c1 + 1) * self.fs.ny;
        let entered = &self.fs.entered[range.clone()];
        if entered.iter().all(|&e| e == NONE || e <= self.step) {
            std::borrow::Cow::Borrowed(&self.fs.reach[range])
        } else {
            std::borrow::Cow::Owned(entered.iter().map(|&e| e <= self.step).collect())
        }
    }

    /// True (β0, β1) of R ∩ [x0, x1] × [0, height] (x in metres; the band holds the columns
    /// whose centres lie in [x0, x1]; an empty or non-finite band gives `[0, 0]`).
    pub fn betti_in_band(&self, x0: f64, x1: f64) -> [usize; 2] {
        match self.fs.columns(x0, x1) {
            None => [0, 0],
            Some((c0, c1)) => {
                let slice = self.band(c0, c1);
                let ncols = c1 - c0 + 1;
                let (_, b0) = label_4(&slice, ncols, self.fs.ny);
                [b0, count_holes_8(&slice, ncols, self.fs.ny)]
            }
        }
    }

    /// Number of components of R ∩ [x0, x1] × [0, height] (β0 of the band; the true number
    /// of connections when the band is the overlap of two windows' domains).
    pub fn components_in_band(&self, x0: f64, x1: f64) -> usize {
        self.label_band(x0, x1).count()
    }

    /// Labels the components of R ∩ [x0, x1] × [0, height], for matching points to them.
    pub fn label_band(&self, x0: f64, x1: f64) -> BandComponents {
        match self.fs.columns(x0, x1) {
            None => BandComponents {
                resolution: self.fs.resolution,
                c0: 0,
                ncols: 0,
                ny: self.fs.ny,
                labels: Vec::new(),
                count: 0,
            },
            Some((c0, c1)) => {
                let slice = self.band(c0, c1);
                let ncols = c1 - c0 + 1;
                let (labels, count) = label_4(&slice, ncols, self.fs.ny);
                BandComponents {
                    resolution: self.fs.resolution,
                    c0,
                    ncols,
                    ny: self.fs.ny,
                    labels,
                    count,
                }
            }
        }
    }

    /// The holes of R ∩ [x0, x1] × [0, height], the ones [`Reached::betti_in_band`]
    /// counts as β1 (same raster, same rule), in order of their first cell (column-major),
    /// for telling which of them a map found ([`crate::eval::holes`]).
    pub fn holes_in_band(&self, x0: f64, x1: f64) -> Vec<TrueHole> {
        let Some((c0, c1)) = self.fs.columns(x0, x1) else {
            return Vec::new();
        };
        let ny = self.fs.ny;
        let slice = self.band(c0, c1);
        let h = self.fs.resolution;
        let centre = |k: usize| {
            [
                ((c0 + k / ny) as f64 + 0.5) * h,
                ((k % ny) as f64 + 0.5) * h,
            ]
        };
        hole_cells_8(&slice, c1 - c0 + 1, ny)
            .into_iter()
            .map(|cells| {
                let n = cells.len();
                let (mut sx, mut sy) = (0.0, 0.0);
                for &k in &cells {
                    let p = centre(k);
                    sx += p[0];
                    sy += p[1];
                }
                let mean = [sx / n as f64, sy / n as f64];
                let off = |p: [f64; 2]| (p[0] - mean[0]).hypot(p[1] - mean[1]);
                let inside = cells
                    .iter()
                    .map(|&k| centre(k))
                    .min_by(|a, b| off(*a).total_cmp(&off(*b)))
                    .expect("a hole has a cell");
                let m = n.min(HOLE_SAMPLES);
                let samples = (0..m)
                    .map(|i| centre(cells[i * n / m + n / (2 * m)]))
                    .collect();
                TrueHole {
                    inside,
                    area: n as f64 * h * h,
                    samples,
                }
            })
            .collect()
    }
}

impl BandComponents {
    /// Number of components (β0 of the band).
    pub fn count(&self) -> usize {
        self.count
    }

    /// The band component containing `p` (metres, arena coordinates), numbered `0..count()`
    /// in the order of their first cell (column-major); a point on a non-reachable cell snaps
    /// to the nearest reachable cell of the band within [`SNAP_CELLS`] cells; `None` outside
    /// the band or off R.
    pub fn component_of(&self, p: Vec2) -> Option<usize> {
        if self.ncols == 0 {
            return None;
        }
        let shifted = (p.0 - self.c0 as f64 * self.resolution, p.1);
        snap(shifted, self.resolution, self.ncols, self.ny, |k| {
            self.labels[k]
        })
    }
}

/// The domain D_i of a window [start, end] (seconds): the band swept by D(t) over the
/// window, `(x_min, x_max)` in metres. The leader moves monotonically, so this is the hull
/// of D(start) and D(end), whichever way it sweeps.
pub fn window_band(world: &World, start: f64, end: f64) -> (f64, f64) {
    let (a, b) = (world.domain(start), world.domain(end));
    (a.0.min(b.0), a.1.max(b.1))
}

/// Intersection of two bands `(x_min, x_max)`, or `None` if they do not meet.
pub fn overlap(a: (f64, f64), b: (f64, f64)) -> Option<(f64, f64)> {
    let (lo, hi) = (a.0.max(b.0), a.1.min(b.1));
    (lo <= hi).then_some((lo, hi))
}

/// R as the sweep builds it ([`swept`]).
struct Sweep {
    /// Per cell: the step at which it entered R (see [`FreeSpace`]'s `entered`), or `NONE`.
    entered: Vec<u32>,
    lead_start: usize,
    rightward: bool,
}

/// The cells of the free space `reach` that the swarm can visit while it stays in the moving
/// domain D(t), and when each enters:
/// flood fill from the placement's cells `seeds` inside D(0) (the dispersion; step 0), then,
/// as the domain's leading edge (its right edge, or its left one for a leftward sweep)
/// passes each column (step k after k columns), from that column's cells next to a visited
/// one, over unvisited cells of `reach` inside the domain at that moment. A cell enters
/// once, so the cost is O(cells) plus one pass over each column.
fn swept(reach: &[bool], seeds: &[usize], world: &World, h: f64, nx: usize, ny: usize) -> Sweep {
    let mut entered = vec![NONE; nx * ny];
    // Columns whose centres lie in [a, b].
    let cols = |a: f64, b: f64| -> (usize, usize) {
        let c0 = ((a / h - 0.5).ceil().max(0.0) as usize).min(nx - 1);
        let c1 = (((b / h - 0.5).floor()).max(0.0) as usize).min(nx - 1);
        (c0, c1.max(c0))
    };
    let flood =
        |entered: &mut Vec<u32>, stack: &mut Vec<usize>, c0: usize, c1: usize, step: u32| {
            while let Some(k) = stack.pop() {
                let (i, j) = (k / ny, k % ny);
                let mut push = |ii: usize, jj: usize| {
                    let q = ii * ny + jj;
                    if ii >= c0 && ii <= c1 && reach[q] && entered[q] == NONE {
                        entered[q] = step;
                        stack.push(q);
                    }
                };
                if i > 0 {
                    push(i - 1, j);
                }
                if i + 1 < nx {
                    push(i + 1, j);
                }
                if j > 0 {
                    push(i, j - 1);
                }
                if j + 1 < ny {
                    push(i, j + 1);
                }
            }
        };
    let (a0, b0) = world.domain(0.0);
    let (c0_start, c1_start) = cols(a0, b0);
    // The placement may reach past D(0): its agents start there and walk back into it.
    let (mut lo, mut hi) = (c0_start, c1_start);
    let mut stack: Vec<usize> = Vec::new();
    for &k in seeds {
        if reach[k] && entered[k] == NONE {
            entered[k] = 0;
            stack.push(k);
            lo = lo.min(k / ny);
            hi = hi.max(k / ny);
        }
    }
    flood(&mut entered, &mut stack, lo, hi, 0);
    let (mut c0, mut c1) = (c0_start, c1_start);
    let (a_end, b_end) = world.domain(world.total_duration());
    let width = b0 - a0;
    // The leading edge moves one column at a time (right, or left for a leftward sweep);
    // the new column's cells next to a visited one enter, and the flood goes on inside the
    // domain of that moment.
    let mut enter =
        |entered: &mut Vec<u32>, column: usize, from: usize, c0: usize, c1: usize, step: u32| {
            for j in 0..ny {
                let k = column * ny + j;
                if reach[k] && entered[k] == NONE && entered[from * ny + j] != NONE {
                    entered[k] = step;
                    stack.push(k);
                }
            }
            flood(entered, &mut stack, c0, c1, step);
        };
    // Steps count columns; a raster has far fewer than `NONE` of them (`MAX_CELLS`).
    let step_of = |k: usize| u32::try_from(k).unwrap_or(NONE - 1);
    let rightward = world.leader.end_x >= world.leader.start_x;
    if rightward {
        let (_, last) = cols(b_end, b_end);
        while c1 < last {
            c1 += 1;
            let right = (c1 as f64 + 0.5) * h;
            c0 = cols(right - width, right).0.max(c0);
            enter(&mut entered, c1, c1 - 1, c0, c1, step_of(c1 - c1_start));
        }
    } else {
        let (first, _) = cols(a_end, a_end);
        while c0 > first {
            c0 -= 1;
            let left = (c0 as f64 + 0.5) * h;
            c1 = cols(left, left + width).1.min(c1);
            enter(&mut entered, c0, c0 + 1, c0, c1, step_of(c0_start - c0));
        }
    }
    Sweep {
        entered,
        lead_start: if rightward { c1_start } else { c0_start },
        rightward,
    }
}

/// Indices k in `0..n` whose cell centres `(k + 0.5) h` lie in [lo, hi], or `None`.
fn index_range(lo: f64, hi: f64, h: f64, n: usize) -> Option<(usize, usize)> {
    // `f64::max` would turn a NaN bound into 0: reject it first.
    if lo.is_nan() || hi.is_nan() || n == 0 {
        return None;
    }
    let a = (lo / h - 0.5).ceil().max(0.0);
    let b = (hi / h - 0.5).floor().min(n as f64 - 1.0);
    if a <= b {
        Some((a as usize, b as usize))
    } else {
        None
    }
}

fn cell_of(p: Vec2, h: f64, ncols: usize, ny: usize) -> Option<(usize, usize)> {
    let (fi, fj) = ((p.0 / h).floor(), (p.1 / h).floor());
    if fi >= 0.0 && fj >= 0.0 && fi < ncols as f64 && fj < ny as f64 {
        Some((fi as usize, fj as usize))
    } else {
        None
    }
}

/// The label of the labelled cell nearest to `p` (by centre distance, ties to the lowest
/// index) among the cells within [`SNAP_CELLS`] of p's cell, the cell itself first.
fn snap(p: Vec2, h: f64, ncols: usize, ny: usize, label: impl Fn(usize) -> u32) -> Option<usize> {
    if !(p.0.is_finite() && p.1.is_finite()) {
        return None;
    }
    let s = SNAP_CELLS as f64;
    let (fi, fj) = ((p.0 / h).floor(), (p.1 / h).floor());
    if fi < -s - 1.0 || fj < -s - 1.0 || fi > ncols as f64 + s || fj > ny as f64 + s {
        return None;
    }
    if let Some((i, j)) = cell_of(p, h, ncols, ny) {
        let l = label(i * ny + j);
        if l != NONE {
            return Some(l as usize);
        }
    }
    let (ci, cj) = (fi as i64, fj as i64);
    let s = SNAP_CELLS as i64;
    let mut best: Option<(f64, usize)> = None;
    for i in (ci - s).max(0)..=(ci + s).min(ncols as i64 - 1) {
        for j in (cj - s).max(0)..=(cj + s).min(ny as i64 - 1) {
            let k = i as usize * ny + j as usize;
            let l = label(k);
            if l == NONE {
                continue;
            }
            let d = ((i as f64 + 0.5) * h - p.0).hypot((j as f64 + 0.5) * h - p.1);
            if best.is_none_or(|(bd, _)| d < bd) {
                best = Some((d, l as usize));
            }
        }
    }
    best.map(|(_, l)| l)
}

/// 4-connected components of `mask` (column-major, `ncols × ny`): per-cell labels
/// (`NONE` off the mask), numbered in order of first cell, and their number.
fn label_4(mask: &[bool], ncols: usize, ny: usize) -> (Vec<u32>, usize) {
    let mut labels = vec![NONE; mask.len()];
    let mut stack = Vec::new();
    let mut n = 0u32;
    for s in 0..mask.len() {
        if !mask[s] || labels[s] != NONE {
            continue;
        }
        labels[s] = n;
        stack.push(s);
        while let Some(k) = stack.pop() {
            let (i, j) = (k / ny, k % ny);
            let mut visit = |q: usize| {
                if mask[q] && labels[q] == NONE {
                    labels[q] = n;
                    stack.push(q);
                }
            };
            if j > 0 {
                visit(k - 1);
            }
            if j + 1 < ny {
                visit(k + 1);
            }
            if i > 0 {
                visit(k - ny);
            }
            if i + 1 < ncols {
                visit(k + ny);
            }
        }
        n += 1;
    }
    (labels, n as usize)
}

/// Number of bounded 8-connected components of the complement of `mask` (column-major,
/// `ncols × ny`) when the grid is padded by a ring of complement cells: components that
/// reach the first or last column or row belong to the unbounded outside.
fn count_holes_8(mask: &[bool], ncols: usize, ny: usize) -> usize {
    holes_8(mask, ncols, ny, |_, _| ())
}

/// Floods every bounded 8-connected component of the complement of `mask` (the holes
/// [`count_holes_8`] counts), calling `cell(h, k)` for each cell `k` of hole `h`, holes
/// numbered `0..` in order of their first cell (column-major); returns their number.
fn holes_8(mask: &[bool], ncols: usize, ny: usize, mut cell: impl FnMut(usize, usize)) -> usize {
    let mut seen = vec![false; mask.len()];
    let mut stack = Vec::new();
    let mut flood = |start: usize, seen: &mut Vec<bool>, cell: &mut dyn FnMut(usize)| {
        seen[start] = true;
        stack.push(start);
        while let Some(k) = stack.pop() {
            cell(k);
            let (i, j) = (k / ny, k % ny);
            let (ilo, ihi) = (i.saturating_sub(1), (i + 1).min(ncols - 1));
            let (jlo, jhi) = (j.saturating_sub(1), (j + 1).min(ny - 1));
            for a in ilo..=ihi {
                for b in jlo..=jhi {
                    let q = a * ny + b;
                    if !mask[q] && !seen[q] {
                        seen[q] = true;
                        stack.push(q);
                    }
                }
            }
        }
    };
    let boundary = (0..ny)
        .flat_map(|j| [j, (ncols - 1) * ny + j])
        .chain((0..ncols).flat_map(|i| [i * ny, i * ny + ny - 1]));
    for k in boundary {
        if !mask[k] && !seen[k] {
            flood(k, &mut seen, &mut |_| ());
        }
    }
    let mut holes = 0;
    for k in 0..mask.len() {
        if !mask[k] && !seen[k] {
            flood(k, &mut seen, &mut |q| cell(holes, q));
            holes += 1;
        }
    }
    holes
}

/// The cells of each hole of [`holes_8`], each list sorted (column-major order).
fn hole_cells_8(mask: &[bool], ncols: usize, ny: usize) -> Vec<Vec<usize>> {
    let mut cells: Vec<Vec<usize>> = Vec::new();
    holes_8(mask, ncols, ny, |h, k| {
        if cells.len() <= h {
            cells.resize_with(h + 1, Vec::new);
        }
        cells[h].push(k);
    });
    for c in &mut cells {
        c.sort_unstable();
    }
    cells
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_truth_coarsens_only_for_arenas_beyond_its_cell_budget() {
        // Every bundled world and anything up to 20 000 m² keeps 1 cm.
        assert_eq!(resolution_for(30.0, 10.0), DEFAULT_RESOLUTION);
        assert_eq!(resolution_for(200.0, 100.0), DEFAULT_RESOLUTION);
        for (w, h) in [
            (3000.0, 10.0),
            (10_000.0, 10_000.0),
            (10_000.0, 1e-6),
            (1e-3, 10_000.0),
        ] {
            let r = resolution_for(w, h);
            let cells = (w / r).ceil() * (h / r).ceil();
            assert!(cells <= MAX_CELLS as f64, "{w} x {h}: {cells} cells at {r}");
            // No coarser than it must be.
            let finer = r * (1.0 - 1e-9);
            assert!(
                r == DEFAULT_RESOLUTION
                    || (w / finer).ceil() * (h / finer).ceil() > MAX_CELLS as f64,
                "{w} x {h}: {r} is coarser than needed"
            );
        }
        assert!((resolution_for(3000.0, 10.0) - 0.012255).abs() < 1e-6);
    }

    fn grid(rows: &[&str]) -> (Vec<bool>, usize, usize) {
        // rows[0] is the top row (largest j); '#' is foreground.
        let ny = rows.len();
        let ncols = rows[0].len();
        let mut m = vec![false; ncols * ny];
        for (r, line) in rows.iter().enumerate() {
            let j = ny - 1 - r;
            for (i, ch) in line.chars().enumerate() {
                m[i * ny + j] = ch == '#';
            }
        }
        (m, ncols, ny)
    }

    #[test]
    fn dual_connectivity_on_small_pictures() {
        // A diagonal touch does not join foreground (4-connected) ...
        let (m, c, n) = grid(&["#.", ".#"]);
        assert_eq!(label_4(&m, c, n).1, 2);
        // ... and a ring whose inside leaks diagonally is not a hole: none here.
        let (m, c, n) = grid(&["###", "#.#", "###"]);
        assert_eq!((label_4(&m, c, n).1, count_holes_8(&m, c, n)), (1, 1));
        let (m, c, n) = grid(&[".....", ".###.", ".#.#.", ".###.", "....."]);
        assert_eq!(count_holes_8(&m, c, n), 1);
        // Corner-cut ring: the hole's cell touches the outside diagonally through a gap.
        let (m, c, n) = grid(&[".##.", "#..#", "#..#", ".##."]);
        assert_eq!((label_4(&m, c, n).1, count_holes_8(&m, c, n)), (4, 0));
        // Hole touching the padded border is not a hole.
        let (m, c, n) = grid(&["###", "#.#", "#.#"]);
        assert_eq!(count_holes_8(&m, c, n), 0);
    }

    #[test]
    fn index_range_picks_centres() {
        assert_eq!(index_range(0.0, 1.0, 0.1, 10), Some((0, 9)));
        assert_eq!(index_range(0.06, 0.14, 0.1, 10), None);
        assert_eq!(index_range(0.04, 0.16, 0.1, 10), Some((0, 1)));
        assert_eq!(index_range(f64::NAN, 1.0, 0.1, 10), None);
        assert_eq!(index_range(-5.0, 50.0, 0.1, 10), Some((0, 9)));
    }
}
