//! `check` split into shards (`--scene` per job, each with its own `--out`) and joined by
//! `report --merge`: one run equal to the unsharded check; and a job's `out` folder accepted
//! from in another checkout, as a CI artifact is.

use crate::common;

/// Shards: `check --scene` on three "jobs" (arrow after a light change, corner, ibl), each with
/// its own `--out`, joined by `report --merge` into one run that equals the unsharded check of
/// the three scenes (its results, verdicts, verification of arrow's new outputs and
/// cross-backend comparisons, its JUnit file and its summary, with the GPU times and the output
/// folders' names aside); one page; a
/// last-check.json whose failure images resolve into the shards (accepting from it works); a
/// scene checked in two shards, or a shard given twice, is refused.
#[test]
fn sharded_checks_merge_into_one_report() {
    if !common::gl_available() {
        return;
    }
    let root = common::temp_workspace();
    let scene = root.path().join("scenes/arrow.toml");
    let text = std::fs::read_to_string(&scene).unwrap();
    std::fs::write(&scene, text.replace("intensity = 2.5", "intensity = 3.0")).unwrap();
    let run = |args: &[&str]| {
        let output = common::harness_command()
            .args(args)
            .env("HARNESS_ROOT", root.path())
            .output()
            .unwrap();
        let text = format!(
            "{}{}",
            String::from_utf8_lossy(&output.stdout),
            String::from_utf8_lossy(&output.stderr)
        );
        (output.status.code(), text)
    };
    // A shard's check; `verify` as a job would (the default), or not (`--no-verify`).
    let shard_with = |scene: &str, name: &str, verify: bool| {
        let out = root.path().join(name);
        let args = [
            "check",
            "--no-speed",
            "--backend",
            "gl",
            "--scene",
            scene,
            "--out",
        ];
        let no_verify: &[&str] = if verify { &[] } else { &["--no-verify"] };
        let (code, text) = run(&[&args[..], &[out.to_str().unwrap()], no_verify].concat());
        (code, text, out)
    };
    let shard = |scene: &str, name: &str| shard_with(scene, name, true);
    let (code, _, arrow) = shard("arrow", "shard-arrow");
    assert_eq!(code, Some(1));
    let (code, _, corner) = shard("corner", "shard-corner");
    assert_eq!(code, Some(0));
    let (code, _, ibl) = shard("ibl", "shard-ibl");
    assert_eq!(code, Some(0));
    let merged = root.path().join("merged");
    let junit = merged.join("junit.xml");
    let (code, text) = run(&[
        "report",
        "--merge",
        arrow.to_str().unwrap(),
        corner.to_str().unwrap(),
        ibl.to_str().unwrap(),
        "--out",
        merged.to_str().unwrap(),
        "--junit",
        junit.to_str().unwrap(),
        "--summary",
        merged.join("summary.md").to_str().unwrap(),
    ]);
    assert_eq!(code, Some(1), "{text}");
    // The failure images are copied beside the joined page, which then stands alone.
    let failures = format!("failure images: {}", merged.join("failures").display());
    assert!(text.lines().any(|l| l == failures), "{text}");
    let whole = root.path().join("unsharded");
    let (code, whole_text) = run(&[
        "check",
        "--no-speed",
        "--backend",
        "gl",
        "--scene",
        "arrow",
        "--scene",
        "corner",
        "--scene",
        "ibl",
        "--out",
        whole.to_str().unwrap(),
        "--junit",
        whole.join("junit.xml").to_str().unwrap(),
        "--summary",
        whole.join("summary.md").to_str().unwrap(),
    ]);
    assert_eq!(code, Some(1), "{whole_text}");
    // The verified section says how to accept from this check's folder (not the default one).
    let accept = format!("bless --from-last-check --out {}", whole.display());
    assert!(whole_text.contains(&accept), "{whole_text}");
    let shards = [&arrow, &corner, &ibl];
    let comparable = |dir: &std::path::Path, file: &str| {
        let mut text = std::fs::read_to_string(dir.join(file)).unwrap();
        if file == "last-check.json" {
            let mut run: serde_json::Value = serde_json::from_str(&text).unwrap();
            run.as_object_mut().unwrap().remove("timings");
            text = serde_json::to_string_pretty(&run).unwrap();
        }
        for out in shards.iter().copied().chain([&whole, &merged]) {
            text = text.replace(out.to_str().unwrap(), "OUT");
        }
        without_attributes(&text, &["time", "timestamp"])
    };
    for file in ["last-check.json", "junit.xml", "summary.md"] {
        assert_eq!(
            comparable(&merged, file),
            comparable(&whole, file),
            "the merged {file} differs from the unsharded one"
        );
    }
    let joined: harness::golden::check::CheckRun =
        serde_json::from_slice(&std::fs::read(merged.join("last-check.json")).unwrap()).unwrap();
    let verified: Vec<&str> = joined
        .verifications
        .iter()
        .map(|v| v.scene.as_str())
        .collect();
    assert_eq!(verified, ["arrow"]);
    let report =
        quick_junit::Report::deserialize_from_str(&std::fs::read_to_string(&junit).unwrap())
            .unwrap();
    let suites: Vec<&str> = report.test_suites.iter().map(|s| s.name.as_str()).collect();
    assert_eq!(suites, ["arrow", "corner", "ibl"]);
    let lines = text.lines().filter(|l| {
        ["arrow ", "corner ", "ibl "]
            .iter()
            .any(|s| l.starts_with(s))
    });
    assert_eq!(report.tests, lines.count(), "{text}");
    assert_eq!(report.failures, 2, "{text}");
    let page = std::fs::read_to_string(merged.join("report.html")).unwrap();
    assert!(page.contains("data-scene=\"corner\"") && page.contains("id=\"case-arrow-light\""));
    // Its links are to the copies beside it, which travel with the folder.
    assert!(!page.contains("file://"));
    assert!(page.contains("href=\"failures/arrow/gl/light_actual.exr\""));
    assert!(merged.join("failures/arrow/gl/light_actual.exr").is_file());
    let (code, text) = run(&[
        "bless",
        "--from-last-check",
        "--unverified",
        "--scene",
        "arrow",
        "--pass",
        "light",
        "--out",
        merged.to_str().unwrap(),
    ]);
    assert_eq!(code, Some(0), "{text}");
    assert!(
        text.contains("arrow/light: CHANGED vs old golden"),
        "{text}"
    );

    // Only there to overlap: not verified.
    let (_, _, again) = shard_with("arrow", "shard-arrow-again", false);
    refuses_overlapping_shards(&run, &arrow, &again);
}

