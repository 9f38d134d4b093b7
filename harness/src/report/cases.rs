//! The page's cases: each failing pass with its backends' results and a viewer per failing
//! backend (the golden and the output at full resolution, while the page's budget lasts), then
//! each passing pass as a thumbnail of its golden.

use std::fmt::Write as _;
use std::path::Path;

use engine::plan::TargetId;
use engine::Image;

use super::pixels::{display_mode, pixel_bytes, Blobs};
use super::thumbnails::thumbnail;
use super::{bless_html, case_id, metrics_text, result_label};
use crate::golden::check::{CheckRun, Outputs};
use crate::golden::suite::PassCheck;
use crate::golden::GoldenStore;
use crate::html::escape;

/// Pixel data embedded at full resolution before the remaining failures fall back to
/// thumbnails (base64 bytes).
const EMBED_BUDGET: usize = 64 << 20;

/// What the cases are written from.
struct Page<'a> {
    run: &'a CheckRun,
    outputs: &'a Outputs,
    store: &'a GoldenStore,
    page_dir: Option<&'a Path>,
}

/// The failing passes with their viewers, then the passing ones as thumbnails.
pub(super) fn cases(
    out: &mut String,
    run: &CheckRun,
    outputs: &Outputs,
    store: &GoldenStore,
    page_dir: Option<&Path>,
    blobs: &mut Blobs,
) {
    let page = Page {
        run,
        outputs,
        store,
        page_dir,
    };
    let keys = case_keys(run);
    let failing =
        |scene: &str, pass: TargetId| results_of(run, scene, pass).any(|r| !r.outcome.passed());

    out.push_str("<h2 id=\"failing\">Failing passes</h2>");
    let mut any = false;
    for &(scene, pass) in keys.iter().filter(|(s, p)| failing(s, *p)) {
        any = true;
        page.failing_case(out, blobs, scene, pass);
    }
    if !any {
        if run.speed.checks.iter().any(|c| c.failed()) {
            out.push_str(
                "<p>No image failed; <a href=\"#speed\">speed checks</a> did (listed at the \
                 top and in the speed table).</p>",
            );
        } else {
            out.push_str("<p>None.</p>");
        }
    }

    out.push_str("<h2 id=\"passing\">Passing passes</h2><div class=\"thumbs\">");
    for &(scene, pass) in keys.iter().filter(|(s, p)| !failing(s, *p)) {
        page.passing_case(out, scene, pass);
    }
    out.push_str("</div>");
}

/// Every scene's pass of the run, once each, in the order of the results.
fn case_keys(run: &CheckRun) -> Vec<(&str, TargetId)> {
    let mut keys: Vec<(&str, TargetId)> = Vec::new();
    for r in &run.results {
        if !keys.contains(&(r.scene.as_str(), r.pass)) {
            keys.push((r.scene.as_str(), r.pass));
        }
    }
    keys
}

/// The results of one scene's pass, one per backend.
fn results_of<'a>(
    run: &'a CheckRun,
    scene: &'a str,
    pass: TargetId,
) -> impl Iterator<Item = &'a PassCheck> + 'a {
    run.results
        .iter()
        .filter(move |r| r.scene == scene && r.pass == pass)
}

