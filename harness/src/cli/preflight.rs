//! What a command can see is wrong before it does any work: an output folder that is a file or
//! lies under one, a file to write that is a folder or lies under a file, a suite with no scene.
//! The commands refuse them as usage errors (exit 2, nothing written), so that a long check does
//! not render everything and then fail to write its report, and an empty suite does not pass.

use std::path::Path;

/// Why `dir` cannot be the folder `flag` names for a command to write into: it, or a folder on
/// its way, is a file. None where it can be (it need not exist yet).
pub(crate) fn folder_problem(flag: &str, dir: &Path) -> Option<String> {
    let file = dir.ancestors().find(|a| a.is_file())?;
    Some(if file == dir {
        format!("{flag} {}: is a file, not a folder", dir.display())
    } else {
        format!(
            "{flag} {}: {} is a file, not a folder",
            dir.display(),
            file.display()
        )
    })
}

/// Why `path` cannot be the file `flag` names for a command to write: it is a folder, or a
/// folder on its way is a file.
pub(crate) fn file_problem(flag: &str, path: &Path) -> Option<String> {
    if path.is_dir() {
        return Some(format!(
            "{flag} {}: is a folder, not a file",
            path.display()
        ));
    }
    let file = path.ancestors().skip(1).find(|a| a.is_file())?;
    Some(format!(
        "{flag} {}: {} is a file, not a folder",
        path.display(),
        file.display()
    ))
}

/// The first problem with what a check (or a joined report) writes: `out`, and the JUnit and
/// summary files when asked for.
pub(crate) fn report_problem(
    out: &Path,
    junit: Option<&Path>,
    summary: Option<&Path>,
) -> Option<String> {
    folder_problem("--out", out)
        .or_else(|| junit.and_then(|p| file_problem("--junit", p)))
        .or_else(|| summary.and_then(|p| file_problem("--summary", p)))
}

/// Why a check of every canonical scene has nothing to check: scenes/ has no scene (a mistyped
/// HARNESS_ROOT, or a checkout without them), which would otherwise pass with no check at all.
pub(crate) fn no_scenes(named: &[String]) -> Option<String> {
    let dir = harness::scenes_dir();
    (named.is_empty() && engine::scene_file::canonical_scenes(&dir).is_empty()).then(|| {
        let root = std::env::var("HARNESS_ROOT")
            .map_or(String::new(), |r| format!(" (HARNESS_ROOT is {r})"));
        format!("{} holds no scene{root}", dir.display())
    })
}
