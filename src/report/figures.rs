//! The six figure kinds of the report (paper §"Simulation Results", whose figures show each
//! scenario in rows: environment, diagrams, point clouds, inter-domain clouds, dendrograms,
//! global map), drawn with `plotters`' SVG backend. Each function returns the SVG text of one
//! figure; nothing here reads files or the clock, so the same [`RunData`] always gives the
//! same bytes. Cost: linear in the events drawn (a few thousand circles per window).

use super::ReportError;
use super::data::{ComponentIn, ConnectionIn, RunData, WindowIn};
use crate::world::{Obstacle, World};
use plotters::coord::Shift;
use plotters::coord::types::RangedCoordf64;
use plotters::element::DashedPathElement;
use plotters::prelude::*;
use std::collections::BTreeMap;

/// One rendered figure.
#[derive(Debug, Clone, PartialEq)]
pub struct Figure {
    /// File name under `report/`, e.g. `window_1_diagram.svg`.
    pub name: String,
    /// Heading in the page.
    pub title: String,
    /// What the figure shows, for the page's caption.
    pub caption: String,
    /// The SVG document.
    pub svg: String,
}

type DrawResult = Result<(), Box<dyn std::error::Error>>;
type Area<'a> = DrawingArea<SVGBackend<'a>, Shift>;
type Chart<'a, 'b> = ChartContext<'a, SVGBackend<'b>, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

const FONT: &str = "sans-serif";
const H0: RGBColor = RGBColor(31, 119, 180);
const H1: RGBColor = RGBColor(255, 127, 14);
const OBSTACLE: RGBColor = RGBColor(90, 90, 90);
const LANDMARK: RGBColor = RGBColor(214, 39, 40);
const NOISE: RGBColor = RGBColor(190, 190, 190);
/// Ten distinguishable colours for clusters and windows (the "category10" palette).
const PALETTE: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
];

