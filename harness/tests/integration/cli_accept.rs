//! `harness bless --from-last-check`: accepting what `check` rendered and kept, and the
//! verification every new golden goes through first.

use super::cli_bless::{changed_files, snapshot};
use crate::common;

/// `bless --from-last-check` accepts what `check` rendered without rendering again: after a
/// light change, accepting arrow's light pass (`--unverified`, with no driver to be found, so a
/// render would fail) writes that golden and its record (the check's backend and driver, the
/// metrics against the old golden, unverified) and nothing else; the next check passes it and
/// still fails the final image, until it is accepted too. (Accepting on the check's own
/// verification, rendering nothing, is in the review page's test.) A kept output whose scene
/// file changed after the check is refused, verified or not, naming the file; one whose noise
/// model changed is verified again, although the check verified it; a golden rewritten after
/// the check is refused too.
#[test]
fn bless_from_the_last_check_accepts_its_outputs_without_rendering() {
    if !common::gl_available() {
        return;
    }
    let root = common::temp_workspace();
    let scene = root.path().join("scenes/arrow.toml");
    let text = std::fs::read_to_string(&scene).unwrap();
    let with_intensity = |value: &str| {
        std::fs::write(
            &scene,
            text.replace("intensity = 2.5", &format!("intensity = {value}")),
        )
        .unwrap();
    };
    with_intensity("3.0");
    let out = root.path().join("out");
    let check = |verify: bool| {
        let output = common::harness_command()
            .args([
                "check",
                "--scene",
                "arrow",
                "--backend",
                "gl",
                "--no-speed",
                "--json",
            ])
            .args(["--out", out.to_str().unwrap()])
            .args((!verify).then_some("--no-verify"))
            .env("HARNESS_ROOT", root.path())
            .output()
            .unwrap();
        let failing = common::cli::failing_passes(&output.stdout);
        (output.status.code(), failing)
    };
    let accept = |pass: &str, drivers: bool, verify: bool| {
        let mut command = common::harness_command();
        command
            .args([
                "bless",
                "--from-last-check",
                "--scene",
                "arrow",
                "--pass",
                pass,
                "--reason",
                "arrow's light moved on purpose",
            ])
            .args(["--out", out.to_str().unwrap()])
            .env("HARNESS_ROOT", root.path());
        if !verify {
            command.arg("--unverified");
        }
        if !drivers {
            command
                .env("LIBGL_DRIVERS_PATH", "/nonexistent")
                .env("VK_DRIVER_FILES", "/nonexistent/icd.json")
                .env("VK_ICD_FILENAMES", "/nonexistent/icd.json");
        }
        let output = command.output().unwrap();
        let stdout = String::from_utf8_lossy(&output.stdout).into_owned();
        let stderr = String::from_utf8_lossy(&output.stderr).into_owned();
        (output.status.code(), stdout + &stderr)
    };
    let light_final = vec!["light".to_owned(), "final".to_owned()];
    assert_eq!(check(false), (Some(1), light_final));
    let golden = root.path().join("golden");
    let before = snapshot(&golden);
    refuses_what_the_check_did_not_check(root.path(), &out);
    assert_eq!(snapshot(&golden), before);
    std::thread::sleep(std::time::Duration::from_millis(20));
    let (code, stdout) = accept("light", false, false);
    assert_eq!(code, Some(0), "{stdout}");
    assert!(
        stdout.contains("arrow/light: CHANGED vs old golden") && stdout.contains("wrote "),
        "{stdout}"
    );
    let after = snapshot(&golden);
    assert_eq!(
        changed_files(&golden, &before, &after),
        ["arrow/blessed.toml", "arrow/light.exr"]
    );
    // The golden holds exactly the pixels the check kept (the files' compression may differ).
    let kept = harness::images::read_exr(&out.join("failures/arrow/gl/light_actual.exr")).unwrap();
    let blessed = harness::images::read_exr(&golden.join("arrow/light.exr")).unwrap();
    assert!(
        kept.data == blessed.data && (kept.width, kept.height) == (blessed.width, blessed.height),
        "the blessed light buffer is not the one the check kept"
    );
    let records = || {
        harness::golden::GoldenStore::new(&golden)
            .records("arrow")
            .unwrap()
    };
    let light = &records()["light"];
    assert_eq!(light.backend, engine::backend::BackendKind::Gl);
    assert_eq!(
        light.reason.as_deref(),
        Some("arrow's light moved on purpose")
    );
    assert!(light.driver.contains("llvmpipe"), "{}", light.driver);
    assert!(
        light
            .previous
            .starts_with("CHANGED vs old golden: fraction_over"),
        "{}",
        light.previous
    );
    assert!(light.unverified);

    assert_eq!(check(false), (Some(1), vec!["final".to_owned()]));
    let (code, stdout) = accept("final", true, false);
    assert_eq!(code, Some(0), "{stdout}");
    assert_eq!(check(false), (Some(0), vec![]));

    after_the_check(&golden, check, accept, with_intensity);
}

