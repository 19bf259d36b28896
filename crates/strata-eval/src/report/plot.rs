//! SVG plots for the reports, drawn with `plotters`' SVG backend: grouped bars (per-pass GPU
//! times) and lines with markers (error against layers, flicker against frames). Each function
//! returns the SVG document as a string.

use anyhow::{anyhow, Result};
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;

/// Plot size in pixels.
pub const SIZE: (u32, u32) = (720, 360);

/// Series colours, in order (also the bars' fill, so tests can count bars by colour).
pub const COLOURS: [RGBColor; 6] = [
    RGBColor(0x1f, 0x77, 0xb4),
    RGBColor(0xff, 0x7f, 0x0e),
    RGBColor(0x2c, 0xa0, 0x2c),
    RGBColor(0xd6, 0x27, 0x28),
    RGBColor(0x94, 0x67, 0xbd),
    RGBColor(0x8c, 0x56, 0x4b),
];

/// Axis label font size, and the width of one of its characters as estimated for layout.
const LABEL_PX: u32 = 14;
const LABEL_CHAR_PX: f64 = 7.5;

fn err<E: std::fmt::Debug>(e: E) -> anyhow::Error {
    anyhow!("cannot draw the plot: {e:?}")
}

/// The upper end of a value axis: a little above the largest finite value (1 when there is none).
fn top(values: impl Iterator<Item = f64>) -> f64 {
    let max = values.filter(|v| v.is_finite()).fold(0.0f64, f64::max);
    if max > 0.0 {
        max * 1.15
    } else {
        1.0
    }
}

/// A white plot with a title, axis label areas `areas` px deep (under the x axis, left of
/// the y axis) and the ranges `x` × `y`.
fn chart<'a, 'b>(
    root: &'a DrawingArea<SVGBackend<'b>, plotters::coord::Shift>,
    title: &str,
    x: std::ops::Range<f64>,
    y: std::ops::Range<f64>,
    areas: (u32, u32),
) -> Result<ChartContext<'a, SVGBackend<'b>, Cartesian2d<RangedCoordf64, RangedCoordf64>>> {
    root.fill(&WHITE).map_err(err)?;
    ChartBuilder::on(root)
        .caption(title, ("sans-serif", 18))
        .margin(12)
        .x_label_area_size(areas.0)
        .y_label_area_size(areas.1)
        .build_cartesian_2d(x, y)
        .map_err(err)
}

/// The series' legend, upper right.
fn legend<'a, 'b: 'a, CT: CoordTranslate>(chart: &mut ChartContext<'a, SVGBackend<'b>, CT>) -> Result<()> {
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .position(SeriesLabelPosition::UpperRight)
        .draw()
        .map_err(err)
}

