//! The review page in a real browser: after a change to the arrow scene's light, `harness check`
//! writes the report, and the system Chromium, driven over the Chrome DevTools Protocol, opens it
//! the way a reviewer would: failures come first, the failures-only filter hides the passing
//! rows, the swipe slider moves, the pixel inspector prints the values stored in the golden and
//! the output (fp16 for the light buffer, 8-bit for the final image), zoom keeps the pixel under
//! the pointer, and the exposure control changes how the HDR pass is shown.
//!
//! Needs Chromium (`apt-get install -y chromium`; CI installs it). Without it the test says so
//! on stderr and passes, unless REQUIRE_CHROMIUM=1.

use crate::common;
use std::net::TcpStream;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use serde_json::{json, Value};
use tungstenite::stream::MaybeTlsStream;
use tungstenite::{Message, WebSocket};

pub(crate) fn chromium() -> Option<&'static str> {
    [
        "/usr/bin/chromium",
        "/usr/bin/chromium-browser",
        "/usr/bin/google-chrome",
    ]
    .into_iter()
    .find(|p| Path::new(p).exists())
}

/// A headless Chromium and one page of it, driven over the DevTools Protocol (JSON messages on
/// a WebSocket; the few commands the test needs).
pub(crate) struct Browser {
    child: Child,
    socket: WebSocket<MaybeTlsStream<TcpStream>>,
    next_id: u64,
    session: Option<String>,
    /// Names of the events received so far.
    events: Vec<String>,
    _profile: tempfile::TempDir,
}

impl Browser {
    pub(crate) fn launch(executable: &str) -> Browser {
        let profile = tempfile::tempdir().unwrap();
        let child = Command::new(executable)
            .args([
                "--headless",
                "--no-sandbox",
                "--disable-gpu",
                "--disable-quic",
                "--no-first-run",
                "--disable-background-networking",
                "--disable-component-update",
                "--disable-sync",
                "--hide-scrollbars",
                "--remote-debugging-port=0",
            ])
            .arg(format!("--user-data-dir={}", profile.path().display()))
            .arg("about:blank")
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        // Chromium writes the port it listens on, and the browser's endpoint, into the profile.
        let port_file = profile.path().join("DevToolsActivePort");
        let started = Instant::now();
        let endpoint = loop {
            if let Ok(text) = std::fs::read_to_string(&port_file) {
                let lines: Vec<&str> = text.lines().collect();
                if lines.len() >= 2 {
                    break format!("ws://127.0.0.1:{}{}", lines[0], lines[1]);
                }
            }
            assert!(
                started.elapsed() < Duration::from_secs(60),
                "Chromium did not open its DevTools port"
            );
            std::thread::sleep(Duration::from_millis(50));
        };
        let (socket, _) = tungstenite::connect(endpoint).unwrap();
        Browser {
            child,
            socket,
            next_id: 0,
            session: None,
            events: Vec::new(),
            _profile: profile,
        }
    }

    /// Reads the next message, noting events.
    fn receive(&mut self) -> Value {
        loop {
            if let Message::Text(text) = self.socket.read().unwrap() {
                let message: Value = serde_json::from_str(&text).unwrap();
                if let Some(event) = message["method"].as_str() {
                    self.events.push(event.to_owned());
                }
                return message;
            }
        }
    }

    /// Waits until the page has sent the event `name`.
    fn wait_for(&mut self, name: &str) {
        while !self.events.iter().any(|e| e == name) {
            self.receive();
        }
    }

    /// Sends a command and waits for its answer (noting the events in between).
    fn call(&mut self, method: &str, params: Value) -> Value {
        self.next_id += 1;
        let id = self.next_id;
        let mut message = json!({ "id": id, "method": method, "params": params });
        if let Some(session) = &self.session {
            message["sessionId"] = json!(session);
        }
        self.socket
            .send(Message::text(message.to_string()))
            .unwrap();
        loop {
            let answer = self.receive();
            if answer["id"] == json!(id) {
                assert!(
                    answer.get("error").is_none(),
                    "{method} failed: {}",
                    answer["error"]
                );
                return answer["result"].clone();
            }
        }
    }