/// The harness run in the test's workspace: its exit code and its output.
type Run<'a> = &'a dyn Fn(&[&str]) -> (Option<i32>, String);

/// A scene checked in two shards, a shard given twice, and a joined run written into one of
/// its shards (over that shard's own run) are refused.
fn refuses_overlapping_shards(run: Run, arrow: &std::path::Path, again: &std::path::Path) {
    let twice = [arrow.to_str().unwrap(), again.to_str().unwrap()];
    let (code, text) = run(&[&["report", "--merge"][..], &twice].concat());
    assert_eq!(code, Some(1), "{text}");
    assert!(text.contains("in two shards"), "{text}");
    let (code, text) = run(&["report", "--merge", twice[0], twice[0]]);
    assert_eq!(code, Some(1), "{text}");
    assert!(text.contains("given twice"), "{text}");
    let before = std::fs::read(arrow.join("last-check.json")).unwrap();
    let (code, text) = run(&["report", "--merge", twice[0], "--out", twice[0]]);
    assert_eq!(code, Some(2), "{text}");
    assert!(text.contains("is one of the shards"), "{text}");
    assert_eq!(
        std::fs::read(arrow.join("last-check.json")).unwrap(),
        before
    );
}

/// `xml` without the attributes named (` name="..."`): JUnit's times, which no two runs share.
fn without_attributes(xml: &str, names: &[&str]) -> String {
    let mut out = xml.to_owned();
    for name in names {
        let marker = format!(" {name}=\"");
        while let Some(start) = out.find(&marker) {
            let value = start + marker.len();
            let end = value + out[value..].find('"').unwrap() + 1;
            out.replace_range(start..end, "");
        }
    }
    out
}