/// A grouped bar chart: one group per category, one bar per series (NaN bars are left out).
/// `series` holds `(name, one value per category)`; with more than one series, a legend.
/// Categories whose names do not fit under their group (many passes) are listed down the
/// left instead, with the bars running across, first category on top.
pub fn bars(title: &str, y_label: &str, categories: &[String], series: &[(String, Vec<f64>)]) -> Result<String> {
    let n = categories.len().max(1);
    let mut vmax = top(series.iter().flat_map(|(_, v)| v.iter().copied()));
    if series.len() > 1 {
        // room beyond the bars for the legend, upper right
        vmax *= 1.0 + 0.1 * series.len().min(6) as f64;
    }
    let longest = categories.iter().map(|c| c.chars().count()).max().unwrap_or(0) as f64 * LABEL_CHAR_PX;
    let across = longest + 8.0 > (SIZE.0 - 64 - 24) as f64 / n as f64;
    let groups = series.len().max(1) as f64;
    let width = 0.8 / groups;
    // category i's slot: down from the top when the bars run across
    let slot = |i: usize| if across { (n - 1 - i) as f64 } else { i as f64 };
    let label = |x: &f64| {
        let i = x.round();
        if (x - i).abs() < 1e-6 && i >= 0.0 && i < n as f64 {
            let i = i as usize;
            categories
                .get(if across { n - 1 - i } else { i })
                .cloned()
                .unwrap_or_default()
        } else {
            String::new()
        }
    };
    let size = if across {
        (
            SIZE.0,
            SIZE.1.max(100 + n as u32 * (8 + 6 * series.len().min(4) as u32)),
        )
    } else {
        SIZE
    };
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
        let slots = -0.5f64..(n as f64 - 0.5);
        let mut chart = if across {
            chart(&root, title, 0f64..vmax, slots, (40, longest as u32 + 16))?
        } else {
            chart(&root, title, slots, 0f64..vmax, (40, 64))?
        };
        let mut mesh = chart.configure_mesh();
        mesh.label_style(("sans-serif", LABEL_PX));
        if across {
            mesh.disable_y_mesh()
                .y_labels(n)
                .y_label_formatter(&label)
                .x_desc(y_label);
        } else {
            mesh.disable_x_mesh()
                .x_labels(n)
                .x_label_formatter(&label)
                .y_desc(y_label);
        }
        mesh.draw().map_err(err)?;
        for (s, (name, values)) in series.iter().enumerate() {
            let colour = COLOURS[s % COLOURS.len()];
            // series 0 on top in a group that runs across, leftmost in one that stands
            let offset = if across { groups - 1.0 - s as f64 } else { s as f64 };
            let bars = values.iter().enumerate().filter(|(_, v)| v.is_finite()).map(|(i, v)| {
                let c0 = slot(i) - 0.4 + offset * width;
                let corners = if across {
                    [(0.0, c0), (*v, c0 + width)]
                } else {
                    [(c0, 0.0), (c0 + width, *v)]
                };
                Rectangle::new(corners, colour.filled())
            });
            let drawn = chart.draw_series(bars).map_err(err)?;
            if series.len() > 1 {
                drawn
                    .label(name.as_str())
                    .legend(move |(x, y)| PathElement::new([(x, y), (x + 16, y)], colour.stroke_width(6)));
            }
        }
        if series.len() > 1 {
            legend(&mut chart)?;
        }
        root.present().map_err(err)?;
    }
    Ok(svg)
}

/// Lines with a marker at every point: `series` holds `(name, points (x, y))`; non-finite
/// points are left out. Integer x axes (layers, frames) get integer tick labels.
pub fn lines(title: &str, x_label: &str, y_label: &str, series: &[(String, Vec<(f64, f64)>)]) -> Result<String> {
    let finite = |p: &&(f64, f64)| p.0.is_finite() && p.1.is_finite();
    let xs: Vec<f64> = series
        .iter()
        .flat_map(|(_, p)| p.iter().filter(finite).map(|p| p.0))
        .collect();
    let (x0, x1) = match (xs.iter().copied().reduce(f64::min), xs.iter().copied().reduce(f64::max)) {
        (Some(a), Some(b)) if b > a => (a - 0.05 * (b - a), b + 0.05 * (b - a)),
        (Some(a), _) => (a - 0.5, a + 0.5),
        _ => (0.0, 1.0),
    };
    let ymax = top(series.iter().flat_map(|(_, p)| p.iter().map(|p| p.1)));
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, SIZE).into_drawing_area();
        let mut chart = chart(&root, title, x0..x1, 0f64..ymax, (40, 64))?;
        let integer_ticks = |x: &f64| {
            if (x - x.round()).abs() < 1e-6 {
                format!("{}", x.round())
            } else {
                String::new()
            }
        };
        chart
            .configure_mesh()
            .x_desc(x_label)
            .y_desc(y_label)
            .x_label_formatter(&integer_ticks)
            .label_style(("sans-serif", 14))
            .draw()
            .map_err(err)?;
        for (s, (name, points)) in series.iter().enumerate() {
            let colour = COLOURS[s % COLOURS.len()];
            let pts: Vec<(f64, f64)> = points.iter().filter(finite).copied().collect();
            chart
                .draw_series(LineSeries::new(pts.clone(), colour.stroke_width(2)))
                .map_err(err)?
                .label(name.as_str())
                .legend(move |(x, y)| PathElement::new([(x, y), (x + 16, y)], colour.stroke_width(2)));
            chart
                .draw_series(pts.into_iter().map(|p| Circle::new(p, 4, colour.filled())))
                .map_err(err)?;
        }
        legend(&mut chart)?;
        root.present().map_err(err)?;
    }
    Ok(svg)
}

