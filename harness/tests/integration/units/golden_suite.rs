//! Tests of `harness::golden::suite`.

use harness::golden::command_line::bless_command;
use harness::golden::suite::*;
use harness::golden::tolerance::{Metric, Rule};
use std::path::Path;

#[test]
fn bless_commands_quote_paths_a_shell_would_split() {
    assert_eq!(
        bless_command("chess"),
        "cargo run -p harness -- bless --scene chess"
    );
    assert_eq!(
        bless_command("my scenes/it's.toml"),
        "cargo run -p harness -- bless --scene 'my scenes/it'\\''s.toml'"
    );
    // A deliberate change of timings: elsewhere than on the blessing host, every pass (a bless
    // there keeps another host's timing goldens unless they all move).
    use harness::golden::command_line::speed_bless_command;
    assert_eq!(
        speed_bless_command("chess", true),
        "cargo run -p harness -- bless --scene chess --speed-only"
    );
    assert_eq!(
        speed_bless_command("chess", false),
        "cargo run -p harness -- bless --scene chess --speed-only --every-pass"
    );
}

#[test]
fn a_scene_outside_scenes_is_named_by_its_path() {
    let inside = harness::scenes_dir().join("arrow.toml");
    assert_eq!(scene_argument(&inside), "arrow");
    let outside = Path::new("/tmp/elsewhere/arrow.toml");
    assert_eq!(scene_argument(outside), "/tmp/elsewhere/arrow.toml");
    // A relative path stays as given (what the user typed, matched again by an accept).
    let relative = Path::new("elsewhere/arrow.toml");
    assert_eq!(scene_argument(relative), "elsewhere/arrow.toml");
}

/// arrow.toml, written into `dir` with its assets found in scenes/ and `extra` appended.
fn arrow_with(dir: &Path, extra: &str) -> std::path::PathBuf {
    let assets = harness::scenes_dir().join("assets");
    let text = std::fs::read_to_string(harness::scenes_dir().join("arrow.toml"))
        .unwrap()
        .replace("\"assets/", &format!("\"{}/", assets.display()));
    let path = dir.join("arrow_tolerances.toml");
    std::fs::write(&path, format!("{text}\n{extra}\n")).unwrap();
    path
}

/// A scene file's `[tolerances.<pass>]` replaces the noise model's rule for that pass; a FLIP
/// metric on a float pass is refused when the scene loads (FLIP compares 8-bit images, so the
/// rule could only fail later, and only when the images differ), naming the file and the pass.
#[test]
fn a_scene_files_tolerances_are_read_and_flip_is_refused_on_a_float_pass() {
    let dir = tempfile::tempdir().unwrap();
    let final_flip = arrow_with(
        dir.path(),
        "[tolerances.final]\nall = [{ metric = \"flip_mean\", max = 0.01 }]",
    );
    let case = Case::load(final_flip.to_str().unwrap()).unwrap();
    let pass = engine::plan::TargetId::Final;
    assert_eq!(case.limit_sources[&pass], LimitSource::SceneFile);
    assert!(case.rules[&pass].flip_metric().is_some());

    let light_flip = arrow_with(
        dir.path(),
        "[tolerances.light]\nall = [{ metric = \"rmse\", max = 0.01 }, \
         { metric = \"flip_percentile\", percentile = 0.99, max = 0.1 }]",
    );
    let error = Case::load(light_flip.to_str().unwrap()).err().unwrap();
    let text = error.to_string();
    assert!(
        matches!(error, SuiteError::FlipOnFloatPass { .. }),
        "{text}"
    );
    assert!(
        text.contains("arrow_tolerances.toml")
            && text.contains("[tolerances.light]")
            && text.contains("flip(p99)")
            && text.contains("float pass"),
        "{text}"
    );
}

