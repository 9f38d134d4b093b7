//! `harness check`: a scene that does not load, failures with their images and the bless
//! command, and a note when the driver differs from the blessing one.

use crate::common;
use common::cli::darken;

/// A scene in scenes/ whose mesh does not load is one failed case: `check` reports it with its
/// error (once), checks every other scene as usual, writes the report, and exits 1.
#[test]
fn a_broken_scene_is_one_failed_case_and_the_others_are_checked() {
    if !common::gl_available() {
        return;
    }
    let root = common::temp_workspace();
    std::fs::write(
        root.path().join("scenes/broken.toml"),
        "[camera]\nposition = [0, 0, 1]\ntarget = [0, 0, 0]\n[[objects]]\nmesh = \"assets/gone.obj\"\n",
    )
    .unwrap();
    let out = root.path().join("out");
    // An earlier run's failure image of a checked scene, which this run must remove.
    let stale = out.join("failures/arrow/gl/final_diff.png");
    std::fs::create_dir_all(stale.parent().unwrap()).unwrap();
    std::fs::write(&stale, b"old").unwrap();
    let output = common::harness_command()
        .args([
            "check",
            "--no-verify",
            "--no-speed",
            "--backend",
            "gl",
            "--out",
            out.to_str().unwrap(),
        ])
        .env("HARNESS_ROOT", root.path())
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&output.stdout);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(1), "{stdout}\n{stderr}");
    let load_lines: Vec<&str> = stdout
        .lines()
        .filter(|l| l.contains("FAILED") && l.contains(" load: "))
        .collect();
    assert_eq!(load_lines.len(), 1, "{stdout}");
    assert!(
        load_lines[0].starts_with("broken") && load_lines[0].contains("gone.obj: cannot read file"),
        "{}",
        load_lines[0]
    );
    assert_eq!(
        load_lines[0].matches("os error 2").count(),
        1,
        "{}",
        load_lines[0]
    );
    for scene in ["arrow", "chess", "ibl"] {
        let rows: Vec<&str> = stdout
            .lines()
            .filter(|l| l.starts_with(scene) && l.contains(" gl "))
            .collect();
        assert!(rows.len() >= 8, "{scene} was not checked:\n{stdout}");
        assert!(
            rows.iter().all(|r| r.contains(" ok ")),
            "{scene}:\n{stdout}"
        );
    }
    assert!(stdout.contains("1 scene(s) did not load"), "{stdout}");
    // No bless fixes a scene that does not load: no bless advice.
    assert!(
        stdout.contains("nothing here for a bless to take") && !stdout.contains("after reviewing"),
        "{stdout}"
    );
    let report = std::fs::read_to_string(out.join("report.html")).unwrap();
    assert!(report.contains("scene broken did not load"));
    // The canonical scenes pass: the review page shows them as thumbnails and stays small
    // (the thumbnails are per scene and pass, so more backends add only table rows).
    assert!(
        report.len() < 5_000_000,
        "report.html is {} bytes",
        report.len()
    );
    assert!(
        !stale.exists(),
        "the earlier run's failure image is still there"
    );
    // `harness scenes` does not list it as fine.
    let output = common::harness_command()
        .arg("scenes")
        .env("HARNESS_ROOT", root.path())
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert_eq!(output.status.code(), Some(1), "{stdout}");
    assert!(
        stdout
            .lines()
            .any(|l| l.starts_with("broken") && l.contains("DOES NOT LOAD")),
        "{stdout}"
    );
}

