//! The speed-against-error sweeps of the canonical scenes: the shadow and IBL sweeps as insta
//! snapshots of their errors (times vary run to run and are left out; errors are rounded so the
//! text is stable), and explicit bounds where a regression must fail whatever the snapshot
//! says: the IBL default's error against the Monte Carlo reference per material row and
//! roughness, and every G-buffer storage setting's p99 error. Run on `gl` (the numbers are that
//! driver's); skipped with a note where it is missing, unless `REQUIRE_BACKENDS` names it.

/// The IBL default's mean and 95th-percentile relative error against the Monte Carlo reference
/// (ibl scene, gl, Mesa 22.3.6 llvmpipe; 576 reference pixels, 19 to 31 per cell), per material
/// row and roughness, as measured: (row, roughness, mean, p95).
const IBL_DEFAULT_ERROR: &[(&str, f64, f64, f64)] = &[
    ("anisotropic", 0.0, 0.0235, 0.1016),
    ("anisotropic", 0.2, 0.5193, 1.3315),
    ("anisotropic", 0.4, 0.6409, 1.2207),
    ("anisotropic", 0.6, 0.5901, 1.4662),
    ("anisotropic", 0.8, 0.6410, 1.5767),
    ("anisotropic", 1.0, 1.0114, 1.8956),
    ("clearcoat", 0.0, 0.0303, 0.0975),
    ("clearcoat", 0.2, 0.0769, 0.7792),
    ("clearcoat", 0.4, 0.0447, 0.1430),
    ("clearcoat", 0.6, 0.0180, 0.0452),
    ("clearcoat", 0.8, 0.0577, 0.1775),
    ("clearcoat", 1.0, 0.0230, 0.0387),
    ("dielectric", 0.0, 0.0503, 0.1515),
    ("dielectric", 0.2, 0.0288, 0.1866),
    ("dielectric", 0.4, 0.0462, 0.2363),
    ("dielectric", 0.6, 0.0346, 0.1260),
    ("dielectric", 0.8, 0.0185, 0.0298),
    ("dielectric", 1.0, 0.0205, 0.0400),
    ("metal", 0.0, 0.0217, 0.1086),
    ("metal", 0.2, 0.1526, 0.3699),
    ("metal", 0.4, 0.1871, 0.7217),
    ("metal", 0.6, 0.3279, 1.0379),
    ("metal", 0.8, 0.1235, 0.2788),
    ("metal", 1.0, 0.0653, 0.1560),
];

/// IBL limit = margin x measured + slack: the reference is seeded and computed on the CPU, so
/// only the render moves between drivers, by far less than this (a 1-LSB change of the light
/// buffer is under 0.1% relative); a mean error 10% larger than today, plus half a percentage
/// point, is a regression. A p95 of about 24 pixels is their second largest, one pixel's
/// error, so its slack is a whole percentage point.
const IBL_MARGIN: f64 = 1.1;
const IBL_SLACK: f64 = 0.005;
const IBL_P95_SLACK: f64 = 0.01;

/// The G-buffer sweep's p99 relative error of the light buffer (chess, gl, Mesa 22.3.6
/// llvmpipe) per storage setting and distance from the origin, as measured.
const GBUFFER_P99: &[(&str, f64, f64)] = &[
    ("camera-relative/fp16", 0.0, 0.0),
    ("camera-relative/octahedral", 0.0, 8.91e-4),
    ("world/fp16", 0.0, 1.79e-3),
    ("world/octahedral", 0.0, 2.23e-3),
    ("depth/fp16", 0.0, 1.79e-3),
    ("depth/octahedral", 0.0, 2.23e-3),
    ("camera-relative/fp16", 1e3, 0.0),
    ("camera-relative/octahedral", 1e3, 8.91e-4),
    ("world/fp16", 1e3, 0.410),
    ("world/octahedral", 1e3, 0.410),
    ("depth/fp16", 1e3, 1.79e-3),
    ("depth/octahedral", 1e3, 2.23e-3),
    ("camera-relative/fp16", 1e4, 0.0),
    ("camera-relative/octahedral", 1e4, 8.91e-4),
    ("world/fp16", 1e4, 0.399),
    ("world/octahedral", 1e4, 0.399),
    ("depth/fp16", 1e4, 1.79e-3),
    ("depth/octahedral", 1e4, 2.23e-3),
];

