//! Why a scene's passes failed, in three parts, for each failing image check:
//!
//! - **origin:** a failing output that reads no output that moved (beyond the noise model's
//!   bound for unchanged renders, half its limit: [`MAX_NOISE_RATIO`]) is where the change
//!   starts, in the plan passes that write it; one that reads a moved output (the final image
//!   after the light buffer) only moved because that one did, failing or not, and the change
//!   starts where the earliest of those moved;
//! - **agreement:** every backend checked moved alike (a change in the renderer, a scene or an
//!   asset), or some moved and others did not (those backends or their drivers);
//! - **advice:** one line, bless if intended or where to look first.
//!
//! `check` prints it under its table and carries it in the JSON, the JUnit XML, the Markdown
//! summary and the review page; the mutation self-test checks that it names each mutation's
//! origin.

use std::collections::BTreeMap;

use engine::backend::BackendKind;
use engine::plan::{PassId, RenderPlan, TargetId};

use super::check::CrossBackend;
use super::command_line::bless_command;
use super::noise::MAX_NOISE_RATIO;
use super::suite::PassCheck;

/// Where a failing output stands in its scene's failure.
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case", tag = "role")]
pub enum Role {
    /// The change starts in the plan passes that write it.
    Origin {
        /// Those plan passes, in plan order.
        passes: Vec<PassId>,
    },
    /// No golden to compare with, or one that cannot be compared (its size or format changed):
    /// nothing says whether or where it moved.
    NoComparison,
    /// It reads outputs that moved (directly or through other passes): it moved because they
    /// did.
    Downstream {
        /// The earliest moved outputs upstream of it, where the change starts (failing or
        /// within their tolerance).
        of: Vec<TargetId>,
    },
}

/// Whether the backends that rendered a scene moved alike on one output.
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case", tag = "agreement")]
pub enum Agreement {
    /// Every backend checked failed it: the renderer, the scene or an asset changed.
    AllBackends,
    /// These backends failed it and the others did not: those backends or their drivers.
    Only {
        /// The backends that failed.
        moved: Vec<BackendKind>,
        /// The backends that passed.
        held: Vec<BackendKind>,
    },
    /// Only one backend rendered the scene: nothing to tell the two causes apart.
    OneBackend,
}

/// The verdict on one failing image check.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Diagnosis {
    /// Scene.
    pub scene: String,
    /// The failing output.
    pub pass: TargetId,
    /// Backend.
    pub backend: BackendKind,
    /// Origin, or downstream of which outputs.
    #[serde(flatten)]
    pub role: Role,
    /// How the backends moved on this output.
    #[serde(flatten)]
    pub agreement: Agreement,
    /// What to do, in one line.
    pub advice: String,
}

impl Diagnosis {
    /// The verdict in a few words: `origin: the lighting_pbr pass, every backend`, `moved
    /// because light moved`, `origin: the geometry pass, gl alone (wgpu-vulkan held)`.
    pub fn headline(&self) -> String {
        let agreement = match &self.agreement {
            Agreement::AllBackends => "every backend".to_owned(),
            Agreement::Only { moved, held } => {
                format!(
                    "{} alone ({} held)",
                    crate::names(moved),
                    crate::names(held)
                )
            }
            Agreement::OneBackend => "one backend checked".to_owned(),
        };
        match &self.role {
            Role::Origin { passes } => format!("origin: {}, {agreement}", passes_phrase(passes)),
            Role::Downstream { of } => format!("moved because {} moved", crate::names(of)),
            Role::NoComparison => "nothing to compare with".to_owned(),
        }
    }
}

/// The verdict on `scene`'s `pass` on `backend` in `diagnoses`, if it failed.
pub fn find<'a>(
    diagnoses: &'a [Diagnosis],
    scene: &str,
    pass: TargetId,
    backend: BackendKind,
) -> Option<&'a Diagnosis> {
    diagnoses
        .iter()
        .find(|d| d.scene == scene && d.pass == pass && d.backend == backend)
}