/// What a JUnit consumer (the Jenkins/GitLab schema) needs of `xml`, read with quick-xml apart
/// from the crate that wrote it: a `testsuites` root whose `tests` and `failures` are the sums
/// of its suites', each `testsuite` named with as many `testcase`s as its `tests` says, each
/// `testcase` with a name and a class, each `failure` with a message. Returns (tests, failures).
fn junit_structure(xml: &str) -> (usize, usize) {
    use quick_xml::events::{BytesStart, Event};
    let attribute = |element: &BytesStart, name: &str| -> Option<String> {
        element.try_get_attribute(name).unwrap().map(|a| {
            a.normalized_value(quick_xml::XmlVersion::Explicit1_0)
                .unwrap()
                .into_owned()
        })
    };
    let count = |element: &BytesStart, name: &str| -> usize {
        attribute(element, name)
            .unwrap_or_else(|| panic!("no {name} on {element:?}"))
            .parse()
            .unwrap()
    };
    let mut reader = quick_xml::Reader::from_str(xml);
    let (mut root, mut suite_tests, mut cases, mut failures) = (None, 0, 0, 0);
    let (mut sum_tests, mut sum_failures) = (0, 0);
    loop {
        match reader.read_event().unwrap() {
            Event::Start(e) | Event::Empty(e) => match e.name().as_ref() {
                b"testsuites" => root = Some((count(&e, "tests"), count(&e, "failures"))),
                b"testsuite" => {
                    assert!(attribute(&e, "name").is_some_and(|n| !n.is_empty()));
                    suite_tests = count(&e, "tests");
                    sum_tests += suite_tests;
                    sum_failures += count(&e, "failures");
                    cases = 0;
                }
                b"testcase" => {
                    assert!(
                        attribute(&e, "name").is_some() && attribute(&e, "classname").is_some()
                    );
                    cases += 1;
                }
                b"failure" => {
                    assert!(attribute(&e, "message").is_some_and(|m| !m.is_empty()));
                    failures += 1;
                }
                _ => {}
            },
            Event::End(e) if e.name().as_ref() == b"testsuite" => {
                assert_eq!(cases, suite_tests, "a suite's tests attribute");
            }
            Event::Eof => break,
            _ => {}
        }
    }
    let (tests, root_failures) = root.expect("a testsuites root");
    assert_eq!((tests, root_failures), (sum_tests, sum_failures));
    assert_eq!(failures, root_failures);
    (tests, failures)
}

/// `--junit` and `--summary` of the run in `check_reports_failures_with_images_and_the_bless_command`
/// (arrow's final golden darkened, its light golden removed): the JUnit XML has what its
/// consumers read ([`junit_structure`]) and parses with quick-junit's reader into a suite for arrow, a case per pass and backend, the two failures
/// with their messages, the verdict and the images; the Markdown lists them first with the
/// bless command.
fn ci_formats_name_the_failures(out: &std::path::Path, stdout: &str) {
    use quick_junit::{NonSuccessKind, TestCaseStatus};
    let xml = std::fs::read_to_string(out.join("junit.xml")).unwrap();
    let (tests, failed) = junit_structure(&xml);
    let report = quick_junit::Report::deserialize_from_str(&xml).unwrap();
    assert_eq!((report.tests, report.failures), (tests, failed));
    let checks = stdout.lines().filter(|l| l.starts_with("arrow ")).count();
    assert_eq!(report.tests, checks, "{xml}");
    assert_eq!(report.test_suites.len(), 1);
    let suite = &report.test_suites[0];
    assert_eq!(suite.name.as_str(), "arrow");
    let case = |name: &str| {
        suite
            .test_cases
            .iter()
            .find(|c| c.name.as_str() == name)
            .unwrap_or_else(|| panic!("no test case {name}: {xml}"))
    };
    let failures: Vec<&str> = suite
        .test_cases
        .iter()
        .filter(|c| !matches!(c.status, TestCaseStatus::Success { .. }))
        .map(|c| c.name.as_str())
        .collect();
    assert_eq!(report.failures, failures.len());
    assert!(
        failures.contains(&"final::gl") && failures.contains(&"light::gl"),
        "{failures:?}"
    );
    let TestCaseStatus::NonSuccess {
        kind,
        message,
        description,
        ..
    } = &case("final::gl").status
    else {
        panic!("final::gl passed: {xml}");
    };
    assert_eq!(*kind, NonSuccessKind::Failure);
    let message = message.as_ref().unwrap().as_str();
    let description = description.as_ref().unwrap().as_str();
    assert!(
        message.contains("fraction_over") && message.contains("origin: the tonemap pass"),
        "{message}"
    );
    assert!(
        description.contains("failures/arrow/gl/final_actual.png")
            && description.contains("final_diff.png")
            && description.contains("bless --scene arrow"),
        "{description}"
    );
    assert!(matches!(
        case("depth::gl").status,
        TestCaseStatus::Success { .. }
    ));
    assert_eq!(
        case("depth::gl").classname.as_ref().map(|c| c.as_str()),
        Some("arrow")
    );

    let summary = std::fs::read_to_string(out.join("summary.md")).unwrap();
    assert!(summary.starts_with("## Render check FAILED"), "{summary}");
    let failing = summary
        .split("### Failing")
        .nth(1)
        .expect("a failing section");
    assert!(
        failing.contains("| arrow | final | gl | FAILED | **origin: the tonemap pass")
            && failing.contains("| arrow | light | gl | MISSING | **nothing to compare with**")
            && failing.contains(&format!(
                "{} bless --scene arrow",
                env!("CARGO_BIN_EXE_harness")
            )),
        "{summary}"
    );
}