/// Lines on log–log axes: `series` holds `(name, points (x, y))`; points that are not
/// positive and finite are left out. Series of up to 32 points get a marker at each.
pub fn log_lines(title: &str, x_label: &str, y_label: &str, series: &[(String, Vec<(f64, f64)>)]) -> Result<String> {
    let ok = |p: &&(f64, f64)| p.0 > 0.0 && p.1 > 0.0 && p.0.is_finite() && p.1.is_finite();
    let all: Vec<(f64, f64)> = series.iter().flat_map(|(_, p)| p.iter().filter(ok).copied()).collect();
    let range = |v: Vec<f64>| {
        let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = v.iter().copied().fold(0.0f64, f64::max);
        if lo.is_finite() && hi > lo {
            (lo / 1.25)..(hi * 1.25)
        } else if lo.is_finite() {
            (lo / 2.0)..(lo * 2.0)
        } else {
            1.0..10.0
        }
    };
    let (xs, ys) = (
        range(all.iter().map(|p| p.0).collect()),
        range(all.iter().map(|p| p.1).collect()),
    );
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, SIZE).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 18))
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(64)
            .build_cartesian_2d(xs.log_scale(), ys.log_scale())
            .map_err(err)?;
        // labels at 1, 2 and 5 × a power of ten only, in plain numbers
        let tick = |v: &f64| {
            let mantissa = v / 10f64.powf(v.log10().floor());
            if ![1.0, 2.0, 5.0].iter().any(|m| (mantissa - m).abs() < 1e-6) {
                String::new()
            } else if *v >= 1.0 {
                format!("{}", v.round())
            } else {
                super::sig4(*v).trim_end_matches('0').to_string()
            }
        };
        chart
            .configure_mesh()
            .x_desc(x_label)
            .y_desc(y_label)
            .x_labels(30)
            .y_labels(30)
            .x_label_formatter(&tick)
            .y_label_formatter(&tick)
            .light_line_style(WHITE)
            .label_style(("sans-serif", LABEL_PX))
            .draw()
            .map_err(err)?;
        for (s, (name, points)) in series.iter().enumerate() {
            let colour = COLOURS[s % COLOURS.len()];
            let pts: Vec<(f64, f64)> = points.iter().filter(ok).copied().collect();
            let marked = pts.len() <= 32;
            chart
                .draw_series(LineSeries::new(pts.clone(), colour.stroke_width(2)))
                .map_err(err)?
                .label(name.as_str())
                .legend(move |(x, y)| PathElement::new([(x, y), (x + 16, y)], colour.stroke_width(2)));
            if marked {
                chart
                    .draw_series(pts.into_iter().map(|p| Circle::new(p, 3, colour.filled())))
                    .map_err(err)?;
            }
        }
        legend(&mut chart)?;
        root.present().map_err(err)?;
    }
    Ok(svg)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `<rect` elements filled with series colour `s`.
    fn filled_rects(svg: &str, s: usize) -> usize {
        let c = COLOURS[s];
        let fill = format!("fill=\"#{:02X}{:02X}{:02X}\"", c.0, c.1, c.2);
        svg.lines().filter(|l| l.contains("<rect") && l.contains(&fill)).count()
    }

    fn is_svg(svg: &str) {
        assert!(svg.trim_start().starts_with("<svg"), "{}", &svg[..svg.len().min(200)]);
        assert!(svg.trim_end().ends_with("</svg>"));
        assert!(svg.contains("xmlns=\"http://www.w3.org/2000/svg\""));
    }

    #[test]
    fn bar_chart_has_one_bar_per_value() {
        let cats: Vec<String> = ["depth-mip", "ao", "ao-blur-h"].iter().map(|s| s.to_string()).collect();
        let svg = bars(
            "AO passes <k & 1>",
            "ms",
            &cats,
            &[("k = 2".into(), vec![0.1, 0.5, 0.2])],
        )
        .unwrap();
        is_svg(&svg);
        assert_eq!(filled_rects(&svg, 0), 3, "{svg}");
        for c in &cats {
            assert!(svg.contains(&format!("\n{c}\n")), "label {c} missing");
        }
        assert!(svg.contains("AO passes &lt;k &amp; 1&gt;"), "text is escaped");
    }

    #[test]
    fn grouped_bars_skip_missing_values_and_have_a_legend() {
        let cats: Vec<String> = ["a", "b", "c", "d"].iter().map(|s| s.to_string()).collect();
        let svg = bars(
            "t",
            "ms",
            &cats,
            &[
                ("k = 2".into(), vec![1.0, 2.0, 3.0, 4.0]),
                ("k = 1".into(), vec![0.5, f64::NAN, 1.5, 2.0]),
            ],
        )
        .unwrap();
        is_svg(&svg);
        assert_eq!(filled_rects(&svg, 0), 4);
        assert_eq!(filled_rects(&svg, 1), 3);
        assert!(svg.contains("k = 1") && svg.contains("k = 2"));
    }

    /// Names too long for their group (many passes) go down the left, with the bars running
    /// across in category order from the top, each as long as its value.
    #[test]
    fn many_long_categories_run_across_in_order() {
        let cats: Vec<String> = (0..12).map(|i| format!("bzb-gi-glossy-pass-{i}")).collect();
        let values: Vec<f64> = (1..=12).map(f64::from).collect();
        let svg = bars("t", "ms", &cats, &[("median".into(), values)]).unwrap();
        is_svg(&svg);
        let c = COLOURS[0];
        let fill = format!("fill=\"#{:02X}{:02X}{:02X}\"", c.0, c.1, c.2);
        let attr = |l: &str, a: &str| -> f64 {
            let at = l.find(&format!(" {a}=\"")).unwrap() + a.len() + 3;
            l[at..].split('"').next().unwrap().parse().unwrap()
        };
        let rects: Vec<(f64, f64)> = svg
            .lines()
            .filter(|l| l.contains("<rect") && l.contains(&fill))
            .map(|l| (attr(l, "y"), attr(l, "width")))
            .collect();
        assert_eq!(rects.len(), 12);
        for w in rects.windows(2) {
            assert!(w[1].0 > w[0].0, "category order runs down: {rects:?}");
            assert!(w[1].1 > w[0].1, "longer bars for larger values: {rects:?}");
        }
        for c in &cats {
            assert!(svg.contains(&format!("\n{c}\n")), "label {c} missing");
        }
    }

    #[test]
    fn line_chart_marks_every_point() {
        let svg = lines(
            "error vs layers",
            "layers k",
            "error",
            &[
                ("FLIP".into(), vec![(1.0, 0.2), (2.0, 0.1), (3.0, 0.08)]),
                ("MAE".into(), vec![(1.0, 0.05), (2.0, f64::NAN), (3.0, 0.02)]),
            ],
        )
        .unwrap();
        is_svg(&svg);
        assert_eq!(svg.matches("<circle").count(), 5, "{svg}");
        assert!(svg.contains("<polyline"));
        assert!(svg.contains("layers k") && svg.contains("FLIP") && svg.contains("MAE"));
        // a single point still gives a valid plot
        is_svg(&lines("one", "k", "e", &[("FLIP".into(), vec![(1.0, 0.2)])]).unwrap());
    }
}
