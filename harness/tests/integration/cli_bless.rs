//! `harness bless`: it rewrites only the named goldens, or only the passes a change reaches,
//! refuses without a scene, waits while another bless holds the scene, and `--prune` removes
//! the orphans `check` lists.

use crate::common;
use std::path::{Path, PathBuf};

/// Every file under `dir` (the bless lock aside): its bytes and modification time.
pub(crate) fn snapshot(
    dir: &Path,
) -> std::collections::BTreeMap<PathBuf, (Vec<u8>, std::time::SystemTime)> {
    let mut out = std::collections::BTreeMap::new();
    for entry in std::fs::read_dir(dir).unwrap() {
        let entry = entry.unwrap();
        if entry.file_type().unwrap().is_dir() {
            out.extend(snapshot(&entry.path()));
        } else if entry.file_name() == harness::golden::LOCK_FILE {
            // The bless lock (see below): a lock, not a golden.
            continue;
        } else {
            let meta = entry.metadata().unwrap();
            out.insert(
                entry.path(),
                (
                    std::fs::read(entry.path()).unwrap(),
                    meta.modified().unwrap(),
                ),
            );
        }
    }
    out
}

/// Runs `harness bless ARGS` against the workspace copy at `root`; fails the test unless it
/// succeeds. Returns its stdout.
fn bless_in(root: &Path, args: &[&str]) -> String {
    // Images only: the timing goldens' bless is tested in speed.rs.
    let output = common::harness_command()
        .arg("bless")
        .args(args)
        .arg("--no-speed")
        .env("HARNESS_ROOT", root)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&output.stdout).into_owned();
    assert!(
        output.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&output.stderr)
    );
    stdout
}

/// The files under `dir` that differ between two snapshots (new ones too), relative to `dir`.
pub(crate) fn changed_files(
    dir: &Path,
    before: &std::collections::BTreeMap<PathBuf, (Vec<u8>, std::time::SystemTime)>,
    after: &std::collections::BTreeMap<PathBuf, (Vec<u8>, std::time::SystemTime)>,
) -> Vec<String> {
    after
        .iter()
        .filter(|(path, state)| before.get(*path) != Some(*state))
        .map(|(path, _)| path.strip_prefix(dir).unwrap().display().to_string())
        .collect()
}

/// `bless --scene chess --pass final` rewrites that golden and chess's blessed.toml (with the
/// `--reason` given), and nothing else (run against a temporary copy of scenes/ and golden/
/// through HARNESS_ROOT).
#[test]
fn bless_rewrites_only_the_named_golden() {
    if !common::gl_available() {
        return;
    }
    let root = common::temp_workspace();
    let golden = root.path().join("golden");
    let before = snapshot(&golden);
    std::thread::sleep(std::time::Duration::from_millis(20));
    let stdout = bless_in(
        root.path(),
        &[
            "--scene",
            "chess",
            "--pass",
            "final",
            "--unverified",
            "--reason",
            "tone mapping's white point moved",
        ],
    );
    assert!(
        stdout.contains("chess/final: within tolerance vs old golden"),
        "{stdout}"
    );
    let after = snapshot(&golden);
    assert_eq!(
        before.keys().collect::<Vec<_>>(),
        after.keys().collect::<Vec<_>>()
    );
    assert_eq!(
        changed_files(&golden, &before, &after),
        ["chess/blessed.toml", "chess/final.png"]
    );
    let record = std::fs::read_to_string(golden.join("chess/blessed.toml")).unwrap();
    assert!(
        record.contains("[passes.final]") && record.contains("driver = "),
        "{record}"
    );
    // `--reason` is recorded beside the golden written, and only there.
    let records: toml::Value = toml::from_str(&record).unwrap();
    assert_eq!(
        records["passes"]["final"]["reason"].as_str(),
        Some("tone mapping's white point moved")
    );
    assert_eq!(record.matches("reason = ").count(), 1, "{record}");

    // A copy of a canonical scene elsewhere, under its name, is checked against its goldens but
    // never blessed over them.
    let elsewhere = root.path().join("elsewhere/arrow.toml");
    std::fs::create_dir_all(elsewhere.parent().unwrap()).unwrap();
    let text = std::fs::read_to_string(root.path().join("scenes/arrow.toml")).unwrap();
    std::fs::write(&elsewhere, text.replace("\"assets/", "\"../scenes/assets/")).unwrap();
    let before = snapshot(&golden);
    for mode in ["--every-pass", "--prune"] {
        let output = common::harness_command()
            .args(["bless", "--no-speed", mode, "--scene"])
            .arg(&elsewhere)
            .env("HARNESS_ROOT", root.path())
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(1), "{mode}: {stderr}");
        assert!(
            stderr.contains("shares its name with the canonical scene")
                && stderr.contains("golden/arrow/"),
            "{mode}: {stderr}"
        );
    }
    assert_eq!(snapshot(&golden), before);

    // Without --scene or --all, bless refuses.
    let output = common::harness_command()
        .arg("bless")
        .env("HARNESS_ROOT", root.path())
        .output()
        .unwrap();
    assert_eq!(output.status.code(), Some(1));
    // A reason with nothing to record it beside (pruning writes no golden) is refused, not
    // dropped; so is an empty one (it would read as one given).
    for (args, why) in [
        (["--prune", "--reason", "gone"], "cannot be used with"),
        (["--no-speed", "--reason", "  "], "the text is empty"),
    ] {
        let output = common::harness_command()
            .args(["bless", "--scene", "chess"])
            .args(args)
            .env("HARNESS_ROOT", root.path())
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(2), "{stderr}");
        assert!(stderr.contains(why), "{stderr}");
    }
}