/// A changed golden fails `check` with the metrics and leaves actual, golden, diff and the HTML
/// report on disk; a missing golden fails with the exact bless command.
#[test]
fn check_reports_failures_with_images_and_the_bless_command() {
    if !common::gl_available() {
        return;
    }
    let root = common::temp_workspace();
    // Darken the golden final image of `arrow` by 3/255: a change the tolerance must catch.
    darken(&root.path().join("golden/arrow/final.png"), 3);
    std::fs::remove_file(root.path().join("golden/arrow/light.exr")).unwrap();
    // The golden's record says why it was blessed (as `bless --reason` writes it): the page
    // quotes it, escaped.
    let records = root.path().join("golden/arrow/blessed.toml");
    let text = std::fs::read_to_string(&records).unwrap();
    assert!(text.contains("[passes.final]\n"), "{text}");
    let text = text.replacen(
        "[passes.final]\n",
        "[passes.final]\nreason = \"the <b>tone curve</b> moved\"\n",
        1,
    );
    std::fs::write(&records, text).unwrap();
    let out = root.path().join("out");
    let output = common::harness_command()
        .args([
            "check",
            "--no-verify",
            "--no-speed",
            "--scene",
            "arrow",
            "--out",
            out.to_str().unwrap(),
            "--junit",
            out.join("junit.xml").to_str().unwrap(),
            "--summary",
            out.join("summary.md").to_str().unwrap(),
        ])
        .env("HARNESS_ROOT", root.path())
        // Run as the executable itself, not through cargo: the commands it prints say so.
        .env_remove("CARGO_PKG_NAME")
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert_eq!(output.status.code(), Some(1), "{stdout}");
    ci_formats_name_the_failures(&out, &stdout);
    let line = |pass: &str| {
        stdout
            .lines()
            .find(|l| l.starts_with("arrow") && l.contains(pass) && l.contains(" gl "))
            .unwrap_or_default()
            .to_owned()
    };
    assert!(
        line("final").contains("FAILED") && line("final").contains("fraction_over"),
        "{stdout}"
    );
    // The failing check's value / limit, the pixels over its threshold, and the largest
    // difference with its pixel. That is 3/255 from the darkening plus whatever this host's
    // rounding moved the render (another CPU rounds other pixels), so the expected figure is
    // computed here from the written output and the darkened golden, not assumed. Pixels tied
    // in 8-bit steps may be told apart by float rounding, so the named pixel is checked to hold
    // that difference rather than to be the first of them.
    let differences = channel_differences(
        &out.join("failures/arrow/gl/final_actual.png"),
        &root.path().join("golden/arrow/final.png"),
    );
    let largest = *differences.iter().max().unwrap();
    assert!(largest >= 3, "largest difference {largest}/255");
    let final_line = line("final");
    let expected = format!("px differ, the most {:.4e}", f64::from(largest) / 255.0);
    assert!(
        final_line.contains("px over")
            && final_line.contains(&expected)
            && final_line.contains("x) FAILED"),
        "expected `{expected}`\n{stdout}"
    );
    // Then (where the golden's value there is not 0) its share of it, and the pixel.
    let (x, y) = final_line
        .split(&expected)
        .nth(1)
        .and_then(|rest| rest.split(" at (").nth(1))
        .and_then(|rest| rest.split(')').next())
        .and_then(|xy| xy.split_once(", "))
        .map(|(x, y)| (x.parse::<usize>().unwrap(), y.parse::<usize>().unwrap()))
        .unwrap();
    assert_eq!(differences[y * 512 + x], largest, "at ({x}, {y})");
    assert!(
        line("light").contains("MISSING") && line("light").contains("no golden at "),
        "{stdout}"
    );
    // One bless suggestion for the scene, not one per pass (the verdicts above it quote the
    // command in their advice).
    let suggestions: Vec<&str> = stdout
        .lines()
        .filter(|l| {
            let l = l.trim_start();
            l.starts_with("HARNESS_ROOT=") && l.contains(" bless --scene ")
        })
        .collect();
    let verdict = |pass: &str| {
        stdout
            .lines()
            .find(|l| l.starts_with(&format!("  arrow/{pass}: ")))
            .unwrap_or_default()
    };
    assert!(
        verdict("final").contains("origin: the tonemap pass, every backend")
            && verdict("light").contains("nothing to compare with"),
        "{stdout}"
    );
    // It names the workspace the check ran in: pasted without it, it would bless another.
    let in_this_workspace = format!(
        "  HARNESS_ROOT={} {} bless --scene arrow",
        root.path().display(),
        env!("CARGO_BIN_EXE_harness")
    );
    assert_eq!(suggestions, [in_this_workspace.as_str()], "{stdout}");
    assert!(line("mask").contains(" ok "), "{stdout}");
    // Under --out, not the workspace's target/.
    let failures = out.join("failures/arrow/gl");
    for file in [
        "final_actual.png",
        "final_golden.png",
        "final_diff.png",
        "light_actual.exr",
    ] {
        assert!(failures.join(file).is_file(), "{file} not written");
    }
    assert!(!root.path().join("target/harness/failures").exists());
    let report = std::fs::read_to_string(out.join("report.html")).unwrap();
    assert!(report.contains("data:image/png;base64,") && report.contains("FAILED"));
    // Only final's failing case has a golden to say it of (light's was removed).
    let records: Vec<&str> = report
        .split("<p class=\"golden-record\">")
        .skip(1)
        .filter_map(|rest| rest.split("</p>").next())
        .collect();
    let [record] = records[..] else {
        panic!("one golden record expected: {records:?}");
    };
    assert!(
        record.starts_with("The golden: blessed ")
            && record.contains(" from gl (")
            && record.ends_with(", because: <q>the &lt;b&gt;tone curve&lt;/b&gt; moved</q>"),
        "{record}"
    );
}