/// G-buffer limit = margin x measured + slack, where the slack is one fp16 rounding step in
/// relative terms (2^-11): a p99 that doubles fails, as does any error where there was none.
const GBUFFER_MARGIN: f64 = 1.5;
const GBUFFER_SLACK: f64 = 4.9e-4;

use crate::common;
use engine::BackendKind;

fn gl_available() -> bool {
    common::available_backends().contains(&BackendKind::Gl)
}

#[test]
fn chess_shadow_sweep() {
    if !gl_available() {
        return;
    }
    // chess's sunset maps come from the IBL caches: the precompute is not under test here.
    harness::use_ibl_cache();
    let scene = harness::load_scene("chess").unwrap().scene;
    // The snapshot holds errors, not times: only the passes the shadow terms need are run.
    let rows = harness::measure::sweep::shadow_sweep_with(
        &scene,
        BackendKind::Gl,
        1,
        harness::measure::sweep::ShadowSweepCost::Untimed,
        |_| {},
    )
    .unwrap();
    assert!(
        rows.iter().any(|r| r.is_default),
        "the default setting is swept"
    );
    insta::assert_snapshot!(harness::measure::sweep::stable_table(&rows));
}

#[test]
fn ibl_sweep() {
    if !gl_available() {
        return;
    }
    // The maps come from the IBL caches: this test checks errors, not the precompute's cost,
    // and the cache is keyed by the environment, the settings and the maps' format version.
    harness::use_ibl_cache();
    let scene = harness::load_scene("ibl").unwrap().scene;
    let rows = harness::measure::sweep::ibl_sweep_with(
        &scene,
        BackendKind::Gl,
        1,
        harness::measure::sweep::MapSource::Cached,
        |_| {},
    )
    .unwrap();
    assert!(
        rows.iter().any(|r| r.is_default),
        "the default setting is swept"
    );
    insta::assert_snapshot!(harness::measure::sweep::stable_ibl_table(&rows));
    // The default's error against the Monte Carlo reference, mean and p95 per material row and
    // roughness, bounded by what it is today plus a margin.
    let default = rows.iter().find(|r| r.is_default).unwrap();
    let over = ibl_over_limits(default);
    assert!(over.is_empty(), "{}", over.join("\n"));
    // The bounds catch a real loss of accuracy: each cheaper setting of the sweep (fewer
    // samples, a coarser specular map, SH9 irradiance) breaks at least one of them.
    for row in rows.iter().filter(|r| !r.is_default) {
        let over = ibl_over_limits(row);
        eprintln!("{}: over the default's limits in {over:?}", row.setting);
        if [
            "64 samples",
            "specular 64",
            "specular 256",
            "sh9 irradiance",
        ]
        .contains(&row.setting.as_str())
        {
            assert!(
                !over.is_empty(),
                "{} passes the default's limits",
                row.setting
            );
        }
    }
    // The most accurate setting meets the goal in all 24 cells under ibl's own sky
    // (interior.exr; docs/renderer.md has sunset.exr's and an unseen sky's sweeps), and without
    // its three extracted suns the same sampling does not: the lamps are what was left.
    let best = rows
        .iter()
        .find(|r| r.setting == harness::measure::sweep::BEST_SETTING)
        .expect("the best setting is swept");
    assert_eq!(
        best.by_family.iter().map(|(_, c)| c.len()).sum::<usize>(),
        24
    );
    let over = over_the_goal(best);
    assert!(over.is_empty(), "{}", over.join("\n"));
    let fis_256 = rows.iter().find(|r| r.setting == "fis 256").unwrap();
    assert!(!over_the_goal(fis_256).is_empty());
}

