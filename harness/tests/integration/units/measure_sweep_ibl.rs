//! Tests of `harness::measure::sweep::ibl`.

use harness::measure::sweep::ibl::*;

#[test]
fn the_specular_cube_holds_six_rgba16f_faces_per_level_down_to_4x4() {
    let cube = |specular_size| engine::ibl::IblSettings {
        specular_size,
        ..Default::default()
    };
    // 128, 64, 32, 16, 8 and 4: 21,840 texels a face.
    let bytes = 6.0 * 8.0 * 21_840.0;
    assert_eq!(specular_mib(&cube(128)), bytes / f64::from(1u32 << 20));
    assert!((specular_mib(&cube(512)) / specular_mib(&cube(256)) - 4.0).abs() < 1e-3);
}

#[test]
fn a_tried_setting_reads_the_keys_of_quality_ibl_and_defaults_the_rest() {
    let tried = parse_tried_setting(
        r#"extract_sun = true, extracted_lights = 2, dominant_direction = "frostbite""#,
    )
    .unwrap();
    assert_eq!(
        tried,
        engine::ibl::IblSettings {
            extract_sun: true,
            extracted_lights: 2,
            dominant_direction: engine::ibl::DominantDirection::Frostbite,
            ..Default::default()
        }
    );
    assert_eq!(parse_tried_setting("").unwrap(), Default::default());
}

#[test]
fn a_tried_setting_that_is_not_one_says_what_is_wrong() {
    let unknown = parse_tried_setting("samples = 4").unwrap_err();
    assert!(unknown.contains("unknown field `samples`"), "{unknown}");
    let malformed = parse_tried_setting("runtime_samples = ").unwrap_err();
    assert!(
        malformed.starts_with("not a [quality.ibl] setting"),
        "{malformed}"
    );
    // Parsed, then refused by the scene file's own checks.
    let out_of_range = parse_tried_setting("runtime_samples = 4096").unwrap_err();
    assert!(out_of_range.contains("at most 1024"), "{out_of_range}");
}

#[test]
fn the_sweep_visits_the_default_and_what_was_chosen() {
    let names = |choice: &IblSweepChoice| -> Vec<String> {
        choice
            .settings()
            .into_iter()
            .map(|(name, _)| name)
            .collect()
    };
    let everything = names(&IblSweepChoice::default());
    assert!(everything.len() > 20, "{everything:?}");
    assert_eq!(everything[0], "default");
    let frostbite = IblSweepChoice {
        only: vec!["frostbite".to_owned()],
        tried: Vec::new(),
    };
    let chosen = names(&frostbite);
    assert_eq!(chosen[0], "default");
    assert!(chosen.len() > 2, "{chosen:?}");
    assert!(
        chosen[1..].iter().all(|n| n.contains("frostbite")),
        "{chosen:?}"
    );
    let text = "anisotropic_samples = 6";
    let tried = IblSweepChoice {
        only: Vec::new(),
        tried: vec![(text.to_owned(), parse_tried_setting(text).unwrap())],
    };
    assert_eq!(names(&tried), ["default", text]);
}

/// A row of the IBL sweep with every cell at `worst` mean error and `lighting_ms`.
fn row(setting: &str, is_default: bool, lighting_ms: f64, worst: f64) -> IblSweepRow {
    let cell = |mean: f64| harness::reference::ibl::CellError {
        roughness: 0.5,
        mean,
        p95: mean * 2.0,
        bias: 0.0,
        pixels: 10,
    };
    IblSweepRow {
        setting: setting.to_owned(),
        settings: engine::ibl::IblSettings::default(),
        precompute_s: 1.0,
        lighting_ms: Some(lighting_ms),
        specular_mib: 1.0,
        by_roughness: Vec::new(),
        mean_relative: worst,
        p99_max_relative: (worst, worst),
        by_family: vec![("metal".to_owned(), vec![cell(worst / 2.0), cell(worst)])],
        is_default,
        pareto: false,
    }
}

#[test]
fn the_default_bound_weighs_each_setting_against_the_default_rows_lighting_time() {
    use harness::measure::sweep::ibl_default_goal_line;
    // The default misses (40%); a setting at x1.4 is within 25%; one at x2 is more accurate.
    let rows = [
        row("default", true, 10.0, 0.40),
        row("cheap", false, 14.0, 0.20),
        row("dear", false, 20.0, 0.05),
    ];
    let line = ibl_default_goal_line(&rows);
    assert!(line.ends_with("met by cheap (x1.40)"), "{line}");
    let line = ibl_default_goal_line(&[rows[0].clone(), rows[2].clone()]);
    assert!(
        line.ends_with(
            "met by none; cheapest within the error: dear (x2.00); most accurate within the \
             cost: default (40.0%)"
        ),
        "{line}"
    );
}
