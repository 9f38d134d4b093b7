//! A check run in the formats CI systems read: JUnit XML for test-report actions (GitLab,
//! Jenkins, GitHub's test reporters) and a Markdown summary for a job page (GitHub's
//! `$GITHUB_STEP_SUMMARY`). `harness check --junit FILE --summary FILE` writes them beside the
//! review page; both name the same cases as the golden test binary, `<scene>::<pass>::<backend>`
//! and `<scene>::speed::<pass>::<backend>`.

mod junit;
mod summary;

pub use junit::junit;
pub use summary::summary;

use crate::golden::check::CheckRun;
use crate::golden::speed::{SpeedCheck, SpeedOutcome};

/// What a CI system is told about one case.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Status {
    Passed,
    /// A check outside its limit, or a golden missing.
    Failed,
    /// Nothing could be compared or measured: a render, a load or a probe failed.
    Error,
    /// Not checked, with the reason (an untimed pass).
    Skipped,
}

/// The status of a speed check: a faster pass is a pass (with a note), an untimed one skipped.
fn speed_status(check: &SpeedCheck) -> Status {
    match check.outcome {
        SpeedOutcome::Passed | SpeedOutcome::Faster => Status::Passed,
        SpeedOutcome::Slower | SpeedOutcome::MissingGolden | SpeedOutcome::TargetsChanged(_) => {
            Status::Failed
        }
        SpeedOutcome::Untimed(_) => Status::Skipped,
    }
}

/// How many cases a run has, and how many did not pass (failed or errors): the console's,
/// the summary's and the JUnit file's counts alike (a scene that did not load, a backend asked
/// for and missing, a render or probe that failed each count as one).
pub fn counts(run: &CheckRun) -> (usize, usize) {
    let missing = run.backends.iter().filter(|b| b.missing()).count();
    let total = run.results.len()
        + missing
        + run.render_errors.len()
        + run.load_errors.len()
        + run.speed.checks.len()
        + run.speed.errors.len();
    let bad = run.results.iter().filter(|r| !r.outcome.passed()).count()
        + missing
        + run.render_errors.len()
        + run.load_errors.len()
        + run
            .speed
            .checks
            .iter()
            .filter(|c| speed_status(c) == Status::Failed)
            .count()
        + run.speed.errors.len();
    (total, bad)
}
