//! The HTML review page of a check run: one self-contained file built for finding what changed.
//!
//! - A summary table, failing checks first, each row linking to its case, with a failures-only
//!   filter and, per failing scene, the bless command ready to copy.
//! - Per failing pass: the golden and each backend's output at full resolution, embedded as
//!   zlib-compressed exact pixel data (8-bit, fp16 or fp32) that `review.js` draws side by side,
//!   as a swipe or a flicker, zoomable, with an exposure control for float passes, a
//!   false-colour difference in units of the pass's tolerance threshold, and a pixel inspector.
//! - Passing passes as small PNG thumbnails of the golden, so that the canonical run's page stays
//!   small (a few MB).
//! - Driver fingerprints, the cross-backend table, GPU time per pass, and the latest benchmark,
//!   sweep and hard-case results.

use std::fmt::Write as _;

use base64::Engine as _;
use engine::{Image, ImageData};

use std::path::Path;

use crate::golden::check::{CheckRun, Outputs};
use crate::golden::{GoldenStore, Outcome};
use crate::images;

/// Largest thumbnail edge in pixels.
const PREVIEW: u32 = 160;

/// Pixel data embedded at full resolution before the remaining failures fall back to
/// thumbnails (base64 bytes).
const EMBED_BUDGET: usize = 64 << 20;

/// The page's style sheet.
const STYLE: &str = include_str!("review.css");

/// The viewers, filter and copy buttons.
const SCRIPT: &str = include_str!("review.js");

use crate::html::escape;

/// An 8-bit thumbnail of a pass output: HDR values Reinhard-mapped, depth stretched over its
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

/// A part of the review page contributed by something other than the golden check (the
/// benchmarks, the sweeps, the hard cases): HTML made from the results it kept in the page's
/// folder, empty when it kept none. The report knows nothing else of what made them.
pub trait Section {
    /// The section's HTML from the results kept in `dir`.
    fn html(&self, dir: &Path) -> String;
}

/// How the viewer maps a pass's values to the screen.
fn display_mode(image: &Image, pass: &str) -> &'static str {
    match (&image.data, pass) {
        (ImageData::U8(_), _) => "srgb8",
        (ImageData::F32(_), "depth") => "depth",
        (ImageData::F32(_), "light") => "hdr",
        (ImageData::F32(_), p)
            if p.starts_with("gbuffer_normal") || p.starts_with("gbuffer_tangent") =>
        {
            "signed"
        }
        (ImageData::F32(_), _) => "linear",
    }
}

/// The exact pixel data of an image for the viewer: its storage kind (`u8`; `f16` for fp16
/// targets, whose values fp16 holds exactly; `f32` otherwise) and the bytes, little-endian.
/// `like` decides the kind, so that a golden read from an fp16 EXR is embedded like the fp16
/// output it is compared with.
fn pixel_bytes(image: &Image, like: &Image) -> (&'static str, Vec<u8>) {
    match &image.data {
        ImageData::U8(data) => ("u8", data.clone()),
        ImageData::F32(data) if like.format == engine::backend::TextureFormat::Rgba16Float => (
            "f16",
            data.iter()
                .flat_map(|&v| half::f16::from_f32(v).to_le_bytes())
                .collect(),
        ),
        ImageData::F32(data) => ("f32", data.iter().flat_map(|v| v.to_le_bytes()).collect()),
    }
}

/// Pixel data embedded once each at the end of the page, zlib-compressed and base64-encoded in
/// `<script type="application/octet-stream" id="blob-N">` elements; identical data (backends
/// that render the same pixels) is embedded once, and compressed once.
#[derive(Default)]
struct Blobs {
    /// Encoded blobs, in page order.
    encoded: Vec<String>,
    /// Hash and length of each blob's raw bytes, to find repeats before compressing.
    raw: Vec<(u64, usize)>,
}

impl Blobs {
    fn add(&mut self, bytes: &[u8]) -> usize {
        use std::hash::{Hash as _, Hasher as _};
        let mut hasher = std::collections::hash_map::DefaultHasher::new();
        bytes.hash(&mut hasher);
        let id = (hasher.finish(), bytes.len());
        if let Some(same) = self.raw.iter().position(|r| *r == id) {
            return same;
        }
        use std::io::Write as _;
        let mut encoder =
            flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::default());
        // Writing to a Vec cannot fail.
        let _ = encoder.write_all(bytes);
        let compressed = encoder.finish().unwrap_or_default();
        self.encoded
            .push(base64::engine::general_purpose::STANDARD.encode(compressed));
        self.raw.push(id);
        self.encoded.len() - 1
    }

    /// Base64 bytes embedded so far.
    fn bytes(&self) -> usize {
        self.encoded.iter().map(String::len).sum()
    }

    fn html(&self) -> String {
        let mut out = String::new();
        for (i, blob) in self.encoded.iter().enumerate() {
            let _ = writeln!(
                out,
                "<script type=\"application/octet-stream\" id=\"blob-{i}\">{blob}</script>"
            );
        }
        out
    }
}

