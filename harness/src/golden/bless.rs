//! Blessing: the one path by which a golden is rewritten, shared by `harness bless` and
//! `UPDATE_GOLDENS=1 cargo test`. A pass is rewritten when it has no golden, cannot be compared
//! with it, or is outside its tolerance; or when asked for by name or with every pass. Each
//! write records the backend, its driver and the metrics against the golden it replaces.

use std::fmt;
use std::path::PathBuf;

use engine::backend::BackendKind;
use engine::plan::TargetId;
use engine::Image;

use super::suite::Case;
use super::{GoldenError, GoldenStore, Outcome, SceneLock};
use crate::golden;

/// A reason for a bless as recorded (`--reason`, the review page's field): trimmed, and None
/// when nothing is left (an empty reason would read as one given).
pub fn given_reason(text: &str) -> Option<&str> {
    Some(text.trim()).filter(|r| !r.is_empty())
}

/// Why `case`'s goldens may not be written, when it is a file outside scenes/ that
/// shares a canonical scene's name ([`refusal_for`]), or the name of another file outside
/// scenes/ whose goldens its folder holds.
pub fn refusal(case: &Case) -> Option<String> {
    refusal_for(case.name(), &case.loaded.path.to_string_lossy())
        .or_else(|| another_files_folder(case))
}

/// Why a scene file outside scenes/ may not write golden/<name>/: its blessed.toml records
/// another scene file, still there and still of that name, as the one its goldens were
/// blessed from (two files named alike would overwrite each other's goldens without a word).
fn another_files_folder(case: &Case) -> Option<String> {
    if is_canonical(case) {
        return None;
    }
    let recorded = GoldenStore::workspace()
        .scene_file(case.name())
        .ok()
        .flatten()?;
    let same = match (recorded.canonicalize(), case.loaded.path.canonicalize()) {
        (Ok(a), Ok(b)) => a == b,
        _ => false,
    };
    let still_named_so = scene_name_of(&recorded).is_some_and(|name| name == case.name());
    (!same && still_named_so).then(|| {
        format!(
            "{} is named `{}`, as is {}, whose goldens golden/{}/ holds (its blessed.toml \
             records that file): its goldens would be written over them. Give this file a name \
             of its own (`name = \"...\"`), or bless that one",
            case.loaded.path.display(),
            case.name(),
            recorded.display(),
            case.name()
        )
    })
}

/// Why the goldens of the scene `name`, loaded from `argument` (a canonical name or a scene
/// file's path), may not be written: when it is a file outside scenes/ that shares a canonical
/// scene's name, its goldens would be written over that scene's (a scene's name is its golden
/// folder), which the next check of the canonical scene would fail. Checking such a copy
/// against the canonical goldens is fine; blessing it is not.
pub fn refusal_for(name: &str, argument: &str) -> Option<String> {
    let canonical = crate::scenes_dir().join(format!("{name}.toml"));
    // A bare name is a canonical scene (a file in scenes/ is named by its stem); no canonical
    // scene of that name, nothing to overwrite. Any other path that does not resolve to the
    // canonical file (moved, deleted, read from another folder) is refused: fail closed.
    if argument == name || !canonical.is_file() {
        return None;
    }
    let path = std::path::Path::new(argument);
    (!is_canonical_file(name, path)).then(|| {
        format!(
            "{} shares its name with the canonical scene {}: its goldens would be written \
             over golden/{name}/, which are that scene's. Edit {} instead, or give this file a \
             name of its own (a scene's name is its golden folder)",
            path.display(),
            canonical.display(),
            canonical.display()
        )
    })
}

/// The name of the scene in the file at `path`, as a load would give it (its `name`, or its
/// stem), read without loading its assets; None where the file cannot be read as TOML.
fn scene_name_of(path: &std::path::Path) -> Option<String> {
    let text = std::fs::read_to_string(path).ok()?;
    let table: toml::Table = toml::from_str(&text).ok()?;
    match table.get("name") {
        Some(toml::Value::String(name)) => Some(name.clone()),
        Some(_) => None,
        None => Some(path.file_stem()?.to_str()?.to_owned()),
    }
}

/// Whether `case` is the scene of scenes/ named like it (not a scene file elsewhere).
pub fn is_canonical(case: &Case) -> bool {
    is_canonical_file(case.name(), &case.loaded.path)
}

/// Whether `path` is the file of the canonical scene `name`, `scenes/<name>.toml` (links and
/// `..` resolved; false when either is missing).
fn is_canonical_file(name: &str, path: &std::path::Path) -> bool {
    let canonical = crate::scenes_dir().join(format!("{name}.toml"));
    canonical
        .canonicalize()
        .ok()
        .zip(path.canonicalize().ok())
        .is_some_and(|(a, b)| a == b)
}

/// Which of a case's golden passes to rewrite beyond those that changed.
#[derive(Clone, Copy, Debug, Default)]
pub struct BlessRequest<'a> {
    /// Passes to rewrite even when within tolerance.
    pub named: &'a [TargetId],
    /// Rewrite every pass.
    pub every_pass: bool,
    /// Decide, print, and write nothing.
    pub dry_run: bool,
    /// Written without verification (recorded in blessed.toml; see [`super::verify`]).
    pub unverified: bool,
    /// Why the picture changed, recorded in blessed.toml beside each golden written.
    pub reason: Option<&'a str>,
}

