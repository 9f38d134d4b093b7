//! Sharded checks joined: `harness check --scene S --out DIR` on several CI jobs, each leaving its
//! `last-check.json` and `failures/` in its DIR; `harness report --merge DIR... --out OUT` joins
//! them into one run (one page, one JUnit file, one summary, and a `last-check.json` that
//! `bless --from-last-check` and `harness review` accept from). The failure images are copied
//! into OUT's `failures/` (a path recorded on the job that wrote it is looked up again under the
//! folder it was downloaded to, `<DIR>/failures/<scene>/<backend>/<file>`), so the joined folder
//! stands alone: its page links them beside it, and `harness review` serves them.

use std::path::{Path, PathBuf};

use super::accept::LAST_CHECK;
use super::check::{CheckRun, Outputs};
use super::suite::Artifacts;

/// Why shards could not be joined.
#[derive(Debug, thiserror::Error)]
pub enum MergeError {
    /// A shard's results could not be read.
    #[error("{path}: {message}")]
    Shard {
        /// The shard's last-check.json.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
    /// The joined run would be written into one of the shards, over its own results.
    #[error("{out} is one of the shards: write the joined run to a folder of its own")]
    OutIsShard {
        /// The folder.
        out: PathBuf,
    },
    /// A failure image could not be copied into the joined folder.
    #[error("{from}: cannot copy it to {to}: {message}")]
    Copy {
        /// The shard's file.
        from: PathBuf,
        /// Where it was going.
        to: PathBuf,
        /// What went wrong.
        message: String,
    },
    /// Two shards checked different commits: their goldens and scenes need not be the same.
    #[error(
        "{first} checked commit {first_commit} and {second} checked {second_commit}: shards of \
         one run check one commit"
    )]
    Commits {
        /// One shard.
        first: PathBuf,
        /// Its commit.
        first_commit: String,
        /// The other.
        second: PathBuf,
        /// Its commit.
        second_commit: String,
    },
    /// Two shards checked the same scene on the same backend.
    #[error("{scene} on {backend} is in two shards ({first} and {second}): shard by scene")]
    Overlap {
        /// Scene.
        scene: String,
        /// Backend.
        backend: String,
        /// One shard.
        first: PathBuf,
        /// The other.
        second: PathBuf,
    },
}

