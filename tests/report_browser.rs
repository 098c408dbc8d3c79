//! The report page in a real browser: headless Chromium (Debian's `chromium`, installed by
//! `scripts/install-chromium.sh`) loads `report/index.html` of a fresh run from disk. The test
//! fails on any console error or uncaught exception, checks that every figure rendered with
//! a non-zero size, presses play and sees the replay's time advance, and saves a screenshot.
//!
//! Chromium is driven through the DevTools protocol over `--remote-debugging-pipe` (file
//! descriptors 3 and 4, NUL-separated JSON messages): no port, no WebSocket client, no
//! extra crate (see ARCHITECTURE.md, "Crates, and why"). Without Chromium the test prints a
//! loud SKIPPED banner and passes. `SWARMMAP_CHROMIUM=/path/to/chrome` picks the binary.

use serde_json::{Value, json};
use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, ChildStdin, Command, Stdio};
use std::sync::mpsc::{Receiver, RecvTimeoutError, channel};
use std::time::{Duration, Instant};

const TINY: &str = "tests/fixtures/worlds/tiny.ron";

/// The Chromium binary: `$SWARMMAP_CHROMIUM`, else the first of the usual names on PATH.
fn find_chromium() -> Option<PathBuf> {
    if let Some(p) = std::env::var_os("SWARMMAP_CHROMIUM") {
        return Some(PathBuf::from(p));
    }
    let path = std::env::var_os("PATH")?;
    for dir in std::env::split_paths(&path) {
        for name in ["chromium", "chromium-browser", "google-chrome", "chrome"] {
            let p = dir.join(name);
            if p.is_file() {
                return Some(p);
            }
        }
    }
    None
}

/// Writes past the test harness's output capture, so the message shows in a plain
/// `cargo test` run.
fn shout(msg: &str) {
    let _ = writeln!(std::io::stderr().lock(), "{msg}");
}

struct Browser {
    child: Child,
    input: ChildStdin,
    messages: Receiver<Value>,
    pending: Vec<Value>,
    next_id: u64,
    session: Option<String>,
}

