//! The report's figures and page for a fixed run (`tests/fixtures/report/tiny`, see its
//! README): insta snapshots of every SVG, plus checks against the map files themselves
//! (markers per bar, cluster counts, the replay decoding back to `trajectories.csv`).

use std::path::Path;
use swarmmap::report::{load_run, render};

const FIXTURE: &str = "tests/fixtures/report/tiny";

#[test]
fn every_figure_matches_its_snapshot() {
    let run = load_run(Path::new(FIXTURE)).unwrap();
    let report = render(&run).unwrap();
    let names: Vec<&str> = report.figures.iter().map(|f| f.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "global.svg",
            "environment.svg",
            "window_1_diagram.svg",
            "window_1_cloud.svg",
            "window_2_diagram.svg",
            "window_2_cloud.svg",
            "connection_1_cloud.svg",
            "connection_1_dendrogram.svg",
        ]
    );
    for f in &report.figures {
        insta::assert_snapshot!(f.name.trim_end_matches(".svg"), &f.svg);
    }
}

fn json(path: &str) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(Path::new(FIXTURE).join(path)).unwrap()).unwrap()
}

#[test]
fn figures_draw_what_the_map_files_hold() {
    let run = load_run(Path::new(FIXTURE)).unwrap();
    let report = render(&run).unwrap();
    let svg = |name: &str| &report.figures.iter().find(|f| f.name == name).unwrap().svg;
    for i in 1..=2 {
        // One orange triangle per H1 bar, plus the legend's (triangles are never merged).
        let w = json(&format!("maps/window_{i}.json"));
        let h1: usize = w["components"]
            .as_array()
            .unwrap()
            .iter()
            .map(|c| {
                c["diagram"]
                    .as_array()
                    .unwrap()
                    .iter()
                    .filter(|b| b["dim"] == 1)
                    .count()
            })
            .sum();
        let components = w["components"].as_array().unwrap().len();
        let triangles = svg(&format!("window_{i}_diagram.svg"))
            .lines()
            .filter(|l| l.starts_with("<polygon") && l.contains("fill=\"#FF7F0E\""))
            .count();
        assert_eq!(triangles, h1 + components, "window {i}");
        // Each component's panel title carries its Betti numbers.
        for (c, comp) in w["components"].as_array().unwrap().iter().enumerate() {
            let title = format!(
                "W{i} component {}: (β0, β1) = ({}, {})",
                c + 1,
                comp["betti"][0],
                comp["betti"][1]
            );
            assert!(
                svg(&format!("window_{i}_diagram.svg")).contains(&title),
                "{title}"
            );
        }
    }
    let c = json("maps/connection_1.json");
    assert!(svg("connection_1_cloud.svg").contains(&format!(
        "M1–M2: {} cluster(s), c = {} s",
        c["count"],
        c["cutoff"].as_f64().unwrap()
    )));
    let s = json("summary.json");
    let g = &s["global"];
    assert!(svg("global.svg").contains(&format!(
        "estimated global map: (β0, β1) = ({}, {})",
        g["betti"][0], g["betti"][1]
    )));
    assert!(svg("global.svg").contains(&format!(
        "true environment: (β0, β1) = ({}, {})",
        g["truth"][0], g["truth"][1]
    )));
    // The page inlines every figure exactly as written to its own file.
    for f in &report.figures {
        assert!(report.html.contains(f.svg.trim()), "{} not inlined", f.name);
    }
    assert!(report.replay);
}

/// Base64 and varint decoding written independently of the library's encoder.
fn decode_replay(html: &str) -> (Vec<f64>, usize, Vec<(f64, f64, u8)>) {
    let start = html.find("id=\"replay-data\">").unwrap() + "id=\"replay-data\">".len();
    let end = start + html[start..].find("</script>").unwrap();
    let v: serde_json::Value = serde_json::from_str(&html[start..end]).unwrap();
    let times: Vec<f64> = v["times"]
        .as_array()
        .unwrap()
        .iter()
        .map(|t| t.as_f64().unwrap())
        .collect();
    let n = v["agents"].as_u64().unwrap() as usize;
    let q = v["quantum"].as_f64().unwrap();
    let mut bytes = Vec::new();
    let (mut acc, mut bits) = (0u32, 0);
    for c in v["data"].as_str().unwrap().bytes().filter(|&c| c != b'=') {
        let d = match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' => 62,
            _ => 63,
        };
        acc = (acc << 6) | u32::from(d);
        bits += 6;
        if bits >= 8 {
            bits -= 8;
            bytes.push((acc >> bits) as u8);
            acc &= (1 << bits) - 1;
        }
    }
    let mut it = bytes.into_iter();
    let mut varint = || {
        let (mut v, mut mul) = (0u64, 1u64);
        loop {
            let b = it.next().unwrap();
            v += u64::from(b & 127) * mul;
            mul *= 128;
            if b < 128 {
                return v;
            }
        }
    };
    let unzig = |v: u64| {
        if v.is_multiple_of(2) {
            (v / 2) as i64
        } else {
            -(v.div_ceil(2) as i64)
        }
    };
    let mut cur = vec![(0i64, 0i64, 0u8); n];
    let mut frames = Vec::new();
    for _ in &times {
        for c in cur.iter_mut() {
            let a = varint();
            let b = varint();
            c.0 += unzig(a / 4);
            c.1 += unzig(b);
            c.2 = (a % 4) as u8;
            frames.push((c.0 as f64 * q, c.1 as f64 * q, c.2));
        }
    }
    (times, n, frames)
}