/// A CI job's `out` folder, downloaded: its last-check.json names the job's paths, which do not
/// exist here. Accepting from it in another checkout reads the kept outputs from the download
/// and writes (and guards) that checkout's goldens, not the paths the job recorded.
#[test]
fn a_downloaded_check_is_accepted_in_another_checkout() {
    if !common::gl_available() {
        return;
    }
    let (job, mine) = (common::temp_workspace(), common::temp_workspace());
    common::brighten_corner(job.path());
    common::brighten_corner(mine.path());
    let job_out = job.path().join("out");
    let checked = common::harness_command()
        .args([
            "check",
            "--scene",
            "corner",
            "--backend",
            "gl",
            "--no-speed",
        ])
        .arg("--out")
        .arg(&job_out)
        .env("HARNESS_ROOT", job.path())
        .output()
        .unwrap();
    assert_eq!(checked.status.code(), Some(1));
    // Downloaded: the job's folder is gone, its copy is here.
    let download = mine.path().join("artifact");
    std::fs::rename(&job_out, &download).unwrap();
    let recorded = std::fs::read_to_string(download.join("last-check.json")).unwrap();
    assert!(recorded.contains(&job_out.display().to_string()));
    let job_goldens = super::cli_bless::snapshot(&job.path().join("golden"));
    let accept = || {
        common::harness_command()
            .args([
                "bless",
                "--from-last-check",
                "--no-speed",
                "--backend",
                "gl",
            ])
            .arg("--out")
            .arg(&download)
            .env("HARNESS_ROOT", mine.path())
            .output()
            .unwrap()
    };
    let accepted = accept();
    let stdout = String::from_utf8_lossy(&accepted.stdout);
    let stderr = String::from_utf8_lossy(&accepted.stderr);
    assert!(accepted.status.success(), "{stdout}{stderr}");
    let written = format!("wrote {}", mine.path().join("golden/corner").display());
    assert!(stdout.contains(&written), "{stdout}");
    let after = super::cli_bless::snapshot(&job.path().join("golden"));
    let changed = super::cli_bless::changed_files(job.path(), &job_goldens, &after);
    assert!(changed.is_empty(), "{changed:?}");
    // Accepted again: this checkout's goldens are the ones rewritten since the check.
    let again = accept();
    let stdout = String::from_utf8_lossy(&again.stdout);
    assert!(stdout.contains("already accepted"), "{stdout}");
}

/// Shards that checked different commits are not one run: joining them is refused, naming both;
/// shards of one commit (or that name none, outside a git tree) join, keeping it.
#[test]
fn shards_of_different_commits_are_not_joined() {
    use harness::golden::check::CheckRun;
    use harness::golden::merge::{merge, MergeError};
    let dir = tempfile::tempdir().unwrap();
    let shard = |name: &str, commit: Option<&str>| {
        let path = dir.path().join(name);
        std::fs::create_dir_all(&path).unwrap();
        let run = CheckRun {
            commit: commit.map(str::to_owned),
            ..CheckRun::default()
        };
        std::fs::write(
            path.join("last-check.json"),
            serde_json::to_vec(&run).unwrap(),
        )
        .unwrap();
        path
    };
    let (a, b) = (shard("a", Some("1111")), shard("b", Some("2222")));
    let (same, none) = (shard("same", Some("1111")), shard("none", None));
    let out = dir.path().join("joined");
    let error = merge(&[a.clone(), none.clone(), b], &out).err().unwrap();
    assert!(
        matches!(error, MergeError::Commits { .. })
            && error.to_string().contains("checked commit 1111")
            && error.to_string().contains("checked 2222"),
        "{error}"
    );
    let (joined, _) = merge(&[a, none, same], &out).unwrap();
    assert_eq!(joined.commit.as_deref(), Some("1111"));
}