/// The anchor of a scene's pass on the page.
fn case_id(scene: &str, pass: &str) -> String {
    let clean = |s: &str| {
        s.chars()
            .map(|c| if c.is_ascii_alphanumeric() { c } else { '-' })
            .collect::<String>()
    };
    format!("case-{}-{}", clean(scene), clean(pass))
}

/// A link to a file the run wrote: relative to the page when it lies under `page_dir`.
fn file_link(path: &Path, page_dir: Option<&Path>) -> String {
    match page_dir.and_then(|dir| path.strip_prefix(dir).ok()) {
        Some(relative) => relative.display().to_string(),
        None => format!("file://{}", path.display()),
    }
}

/// The checks of a result as text, worst first, with the largest difference.
fn metrics_text(outcome: &Outcome) -> String {
    match outcome {
        Outcome::Passed(v) | Outcome::Failed(v) => {
            let mut checks: Vec<_> = v.checks.iter().collect();
            checks.sort_by(|a, b| b.ratio().total_cmp(&a.ratio()));
            let mut lines: Vec<String> = checks.iter().map(ToString::to_string).collect();
            if v.non_finite > 0 {
                lines.insert(0, format!("{} NaN/Inf values in the output", v.non_finite));
            }
            if let Some(largest) = &v.largest_difference {
                lines.push(largest.to_string());
            }
            lines.join("\n")
        }
        Outcome::MissingGolden => "no golden".to_owned(),
        Outcome::Incomparable(why) => why.clone(),
    }
}

fn result_label(outcome: &Outcome) -> &'static str {
    match outcome {
        Outcome::Passed(_) => "ok",
        Outcome::Failed(_) => "FAILED",
        Outcome::MissingGolden => "no golden",
        Outcome::Incomparable(_) => "incomparable",
    }
}

fn bless_html(command: &str) -> String {
    format!(
        "<code>{}</code> <button type=\"button\" class=\"copy\" data-copy=\"{}\">copy</button>",
        escape(command),
        escape(command)
    )
}

