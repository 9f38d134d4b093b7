//! Faults in the middle of a run: a shader that fails to compile, a backend lost mid-run, a
//! failed readback, a full disk while writing a golden or the report, and a bless killed
//! mid-write. Each gives an error naming the scene, the pass (or output or file) and the
//! backend; a check run goes on with the other scenes and fails; no golden is ever left
//! half-written.

use crate::common;
use engine::plan::TargetId;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant};

use engine::backend::*;
use engine::renderer::{self, Readback};
use engine::{BackendKind, Image};

/// A backend that forwards to a real one, with faults injected on request.
struct Faulty {
    inner: Box<dyn Backend>,
    /// This shader file is replaced by WGSL that does not compile.
    break_shader: Option<&'static str>,
    /// Every submit fails as if the device were lost.
    lose_device: bool,
    /// Every readback fails.
    fail_readback: bool,
}

impl Faulty {
    fn new(kind: BackendKind) -> Self {
        Self {
            inner: engine::backend::create(kind).unwrap(),
            break_shader: None,
            lose_device: false,
            fail_readback: false,
        }
    }

    fn injected(&self, context: &str, message: &str) -> BackendError {
        BackendError::Driver {
            backend: self.inner.kind().name(),
            context: context.to_owned(),
            message: format!("{message} (injected)"),
        }
    }
}

impl Backend for Faulty {
    fn kind(&self) -> BackendKind {
        self.inner.kind()
    }
    fn info(&self) -> &DriverInfo {
        self.inner.info()
    }
    fn features(&self) -> Features {
        self.inner.features()
    }
    fn create_texture(&mut self, desc: &TextureDesc) -> Result<Handle<Texture>> {
        self.inner.create_texture(desc)
    }
    fn write_texture(&mut self, t: Handle<Texture>, at: Subresource, data: &[u8]) -> Result<()> {
        self.inner.write_texture(t, at, data)
    }
    fn destroy_texture(&mut self, t: Handle<Texture>) -> Result<()> {
        self.inner.destroy_texture(t)
    }
    fn create_buffer(&mut self, desc: &BufferDesc) -> Result<Handle<Buffer>> {
        self.inner.create_buffer(desc)
    }
    fn write_buffer(&mut self, b: Handle<Buffer>, offset: u64, data: &[u8]) -> Result<()> {
        self.inner.write_buffer(b, offset, data)
    }
    fn destroy_buffer(&mut self, b: Handle<Buffer>) -> Result<()> {
        self.inner.destroy_buffer(b)
    }
    fn create_sampler(&mut self, desc: &SamplerDesc) -> Result<Handle<Sampler>> {
        self.inner.create_sampler(desc)
    }
    fn destroy_sampler(&mut self, s: Handle<Sampler>) -> Result<()> {
        self.inner.destroy_sampler(s)
    }
    fn create_shader(&mut self, desc: &ShaderDesc) -> Result<Handle<Shader>> {
        if self.break_shader == Some(desc.name.as_str()) {
            let broken = ShaderDesc {
                name: desc.name.clone(),
                wgsl: format!("{}\nfn broken( {{", desc.wgsl),
            };
            return self.inner.create_shader(&broken);
        }
        self.inner.create_shader(desc)
    }
    fn destroy_shader(&mut self, s: Handle<Shader>) -> Result<()> {
        self.inner.destroy_shader(s)
    }
    fn create_pipeline(&mut self, desc: &PipelineDesc) -> Result<Handle<Pipeline>> {
        self.inner.create_pipeline(desc)
    }
    fn destroy_pipeline(&mut self, p: Handle<Pipeline>) -> Result<()> {
        self.inner.destroy_pipeline(p)
    }
    fn submit(&mut self, passes: &[RenderPass]) -> Result<Vec<PassTiming>> {
        if self.lose_device {
            let first = passes.first().map_or("submit", |p| p.name.as_str());
            return Err(self.injected(first, "device lost"));
        }
        self.inner.submit(passes)
    }
    fn read_texture(&mut self, t: Handle<Texture>, at: Subresource) -> Result<Image> {
        if self.fail_readback {
            return Err(self.injected("read_texture", "readback failed"));
        }
        self.inner.read_texture(t, at)
    }
    fn live_resources(&self) -> usize {
        self.inner.live_resources()
    }
    fn pipelines_compiled(&self) -> u64 {
        self.inner.pipelines_compiled()
    }
}