    /// Opens `url` in a new page of 1600x1200 CSS pixels and talks to that page from now on.
    pub(crate) fn open(&mut self, url: &str) {
        let target = self.call("Target.createTarget", json!({ "url": "about:blank" }));
        let attached = self.call(
            "Target.attachToTarget",
            json!({ "targetId": target["targetId"], "flatten": true }),
        );
        self.session = Some(attached["sessionId"].as_str().unwrap().to_owned());
        self.call(
            "Emulation.setDeviceMetricsOverride",
            json!({ "width": 1600, "height": 1200, "deviceScaleFactor": 1, "mobile": false }),
        );
        self.call("Page.enable", json!({}));
        self.events.clear();
        self.call("Page.navigate", json!({ "url": url }));
        self.wait_for("Page.loadEventFired");
    }

    /// Evaluates JavaScript in the page (awaiting a promise) and returns its value.
    pub(crate) fn eval(&mut self, expression: &str) -> Value {
        let result = self.call(
            "Runtime.evaluate",
            json!({ "expression": expression, "awaitPromise": true, "returnByValue": true }),
        );
        assert!(
            result.get("exceptionDetails").is_none(),
            "{expression}: {}",
            result["exceptionDetails"]
        );
        result["result"]["value"].clone()
    }

    fn mouse(&mut self, kind: &str, x: f64, y: f64) {
        self.call(
            "Input.dispatchMouseEvent",
            json!({ "type": kind, "x": x, "y": y, "button": "left", "clickCount": 1 }),
        );
    }

    /// A left click at (x, y) in CSS pixels of the viewport.
    fn click(&mut self, x: f64, y: f64) {
        self.mouse("mouseMoved", x, y);
        self.mouse("mousePressed", x, y);
        self.mouse("mouseReleased", x, y);
    }

    /// Scrolls the element found by `selector` into view and returns its box (x, y, width,
    /// height) in the viewport.
    fn rect(&mut self, selector: &str) -> [f64; 4] {
        let value = self.eval(&format!(
            "(() => {{ const e = document.querySelector({selector:?}); \
             e.scrollIntoView({{block: 'center', inline: 'nearest'}}); \
             const r = e.getBoundingClientRect(); return [r.left, r.top, r.width, r.height]; }})()"
        ));
        let v: Vec<f64> = value
            .as_array()
            .unwrap()
            .iter()
            .map(|n| n.as_f64().unwrap())
            .collect();
        [v[0], v[1], v[2], v[3]]
    }

    /// Clicks the middle of the element found by `selector`.
    pub(crate) fn click_on(&mut self, selector: &str) {
        let [x, y, w, h] = self.rect(selector);
        self.click(x + w / 2.0, y + h / 2.0);
    }

    /// Moves the pointer over pixel (px, py) of a canvas shown at `zoom`, and returns what the
    /// viewer's inspector then says.
    fn inspect(&mut self, viewer: &str, role: &str, zoom: f64, px: u32, py: u32) -> String {
        let canvas = format!("{viewer} .side canvas.{role}");
        let inspector = format!("{viewer} .inspector");
        let (ox, oy) = (f64::from(px) * zoom, f64::from(py) * zoom);
        // Scroll the page to the viewer's panes and the panes to the pixel, then find where the
        // canvas's content (inside its border) is.
        let value = self.eval(&format!(
            "(() => {{ const c = document.querySelector({canvas:?});              const panes = c.closest('.panes');              panes.scrollIntoView({{block: 'start', inline: 'start'}});              window.scrollBy(0, -80);              let cr = c.getBoundingClientRect(), pr = panes.getBoundingClientRect();              panes.scrollTop += cr.top + {oy} - (pr.top + 100);              panes.scrollLeft += cr.left + {ox} - (pr.left + 100);              cr = c.getBoundingClientRect();              document.querySelector({inspector:?}).textContent = '';              return [cr.left + c.clientLeft, cr.top + c.clientTop]; }})()"
        ));
        let x = value[0].as_f64().unwrap();
        let y = value[1].as_f64().unwrap();
        // The first whole CSS pixel of the zoomed pixel: mouse events carry whole-pixel client
        // coordinates.
        let (mx, my) = ((x + ox).ceil(), (y + oy).ceil());
        assert!(
            (0.0..1600.0).contains(&mx) && (0.0..1200.0).contains(&my),
            "pixel ({px}, {py}) at {zoom}x is outside the viewport at ({mx}, {my})"
        );
        self.mouse("mouseMoved", mx, my);
        self.eval(&format!(
            "document.querySelector({inspector:?}).textContent"
        ))
        .as_str()
        .unwrap()
        .to_owned()
    }
}