/// Colour of `f` in [0, 1] on the viridis map (five stops, linear in between).
pub fn viridis(f: f64) -> RGBColor {
    const STOPS: [(u8, u8, u8); 5] = [
        (68, 1, 84),
        (59, 82, 139),
        (33, 145, 140),
        (94, 201, 98),
        (253, 231, 37),
    ];
    let f = if f.is_finite() {
        f.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let x = f * 4.0;
    let i = (x.floor() as usize).min(3);
    let t = x - i as f64;
    let (a, b) = (STOPS[i], STOPS[i + 1]);
    let mix = |p: u8, q: u8| (p as f64 + (q as f64 - p as f64) * t).round() as u8;
    RGBColor(mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
}

fn render(
    name: &str,
    size: (u32, u32),
    draw: impl FnOnce(&Area<'_>) -> DrawResult,
) -> Result<String, ReportError> {
    let plot = |e: &dyn std::fmt::Display| ReportError::Plot {
        figure: name.to_string(),
        message: e.to_string(),
    };
    let mut buf = String::new();
    {
        let root = SVGBackend::with_string(&mut buf, size).into_drawing_area();
        root.fill(&WHITE).map_err(|e| plot(&e))?;
        draw(&root).map_err(|e| plot(&e))?;
        root.present().map_err(|e| plot(&e))?;
    }
    Ok(compact(&buf))
}

/// Drops what an SVG renderer assumes anyway, to keep the page small: attributes at their
/// default values (`opacity="1"`, `stroke-width` of an unstroked shape, a circle's
/// `stroke="none"`) and circles that
/// repeat an earlier identical one (the same marker at the same pixel draws the same thing;
/// many encounters share a pixel).
pub fn compact(svg: &str) -> String {
    let mut seen = std::collections::BTreeSet::new();
    let mut out = String::with_capacity(svg.len());
    for line in svg.split_inclusive('\n') {
        let line = line
            .replace(" opacity=\"1\"", "")
            .replace(" stroke=\"none\" stroke-width=\"1\"", " stroke=\"none\"");
        // A circle's stroke is none unless set.
        let line = if line.starts_with("<circle") {
            line.replace(" stroke=\"none\"", "")
        } else {
            line
        };
        if line.starts_with("<circle") && !seen.insert(line.clone()) {
            continue;
        }
        out.push_str(&line);
    }
    out
}

/// A padded, non-degenerate range around values.
fn span(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
    if !lo.is_finite() {
        return (-1.0, 1.0);
    }
    let pad = if hi > lo { 0.06 * (hi - lo) } else { 1.0 };
    (lo - pad, hi + pad)
}

fn chart<'a, 'b>(
    area: &'a Area<'b>,
    title: &str,
    x: (f64, f64),
    y: (f64, f64),
    x_desc: &str,
    y_desc: &str,
) -> Result<Chart<'a, 'b>, Box<dyn std::error::Error>> {
    chart_with(area, title, x, y, (x_desc, y_desc), 6)
}

/// Largest magnitude an axis reaches: the figures' values are seconds, metres and
/// multiples of σ, far below it, and plotters' tick search does not finish on ranges near
/// `f64::MAX` (a hand-edited map or model can hold such values).
const AXIS_LIMIT: f64 = 1e12;

/// `range` clamped to ±[`AXIS_LIMIT`], ordered and non-degenerate.
fn plottable((lo, hi): (f64, f64)) -> (f64, f64) {
    let clamp = |v: f64| {
        if v.is_nan() {
            0.0
        } else {
            v.clamp(-AXIS_LIMIT, AXIS_LIMIT)
        }
    };
    let (lo, hi) = (clamp(lo), clamp(hi));
    let (lo, hi) = (lo.min(hi), lo.max(hi));
    if hi - lo > 1e-9 * lo.abs().max(hi.abs()).max(1e-12) {
        (lo, hi)
    } else {
        (lo - 1.0, hi + 1.0)
    }
}

fn chart_with<'a, 'b>(
    area: &'a Area<'b>,
    title: &str,
    x: (f64, f64),
    y: (f64, f64),
    (x_desc, y_desc): (&str, &str),
    y_labels: usize,
) -> Result<Chart<'a, 'b>, Box<dyn std::error::Error>> {
    let (x, y) = (plottable(x), plottable(y));
    let mut c = ChartBuilder::on(area)
        .caption(title, (FONT, 14))
        .margin(8)
        .x_label_area_size(38)
        .y_label_area_size(52)
        .build_cartesian_2d(x.0..x.1, y.0..y.1)?;
    c.configure_mesh()
        .disable_mesh()
        .x_desc(x_desc)
        .y_desc(y_desc)
        .x_labels(6)
        .y_labels(y_labels)
        .label_style((FONT, 11))
        .axis_desc_style((FONT, 12))
        .draw()?;
    Ok(c)
}

fn legend<'a, 'b: 'a>(c: &mut Chart<'a, 'b>) -> DrawResult {
    c.configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK.mix(0.4))
        .label_font((FONT, 11))
        .draw()?;
    Ok(())
}

/// Outline of an obstacle as a polygon, metres (discs and wall caps with 48 segments).
pub fn obstacle_polygons(o: &Obstacle) -> Vec<Vec<(f64, f64)>> {
    let disc = |c: (f64, f64), r: f64| -> Vec<(f64, f64)> {
        (0..48)
            .map(|k| {
                let a = std::f64::consts::TAU * k as f64 / 48.0;
                (c.0 + r * a.cos(), c.1 + r * a.sin())
            })
            .collect()
    };
    match o {
        Obstacle::Rect { min, max } => vec![vec![
            (min.0, min.1),
            (max.0, min.1),
            (max.0, max.1),
            (min.0, max.1),
        ]],
        Obstacle::Circle { center, radius } => vec![disc(*center, *radius)],
        Obstacle::Polygon { points } => vec![points.clone()],
        Obstacle::Wall {
            from,
            to,
            thickness,
        } => {
            let (dx, dy) = (to.0 - from.0, to.1 - from.1);
            let len = dx.hypot(dy).max(1e-12);
            let h = thickness / 2.0;
            let (nx, ny) = (-dy / len * h, dx / len * h);
            vec![
                vec![
                    (from.0 + nx, from.1 + ny),
                    (to.0 + nx, to.1 + ny),
                    (to.0 - nx, to.1 - ny),
                    (from.0 - nx, from.1 - ny),
                ],
                disc(*from, h),
                disc(*to, h),
            ]
        }
    }
}

fn draw_arena(c: &mut Chart<'_, '_>, world: &World, fill: RGBColor) -> DrawResult {
    let (w, h) = (world.arena.width, world.arena.height);
    c.draw_series(std::iter::once(PathElement::new(
        vec![(0.0, 0.0), (w, 0.0), (w, h), (0.0, h), (0.0, 0.0)],
        BLACK.stroke_width(2),
    )))?;
    draw_obstacles(c, world, fill.filled())
}

/// Every obstacle of `world`, filled with `style`.
fn draw_obstacles(c: &mut Chart<'_, '_>, world: &World, style: ShapeStyle) -> DrawResult {
    for o in &world.obstacles {
        c.draw_series(
            obstacle_polygons(o)
                .into_iter()
                .map(|p| Polygon::new(p, style)),
        )?;
    }
    Ok(())
}

/// Pixel size of a plot of the arena at `width` pixels, keeping the aspect ratio.
fn arena_size(world: &World, width: u32, y_extra: f64) -> (u32, u32) {
    let plot_w = width.saturating_sub(80) as f64;
    let ratio = world.arena.height * y_extra / world.arena.width.max(1e-9);
    let h = (plot_w * ratio + 90.0).clamp(220.0, 900.0);
    (width, h as u32)
}

/// Landmark positions over the whole run, metres: every distinct position an agent held as
/// a landmark in `trajectories.csv` (when recorded), together with, for each landmark static
/// interval of the log, the true position of the agent at its first encounter in that
/// interval (truth columns; catches landmarks shorter than the trajectory interval).
/// O(samples + intervals · k) for k encounters per agent.
pub fn landmark_positions(run: &RunData) -> Vec<(f64, f64)> {
    let mut out = Vec::new();
    if let Some(traj) = &run.trajectories {
        let mut last: BTreeMap<u32, (f64, f64)> = BTreeMap::new();
        for s in traj.iter().filter(|s| s.state == 2) {
            let p = (s.x, s.y);
            let same = last
                .get(&s.agent)
                .is_some_and(|q| (q.0 - p.0).hypot(q.1 - p.1) < 1e-3);
            if !same {
                out.push(p);
                last.insert(s.agent, p);
            }
        }
    }
    // Encounters by agent, in log order (sorted by start).
    let mut by_agent: BTreeMap<u32, Vec<usize>> = BTreeMap::new();
    for (k, e) in run.log.encounters.iter().enumerate() {
        if e.truth.is_some() {
            by_agent.entry(e.a).or_default().push(k);
            by_agent.entry(e.b).or_default().push(k);
        }
    }
    for iv in run
        .log
        .static_intervals
        .iter()
        .filter(|s| s.reason == crate::log::StaticReason::Landmark)
    {
        let Some(list) = by_agent.get(&iv.agent) else {
            continue;
        };
        let hit = list.iter().find_map(|&k| {
            let e = &run.log.encounters[k];
            let t = e.truth?;
            if e.start > iv.end || e.end < iv.start {
                None
            } else if e.a == iv.agent {
                Some((t[0], t[1]))
            } else {
                Some((t[2], t[3]))
            }
        });
        out.extend(hit);
    }
    out
}

/// Figure 1: the environment to scale with the agents' initial positions, every landmark
/// position, the leader's path and the windows' domains D_i. `None` without a world.
pub fn environment(run: &RunData) -> Result<Option<Figure>, ReportError> {
    let Some(world) = &run.world else {
        return Ok(None);
    };
    let (w, h) = (world.arena.width, world.arena.height);
    let initial: Vec<(f64, f64)> = run
        .trajectories
        .as_ref()
        .and_then(|t| {
            let t0 = t.first()?.time;
            Some(
                t.iter()
                    .take_while(|s| s.time == t0)
                    .map(|s| (s.x, s.y))
                    .collect(),
            )
        })
        .unwrap_or_default();
    let landmarks = landmark_positions(run);
    let domains: Vec<(usize, [f64; 2])> = run
        .summary
        .windows
        .iter()
        .filter_map(|s| s.domain.map(|d| (s.index, d)))
        .collect();
    let svg = render("environment", arena_size(world, 960, 1.42), |root| {
        let mut c = chart(
            root,
            &format!("{}: environment, landmarks and domains", world.name),
            (-0.02 * w, 1.02 * w),
            // Room above the arena for the domains and the leader, below it for the legend.
            (-0.22 * h, 1.2 * h),
            "x (m)",
            "y (m)",
        )?;
        for (k, (i, d)) in domains.iter().enumerate() {
            let col = PALETTE[k % 2];
            c.draw_series(std::iter::once(Rectangle::new(
                [(d[0], 0.0), (d[1], h)],
                col.mix(0.10).filled(),
            )))?;
            // Each domain also as a bracket above the arena, staggered so overlaps show.
            let y = h * (1.03 + 0.045 * (k % 2) as f64);
            c.draw_series(std::iter::once(PathElement::new(
                vec![(d[0], y), (d[1], y)],
                col.stroke_width(3),
            )))?;
            c.draw_series(std::iter::once(Text::new(
                format!("D{i}"),
                (d[0] + 0.01 * w, y + 0.01 * h),
                (FONT, 11).into_font().color(&col),
            )))?;
        }
        draw_arena(&mut c, world, OBSTACLE)?;
        let y_leader = 1.15 * h;
        c.draw_series(DashedLineSeries::new(
            vec![
                (world.leader.start_x, y_leader),
                (world.leader.end_x, y_leader),
            ],
            6,
            4,
            BLACK.stroke_width(2),
        ))?
        .label("leader path")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], BLACK.stroke_width(2)));
        let dir = if world.leader.end_x >= world.leader.start_x {
            1.0
        } else {
            -1.0
        };
        let tip = world.leader.end_x;
        c.draw_series(std::iter::once(Polygon::new(
            vec![
                (tip, y_leader),
                (tip - dir * 0.02 * w, y_leader + 0.025 * h),
                (tip - dir * 0.02 * w, y_leader - 0.025 * h),
            ],
            BLACK.filled(),
        )))?;
        c.draw_series(
            landmarks
                .iter()
                .map(|&p| Circle::new(p, 2, LANDMARK.filled())),
        )?
        .label("landmark positions")
        .legend(|(x, y)| Circle::new((x + 8, y), 3, LANDMARK.filled()));
        c.draw_series(
            initial
                .iter()
                .map(|&p| Circle::new(p, 3, BLACK.stroke_width(1))),
        )?
        .label("initial positions")
        .legend(|(x, y)| Circle::new((x + 8, y), 3, BLACK.stroke_width(1)));
        c.configure_series_labels()
            .position(SeriesLabelPosition::LowerLeft)
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK.mix(0.4))
            .label_font((FONT, 11))
            .draw()?;
        Ok(())
    })?;
    let replay_note = if run.trajectories.is_some() {
        "initial positions from trajectories.csv; landmark positions from trajectories.csv and from the landmarks' encounters (truth columns)"
    } else {
        "no trajectories.csv: landmark positions from the landmarks' encounters (truth columns), initial positions unknown"
    };
    Ok(Some(Figure {
        name: "environment.svg".into(),
        title: "Environment".into(),
        caption: format!(
            "Arena {w} m × {h} m and its obstacles (grey) to scale; the leader's path (dashed, arrow: direction) and the domains D_i of the windows (bands and brackets); {replay_note}."
        ),
        svg,
    }))
}

