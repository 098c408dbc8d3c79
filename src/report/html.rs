//! The report page: one self-contained HTML file (inline CSS, inline SVG figures, inline
//! script and replay data; no network, opens from `file://`). Built from strings in a fixed
//! order, so the same inputs give the same bytes.

use super::data::RunData;
use super::figures::{Figure, leader_x, obstacle_polygons};
use super::replay::{QUANTUM, Replay};
use serde_json::json;
use std::fmt::Write as _;

/// Escapes text for HTML content and attribute values.
pub fn escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

fn opt(v: Option<f64>, digits: usize) -> String {
    v.map_or_else(|| "–".to_string(), |x| format!("{x:.digits$}"))
}

fn verdict(ok: Option<bool>) -> &'static str {
    match ok {
        Some(true) => "<td class=\"ok\">ok</td>",
        Some(false) => "<td class=\"wrong\">WRONG</td>",
        None => "<td>–</td>",
    }
}

fn betti(b: [usize; 2]) -> String {
    format!("({}, {})", b[0], b[1])
}

fn summary_tables(run: &RunData) -> String {
    let s = &run.summary;
    let mut h = String::new();
    h.push_str("<table id=\"windows\"><caption>Local maps: estimated vs true (β0, β1) per window, and geometric fidelity</caption>\n<thead><tr><th>window</th><th>span (s)</th><th>domain D<sub>i</sub> (m)</th><th>events</th><th>estimated</th><th>true</th><th></th><th>Spearman ρ</th><th>Procrustes</th></tr></thead><tbody>\n");
    for w in &s.windows {
        let _ = writeln!(
            h,
            "<tr><td>W{}</td><td>{:.0}–{:.0}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td>{}<td>{}</td><td>{}</td></tr>",
            w.index,
            w.start,
            w.end,
            w.domain
                .map_or_else(|| "–".into(), |d| format!("{:.1}–{:.1}", d[0], d[1])),
            w.events,
            betti(w.betti),
            w.truth.map_or_else(|| "–".into(), betti),
            verdict(w.truth.map(|t| t == w.betti)),
            opt(w.fidelity.spearman, 2),
            opt(w.fidelity.procrustes, 3),
        );
    }
    h.push_str("</tbody></table>\n");
    h.push_str("<table id=\"connections\"><caption>Connections between consecutive maps (clusters of the inter-domain cloud)</caption>\n<thead><tr><th>pair</th><th>estimated</th><th>true</th><th></th></tr></thead><tbody>\n");
    for c in &s.connections {
        let _ = writeln!(
            h,
            "<tr><td>M{}–M{}</td><td>{}</td><td>{}</td>{}</tr>",
            c.between[0],
            c.between[1],
            c.count,
            c.truth.map_or_else(|| "–".into(), |t| t.to_string()),
            verdict(c.truth.map(|t| t == c.count)),
        );
    }
    h.push_str("</tbody></table>\n");
    let _ = writeln!(
        h,
        "<table id=\"global\"><caption>Global map</caption>\n<thead><tr><th></th><th>estimated</th><th>true</th><th></th><th>gluing cycles</th></tr></thead><tbody>\n<tr><td>(β0, β1)</td><td>{}</td><td>{}</td>{}<td>{}</td></tr>\n</tbody></table>",
        betti(s.global.betti),
        s.global.truth.map_or_else(|| "–".into(), betti),
        verdict(s.global.truth.map(|t| t == s.global.betti)),
        s.global.gluing_cycles,
    );
    let total: f64 = s.timings.values().sum();
    h.push_str("<table id=\"timings\"><caption>Time per stage (wall clock, from summary.json)</caption>\n<thead><tr><th>stage</th><th>seconds</th><th>share</th></tr></thead><tbody>\n");
    for (k, v) in &s.timings {
        let _ = writeln!(
            h,
            "<tr><td>{}</td><td>{v:.2}</td><td>{:.0} %</td></tr>",
            escape(k),
            100.0 * v / total.max(1e-12)
        );
    }
    let _ = writeln!(
        h,
        "<tr><td><b>total</b></td><td><b>{total:.2}</b></td><td></td></tr>"
    );
    for (k, v) in &s.alongside {
        let _ = writeln!(
            h,
            "<tr><td>{} (alongside the simulation, another core)</td><td>{v:.2}</td><td></td></tr>",
            escape(k)
        );
    }
    h.push_str("</tbody></table>\n");
    h
}

