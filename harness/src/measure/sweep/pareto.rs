//! The Pareto front of settings over cost and error, and its SVG scatter plot.

/// Which points (cost, error) are on the Pareto front: no other point is at most as costly
/// and at most as wrong, and strictly better in one of the two.
pub fn pareto_front(points: &[(f64, f64)]) -> Vec<bool> {
    let points: Vec<Vec<f64>> = points.iter().map(|&(c, e)| vec![c, e]).collect();
    pareto_front_n(&points)
}

/// [`pareto_front`] over any number of criteria, each to be minimised: a point is on the front
/// when no other point is at most as large in every criterion and smaller in one.
pub fn pareto_front_n(points: &[Vec<f64>]) -> Vec<bool> {
    let dominates = |a: &[f64], b: &[f64]| {
        a.iter().zip(b).all(|(x, y)| x <= y) && a.iter().zip(b).any(|(x, y)| x < y)
    };
    points
        .iter()
        .map(|p| !points.iter().any(|q| dominates(q, p)))
        .collect()
}

/// An SVG scatter plot (plotters) of error against cost: every setting labelled, the Pareto
/// front joined and in green, the default ringed in orange.
pub fn pareto_svg(
    title: &str,
    x_label: &str,
    y_label: &str,
    points: &[(String, f64, f64, bool, bool)],
) -> String {
    use plotters::prelude::*;
    let mut svg = String::new();
    let drawn = (|| -> Result<(), Box<dyn std::error::Error>> {
        let root = SVGBackend::with_string(&mut svg, (480, 300)).into_drawing_area();
        root.fill(&WHITE)?;
        let finite = |v: f64| if v.is_finite() { v } else { 0.0 };
        let (x0, x1) = points.iter().fold((f64::MAX, f64::MIN), |(a, b), p| {
            (a.min(finite(p.1)), b.max(finite(p.1)))
        });
        let y1 = points.iter().map(|p| finite(p.2)).fold(0.0, f64::max);
        let pad = ((x1 - x0) * 0.08).max(1e-6);
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 14))
            .margin(10)
            .x_label_area_size(32)
            .y_label_area_size(56)
            .build_cartesian_2d((x0 - pad)..(x1 + pad), 0.0..(y1 * 1.1).max(1e-9))?;
        chart
            .configure_mesh()
            .x_desc(x_label)
            .y_desc(y_label)
            .label_style(("sans-serif", 10))
            .draw()?;
        let mut front: Vec<(f64, f64)> = points
            .iter()
            .filter(|p| p.3)
            .map(|p| (finite(p.1), finite(p.2)))
            .collect();
        front.sort_by(|a, b| a.0.total_cmp(&b.0));
        let green = RGBColor(34, 160, 102);
        chart.draw_series(LineSeries::new(front, green.stroke_width(2)))?;
        for (label, x, y, on_front, is_default) in points {
            let at = (finite(*x), finite(*y));
            let color = if *on_front {
                green
            } else {
                RGBColor(150, 150, 150)
            };
            chart.draw_series(std::iter::once(Circle::new(at, 4, color.filled())))?;
            if *is_default {
                chart.draw_series(std::iter::once(Circle::new(
                    at,
                    8,
                    RGBColor(204, 102, 0).stroke_width(2),
                )))?;
            }
            chart.draw_series(std::iter::once(Text::new(
                label.clone(),
                at,
                ("sans-serif", 9).into_font(),
            )))?;
        }
        root.present()?;
        Ok(())
    })();
    match drawn {
        Ok(()) => svg,
        Err(e) => format!("<p>plot failed: {e}</p>"),
    }
}