/// What blessing did to one pass.
#[derive(Clone, Debug, PartialEq)]
pub enum BlessOutcome {
    /// Within tolerance and not asked for: the golden stays.
    Kept,
    /// Would be rewritten (a dry run).
    WouldWrite,
    /// Would be written where there is no golden (a dry run).
    WouldWriteNew,
    /// Rewritten at this path.
    Written(PathBuf),
}

/// One pass of one scene after blessing.
#[derive(Clone, Debug, PartialEq)]
pub struct BlessedPass {
    /// Scene.
    pub scene: String,
    /// Pass.
    pub pass: TargetId,
    /// The output against the golden it would replace: "new", or the metrics.
    pub previous: String,
    /// What was done.
    pub outcome: BlessOutcome,
}

impl fmt::Display for BlessedPass {
    /// One line per pass (two when written): the same words on every route.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}: {}", self.scene, self.pass, self.previous)?;
        match &self.outcome {
            BlessOutcome::Kept => f.write_str("; kept"),
            BlessOutcome::WouldWrite => f.write_str("; would be rewritten (dry run)"),
            BlessOutcome::WouldWriteNew => f.write_str("; would be written (dry run)"),
            BlessOutcome::Written(path) => write!(f, "\n  wrote {}", path.display()),
        }
    }
}

/// Blesses `image`, the fresh output of `case`'s `pass` rendered on `backend` (whose driver
/// fingerprint is `driver`), as `request` asks, holding the scene's `lock`.
pub fn bless_pass(
    store: &GoldenStore,
    lock: &SceneLock,
    case: &Case,
    pass: TargetId,
    image: &Image,
    (backend, driver): (BackendKind, &str),
    request: BlessRequest<'_>,
) -> Result<BlessedPass, GoldenError> {
    if lock.scene() != case.name() {
        return Err(GoldenError::Record {
            path: store.root().join(case.name()),
            message: format!("blessing it while holding {}'s lock", lock.scene()),
        });
    }
    let change = bless_change(store, case, pass, image);
    let write = change.changed || request.every_pass || request.named.contains(&pass);
    let outcome = if !write {
        BlessOutcome::Kept
    } else if request.dry_run && change.missing {
        BlessOutcome::WouldWriteNew
    } else if request.dry_run {
        BlessOutcome::WouldWrite
    } else {
        BlessOutcome::Written(store.bless(
            lock,
            pass,
            image,
            super::Provenance {
                backend,
                driver,
                previous: &change.previous,
                unverified: request.unverified,
                reason: request.reason,
                scene_file: (!is_canonical(case)).then_some(case.loaded.path.as_path()),
            },
        )?)
    };
    Ok(BlessedPass {
        scene: case.name().to_owned(),
        pass,
        previous: change.previous,
        outcome,
    })
}

/// What blessing one fresh pass output would change.
#[derive(Clone, Debug, PartialEq)]
pub struct BlessChange {
    /// Whether the golden needs rewriting: it is missing, cannot be compared, or the output is
    /// outside the pass's tolerance.
    pub changed: bool,
    /// How the output differs from the golden it would replace (recorded in blessed.toml):
    /// "new", or the metrics against the old golden.
    pub previous: String,
    /// Whether there is no golden: a bless writes a new one.
    pub missing: bool,
}

/// Compares a fresh output of `case`'s `pass` with its golden, for `harness bless` and
/// `UPDATE_GOLDENS=1`: a pass within tolerance is left alone unless asked for by name.
pub fn bless_change(
    store: &GoldenStore,
    case: &Case,
    pass: TargetId,
    image: &Image,
) -> BlessChange {
    let old = match store.load(case.name(), pass, golden::is_eight_bit(image)) {
        Ok(Some(old)) => old,
        Ok(None) => {
            return BlessChange {
                changed: true,
                previous: "new".to_owned(),
                missing: true,
            }
        }
        // A golden that cannot be read is what a bless repairs.
        Err(e) => {
            return BlessChange {
                changed: true,
                previous: format!("old golden unreadable: {e}"),
                missing: false,
            }
        }
    };
    match golden::check(image, Some(&old), &case.rules[&pass]) {
        Outcome::Passed(v) | Outcome::Failed(v) => {
            let metrics = v
                .checks
                .iter()
                .map(ToString::to_string)
                .collect::<Vec<_>>()
                .join("; ");
            BlessChange {
                changed: !v.passed,
                previous: format!(
                    "{} vs old golden: {metrics}",
                    if v.passed {
                        "within tolerance"
                    } else {
                        "CHANGED"
                    }
                ),
                missing: false,
            }
        }
        Outcome::MissingGolden => BlessChange {
            changed: true,
            previous: "new".to_owned(),
            missing: true,
        },
        Outcome::Incomparable(why) => BlessChange {
            changed: true,
            previous: format!("incomparable with old golden: {why}"),
            missing: false,
        },
    }
}

/// What a bless of `case` can see before it writes anything, so that it does not stop half-way
/// through a scene for it: blessed.toml must read (it is rewritten with each pass), and no
/// golden's path (in either format) may be a folder. Checked for every scene before any is
/// written.
pub fn preflight(store: &GoldenStore, case: &Case) -> Result<(), GoldenError> {
    store.records(case.name())?;
    for &pass in &case.passes {
        for eight_bit in [true, false] {
            let path = store.path(case.name(), pass, eight_bit);
            if path.is_dir() {
                return Err(GoldenError::Record {
                    message: "is a folder where the golden of a pass belongs: nothing blessed \
                              (move it away)"
                        .to_owned(),
                    path,
                });
            }
        }
    }
    Ok(())
}