fn chess() -> engine::scene::Scene {
    harness::use_ibl_cache();
    harness::load_scene("chess").unwrap().scene
}

#[test]
fn a_shader_that_fails_to_compile_names_the_scene_the_shader_and_the_backend() {
    for kind in common::available_backends() {
        let mut backend = Faulty::new(kind);
        backend.break_shader = Some("lighting.wgsl");
        let before = backend.live_resources();
        let error = renderer::render(&mut backend, &chess(), Readback::All)
            .err()
            .expect("a broken shader must fail the render")
            .to_string();
        eprintln!("{kind}: {}", error.lines().next().unwrap_or_default());
        assert!(
            error.contains("scene `chess`")
                && error.contains("lighting.wgsl")
                && error.contains(kind.name()),
            "{kind}: {error}"
        );
        assert_eq!(backend.live_resources(), before, "{kind}: resources leaked");
    }
}

#[test]
fn a_failed_readback_names_the_scene_the_output_and_the_backend() {
    for kind in common::available_backends() {
        let mut backend = Faulty::new(kind);
        backend.fail_readback = true;
        let error = renderer::render(&mut backend, &chess(), Readback::Only(&[TargetId::Light]))
            .err()
            .expect("a failed readback must fail the render")
            .to_string();
        eprintln!("{kind}: {error}");
        assert!(
            error.contains("scene `chess`")
                && error.contains("pass output `light`")
                && error.contains(kind.name()),
            "{kind}: {error}"
        );
    }
}

/// A check over every canonical scene on one backend, lost at its second render: that scene
/// fails with an error naming the scene, the first pass and the backend, the scenes after it
/// are rendered and checked as usual and pass, and the run as a whole fails. (One backend: the
/// fault is in one, and the golden suite checks every scene on every backend.)
#[test]
fn a_backend_lost_mid_run_fails_its_scene_and_the_run_goes_on() {
    harness::use_ibl_cache();
    let Some(&kind) = common::available_backends().first() else {
        return;
    };
    let cases = harness::golden::suite::canonical_cases().unwrap();
    let store = harness::golden::GoldenStore::workspace();
    let created = AtomicUsize::new(0);
    let create = |k: BackendKind| -> Result<Box<dyn Backend>> {
        let mut backend = Faulty::new(k);
        backend.lose_device = k == kind && created.fetch_add(1, Ordering::SeqCst) == 1;
        Ok(Box::new(backend))
    };
    let failures = tempfile::tempdir().unwrap();
    let (run, _) = harness::golden::check::run_with(
        &cases,
        &store,
        &[kind],
        failures.path(),
        &create,
        |_, _, _| {},
    );
    assert!(!run.passed());
    assert_eq!(run.render_errors.len(), 1, "{:?}", run.render_errors);
    let (scene, backend, error) = &run.render_errors[0];
    eprintln!("{scene} on {backend}: {error}");
    assert_eq!(*backend, kind);
    assert!(
        error.contains(&format!("scene `{scene}`"))
            && error.contains("device lost")
            && error.contains(kind.name()),
        "{error}"
    );
    // The lost scene's first pass is named.
    let case = cases.iter().find(|c| c.name() == scene).unwrap();
    let first = case.frame.plan().passes[0].id;
    assert!(error.contains(&first.to_string()), "{error}");
    // Everything else was rendered and checked, and passed.
    let renders = cases.len();
    let checked: std::collections::BTreeSet<(&str, engine::backend::BackendKind)> = run
        .results
        .iter()
        .map(|r| (r.scene.as_str(), r.backend))
        .collect();
    assert_eq!(checked.len(), renders - 1);
    assert!(run.results.iter().all(|r| r.outcome.passed()));
}

fn harness_bin() -> Command {
    common::harness_command()
}

fn temporaries(dir: &Path) -> Vec<PathBuf> {
    std::fs::read_dir(dir)
        .unwrap()
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.file_name().unwrap().to_string_lossy().contains(".tmp"))
        .collect()
}