fn panel_count(n: usize) -> (u32, u32) {
    let n = n.max(1) as u32;
    (360 * n, 360)
}

fn diagram_panel(area: &Area<'_>, w: &WindowIn, ci: usize, comp: &ComponentIn) -> DrawResult {
    let sigma = comp.scale;
    let mut top = comp
        .diagram
        .iter()
        .flat_map(|b| [Some(b.birth), b.death])
        .flatten()
        .fold(0.0f64, f64::max);
    if let Some(cl) = &w.classifier {
        top = top.max(cl.h0_ratio * sigma).max(cl.h1_span * sigma);
    }
    if top <= 0.0 {
        top = 1.0;
    }
    let inf = 1.08 * top;
    let lim = 1.16 * top;
    let title = format!(
        "W{} component {}: (β0, β1) = ({}, {}), σ = {:.1} s",
        w.index,
        ci + 1,
        comp.betti[0],
        comp.betti[1],
        sigma
    );
    let mut c = chart(
        area,
        &title,
        (0.0, lim),
        (0.0, lim),
        "birth (s)",
        "death (s)",
    )?;
    c.draw_series(std::iter::once(PathElement::new(
        vec![(0.0, 0.0), (lim, lim)],
        BLACK.mix(0.5).stroke_width(1),
    )))?;
    c.draw_series(DashedLineSeries::new(
        vec![(0.0, inf), (lim, inf)],
        2,
        3,
        BLACK.mix(0.5).stroke_width(1),
    ))?;
    c.draw_series(std::iter::once(Text::new(
        "∞ (essential)",
        (0.02 * lim, inf + 0.035 * lim),
        (FONT, 10),
    )))?;
    if let Some(cl) = &w.classifier {
        let h0 = cl.h0_ratio * sigma;
        c.draw_series(DashedLineSeries::new(
            vec![(0.0, h0), (lim, h0)],
            6,
            4,
            H0.stroke_width(1),
        ))?
        .label("thresholds (dashed)")
        .legend(|(x, y)| {
            DashedPathElement::new(vec![(x, y), (x + 18, y)], 4, 2, BLACK.stroke_width(1))
        });
        if cl.h1_ratio > 0.0 {
            c.draw_series(DashedLineSeries::new(
                vec![(0.0, 0.0), (lim / cl.h1_ratio, lim)],
                6,
                4,
                H1.stroke_width(1),
            ))?;
        }
        let s = cl.h1_span * sigma;
        if s < lim {
            c.draw_series(DashedLineSeries::new(
                vec![(0.0, s), (lim - s, lim)],
                2,
                3,
                H1.stroke_width(1),
            ))?;
        }
    }
    let pos = |b: &super::data::BarIn| (b.birth, b.death.unwrap_or(inf));
    c.draw_series(
        comp.diagram
            .iter()
            .filter(|b| b.dim == 0)
            .map(|b| Circle::new(pos(b), 3, H0.filled())),
    )?
    .label("H0")
    .legend(|(x, y)| Circle::new((x + 8, y), 3, H0.filled()));
    c.draw_series(
        comp.diagram
            .iter()
            .filter(|b| b.dim == 1)
            .map(|b| TriangleMarker::new(pos(b), 4, H1.filled())),
    )?
    .label("H1")
    .legend(|(x, y)| TriangleMarker::new((x + 8, y), 4, H1.filled()));
    c.draw_series(
        comp.diagram
            .iter()
            .filter(|b| b.robust)
            .map(|b| Circle::new(pos(b), 7, BLACK.stroke_width(2))),
    )?
    .label("robust")
    .legend(|(x, y)| Circle::new((x + 8, y), 6, BLACK.stroke_width(2)));
    c.configure_series_labels()
        .position(SeriesLabelPosition::LowerRight)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK.mix(0.4))
        .label_font((FONT, 10))
        .draw()?;
    Ok(())
}