/// The outputs `target` reads, directly or through the passes before it, in `plan` (not the
/// outputs written beside it by the same pass).
pub fn upstream(plan: &RenderPlan, target: TargetId) -> Vec<TargetId> {
    let mut needed = vec![target];
    let mut upstream = Vec::new();
    for pass in plan.passes.iter().rev() {
        if !pass.writes.iter().any(|t| needed.contains(t)) {
            continue;
        }
        for read in &pass.reads {
            if !needed.contains(read) {
                needed.push(*read);
                upstream.push(*read);
            }
        }
    }
    upstream
}

/// Where the change that failed the outputs `failing` starts, given every output that `moved`
/// (failing ones included): a failing output that reads no moved output is its own start; one
/// that does starts at the earliest moved outputs upstream of it (those that read no moved
/// output). Each output once, in `failing`'s order.
pub fn start_outputs(plan: &RenderPlan, failing: &[TargetId], moved: &[TargetId]) -> Vec<TargetId> {
    let mut starts = Vec::new();
    for &output in failing {
        for start in starts_of(plan, output, moved) {
            if !starts.contains(&start) {
                starts.push(start);
            }
        }
    }
    starts
}

/// The earliest moved outputs upstream of `output` (itself when none upstream moved).
fn starts_of(plan: &RenderPlan, output: TargetId, moved: &[TargetId]) -> Vec<TargetId> {
    let above: Vec<TargetId> = upstream(plan, output)
        .into_iter()
        .filter(|u| moved.contains(u))
        .collect();
    if above.is_empty() {
        return vec![output];
    }
    above
        .iter()
        .copied()
        .filter(|u| !upstream(plan, *u).iter().any(|x| moved.contains(x)))
        .collect()
}

/// The plan passes that write any of `outputs`, in plan order.
pub fn writers(plan: &RenderPlan, outputs: &[TargetId]) -> Vec<PassId> {
    plan.passes
        .iter()
        .filter(|pass| pass.writes.iter().any(|t| outputs.contains(t)))
        .map(|pass| pass.id)
        .collect()
}

/// The plan passes where the change that failed `failing` starts (see [`start_outputs`]).
pub fn origins(plan: &RenderPlan, failing: &[TargetId], moved: &[TargetId]) -> Vec<PassId> {
    writers(plan, &start_outputs(plan, failing, moved))
}

/// Whether a check's output moved beyond what unchanged renders do: failed, or above
/// [`MAX_NOISE_RATIO`] of its limit. One without a golden to compare with did not, as far as
/// anyone can tell.
fn moved(check: &PassCheck) -> bool {
    match &check.outcome {
        crate::golden::Outcome::Passed(v) => v.ratio > MAX_NOISE_RATIO,
        crate::golden::Outcome::Failed(_) => true,
        crate::golden::Outcome::MissingGolden | crate::golden::Outcome::Incomparable(_) => false,
    }
}

/// The verdict on every failing (or missing, or incomparable) check of `results`, given each
/// scene's plan and the cross-backend comparisons.
pub fn diagnose(
    plans: &BTreeMap<String, RenderPlan>,
    results: &[PassCheck],
    cross: &[CrossBackend],
) -> Vec<Diagnosis> {
    let mut out = Vec::new();
    for r in results.iter().filter(|r| !r.outcome.passed()) {
        let Some(plan) = plans.get(&r.scene) else {
            continue;
        };
        let moved_here: Vec<TargetId> = results
            .iter()
            .filter(|o| o.scene == r.scene && o.backend == r.backend && moved(o))
            .map(|o| o.pass)
            .collect();
        let starts = starts_of(plan, r.pass, &moved_here);
        let role = if !moved(r) {
            Role::NoComparison
        } else if starts == [r.pass] {
            let passes = writers(plan, &starts);
            if passes.is_empty() {
                continue;
            }
            Role::Origin { passes }
        } else {
            Role::Downstream { of: starts }
        };
        let checked: Vec<&PassCheck> = results
            .iter()
            .filter(|o| o.scene == r.scene && o.pass == r.pass)
            .collect();
        let (moved, held): (Vec<&PassCheck>, Vec<&PassCheck>) =
            checked.iter().partition(|o| !o.outcome.passed());
        let agreement = if checked.len() < 2 {
            Agreement::OneBackend
        } else if held.is_empty() {
            Agreement::AllBackends
        } else {
            Agreement::Only {
                moved: moved.iter().map(|o| o.backend).collect(),
                held: held.iter().map(|o| o.backend).collect(),
            }
        };
        let disagree = cross
            .iter()
            .find(|c| c.scene == r.scene && c.pass == r.pass && !c.within_tolerance);
        let advice = advice(r, &role, &agreement, disagree);
        out.push(Diagnosis {
            scene: r.scene.clone(),
            pass: r.pass,
            backend: r.backend,
            role,
            agreement,
            advice,
        });
    }
    out
}

