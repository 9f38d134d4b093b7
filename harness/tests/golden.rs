//! The golden-image suite: one test per scene x pass x backend, named
//! `<scene>::<pass>::<backend>` (so `cargo test --test golden chess::final` filters), runnable
//! under `cargo nextest` (and so shardable with `--partition count:K/N`).
//!
//! Each (scene, backend) is rendered once, by the first of its tests to run. A backend that is
//! not available here is reported as ignored, with the reason on stderr; `REQUIRE_BACKENDS`
//! (comma-separated names) turns that into a failure. `UPDATE_GOLDENS=1` blesses the reference
//! backend's outputs instead of checking them, and checks the other backends against those.
//!
//! The speed checks are tests too, `<scene>::speed::<pass>::<backend>`, the verdicts of
//! `harness check`: each backend's scenes are probed once, in a child process (the harness
//! binary, one rasterizer thread), while no render of this process runs. `HARNESS_NO_SPEED=1`
//! marks them ignored.

use std::collections::HashMap;
use std::sync::{Arc, Mutex, OnceLock, RwLock};

use engine::backend::{self, BackendKind};
use engine::plan::{PassId, TargetId};
use engine::renderer::Frame;
use harness::golden::bless::{bless_pass, BlessRequest};
use harness::golden::suite::{self, Case, REFERENCE_BACKEND};
use harness::golden::{self, GoldenStore};
use libtest_mimic::{Arguments, Failed, Trial};

type Rendered = Arc<OnceLock<Result<Frame, String>>>;
type Probed = Arc<OnceLock<Result<Vec<harness::golden::speed::SpeedCheck>, String>>>;

/// Held for reading by every render and for writing by every speed probe: a probe times its
/// passes while this process renders nothing.
static QUIET: RwLock<()> = RwLock::new(());

struct Suite {
    cases: Vec<Case>,
    store: GoldenStore,
    frames: Mutex<HashMap<(usize, BackendKind), Rendered>>,
    probes: Mutex<HashMap<BackendKind, Probed>>,
    update: bool,
    /// Checks that did not pass, for the HTML report written at the end.
    failures: Mutex<Vec<harness::golden::suite::PassCheck>>,
}

impl Suite {
    fn frame(&self, case: usize, kind: BackendKind) -> Rendered {
        let cell = self
            .frames
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .entry((case, kind))
            .or_default()
            .clone();
        cell.get_or_init(|| {
            let _rendering = QUIET.read().unwrap_or_else(|e| e.into_inner());
            self.cases[case].render(kind).map_err(|e| e.to_string())
        });
        cell
    }

    /// The speed checks of every scene on one backend, probed once (one child process: one
    /// start and one compile of each scene's pipelines for the backend).
    fn probe(&self, kind: BackendKind) -> Probed {
        let cell = self
            .probes
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .entry(kind)
            .or_default()
            .clone();
        cell.get_or_init(|| {
            let _quiet = QUIET.write().unwrap_or_else(|e| e.into_inner());
            let driver = backend::probe(kind)
                .info
                .map(|info| golden::fingerprint(&info))
                .unwrap_or_default();
            let scenes: Vec<(String, String)> = self
                .cases
                .iter()
                .map(|c| (c.name().to_owned(), c.argument()))
                .collect();
            let started = harness::golden::speed::start_check(
                std::path::Path::new(env!("CARGO_BIN_EXE_harness")),
                &scenes,
                &[kind],
                Default::default(),
                &[],
            );
            let run = harness::golden::speed::check_scenes(
                started,
                self.store.root(),
                &scenes,
                &[(kind, driver)],
                |_| {},
            );
            match run.errors.first() {
                Some(e) => Err(e.clone()),
                None => Ok(run.checks),
            }
        });
        cell
    }

    /// The speed checks of one scene on one backend.
    fn speed_checks(
        &self,
        case: usize,
        kind: BackendKind,
    ) -> Result<Vec<harness::golden::speed::SpeedCheck>, Failed> {
        let probed = self.probe(kind);
        let scene = self.cases[case].name();
        match probed.get() {
            Some(Ok(checks)) => Ok(checks
                .iter()
                .filter(|c| c.scene == scene)
                .cloned()
                .collect()),
            Some(Err(e)) => Err(format!("speed probe failed: {e}").into()),
            None => Err("speed probe did not run".into()),
        }
    }