fn empty_panel(area: &Area<'_>, title: &str, note: &str) -> DrawResult {
    let c = chart(area, title, (0.0, 1.0), (0.0, 1.0), "", "")?;
    c.plotting_area().draw(&Text::new(
        note.to_string(),
        (0.08, 0.5),
        (FONT, 13).into_font(),
    ))?;
    Ok(())
}

/// Figure 2: the persistence diagram of each component of a window, H0 and H1 in different
/// colours, the classifier's thresholds dashed and the robust features ringed.
pub fn diagram(w: &WindowIn) -> Result<Figure, ReportError> {
    let name = format!("window_{}_diagram.svg", w.index);
    let svg = render(&name, panel_count(w.components.len()), |root| {
        if w.components.is_empty() {
            return empty_panel(root, &format!("W{}", w.index), "no real component");
        }
        let panels = root.split_evenly((1, w.components.len()));
        for ((ci, comp), area) in w.components.iter().enumerate().zip(&panels) {
            diagram_panel(area, w, ci, comp)?;
        }
        Ok(())
    })?;
    let thresholds = match &w.classifier {
        Some(cl) => format!(
            "Dashed: the classifier's thresholds (H0 robust above {:.2}σ; H1 robust above both orange lines: death/birth ≥ {:.2} and death − birth ≥ {:.2}σ), σ = the component's sampling scale.",
            cl.h0_ratio, cl.h1_ratio, cl.h1_span
        ),
        None => "These maps predate recorded thresholds; rerun `swarmmap map` to draw them.".into(),
    };
    let rank = w
        .outlier_rank
        .map(|k| {
            format!(
                " The representatives were picked with the outlier filter's neighbour rank k = {k}."
            )
        })
        .unwrap_or_default();
    Ok(Figure {
        name,
        title: format!("W{}: persistence diagram", w.index),
        caption: format!(
            "Vietoris–Rips persistence of each real component's encounter metric (seconds): H0 blue dots, H1 orange triangles, robust classes ringed, essential classes on the ∞ line. {thresholds}{rank}"
        ),
        svg,
    })
}

fn true_pos(run: &RunData, w: &WindowIn, j: usize) -> Option<(f64, f64)> {
    let e = run.log.encounters.get(w.events.get(j)?.encounter?)?;
    let t = e.truth?;
    Some(((t[0] + t[2]) / 2.0, (t[1] + t[3]) / 2.0))
}

fn time_colour(t: f64, (t0, t1): (f64, f64)) -> RGBColor {
    viridis(if t1 > t0 { (t - t0) / (t1 - t0) } else { 0.0 })
}

/// The void triangles (closed, as event indices) of the robust holes of component `comp`
/// of `w`, or of all its components.
fn voids_of<'w>(w: &'w WindowIn, comp: Option<usize>) -> impl Iterator<Item = [usize; 4]> + 'w {
    w.components
        .iter()
        .enumerate()
        .filter(move |(c, _)| comp.is_none_or(|k| k == *c))
        .flat_map(|(_, comp)| comp.holes.iter().filter_map(|h| h.void))
        .map(|[a, b, c]| [a, b, c, a])
}

fn cycles_of<'w>(
    w: &'w WindowIn,
    comp: Option<usize>,
) -> impl Iterator<Item = (usize, usize)> + 'w {
    w.components
        .iter()
        .enumerate()
        .filter(move |(c, _)| comp.is_none_or(|k| k == *c))
        .flat_map(|(_, comp)| comp.holes.iter().flat_map(|h| h.cycle.iter().copied()))
}

/// Figure 3: the encounter point cloud of a window (the first two coordinates of each
/// component's embedding) coloured by time and, with truth, the same events at their true
/// positions; the representative cycles of the robust holes drawn on both.
/// Most events drawn per point-cloud panel: beyond it every k-th event is drawn (a fixed
/// stride, so the figure stays deterministic), which keeps a page with r_d = 10 cm windows
/// (5 000+ events each) small enough to mail without changing what the cloud looks like.
pub const MAX_CLOUD_POINTS: usize = 1000;