/// Writes the report as one HTML string.
///
/// `page_dir` is where the page will be written (failure images under it are linked
/// relatively); with it, each of `sections` adds what it kept there (the latest bench results,
/// sweeps and hard cases: [`crate::measure::report_sections`]).
pub fn html(
    run: &CheckRun,
    outputs: &Outputs,
    store: &GoldenStore,
    page_dir: Option<&Path>,
    sections: &[&dyn Section],
) -> String {
    let failed = run.results.iter().filter(|r| !r.outcome.passed()).count();
    let mut out = String::new();
    let _ = write!(
        out,
        "<!doctype html><html><head><meta charset=\"utf-8\"><title>Render check: {}</title>\
         <style>{STYLE}</style></head><body>",
        if run.passed() { "passed" } else { "FAILED" }
    );
    let _ = write!(
        out,
        "<h1>Render check: {}</h1><p>{} checks, {} failed, {} render errors, {} scenes that did \
         not load.</p><div class=\"controls\"><label><input type=\"checkbox\" \
         id=\"failures-only\"> show failures only</label> · <a href=\"#summary\">summary</a> · \
         <a href=\"#failing\">failing passes</a> · <a href=\"#passing\">passing passes</a> · \
         <a href=\"#backends\">backends</a></div>",
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
    for (scene, backend, error) in &run.render_errors {
        let _ = write!(
            out,
            "<p class=\"failed\">render of {} on {} failed: {}</p>",
            escape(scene),
            escape(backend),
            escape(error)
        );
    }
    let commands = run.bless_commands();
    if !commands.is_empty() {
        out.push_str(
            "<p>After reviewing, bless what changed on purpose (each command rewrites only its \
             scene's passes outside tolerance or without a golden):</p><ul>",
        );
        for command in &commands {
            let _ = write!(out, "<li>{}</li>", bless_html(command));
        }
        out.push_str("</ul>");
    }
    summary(&mut out, run);
    let mut blobs = Blobs::default();
    cases(&mut out, run, outputs, store, page_dir, &mut blobs);
    details(&mut out, run);
    if let Some(dir) = page_dir {
        for section in sections {
            out.push_str(&section.html(dir));
        }
    }
    out.push_str(&blobs.html());
    let _ = writeln!(out, "<script>{SCRIPT}</script></body></html>");
    out
}

/// The summary table: failing checks first, each row linking to its case.
fn summary(out: &mut String, run: &CheckRun) {
    out.push_str(
        "<h2 id=\"summary\">Summary</h2><table class=\"summary\"><tr><th>scene</th><th>pass</th>\
         <th>backend</th><th>result</th><th>checks (worst first) and largest difference</th>\
         </tr>",
    );
    let mut rows: Vec<_> = run.results.iter().collect();
    rows.sort_by_key(|r| r.outcome.passed());
    for r in rows {
        let class = if r.outcome.passed() {
            "passed"
        } else {
            "failed"
        };
        let _ = write!(
            out,
            "<tr class=\"{class}\"><td>{}</td><td><a href=\"#{}\">{}</a></td><td>{}</td>\
             <td>{}</td><td><code>{}</code></td></tr>",
            escape(&r.scene),
            case_id(&r.scene, &r.pass),
            escape(&r.pass),
            escape(&r.backend),
            result_label(&r.outcome),
            escape(&metrics_text(&r.outcome)).replace('\n', "<br>")
        );
    }
    out.push_str("</table>");
}

/// The failing passes with their viewers, then the passing ones as thumbnails.
fn cases(
    out: &mut String,
    run: &CheckRun,
    outputs: &Outputs,
    store: &GoldenStore,
    page_dir: Option<&Path>,
    blobs: &mut Blobs,
) {
    let mut keys: Vec<(&str, &str)> = Vec::new();
    for r in &run.results {
        if !keys.contains(&(r.scene.as_str(), r.pass.as_str())) {
            keys.push((r.scene.as_str(), r.pass.as_str()));
        }
    }
    let failing =
        |scene: &str, pass: &str| results_of(run, scene, pass).any(|r| !r.outcome.passed());
    let load_golden = |scene: &str, pass: &str| {
        let eight_bit = results_of(run, scene, pass)
            .next()
            .map(|r| r.golden_path.extension().is_some_and(|e| e == "png"))
            .unwrap_or(true);
        store.load(scene, pass, eight_bit).ok().flatten()
    };

    out.push_str("<h2 id=\"failing\">Failing passes</h2>");
    let mut any = false;
    for &(scene, pass) in keys.iter().filter(|(s, p)| failing(s, p)) {
        any = true;
        let golden_image = load_golden(scene, pass);
        // Embedded once, when the first viewer needs it.
        let mut golden_blob = None;
        let _ = write!(
            out,
            "<section class=\"case failing\" id=\"{}\"><h3>{} / {}</h3>",
            case_id(scene, pass),
            escape(scene),
            escape(pass)
        );
        if let Some(first) = results_of(run, scene, pass).next() {
            let _ = write!(
                out,
                "<p>If the change is intended: {}</p>",
                bless_html(&crate::golden::suite::bless_command(&first.scene_argument))
            );
        }
        for r in results_of(run, scene, pass) {
            let _ = write!(
                out,
                "<div class=\"backend-result {}\"><b>{}</b>: {} <code>{}</code>",
                if r.outcome.passed() {
                    "passed"
                } else {
                    "failed"
                },
                escape(&r.backend),
                result_label(&r.outcome),
                escape(&metrics_text(&r.outcome))
            );
            let files: Vec<String> = [
                ("actual", &r.artifacts.actual),
                ("golden", &r.artifacts.golden),
                ("diff", &r.artifacts.diff),
            ]
            .into_iter()
            .filter_map(|(label, path)| {
                path.as_ref().map(|p| {
                    format!(
                        "<a href=\"{}\">{label}</a>",
                        escape(&file_link(p, page_dir))
                    )
                })
            })
            .collect();
            if !files.is_empty() {
                let _ = write!(out, " files: {}", files.join(" "));
            }
            out.push_str("</div>");
            if r.outcome.passed() {
                continue;
            }
            let key = (r.scene.clone(), r.pass.clone(), r.backend.clone());
            let (Some(actual), Some(golden_image)) = (outputs.get(&key), golden_image.as_ref())
            else {
                if let Some(actual) = outputs.get(&key) {
                    out.push_str(&thumbnail("actual (no golden to compare)", actual, pass));
                }
                continue;
            };
            let comparable = (actual.width, actual.height, actual.channels())
                == (
                    golden_image.width,
                    golden_image.height,
                    golden_image.channels(),
                )
                && actual.as_u8().is_some() == golden_image.as_u8().is_some();
            if !comparable {
                out.push_str(&thumbnail("actual", actual, pass));
                out.push_str(&thumbnail("golden", golden_image, pass));
                continue;
            }
            if blobs.bytes() > EMBED_BUDGET {
                // A change that fails everything would make a page too large to open: the
                // remaining failures get thumbnails, and their files are linked above.
                let _ = write!(
                    out,
                    "<p class=\"note\">Not embedded at full resolution: the page already holds \
                     {} MB of pixel data (see the files linked above).</p>",
                    EMBED_BUDGET >> 20
                );
                out.push_str(&thumbnail("actual", actual, pass));
                out.push_str(&thumbnail("golden", golden_image, pass));
                continue;
            }
            let (kind, bytes) = pixel_bytes(actual, actual);
            let actual_blob = blobs.add(&bytes);
            let golden_blob =
                *golden_blob.get_or_insert_with(|| blobs.add(&pixel_bytes(golden_image, actual).1));
            let criterion = r
                .criterion
                .unwrap_or(crate::golden::tolerance::PixelCriterion {
                    threshold: if kind == "u8" { 1.0 / 255.0 } else { 1e-3 },
                    floor: None,
                    channels: crate::golden::metrics::Channels::All,
                });
            let _ = write!(
                out,
                "<div class=\"viewer\" data-label=\"{}\" data-width=\"{}\" data-height=\"{}\" \
                 data-channels=\"{}\" data-kind=\"{kind}\" data-display=\"{}\" \
                 data-golden=\"{golden_blob}\" data-actual=\"{actual_blob}\" \
                 data-threshold=\"{}\" data-floor=\"{}\" data-rgb=\"{}\"><noscript>The viewer \
                 needs JavaScript.</noscript></div>",
                escape(&r.backend),
                actual.width,
                actual.height,
                actual.channels(),
                display_mode(actual, pass),
                criterion.threshold,
                criterion.floor.map(|f| f.to_string()).unwrap_or_default(),
                u8::from(criterion.channels == crate::golden::metrics::Channels::Rgb),
            );
        }
        out.push_str("</section>");
    }
    if !any {
        out.push_str("<p>None.</p>");
    }

    out.push_str("<h2 id=\"passing\">Passing passes</h2><div class=\"thumbs\">");
    for &(scene, pass) in keys.iter().filter(|(s, p)| !failing(s, p)) {
        let backends: Vec<&str> = results_of(run, scene, pass)
            .map(|r| r.backend.as_str())
            .collect();
        let _ = write!(
            out,
            "<section class=\"passing\" id=\"{}\">",
            case_id(scene, pass)
        );
        let label = format!("{scene} / {pass}: ok on {}", backends.join(", "));
        match load_golden(scene, pass) {
            Some(golden_image) => out.push_str(&thumbnail(&label, &golden_image, pass)),
            None => {
                let _ = write!(out, "<figure>{}</figure>", escape(&label));
            }
        }
        out.push_str("</section>");
    }
    out.push_str("</div>");
}

/// The results of one scene's pass, one per backend.
fn results_of<'a>(
    run: &'a CheckRun,
    scene: &'a str,
    pass: &'a str,
) -> impl Iterator<Item = &'a crate::golden::suite::PassCheck> + 'a {
    run.results
        .iter()
        .filter(move |r| r.scene == scene && r.pass == pass)
}