    /// Fails when a pass was timed that has no timing golden for `kind`.
    fn run_speed_goldens(&self, case: usize, kind: BackendKind) -> Result<(), Failed> {
        let checks = self.speed_checks(case, kind)?;
        let missing: Vec<PassId> = checks
            .iter()
            .filter(|c| c.outcome == harness::golden::speed::SpeedOutcome::MissingGolden)
            .map(|c| c.pass)
            .collect();
        if missing.is_empty() {
            Ok(())
        } else {
            Err(format!(
                "no timing golden on {kind} for {}; bless them: {}",
                harness::names(&missing),
                self.speed_bless(case, &checks[0])
            )
            .into())
        }
    }

    /// The command that blesses a deliberate change of a speed check's timing: where a bless
    /// from here writes it (the host that blessed, or one recorded against it), the timings
    /// that moved; elsewhere (where a bless keeps another host's timing goldens) every pass,
    /// moving the backend's timing goldens to this host.
    fn speed_bless(&self, case: usize, check: &harness::golden::speed::SpeedCheck) -> String {
        harness::golden::command_line::speed_bless_command(
            &self.cases[case].argument(),
            check.bless_writes_here(),
        )
    }

    fn run_speed(&self, case: usize, pass: PassId, kind: BackendKind) -> Result<(), Failed> {
        let checks = self.speed_checks(case, kind)?;
        let Some(check) = checks.iter().find(|c| c.pass == pass) else {
            return Err(format!("{pass} was not timed on {kind}").into());
        };
        if check.failed() {
            return Err(format!(
                "{} on {kind}: {}\n  bless a deliberate change: {}",
                check.pass,
                check.describe(),
                self.speed_bless(case, check)
            )
            .into());
        }
        if !matches!(check.outcome, harness::golden::speed::SpeedOutcome::Passed) {
            eprintln!(
                "note: {}/{} on {kind}: {}",
                check.scene,
                pass,
                check.describe()
            );
        }
        Ok(())
    }

    fn run(&self, case_index: usize, pass: TargetId, kind: BackendKind) -> Result<(), Failed> {
        let case = &self.cases[case_index];
        let rendered = self.frame(case_index, kind);
        let frame = match rendered.get() {
            Some(Ok(frame)) => frame,
            Some(Err(e)) => return Err(format!("render failed on {kind}: {e}").into()),
            None => return Err("render did not run".into()),
        };
        let actual = &frame.outputs[&pass];
        if self.update {
            if kind == REFERENCE_BACKEND {
                // The same path, and the same words, as `harness bless --scene S`.
                let driver = backend::create(kind)
                    .map(|b| golden::fingerprint(b.info()))
                    .unwrap_or_default();
                // Trials of one scene run in parallel: each holds the scene's lock while it
                // writes its golden and blessed.toml.
                let lock = self
                    .store
                    .lock_scene(case.name(), |_| {})
                    .map_err(|e| Failed::from(e.to_string()))?;
                let blessed = bless_pass(
                    &self.store,
                    &lock,
                    case,
                    pass,
                    actual,
                    (kind, &driver),
                    // The other backends are checked against this render below, the CPU code
                    // paths not: recorded as unverified (`harness bless` verifies).
                    BlessRequest {
                        unverified: true,
                        ..BlessRequest::default()
                    },
                )
                .map_err(|e| Failed::from(e.to_string()))?;
                eprintln!("{blessed}");
                return Ok(());
            }
            // Check the other backends against the reference backend's fresh render.
            let reference = self.frame(case_index, REFERENCE_BACKEND);
            if let Some(Ok(reference)) = reference.get() {
                let outcome =
                    golden::check(actual, Some(&reference.outputs[&pass]), &case.rules[&pass]);
                return if outcome.passed() {
                    Ok(())
                } else {
                    Err(format!(
                        "{kind} disagrees with {REFERENCE_BACKEND} being blessed: {outcome:?}"
                    )
                    .into())
                };
            }
        }
        let check = suite::check_pass(
            &self.store,
            case,
            pass,
            kind,
            actual,
            &suite::default_failures_dir(),
        );
        if check.outcome.passed() {
            Ok(())
        } else {
            let message = check.message();
            self.failures
                .lock()
                .unwrap_or_else(|e| e.into_inner())
                .push(check);
            Err(format!("{message}\n  report {}", report_path().display()).into())
        }
    }
}

