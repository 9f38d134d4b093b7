//! The HTML report opens in a browser and shows its images: `harness check` writes it, headless
//! Chromium takes a screenshot, and the screenshot must contain rendered images (many distinct
//! colors, which a page of text and tables alone does not have).
//!
//! Needs Chromium (`apt-get install -y chromium`; CI installs it). Without it the test says so
//! on stderr and passes, unless REQUIRE_CHROMIUM=1.

mod common;

use std::path::Path;
use std::process::Command;

fn chromium() -> Option<&'static str> {
    [
        "/usr/bin/chromium",
        "/usr/bin/chromium-browser",
        "/usr/bin/google-chrome",
    ]
    .into_iter()
    .find(|p| Path::new(p).exists())
}

#[test]
fn report_screenshot_shows_the_images() {
    let Some(browser) = chromium() else {
        if std::env::var("REQUIRE_CHROMIUM").as_deref() == Ok("1") {
            panic!("REQUIRE_CHROMIUM=1 but no Chromium found (apt-get install -y chromium)");
        }
        eprintln!(
            "note: no Chromium; report screenshot test skipped (apt-get install -y chromium)"
        );
        return;
    };
    if !common::gl_available() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let output = common::harness_command()
        .args([
            "check",
            "--scene",
            "arrow",
            "--out",
            dir.path().to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stdout)
    );
    let report = dir.path().join("report.html");
    let screenshot = dir.path().join("report.png");
    let profile = dir.path().join("profile");
    let status = Command::new(browser)
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
            "--window-size=1280,5000",
        ])
        .arg(format!("--user-data-dir={}", profile.display()))
        .arg(format!("--screenshot={}", screenshot.display()))
        .arg(format!("file://{}", report.display()))
        .output()
        .unwrap();
    assert!(
        screenshot.is_file(),
        "no screenshot: {}",
        String::from_utf8_lossy(&status.stderr)
    );
    let image = image::open(&screenshot).unwrap().to_rgb8();
    // Tall enough to reach past the tables and the dark G-buffer targets (positions, tangents) into
    // the lit passes.
    assert_eq!(image.dimensions(), (1280, 5000));
    let colors: std::collections::HashSet<[u8; 3]> = image.pixels().map(|p| p.0).collect();
    // Text and tables give a few hundred colors; the embedded renders give thousands.
    assert!(
        colors.len() > 3000,
        "only {} distinct colors in the screenshot",
        colors.len()
    );
    let keep = std::env::var_os("KEEP_REPORT_SCREENSHOT");
    if let Some(path) = keep {
        std::fs::copy(&screenshot, path).unwrap();
    }
}