/// The clusters of a connection's cloud as a caption says them: their number, and how many
/// of them join the two maps when not all do (`count`, [`crate::mapping::stitch`]).
fn clusters_said(conn: &ConnectionIn) -> String {
    let clusters = conn.points.iter().map(|p| p.label + 1).max().unwrap_or(0);
    if clusters == conn.count {
        format!("{clusters} cluster(s)")
    } else {
        format!("{clusters} cluster(s), {} joining both maps", conn.count)
    }
}

/// The stride that draws at most [`MAX_CLOUD_POINTS`] of `n` points.
fn stride(n: usize) -> usize {
    n.div_ceil(MAX_CLOUD_POINTS).max(1)
}

pub fn cloud(run: &RunData, w: &WindowIn) -> Result<Figure, ReportError> {
    let name = format!("window_{}_cloud.svg", w.index);
    let truth: Option<Vec<(f64, f64)>> = (0..w.events.len()).map(|j| true_pos(run, w, j)).collect();
    let truth = truth.filter(|t| !t.is_empty());
    let panels_n = w.components.len() + usize::from(truth.is_some());
    let times = (w.start, w.end);
    let svg = render(&name, panel_count(panels_n), |root| {
        if panels_n == 0 {
            return empty_panel(root, &format!("W{}", w.index), "no real component");
        }
        let panels = root.split_evenly((1, panels_n));
        for (ci, comp) in w.components.iter().enumerate() {
            let pts: Vec<(f64, f64)> = comp
                .events
                .iter()
                .map(|&j| (w.events[j].point[0], w.events[j].point[1]))
                .collect();
            let mut c = chart(
                &panels[ci],
                &format!("W{} component {}: embedding", w.index, ci + 1),
                span(pts.iter().map(|p| p.0)),
                span(pts.iter().map(|p| p.1)),
                "MDS coordinate 1 (s)",
                "MDS coordinate 2 (s)",
            )?;
            let k = stride(pts.len());
            c.draw_series(comp.events.iter().zip(&pts).step_by(k).map(|(&j, &p)| {
                Circle::new(p, 2, time_colour(w.events[j].start, times).filled())
            }))?;
            let at = |j: usize| (w.events[j].point[0], w.events[j].point[1]);
            c.draw_series(
                cycles_of(w, Some(ci))
                    .map(|(a, b)| PathElement::new(vec![at(a), at(b)], BLACK.stroke_width(2))),
            )?;
            c.draw_series(
                voids_of(w, Some(ci))
                    .map(|t| PathElement::new(t.map(at).to_vec(), RED.stroke_width(2))),
            )?;
        }
        if let Some(truth) = &truth {
            let domain = run
                .summary
                .windows
                .iter()
                .find(|s| s.index == w.index)
                .and_then(|s| s.domain);
            let x = domain.map_or_else(|| span(truth.iter().map(|p| p.0)), |d| (d[0], d[1]));
            let y = run.world.as_ref().map_or_else(
                || span(truth.iter().map(|p| p.1)),
                |wd| (0.0, wd.arena.height),
            );
            let mut c = chart(
                &panels[panels_n - 1],
                &format!("W{}: the same events at their true positions", w.index),
                x,
                y,
                "x (m)",
                "y (m)",
            )?;
            if let Some(world) = &run.world {
                draw_obstacles(&mut c, world, OBSTACLE.mix(0.35).filled())?;
            }
            let k = stride(truth.len());
            c.draw_series(w.events.iter().zip(truth).step_by(k).map(|(e, &p)| {
                let col = if e.noise {
                    NOISE
                } else {
                    time_colour(e.start, times)
                };
                Circle::new(p, 2, col.filled())
            }))?;
            c.draw_series(
                cycles_of(w, None).map(|(a, b)| {
                    PathElement::new(vec![truth[a], truth[b]], BLACK.stroke_width(2))
                }),
            )?;
            c.draw_series(
                voids_of(w, None)
                    .map(|t| PathElement::new(t.map(|j| truth[j]).to_vec(), RED.stroke_width(2))),
            )?;
        }
        Ok(())
    })?;
    Ok(Figure {
        name,
        title: format!("W{}: encounter point cloud", w.index),
        caption: format!(
            "Each event of W{} ({:.0}–{:.0} s){} coloured by its start time (viridis: dark = early, yellow = late); black: representative cycles of the robust holes (drawn through each bar's birth edge); red: the triangle whose entry kills each hole's class, which spans its void.{}",
            w.index,
            w.start,
            w.end,
            if w.events.len() > MAX_CLOUD_POINTS {
                format!(
                    " (one event in {} drawn, of {})",
                    stride(w.events.len()),
                    w.events.len()
                )
            } else {
                String::new()
            },
            if truth.is_some() {
                " Right: the same events at their true positions (grey: noise components)."
            } else {
                " The log has no truth columns, so there is no true view."
            }
        ),
        svg,
    })
}