fn round(v: f64) -> f64 {
    (v / QUANTUM).round() * QUANTUM
}

/// The replay's JSON payload: frames, arena, obstacles and the leader's x per frame.
fn replay_json(run: &RunData, r: &Replay) -> String {
    let (arena, obstacles, window) = match &run.world {
        Some(w) => (
            [w.arena.width, w.arena.height],
            w.obstacles
                .iter()
                .flat_map(obstacle_polygons)
                .map(|p| p.iter().map(|q| [round(q.0), round(q.1)]).collect())
                .collect::<Vec<Vec<[f64; 2]>>>(),
            Some(w.leader.window),
        ),
        None => {
            let t = run.trajectories.as_deref().unwrap_or_default();
            let w = t.iter().map(|s| s.x).fold(0.0f64, f64::max);
            let h = t.iter().map(|s| s.y).fold(0.0f64, f64::max);
            ([w.max(1.0), h.max(1.0)], Vec::new(), None)
        }
    };
    let leader: Option<Vec<f64>> = (!run.log.leader.is_empty()).then(|| {
        r.times
            .iter()
            .map(|&t| round(leader_x(&run.log.leader, t).unwrap_or(0.0)))
            .collect()
    });
    json!({
        "agents": r.agents.len(),
        "times": r.times.iter().map(|&t| (t * 100.0).round() / 100.0).collect::<Vec<_>>(),
        "quantum": QUANTUM,
        "data": r.data,
        "arena": arena,
        "obstacles": obstacles,
        "leader": leader,
        "window": window,
    })
    .to_string()
}