impl Page<'_> {
    /// The golden of a scene's pass, in the storage its results name.
    fn golden(&self, scene: &str, pass: TargetId) -> Option<Image> {
        let eight_bit = results_of(self.run, scene, pass)
            .next()
            .map(|r| r.golden_path.extension().is_some_and(|e| e == "png"))
            .unwrap_or(true);
        self.store.load(scene, pass, eight_bit).ok().flatten()
    }

    /// A failing pass: its bless command, each backend's result, and a comparison for each
    /// backend that failed.
    fn failing_case(&self, out: &mut String, blobs: &mut Blobs, scene: &str, pass: TargetId) {
        let golden_image = self.golden(scene, pass);
        // Embedded once, when the first viewer needs it.
        let mut golden_blob = None;
        let _ = write!(
            out,
            "<section class=\"case failing\" id=\"{}\"><h3>{} / {}</h3>",
            case_id(scene, pass),
            escape(scene),
            escape(&pass.to_string())
        );
        if let Some(first) = results_of(self.run, scene, pass).next() {
            let _ = write!(
                out,
                "<p>If the change is intended: {}</p>",
                bless_html(&crate::golden::command_line::bless_command(
                    &first.scene_argument
                ))
            );
        }
        if golden_image.is_some() {
            self.golden_record(out, scene, pass);
        }
        for r in results_of(self.run, scene, pass) {
            self.result_line(out, r);
            if r.outcome.passed() {
                continue;
            }
            self.comparison(out, blobs, r, golden_image.as_ref(), &mut golden_blob);
        }
        out.push_str("</section>");
    }

    /// What blessed.toml says of the pass's golden: when, from which backend and driver, whether
    /// it was verified, and why it changed when the person blessing said (`bless --reason`).
    fn golden_record(&self, out: &mut String, scene: &str, pass: TargetId) {
        let Ok(records) = self.store.records(scene) else {
            return;
        };
        let Some(record) = records.get(&pass.to_string()) else {
            return;
        };
        let _ = write!(
            out,
            "<p class=\"golden-record\">The golden: blessed {} from {} ({}){}",
            escape(&record.blessed),
            escape(record.backend.name()),
            escape(&record.driver),
            if record.unverified {
                ", unverified"
            } else {
                ""
            }
        );
        match &record.reason {
            Some(reason) => {
                let _ = write!(out, ", because: <q>{}</q></p>", escape(reason));
            }
            None => out.push_str("; no reason recorded.</p>"),
        }
    }

    /// One backend's result: its verdict, checks and the files the run wrote.
    fn result_line(&self, out: &mut String, r: &PassCheck) {
        let _ = write!(
            out,
            "<div class=\"backend-result {}\"><b>{}</b>: {} <code>{}</code>",
            if r.outcome.passed() {
                "passed"
            } else {
                "failed"
            },
            escape(r.backend.name()),
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
                    escape(&file_link(p, self.page_dir))
                )
            })
        })
        .collect();
        if !files.is_empty() {
            let _ = write!(out, " files: {}", files.join(" "));
        }
        out.push_str("</div>");
    }

    /// A failing backend's output against the golden: a viewer, or thumbnails where the two
    /// cannot be compared or the page already holds its budget of pixel data.
    fn comparison(
        &self,
        out: &mut String,
        blobs: &mut Blobs,
        r: &PassCheck,
        golden_image: Option<&Image>,
        golden_blob: &mut Option<usize>,
    ) {
        let pass = r.pass;
        let key = (r.scene.clone(), r.pass, r.backend);
        let (Some(actual), Some(golden_image)) = (self.outputs.get(&key), golden_image) else {
            if let Some(actual) = self.outputs.get(&key) {
                out.push_str(&thumbnail("actual (no golden to compare)", actual, pass));
            }
            return;
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
            return;
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
            return;
        }
        viewer(out, blobs, r, actual, golden_image, golden_blob);
    }

    /// A passing pass: a thumbnail of its golden, captioned with the backends it passed on.
    fn passing_case(&self, out: &mut String, scene: &str, pass: TargetId) {
        let backends: Vec<&str> = results_of(self.run, scene, pass)
            .map(|r| r.backend.name())
            .collect();
        let _ = write!(
            out,
            "<section class=\"passing\" id=\"{}\">",
            case_id(scene, pass)
        );
        let label = format!("{scene} / {pass}: ok on {}", backends.join(", "));
        match self.golden(scene, pass) {
            Some(golden_image) => out.push_str(&thumbnail(&label, &golden_image, pass)),
            None => {
                let _ = write!(out, "<figure>{}</figure>", escape(&label));
            }
        }
        out.push_str("</section>");
    }
}

/// The viewer of a failing backend: its output and the golden embedded as blobs (the golden
/// once per pass, in `golden_blob`), with the tolerance's per-pixel criterion.
fn viewer(
    out: &mut String,
    blobs: &mut Blobs,
    r: &PassCheck,
    actual: &Image,
    golden_image: &Image,
    golden_blob: &mut Option<usize>,
) {
    let pass = r.pass;
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
        escape(r.backend.name()),
        actual.width,
        actual.height,
        actual.channels(),
        display_mode(actual, pass),
        criterion.threshold,
        criterion.floor.map(|f| f.to_string()).unwrap_or_default(),
        u8::from(criterion.channels == crate::golden::metrics::Channels::Rgb),
    );
}

/// A link to a file the run wrote: relative to the page when it lies under `page_dir`.
fn file_link(path: &Path, page_dir: Option<&Path>) -> String {
    match page_dir.and_then(|dir| path.strip_prefix(dir).ok()) {
        Some(relative) => crate::url::encoded(relative),
        None => format!("file://{}", crate::url::encoded(path)),
    }
}