/// Figure 4: the inter-domain point cloud of a pair, coloured by cluster (2-D projection of
/// the correspondence metric and, with truth, the true positions).
pub fn pair_cloud(run: &RunData, conn: &ConnectionIn) -> Result<Figure, ReportError> {
    let [i, j] = conn.between;
    let name = format!("connection_{i}_cloud.svg");
    let truth: Option<Vec<(f64, f64)>> = conn
        .points
        .iter()
        .map(|p| p.truth.map(|t| (t[0], t[1])))
        .collect();
    let truth = truth.filter(|t| !t.is_empty());
    let panels_n = 1 + usize::from(truth.is_some());
    let colour = |label: usize| PALETTE[label % PALETTE.len()];
    let svg = render(&name, panel_count(panels_n), |root| {
        let panels = root.split_evenly((1, panels_n));
        let pts: Vec<(f64, f64)> = conn.points.iter().map(|p| (p.xy[0], p.xy[1])).collect();
        let mut c = chart(
            &panels[0],
            &format!("M{i}–M{j}: {}, c = {} s", clusters_said(conn), conn.cutoff),
            span(pts.iter().map(|p| p.0)),
            span(pts.iter().map(|p| p.1)),
            "MDS coordinate 1 (s)",
            "MDS coordinate 2 (s)",
        )?;
        c.draw_series(
            conn.points
                .iter()
                .zip(&pts)
                .map(|(p, &q)| Circle::new(q, 4, colour(p.label).filled())),
        )?;
        if let Some(truth) = &truth {
            let mut x = span(truth.iter().map(|p| p.0));
            let mut y = span(truth.iter().map(|p| p.1));
            if let Some(world) = &run.world {
                y = (0.0, world.arena.height);
                x = (x.0.max(0.0), x.1.min(world.arena.width));
            }
            let mut c = chart(
                &panels[1],
                &format!("M{i}–M{j}: true positions"),
                x,
                y,
                "x (m)",
                "y (m)",
            )?;
            if let Some(world) = &run.world {
                draw_obstacles(&mut c, world, OBSTACLE.mix(0.35).filled())?;
            }
            c.draw_series(
                conn.points
                    .iter()
                    .zip(truth)
                    .map(|(p, &q)| Circle::new(q, 4, colour(p.label).filled())),
            )?;
        }
        Ok(())
    })?;
    Ok(Figure {
        name,
        title: format!("M{i}–M{j}: inter-domain point cloud"),
        caption: format!(
            "The static agents S_{{{i},{j}}} with their nearest encounters, one colour per single-linkage cluster (one cluster = one connection). Left: classical MDS of the correspondence metric (unconnected pairs drawn at twice the largest distance){}.",
            if truth.is_some() {
                "; right: true positions"
            } else {
                ""
            }
        ),
        svg,
    })
}

/// Leaf order and x positions of a dendrogram's clusters (leaves `0..n`, merge `k` is
/// `n + k`); roots from the last merge down, children left to right.
fn dendrogram_layout(n: usize, merges: &[super::data::MergeIn]) -> Vec<f64> {
    let total = n + merges.len();
    let mut parent = vec![usize::MAX; total];
    for (k, m) in merges.iter().enumerate() {
        parent[m.a] = n + k;
        parent[m.b] = n + k;
    }
    let mut x = vec![0.0; total];
    let mut next = 0.0;
    // Depth-first from each root, with an explicit stack.
    for root in (0..total).rev().filter(|&r| parent[r] == usize::MAX) {
        let mut stack = vec![root];
        while let Some(node) = stack.pop() {
            if node < n {
                x[node] = next;
                next += 1.0;
            } else {
                let m = merges[node - n];
                stack.push(m.b);
                stack.push(m.a);
            }
        }
    }
    for (k, m) in merges.iter().enumerate() {
        x[n + k] = (x[m.a] + x[m.b]) / 2.0;
    }
    x
}

/// Figure 5: the single-linkage dendrogram of a pair's inter-domain cloud with the cut-off c.
pub fn dendrogram(conn: &ConnectionIn) -> Result<Figure, ReportError> {
    let [i, j] = conn.between;
    let name = format!("connection_{i}_dendrogram.svg");
    let n = conn.points.len();
    let finite_max = conn
        .merges
        .iter()
        .filter_map(|m| m.height)
        .fold(0.0f64, f64::max)
        .max(conn.cutoff);
    let top = if finite_max > 0.0 { finite_max } else { 1.0 };
    let never = 1.12 * top;
    let height_of = |m: &super::data::MergeIn| m.height.unwrap_or(never);
    let xs = dendrogram_layout(n, &conn.merges);
    let mut y = vec![0.0; n + conn.merges.len()];
    for (k, m) in conn.merges.iter().enumerate() {
        y[n + k] = height_of(m);
    }
    let width = (120 + 9 * n as u32).clamp(480, 1200);
    let svg = render(&name, (width, 340), |root| {
        let mut c = chart(
            root,
            &format!("M{i}–M{j}: single linkage, {} below c", clusters_said(conn)),
            (-1.0, n.max(1) as f64),
            (0.0, 1.22 * top),
            "points of the inter-domain cloud (leaf order)",
            "merge height (s)",
        )?;
        c.draw_series(conn.merges.iter().enumerate().map(|(k, m)| {
            let h = y[n + k];
            PathElement::new(
                vec![
                    (xs[m.a], y[m.a]),
                    (xs[m.a], h),
                    (xs[m.b], h),
                    (xs[m.b], y[m.b]),
                ],
                BLACK.stroke_width(1),
            )
        }))?;
        if conn.merges.iter().any(|m| m.height.is_none()) {
            c.draw_series(DashedLineSeries::new(
                vec![(-1.0, never), (n as f64, never)],
                2,
                3,
                BLACK.mix(0.5).stroke_width(1),
            ))?;
            c.draw_series(std::iter::once(Text::new(
                "not connected",
                (-0.5, never + 0.03 * top),
                (FONT, 10),
            )))?;
        }
        c.draw_series(DashedLineSeries::new(
            vec![(-1.0, conn.cutoff), (n as f64, conn.cutoff)],
            6,
            4,
            LANDMARK.stroke_width(2),
        ))?
        .label(format!("cut-off c = {} s", conn.cutoff))
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], LANDMARK.stroke_width(2)));
        c.draw_series(
            conn.points
                .iter()
                .enumerate()
                .map(|(k, p)| Circle::new((xs[k], 0.0), 3, PALETTE[p.label % 10].filled())),
        )?;
        legend(&mut c)
    })?;
    Ok(Figure {
        name,
        title: format!("M{i}–M{j}: dendrogram"),
        caption: format!(
            "Single-linkage dendrogram of the inter-domain cloud in the correspondence metric (seconds); red dashed: the cut-off c = {} s. Leaves are coloured by cluster; merges of parts the encounter graph does not connect are drawn on the dotted line.",
            conn.cutoff
        ),
        svg,
    })
}

