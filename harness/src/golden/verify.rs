//! Verified bless: before a new golden is written, by `harness bless` or `bless
//! --from-last-check`, it must reproduce. The scene is rendered again on every available
//! backend, as the drivers are and under llvmpipe's and lavapipe's other CPU code paths (the
//! cheap environment sources of the noise model: `drivers`, `cpu-sse4.1`, `cpu-avx`), each in a
//! child `harness check` against a temporary golden folder that holds the candidates; every
//! candidate pass must pass its own limits there. A golden that only one backend or one code
//! path can produce, or an output kept by a check of a scene that has changed since, is refused
//! with the source that disagreed. `--unverified` skips this and blessed.toml records it.
//!
//! `check` verifies the outputs it keeps of the reference backend's failing passes as it goes
//! (unless `--no-verify`) and records a [`Verification`] in last-check.json, so that accepting
//! them later (`harness review`, `bless --from-last-check`) renders nothing: the record is used
//! while the scene's inputs ([`inputs_digest`]) and the kept files are as they were, for the
//! passes it speaks for ([`Verification::verdict_on`]); otherwise the accept verifies again. A
//! verification that could not run is not recorded.

use std::path::Path;
use std::process::Command;

use engine::backend::BackendKind;
use engine::plan::TargetId;
use engine::Image;

use super::check::CheckRun;
use super::portability::{sources, SourceKind};
use super::suite::Case;
use super::GoldenStore;

/// The noise sources a candidate golden must reproduce under.
pub const SOURCES: [&str; 3] = ["drivers", "cpu-sse4.1", "cpu-avx"];

/// A source under which a candidate did not reproduce within its limits.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Disagreement {
    /// The source (`drivers`, `cpu-sse4.1`, ...).
    pub source: String,
    /// The backend that rendered it (None when the render itself failed for every backend).
    pub backend: Option<BackendKind>,
    /// The pass.
    pub pass: Option<TargetId>,
    /// What the check said.
    pub detail: String,
}

impl std::fmt::Display for Disagreement {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let pass = self.pass.map_or("-".to_owned(), |p| p.to_string());
        let backend = self.backend.map_or("-", BackendKind::name);
        write!(
            f,
            "{pass} does not reproduce under {} on {backend}: {}",
            self.source, self.detail
        )
    }
}

/// What `check` found when it verified the outputs it kept of one scene's failing passes on
/// one backend.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Verification {
    /// The scene.
    pub scene: String,
    /// The backend whose outputs were verified.
    pub backend: BackendKind,
    /// The passes verified together.
    pub passes: Vec<TargetId>,
    /// The scene's inputs when it was verified ([`inputs_digest`]).
    pub inputs: String,
    /// Each pass's output as the check kept it: a digest of the file's bytes ([`file_digest`]),
    /// so that an accept takes the record only for the very files it verified.
    pub kept: Vec<(TargetId, String)>,
    /// Where they did not reproduce (empty: verified under every source).
    pub disagreements: Vec<Disagreement>,
}

impl Verification {
    /// Whether every output verified reproduced under every source.
    pub fn verified(&self) -> bool {
        self.disagreements.is_empty()
    }

    /// What this record says of `kept` (some of its passes, each with the file it keeps), while
    /// `inputs` are the scene's now: `Some(empty)` verified, `Some(disagreements)` refused (the
    /// ones about those passes, and render failures), `None` when it cannot say (other inputs,
    /// other files, a pass it did not cover, or a refusal about other passes only: the
    /// verification stops at the first source that disagrees, so the others were not tried
    /// under every source) and the accept must verify again.
    pub fn verdict_on(
        &self,
        inputs: &str,
        kept: &[(TargetId, Option<String>)],
    ) -> Option<Vec<Disagreement>> {
        if self.inputs != inputs {
            return None;
        }
        for (pass, digest) in kept {
            let recorded = self.kept.iter().find(|(p, _)| p == pass).map(|(_, d)| d);
            if digest.is_none() || recorded != digest.as_ref() {
                return None;
            }
        }
        if self.disagreements.is_empty() {
            return Some(Vec::new());
        }
        let relevant: Vec<Disagreement> = self
            .disagreements
            .iter()
            .filter(|d| d.pass.is_none_or(|p| kept.iter().any(|(k, _)| *k == p)))
            .cloned()
            .collect();
        (!relevant.is_empty()).then_some(relevant)
    }