/// A scene file's limit that no 8-bit render can reach (its values lie in 0..1) is refused when
/// the scene loads, naming the file, the pass and why; the same limit on a float pass, whose
/// values are not bounded, loads.
#[test]
fn a_limit_an_eight_bit_pass_can_never_reach_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    for (rule, says) in [
        (
            "metric = \"max_abs\", max = 1.0",
            "`max` 1 can never be exceeded",
        ),
        (
            "metric = \"rmse\", max = 2.0",
            "`max` 2 can never be exceeded",
        ),
        ("metric = \"psnr\", min = -1e9", "can never be undercut"),
        (
            "metric = \"fraction_over\", threshold = 1.0, max = 1e-4",
            "`threshold` 1 can never be exceeded",
        ),
        (
            "metric = \"relative\", percentile = 0.5, floor = 1e30, max = 0.01",
            "with `floor` 1.000e30 no relative error there goes beyond 1.000e-30",
        ),
    ] {
        let file = arrow_with(
            dir.path(),
            &format!("[tolerances.final]\nall = [{{ {rule} }}]"),
        );
        let error = Case::load(file.to_str().unwrap()).err().unwrap();
        let text = error.to_string();
        assert!(
            matches!(error, SuiteError::Tolerance { .. })
                && text.contains("arrow_tolerances.toml")
                && text.contains("final")
                && text.contains(says),
            "{rule}: {text}"
        );
    }
    let float = arrow_with(
        dir.path(),
        "[tolerances.light]\nall = [{ metric = \"max_abs\", max = 5.0 }]",
    );
    assert!(Case::load(float.to_str().unwrap()).is_ok());
}

/// A scene named as one of golden/'s own entries (`evidence`, which holds other hosts'
/// recordings) is refused when it loads: its goldens would land among them, and a prune would
/// take the recordings for a pass that is gone.
#[test]
fn a_scene_may_not_be_named_as_goldens_own_files() {
    let dir = tempfile::tempdir().unwrap();
    let arrow = arrow_with(dir.path(), "");
    let text = std::fs::read_to_string(&arrow).unwrap();
    for name in ["evidence", "noise.toml"] {
        let path = dir.path().join("named.toml");
        std::fs::write(&path, format!("name = \"{name}\"\n{text}")).unwrap();
        let error = Case::load(path.to_str().unwrap()).err().unwrap();
        let text = error.to_string();
        assert!(
            matches!(error, SuiteError::ReservedName { .. })
                && text.contains("named.toml")
                && text.contains(&format!("named `{name}`")),
            "{text}"
        );
    }
    // A file named so, without a name of its own, is named by its stem.
    let path = dir.path().join("evidence.toml");
    std::fs::write(&path, &text).unwrap();
    assert!(matches!(
        Case::load(path.to_str().unwrap()),
        Err(SuiteError::ReservedName { .. })
    ));
}

/// A scene without figures of its own borrows each pass's largest limit as a number of pixels:
/// corner's 30 pixels at 256x256 (a fraction of 4.58e-4) are 30 pixels of a 512x512 G-buffer
/// target (1.15e-4), not 120; chess's light, 147 pixels at 512x512, is the light's largest.
#[test]
fn a_borrowed_limit_keeps_its_pixel_count() {
    let dir = tempfile::tempdir().unwrap();
    let case = Case::load(arrow_with(dir.path(), "").to_str().unwrap()).unwrap();
    let limit = |pass| match &case.rules[&pass] {
        Rule::All(checks) => match &checks[0] {
            Rule::Check { limit, .. } => *limit,
            other => panic!("{other:?}"),
        },
        other => panic!("{other:?}"),
    };
    let albedo = engine::plan::TargetId::GBuffer(engine::plan::GBufferTarget::Albedo);
    assert_eq!(case.limit_sources[&albedo], LimitSource::Borrowed);
    assert_eq!(limit(albedo), 1.15e-4);
    assert_eq!(limit(engine::plan::TargetId::Light), 5.61e-4);
    // Limits not on pixels are borrowed as they are: ibl's mean FLIP, the largest.
    let flip = match &case.rules[&engine::plan::TargetId::Final] {
        Rule::All(checks) => checks.clone(),
        other => panic!("{other:?}"),
    };
    assert!(flip.contains(&Rule::Check {
        metric: Metric::FlipMean,
        limit: 0.0208
    }));
}

/// A printed command names a scene so that a shell and the argument parser read it back: quoted
/// where needed, and as `--scene=-x` where it begins with a dash (`--scene -x` reads as a flag).
#[test]
fn printed_commands_name_any_scene_so_it_reads_back() {
    use harness::golden::command_line::{bless_command, scene_flag};
    assert_eq!(scene_flag("chess"), "--scene chess");
    assert_eq!(scene_flag("-dash"), "--scene=-dash");
    assert_eq!(
        scene_flag("my scenes/a b.toml"),
        "--scene 'my scenes/a b.toml'"
    );
    assert!(bless_command("-dash").ends_with("bless --scene=-dash"));
}