/// After a change to one light's intensity, `bless --scene arrow` rewrites only the passes that
/// light reaches (light and final) and their blessed.toml entries; the G-buffer, shadow and mask
/// goldens and their records stay as they were. A scene given by path gets a bless suggestion
/// with its path, which works.
#[test]
fn bless_after_a_light_change_rewrites_only_the_changed_passes() {
    if !common::gl_available() {
        return;
    }
    let root = common::temp_workspace();
    let scene = root.path().join("scenes/arrow.toml");
    let text = std::fs::read_to_string(&scene).unwrap();
    assert!(text.contains("intensity = 2.5"));
    std::fs::write(&scene, text.replace("intensity = 2.5", "intensity = 3.0")).unwrap();
    let golden = root.path().join("golden");
    let records_before = std::fs::read_to_string(golden.join("arrow/blessed.toml")).unwrap();
    let before = snapshot(&golden);
    std::thread::sleep(std::time::Duration::from_millis(20));
    let stdout = bless_in(root.path(), &["--scene", "arrow"]);
    let after = snapshot(&golden);
    assert_eq!(
        changed_files(&golden, &before, &after),
        ["arrow/blessed.toml", "arrow/final.png", "arrow/light.exr"],
        "{stdout}"
    );
    assert!(
        stdout.contains("arrow/light: CHANGED vs old golden"),
        "{stdout}"
    );
    assert!(
        stdout.contains("arrow/mask: within tolerance vs old golden"),
        "{stdout}"
    );
    // The records of the passes kept are the same lines as before.
    let records_after = std::fs::read_to_string(golden.join("arrow/blessed.toml")).unwrap();
    // Verified (the default): rendered again on every backend and CPU code path first.
    assert!(!records_after.contains("unverified"), "{records_after}");
    let section = |text: &str, pass: &str| {
        let start = text.find(&format!("[passes.{pass}]")).unwrap();
        let rest = &text[start..];
        let end = rest[1..].find("\n[").map_or(rest.len(), |e| e + 1);
        rest[..end].to_owned()
    };
    for pass in [
        "mask",
        "depth",
        "gbuffer_albedo",
        "shadow_0",
        "shadow_term_0",
    ] {
        assert_eq!(
            section(&records_before, pass),
            section(&records_after, pass),
            "{pass}"
        );
    }
    assert_ne!(
        section(&records_before, "light"),
        section(&records_after, "light")
    );

    // A second bless finds nothing to rewrite.
    let again = snapshot(&golden);
    bless_in(root.path(), &["--scene", "arrow"]);
    assert_eq!(snapshot(&golden), again);

    // A copy of the scene given by path: check suggests blessing it by path, and that works.
    let copy = root.path().join("elsewhere/arrow.toml");
    std::fs::create_dir_all(copy.parent().unwrap()).unwrap();
    let text = std::fs::read_to_string(&scene).unwrap();
    // Relative asset paths resolve against the scene file: point them back at scenes/. The
    // copy's light differs from the blessed one, so its light and final passes fail.
    let moved = text
        .replace("\"assets/", "\"../scenes/assets/")
        .replace("intensity = 3.0", "intensity = 2.0");
    std::fs::write(&copy, moved).unwrap();
    let output = common::harness_command()
        .args([
            "check",
            "--no-verify",
            "--no-speed",
            "--backend",
            "gl",
            "--scene",
            copy.to_str().unwrap(),
            "--out",
            root.path().join("out").to_str().unwrap(),
        ])
        .env("HARNESS_ROOT", root.path())
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&output.stdout);
    let suggestion = format!(
        "  HARNESS_ROOT={} cargo run -p harness -- bless --scene {}",
        root.path().display(),
        copy.display()
    );
    assert!(stdout.lines().any(|l| l == suggestion), "{stdout}");
}