/// Leader x at time `t` from its track (linear in between, clamped at the ends).
pub fn leader_x(track: &[(f64, f64)], t: f64) -> Option<f64> {
    let first = track.first()?;
    let last = track.last()?;
    if t <= first.0 {
        return Some(first.1);
    }
    if t >= last.0 {
        return Some(last.1);
    }
    let k = track.partition_point(|p| p.0 <= t);
    let (a, b) = (track[k - 1], track[k]);
    let f = if b.0 > a.0 {
        (t - a.0) / (b.0 - a.0)
    } else {
        0.0
    };
    Some(a.1 + f * (b.1 - a.1))
}

/// Figure 6: the global topological map as a sketch along the sweep (components as bars over
/// their domains, connections as edges, holes as rings where their cycles were seen), beside
/// the true environment, with estimated and true Betti numbers.
pub fn global(run: &RunData) -> Result<Figure, ReportError> {
    let name = "global.svg".to_string();
    let s = &run.summary;
    let by_space = s.windows.iter().all(|w| w.domain.is_some()) && !run.log.leader.is_empty();
    let extent = |w: &crate::mapping::output::WindowSummary| match (by_space, w.domain) {
        (true, Some(d)) => (d[0], d[1]),
        _ => (w.start, w.end),
    };
    let height = run.world.as_ref().map_or(1.0, |w| w.arena.height);
    let mut nodes: Vec<(f64, f64)> = Vec::with_capacity(run.global.nodes.len());
    let mut bars = Vec::new();
    for &(wi, c) in &run.global.nodes {
        let win = s.windows.iter().find(|w| w.index == wi);
        let count = run
            .windows
            .iter()
            .find(|w| w.index == wi)
            .map_or(1, |w| w.components.len().max(1));
        let (x0, x1) = win.map_or((0.0, 0.0), extent);
        let y = height * (c + 1) as f64 / (count + 1) as f64;
        nodes.push(((x0 + x1) / 2.0, y));
        bars.push((wi, x0, x1, y));
    }
    let mut holes = Vec::new();
    for &(wi, c, h) in &run.global.holes {
        let Some(w) = run.windows.iter().find(|w| w.index == wi) else {
            continue;
        };
        let Some(hole) = w.components.get(c).and_then(|comp| comp.mark(h)) else {
            continue;
        };
        let mut times: Vec<f64> = hole
            .cycle
            .iter()
            .flat_map(|&(a, b)| [a, b])
            .filter_map(|j| w.events.get(j).map(|e| e.start))
            .collect();
        times.sort_by(f64::total_cmp);
        let Some(&t) = times.get(times.len() / 2) else {
            continue;
        };
        let x = if by_space {
            leader_x(&run.log.leader, t).unwrap_or(t)
        } else {
            t
        };
        let y = run
            .global
            .nodes
            .iter()
            .position(|&n| n == (wi, c))
            .map_or(height / 2.0, |k| nodes[k].1);
        holes.push((x, y));
    }
    let x_range = if by_space {
        let w = run.world.as_ref().map_or_else(
            || {
                s.windows
                    .iter()
                    .filter_map(|w| w.domain)
                    .map(|d| d[1])
                    .fold(0.0, f64::max)
            },
            |w| w.arena.width,
        );
        (-0.02 * w, 1.02 * w)
    } else {
        span(s.windows.iter().flat_map(|w| [w.start, w.end]))
    };
    let truth = s.global.truth;
    let panels_n = 1 + usize::from(run.world.is_some());
    let svg = render(&name, (520 * panels_n as u32, 360), |root| {
        let panels = root.split_evenly((1, panels_n));
        let mut c = chart_with(
            &panels[0],
            &format!(
                "estimated global map: (β0, β1) = ({}, {})",
                s.global.betti[0], s.global.betti[1]
            ),
            x_range,
            (0.0, height),
            (
                if by_space {
                    "position along the sweep (m)"
                } else {
                    "time (s)"
                },
                "components of each window (stacked)",
            ),
            0,
        )?;
        for &(wi, x0, x1, y) in &bars {
            let col = PALETTE[(wi + 1) % 2];
            c.draw_series(std::iter::once(Rectangle::new(
                [(x0, y - 0.03 * height), (x1, y + 0.03 * height)],
                col.mix(0.25).filled(),
            )))?;
        }
        let mut multiplicity: BTreeMap<(usize, usize), usize> = BTreeMap::new();
        for &(a, b) in &run.global.edges {
            *multiplicity.entry((a.min(b), a.max(b))).or_default() += 1;
        }
        let mut drawn: BTreeMap<(usize, usize), usize> = BTreeMap::new();
        for &(a, b) in &run.global.edges {
            let key = (a.min(b), a.max(b));
            let m = multiplicity.get(&key).copied().unwrap_or(1);
            let k = drawn.entry(key).or_default();
            let off = (*k as f64 - (m as f64 - 1.0) / 2.0) * 0.09 * height;
            *k += 1;
            let (p, q) = (nodes[a], nodes[b]);
            let mid = ((p.0 + q.0) / 2.0, (p.1 + q.1) / 2.0 + off);
            c.draw_series(std::iter::once(PathElement::new(
                vec![p, mid, q],
                BLACK.stroke_width(2),
            )))?;
        }
        c.draw_series(
            run.global
                .nodes
                .iter()
                .zip(&nodes)
                .map(|(&(wi, _), &p)| Circle::new(p, 5, PALETTE[(wi + 1) % 2].filled())),
        )?;
        c.draw_series(run.global.nodes.iter().zip(&nodes).map(|(&(wi, ci), &p)| {
            Text::new(
                format!("M{wi}.{}", ci + 1),
                (p.0, p.1 + 0.05 * height),
                (FONT, 10),
            )
        }))?;
        c.draw_series(
            holes
                .iter()
                .map(|&p| Circle::new(p, 9, LANDMARK.stroke_width(3))),
        )?;
        if let Some(world) = &run.world {
            let mut c = chart(
                &panels[1],
                &match truth {
                    Some(t) => format!("true environment: (β0, β1) = ({}, {})", t[0], t[1]),
                    None => "true environment".to_string(),
                },
                (-0.02 * world.arena.width, 1.02 * world.arena.width),
                (0.0, world.arena.height),
                "x (m)",
                "y (m)",
            )?;
            draw_arena(&mut c, world, OBSTACLE)?;
        }
        Ok(())
    })?;
    Ok(Figure {
        name,
        title: "Global topological map".into(),
        caption: format!(
            "Left: each local component M_i.c as a bar over its window's {} with a dot at its centre, the connections as edges (parallel edges bent apart), and each distinct local hole as a red ring where its cycle was seen; {} gluing cycle(s). Right: the true environment.",
            if by_space { "domain D_i" } else { "time span" },
            run.global.gluing_cycles
        ),
        svg,
    })
}

