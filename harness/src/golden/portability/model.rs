//! From measurements to figures: the noise model (the largest value per source and backend,
//! and the limit it gives), the worst `value / limit` per source, and the table of them.

use std::collections::BTreeMap;

use engine::backend::BackendKind;
use engine::plan::TargetId;

use super::measuring::{Measurement, Missed};
use crate::golden::noise::{
    resolution, round_up, CheckFigures, NoiseModel, SceneFigures, MAX_NOISE_RATIO, REGENERATE,
};
use crate::golden::suite::Case;

/// A table of `ratios`: a row per scene, pass and metric, a numbered column per source holding
/// the worst `value / limit` over backends (`!` above [`MAX_NOISE_RATIO`], `X` above 1), then
/// the limit.
pub fn table(ratios: &[Ratio], sources: &[String]) -> String {
    // (scene, pass, metric) -> (limit, ratio per source).
    type Row = (f64, BTreeMap<String, f64>);
    let mut rows: BTreeMap<(String, TargetId, String), Row> = BTreeMap::new();
    for r in ratios {
        let row = rows
            .entry((r.scene.clone(), r.pass, r.metric.clone()))
            .or_insert((r.limit, BTreeMap::new()));
        row.1.insert(r.source.clone(), r.ratio);
    }
    // Columns are numbered, with a legend above: source names are too long for a column.
    let mut out = String::from("sources:");
    for (i, s) in sources.iter().enumerate() {
        out.push_str(&format!(" [{}] {s}", i + 1));
    }
    out.push('\n');
    out.push_str(&format!("{:<8} {:<17} {:<44}", "scene", "pass", "metric"));
    for i in 0..sources.len() {
        out.push_str(&format!(" {:>7}", format!("[{}]", i + 1)));
    }
    out.push_str("  limit\n");
    for ((scene, pass, metric), (limit, cells)) in rows {
        out.push_str(&format!("{scene:<8} {pass:<17} {metric:<44}"));
        for s in sources {
            let cell = match cells.get(s) {
                None => "-".to_owned(),
                Some(&r) if r > 1.0 => format!("X{r:.2}"),
                Some(&r) if r > MAX_NOISE_RATIO => format!("!{r:.2}"),
                Some(&r) => format!("{r:.2}"),
            };
            out.push_str(&format!(" {cell:>7}"));
        }
        out.push_str(&format!("  {limit:.3e}\n"));
    }
    out.push_str(&format!(
        "cells: worst value / limit over backends; ! above {MAX_NOISE_RATIO}, X above 1 (fails)\n"
    ));
    out
}

/// The model the measurements give: per scene, pass and metric the largest value per
/// `<source>/<backend>`, and the limit `margin x max(noise, resolution)`. Scenes of `previous`
/// that were not measured are kept as they were, with their known crashes.
pub fn build_model(
    cases: &[Case],
    measurements: &[Measurement],
    margin: f64,
    sources: BTreeMap<String, String>,
    missed: &[Missed],
    previous: &NoiseModel,
) -> NoiseModel {
    // Keys are `<source>/<backend>/<scene>`: a measured scene's crashes are this run's.
    let measured = |key: &str| {
        let scene = key.rsplit('/').next().unwrap_or_default();
        cases.iter().any(|c| c.name() == scene)
    };
    let kept_crashes = previous
        .known_crashes
        .iter()
        .filter(|(key, _)| !measured(key))
        .map(|(key, why)| (key.clone(), why.clone()));
    let new_crashes = missed.iter().filter(|m| m.known).map(|m| {
        (
            format!("{}/{}/{}", m.source, m.backend, m.scene),
            m.error.clone(),
        )
    });
    // A run limited to some scenes keeps the descriptions of the last full run for the sources
    // it knows: such a run may not reach every backend (a known crash on its scenes), and the
    // descriptions document the drivers of the whole measurement.
    let partial = previous
        .scenes
        .keys()
        .any(|scene| !cases.iter().any(|c| c.name() == scene));
    let mut sources = sources;
    if partial {
        for (name, description) in &previous.sources {
            sources.insert(name.clone(), description.clone());
        }
    }
    let mut model = NoiseModel {
        margin,
        regenerate: REGENERATE.to_owned(),
        sources,
        known_crashes: kept_crashes.chain(new_crashes).collect(),
        scenes: previous.scenes.clone(),
    };
    for case in cases {
        let mut passes = SceneFigures::new();
        for &pass in &case.passes {
            let pixels = case.pixels(pass);
            let mut checks = BTreeMap::new();
            for (metric, _) in case.rules[&pass].checks() {
                let key = metric.to_string();
                let mut noise = BTreeMap::new();
                for m in measurements
                    .iter()
                    .filter(|m| m.scene == case.name() && m.pass == pass)
                {
                    if let Some((_, v)) = m.values.iter().find(|(k, _)| *k == key) {
                        let slot = noise
                            .entry(format!(
                                "{}/{}",
                                m.source,
                                m.backend.map_or("-", BackendKind::name)
                            ))
                            .or_insert(0.0f64);
                        *slot = slot.max(*v);
                    }
                }
                let resolution = resolution(metric, pixels);
                let worst = noise.values().fold(0.0f64, |m, &v| m.max(v));
                checks.insert(
                    key,
                    CheckFigures {
                        limit: round_up(margin * worst.max(resolution)),
                        resolution,
                        noise,
                    },
                );
            }
            passes.insert(pass.to_string(), checks);
        }
        model.scenes.insert(case.name().to_owned(), passes);
    }
    model
}

/// The worst `value / limit` of each `(source, scene, pass)` over backends and metrics, with the
/// limits of `cases`' rules.
pub fn ratios(cases: &[Case], measurements: &[Measurement]) -> Vec<Ratio> {
    let mut out: BTreeMap<(String, String, TargetId, String), Ratio> = BTreeMap::new();
    for m in measurements {
        let Some(case) = cases.iter().find(|c| c.name() == m.scene) else {
            continue;
        };
        let Some(rule) = case.rules.get(&m.pass) else {
            continue;
        };
        for (metric, limit) in rule.checks() {
            let key = metric.to_string();
            let Some((_, value)) = m.values.iter().find(|(k, _)| *k == key) else {
                continue;
            };
            let ratio = crate::golden::tolerance::ratio(*value, limit, false);
            let entry = out
                .entry((m.source.clone(), m.scene.clone(), m.pass, key.clone()))
                .or_insert(Ratio {
                    source: m.source.clone(),
                    scene: m.scene.clone(),
                    pass: m.pass,
                    metric: key.clone(),
                    backend: m.backend,
                    value: *value,
                    limit,
                    ratio,
                });
            if ratio > entry.ratio {
                entry.ratio = ratio;
                entry.value = *value;
                entry.backend = m.backend;
            }
        }
    }
    out.into_values().collect()
}

/// One source's worst measurement of one check against its limit.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Ratio {
    /// Source.
    pub source: String,
    /// Scene.
    pub scene: String,
    /// Pass.
    pub pass: TargetId,
    /// Metric, as printed.
    pub metric: String,
    /// The backend with the worst value (none, `-` in JSON, for synthetic rounding).
    #[serde(serialize_with = "crate::backend_or_dash")]
    pub backend: Option<BackendKind>,
    /// The worst value.
    pub value: f64,
    /// The limit.
    pub limit: f64,
    /// value / limit.
    pub ratio: f64,
}