/// The plan is the frame: with `[quality.ibl] extract_sun`, the environment's sun is a shadowed
/// light of the scene as drawn, so `bless` writes its shadow map and shadow term as goldens
/// (they were missing when the suite planned the scene as loaded), and `check` checks them.
#[test]
fn an_extracted_sun_gets_its_shadow_goldens() {
    if !common::gl_available() {
        return;
    }
    let root = common::temp_workspace();
    common::ibl_with_extracted_sun(&root.path().join("scenes"), "ibl_sun");
    let stdout = bless_in(root.path(), &["--scene", "ibl_sun"]);
    let golden = root.path().join("golden/ibl_sun");
    for file in [
        "shadow_0.exr",
        "shadow_term_0.exr",
        "light.exr",
        "final.png",
    ] {
        assert!(golden.join(file).is_file(), "no {file}:\n{stdout}");
    }
    assert!(stdout.contains("ibl_sun/shadow_term_0: new"), "{stdout}");
    // It says where it recorded what it did.
    let record = "ibl_sun: recorded how each was blessed in ";
    assert!(stdout.contains(record) && stdout.contains("ibl_sun/blessed.toml"));
    let records = std::fs::read_to_string(golden.join("blessed.toml")).unwrap();
    for pass in ["shadow_0", "shadow_term_0"] {
        assert!(records.contains(&format!("[passes.{pass}]")), "{records}");
    }
    let output = common::harness_command()
        .args([
            "check",
            "--no-verify",
            "--no-speed",
            "--scene",
            "ibl_sun",
            "--backend",
            "gl",
            "--out",
        ])
        .arg(root.path().join("out"))
        .env("HARNESS_ROOT", root.path())
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(
        output.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&output.stderr)
    );
    for pass in ["shadow_0", "shadow_term_0"] {
        assert!(
            stdout
                .lines()
                .any(|l| l.starts_with("ibl_sun") && l.contains(&format!(" {pass} "))),
            "check did not check {pass}:\n{stdout}"
        );
    }
}