/// What changed after a check (of arrow at 3.5, its outputs verified) decides the accept: the
/// scene file, refused; the noise model, verified again; a golden, refused.
fn after_the_check(
    golden: &std::path::Path,
    check: impl Fn(bool) -> (Option<i32>, Vec<String>),
    accept: impl Fn(&str, bool, bool) -> (Option<i32>, String),
    with_intensity: impl Fn(&str),
) {
    let light_final = vec!["light".to_owned(), "final".to_owned()];
    // Checked (and verified) at 3.5, accepted after the scene went back to 3.0: the kept
    // outputs are of the scene as it was, so the accept is refused, verified or not, naming the
    // file that changed and the check to run, and nothing is written.
    with_intensity("3.5");
    assert_eq!(check(true), (Some(1), light_final));
    with_intensity("3.0");
    let before = snapshot(golden);
    for verify in [true, false] {
        let (code, stdout) = accept("light", true, verify);
        assert_eq!(code, Some(1), "{stdout}");
        assert!(
            stdout.contains("arrow changed since the check (")
                && stdout.contains("scenes/arrow.toml)")
                && stdout.contains(" check --scene arrow --out ")
                && stdout.contains("`), then accept"),
            "{stdout}"
        );
        assert_eq!(snapshot(golden), before);
    }
    // The scene as checked again, but the noise model edited since: the check's verification
    // is of other inputs, so the accept verifies again (the outputs reproduce) and writes.
    with_intensity("3.5");
    let noise = golden.join("noise.toml");
    let model = std::fs::read_to_string(&noise).unwrap();
    std::fs::write(&noise, format!("{model}\n# edited after the check\n")).unwrap();
    let (code, stdout) = accept("light", true, true);
    assert_eq!(code, Some(0), "{stdout}");
    assert!(
        stdout.contains("verifying arrow's new goldens under cpu-avx") && stdout.contains("wrote "),
        "{stdout}"
    );
    assert_ne!(snapshot(golden), before);

    // The final golden only touched after that check (a checkout newer than the check, as on
    // another machine): not a change. Rewritten: accepting the check's final is refused.
    let final_png = golden.join("arrow/final.png");
    let future = std::time::SystemTime::now() + std::time::Duration::from_secs(60);
    let touch = || {
        std::fs::File::options()
            .write(true)
            .open(&final_png)
            .unwrap()
            .set_modified(future)
            .unwrap();
    };
    touch();
    let (code, stdout) = accept("final", true, false);
    assert!(
        code == Some(0) && stdout.contains("arrow/final: CHANGED vs old golden"),
        "{stdout}"
    );
    common::cli::darken(&final_png, 1);
    touch();
    let (code, stdout) = accept("final", true, false);
    assert_eq!(code, Some(1), "{stdout}");
    assert!(
        stdout.contains("REFUSED arrow/final (gl)")
            && stdout.contains("changed after the last check"),
        "{stdout}"
    );
}

