//! The self-test's findings as text: the margin table of the mutations and the noise table of
//! the unchanged renders.

use engine::backend::BackendKind;

use super::{Mutation, MutationResult, SelfTest};
use crate::golden::noise::{MAX_NOISE_RATIO, MIN_MUTATION_RATIO};

impl SelfTest {
    /// The backends named in the findings, in order of first appearance.
    fn backends(&self) -> Vec<BackendKind> {
        let mut backends: Vec<BackendKind> = Vec::new();
        for b in self
            .mutations
            .iter()
            .map(|m| m.backend)
            .chain(self.noise.iter().filter_map(|n| n.backend))
        {
            if !backends.contains(&b) {
                backends.push(b);
            }
        }
        backends
    }

    /// The margin table: per mutation and scene, the originating pass's `value / limit` on
    /// every backend (at least [`MIN_MUTATION_RATIO`] to pass), and the other passes it failed.
    pub fn margin_table(&self) -> String {
        let backends = self.backends();
        let mut out = format!("{:<34} {:<7} {:<17}", "mutation", "scene", "origin pass");
        for b in &backends {
            out.push_str(&format!(" {b:>11}"));
        }
        out.push_str("  also failing\n");
        let mut keys: Vec<(Mutation, &str)> = self
            .mutations
            .iter()
            .map(|m| (m.mutation, m.scene.as_str()))
            .collect();
        keys.sort();
        keys.dedup();
        for (mutation, scene) in keys {
            let rows: Vec<&MutationResult> = self
                .mutations
                .iter()
                .filter(|m| m.mutation == mutation && m.scene == scene)
                .collect();
            out.push_str(&format!(
                "{:<34} {scene:<7} {:<17}",
                mutation.describe(),
                if mutation == Mutation::ShadowBias {
                    "shadow_term_*".to_owned()
                } else {
                    mutation.origin().to_string()
                }
            ));
            if !rows.iter().any(|m| m.applies) {
                out.push_str(" n/a\n");
                continue;
            }
            let mut also = Vec::new();
            for b in &backends {
                let cell = match rows.iter().find(|m| m.backend == *b) {
                    None => "-".to_owned(),
                    Some(m) if m.error.is_some() => "ERROR".to_owned(),
                    Some(m) => {
                        for p in m.also_failing() {
                            if !also.contains(&p) {
                                also.push(p);
                            }
                        }
                        match m.origin_ratio() {
                            None => "no golden".to_owned(),
                            Some(r) if r < MIN_MUTATION_RATIO => format!("WEAK {}", ratio(r)),
                            Some(r) => ratio(r),
                        }
                    }
                };
                out.push_str(&format!(" {cell:>11}"));
            }
            let also: Vec<String> = also.iter().map(ToString::to_string).collect();
            out.push_str(&format!("  {}\n", also.join(",")));
        }
        out
    }

    /// The noise table: per source and scene, the worst `value / limit` over every pass on each
    /// backend (at most [`MAX_NOISE_RATIO`] to pass), with the pass it was in.
    pub fn noise_table(&self) -> String {
        let backends = self.backends();
        let mut out = format!("{:<28} {:<7}", "unchanged render, source", "scene");
        let columns: Vec<Option<BackendKind>> =
            backends.iter().copied().map(Some).chain([None]).collect();
        for b in &columns {
            out.push_str(&format!(
                " {:>26}",
                b.map_or("(no backend)", BackendKind::name)
            ));
        }
        out.push('\n');
        let mut keys: Vec<(&str, &str, bool)> = self
            .noise
            .iter()
            .map(|n| (n.source.as_str(), n.scene.as_str(), n.live))
            .collect();
        keys.sort_by_key(|k| (!k.2, k.0, k.1));
        keys.dedup();
        for (source, scene, live) in keys {
            let label = if live {
                format!("{source} (live)")
            } else {
                source.to_owned()
            };
            out.push_str(&format!("{label:<28} {scene:<7}"));
            for b in &columns {
                let worst = self
                    .noise
                    .iter()
                    .filter(|n| n.source == source && n.scene == scene && n.backend == *b)
                    .max_by(|x, y| x.ratio.total_cmp(&y.ratio));
                let cell = worst.map_or("-".to_owned(), |n| {
                    if n.ratio == 0.0 {
                        return "0".to_owned();
                    }
                    format!(
                        "{}{} {}",
                        if n.ratio > MAX_NOISE_RATIO {
                            "HIGH "
                        } else {
                            ""
                        },
                        ratio(n.ratio),
                        n.pass
                    )
                });
                out.push_str(&format!(" {cell:>26}"));
            }
            out.push('\n');
        }
        out
    }
}

/// A ratio as the tables print it (`0.42x`, `12.3x`, `150x`).
fn ratio(r: f64) -> String {
    if r >= 100.0 {
        format!("{r:.0}x")
    } else if r >= 10.0 {
        format!("{r:.1}x")
    } else {
        format!("{r:.2}x")
    }
}
