//! The sources of variation between machines: the drivers as they are, llvmpipe's other CPU
//! code paths, a second Mesa release (once installed), synthetic rounding, and the hosts whose
//! renders are recorded in `golden/evidence/`; and picking some of them by name.

use std::path::{Path, PathBuf};

use crate::golden::GoldenStore;

/// How a source changes a render.
#[derive(Clone, Debug, PartialEq)]
pub enum SourceKind {
    /// Renders in a child process with these environment variables set (the drivers as they
    /// are, when empty).
    Environment(Vec<(String, String)>),
    /// 8-bit outputs re-quantized from an f64 evaluation of the same tone mapping of the light
    /// buffer; float outputs moved by ±1 ulp of their storage (seeded, per value).
    SyntheticRounding,
    /// Outputs rendered on another host, kept in `golden/evidence/<name>/` as
    /// `<scene>_<pass>_<backend>.png|exr`.
    Recorded(PathBuf),
}

/// A source of variation between machines.
#[derive(Clone, Debug, PartialEq)]
pub struct Source {
    /// Name (`drivers`, `cpu-sse4.1`, `mesa-25.0.7`, `synthetic-rounding`, ...).
    pub name: String,
    /// What it is.
    pub description: String,
    /// How it changes a render.
    pub kind: SourceKind,
    /// Cheap enough for CI (a short run with no download).
    pub cheap: bool,
}

/// Where `scripts/mesa-backports.sh` installs the second Mesa.
pub fn mesa_backports_prefix() -> PathBuf {
    std::env::var_os("HARNESS_MESA_BACKPORTS")
        .map(PathBuf::from)
        .unwrap_or_else(|| crate::workspace_root().join("target/mesa-backports"))
}

/// The second Mesa's environment (from `<prefix>/env.list`, `KEY=value` lines) and version, or
/// why it is not there.
pub fn mesa_backports() -> Result<(String, Vec<(String, String)>), String> {
    let prefix = mesa_backports_prefix();
    let list = prefix.join("env.list");
    let text = std::fs::read_to_string(&list).map_err(|_| {
        format!(
            "no second Mesa at {} (install it with scripts/mesa-backports.sh)",
            prefix.display()
        )
    })?;
    let version = std::fs::read_to_string(prefix.join("version"))
        .unwrap_or_default()
        .trim()
        .to_owned();
    let vars = text
        .lines()
        .filter_map(|l| l.split_once('='))
        .map(|(k, v)| (k.trim().to_owned(), v.trim().to_owned()))
        .collect();
    Ok((version, vars))
}

fn env_source(name: &str, description: &str, vars: &[(&str, &str)], cheap: bool) -> Source {
    Source {
        name: name.to_owned(),
        description: description.to_owned(),
        kind: SourceKind::Environment(
            vars.iter()
                .map(|(k, v)| ((*k).to_owned(), (*v).to_owned()))
                .collect(),
        ),
        cheap,
    }
}