fn main() {
    let arguments = Arguments::from_args();
    harness::use_ibl_cache();
    // A scene that does not load is one failing test with its error; the others run.
    let (cases, broken) = match suite::canonical_suite() {
        Ok(suite) => suite,
        Err(e) => {
            eprintln!("error: cannot set up the golden suite: {e}");
            std::process::exit(101);
        }
    };
    let required = std::env::var("REQUIRE_BACKENDS").unwrap_or_default();
    let mut available = Vec::new();
    let mut trials = Vec::new();
    // A whole run clears the failure images of earlier runs first (a filtered one leaves them).
    if arguments.filter.is_none() {
        for case in &cases {
            suite::clear_artifacts(&suite::default_failures_dir(), case.name());
        }
    }
    for scene in broken {
        trials.push(Trial::test(format!("{}::load", scene.scene), move || {
            Err(format!("scene `{}` did not load: {}", scene.scene, scene.error).into())
        }));
    }
    for kind in BackendKind::ALL {
        let status = backend::probe(kind);
        if status.available {
            available.push(kind);
        } else {
            let reason = format!(
                "{kind} unavailable: {} (fix: {})",
                status.reason.unwrap_or_default(),
                status.fix.unwrap_or_default()
            );
            if required.split(',').any(|r| r.trim() == kind.name()) {
                let message = format!("{reason}; REQUIRE_BACKENDS names it");
                trials.push(Trial::test(format!("backend::{kind}"), move || {
                    Err(message.into())
                }));
            } else {
                eprintln!("note: {reason}; its golden tests are ignored");
            }
        }
    }
    let suite = Arc::new(Suite {
        cases,
        store: GoldenStore::workspace(),
        frames: Mutex::default(),
        probes: Mutex::default(),
        update: std::env::var("UPDATE_GOLDENS").is_ok_and(|v| v == "1"),
        failures: Mutex::default(),
    });
    // The speed tests first: their probes then run before the renders start.
    let no_speed = std::env::var("HARNESS_NO_SPEED").is_ok_and(|v| v == "1");
    for (index, case) in suite.cases.iter().enumerate() {
        let goldens = harness::golden::speed::TimingGoldens::load(suite.store.root(), case.name())
            .unwrap_or_default();
        for kind in BackendKind::ALL {
            let ignored = no_speed || !available.contains(&kind);
            // Every pass timed without a golden fails here (a pass new to the plan).
            let name = format!("{}::speed::goldens::{kind}", case.name());
            let all = suite.clone();
            trials.push(
                Trial::test(name, move || all.run_speed_goldens(index, kind))
                    .with_ignored_flag(ignored),
            );
            let timed = case.frame.plan().passes.iter().map(|p| p.id);
            let blessed = goldens.backends.get(&kind);
            for pass in timed.filter(|id| blessed.is_some_and(|b| b.passes.contains_key(id))) {
                let name = format!("{}::speed::{pass}::{kind}", case.name());
                let suite = suite.clone();
                trials.push(
                    Trial::test(name, move || suite.run_speed(index, pass, kind))
                        .with_ignored_flag(ignored),
                );
            }
        }
    }
    for (index, case) in suite.cases.iter().enumerate() {
        for &pass in &case.passes {
            for kind in BackendKind::ALL {
                let name = format!("{}::{pass}::{kind}", case.name());
                let is_available = available.contains(&kind);
                let suite = suite.clone();
                trials.push(
                    Trial::test(name, move || suite.run(index, pass, kind))
                        .with_ignored_flag(!is_available),
                );
            }
        }
    }
    let conclusion = libtest_mimic::run(&arguments, trials);
    write_failure_report(&suite);
    conclusion.exit();
}

fn report_path() -> std::path::PathBuf {
    harness::workspace_root().join("target/harness/report.html")
}

/// After a run with failures: the HTML report of the failed checks (golden | actual | diff).
fn write_failure_report(suite: &Suite) {
    let failures = suite.failures.lock().unwrap_or_else(|e| e.into_inner());
    if failures.is_empty() {
        return;
    }
    let frames = suite.frames.lock().unwrap_or_else(|e| e.into_inner());
    let mut outputs = harness::golden::check::Outputs::new();
    for check in failures.iter() {
        let Some(index) = suite.cases.iter().position(|c| c.name() == check.scene) else {
            continue;
        };
        let kind = check.backend;
        if let Some(Some(Ok(frame))) = frames.get(&(index, kind)).map(|cell| cell.get()) {
            if let Some(image) = frame.outputs.get(&check.pass) {
                outputs.insert((check.scene.clone(), check.pass, kind), image.clone());
            }
        }
    }
    let run = harness::golden::check::CheckRun {
        results: failures.clone(),
        ..Default::default()
    };
    let html = harness::report::html(&run, &outputs, &suite.store, None, &[]);
    match harness::images::write_atomically(&report_path(), html.as_bytes()) {
        Ok(()) => eprintln!("report of the failures: {}", report_path().display()),
        Err(e) => eprintln!("could not write the report: {e}"),
    }
}