/// The runs under `shards` as one, to be written to `out` (not one of them): their failure
/// images copied into `out/failures/`, and the outputs of its failing passes read back from them
/// (for the page's viewers).
pub fn merge(shards: &[PathBuf], out: &Path) -> Result<(CheckRun, Outputs), MergeError> {
    let same = |a: &Path, b: &Path| match (a.canonicalize(), b.canonicalize()) {
        (Ok(a), Ok(b)) => a == b,
        _ => a == b,
    };
    if shards.iter().any(|shard| same(shard, out)) {
        return Err(MergeError::OutIsShard {
            out: out.to_owned(),
        });
    }
    let mut merged = CheckRun::default();
    // The first shard that names its commit, and the commit.
    let mut committed: Option<(PathBuf, String)> = None;
    let mut owner: Vec<(String, String, PathBuf)> = Vec::new();
    let mut disputed: Vec<engine::backend::BackendKind> = Vec::new();
    for (i, dir) in shards.iter().enumerate() {
        if shards[..i].contains(dir) {
            return Err(MergeError::Shard {
                path: dir.clone(),
                message: "given twice".to_owned(),
            });
        }
        let path = dir.join(LAST_CHECK);
        let error = |message: String| MergeError::Shard {
            path: path.clone(),
            message,
        };
        let bytes = std::fs::read(&path).map_err(|e| error(e.to_string()))?;
        let mut run: CheckRun = serde_json::from_slice(&bytes).map_err(|e| error(e.to_string()))?;
        if let Some(commit) = &run.commit {
            match &committed {
                Some((first, first_commit)) if first_commit != commit => {
                    return Err(MergeError::Commits {
                        first: first.clone(),
                        first_commit: first_commit.clone(),
                        second: dir.clone(),
                        second_commit: commit.clone(),
                    });
                }
                Some(_) => {}
                None => committed = Some((dir.clone(), commit.clone())),
            }
        }
        for r in &mut run.results {
            let key = (r.scene.clone(), r.backend.name().to_owned());
            match owner.iter().find(|(s, b, _)| (s, b) == (&key.0, &key.1)) {
                Some((_, _, first)) if first != dir => {
                    return Err(MergeError::Overlap {
                        scene: key.0,
                        backend: key.1,
                        first: first.clone(),
                        second: dir.clone(),
                    })
                }
                Some(_) => {}
                None => owner.push((key.0, key.1, dir.clone())),
            }
            rebase(&mut r.artifacts, dir);
        }
        for b in run.backends {
            match merged.backends.iter_mut().find(|m| m.backend == b.backend) {
                // Asked for and missing in any shard fails the joined run as it failed that
                // shard (its scenes went unchecked there); otherwise available in any shard
                // is available, and the first fingerprint seen is kept.
                Some(m) if m.missing() => {}
                Some(m) if b.missing() || (m.unavailable.is_some() && b.unavailable.is_none()) => {
                    *m = b;
                }
                Some(_) => {}
                None => merged.backends.push(b),
            }
        }
        merged.results.extend(run.results);
        merged.render_errors.extend(run.render_errors);
        merged.load_errors.extend(run.load_errors);
        merged.cross.extend(run.cross);
        merged.timings.extend(run.timings);
        for note in run.driver_notes {
            if !merged.driver_notes.contains(&note) {
                merged.driver_notes.push(note);
            }
        }
        merged.speed.checks.extend(run.speed.checks);
        merged.speed.errors.extend(run.speed.errors);
        // Shards of different hosts name different recordings: a backend they disagree on
        // has none (the advice then says to record the host, without a name).
        for (backend, name) in run.speed.recorded_as {
            if merged
                .speed
                .recorded_as
                .get(&backend)
                .is_some_and(|n| *n != name)
            {
                disputed.push(backend);
            }
            merged.speed.recorded_as.entry(backend).or_insert(name);
        }
        merged.speed.unspecialised_lighting |= run.speed.unspecialised_lighting;
        for note in run.speed.host_notes {
            if !merged.speed.host_notes.contains(&note) {
                merged.speed.host_notes.push(note);
            }
        }
        merged.diagnoses.extend(run.diagnoses);
        merged.verifications.extend(run.verifications);
        merged.inputs.extend(run.inputs);
        for orphan in run.orphans {
            if !merged.orphans.contains(&orphan) {
                merged.orphans.push(orphan);
            }
        }
    }
    for backend in disputed {
        merged.speed.recorded_as.remove(&backend);
    }
    merged.commit = committed.map(|(_, commit)| commit);
    for r in &mut merged.results {
        gather(&mut r.artifacts, out)?;
    }
    let mut outputs = Outputs::new();
    for r in merged.results.iter().filter(|r| !r.outcome.passed()) {
        let Some(actual) = &r.artifacts.actual else {
            continue;
        };
        let image = if actual.extension().is_some_and(|x| x == "png") {
            crate::images::read_png(actual)
        } else {
            crate::images::read_exr(actual)
        };
        if let Ok(image) = image {
            outputs.insert((r.scene.clone(), r.pass, r.backend), image);
        }
    }
    Ok((merged, outputs))
}

/// The files of `artifacts` that a check wrote.
fn files_mut(artifacts: &mut Artifacts) -> impl Iterator<Item = &mut PathBuf> {
    [
        &mut artifacts.actual,
        &mut artifacts.golden,
        &mut artifacts.diff,
    ]
    .into_iter()
    .flatten()
}

/// Where `path`, a check's `<out>/failures/<scene>/<backend>/<file>`, lies under `dir`'s
/// `failures/` (its last three parts); None for a shorter path.
fn under_failures(path: &Path, dir: &Path) -> Option<PathBuf> {
    let parts: Vec<_> = path.iter().collect();
    let tail: PathBuf = parts.get(parts.len().checked_sub(3)?..)?.iter().collect();
    Some(dir.join("failures").join(tail))
}

/// Copies the files of `artifacts` to the same place under `out` (see [`under_failures`]), and
/// points them there.
fn gather(artifacts: &mut Artifacts, out: &Path) -> Result<(), MergeError> {
    for path in files_mut(artifacts) {
        let Some(to) = under_failures(path, out).filter(|_| path.exists()) else {
            continue;
        };
        let copy = || -> std::io::Result<()> {
            if let Some(dir) = to.parent() {
                std::fs::create_dir_all(dir)?;
            }
            std::fs::copy(&*path, &to).map(|_| ())
        };
        copy().map_err(|e| MergeError::Copy {
            from: path.clone(),
            to: to.clone(),
            message: e.to_string(),
        })?;
        *path = to;
    }
    Ok(())
}

/// Points `artifacts` recorded in another place (another machine's job, a folder since moved)
/// at the copies under `dir`, the folder `check --out` wrote them to as it is here (see
/// [`under_failures`]), keeping each as recorded where there is no such copy.
pub(crate) fn rebase(artifacts: &mut Artifacts, dir: &Path) {
    for path in files_mut(artifacts) {
        if let Some(here) = under_failures(path, dir).filter(|here| here.exists()) {
            *path = here;
        }
    }
}
