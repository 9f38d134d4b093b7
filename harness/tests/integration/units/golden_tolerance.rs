//! Tests of `harness::golden::tolerance`.

use engine::backend::TextureFormat;
use engine::Image;
use engine::ImageData;
use harness::golden::tolerance::*;

fn rule(text: &str) -> Result<Rule, RuleError> {
    let value: toml::Value = toml::from_str::<toml::Table>(text).unwrap().into();
    Rule::from_toml(&value, "final")
}

fn gray(values: &[u8]) -> Image {
    Image {
        width: values.len() as u32,
        height: 1,
        format: TextureFormat::Rgba8UnormSrgb,
        data: ImageData::U8(values.iter().flat_map(|&v| [v, v, v, 255]).collect()),
    }
}

#[test]
fn all_and_any_combine_checks() {
    let golden = gray(&[10, 10, 10, 10]);
    let actual = gray(&[10, 10, 10, 30]);
    let strict = rule(
        r#"all = [{ metric = "max_abs", max = 0.01 }, { metric = "fraction_over", threshold = 0.01, max = 0.5 }]"#,
    )
    .unwrap();
    let verdict = strict.evaluate(&actual, &golden).unwrap();
    assert!(!verdict.passed);
    assert_eq!(verdict.checks.len(), 2);
    assert!(!verdict.checks[0].passed && verdict.checks[1].passed);
    let lenient = rule(
        r#"any = [{ metric = "max_abs", max = 0.01 }, { metric = "fraction_over", threshold = 0.01, max = 0.5 }]"#,
    )
    .unwrap();
    assert!(lenient.evaluate(&actual, &golden).unwrap().passed);
}

#[test]
fn psnr_is_a_lower_bound() {
    let golden = gray(&[10, 10]);
    let actual = gray(&[10, 11]);
    assert!(
        rule(
            r#"metric = "psnr"
min = 40"#
        )
        .unwrap()
        .evaluate(&actual, &golden)
        .unwrap()
        .passed
    );
    assert!(
        !rule(
            r#"metric = "psnr"
min = 60"#
        )
        .unwrap()
        .evaluate(&actual, &golden)
        .unwrap()
        .passed
    );
}

#[test]
fn bad_rules_are_named() {
    let e = rule(r#"metric = "max_abs""#).unwrap_err();
    assert!(e.to_string().contains("needs `max`"), "{e}");
    let e = rule(r#"metric = "fliip""#).unwrap_err();
    assert!(e.to_string().contains("unknown metric `fliip`"), "{e}");
    let e = rule(
        r#"metric = "rmse"
max = 1
shift = 1"#,
    )
    .unwrap_err();
    assert!(e.to_string().contains("unknown key `shift`"), "{e}");
    let e = rule(r#"all = [{ metric = "rmse" }]"#).unwrap_err();
    assert!(e.to_string().contains("final.all[0]"), "{e}");
    // A limit no render could meet, and a threshold every pixel is over.
    let e = rule("metric = \"flip_mean\"\nmax = -1").unwrap_err();
    assert!(e.to_string().contains("`max` -1 is negative"), "{e}");
    let e = rule("metric = \"fraction_over\"\nthreshold = -0.1\nmax = 0.01").unwrap_err();
    assert!(
        e.to_string().contains("`threshold` -0.1 is negative"),
        "{e}"
    );
    assert!(rule("metric = \"max_abs\"\nmax = 0").is_ok());
    // A limit no render could exceed: a fraction or a FLIP error at 1 or more.
    for metric in [
        "metric = \"flip_mean\"\nmax = 5",
        "metric = \"flip_percentile\"\npercentile = 0.99\nmax = 1",
        "metric = \"fraction_over\"\nthreshold = 0.01\nmax = 1.5",
    ] {
        let e = rule(metric).unwrap_err().to_string();
        assert!(
            e.contains("can never be exceeded") && e.contains("lies in 0..1"),
            "{e}"
        );
    }
    assert!(rule("metric = \"flip_mean\"\nmax = 0.99").is_ok());
    assert!(rule("metric = \"rmse\"\nmax = 5").is_ok());
}
