//! The HTML report of a check run: one self-contained file (images embedded as PNG data URIs,
//! downscaled to at most 256 pixels) with, per scene and pass, the golden and each backend's
//! output and diff heatmap with the metrics; the cross-backend table; driver fingerprints; and
//! GPU timings per pass.

use std::fmt::Write as _;

use base64::Engine as _;
use engine::{Image, ImageData};

use crate::check::CheckRun;
use crate::golden::{self, GoldenStore, Outcome};
use crate::images;

/// Largest preview edge in pixels.
const PREVIEW: u32 = 256;

fn escape(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// An 8-bit preview of a pass output: HDR values Reinhard-mapped, depth stretched over its
/// range, 8-bit images as they are; box-downscaled to at most [`PREVIEW`] pixels.
pub fn preview(image: &Image, pass: &str) -> Image {
    let display = match (&image.data, pass) {
        (ImageData::F32(data), "depth") => {
            let finite = data.iter().copied().filter(|v| v.is_finite() && *v < 1.0);
            let (lo, hi) = finite.fold((f32::MAX, f32::MIN), |(lo, hi), v| (lo.min(v), hi.max(v)));
            let span = (hi - lo).max(1e-9);
            let mapped = data
                .iter()
                .map(|&v| if v >= 1.0 { 1.0 } else { (v - lo) / span })
                .collect();
            images::display_u8(&Image {
                data: ImageData::F32(mapped),
                ..image.clone()
            })
        }
        (ImageData::F32(data), "light") => images::display_u8(&Image {
            data: ImageData::F32(data.iter().map(|&v| v / (1.0 + v.abs())).collect()),
            ..image.clone()
        }),
        (ImageData::F32(data), p) if p.starts_with("gbuffer_normal") => {
            images::display_u8(&Image {
                data: ImageData::F32(data.iter().map(|&v| v * 0.5 + 0.5).collect()),
                ..image.clone()
            })
        }
        _ => images::display_u8(image),
    };
    downscale(&display)
}

fn downscale(image: &Image) -> Image {
    let factor = image.width.max(image.height).div_ceil(PREVIEW).max(1);
    if factor == 1 {
        return image.clone();
    }
    let Some(data) = image.as_u8() else {
        return image.clone();
    };
    let (w, h) = (image.width / factor, image.height / factor);
    let mut out = Vec::with_capacity((w * h * 4) as usize);
    for y in 0..h {
        for x in 0..w {
            for c in 0..4 {
                let mut sum = 0u32;
                for dy in 0..factor {
                    for dx in 0..factor {
                        let i =
                            (((y * factor + dy) * image.width + x * factor + dx) * 4 + c) as usize;
                        sum += u32::from(data[i]);
                    }
                }
                out.push((sum / (factor * factor)) as u8);
            }
        }
    }
    Image {
        width: w,
        height: h,
        format: image.format,
        data: ImageData::U8(out),
    }
}

fn data_uri(image: &Image) -> String {
    let png = images::encode_png(
        image,
        std::path::Path::new("preview.png"),
        images::PngCompression::Fast,
    )
    .unwrap_or_default();
    format!(
        "data:image/png;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(png)
    )
}

fn figure(label: &str, image: Option<&Image>, pass: &str) -> String {
    match image {
        Some(image) => format!(
            "<figure><img src=\"{}\" alt=\"{}\"><figcaption>{}</figcaption></figure>",
            data_uri(&preview(image, pass)),
            escape(label),
            escape(label)
        ),
        None => format!(
            "<figure class=\"missing\"><div>none</div><figcaption>{}</figcaption></figure>",
            escape(label)
        ),
    }
}

/// Outputs of the run, by (scene, pass, backend), to show in the report.
pub type Outputs = std::collections::BTreeMap<(String, String, String), Image>;

/// Writes the report as one HTML string.
///
/// With `bench_dir`, the latest `harness bench` results found there are added (pass times
/// against floors, scaling-series plots).
pub fn html(
    run: &CheckRun,
    outputs: &Outputs,
    store: &GoldenStore,
    bench_dir: Option<&std::path::Path>,
) -> String {
    let failed = run.results.iter().filter(|r| !r.outcome.passed()).count();
    let mut out = String::new();
    let _ = write!(
        out,
        "<!doctype html><html><head><meta charset=\"utf-8\"><title>Render check: {}</title><style>
body{{font-family:system-ui,sans-serif;margin:1.5em;background:#fafafa;color:#222}}
h1 .fail{{color:#b00}} h1 .pass{{color:#070}}
table{{border-collapse:collapse;margin:0.5em 0 1.5em}} td,th{{border:1px solid #ccc;padding:2px 8px;font-size:13px;text-align:left}}
.passed{{background:#e8f6e8}} .failed{{background:#fbe3e3}} .note{{background:#eef3fb}}
.pass-block{{border:1px solid #ddd;background:#fff;margin:1em 0;padding:0.5em 1em}}
figure{{display:inline-block;margin:4px;text-align:center;vertical-align:top}} figure img{{image-rendering:pixelated;border:1px solid #999;max-width:256px}}
figure.missing div{{width:128px;height:128px;border:1px dashed #999;line-height:128px;color:#999}}
figcaption{{font-size:12px}} code{{font-size:12px}}
</style></head><body>",
        if run.passed() { "passed" } else { "FAILED" }
    );
    let _ = write!(
        out,
        "<h1>Render check: {}</h1><p>{} checks, {} failed, {} render errors, {} scenes that did \
         not load.</p>",
        if run.passed() {
            "<span class=\"pass\">passed</span>"
        } else {
            "<span class=\"fail\">FAILED</span>"
        },
        run.results.len(),
        failed,
        run.render_errors.len(),
        run.load_errors.len()
    );
    for broken in &run.load_errors {
        let _ = write!(
            out,
            "<p class=\"failed\">scene {} did not load: {}</p>",
            escape(&broken.scene),
            escape(&broken.error)
        );
    }
    out.push_str("<h2>Backends</h2><table><tr><th>backend</th><th>driver fingerprint</th></tr>");
    for b in &run.backends {
        let _ = write!(
            out,
            "<tr><td>{}</td><td>{}</td></tr>",
            b.backend,
            escape(
                b.fingerprint
                    .as_deref()
                    .or(b.unavailable.as_deref())
                    .unwrap_or("")
            )
        );
    }
    out.push_str("</table>");
    for note in &run.driver_notes {
        let _ = write!(out, "<p class=\"note\">Note: {}</p>", escape(note));
    }
    for (scene, backend, error) in &run.render_errors {
        let _ = write!(
            out,
            "<p class=\"failed\">render of {} on {} failed: {}</p>",
            escape(scene),
            escape(backend),
            escape(error)
        );
    }

    out.push_str("<h2>Summary</h2><table><tr><th>scene</th><th>pass</th><th>backend</th><th>result</th><th>metrics</th></tr>");
    for r in &run.results {
        let (class, label, metrics) = match &r.outcome {
            Outcome::Passed(v) => (
                "passed",
                "ok",
                v.checks
                    .iter()
                    .map(ToString::to_string)
                    .collect::<Vec<_>>()
                    .join("<br>"),
            ),
            Outcome::Failed(v) => (
                "failed",
                "FAILED",
                v.checks
                    .iter()
                    .map(ToString::to_string)
                    .collect::<Vec<_>>()
                    .join("<br>"),
            ),
            Outcome::MissingGolden => ("failed", "no golden", String::new()),
            Outcome::Incomparable(why) => ("failed", "incomparable", escape(why)),
        };
        let _ = write!(
            out,
            "<tr class=\"{class}\"><td>{}</td><td>{}</td><td>{}</td><td>{label}</td><td><code>{metrics}</code></td></tr>",
            r.scene, r.pass, r.backend
        );
    }
    out.push_str("</table>");

    out.push_str("<h2>Cross-backend agreement (largest disagreement per pass)</h2><table><tr><th>scene</th><th>pass</th><th>backends</th><th>max abs</th><th>fraction over</th><th>within tolerance</th></tr>");
    for c in &run.cross {
        let _ = write!(
            out,
            "<tr class=\"{}\"><td>{}</td><td>{}</td><td>{} vs {}</td><td>{:.3e}</td><td>{:.3e}</td><td>{}</td></tr>",
            if c.within_tolerance { "passed" } else { "failed" },
            c.scene,
            c.pass,
            c.a,
            c.b,
            c.max_abs,
            c.fraction_over,
            if c.within_tolerance { "yes" } else { "NO" }
        );
    }
    out.push_str("</table>");

    out.push_str("<h2>Passes</h2>");
    let mut keys: Vec<(&str, &str)> = run
        .results
        .iter()
        .map(|r| (r.scene.as_str(), r.pass.as_str()))
        .collect();
    keys.dedup();
    for (scene, pass) in keys {
        let _ = write!(out, "<div class=\"pass-block\"><h3>{scene} / {pass}</h3>");
        let eight_bit = run
            .results
            .iter()
            .find(|r| r.scene == scene && r.pass == pass)
            .map(|r| r.golden_path.extension().is_some_and(|e| e == "png"))
            .unwrap_or(true);
        let golden_image = store.load(scene, pass, eight_bit).ok().flatten();
        out.push_str(&figure("golden", golden_image.as_ref(), pass));
        for r in run
            .results
            .iter()
            .filter(|r| r.scene == scene && r.pass == pass)
        {
            let actual = outputs.get(&(r.scene.clone(), r.pass.clone(), r.backend.clone()));
            out.push_str(&figure(
                &format!(
                    "{} ({})",
                    r.backend,
                    if r.outcome.passed() { "ok" } else { "FAILED" }
                ),
                actual,
                pass,
            ));
            if let (Some(actual), Some(golden_image)) = (actual, golden_image.as_ref()) {
                let scale = if golden::is_eight_bit(actual) {
                    16.0 / 255.0
                } else {
                    0.05
                };
                let diff = golden::diff_heatmap(actual, golden_image, scale);
                out.push_str(&figure(
                    &format!("diff {}", r.backend),
                    diff.as_ref(),
                    "diff",
                ));
            }
        }
        out.push_str("</div>");
    }

    out.push_str("<h2>GPU time per pass (ms)</h2><table><tr><th>scene</th><th>backend</th><th>pass</th><th>ms</th></tr>");
    for t in &run.timings {
        let _ = write!(
            out,
            "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
            t.scene,
            t.backend,
            t.pass,
            t.ms.map_or("-".to_owned(), |ms| format!("{ms:.3}"))
        );
    }
    out.push_str("</table>");
    if let Some(dir) = bench_dir {
        out.push_str(&crate::bench::report_sections(dir));
        out.push_str(&crate::sweep::report_sections(dir));
        out.push_str(&crate::hard_cases::report_section(dir));
    }
    out.push_str("</body></html>\n");
    out
}