/// A small PNG thumbnail with a caption.
fn thumbnail(label: &str, image: &Image, pass: &str) -> String {
    format!(
        "<figure><img src=\"{}\" alt=\"{}\"><figcaption>{}</figcaption></figure>",
        data_uri(&preview(image, pass)),
        escape(label),
        escape(label)
    )
}

/// Backends, cross-backend agreement and GPU times.
fn details(out: &mut String, run: &CheckRun) {
    out.push_str(
        "<h2 id=\"backends\">Backends</h2><table><tr><th>backend</th><th>driver fingerprint</th>\
         </tr>",
    );
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
    out.push_str(
        "<h2>Cross-backend agreement (largest disagreement per pass)</h2><table><tr>\
         <th>scene</th><th>pass</th><th>backends</th><th>max abs</th><th>fraction over</th>\
         <th>within tolerance</th></tr>",
    );
    for c in &run.cross {
        let _ = write!(
            out,
            "<tr class=\"{}\"><td>{}</td><td>{}</td><td>{} vs {}</td><td>{:.3e}</td><td>{:.3e}</td><td>{}</td></tr>",
            if c.within_tolerance { "passed" } else { "failed" },
            escape(&c.scene),
            escape(&c.pass),
            c.a,
            c.b,
            c.max_abs,
            c.fraction_over,
            if c.within_tolerance { "yes" } else { "NO" }
        );
    }
    out.push_str("</table>");
    out.push_str(
        "<h2>GPU time per pass (ms)</h2><table><tr><th>scene</th><th>backend</th><th>pass</th>\
         <th>ms</th></tr>",
    );
    for t in &run.timings {
        let _ = write!(
            out,
            "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
            escape(&t.scene),
            t.backend,
            escape(&t.pass),
            t.ms.map_or("-".to_owned(), |ms| format!("{ms:.3}"))
        );
    }
    out.push_str("</table>");
}