/// Per pixel, in row order, the largest absolute channel difference of two 8-bit images (in
/// 8-bit steps).
fn channel_differences(actual: &std::path::Path, golden: &std::path::Path) -> Vec<u8> {
    let actual = image::open(actual).unwrap().to_rgba8();
    let golden = image::open(golden).unwrap().to_rgba8();
    assert_eq!(actual.dimensions(), (512, 512));
    actual
        .pixels()
        .zip(golden.pixels())
        .map(|(a, g)| (0..4).map(|c| a[c].abs_diff(g[c])).max().unwrap())
        .collect()
}

/// When the driver differs from the one the goldens were blessed with, `check` says so, as
/// information: the run still passes.
#[test]
fn check_notes_a_driver_other_than_the_blessing_one() {
    if !common::available_backends().contains(&engine::BackendKind::Gl) {
        return;
    }
    let root = common::temp_workspace();
    let record = root.path().join("golden/arrow/blessed.toml");
    let text = std::fs::read_to_string(&record).unwrap();
    let moved: String = text
        .lines()
        .map(|l| {
            if l.starts_with("driver = ") {
                "driver = \"OpenGL 4.6 | some other GPU | Mesa 99.0\"".to_owned()
            } else {
                l.to_owned()
            }
        })
        .collect::<Vec<_>>()
        .join("\n");
    std::fs::write(&record, moved).unwrap();
    let out = root.path().join("out");
    let output = common::harness_command()
        .args([
            "check",
            "--no-verify",
            "--no-speed",
            "--scene",
            "arrow",
            "--backend",
            "gl",
            "--out",
        ])
        .arg(&out)
        .env("HARNESS_ROOT", root.path())
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(output.status.success(), "{stderr}");
    assert!(
        stderr.contains(
            "note: goldens of arrow were blessed on gl with `OpenGL 4.6 | some other GPU"
        ) && stderr.contains("are not failures"),
        "{stderr}"
    );
    let report = std::fs::read_to_string(out.join("report.html")).unwrap();
    assert!(
        report.contains("some other GPU"),
        "the report does not say it"
    );
}