/// Every figure of a run, in page order: global map, environment, then per window its
/// diagram and point cloud, then per pair its inter-domain cloud and dendrogram.
pub fn all(run: &RunData) -> Result<Vec<Figure>, ReportError> {
    let mut out = vec![global(run)?];
    out.extend(environment(run)?);
    for w in &run.windows {
        out.push(diagram(w)?);
        out.push(cloud(run, w)?);
    }
    for c in &run.connections {
        out.push(pair_cloud(run, c)?);
        out.push(dendrogram(c)?);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::data::MergeIn;

    /// Axis ranges from hand-edited maps (a scale or threshold near `f64::MAX`, NaN,
    /// reversed or empty) become finite, ordered and non-empty; plotters' tick search did
    /// not finish on the huge ones.
    #[test]
    fn axis_ranges_are_made_plottable() {
        assert_eq!(plottable((0.0, 10.0)), (0.0, 10.0));
        assert_eq!(plottable((0.0, 1e308)), (0.0, AXIS_LIMIT));
        assert_eq!(plottable((f64::NEG_INFINITY, f64::NAN)), (-AXIS_LIMIT, 0.0));
        assert_eq!(plottable((3.0, 1.0)), (1.0, 3.0));
        assert_eq!(plottable((2.0, 2.0)), (1.0, 3.0));
        assert_eq!(plottable((f64::NAN, f64::NAN)), (-1.0, 1.0));
        // Drawn, a huge range takes no longer than any other.
        let mut svg = String::new();
        {
            let root = SVGBackend::with_string(&mut svg, (200, 150)).into_drawing_area();
            chart(&root, "t", (0.0, 1e308), (-1e308, 1e308), "x", "y").unwrap();
        }
        assert!(svg.contains("<svg"));
    }

    #[test]
    fn compact_drops_defaults_and_repeated_circles_only() {
        let svg = "<svg>\n<circle cx=\"1\" cy=\"2\" r=\"3\" opacity=\"1\" fill=\"#1F77B4\" stroke=\"none\" stroke-width=\"1\"/>\n<circle cx=\"1\" cy=\"2\" r=\"3\" opacity=\"1\" fill=\"#1F77B4\" stroke=\"none\" stroke-width=\"1\"/>\n<circle cx=\"1\" cy=\"2\" r=\"7\" opacity=\"0.5\" fill=\"none\" stroke=\"#000000\" stroke-width=\"2\"/>\n<polyline points=\"0,0 1,1 \"/>\n<polyline points=\"0,0 1,1 \"/>\n</svg>\n";
        let c = compact(svg);
        assert_eq!(
            c,
            "<svg>\n<circle cx=\"1\" cy=\"2\" r=\"3\" fill=\"#1F77B4\"/>\n<circle cx=\"1\" cy=\"2\" r=\"7\" opacity=\"0.5\" fill=\"none\" stroke=\"#000000\" stroke-width=\"2\"/>\n<polyline points=\"0,0 1,1 \"/>\n<polyline points=\"0,0 1,1 \"/>\n</svg>\n"
        );
    }

    #[test]
    fn viridis_ends_and_middle() {
        assert_eq!(viridis(0.0), RGBColor(68, 1, 84));
        assert_eq!(viridis(1.0), RGBColor(253, 231, 37));
        assert_eq!(viridis(0.5), RGBColor(33, 145, 140));
        assert_eq!(viridis(f64::NAN), viridis(0.0));
    }

    #[test]
    fn dendrogram_layout_puts_merged_leaves_side_by_side() {
        // Leaves 0 and 2 merge first, then 1 joins: leaf order keeps {0, 2} adjacent.
        let m = |a, b, h| MergeIn {
            a,
            b,
            height: Some(h),
            size: 0,
        };
        let x = dendrogram_layout(3, &[m(0, 2, 1.0), m(1, 3, 2.0)]);
        assert_eq!((x[0] - x[2]).abs(), 1.0);
        assert_eq!(x[3], (x[0] + x[2]) / 2.0);
        assert_eq!(x[4], (x[1] + x[3]) / 2.0);
        let mut leaves = vec![x[0], x[1], x[2]];
        leaves.sort_by(f64::total_cmp);
        assert_eq!(leaves, vec![0.0, 1.0, 2.0]);
    }

    #[test]
    fn leader_track_interpolates_and_clamps() {
        let track = [(0.0, 1.0), (10.0, 2.0), (20.0, 4.0)];
        assert_eq!(leader_x(&track, -5.0), Some(1.0));
        assert_eq!(leader_x(&track, 5.0), Some(1.5));
        assert_eq!(leader_x(&track, 15.0), Some(3.0));
        assert_eq!(leader_x(&track, 25.0), Some(4.0));
        assert_eq!(leader_x(&[], 1.0), None);
    }

    #[test]
    fn walls_have_round_caps() {
        let o = Obstacle::Wall {
            from: (0.0, 0.0),
            to: (2.0, 0.0),
            thickness: 0.2,
        };
        let polys = obstacle_polygons(&o);
        assert_eq!(polys.len(), 3);
        // The quad spans ±0.1 m around the segment.
        let ys: Vec<f64> = polys[0].iter().map(|p| p.1).collect();
        assert!(ys.iter().all(|y| (y.abs() - 0.1).abs() < 1e-12));
    }
}