    /// One line: what was verified and how it went, with what to do.
    pub fn summary(&self) -> String {
        let passes = crate::names(&self.passes);
        match self.disagreements.first() {
            None => format!(
                "{}'s new {passes} ({}) reproduce on every backend under {}: accepting them \
                 (`harness review`, `bless --from-last-check`) renders nothing",
                self.scene,
                self.backend,
                SOURCES.join(", ")
            ),
            Some(first) => format!(
                "{}'s new {passes} ({}) do not reproduce: {first}{}; accepting them is refused \
                 (`--unverified` records them anyway)",
                self.scene,
                self.backend,
                match self.disagreements.len() {
                    1 => String::new(),
                    n => format!(" (and {} more)", n - 1),
                }
            ),
        }
    }
}

/// A digest of what a scene's verification depends on that can change between a check and an
/// accept: every file the scene was loaded from (the scene file, its environment, meshes,
/// material libraries and textures), the noise model the limits come from, and the harness
/// executable that renders it.
pub fn inputs_digest(store: &GoldenStore, case: &Case) -> String {
    use std::hash::{Hash, Hasher};
    let mut hasher = std::collections::hash_map::DefaultHasher::new();
    std::fs::read(store.root().join("noise.toml"))
        .unwrap_or_default()
        .hash(&mut hasher);
    // As the check recorded them when it loaded the scene.
    case.inputs.files.hash(&mut hasher);
    crate::golden::speed::history::build().hash(&mut hasher);
    format!("{:016x}", hasher.finish())
}

pub use super::scene_inputs::file_digest;

/// Renders `case` under each of [`SOURCES`] (children of `exe`, the harness binary) against a
/// temporary copy of its golden folder holding `candidates`, and returns where a candidate pass
/// fails its limits under the first source where one does (empty: verified). `progress` is told
/// each source.
pub fn verify(
    exe: &Path,
    store: &GoldenStore,
    case: &Case,
    candidates: &[(TargetId, Image)],
    mut progress: impl FnMut(&str),
) -> Result<Vec<Disagreement>, String> {
    let temp = tempfile::tempdir().map_err(|e| format!("cannot make a temporary folder: {e}"))?;
    let golden = temp.path().join("golden");
    let scene_dir = golden.join(case.name());
    copy_folder(&store.root().join(case.name()), &scene_dir)?;
    // The limits come from the noise model.
    let noise = store.root().join("noise.toml");
    if noise.exists() {
        std::fs::copy(&noise, golden.join("noise.toml"))
            .map_err(|e| format!("cannot copy {}: {e}", noise.display()))?;
    }
    let candidate_store = GoldenStore::new(&golden);
    for (pass, image) in candidates {
        let path = candidate_store.path(case.name(), *pass, super::is_eight_bit(image));
        crate::images::write_image(image, &path, crate::images::FileCompression::Fast)
            .map_err(|e| e.to_string())?;
    }
    // The same candidates of the same scene verified before, under the same drivers and
    // environment (only where HARNESS_VERIFY_CACHE names a folder).
    let passes: Vec<TargetId> = candidates.iter().map(|(pass, _)| *pass).collect();
    let cache = super::verify_cache::folder().and_then(|folder| {
        let inputs = inputs_digest(store, case);
        Some((
            super::verify_cache::key(&inputs, case, &golden, &passes)?,
            folder,
        ))
    });
    if let Some((key, folder)) = &cache {
        if let Some(kept) = super::verify_cache::lookup(folder, key) {
            progress(&format!(
                "every source: the same candidates were verified before ({})",
                super::verify_cache::CACHE_ENV
            ));
            return Ok(kept);
        }
    }
    let (all, _) = sources(store);
    let mut disagreements = Vec::new();
    for source in all.iter().filter(|s| SOURCES.contains(&s.name.as_str())) {
        let SourceKind::Environment(vars) = &source.kind else {
            continue;
        };
        progress(&source.name);
        let out = temp.path().join(format!("out-{}", source.name));
        // Only the candidates' passes: the renders run what they need, and nothing else is
        // compared.
        let passes = candidates
            .iter()
            .flat_map(|(pass, _)| ["--pass".to_owned(), pass.to_string()]);
        let output = Command::new(exe)
            .args(["check", "--json", "--no-speed", "--no-verify", "--scene"])
            .arg(&case.loaded.path)
            .args(passes)
            .arg("--out")
            .arg(&out)
            .env("HARNESS_ROOT", temp.path())
            // The maps of this workspace's cache (the temporary root has none).
            .env(
                "HARNESS_IBL_CACHE",
                crate::ibl_cache_dir().unwrap_or_default(),
            )
            .envs(vars.iter().map(|(k, v)| (k, v)))
            .output()
            .map_err(|e| format!("cannot run {}: {e}", exe.display()))?;
        let run: CheckRun = match serde_json::from_slice(&output.stdout) {
            Ok(run) => run,
            Err(_) => {
                disagreements.push(Disagreement {
                    source: source.name.clone(),
                    backend: None,
                    pass: None,
                    detail: format!(
                        "the check did not run ({}): {}",
                        output.status,
                        String::from_utf8_lossy(&output.stderr)
                            .lines()
                            .last()
                            .unwrap_or_default()
                    ),
                });
                continue;
            }
        };
        for r in &run.results {
            if candidates.iter().any(|(p, _)| *p == r.pass) && !r.outcome.passed() {
                disagreements.push(Disagreement {
                    source: source.name.clone(),
                    backend: Some(r.backend),
                    pass: Some(r.pass),
                    detail: r.worst(),
                });
            }
        }
        for (_, backend, error) in &run.render_errors {
            disagreements.push(Disagreement {
                source: source.name.clone(),
                backend: Some(*backend),
                pass: None,
                detail: format!("render failed: {error}"),
            });
        }
        // Refused already: the sources after this one would only say more of the same.
        if !disagreements.is_empty() {
            break;
        }
    }
    if let Some((key, folder)) = &cache {
        super::verify_cache::keep(folder, key, &disagreements);
    }
    Ok(disagreements)
}