/// A backend this machine lacks (the Vulkan driver hidden): not asked for, the check passes on
/// the others and says what it did not check, on stderr, in the summary and as a skipped JUnit
/// case; asked for by name (`--backend`), its absence fails the check everywhere it reports.
#[test]
fn a_backend_asked_for_and_missing_fails_the_check_and_one_not_asked_for_is_named() {
    if !common::available_backends().contains(&engine::BackendKind::Gl) {
        return;
    }
    let root = common::temp_workspace();
    let check = |named: &[&str]| {
        let out = root.path().join(format!("out{}", named.len()));
        let mut command = common::harness_command();
        command
            .args(["check", "--no-verify", "--no-speed", "--scene", "arrow"])
            .args(named.iter().flat_map(|b| ["--backend", b]))
            .arg("--out")
            .arg(&out)
            .arg("--junit")
            .arg(out.join("junit.xml"))
            .arg("--summary")
            .arg(out.join("summary.md"))
            .env("HARNESS_ROOT", root.path())
            .env("VK_ICD_FILENAMES", "/nonexistent/icd.json")
            .env("VK_DRIVER_FILES", "/nonexistent/icd.json");
        let output = command.output().unwrap();
        let text = String::from_utf8_lossy(&output.stdout).into_owned()
            + &String::from_utf8_lossy(&output.stderr);
        let read = |file: &str| std::fs::read_to_string(out.join(file)).unwrap();
        let junit = quick_junit::Report::deserialize_from_str(&read("junit.xml")).unwrap();
        let backends = junit
            .test_suites
            .iter()
            .find(|s| s.name.as_str() == "backends")
            .unwrap_or_else(|| panic!("no backends suite: {}", read("junit.xml")))
            .clone();
        let vulkan = backends
            .test_cases
            .iter()
            .find(|c| c.name.as_str() == "wgpu-vulkan")
            .unwrap()
            .status
            .clone();
        // Only what was not checked: an available backend is no case of its own.
        assert!(
            backends.test_cases.iter().all(|c| c.name.as_str() != "gl"),
            "{}",
            read("junit.xml")
        );
        (
            output.status.code(),
            text,
            read("summary.md"),
            read("report.html"),
            vulkan,
        )
    };
    use quick_junit::{NonSuccessKind, TestCaseStatus};

    let (code, text, summary, page, vulkan) = check(&[]);
    // The Vulkan loader's variables are no change of gl's driver.
    assert!(
        !text.contains("goldens of arrow were blessed on gl"),
        "{text}"
    );
    assert_eq!(code, Some(0), "{text}");
    assert!(
        text.contains("note: wgpu-vulkan unavailable, not checked"),
        "{text}"
    );
    assert!(
        summary.contains("### Not checked") && summary.contains("- `wgpu-vulkan`: "),
        "{summary}"
    );
    assert!(
        matches!(vulkan, TestCaseStatus::Skipped { .. }),
        "{vulkan:?}"
    );
    assert!(page.contains("wgpu-vulkan is unavailable here"), "the page");

    let (code, text, summary, page, vulkan) = check(&["gl", "wgpu-vulkan"]);
    assert_eq!(code, Some(1), "{text}");
    assert!(
        text.contains("error: wgpu-vulkan was asked for but is unavailable")
            && text.contains("FAILED       asked for (--backend) but unavailable")
            && text.contains("1 backend(s) asked for are unavailable"),
        "{text}"
    );
    assert!(
        summary.starts_with("## Render check FAILED")
            && summary.contains("| - | - | wgpu-vulkan | UNAVAILABLE |"),
        "{summary}"
    );
    assert!(
        matches!(
            vulkan,
            TestCaseStatus::NonSuccess {
                kind: NonSuccessKind::Failure,
                ..
            }
        ),
        "{vulkan:?}"
    );
    assert!(
        page.contains("<title>Render check: FAILED")
            && page.contains("wgpu-vulkan was asked for but is unavailable"),
        "the page"
    );

    // The only backend asked for, missing: nothing rendered, and still the reports.
    let (code, text, summary, page, vulkan) = check(&["wgpu-vulkan"]);
    assert_eq!(code, Some(1), "{text}");
    assert!(summary.contains("| UNAVAILABLE |"), "{summary}");
    assert!(
        matches!(vulkan, TestCaseStatus::NonSuccess { .. }),
        "{vulkan:?}"
    );
    assert!(
        page.contains("wgpu-vulkan was asked for but is unavailable"),
        "the page"
    );
}
