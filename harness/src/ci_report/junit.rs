//! `check --junit FILE`: one JUnit test suite per scene, one test case per pass and backend (and
//! per timed pass and backend), with the failure's message, its checks and the paths of the
//! images to look at.

use quick_junit::{NonSuccessKind, Report, TestCase, TestCaseStatus, TestSuite};

use super::{speed_status, Status};
use crate::golden::check::CheckRun;
use crate::golden::command_line::speed_bless_command;

/// The run as a JUnit XML document.
pub fn junit(run: &CheckRun) -> Result<String, quick_junit::SerializeError> {
    let mut report = Report::new("harness check");
    for scene in scenes(run) {
        let mut suite = TestSuite::new(scene.as_str());
        for broken in run.load_errors.iter().filter(|b| b.scene == scene) {
            suite.add_test_case(case(
                &scene,
                "load".to_owned(),
                Status::Error,
                &broken.error,
                None,
            ));
        }
        for (_, backend, error) in run.render_errors.iter().filter(|(s, ..)| *s == scene) {
            suite.add_test_case(case(
                &scene,
                format!("render::{backend}"),
                Status::Error,
                error,
                None,
            ));
        }
        for r in run.results.iter().filter(|r| r.scene == scene) {
            let status = match r.outcome {
                crate::golden::Outcome::Passed(_) => Status::Passed,
                crate::golden::Outcome::Failed(_) | crate::golden::Outcome::MissingGolden => {
                    Status::Failed
                }
                crate::golden::Outcome::Incomparable(_) => Status::Error,
            };
            let verdict = crate::golden::diagnosis::find(&run.diagnoses, &scene, r.pass, r.backend);
            let message = match verdict {
                Some(d) => format!("{} ({})", r.worst(), d.headline()),
                None => r.worst(),
            };
            let details = match verdict {
                Some(d) => format!("{}\n  why: {}; {}", r.message(), d.headline(), d.advice),
                None => r.message(),
            };
            suite.add_test_case(case(
                &scene,
                format!("{}::{}", r.pass, r.backend),
                status,
                &message,
                Some(details),
            ));
        }
        for c in run.speed.checks.iter().filter(|c| c.scene == scene) {
            let status = speed_status(c);
            let details = (status == Status::Failed).then(|| {
                if run.speed.unspecialised_lighting {
                    format!(
                        "{}\nthe slowdown of --debug-unspecialised-lighting, reproduced on \
                         purpose: nothing to bless",
                        c.describe()
                    )
                } else {
                    format!(
                        "{}\nif the slowdown is intended, bless the timing goldens with:\n  {}",
                        c.describe(),
                        speed_bless_command(run.scene_argument(&c.scene), c.bless_writes_here())
                    )
                }
            });
            suite.add_test_case(case(
                &scene,
                format!("speed::{}::{}", c.pass, c.backend),
                status,
                &c.describe(),
                details,
            ));
        }
        report.add_test_suite(suite);
    }
    // A case for each unavailable backend: nothing of it was checked (skipped, or failed where
    // it was asked for by name). An available one is no check of its own (its passes are), so
    // the file's count of checks is the console's, skipped backends aside.
    if run.backends.iter().any(|b| b.unavailable.is_some()) {
        let mut suite = TestSuite::new("backends");
        for b in &run.backends {
            let (status, message) = match &b.unavailable {
                None => continue,
                Some(reason) if b.required => (
                    Status::Failed,
                    format!("asked for (--backend) but unavailable: {reason}"),
                ),
                Some(reason) => (Status::Skipped, format!("unavailable: {reason}")),
            };
            suite.add_test_case(case(
                "backends",
                b.backend.name().to_owned(),
                status,
                &message,
                None,
            ));
        }
        report.add_test_suite(suite);
    }
    if !run.speed.errors.is_empty() {
        let mut suite = TestSuite::new("speed probes");
        for (i, error) in run.speed.errors.iter().enumerate() {
            suite.add_test_case(case(
                "speed probes",
                format!("probe {}", i + 1),
                Status::Error,
                error,
                None,
            ));
        }
        report.add_test_suite(suite);
    }
    report.to_string()
}

/// Every scene the run names, in the order it first names them.
fn scenes(run: &CheckRun) -> Vec<String> {
    let mut scenes: Vec<String> = Vec::new();
    let names = run
        .load_errors
        .iter()
        .map(|b| &b.scene)
        .chain(run.results.iter().map(|r| &r.scene))
        .chain(run.render_errors.iter().map(|(s, ..)| s))
        .chain(run.speed.checks.iter().map(|c| &c.scene));
    for name in names {
        if !scenes.contains(name) {
            scenes.push(name.clone());
        }
    }
    scenes
}

/// One test case: `message` on the failure, error or skip; `details` as its text.
fn case(
    scene: &str,
    name: String,
    status: Status,
    message: &str,
    details: Option<String>,
) -> TestCase {
    let mut junit_status = match status {
        Status::Passed => TestCaseStatus::success(),
        Status::Failed => TestCaseStatus::non_success(NonSuccessKind::Failure),
        Status::Error => TestCaseStatus::non_success(NonSuccessKind::Error),
        Status::Skipped => TestCaseStatus::skipped(),
    };
    if status != Status::Passed {
        junit_status.set_message(message);
        if let Some(details) = &details {
            junit_status.set_description(details.as_str());
        }
    }
    let mut case = TestCase::new(name, junit_status);
    case.set_classname(scene);
    if status == Status::Passed {
        case.set_system_out(message);
    }
    case
}
