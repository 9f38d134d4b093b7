//! The command lines the harness prints for a user to paste (a bless or an accept after a
//! failing check), quoted for a POSIX shell, naming the workspace they were made in and run
//! the way this process was run (through cargo, or the executable itself).

/// The `harness bless` command line that rewrites the goldens of a scene's changed or missing
/// passes (`scene` as [`crate::golden::suite::Case::argument`] gives it), quoted for a POSIX
/// shell where needed. In a workspace named by `HARNESS_ROOT`, the command names it too:
/// pasted without it, it would bless the checkout the shell stands in.
pub fn bless_command(scene: &str) -> String {
    format!("{}{} bless {}", workspace(), harness(), scene_flag(scene))
}

/// The `harness check` command line of one scene (`scene` as the user gave it) writing to
/// `out` when given (where an accept reads it again), as [`bless_command`] makes its own.
pub fn check_command(scene: &str, out: Option<&std::path::Path>) -> String {
    let out = out.map_or(String::new(), |dir| {
        format!(" --out {}", shell_quote(&dir.to_string_lossy()))
    });
    format!(
        "{}{} check {}{out}",
        workspace(),
        harness(),
        scene_flag(scene)
    )
}

/// The command that blesses a deliberate change of `scene`'s timings: `--speed-only` where a
/// bless writes them from here (`writes_here`: the host that blessed its timing goldens, or
/// one recorded against them, [`Tier::bless_writes_here`](crate::golden::speed::Tier));
/// elsewhere, where a bless keeps another host's timing goldens, with `--every-pass`, which
/// moves a backend's to this host whole.
pub fn speed_bless_command(scene: &str, writes_here: bool) -> String {
    let flags = if writes_here {
        "--speed-only"
    } else {
        MOVE_TIMINGS_HERE
    };
    format!("{} {flags}", bless_command(scene))
}

/// The command that moves the timing goldens of `scenes` (as
/// [`crate::golden::suite::Case::argument`] gives them) to this host whole, every backend's and
/// every pass: one command for a bless that kept them as another host's.
pub fn move_timings_command(scenes: &[&str]) -> String {
    let scenes: String = scenes
        .iter()
        .map(|scene| format!(" {}", scene_flag(scene)))
        .collect();
    format!(
        "{}{} bless{scenes} {MOVE_TIMINGS_HERE}",
        workspace(),
        harness()
    )
}

/// `harness ARGS` as [`bless_command`] names the harness and the workspace: the command to
/// paste here.
pub fn harness_command(args: &str) -> String {
    format!("{}{} {args}", workspace(), harness())
}

/// The flags of a timing bless that moves another host's timing goldens to this one.
const MOVE_TIMINGS_HERE: &str = "--speed-only --every-pass";

/// What to add where `commands` ([`crate::golden::check::CheckRun::bless_commands`]) are
/// printed under "each rewrites only what moved": a `--speed-only --every-pass` command among
/// them rewrites more, so it is said what (empty when there is none).
pub fn moves_timings_note(commands: &[String]) -> &'static str {
    if commands.iter().any(|c| c.ends_with(MOVE_TIMINGS_HERE)) {
        " A command with `--speed-only --every-pass` is for timings this host did not bless: it \
         moves the backend's timing goldens to this host, every pass; then measure this host's \
         timing noise (`harness noise --timing --write`). The hosts recorded in \
         golden/evidence/ were recorded against the goldens it replaces: there a pass whose \
         golden moved is read at the limits for any host until that host is recorded again."
    } else {
        ""
    }
}

/// The command that accepts what the last check rendered and verified, without rendering
/// again (`bless --from-last-check`), naming the check's `--out` folder when it was not the
/// default (`None`), and the workspace as [`bless_command`] does.
pub fn accept_command(out: Option<&std::path::Path>) -> String {
    let out = out.map_or(String::new(), |dir| {
        format!(" --out {}", shell_quote(&dir.to_string_lossy()))
    });
    format!("{}{} bless --from-last-check{out}", workspace(), harness())
}

/// The harness as this process was started: `cargo run -p harness --` under cargo (which sets
/// `CARGO_PKG_NAME` for what it runs: `cargo run`, `cargo test` and their children; with
/// `--release` where this executable was built without debug assertions), else the executable
/// as it was invoked, made absolute when it was named by a path (`harness` found on the PATH
/// stays as it is). A suggestion that named cargo to someone running a release binary would
/// start a second, dev-profile build.
fn harness() -> String {
    if std::env::var("CARGO_PKG_NAME").is_ok_and(|name| name == "harness") {
        return if cfg!(debug_assertions) {
            "cargo run -p harness --".to_owned()
        } else {
            "cargo run --release -p harness --".to_owned()
        };
    }
    let Some(argv0) = std::env::args_os().next() else {
        return "harness".to_owned();
    };
    let path = std::path::Path::new(&argv0);
    let path = if path.components().count() > 1 {
        std::path::absolute(path).unwrap_or_else(|_| path.to_owned())
    } else {
        path.to_owned()
    };
    shell_quote(&path.to_string_lossy())
}

/// `HARNESS_ROOT=<root> ` when the workspace is named by `HARNESS_ROOT`, else nothing.
fn workspace() -> String {
    std::env::var_os("HARNESS_ROOT")
        .filter(|r| !r.is_empty())
        .map(|r| format!("HARNESS_ROOT={} ", shell_quote(&r.to_string_lossy())))
        .unwrap_or_default()
}

/// `--scene SCENE` for a printed command, quoted for a POSIX shell; `--scene=SCENE` where the
/// scene begins with `-` (a file `-x.toml` in scenes/), which would otherwise read as a flag.
pub fn scene_flag(scene: &str) -> String {
    if scene.starts_with('-') {
        format!("--scene={}", shell_quote(scene))
    } else {
        format!("--scene {}", shell_quote(scene))
    }
}

/// `word` as one word of a POSIX shell: as it is when it needs no quoting, else single-quoted.
fn shell_quote(word: &str) -> String {
    let plain = !word.is_empty()
        && word
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || "_-./".contains(c));
    if plain {
        word.to_owned()
    } else {
        format!("'{}'", word.replace('\'', "'\\''"))
    }
}
