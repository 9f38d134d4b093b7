//! The commands of the `harness` binary: one module per command (or group of small commands),
//! each a thin layer that calls the library, prints its results and picks the exit code.
//! `main.rs` parses the command line and dispatches here. Also the pieces several commands
//! share: the default output folder, the process's runtime directory, and loading the scenes.

pub(super) mod bench;
pub(super) mod bless;
pub(super) mod bless_speed;
pub(super) mod check;
pub(super) mod check_speed;
pub(super) mod hard;
pub(super) mod info;
pub(super) mod noise;
pub(super) mod noise_record;
pub(super) mod noise_timing;
pub(super) mod preflight;
pub(super) mod render;
pub(super) mod review;
pub(super) mod selftest;
pub(super) mod sweep;

use std::path::PathBuf;

/// `target/harness` in the workspace.
pub(crate) fn default_out_dir() -> PathBuf {
    harness::workspace_root().join("target/harness")
}

/// Gives the process a private runtime directory when XDG_RUNTIME_DIR is unset or unusable:
/// the Vulkan loader and Mesa's window-system probes print "XDG_RUNTIME_DIR is invalid or not
/// set" once per device otherwise (eight times a check), although no display is used. Runs
/// first in `main`, before any thread or driver exists.
pub(crate) fn private_runtime_dir() {
    use std::os::unix::fs::{MetadataExt, PermissionsExt};
    let Ok(me) = std::fs::metadata("/proc/self").map(|m| m.uid()) else {
        return;
    };
    let usable = |dir: &std::path::Path| {
        std::fs::metadata(dir)
            .is_ok_and(|m| m.is_dir() && m.uid() == me && m.permissions().mode() & 0o077 == 0)
    };
    if std::env::var_os("XDG_RUNTIME_DIR").is_some_and(|d| usable(std::path::Path::new(&d))) {
        return;
    }
    let dir = std::env::temp_dir().join(format!("harness-runtime-{me}"));
    let _ = std::fs::create_dir(&dir);
    let _ = std::fs::set_permissions(&dir, std::fs::Permissions::from_mode(0o700));
    if usable(&dir) {
        std::env::set_var("XDG_RUNTIME_DIR", &dir);
    }
}

/// Ends the process cleanly when its standard output or error cannot be written, instead of
/// the panic `println!` raises: quietly with status 141 (as a program killed by SIGPIPE) when
/// the reader went away (`harness check | head`), else with the cause and status 1
/// (`> /dev/full`). Every other panic goes to the default hook. Runs first in `main`.
pub(crate) fn end_quietly_on_closed_output() {
    let default = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        let message = info
            .payload()
            .downcast_ref::<String>()
            .map(String::as_str)
            .or_else(|| info.payload().downcast_ref::<&str>().copied())
            .unwrap_or("");
        let stream = ["stdout", "stderr"]
            .into_iter()
            .find(|s| message.starts_with(&format!("failed printing to {s}: ")));
        match stream {
            Some(_) if message.contains("Broken pipe") => std::process::exit(141),
            Some("stdout") => {
                let cause = message.trim_start_matches("failed printing to stdout: ");
                eprintln!("error: cannot write to standard output: {cause}");
                std::process::exit(1);
            }
            Some(_) => std::process::exit(1),
            None => default(info),
        }
    }));
}

/// The scenes named (every canonical one when none is), each that loads as a case and each that
/// does not as a broken scene with its error (printed here), so that a run can go on with the
/// others. Fails only when the noise model cannot be read.
fn load_cases_isolated(
    scenes: &[String],
) -> anyhow::Result<(
    Vec<harness::golden::suite::Case>,
    Vec<harness::golden::suite::BrokenScene>,
)> {
    let (cases, broken) = harness::golden::suite::load_suite(&scenes_or_canonical(scenes))?;
    for case in &cases {
        print_load_warnings(&case.loaded);
    }
    for b in &broken {
        eprintln!("error: scene `{}` did not load: {}", b.scene, b.error);
    }
    Ok((cases, broken))
}

/// The scenes named (every canonical one when none is); any that does not load fails the
/// command (bless and noise need every scene they were asked for).
fn load_cases(scenes: &[String]) -> anyhow::Result<Vec<harness::golden::suite::Case>> {
    let (cases, broken) = load_cases_isolated(scenes)?;
    if !broken.is_empty() {
        anyhow::bail!(
            "{} scene(s) did not load: {}",
            broken.len(),
            broken
                .iter()
                .map(|b| b.scene.as_str())
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    Ok(cases)
}

/// A scene's asset warnings on stderr, once per asset (the loader collects each once).
fn print_load_warnings(loaded: &engine::scene_file::LoadedScene) {
    for warning in &loaded.warnings {
        eprintln!("warning: {warning}");
    }
}

/// The scenes asked for, or every canonical scene (saying which files of scenes/ no name can
/// reach).
fn scenes_or_canonical(scenes: &[String]) -> Vec<String> {
    if scenes.is_empty() {
        for path in engine::scene_file::unnamed_scene_files(&harness::scenes_dir()) {
            eprintln!("warning: {path} is left out: its name is not UTF-8 (rename it)");
        }
        engine::scene_file::canonical_scenes(&harness::scenes_dir())
    } else {
        // A scene named twice is checked once (its failure folder would be cleared and
        // written twice, its speed probed twice).
        let mut unique: Vec<String> = Vec::new();
        for scene in scenes {
            if !unique.contains(scene) {
                unique.push(scene.clone());
            }
        }
        unique
    }
}
