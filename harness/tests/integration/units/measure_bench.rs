//! Tests of `harness::measure::bench`.

use harness::measure::bench::*;
#[test]
fn series_plots_have_a_point_per_value() {
    let points: Vec<SeriesPoint> = [(1u64, 1.0), (8, 3.0), (64, 20.0)]
        .into_iter()
        .map(|(value, ms)| SeriesPoint {
            series: Series::Lights,
            value,
            pass: engine::plan::PassId::Lighting(engine::scene::LightingModel::Pbr),
            pass_ms: Some(ms),
            frame_ms: Some(ms + 1.0),
        })
        .collect();
    let svg = series_svg(&points);
    assert_eq!(svg.matches("<circle").count(), 3);
    assert!(svg.contains("lighting_pbr ms against lights"));
    let table = series_table(&points);
    assert!(table.contains("8.0") && table.contains("6.67"), "{table}");
}