/// Issue 39's goal for one setting: 5% mean and 15% p95 relative error in every cell.
const BEST_MEAN: f64 = 0.05;
const BEST_P95: f64 = 0.15;

/// The cells of `row` over [`BEST_MEAN`] or [`BEST_P95`].
fn over_the_goal(row: &harness::measure::sweep::IblSweepRow) -> Vec<String> {
    row.by_family
        .iter()
        .flat_map(|(family, cells)| cells.iter().map(move |c| (family, c)))
        .filter(|(_, c)| c.mean > BEST_MEAN || c.p95 > BEST_P95)
        .map(|(family, c)| {
            format!(
                "{family} r {}: mean {:.4}, p95 {:.4}",
                c.roughness, c.mean, c.p95
            )
        })
        .collect()
}

/// The cells of a sweep row whose mean or p95 error is over the limits of the default's.
fn ibl_over_limits(row: &harness::measure::sweep::IblSweepRow) -> Vec<String> {
    let mut over = Vec::new();
    for &(family, roughness, mean, p95) in IBL_DEFAULT_ERROR {
        let cells = &row
            .by_family
            .iter()
            .find(|(f, _)| f == family)
            .unwrap_or_else(|| panic!("no {family} row"))
            .1;
        let cell = cells
            .iter()
            .find(|c| (c.roughness - roughness).abs() < 1e-6)
            .unwrap_or_else(|| panic!("no {family} r {roughness}"));
        let limit = IBL_MARGIN * mean + IBL_SLACK;
        if cell.mean > limit {
            over.push(format!(
                "{family} r {roughness}: mean relative error {:.4} > {limit:.4}",
                cell.mean
            ));
        }
        let limit = IBL_MARGIN * p95 + IBL_P95_SLACK;
        if cell.p95 > limit {
            over.push(format!(
                "{family} r {roughness}: p95 relative error {:.4} > {limit:.4}",
                cell.p95
            ));
        }
    }
    over
}

#[test]
fn chess_gbuffer_sweep() {
    if !gl_available() {
        return;
    }
    // chess's sunset maps come from the IBL caches: the precompute is not under test here.
    harness::use_ibl_cache();
    let scene = harness::load_scene("chess").unwrap().scene;
    let rows = harness::measure::sweep::gbuffer_sweep(&scene, BackendKind::Gl, 1, |_| {}).unwrap();
    // The design's claim, measured: fp16 world positions break 10 km out (p99 error over 10%),
    // camera-relative positions do not move at all, and depth reconstruction stays within 1%.
    let at = |setting: &str, distance: f64| {
        rows.iter()
            .find(|r| r.setting == setting && r.distance == distance)
            .unwrap()
    };
    assert!(at("world/fp16", 1e4).p99_relative > 0.1);
    assert_eq!(at("camera-relative/fp16", 1e4).max_relative, 0.0);
    assert!(at("depth/fp16", 1e4).p99_relative < 0.01);
    // Every setting and distance bounded by its measured p99 plus a margin (0 stays 0).
    eprintln!("{}", harness::measure::sweep::stable_gbuffer_table(&rows));
    let mut over = Vec::new();
    for &(setting, distance, measured) in GBUFFER_P99 {
        let p99 = at(setting, distance).p99_relative;
        let limit = GBUFFER_MARGIN * measured + if measured > 0.0 { GBUFFER_SLACK } else { 0.0 };
        if p99 > limit {
            over.push(format!(
                "{setting} at {distance}: p99 {p99:.3e} > {limit:.3e}"
            ));
        }
    }
    assert!(over.is_empty(), "{}", over.join("\n"));
    assert_eq!(
        rows.len(),
        GBUFFER_P99.len(),
        "a setting or distance is not bounded"
    );
}