impl Browser {
    fn launch(chrome: &Path, profile: &Path, log: &Path) -> Browser {
        let stderr = std::fs::File::create(log).unwrap();
        // The shell moves our pipes to the descriptors Chromium reads (3) and writes (4).
        let mut child = Command::new("sh")
            .arg("-c")
            .arg(r#"exec "$0" "$@" 3<&0 4>&1 0</dev/null 1>&2"#)
            .arg(chrome)
            .args([
                "--headless",
                "--no-sandbox",
                "--disable-gpu",
                "--disable-background-networking",
                "--remote-debugging-pipe",
                "--no-first-run",
                "--no-default-browser-check",
                "--hide-scrollbars",
            ])
            .arg(format!("--user-data-dir={}", profile.display()))
            .arg("about:blank")
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(stderr)
            .spawn()
            .expect("start chromium");
        let input = child.stdin.take().unwrap();
        let output = child.stdout.take().unwrap();
        let (tx, messages) = channel();
        std::thread::spawn(move || {
            let mut reader = BufReader::new(output);
            let mut buf = Vec::new();
            loop {
                buf.clear();
                match reader.read_until(0, &mut buf) {
                    Ok(0) | Err(_) => return,
                    Ok(_) => {
                        if buf.last() == Some(&0) {
                            buf.pop();
                        }
                        if let Ok(v) = serde_json::from_slice::<Value>(&buf)
                            && tx.send(v).is_err()
                        {
                            return;
                        }
                    }
                }
            }
        });
        Browser {
            child,
            input,
            messages,
            pending: Vec::new(),
            next_id: 1,
            session: None,
        }
    }

    fn recv(&mut self, deadline: Instant) -> Option<Value> {
        let left = deadline.saturating_duration_since(Instant::now());
        match self.messages.recv_timeout(left) {
            Ok(v) => Some(v),
            Err(RecvTimeoutError::Timeout) => None,
            Err(RecvTimeoutError::Disconnected) => panic!("chromium closed the DevTools pipe"),
        }
    }

    /// Sends a command (to the page session once attached) and waits for its result.
    fn call(&mut self, method: &str, params: Value) -> Value {
        let id = self.next_id;
        self.next_id += 1;
        let mut msg = json!({"id": id, "method": method, "params": params});
        if let Some(s) = &self.session {
            msg["sessionId"] = json!(s);
        }
        let mut bytes = serde_json::to_vec(&msg).unwrap();
        bytes.push(0);
        self.input.write_all(&bytes).unwrap();
        self.input.flush().unwrap();
        let deadline = Instant::now() + Duration::from_secs(30);
        loop {
            let v = self
                .recv(deadline)
                .unwrap_or_else(|| panic!("no answer to {method} within 30 s"));
            if v.get("id") == Some(&json!(id)) {
                if let Some(e) = v.get("error") {
                    panic!("{method} failed: {e}");
                }
                return v["result"].clone();
            }
            self.pending.push(v);
        }
    }

    /// Waits for an event of the page session.
    fn wait_event(&mut self, method: &str, timeout: Duration) -> Value {
        if let Some(k) = self.pending.iter().position(|v| v["method"] == method) {
            return self.pending.remove(k);
        }
        let deadline = Instant::now() + timeout;
        loop {
            let v = self
                .recv(deadline)
                .unwrap_or_else(|| panic!("no {method} within {timeout:?}"));
            if v["method"] == method {
                return v;
            }
            self.pending.push(v);
        }
    }

    /// Drains what has arrived and returns every console error and uncaught exception.
    fn errors(&mut self) -> Vec<String> {
        while let Ok(v) = self.messages.try_recv() {
            self.pending.push(v);
        }
        let mut out = Vec::new();
        for v in &self.pending {
            let p = &v["params"];
            match v["method"].as_str() {
                Some("Runtime.exceptionThrown") => {
                    out.push(format!("uncaught exception: {}", p["exceptionDetails"]))
                }
                Some("Runtime.consoleAPICalled")
                    if p["type"] == "error" || p["type"] == "assert" =>
                {
                    out.push(format!("console.{}: {}", p["type"], p["args"]))
                }
                Some("Log.entryAdded") if p["entry"]["level"] == "error" => {
                    out.push(format!("log error: {}", p["entry"]))
                }
                _ => {}
            }
        }
        out
    }

    fn eval(&mut self, expression: &str) -> Value {
        let r = self.call(
            "Runtime.evaluate",
            json!({"expression": expression, "returnByValue": true, "awaitPromise": true}),
        );
        if let Some(e) = r.get("exceptionDetails") {
            panic!("evaluating {expression}: {e}");
        }
        r["result"]["value"].clone()
    }

    /// Opens a page in a new tab, attaches to it and loads `url`.
    fn open(&mut self, url: &str, size: (u32, u32)) {
        let target = self.call("Target.createTarget", json!({"url": "about:blank"}));
        let attached = self.call(
            "Target.attachToTarget",
            json!({"targetId": target["targetId"], "flatten": true}),
        );
        self.session = Some(attached["sessionId"].as_str().unwrap().to_string());
        self.call("Runtime.enable", json!({}));
        self.call("Log.enable", json!({}));
        self.call("Page.enable", json!({}));
        self.call(
            "Emulation.setDeviceMetricsOverride",
            json!({"width": size.0, "height": size.1, "deviceScaleFactor": 1, "mobile": false}),
        );
        self.call("Page.navigate", json!({"url": url}));
        self.wait_event("Page.loadEventFired", Duration::from_secs(30));
    }

    /// Clicks the centre of the element `selector` with real mouse events.
    fn click(&mut self, selector: &str) {
        let rect = self.eval(&format!(
            "(() => {{ const e = document.querySelector('{selector}'); e.scrollIntoView({{block: 'center'}}); const r = e.getBoundingClientRect(); return [r.x + r.width / 2, r.y + r.height / 2]; }})()"
        ));
        let (x, y) = (rect[0].as_f64().unwrap(), rect[1].as_f64().unwrap());
        for kind in ["mousePressed", "mouseReleased"] {
            self.call(
                "Input.dispatchMouseEvent",
                json!({"type": kind, "x": x, "y": y, "button": "left", "clickCount": 1}),
            );
        }
    }

    fn screenshot(&mut self, path: &Path) {
        let shot = self.call("Page.captureScreenshot", json!({"format": "png"}));
        let png = base64_decode(shot["data"].as_str().unwrap());
        assert!(png.starts_with(b"\x89PNG"), "not a PNG");
        std::fs::write(path, png).unwrap();
    }

    fn close(mut self) {
        self.session = None;
        let id = self.next_id;
        let msg = json!({"id": id, "method": "Browser.close", "params": {}});
        let mut bytes = serde_json::to_vec(&msg).unwrap();
        bytes.push(0);
        let _ = self.input.write_all(&bytes);
        let deadline = Instant::now() + Duration::from_secs(10);
        while Instant::now() < deadline {
            if let Ok(Some(_)) = self.child.try_wait() {
                return;
            }
            std::thread::sleep(Duration::from_millis(50));
        }
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

fn base64_decode(s: &str) -> Vec<u8> {
    let value = |c: u8| match c {
        b'A'..=b'Z' => c - b'A',
        b'a'..=b'z' => c - b'a' + 26,
        b'0'..=b'9' => c - b'0' + 52,
        b'+' => 62,
        b'/' => 63,
        _ => panic!("not base64: {c}"),
    };
    let mut out = Vec::with_capacity(s.len() * 3 / 4);
    let (mut bits, mut n) = (0u32, 0);
    for c in s.bytes().filter(|&c| c != b'=' && !c.is_ascii_whitespace()) {
        bits = (bits << 6) | u32::from(value(c));
        n += 6;
        if n >= 8 {
            n -= 8;
            out.push((bits >> n) as u8);
            bits &= (1 << n) - 1;
        }
    }
    out
}

/// Loads a report page, runs every check and saves a screenshot; returns the figure count.
/// With `poster`, the screenshot shows the top of the page with the replay paused halfway
/// (the README's picture); else the page as it is after pressing play.
fn check_page(
    chrome: &Path,
    index: &Path,
    screenshot: &Path,
    size: (u32, u32),
    poster: bool,
) -> usize {
    let tmp = tempfile::tempdir().unwrap();
    let log = tmp.path().join("chromium.log");
    let mut b = Browser::launch(chrome, &tmp.path().join("profile"), &log);
    let url = format!("file://{}", index.canonicalize().unwrap().display());
    b.open(&url, size);

    // Every figure rendered, with a non-zero size and drawn content.
    let figs = b.eval(
        "({expected: Number(document.body.dataset.figures), figures: Array.from(document.querySelectorAll('figure.fig')).map(f => { const s = f.querySelector('svg'); const r = s ? s.getBoundingClientRect() : {width: 0, height: 0}; return {id: f.id, width: r.width, height: r.height, shapes: s ? s.querySelectorAll('circle, polyline, path, rect, polygon, line').length : 0}; })})",
    );
    let figures = figs["figures"].as_array().unwrap();
    assert!(!figures.is_empty(), "no figures on the page");
    assert_eq!(figures.len() as u64, figs["expected"].as_u64().unwrap());
    for f in figures {
        assert!(
            f["width"].as_f64().unwrap() > 0.0 && f["height"].as_f64().unwrap() > 0.0,
            "figure rendered with zero size: {f}"
        );
        assert!(
            f["shapes"].as_u64().unwrap() > 0,
            "figure draws nothing: {f}"
        );
    }

    // The replay: press play, and its time advances.
    let before = b.eval("document.getElementById('replay-time').dataset.frame");
    assert_eq!(before, json!("0"), "replay does not start at frame 0");
    b.click("#replay-play");
    std::thread::sleep(Duration::from_millis(1500));
    let after = b.eval("({frame: Number(document.getElementById('replay-time').dataset.frame), text: document.getElementById('replay-time').textContent, button: document.getElementById('replay-play').textContent})");
    assert!(
        after["frame"].as_u64().unwrap() > 0,
        "the replay's time did not advance after pressing play: {after}"
    );
    assert_ne!(after["text"], json!("t = 0 s"), "{after}");
    if poster {
        b.click("#replay-play");
        b.eval("(() => { const s = document.getElementById('replay-slider'); s.value = String(Math.round(Number(s.max) * 0.55)); s.dispatchEvent(new Event('input')); window.scrollTo(0, 0); return true; })()");
        std::thread::sleep(Duration::from_millis(300));
    }
    b.screenshot(screenshot);

    let errors = b.errors();
    b.close();
    assert!(
        errors.is_empty(),
        "console errors:\n{}\nchromium log: {}",
        errors.join("\n"),
        std::fs::read_to_string(&log).unwrap_or_default()
    );
    figures.len()
}

#[test]
fn the_report_page_works_in_headless_chromium() {
    let Some(chrome) = find_chromium() else {
        shout(
            "\n==================================================================\n\
             SKIPPED the_report_page_works_in_headless_chromium: Chromium not found.\n\
             Install it with scripts/install-chromium.sh (Debian's `chromium`),\n\
             or set SWARMMAP_CHROMIUM=/path/to/chromium.\n\
             ==================================================================\n",
        );
        return;
    };
    let tmp = tempfile::tempdir().unwrap();
    let run = tmp.path().join("run");
    let status = Command::new(env!("CARGO_BIN_EXE_swarmmap"))
        .args(["run", TINY, "--quiet", "--out"])
        .arg(&run)
        .stdout(Stdio::null())
        .status()
        .unwrap();
    assert!(status.success());
    let shot = Path::new(env!("CARGO_TARGET_TMPDIR")).join("report-tiny.png");
    let n = check_page(
        &chrome,
        &run.join("report/index.html"),
        &shot,
        (1280, 1000),
        false,
    );
    assert_eq!(
        n, 8,
        "tiny: global, environment, 2 × 2 per window, 2 per pair"
    );
    shout(&format!("report screenshot: {}", shot.display()));
}

/// Screenshot of any report: `SWARMMAP_REPORT=RUN_DIR/report/index.html
/// SWARMMAP_SCREENSHOT=out.png cargo test --release --test report_browser -- --ignored`
/// (how `assets/report-scenario2.png` was made).
#[test]
#[ignore = "needs SWARMMAP_REPORT and SWARMMAP_SCREENSHOT; makes the README's screenshot"]
fn screenshot_of_a_report() {
    let chrome = find_chromium().expect("chromium");
    let index = PathBuf::from(std::env::var_os("SWARMMAP_REPORT").expect("SWARMMAP_REPORT"));
    let out = PathBuf::from(std::env::var_os("SWARMMAP_SCREENSHOT").expect("SWARMMAP_SCREENSHOT"));
    check_page(&chrome, &index, &out, (1280, 1450), true);
}
