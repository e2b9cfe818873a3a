//! Log-log plots for the benchmark reports (plotters, bitmap backend).

use plotters::prelude::*;
use std::path::Path;

/// Registers DejaVu Sans for labels when the system has it; without it the
/// plot is drawn without text rather than failing.
fn font_available() -> bool {
    const FONTS: [&str; 2] = [
        "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf",
        "/usr/share/fonts/dejavu/DejaVuSans.ttf",
    ];
    for path in FONTS {
        if let Ok(bytes) = std::fs::read(path) {
            // The font must outlive the process' plotting: leak it once.
            let bytes: &'static [u8] = Box::leak(bytes.into_boxed_slice());
            if plotters::style::register_font("sans-serif", FontStyle::Normal, bytes).is_ok() {
                return true;
            }
        }
    }
    false
}

/// RMSE against seconds, one line per configuration, both axes logarithmic.
pub fn error_vs_time(
    path: &Path,
    series: &[(String, Vec<(f64, f64)>)],
) -> Result<(), Box<dyn std::error::Error>> {
    let text = font_available();
    let pts = series
        .iter()
        .flat_map(|(_, p)| p.iter())
        .filter(|(t, e)| *t > 0.0 && *e > 0.0);
    let (mut t0, mut t1, mut e0, mut e1) = (f64::INFINITY, 0f64, f64::INFINITY, 0f64);
    for &(t, e) in pts {
        t0 = t0.min(t);
        t1 = t1.max(t);
        e0 = e0.min(e);
        e1 = e1.max(e);
    }
    if !(t0 < t1 && e0 < e1) {
        return Err("nothing to plot".into());
    }
    let tmp = path.with_extension("tmp.png");
    {
        let root = BitMapBackend::new(&tmp, (1100, 760)).into_drawing_area();
        root.fill(&WHITE)?;
        let mut builder = ChartBuilder::on(&root);
        builder.margin(20);
        if text {
            builder
                .caption("RMSE against render time", ("sans-serif", 26))
                .x_label_area_size(45)
                .y_label_area_size(70);
        }
        let mut chart = builder.build_cartesian_2d(
            (t0 * 0.8..t1 * 1.25).log_scale(),
            (e0 * 0.8..e1 * 1.25).log_scale(),
        )?;
        if text {
            chart
                .configure_mesh()
                .x_desc("seconds")
                .y_desc("RMSE")
                .x_label_formatter(&tick)
                .y_label_formatter(&tick)
                .draw()?;
        } else {
            chart
                .configure_mesh()
                .disable_x_mesh()
                .disable_y_mesh()
                .draw()?;
        }
        for (i, (name, points)) in series.iter().enumerate() {
            let colour = Palette99::pick(i).to_rgba();
            let style = ShapeStyle {
                color: colour,
                filled: true,
                stroke_width: 2,
            };
            let pts: Vec<(f64, f64)> = points
                .iter()
                .copied()
                .filter(|(t, e)| *t > 0.0 && *e > 0.0)
                .collect();
            let line = chart.draw_series(LineSeries::new(pts.clone(), style))?;
            if text {
                line.label(name.clone())
                    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], style));
            }
            chart.draw_series(pts.iter().map(|&p| Circle::new(p, 3, style)))?;
        }
        if text {
            chart
                .configure_series_labels()
                // Errors fall to the lower right: the lower left stays clear.
                .position(SeriesLabelPosition::LowerLeft)
                .background_style(WHITE.mix(0.85))
                .border_style(BLACK)
                .label_font(("sans-serif", 13))
                .draw()?;
        }
        root.present()?;
    }
    std::fs::rename(&tmp, path)?;
    Ok(())
}

/// A tick label with three significant digits and no trailing zeros (a
/// log axis's ticks are products like 0.009000000001 otherwise).
fn tick(v: &f64) -> String {
    if *v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let decimals = (2 - v.abs().log10().floor() as i32).max(0) as usize;
    let s = format!("{v:.decimals$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn ticks_have_three_significant_digits_at_most() {
        let cases = [
            (0.009000000001, "0.009"),
            (0.25, "0.25"),
            (1.0, "1"),
            (10.0, "10"),
            (0.00123456, "0.00123"),
            (2500.0, "2500"),
        ];
        for (v, want) in cases {
            assert_eq!(super::tick(&v), want, "{v}");
        }
    }
}