/// `the lighting_pbr pass` or `the lighting_pbr and lighting_blinn_phong passes`.
fn passes_phrase(passes: &[PassId]) -> String {
    match passes {
        [one] => format!("the {one} pass"),
        _ => format!("the {} passes", crate::names(passes).replace(", ", " and ")),
    }
}

/// The one line of advice: what to do, given where the change starts and how the backends
/// moved ([`Diagnosis::headline`] says the facts).
fn advice(
    r: &PassCheck,
    role: &Role,
    agreement: &Agreement,
    disagree: Option<&CrossBackend>,
) -> String {
    let bless = bless_command(&r.scene_argument);
    match (role, agreement) {
        (Role::Downstream { of }, _) => format!("look at {} first", crate::names(of)),
        (Role::NoComparison, _) => format!(
            "look at the output ({}); bless it if it is right: `{bless}`",
            r.artifacts
                .actual
                .as_ref()
                .map_or("not written".to_owned(), |p| p.display().to_string())
        ),
        (Role::Origin { .. }, Agreement::AllBackends) => format!(
            "the renderer, the scene or an asset changed: look at {} first; bless if intended: \
             `{bless}`",
            r.pass
        ),
        (Role::Origin { .. }, Agreement::Only { .. }) => {
            let cross = disagree
                .map(|c| format!(" ({} and {} disagree beyond its tolerance)", c.a, c.b))
                .unwrap_or_default();
            format!(
                "that backend or its driver{cross}: compare its driver fingerprint with the \
                 blessing one (golden/{}/blessed.toml) before blessing",
                r.scene
            )
        }
        (Role::Origin { .. }, Agreement::OneBackend) => {
            format!("{ONE_BACKEND_ADVICE}; bless if intended: `{bless}`")
        }
    }
}

/// The advice on a change seen on one backend only, before a verification answers it.
const ONE_BACKEND_ADVICE: &str = "run the other backends to tell a renderer change from a driver's";

/// Updates the advice on changes seen on one backend with what the check's verification of
/// the new outputs found about that output: rendered again on every available backend and CPU
/// code path, it reproduces (a change in the renderer or the scene, not one driver's), or it
/// does not under a named source (a bless would be refused). A verification that stopped at
/// another output's disagreement says nothing of this one, which keeps its advice. Without
/// this the check printed "run the other backends" above the verification that had just.
pub fn after_verification(
    diagnoses: &mut [Diagnosis],
    verifications: &[crate::golden::verify::Verification],
) {
    for d in diagnoses
        .iter_mut()
        .filter(|d| d.agreement == Agreement::OneBackend)
    {
        let Some(v) = verifications
            .iter()
            .find(|v| v.scene == d.scene && v.backend == d.backend && v.passes.contains(&d.pass))
        else {
            continue;
        };
        let mine = v
            .disagreements
            .iter()
            .find(|x| x.pass.is_none_or(|p| p == d.pass));
        if let Some(x) = mine {
            d.advice = format!(
                "the verification rendered it again and it does not reproduce under {} on {}: \
                 that driver or CPU code path, or a render that is not deterministic; a bless \
                 would be refused (`--unverified` records it anyway)",
                x.source,
                x.backend.map_or("every backend", BackendKind::name)
            );
        } else if v.verified() {
            d.advice = d.advice.replacen(
                ONE_BACKEND_ADVICE,
                "the verification rendered it again on every backend and CPU code path, where it \
                 reproduces: a change in the renderer or the scene, not one driver's",
                1,
            );
        }
    }
}