/// Runs the harness with files limited to 4 KiB (`ulimit -f`, SIGXFSZ ignored so writes fail
/// with EFBIG instead): the nearest thing to a full disk a test can make without root.
fn with_full_disk(args: &[&str], root: Option<&Path>) -> std::process::Output {
    let mut command = Command::new("sh");
    command
        .arg("-c")
        .arg("trap '' XFSZ; ulimit -f 4; exec \"$0\" \"$@\"")
        .arg(env!("CARGO_BIN_EXE_harness"))
        .args(args)
        .env(
            "HARNESS_IBL_CACHE",
            harness::ibl_cache_dir().unwrap_or_default(),
        );
    if let Some(root) = root {
        command.env("HARNESS_ROOT", root);
    }
    command.output().unwrap()
}

#[test]
fn a_full_disk_while_blessing_keeps_the_old_golden_and_names_the_file() {
    if !common::gl_available() {
        return;
    }
    let root = common::temp_workspace();
    let golden = root.path().join("golden/chess");
    let before = std::fs::read(golden.join("final.png")).unwrap();
    let record = std::fs::read(golden.join("blessed.toml")).unwrap();
    let output = with_full_disk(
        &[
            "bless",
            "--scene",
            "chess",
            "--pass",
            "final",
            "--no-speed",
            "--unverified",
        ],
        Some(root.path()),
    );
    let stderr = String::from_utf8_lossy(&output.stderr);
    eprintln!("{stderr}");
    assert_eq!(output.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("final.png"), "{stderr}");
    assert_eq!(std::fs::read(golden.join("final.png")).unwrap(), before);
    assert_eq!(std::fs::read(golden.join("blessed.toml")).unwrap(), record);
    assert_eq!(temporaries(&golden), Vec::<PathBuf>::new());
}

#[test]
fn a_full_disk_while_writing_the_report_names_the_file_and_fails() {
    if !common::available_backends().contains(&BackendKind::Gl) {
        return;
    }
    let out = tempfile::tempdir().unwrap();
    // On gl only: the file-size limit that stands in for a full disk also caps memfd sizes, and
    // Mesa 25's lavapipe backs device memory with memfds (it dies of SIGBUS in vkCreateDevice).
    let output = with_full_disk(
        &[
            "check",
            "--no-speed",
            "--scene",
            "arrow",
            "--backend",
            "gl",
            "--out",
            out.path().to_str().unwrap(),
        ],
        None,
    );
    let stderr = String::from_utf8_lossy(&output.stderr);
    eprintln!("{stderr}");
    assert_eq!(output.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("report.html"), "{stderr}");
    assert!(!out.path().join("report.html").exists());
}

/// Kills `harness bless` while its new golden sits written but not yet renamed (the write is
/// held there by HARNESS_FAULT_WRITE_DELAY_MS): the old golden and blessed.toml are intact. The
/// next bless removes the dead process's temporary file. Images only (`--no-speed`): the
/// timing goldens are written through the same atomic write, tested in speed.rs.
#[test]
fn killing_a_bless_mid_write_leaves_the_old_golden_intact() {
    if !common::gl_available() {
        return;
    }
    let root = common::temp_workspace();
    let golden = root.path().join("golden/chess");
    let before = std::fs::read(golden.join("final.png")).unwrap();
    let record = std::fs::read(golden.join("blessed.toml")).unwrap();
    let mut child = harness_bin()
        .args([
            "bless",
            "--scene",
            "chess",
            "--pass",
            "final",
            "--no-speed",
            "--unverified",
        ])
        .env("HARNESS_ROOT", root.path())
        .env(harness::images::WRITE_DELAY_ENV, "60000")
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while temporaries(&golden).is_empty() {
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "bless never started writing"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    assert_eq!(temporaries(&golden).len(), 1, "the kill came mid-write");
    assert_eq!(std::fs::read(golden.join("final.png")).unwrap(), before);
    assert_eq!(std::fs::read(golden.join("blessed.toml")).unwrap(), record);

    let status = harness_bin()
        .args([
            "bless",
            "--scene",
            "chess",
            "--pass",
            "final",
            "--no-speed",
            "--unverified",
        ])
        .env("HARNESS_ROOT", root.path())
        .output()
        .unwrap();
    assert!(status.status.success());
    assert_eq!(temporaries(&golden), Vec::<PathBuf>::new());
}