#[test]
fn the_replay_decodes_back_to_the_trajectories() {
    let run = load_run(Path::new(FIXTURE)).unwrap();
    let report = render(&run).unwrap();
    let (times, n, frames) = decode_replay(&report.html);
    let text = std::fs::read_to_string(Path::new(FIXTURE).join("trajectories.csv")).unwrap();
    let rows: Vec<(f64, usize, f64, f64, String)> = text
        .lines()
        .skip(1)
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            (
                f[0].parse().unwrap(),
                f[1].parse().unwrap(),
                f[2].parse().unwrap(),
                f[3].parse().unwrap(),
                f[4].to_string(),
            )
        })
        .collect();
    let distinct: std::collections::BTreeSet<u64> = rows.iter().map(|r| r.0.to_bits()).collect();
    // Few enough recorded times: every one is a frame.
    assert_eq!(times.len(), distinct.len());
    assert_eq!(n, 40);
    let state = |s: &str| match s {
        "walk" => 0,
        "pause" => 1,
        "landmark" => 2,
        _ => 3,
    };
    for (k, (t, agent, x, y, s)) in rows.iter().enumerate() {
        let f = k / n;
        assert!(
            (times[f] - t).abs() < 0.006,
            "frame {f}: {} vs {t}",
            times[f]
        );
        let (dx, dy, ds) = frames[f * n + agent];
        assert!(
            (dx - x).abs() <= 0.005 + 1e-9 && (dy - y).abs() <= 0.005 + 1e-9,
            "agent {agent} at {t} s: ({dx}, {dy}) vs ({x}, {y})"
        );
        assert_eq!(ds, state(s));
    }
}

#[test]
fn rendering_the_same_run_twice_gives_the_same_bytes() {
    let run = load_run(Path::new(FIXTURE)).unwrap();
    let a = render(&run).unwrap();
    let b = render(&load_run(Path::new(FIXTURE)).unwrap()).unwrap();
    assert!(a == b);
}

/// A hole's cycle is drawn in black and its void (the death triangle) as a closed red
/// triangle, on the embedding and on the true positions.
#[test]
fn a_holes_void_is_drawn_as_a_closed_triangle() {
    let mut run = load_run(Path::new(FIXTURE)).unwrap();
    let w = &mut run.windows[0];
    let e = w.components[0].events.clone();
    w.components[0].holes.push(swarmmap::report::data::HoleIn {
        birth: 1.0,
        death: 2.0,
        cycle: vec![(e[0], e[1]), (e[1], e[2]), (e[0], e[2])],
        void: Some([e[3], e[4], e[5]]),
    });
    let report = render(&run).unwrap();
    let svg = &report
        .figures
        .iter()
        .find(|f| f.name == "window_1_cloud.svg")
        .unwrap()
        .svg;
    let red: Vec<&str> = svg
        .lines()
        .filter(|l| l.starts_with("<polyline") && l.contains("stroke=\"#FF0000\""))
        .collect();
    // One on the embedding panel, one on the true positions.
    assert_eq!(red.len(), 2, "{red:?}");
    for l in red {
        let pts: Vec<&str> = l
            .split("points=\"")
            .nth(1)
            .unwrap()
            .split_whitespace()
            .filter(|p| p.contains(','))
            .collect();
        assert_eq!(pts.len(), 4, "{l}");
        assert_eq!(pts[0], pts[3], "not closed: {l}");
    }
    assert!(
        report
            .figures
            .iter()
            .any(|f| f.caption.contains("red: the triangle"))
    );
}