/// A typo, or what the last check (arrow on gl, under `out`) did not check, is an error naming
/// it, not "nothing to accept".
fn refuses_what_the_check_did_not_check(root: &std::path::Path, out: &std::path::Path) {
    for (flag, value, why) in [
        (
            "--pass",
            "finall",
            "did not check a pass named finall (it checked ",
        ),
        (
            "--backend",
            "wgpu-gl",
            "did not check backend wgpu-gl (it checked gl)",
        ),
        (
            "--scene",
            "chess",
            "did not check scene chess (it checked arrow)",
        ),
    ] {
        let output = common::harness_command()
            .args(["bless", "--from-last-check", flag, value, "--out"])
            .arg(out)
            .env("HARNESS_ROOT", root)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(1), "{flag} {value}: {stderr}");
        assert!(stderr.contains(why), "{flag} {value}: {stderr}");
    }
}

/// The timing goldens are accepted from the last check too, on the host that blessed them
/// (this one is made so, with its own ratios; another host's accept is refused, see
/// `units::golden_accept`): arrow's geometry and lighting goldens on gl at a third of this
/// host's make the check fail those passes' speed checks (SLOWER); `bless
/// --from-last-check --speed-only --pass lighting_pbr` records the ratio the check measured,
/// without probing again, and so does the review page's Accept on the geometry pass's speed row
/// (clicked in Chromium, or posted as the page would without it; rendering forbidden); the next
/// check passes both.
#[test]
fn a_slower_pass_is_accepted_from_the_last_check_as_its_timing_golden() {
    if !common::gl_available() {
        return;
    }
    let root = common::temp_workspace();
    // This host's ratios, blessed here: geometry and lighting a third (a check finds them
    // three times slower), every other pass twice (within its limit or faster, a note).
    use engine::plan::PassId;
    let lighting: PassId = "lighting_pbr".parse().unwrap();
    let slowed = [(PassId::Geometry, 1.0 / 3.0), (lighting, 1.0 / 3.0)];
    common::bless_timings_here(
        root.path(),
        "arrow",
        engine::backend::BackendKind::Gl,
        &slowed,
        2.0,
    );
    let out = root.path().join("out");
    let check = || {
        let output = common::harness_command()
            .args([
                "check",
                "--scene",
                "arrow",
                "--backend",
                "gl",
                "--json",
                "--summary",
            ])
            .arg(out.with_extension("md"))
            .arg("--out")
            .arg(&out)
            .env("HARNESS_ROOT", root.path())
            .output()
            .unwrap();
        let run: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
        let slower: Vec<String> = run["speed"]["checks"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|c| c["outcome"]["verdict"] == "slower")
            .map(|c| c["pass"].as_str().unwrap().to_owned())
            .collect();
        (output.status.code(), slower)
    };
    let slower = vec!["geometry".to_owned(), "lighting_pbr".to_owned()];
    assert_eq!(check(), (Some(1), slower));
    // The summary and the page say what the speed checks can catch on this host, whichever
    // tier it is.
    let summary = std::fs::read_to_string(out.with_extension("md")).unwrap();
    let coverage = summary
        .split("### What the speed checks catch on this host")
        .nth(1)
        .expect("a coverage section");
    assert!(
        coverage.contains("- `gl`: ") && coverage.contains(" timed "),
        "{summary}"
    );
    let page = std::fs::read_to_string(out.join("report.html")).unwrap();
    assert!(page.contains("<p>What the speed checks catch on this host:</p><ul><li>gl: "));
    assert!(page.contains(
        "<tr class=\"failed\" data-speed=\"1\" data-scene=\"arrow\" data-pass=\"geometry\" \
         data-backend=\"gl\">"
    ));
    let output = common::harness_command()
        .args([
            "bless",
            "--from-last-check",
            "--speed-only",
            "--scene",
            "arrow",
            "--pass",
            "lighting_pbr",
            "--reason",
            "the lighting got slower on purpose",
            "--out",
        ])
        .arg(&out)
        .env("HARNESS_ROOT", root.path())
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(output.status.success(), "{stdout}");
    assert!(
        stdout.contains("arrow/lighting_pbr on gl (speed): ratio ")
            && stdout.contains("written")
            && !stdout.contains("geometry"),
        "{stdout}"
    );
    // The reason is recorded beside the ratio written, and only there.
    let reason_of = |pass: &str| {
        let goldens =
            harness::golden::speed::TimingGoldens::load(&root.path().join("golden"), "arrow");
        goldens.unwrap().backends[&engine::backend::BackendKind::Gl].passes
            [&pass.parse::<engine::plan::PassId>().unwrap()]
            .reason
            .clone()
    };
    assert_eq!(
        reason_of("lighting_pbr").as_deref(),
        Some("the lighting got slower on purpose")
    );
    assert_eq!(reason_of("geometry"), None);
    // What the pass writes is recorded beside the ratio accepted, from the check's probe.
    let goldens =
        harness::golden::speed::TimingGoldens::load(&root.path().join("golden"), "arrow").unwrap();
    assert_eq!(
        goldens.backends[&engine::backend::BackendKind::Gl].passes
            [&engine::plan::PassId::Lighting(engine::scene::LightingModel::Pbr)]
            .targets
            .as_deref(),
        Some("route 512x512 depth32f, light 512x512 rgba16f")
    );
    let server = crate::review::Server::start(root.path(), &out);
    let why = "the G-buffer got slower on purpose";
    if let Some(executable) = crate::report::chromium() {
        // The speed row's own Accept button, clicked in a browser, with a reason typed.
        let mut browser = crate::report::Browser::launch(executable);
        browser.open(&server.url);
        browser.eval(&format!(
            "document.querySelector('.accept-bar input.accept-reason').value = {}",
            serde_json::json!(why)
        ));
        let row = "tr[data-speed='1'][data-scene=arrow][data-pass=geometry][data-backend=gl]";
        browser.click_on(&format!("{row} button.accept"));
        let marked = browser.eval(&crate::review::wait_for(
            &format!("document.querySelector(\"{row}\")"),
            "r.classList.contains('accepted')",
            "r.querySelector('td.result').textContent",
        ));
        assert_eq!(marked, serde_json::json!("ACCEPTED"));
        // What was written is said on the page, as the command line says it.
        let notes = browser.eval("document.querySelector('ul.accept-notes').textContent");
        let notes = notes.as_str().unwrap_or_default();
        assert!(
            notes.contains("arrow/geometry on gl (speed): ratio ") && notes.contains("; written"),
            "{notes}"
        );
    } else {
        let answer = server.accept(&serde_json::json!({
            "scene": "arrow", "pass": "geometry", "backend": "gl", "speed": true, "reason": why
        }));
        assert_eq!(
            (&answer["accepted"], &answer["refused"]),
            (
                &serde_json::json!([["arrow", "speed geometry", "gl"]]),
                &serde_json::json!([])
            )
        );
        let notes = answer["notes"].to_string();
        assert!(
            notes.contains("arrow/geometry on gl (speed): ratio ") && notes.contains("; written"),
            "{notes}"
        );
    }
    drop(server);
    assert_eq!(reason_of("geometry").as_deref(), Some(why));
    assert_eq!(check(), (Some(0), vec![]));
}