const STYLE: &str = r#"
body { font-family: sans-serif; margin: 0 auto; max-width: 1100px; padding: 0 16px 48px; color: #222; }
h1 { font-size: 1.5em; margin: 18px 0 4px; }
h2 { font-size: 1.2em; border-bottom: 1px solid #ccc; padding-bottom: 4px; margin-top: 28px; }
p.meta { color: #555; margin: 0 0 8px; }
nav { font-size: 0.9em; }
table { border-collapse: collapse; margin: 8px 16px 12px 0; font-size: 0.9em; display: inline-table; vertical-align: top; }
caption { text-align: left; font-weight: bold; padding-bottom: 4px; }
th, td { border: 1px solid #ccc; padding: 3px 8px; text-align: right; }
td.ok { color: #2a7d2a; font-weight: bold; }
td.wrong { color: #c0282a; font-weight: bold; }
figure { margin: 12px 0 24px; }
figure svg { max-width: 100%; height: auto; display: block; border: 1px solid #eee; }
figcaption { font-size: 0.85em; color: #444; max-width: 960px; margin-top: 4px; }
#replay-canvas { border: 1px solid #ccc; max-width: 100%; display: block; }
.controls { margin: 6px 0; display: flex; gap: 12px; align-items: center; }
.controls input[type=range] { flex: 1; max-width: 700px; }
.key span { display: inline-block; margin-right: 14px; font-size: 0.85em; }
.key i { display: inline-block; width: 10px; height: 10px; margin-right: 4px; vertical-align: middle; }
"#;

const SCRIPT: &str = r#"
(function () {
  'use strict';
  var src = document.getElementById('replay-data');
  if (!src) { return; }
  var R = JSON.parse(src.textContent);
  var bin = atob(R.data), bytes = new Uint8Array(bin.length);
  for (var i = 0; i < bin.length; i++) { bytes[i] = bin.charCodeAt(i); }
  var F = R.times.length, N = R.agents, pos = 0;
  var X = new Float32Array(F * N), Y = new Float32Array(F * N), S = new Uint8Array(F * N);
  function next() {
    var v = 0, mul = 1, b;
    do { b = bytes[pos++]; v += (b & 127) * mul; mul *= 128; } while (b >= 128);
    return v;
  }
  function unzig(v) { return v % 2 === 0 ? v / 2 : -(v + 1) / 2; }
  var cx = new Array(N).fill(0), cy = new Array(N).fill(0);
  for (var f = 0; f < F; f++) {
    for (var k = 0; k < N; k++) {
      var a = next(), b = next();
      cx[k] += unzig(Math.floor(a / 4));
      cy[k] += unzig(b);
      X[f * N + k] = cx[k] * R.quantum;
      Y[f * N + k] = cy[k] * R.quantum;
      S[f * N + k] = a % 4;
    }
  }
  var canvas = document.getElementById('replay-canvas');
  var ctx = canvas.getContext('2d');
  var W = R.arena[0], H = R.arena[1], pad = 12;
  var scale = Math.min((960 - 2 * pad) / W, (520 - 2 * pad) / H);
  canvas.width = Math.round(W * scale + 2 * pad);
  canvas.height = Math.round(H * scale + 2 * pad);
  function px(x) { return pad + x * scale; }
  function py(y) { return pad + (H - y) * scale; }
  var colours = ['#1f3a93', '#9a9a9a', '#d62728', '#ff7f0e'];
  var slider = document.getElementById('replay-slider');
  var label = document.getElementById('replay-time');
  var button = document.getElementById('replay-play');
  slider.max = String(F - 1);
  var frame = 0, playing = false, last = null, FPS = 30;
  function draw() {
    var i = Math.min(Math.floor(frame), F - 1), j = Math.min(i + 1, F - 1), t = frame - i;
    ctx.fillStyle = '#fff';
    ctx.fillRect(0, 0, canvas.width, canvas.height);
    if (R.leader && R.window) {
      var lx = R.leader[i] + (R.leader[j] - R.leader[i]) * t;
      var x0 = Math.max(0, lx - R.window / 2), x1 = Math.min(W, lx + R.window / 2);
      ctx.fillStyle = 'rgba(31, 119, 180, 0.13)';
      ctx.fillRect(px(x0), py(H), (x1 - x0) * scale, H * scale);
      ctx.strokeStyle = 'rgba(31, 119, 180, 0.9)';
      ctx.lineWidth = 2;
      ctx.strokeRect(px(x0), py(H), (x1 - x0) * scale, H * scale);
      ctx.fillStyle = '#1f77b4';
      ctx.beginPath();
      ctx.arc(px(lx), py(H) - 1, 6, 0, 2 * Math.PI);
      ctx.fill();
    }
    ctx.fillStyle = '#5a5a5a';
    R.obstacles.forEach(function (p) {
      ctx.beginPath();
      p.forEach(function (q, n) { if (n === 0) { ctx.moveTo(px(q[0]), py(q[1])); } else { ctx.lineTo(px(q[0]), py(q[1])); } });
      ctx.closePath();
      ctx.fill();
    });
    ctx.strokeStyle = '#000';
    ctx.lineWidth = 2;
    ctx.strokeRect(px(0), py(H), W * scale, H * scale);
    for (var k = 0; k < N; k++) {
      var a = i * N + k, b = j * N + k, s = S[a];
      var x = X[a] + (X[b] - X[a]) * t, y = Y[a] + (Y[b] - Y[a]) * t;
      ctx.fillStyle = colours[s];
      if (s === 2) { ctx.fillRect(px(x) - 3.5, py(y) - 3.5, 7, 7); }
      else { ctx.beginPath(); ctx.arc(px(x), py(y), 2.5, 0, 2 * Math.PI); ctx.fill(); }
    }
    label.textContent = 't = ' + (R.times[i] + (R.times[j] - R.times[i]) * t).toFixed(0) + ' s';
    label.setAttribute('data-frame', String(i));
    slider.value = String(i);
  }
  function tick(now) {
    if (!playing) { return; }
    if (last !== null) { frame = Math.min(F - 1, frame + (now - last) / 1000 * FPS); }
    last = now;
    draw();
    if (frame >= F - 1) { setPlaying(false); return; }
    requestAnimationFrame(tick);
  }
  function setPlaying(on) {
    playing = on;
    button.textContent = on ? 'Pause' : 'Play';
    if (on) {
      if (frame >= F - 1) { frame = 0; }
      last = null;
      requestAnimationFrame(tick);
    }
  }
  button.addEventListener('click', function () { setPlaying(!playing); });
  slider.addEventListener('input', function () { frame = Number(slider.value); draw(); });
  draw();
})();
"#;

/// The whole page.
pub fn page(run: &RunData, figures: &[Figure], replay: Option<&Replay>) -> String {
    let s = &run.summary;
    let title = format!(
        "swarmmap report: {} (seed {})",
        s.world,
        s.seed.map_or_else(|| "–".into(), |x| x.to_string())
    );
    let mut h = String::new();
    let _ = write!(
        h,
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n<title>{}</title>\n<link rel=\"icon\" href=\"data:,\">\n<style>{STYLE}</style>\n</head>\n<body data-figures=\"{}\">\n<h1>{}</h1>\n",
        escape(&title),
        figures.len(),
        escape(&title)
    );
    let source = match &run.world {
        Some(w) => format!(
            "World <b>{}</b>: arena {} m × {} m, {} obstacle(s), {} agents, {} windows. ",
            escape(&w.name),
            w.arena.width,
            w.arena.height,
            w.obstacles.len(),
            w.swarm.agents,
            s.windows.len()
        ),
        None => "A log without a world file: no ground truth, no environment. ".to_string(),
    };
    let _ = writeln!(
        h,
        "<p class=\"meta\">{source}Generated by swarmmap {} from the files of the run directory (<code>swarmmap report RUN_DIR</code> regenerates it).</p>",
        env!("CARGO_PKG_VERSION")
    );
    h.push_str("<nav><a href=\"#summary\">Summary</a> · <a href=\"#replay\">Replay</a>");
    for f in figures {
        let _ = write!(
            h,
            " · <a href=\"#fig-{}\">{}</a>",
            escape(f.name.trim_end_matches(".svg")),
            escape(&f.title)
        );
    }
    h.push_str("</nav>\n<section id=\"summary\">\n<h2>Summary</h2>\n");
    h.push_str(&summary_tables(run));
    h.push_str("</section>\n<section id=\"replay\">\n<h2>Replay</h2>\n");
    match replay {
        Some(r) => {
            let _ = write!(
                h,
                "<canvas id=\"replay-canvas\" width=\"960\" height=\"340\"></canvas>\n<div class=\"controls\"><button id=\"replay-play\" type=\"button\">Play</button><input id=\"replay-slider\" type=\"range\" min=\"0\" max=\"{}\" step=\"1\" value=\"0\" aria-label=\"time\"><span id=\"replay-time\" data-frame=\"0\">t = 0 s</span></div>\n<p class=\"key\"><span><i style=\"background:#1f3a93;border-radius:5px\"></i>walking</span><span><i style=\"background:#9a9a9a;border-radius:5px\"></i>paused</span><span><i style=\"background:#ff7f0e;border-radius:5px\"></i>returning to D(t)</span><span><i style=\"background:#d62728\"></i>landmark</span><span><i style=\"background:rgba(31,119,180,0.3)\"></i>the leader's domain D(t)</span> {} frames of {} agents, {:.0}–{:.0} s (positions to 1 cm).</p>\n<script type=\"application/json\" id=\"replay-data\">{}</script>\n",
                r.times.len().saturating_sub(1),
                r.times.len(),
                r.agents.len(),
                r.times.first().copied().unwrap_or(0.0),
                r.times.last().copied().unwrap_or(0.0),
                replay_json(run, r)
            );
        }
        None if run.trajectories.is_some() => h.push_str("<p id=\"replay-unavailable\">Replay unavailable: this run's <code>trajectories.csv</code> holds no samples.</p>\n"),
        None => h.push_str("<p id=\"replay-unavailable\">Replay unavailable: this run has no <code>trajectories.csv</code>. <code>swarmmap run</code> records one by default; <code>swarmmap simulate --trajectories</code> does on request.</p>\n"),
    }
    h.push_str("</section>\n<section id=\"figures\">\n<h2>Figures</h2>\n");
    for f in figures {
        let _ = write!(
            h,
            "<figure class=\"fig\" id=\"fig-{}\">\n<h3>{}</h3>\n{}\n<figcaption>{} <a href=\"{}\">{}</a></figcaption>\n</figure>\n",
            escape(f.name.trim_end_matches(".svg")),
            escape(&f.title),
            f.svg.trim(),
            escape(&f.caption),
            escape(&f.name),
            escape(&f.name)
        );
    }
    h.push_str("</section>\n");
    if replay.is_some() {
        let _ = writeln!(h, "<script>{SCRIPT}</script>");
    }
    h.push_str("</body>\n</html>\n");
    h
}