/// Two blesses of one scene run at once, from two backends, each rewriting every pass: both
/// succeed, one after the other, and the folder ends as the later one alone would leave it:
/// every record names one backend, and every image is byte for byte what a bless from that
/// backend alone writes (never one backend's image under the other's record).
#[test]
fn two_blesses_at_once_leave_a_consistent_golden_folder() {
    use engine::backend::BackendKind;
    let available = common::available_backends();
    let pair = [BackendKind::Gl, BackendKind::WgpuVulkan];
    if !pair.iter().all(|b| available.contains(b)) {
        return;
    }
    let bless = |root: &Path, backend: BackendKind| {
        common::harness_command()
            .args(["bless", "--scene", "arrow", "--every-pass", "--no-speed"])
            .args(["--unverified", "--backend", backend.name()])
            .env("HARNESS_ROOT", root)
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap()
    };
    let root = common::temp_workspace();
    let running: Vec<_> = pair.iter().map(|&b| bless(root.path(), b)).collect();
    for child in running {
        let output = child.wait_with_output().unwrap();
        let stderr = String::from_utf8_lossy(&output.stderr);
        eprintln!(
            "{}",
            stderr
                .lines()
                .filter(|l| l.contains("waiting"))
                .collect::<String>()
        );
        assert!(output.status.success(), "{stderr}");
    }
    let store = harness::golden::GoldenStore::new(root.path().join("golden"));
    let records = store.records("arrow").unwrap();
    let last = records.values().next().unwrap().backend;
    assert!(
        records.values().all(|r| r.backend == last),
        "blessed.toml mixes backends: {:?}",
        records
            .iter()
            .map(|(p, r)| (p, r.backend))
            .collect::<Vec<_>>()
    );
    // The later bless alone, in a second workspace.
    let alone = common::temp_workspace();
    assert!(bless(alone.path(), last).wait().unwrap().success());
    let files = |root: &Path| {
        let dir = root.join("golden/arrow");
        snapshot(&dir)
            .into_iter()
            .filter(|(path, _)| path.file_name().unwrap() != "blessed.toml")
            .map(|(path, (bytes, _))| (path.strip_prefix(&dir).unwrap().to_owned(), bytes))
            .collect::<std::collections::BTreeMap<_, _>>()
    };
    let (together, by_itself) = (files(root.path()), files(alone.path()));
    assert_eq!(together.len(), by_itself.len());
    for (name, bytes) in &together {
        assert!(
            *bytes == by_itself[name],
            "{} is not what a bless from {last} writes",
            name.display()
        );
    }
}

/// A bless waits while another holds the scene's folder (here, this test holds its lock), says
/// so, and writes once the other is done: two blesses of one scene never interleave.
#[test]
fn a_bless_waits_for_another_bless_of_the_same_scene() {
    if !common::gl_available() {
        return;
    }
    let root = common::temp_workspace();
    let store = harness::golden::GoldenStore::new(root.path().join("golden"));
    let lock = store
        .lock_scene("chess", |_| panic!("nobody else holds it"))
        .unwrap();
    let before = std::fs::read(root.path().join("golden/chess/blessed.toml")).unwrap();
    let mut child = common::harness_command()
        .args([
            "bless",
            "--scene",
            "chess",
            "--pass",
            "final",
            "--no-speed",
            "--unverified",
        ])
        .env("HARNESS_ROOT", root.path())
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    // Its stderr, line by line, until it says it waits (however long loading takes here).
    let stderr = child.stderr.take().unwrap();
    let (lines, received) = std::sync::mpsc::channel();
    let reader = std::thread::spawn(move || {
        use std::io::BufRead;
        for line in std::io::BufReader::new(stderr)
            .lines()
            .map_while(Result::ok)
        {
            let _ = lines.send(line);
        }
    });
    let mut seen = Vec::new();
    while !seen
        .iter()
        .any(|l: &String| l.contains("waiting for another `harness bless` of chess to finish"))
    {
        match received.recv_timeout(std::time::Duration::from_secs(120)) {
            Ok(line) => seen.push(line),
            Err(e) => panic!("no waiting message ({e}): {seen:?}"),
        }
    }
    // Waiting, it has written nothing; a moment later still nothing.
    std::thread::sleep(std::time::Duration::from_millis(300));
    assert_eq!(
        std::fs::read(root.path().join("golden/chess/blessed.toml")).unwrap(),
        before,
        "the bless wrote while another held the scene"
    );
    drop(lock);
    let status = child.wait().unwrap();
    reader.join().unwrap();
    seen.extend(received.try_iter());
    assert!(status.success(), "{seen:?}");
    let records = store.records("chess").unwrap();
    assert_eq!(records["final"].backend, engine::backend::BackendKind::Gl);
    assert_ne!(
        std::fs::read(root.path().join("golden/chess/blessed.toml")).unwrap(),
        before
    );
}