/// `bless --speed-only` where another host blessed every backend's timing goldens, on a host
/// not recorded against them, writes nothing and says so: each backend kept with why and the
/// commands that record this host or move the goldens, and exit 1 (a script must not take it
/// for a bless). Nothing is probed.
#[test]
fn a_speed_only_bless_that_keeps_another_hosts_goldens_fails() {
    let root = common::temp_workspace();
    // No host recorded: this one may be among golden/evidence/'s (a recorded host blesses
    // its slowdowns scaled into the blessing host's terms instead).
    for entry in std::fs::read_dir(root.path().join("golden/evidence")).unwrap() {
        let recording = entry.unwrap().path().join("timing.toml");
        if recording.exists() {
            std::fs::remove_file(recording).unwrap();
        }
    }
    let timing = root.path().join("golden/arrow/timing.toml");
    let text = std::fs::read_to_string(&timing).unwrap();
    let elsewhere: String = text
        .lines()
        .map(|l| {
            if l.starts_with("host = ") {
                "host = \"a host that is not this one\"".to_owned()
            } else {
                l.to_owned()
            }
        })
        .collect::<Vec<_>>()
        .join("\n");
    std::fs::write(&timing, &elsewhere).unwrap();
    let output = common::harness_command()
        .args(["bless", "--scene", "arrow", "--speed-only", "--reason", "r"])
        .env("HARNESS_ROOT", root.path())
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&output.stdout);
    let stderr = String::from_utf8_lossy(&output.stderr);
    if common::available_backends().is_empty() {
        return;
    }
    assert_eq!(output.status.code(), Some(1), "{stdout}{stderr}");
    assert!(
        stdout.contains("(speed): kept: ")
            && stdout.contains("--record-host NAME")
            && stdout.contains("--every-pass"),
        "{stdout}"
    );
    assert!(
        stderr.contains("timing golden(s) asked for (a scene and backend, or a pass) were kept"),
        "{stderr}"
    );
    assert!(!stderr.contains("probe 1 of"), "{stderr}");
    assert_eq!(std::fs::read_to_string(&timing).unwrap(), elsewhere);
}