/// Verifies the outputs `run` kept of each scene's failing passes on one backend (the
/// reference backend when it was checked, else the first available one), as `check` does
/// before it writes last-check.json: one [`Verification`] per scene with failing passes.
/// `progress` is told each scene and source.
pub fn verify_failing(
    exe: &Path,
    store: &GoldenStore,
    cases: &[Case],
    run: &CheckRun,
    outputs: &super::check::Outputs,
    mut progress: impl FnMut(&str),
) -> Vec<Verification> {
    let available: Vec<BackendKind> = run
        .backends
        .iter()
        .filter(|b| b.unavailable.is_none())
        .map(|b| b.backend)
        .collect();
    let Some(backend) = super::suite::reference_among(&available) else {
        return Vec::new();
    };
    let mut verifications = Vec::new();
    for case in cases {
        let failing: Vec<_> = run
            .results
            .iter()
            .filter(|r| r.scene == case.name() && r.backend == backend && !r.outcome.passed())
            .collect();
        let mut candidates: Vec<(TargetId, Image)> = Vec::new();
        let mut kept = Vec::new();
        for r in failing {
            let image = outputs.get(&(r.scene.clone(), r.pass, backend));
            let digest = r.artifacts.actual.as_deref().and_then(file_digest);
            if let (Some(image), Some(digest)) = (image, digest) {
                candidates.push((r.pass, image.clone()));
                kept.push((r.pass, digest));
            }
        }
        if candidates.is_empty() {
            continue;
        }
        let scene = case.name();
        let inputs = inputs_digest(store, case);
        let verified = verify(exe, store, case, &candidates, |source| {
            progress(&format!("verifying {scene}'s new outputs under {source}"));
        });
        // Recorded only when it could say: not when it could not run (a child that gave no
        // results has no backend), nor when the inputs changed meanwhile. The accept verifies.
        let Ok(disagreements) = verified else {
            continue;
        };
        if disagreements.iter().any(|d| d.backend.is_none()) || inputs_digest(store, case) != inputs
        {
            continue;
        }
        verifications.push(Verification {
            scene: scene.to_owned(),
            backend,
            passes: candidates.iter().map(|(p, _)| *p).collect(),
            inputs,
            kept,
            disagreements,
        });
    }
    verifications
}

/// Copies the files of `from` (not its folders: a scene's golden folder has none) into `to`,
/// less the bless lock: a lock a bless holds is no input of the check, and a copy of it would
/// make the same candidates' verification a different one to [`super::verify_cache`].
fn copy_folder(from: &Path, to: &Path) -> Result<(), String> {
    std::fs::create_dir_all(to).map_err(|e| format!("cannot create {}: {e}", to.display()))?;
    let Ok(entries) = std::fs::read_dir(from) else {
        return Ok(());
    };
    for entry in entries.flatten() {
        if entry.file_name() == super::LOCK_FILE {
            continue;
        }
        if entry.file_type().is_ok_and(|t| t.is_file()) {
            std::fs::copy(entry.path(), to.join(entry.file_name()))
                .map_err(|e| format!("cannot copy {}: {e}", entry.path().display()))?;
        }
    }
    Ok(())
}