impl Drop for Browser {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// The numbers the inspector prints after `label:` (up to the next label).
fn values_after(text: &str, label: &str) -> Vec<f64> {
    let start = text
        .find(label)
        .unwrap_or_else(|| panic!("no {label} in {text:?}"))
        + label.len();
    text[start..]
        .split_whitespace()
        .take_while(|w| w.parse::<f64>().is_ok())
        .map(|w| w.parse().unwrap())
        .collect()
}

fn assert_values(printed: &[f64], stored: &[f32], what: &str) {
    assert_eq!(
        printed.len(),
        stored.len(),
        "{what}: {printed:?} vs {stored:?}"
    );
    for (p, s) in printed.iter().zip(stored) {
        let s = f64::from(*s);
        // The inspector prints six significant digits.
        assert!(
            (p - s).abs() <= 1e-5 * s.abs().max(1e-30),
            "{what}: printed {printed:?}, stored {stored:?}"
        );
    }
}

fn exr(path: &Path) -> engine::Image {
    harness::images::read_exr(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// A temporary workspace whose arrow scene's light is brighter (2.5 -> 3.0).
pub(crate) fn workspace_with_a_light_change() -> tempfile::TempDir {
    let root = common::temp_workspace();
    let scene = root.path().join("scenes/arrow.toml");
    let text = std::fs::read_to_string(&scene).unwrap();
    std::fs::write(&scene, text.replace("intensity = 2.5", "intensity = 3.0")).unwrap();
    root
}

/// Brightens the arrow scene's light in a temporary workspace (its light buffer and final image
/// change, nothing else) and runs `harness check` on it (on gl; with `verify`, verifying the
/// outputs it keeps), which must fail. Returns the workspace and the `--out` folder holding
/// report.html, last-check.json and the failure images.
pub(crate) fn check_after_a_light_change(verify: bool) -> (tempfile::TempDir, PathBuf) {
    let root = workspace_with_a_light_change();
    let out = root.path().join("out");
    let output = common::harness_command()
        .args([
            "check",
            "--no-speed",
            "--scene",
            "arrow",
            "--backend",
            "gl",
            "--out",
        ])
        .arg(&out)
        .args((!verify).then_some("--no-verify"))
        .env("HARNESS_ROOT", root.path())
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert_eq!(output.status.code(), Some(1), "{stdout}");
    // One backend checked: the verdict says to run the others, unless the verification just
    // did (then it says what it found).
    let (asked, answered) = (
        stdout.contains("run the other backends to tell"),
        stdout
            .contains("rendered it again on every backend and CPU code path, where it reproduces"),
    );
    assert_eq!((asked, answered), (!verify, verify), "{stdout}");
    (root, out)
}

/// The summary table lists the two failed rows before every passing one.
fn assert_failures_come_first(browser: &mut Browser) {
    let classes = browser.eval(
        "Array.from(document.querySelectorAll('table.summary tr.failed, table.summary \
         tr.passed'), r => r.className)",
    );
    let classes: Vec<&str> = classes
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c.as_str().unwrap())
        .collect();
    let failed = classes.iter().filter(|c| **c == "failed").count();
    assert_eq!(failed, 2, "{classes:?}");
    assert!(
        classes[..failed].iter().all(|c| *c == "failed"),
        "{classes:?}"
    );
    assert!(classes.len() > failed);
}

/// The failures-only filter, clicked, hides every passing row and thumbnail.
fn assert_failures_only_hides_the_passing_rows(browser: &mut Browser) {
    let visible = "Array.from(document.querySelectorAll('table.summary tr.passed, \
                   section.passing')).filter(e => e.getClientRects().length > 0).length";
    assert!(browser.eval(visible).as_u64().unwrap() > 0);
    browser.click_on("#failures-only");
    assert_eq!(
        browser.eval("document.getElementById('failures-only').checked"),
        json!(true)
    );
    assert_eq!(browser.eval(visible), json!(0));
    let failing_rows = "Array.from(document.querySelectorAll('table.summary tr.failed'))\
                        .filter(e => e.getClientRects().length > 0).length";
    assert_eq!(browser.eval(failing_rows), json!(2));
}

/// The summary row links to its case.
fn assert_the_summary_row_links_to_its_case(browser: &mut Browser) {
    let href =
        browser.eval("document.querySelector('table.summary tr.failed a').getAttribute('href')");
    let href = href.as_str().unwrap().to_owned();
    assert!(
        browser
            .eval(&format!("!!document.querySelector({href:?})"))
            .as_bool()
            .unwrap(),
        "{href}"
    );
}

/// In `viewer`: swipe mode, then the slider clicked at a quarter of its width moves there and
/// clips the actual image at that position.
fn assert_the_swipe_slider_moves(browser: &mut Browser, viewer: &str) {
    browser.click_on(&format!("{viewer} button[data-mode=swipe]"));
    assert!(browser
        .eval(&format!(
            "document.querySelector({viewer:?}).classList.contains('mode-swipe')"
        ))
        .as_bool()
        .unwrap());
    let slider = format!("{viewer} .swipe-slider");
    let [x, y, w, h] = browser.rect(&slider);
    browser.click(x + w * 0.25, y + h / 2.0);
    let position = browser
        .eval(&format!("Number(document.querySelector({slider:?}).value)"))
        .as_f64()
        .unwrap();
    assert!((15.0..=35.0).contains(&position), "slider at {position}");
    let clip = browser.eval(&format!(
        "document.querySelector({:?}).style.clipPath",
        format!("{viewer} .swipe canvas.actual")
    ));
    assert_eq!(clip, json!(format!("inset(0px 0px 0px {position}%)")));
}

/// The inspector of `viewer` at pixel (px, py) prints the fp16 values stored in the golden and
/// in the output, which differ there. Returns what it printed.
fn assert_the_inspector_prints_the_stored_values(
    browser: &mut Browser,
    viewer: &str,
    (golden_light, actual_light): (&engine::Image, &engine::Image),
    (px, py): (u32, u32),
) -> String {
    let text = browser.inspect(viewer, "actual", 1.0, px, py);
    assert!(text.starts_with(&format!("pixel ({px}, {py})")), "{text}");
    assert_values(
        &values_after(&text, "golden:"),
        &golden_light.pixel(px, py),
        "golden",
    );
    assert_values(
        &values_after(&text, "actual:"),
        &actual_light.pixel(px, py),
        "actual",
    );
    assert_ne!(golden_light.pixel(px, py), actual_light.pixel(px, py));
    text
}

/// At 4x zoom pixel (px, py) of `viewer` is four times further in, and the inspector reads
/// `text` there again.
fn assert_zoom_keeps_the_pixel(
    browser: &mut Browser,
    viewer: &str,
    (px, py): (u32, u32),
    text: &str,
) {
    browser.eval(&format!(
        "(() => {{ const z = document.querySelector({:?}); z.value = '4'; \
         z.dispatchEvent(new Event('change')); }})()",
        format!("{viewer} select.zoom")
    ));
    let zoomed = browser.inspect(viewer, "actual", 4.0, px, py);
    assert_eq!(zoomed, text);
}

/// Exposure +2 EV: the golden canvas of `viewer` shows the stored value times 4, clamped,
/// sRGB-encoded.
fn assert_exposure_scales_the_hdr_pass(
    browser: &mut Browser,
    viewer: &str,
    golden_light: &engine::Image,
    (px, py): (u32, u32),
) {
    browser.eval(&format!(
        "(() => {{ const e = document.querySelector({:?}); e.value = '2'; \
         e.dispatchEvent(new Event('input')); }})()",
        format!("{viewer} input.exposure")
    ));
    let shown = browser.eval(&format!(
        "Array.from(document.querySelector({:?}).getContext('2d')\
         .getImageData({px}, {py}, 1, 1).data)",
        format!("{viewer} .side canvas.golden")
    ));
    let srgb = |v: f32| {
        let x = f64::from(v * 4.0).clamp(0.0, 1.0);
        let e = if x <= 0.0031308 {
            12.92 * x
        } else {
            1.055 * x.powf(1.0 / 2.4) - 0.055
        };
        (e * 255.0).round()
    };
    let golden_pixel = golden_light.pixel(px, py);
    for c in 0..3 {
        assert!(
            (shown[c].as_f64().unwrap() - srgb(golden_pixel[c])).abs() <= 1.0,
            "{shown} vs {golden_pixel:?}"
        );
    }
}

/// The final image is 8-bit: the inspector prints its stored bytes. And the diff legend is
/// there, scaled to the pass's threshold.
fn assert_the_final_image_shows_its_bytes_and_legend(browser: &mut Browser, out: &Path) {
    let final_actual =
        harness::images::read_png(&out.join("failures/arrow/gl/final_actual.png")).unwrap();
    let final_viewer = "#case-arrow-final .viewer";
    let text = browser.inspect(final_viewer, "actual", 1.0, 200, 300);
    assert_values(
        &values_after(&text, "actual:"),
        &final_actual.pixel(200, 300),
        "final actual",
    );
    let legend = browser.eval(&format!(
        "document.querySelector({:?}).textContent",
        format!("{final_viewer} .legend")
    ));
    assert!(
        legend.as_str().unwrap().contains("threshold 0.006"),
        "{legend}"
    );
}

#[test]
fn the_review_page_finds_the_change_in_a_real_browser() {
    let Some(executable) = chromium() else {
        if std::env::var("REQUIRE_CHROMIUM").as_deref() == Ok("1") {
            panic!("REQUIRE_CHROMIUM=1 but no Chromium found (apt-get install -y chromium)");
        }
        eprintln!("note: no Chromium; review page test skipped (apt-get install -y chromium)");
        return;
    };
    if !common::gl_available() {
        return;
    }
    let (root, out) = check_after_a_light_change(false);
    let report: PathBuf = out.join("report.html");

    let mut browser = Browser::launch(executable);
    browser.open(&format!("file://{}", report.display()));
    let ready = browser.eval("window.reviewReady.then(() => true)");
    assert_eq!(ready, json!(true));

    assert_failures_come_first(&mut browser);
    assert_failures_only_hides_the_passing_rows(&mut browser);
    assert_the_summary_row_links_to_its_case(&mut browser);

    // The light buffer's viewer.
    let viewer = "#case-arrow-light .viewer";
    assert_the_swipe_slider_moves(&mut browser, viewer);

    // Back to side by side; the inspector at the pixel that changed most.
    browser.click_on(&format!("{viewer} button[data-mode=side]"));
    let golden_light = exr(&root.path().join("golden/arrow/light.exr"));
    let actual_light = exr(&out.join("failures/arrow/gl/light_actual.exr"));
    let pixel = (356, 372);
    let text = assert_the_inspector_prints_the_stored_values(
        &mut browser,
        viewer,
        (&golden_light, &actual_light),
        pixel,
    );
    assert_zoom_keeps_the_pixel(&mut browser, viewer, pixel, &text);
    assert_exposure_scales_the_hdr_pass(&mut browser, viewer, &golden_light, pixel);

    assert_the_final_image_shows_its_bytes_and_legend(&mut browser, &out);
}