/// A scene's kept outputs are accepted together or not at all: with one of them gone, or one
/// that is not the size of its pass (accepted unverified, nothing else would notice), the
/// accept refuses the scene, naming the file, and writes none of its goldens.
#[test]
fn an_accept_with_a_kept_output_missing_or_misfit_writes_none_of_the_scene() {
    if !common::gl_available() {
        return;
    }
    let root = common::temp_workspace();
    common::brighten_corner(root.path());
    let out = root.path().join("out");
    let run = |args: &[&str]| {
        common::harness_command()
            .args(args)
            .arg("--out")
            .arg(&out)
            .env("HARNESS_ROOT", root.path())
            .output()
            .unwrap()
    };
    let checked = run(&[
        "check",
        "--scene",
        "corner",
        "--backend",
        "gl",
        "--no-speed",
        "--no-verify",
    ]);
    assert_eq!(checked.status.code(), Some(1));
    let kept = out.join("failures/corner/gl");
    let mut outputs: Vec<_> = std::fs::read_dir(&kept)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| {
            p.file_stem()
                .is_some_and(|s| s.to_string_lossy().ends_with("_actual"))
        })
        .collect();
    outputs.sort();
    assert!(outputs.len() >= 2, "{outputs:?}");
    let golden = root.path().join("golden/corner");
    let before = super::cli_bless::snapshot(&golden);
    let accept = || {
        run(&[
            "bless",
            "--from-last-check",
            "--no-speed",
            "--unverified",
            "--backend",
            "gl",
        ])
    };
    let tiny = engine::Image {
        width: 4,
        height: 4,
        format: engine::backend::TextureFormat::Rgba8Unorm,
        data: engine::ImageData::U8(vec![128; 64]),
    };
    let png = outputs
        .iter()
        .find(|p| p.extension().is_some_and(|x| x == "png"))
        .expect("an 8-bit output kept")
        .clone();
    let saved = std::fs::read(&png).unwrap();
    harness::images::write_image(&tiny, &png, harness::images::FileCompression::Fast).unwrap();
    let misfit = accept();
    let stdout = String::from_utf8_lossy(&misfit.stdout);
    assert_eq!(misfit.status.code(), Some(1), "{stdout}");
    assert!(
        stdout.contains("REFUSED corner: nothing of it accepted")
            && stdout.contains("is 4x4 8-bit, where the pass renders"),
        "{stdout}"
    );
    std::fs::write(&png, saved).unwrap();
    let gone = outputs.last().unwrap();
    std::fs::remove_file(gone).unwrap();
    let missing = accept();
    let stdout = String::from_utf8_lossy(&missing.stdout);
    assert_eq!(missing.status.code(), Some(1), "{stdout}");
    let name = gone.file_name().unwrap().to_string_lossy().into_owned();
    assert!(
        stdout.contains("REFUSED corner: nothing of it accepted") && stdout.contains(&name),
        "{stdout}"
    );
    let after = super::cli_bless::snapshot(&golden);
    let changed = super::cli_bless::changed_files(&golden, &before, &after);
    assert!(changed.is_empty(), "{changed:?}");
}