/// Orphans: `check` lists what in a checked scene's folder nothing produces or records (a
/// golden of a pass gone, a leftover temporary, a golden blessed.toml does not record), as notes
/// that do not fail it; `bless --prune --dry-run` lists every orphan in golden/ (also a gone
/// scene's folder and a record without its golden) and removes nothing; `bless --prune` removes
/// them and nothing else.
#[test]
fn orphans_are_listed_by_check_and_removed_by_prune() {
    if !common::gl_available() {
        return;
    }
    let root = common::temp_workspace();
    let golden = root.path().join("golden");
    std::fs::create_dir_all(golden.join("gone")).unwrap();
    std::fs::copy(
        golden.join("arrow/final.png"),
        golden.join("gone/final.png"),
    )
    .unwrap();
    std::fs::copy(
        golden.join("arrow/final.png"),
        golden.join("arrow/final_old.png"),
    )
    .unwrap();
    std::fs::write(golden.join("arrow/.final.png.tmp1.0"), b"half").unwrap();
    let records = std::fs::read_to_string(golden.join("arrow/blessed.toml")).unwrap();
    let start = records.find("[passes.mask]").unwrap();
    let end = records[start + 1..]
        .find("[passes.")
        .map_or(records.len(), |i| start + 1 + i);
    std::fs::write(
        golden.join("arrow/blessed.toml"),
        format!("{}{}", &records[..start], &records[end..]),
    )
    .unwrap();
    std::fs::remove_file(golden.join("corner/mask.png")).unwrap();
    let before = snapshot(&golden);

    let output = common::harness_command()
        .args([
            "check",
            "--no-verify",
            "--scene",
            "arrow",
            "--backend",
            "gl",
            "--no-speed",
            "--json",
        ])
        .args(["--out", root.path().join("out").to_str().unwrap()])
        .env("HARNESS_ROOT", root.path())
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(0), "{stderr}");
    let json: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
    let listed: Vec<(String, String)> = json["orphans"]
        .as_array()
        .unwrap()
        .iter()
        .map(|o| {
            let name = std::path::Path::new(o["path"].as_str().unwrap())
                .file_name()
                .unwrap()
                .to_string_lossy()
                .into_owned();
            (name, o["kind"].to_string())
        })
        .collect();
    assert_eq!(
        listed,
        [
            (".final.png.tmp1.0".to_owned(), "\"stray\"".to_owned()),
            ("final_old.png".to_owned(), "\"pass_gone\"".to_owned()),
            ("mask.png".to_owned(), "\"unrecorded\"".to_owned()),
        ],
        "{stderr}"
    );
    assert!(stderr.contains("note: orphan: "), "{stderr}");

    let prune = |dry_run: bool| {
        let mut command = common::harness_command();
        command.args(["bless", "--prune"]);
        if dry_run {
            command.arg("--dry-run");
        }
        let output = command.env("HARNESS_ROOT", root.path()).output().unwrap();
        let stdout = String::from_utf8_lossy(&output.stdout).into_owned();
        assert!(
            output.status.success(),
            "{stdout}{}",
            String::from_utf8_lossy(&output.stderr)
        );
        stdout
    };
    let listing = prune(true);
    for expected in [
        "gone: no scene in scenes/ is named gone",
        "final_old.png: no golden pass of arrow",
        ".final.png.tmp1.0: not a golden",
        "arrow/mask.png: arrow/blessed.toml does not record it",
        "corner/blessed.toml: records `mask`, which has no golden in corner",
    ] {
        assert!(listing.contains(expected), "no `{expected}` in:\n{listing}");
    }
    assert_eq!(
        snapshot(&golden).keys().collect::<Vec<_>>(),
        before.keys().collect::<Vec<_>>()
    );

    let removed = prune(false);
    let after = snapshot(&golden);
    let gone: Vec<String> = before
        .keys()
        .filter(|p| !after.contains_key(*p))
        .map(|p| p.strip_prefix(&golden).unwrap().display().to_string())
        .collect();
    assert_eq!(
        gone,
        [
            "arrow/.final.png.tmp1.0",
            "arrow/final_old.png",
            "arrow/mask.png",
            "gone/final.png"
        ],
        "{removed}"
    );
    assert!(!golden.join("gone").exists());
    let corner = harness::golden::GoldenStore::new(&golden)
        .records("corner")
        .unwrap();
    assert!(
        !corner.contains_key("mask") && corner.contains_key("final"),
        "{corner:?}"
    );
    assert!(prune(false).contains("no orphans"));
}