/// Every source: the ones this machine can produce (the second Mesa only once installed: `Err`
/// says how), and the recorded hosts in `golden/evidence/`.
pub fn sources(store: &GoldenStore) -> (Vec<Source>, Vec<(String, String)>) {
    // llvmpipe's and lavapipe's other code paths: (name, what, variable, value, cheap).
    let code_paths = [
        (
            "cpu-sse4.1",
            "llvmpipe/lavapipe limited to SSE4.1 code",
            "GALLIUM_OVERRIDE_CPU_CAPS",
            "sse4.1",
            true,
        ),
        (
            "cpu-avx",
            "llvmpipe/lavapipe limited to AVX code",
            "GALLIUM_OVERRIDE_CPU_CAPS",
            "avx",
            true,
        ),
        (
            "vector-128",
            "llvmpipe/lavapipe with 128-bit vectors",
            "LP_NATIVE_VECTOR_WIDTH",
            "128",
            false,
        ),
        (
            "threads-1",
            "llvmpipe/lavapipe rasterizing on one thread",
            "LP_NUM_THREADS",
            "1",
            false,
        ),
    ];
    let mut sources = vec![env_source(
        "drivers",
        "this machine's drivers as they are (every backend)",
        &[],
        true,
    )];
    for (name, description, key, value, cheap) in code_paths {
        sources.push(env_source(name, description, &[(key, value)], cheap));
    }
    let mut missing = Vec::new();
    match mesa_backports() {
        Ok((version, vars)) => {
            // The second Mesa alone and with each code path: a user's machine brings both at
            // once (a newer Mesa on a CPU without AVX2, say), and they add up.
            let short = version.split('-').next().unwrap_or(&version).to_owned();
            let mesa = format!("mesa-{short}");
            let description = format!("Mesa {version} from bookworm-backports, private prefix");
            sources.push(Source {
                name: mesa.clone(),
                description: description.clone(),
                kind: SourceKind::Environment(vars.clone()),
                cheap: false,
            });
            for (name, what, key, value, _) in code_paths {
                let mut combined = vars.clone();
                combined.push((key.to_owned(), value.to_owned()));
                sources.push(Source {
                    name: format!("{mesa}+{name}"),
                    description: format!("{description}; {what}"),
                    kind: SourceKind::Environment(combined),
                    cheap: false,
                });
            }
        }
        Err(why) => missing.push(("mesa-backports".to_owned(), why)),
    }
    sources.push(Source {
        name: "synthetic-rounding".to_owned(),
        description: "8-bit outputs re-quantized from an f64 tone mapping of the light buffer; \
                      float outputs moved by ±1 ulp of their storage"
            .to_owned(),
        kind: SourceKind::SyntheticRounding,
        cheap: true,
    });
    let evidence = store.root().join("evidence");
    if let Ok(entries) = std::fs::read_dir(&evidence) {
        // A host folder with renders (a host with speed ratios only is a timing source).
        let has_renders = |dir: &Path| {
            std::fs::read_dir(dir).is_ok_and(|files| {
                files.filter_map(Result::ok).any(|f| {
                    let path = f.path();
                    path.extension().is_some_and(|e| e == "png" || e == "exr")
                })
            })
        };
        let mut hosts: Vec<PathBuf> = entries
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.is_dir() && has_renders(p))
            .collect();
        hosts.sort();
        for dir in hosts {
            let name = dir
                .file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_default();
            let readme = std::fs::read_to_string(dir.join("README.md")).unwrap_or_default();
            let description = readme
                .lines()
                .find(|l| !l.trim().is_empty() && !l.starts_with('#'))
                .unwrap_or("renders recorded on another host")
                .to_owned();
            sources.push(Source {
                name,
                description,
                kind: SourceKind::Recorded(dir),
                cheap: true,
            });
        }
    }
    (sources, missing)
}

/// The sources named (every one when `names` is empty; `cheap` picks the quick ones), in the
/// order of `all`, or why a name matches none (`missing` says why a source is not here).
pub fn select(
    all: &[Source],
    missing: &[(String, String)],
    names: &[String],
) -> Result<Vec<Source>, String> {
    for name in names {
        if !all.iter().any(|s| &s.name == name || name == "cheap") {
            if let Some((_, why)) = missing
                .iter()
                .find(|(m, _)| name.starts_with("mesa") && m == "mesa-backports")
            {
                return Err(format!("source `{name}`: {why}"));
            }
            return Err(format!(
                "unknown source `{name}` (sources: {}, or cheap)",
                all.iter()
                    .map(|s| s.name.as_str())
                    .collect::<Vec<_>>()
                    .join(", ")
            ));
        }
    }
    Ok(all
        .iter()
        .filter(|s| {
            names.is_empty()
                || names
                    .iter()
                    .any(|n| *n == s.name || (n == "cheap" && s.cheap))
        })
        .cloned()
        .collect())
}
