//! Tables and plots of benchmark and evaluation results: errors by layer count (rows k, columns
//! FLIP / RMSE / MAE / flicker) with an error-vs-layers plot and a flicker-over-frames plot;
//! per-pass GPU times (rows passes, columns median / min ms) with a bar plot. Plots are written
//! as SVG files into the page's folder, named `{prefix}{what}.svg`.

use std::path::Path;

use anyhow::Result;
use serde::Serialize;

use super::{plot, write_file, Cell, ReportImage, Section, Table};
use crate::eval::views::ViewsEval;
use crate::metrics::ErrorStats;
use crate::results::{
    BenchResult, DeepBench, EvalResult, EvalRun, Fig10, IlsEval, IlsProgressive, PassTime, StageBench,
};

/// Writes `svg` as `dir/file` and returns the figure that shows it.
fn plot_file(dir: &Path, file: String, svg: String, caption: String) -> Result<ReportImage> {
    write_file(&dir.join(&file), svg.as_bytes())?;
    Ok(ReportImage { caption, file })
}

/// A `name | value` table of `v`'s fields other than `skip` (the settings of a run).
fn settings_table<T: Serialize>(caption: &str, v: &T, skip: &[&str]) -> Result<Table> {
    let mut v = serde_json::to_value(v)?;
    if let Some(m) = v.as_object_mut() {
        m.retain(|k, _| !skip.contains(&k.as_str()));
    }
    Ok(Table::key_values(caption, &v))
}

const AO_HEADER: [&str; 7] = [
    "layers k",
    "FLIP",
    "RMSE",
    "MAE",
    "FLIP vs binary",
    "MAE vs binary",
    "flicker",
];

const OIT_HEADER: [&str; 5] = ["layers k", "FLIP", "RMSE", "MAE", "flicker"];

const GI_HEADER: [&str; 9] = [
    "layers k",
    "indirect FLIP",
    "indirect RMSE",
    "indirect MAE",
    "indirect mean / reference's",
    "full FLIP",
    "full RMSE",
    "full MAE",
    "flicker",
];

/// One row of an error table: the label (a layer count, or a configuration of a side-by-side
/// evaluation), then the cells.
struct ErrorRow {
    label: String,
    /// The layer count, for the error-against-layers plot (`None`: a configuration).
    layers: Option<u32>,
    cells: Vec<Cell>,
    /// (FLIP, MAE) for the plot.
    flip_mae: (f32, f32),
}

impl ErrorRow {
    fn layers(layers: u32, cells: Vec<Cell>, flip_mae: (f32, f32)) -> Self {
        Self {
            label: layers.to_string(),
            layers: Some(layers),
            cells,
            flip_mae,
        }
    }

    fn configuration(label: &str, cells: Vec<Cell>, flip_mae: (f32, f32)) -> Self {
        Self {
            label: label.into(),
            layers: None,
            cells,
            flip_mae,
        }
    }
}

/// The cells of an AO row: the errors against the obscurance, then against binary AO.
fn ao_cells(x: &crate::results::AoErrors) -> Vec<Cell> {
    [
        stats_cells(&x.obscurance),
        vec![x.binary.flip.into(), x.binary.mae.into()],
    ]
    .concat()
}

fn stats_cells(s: &ErrorStats) -> Vec<Cell> {
    vec![s.flip.into(), s.rmse.into(), s.mae.into()]
}

/// The cells of a GI row: the indirect light's errors and brightness bias, then the
/// full image's errors.
fn gi_cells(x: &crate::results::GiErrors) -> Vec<Cell> {
    [
        stats_cells(&x.indirect),
        vec![x.indirect.mean_ratio.into()],
        stats_cells(&x.full),
    ]
    .concat()
}

/// Sections of an evaluation: its settings, the errors by layer count, DGB Fig. 10 when
/// present, and the plots.
pub fn eval_sections(r: &EvalResult, dir: &Path, prefix: &str) -> Result<Vec<Section>> {
    let run = r.run();
    let ao_row = |label: &str, x: &crate::results::AoErrors| {
        ErrorRow::configuration(label, ao_cells(x), (x.obscurance.flip, x.obscurance.mae))
    };
    let gi_row = |label: &str, x: &crate::results::GiErrors| {
        ErrorRow::configuration(label, gi_cells(x), (x.indirect.flip, x.indirect.mae))
    };
    let (what, header, rows, fig10): (_, &[&str], Vec<ErrorRow>, Option<&Fig10>) = match r {
        // the side-by-side evaluations: one row per configuration
        EvalResult::Bzb(e) => {
            let mut rows = vec![ao_row("bzb-ao", &e.errors)];
            rows.extend(e.no_visibility.as_ref().map(|x| ao_row("visibility=off (additive)", x)));
            rows.extend(e.dgb_2_layers.as_ref().map(|x| ao_row("DGB AO, 2 layers", x)));
            ("AO against the ray-traced obscurance", &AO_HEADER[..], rows, None)
        }
        EvalResult::AbaAo(e) => {
            let mut rows = vec![ao_row("aba-ao", &e.errors)];
            rows.extend(e.layers_1.as_ref().map(|x| ao_row("multilayer=off", x)));
            rows.extend(e.dgb_2_layers.as_ref().map(|x| ao_row("DGB AO, 2 layers", x)));
            ("AO against the ray-traced obscurance", &AO_HEADER[..], rows, None)
        }
        EvalResult::BzbGi(e) => (
            "bounced-z-buffer GI against the one-bounce path tracer",
            &GI_HEADER[..],
            vec![
                gi_row("bzb-gi", &e.errors),
                gi_row("visibility=off (additive)", &e.no_visibility),
                gi_row("DGB radiosity, 2 layers, one bounce", &e.dgb_2_layers),
            ],
            None,
        ),
        EvalResult::Ao(e) => {
            let row = |layers: u32, x: &crate::results::AoErrors| {
                ErrorRow::layers(layers, ao_cells(x), (x.obscurance.flip, x.obscurance.mae))
            };
            let mut rows: Vec<ErrorRow> = e.by_layers.iter().map(|b| row(b.layers, &b.errors)).collect();
            if rows.is_empty() {
                rows.extend(e.layers_1.as_ref().map(|x| row(1, x)));
                rows.push(row(run.layers, &e.errors));
            }
            ("AO against the ray-traced obscurance", &AO_HEADER[..], rows, None)
        }
        EvalResult::Gi(e) => {
            let row = |layers: u32, x: &crate::results::GiErrors| {
                ErrorRow::layers(layers, gi_cells(x), (x.indirect.flip, x.indirect.mae))
            };
            let mut rows: Vec<ErrorRow> = e.by_layers.iter().map(|b| row(b.layers, &b.errors)).collect();
            if rows.is_empty() {
                rows.extend(e.layers_1.as_ref().map(|x| row(1, x)));
                rows.push(row(run.layers, &e.errors));
            }
            (
                "radiosity against the path tracer",
                &GI_HEADER[..],
                rows,
                e.fig10.as_ref(),
            )
        }
        EvalResult::Oit(e) => (
            "A-buffer OIT against the CPU compositing",
            &OIT_HEADER[..],
            vec![ErrorRow::layers(
                1,
                stats_cells(&e.errors),
                (e.errors.flip, e.errors.mae),
            )],
            None,
        ),
        EvalResult::Ils(e) => (
            "interleaved VPL shading and its brute force against the one-bounce path tracer",
            &GI_HEADER[..],
            vec![
                gi_row(&format!("ils {}", e.pattern), &e.errors),
                gi_row("brute force (all N VPLs at every pixel)", &e.brute_force),
            ],
            None,
        ),
    };
    let by_configuration = rows.iter().any(|r| r.layers.is_none());
    let mut header = header.to_vec();
    let caption = if by_configuration {
        header[0] = "configuration";
        format!("Errors by configuration ({what})")
    } else {
        format!("Errors by layer count ({what})")
    };
    let mut errors = Table::new(caption, &header);
    for r in &rows {
        let flicker = run
            .flicker
            .as_ref()
            .filter(|_| r.layers == Some(run.layers))
            .map(|f| f.mean);
        let mut cells = vec![Cell::Text(r.label.clone())];
        cells.extend(r.cells.iter().cloned());
        cells.push(flicker.into());
        errors.row(cells);
    }
    let skip = [
        "flip",
        "rmse",
        "mae",
        "binary",
        "full",
        "layers_1",
        "by_layers",
        "fig10",
        "brute_force",
        "flicker_per_frame",
        "no_visibility",
        "dgb_2_layers",
        "ref_noise",
        "outliers",
        "ref_outliers",
        "warnings",
        "progressive",
    ];
    let mut section = Section::new(format!("{} on {}: numbers", technique(r), run.scene))
        .text(
            run.warnings
                .iter()
                .map(|w| format!("Warning: {w}"))
                .collect::<Vec<_>>()
                .join(" "),
        )
        .table(settings_table("Settings", r, &skip)?)
        .table(errors)
        .table(reference_table(r));
    if let Some(f) = fig10 {
        let mut t = Table::new(
            "DGB Fig. 10: single-bounce radiosity against single-bounce references",
            &[
                "GPU",
                "FLIP vs visibility",
                "MAE vs visibility",
                "FLIP vs mutual visibility",
                "MAE vs mutual visibility",
            ],
        );
        for (name, row) in [("with the n_Y test", &f.normal_test), ("without", &f.no_normal_test)] {
            t.row(vec![
                name.into(),
                row.vs_visibility.flip.into(),
                row.vs_visibility.mae.into(),
                row.vs_mutual_visibility.flip.into(),
                row.vs_mutual_visibility.mae.into(),
            ]);
        }
        section = section.table(t);
    }
    let mut figures = eval_plots(run, &rows, dir, prefix)?;
    if let EvalResult::Ils(IlsEval {
        progressive: Some(p), ..
    }) = r
    {
        let (table, plot) = progressive_table_and_plot(p, &run.scene, dir, prefix)?;
        section = section.table(table);
        figures.push(plot);
    }
    section = section.figures(figures);
    Ok(vec![section])
}

/// ILS Table 5 (§6.3): per pattern, the per-set noise σ₁ and the frames and GPU time to 1 %
/// relative RMS, measured and predicted; the plot shows each pattern's running mean against
/// its converged image (every frame) and against the path tracer (at 1, 2, 4, … frames), on
/// log–log axes.
fn progressive_table_and_plot(
    p: &IlsProgressive,
    scene: &str,
    dir: &Path,
    prefix: &str,
) -> Result<(Table, ReportImage)> {
    let mut t = Table::new(
        format!(
            "ILS Table 5 (§6.3): K = {} VPL sets of {} paths, {} bounces, until {} % relative RMS of the mean of K other sets; the 1x1 converged image against the path tracer: FLIP {:.4}",
            p.sets,
            p.vpl_paths,
            p.bounces,
            p.target_rms * 100.0,
            p.converged_vs_path_tracer.flip
        ),
        &[
            "n×m",
            "σ₁ (one set)",
            "frames to target",
            "GPU ms to target",
            "predicted frames",
            "predicted GPU ms",
            "predicted GPU ms, static view",
            "GPU ms / frame",
            "VPL-dependent ms / frame",
        ],
    );
    let mut series = Vec::new();
    for q in &p.patterns {
        let reached = q
            .frames_to_target
            .map_or(format!("not in {}", p.sets), |f| f.to_string());
        t.row(vec![
            Cell::Text(q.pattern.clone()),
            q.per_set_rel_rms.into(),
            Cell::Text(reached),
            q.gpu_ms_to_target.into(),
            Cell::Text(q.predicted_frames_to_target.to_string()),
            q.predicted_gpu_ms_to_target.into(),
            q.predicted_static_view_gpu_ms_to_target.into(),
            q.gpu_ms_per_frame.into(),
            q.vpl_dependent_ms_per_frame.into(),
        ]);
        let curve = q.rms_curve.iter().map(|&(k, e)| (k as f64, e)).collect();
        series.push((format!("{} vs converged", q.pattern), curve));
        if !q.rms_vs_path_tracer.is_empty() {
            let curve = q.rms_vs_path_tracer.iter().map(|&(k, e)| (k as f64, e)).collect();
            series.push((format!("{} vs path tracer", q.pattern), curve));
        }
    }
    series.push((
        format!("target {} %", p.target_rms * 100.0),
        vec![(1.0, p.target_rms), (p.sets as f64, p.target_rms)],
    ));
    let svg = plot::log_lines(
        &format!("ILS §6.3 progressive accumulation ({scene})"),
        "frames accumulated",
        "relative RMS",
        &series,
    )?;
    let fig = plot_file(
        dir,
        format!("{prefix}progressive.svg"),
        svg,
        "relative RMS of the running mean against the frames (log–log)".into(),
    )?;
    Ok((t, fig))
}

/// Sections of `eval --technique full --views`: the frame as `render` shows it against the
/// path-traced frame with sky. Per view: clipped pixels, mean display value, outliers; ꟻLIP
/// of the final image and of the probe-only and G-buffer-only composites; and the fixed
/// regions' chroma (issue 14's banner regions), with a plot of each composite's CIELAB
/// (a*, b*) distance to the path tracer's colour per region.
pub fn views_sections(e: &ViewsEval, dir: &Path, prefix: &str) -> Result<Vec<Section>> {
    let skip = [
        "views",
        "regions",
        "flip_blended",
        "flip_probe_only",
        "flip_gbuffer_only",
        "reference_outliers",
        "warnings",
    ];
    let mut views = Table::new(
        format!(
            "Views as `render` shows them (display bytes); the path-traced frame has {} outliers",
            e.reference_outliers
        ),
        &["view", "pixels clipped", "mean (0..255)", "outliers"],
    );
    for v in &e.views {
        views.row(vec![
            Cell::Text(v.view.clone()),
            Cell::Text(format!("{:.2} %", 100.0 * v.clip_fraction)),
            v.mean.into(),
            Cell::Text(v.outliers.to_string()),
        ]);
    }
    let mut flips = Table::new(
        format!(
            "Against the path-traced frame (sky on); mean |blended − probe-only| {:.2}/255, mean confidence {:.3}",
            e.blended_vs_probe_only, e.mean_confidence
        ),
        &["composite", "FLIP"],
    );
    for (name, f) in [
        ("final (blend)", e.flip_blended),
        ("probes only", e.flip_probe_only),
        ("deep G-buffer only", e.flip_gbuffer_only),
    ] {
        flips.row(vec![name.into(), f.into()]);
    }
    let mut regions = Table::new(
        "Regions: chroma C*ab of the mean display colour, and its (a*, b*) distance to the path tracer's",
        &[
            "region",
            "pixels",
            "confidence",
            "C* path tracer",
            "C* probes only",
            "C* blend",
            "C* G-buffer only",
            "Δab probes only",
            "Δab blend",
            "Δab G-buffer only",
            "|blend − probes| /255",
        ],
    );
    for r in &e.regions {
        regions.row(vec![
            Cell::Text(r.name.clone()),
            Cell::Text(r.pixels.to_string()),
            r.confidence.into(),
            r.chroma_reference.into(),
            r.chroma_probe_only.into(),
            r.chroma_blended.into(),
            r.chroma_gbuffer_only.into(),
            r.ab_error_probe_only.into(),
            r.ab_error_blended.into(),
            r.ab_error_gbuffer_only.into(),
            r.blended_vs_probe_only.into(),
        ]);
    }
    let mut section = Section::new(format!("eval full --views on {}: numbers", e.run.scene))
        .table(settings_table("Settings", e, &skip)?)
        .table(views)
        .table(flips)
        .table(regions);
    if !e.regions.is_empty() {
        let names: Vec<String> = e.regions.iter().map(|r| r.name.clone()).collect();
        let series = [
            ("probes only", e.regions.iter().map(|r| r.ab_error_probe_only).collect()),
            ("blend", e.regions.iter().map(|r| r.ab_error_blended).collect()),
            (
                "deep G-buffer only",
                e.regions.iter().map(|r| r.ab_error_gbuffer_only).collect(),
            ),
        ]
        .map(|(n, v): (&str, Vec<f64>)| (n.to_string(), v));
        let svg = plot::bars(
            &format!("Colour error per region ({})", e.run.scene),
            "CIELAB (a*, b*) distance to the path tracer",
            &names,
            &series,
        )?;
        section = section.figures(vec![plot_file(
            dir,
            format!("{prefix}regions.svg"),
            svg,
            "each composite's colour distance to the path-traced frame, per region".into(),
        )?]);
    }
    Ok(vec![section])
}

/// The references' own quality: samples, whether the noise target was met, the noise between
/// the two independent halves, and the speckles of the reference and of the evaluated image.
fn reference_table(r: &EvalResult) -> Table {
    let mut t = Table::new(
        "Reference quality (noise = the two independent halves of the reference compared; outliers = pixels off their 3×3 median by more than 0.25)",
        &[
            "reference",
            "spp",
            "converged",
            "noise FLIP",
            "noise RMSE",
            "reference outliers",
            "GPU outliers",
        ],
    );
    let named: Vec<(&str, &ErrorStats)> = match r {
        EvalResult::Ao(e) | EvalResult::Bzb(e) | EvalResult::AbaAo(e) => {
            vec![("obscurance", &e.errors.obscurance), ("binary AO", &e.errors.binary)]
        }
        EvalResult::Gi(e) => vec![("indirect", &e.errors.indirect), ("full", &e.errors.full)],
        EvalResult::Ils(e) => vec![("indirect", &e.errors.indirect), ("full", &e.errors.full)],
        EvalResult::BzbGi(e) => vec![("indirect", &e.errors.indirect), ("full", &e.errors.full)],
        EvalResult::Oit(e) => vec![("composite", &e.errors)],
    };
    for (name, e) in named {
        let Some(n) = e.ref_noise else { continue };
        let count = |c: Option<u32>| c.map_or(Cell::Text("–".into()), |c| Cell::Text(c.to_string()));
        t.row(vec![
            name.into(),
            Cell::Text(n.spp.to_string()),
            (if n.converged { "yes" } else { "no (cap)" }).into(),
            n.flip.into(),
            n.rmse.into(),
            count(e.ref_outliers),
            count(e.outliers),
        ]);
    }
    t
}

fn technique(r: &EvalResult) -> &'static str {
    match r {
        EvalResult::Ao(_) => "eval ao",
        EvalResult::Bzb(_) => "eval bzb-ao",
        EvalResult::AbaAo(_) => "eval aba-ao",
        EvalResult::Gi(_) => "eval gi",
        EvalResult::Ils(_) => "eval ils",
        EvalResult::BzbGi(_) => "eval bzb-gi",
        EvalResult::Oit(_) => "eval oit",
    }
}

fn eval_plots(run: &EvalRun, rows: &[ErrorRow], dir: &Path, prefix: &str) -> Result<Vec<ReportImage>> {
    let mut figs = Vec::new();
    let points = |f: fn(&ErrorRow) -> f32| {
        rows.iter()
            .filter_map(|r| Some((r.layers? as f64, f(r) as f64)))
            .collect::<Vec<_>>()
    };
    if rows.len() >= 2 && rows.iter().all(|r| r.layers.is_none()) {
        // configurations side by side
        let labels: Vec<String> = rows.iter().map(|r| r.label.clone()).collect();
        let svg = plot::bars(
            &format!("Error by configuration ({})", run.scene),
            "error",
            &labels,
            &[
                ("FLIP".into(), rows.iter().map(|r| r.flip_mae.0 as f64).collect()),
                ("MAE".into(), rows.iter().map(|r| r.flip_mae.1 as f64).collect()),
            ],
        )?;
        figs.push(plot_file(
            dir,
            format!("{prefix}errors.svg"),
            svg,
            "FLIP and MAE of each configuration against the same reference".into(),
        )?);
        return flicker_plot(run, dir, prefix, figs);
    }
    if points(|r| r.flip_mae.0).len() < 2 {
        // one layer count: the table says it all
        return flicker_plot(run, dir, prefix, figs);
    }
    let svg = plot::lines(
        &format!("Error against layers ({})", run.scene),
        "layers k",
        "error",
        &[
            ("FLIP".into(), points(|r| r.flip_mae.0)),
            ("MAE".into(), points(|r| r.flip_mae.1)),
        ],
    )?;
    figs.push(plot_file(
        dir,
        format!("{prefix}errors.svg"),
        svg,
        "FLIP and MAE against the layer count k".into(),
    )?);
    flicker_plot(run, dir, prefix, figs)
}

/// `figs` and, when the run measured flicker, its per-frame plot.
fn flicker_plot(run: &EvalRun, dir: &Path, prefix: &str, mut figs: Vec<ReportImage>) -> Result<Vec<ReportImage>> {
    if let Some(f) = run.flicker.as_ref().filter(|f| !f.per_frame.is_empty()) {
        let pts = f.per_frame.iter().map(|p| (p[0], p[1])).collect();
        let svg = plot::lines(
            &format!("Flicker along the camera path ({}, k = {})", run.scene, run.layers),
            "frame",
            "mean |Δ| after reprojection",
            &[("flicker".into(), pts)],
        )?;
        figs.push(plot_file(
            dir,
            format!("{prefix}flicker.svg"),
            svg,
            format!("flicker per frame (mean {:.5})", f.mean),
        )?);
    }
    Ok(figs)
}

/// A pass table (rows passes, columns median / min ms per configuration) and the total row.
fn pass_table(caption: String, configs: &[(&str, &[PassTime], (f64, f64))]) -> Table {
    let mut header = vec!["pass".to_string()];
    for (name, _, _) in configs {
        header.push(format!("median ms{name}"));
        header.push(format!("min ms{name}"));
    }
    let mut t = Table {
        caption,
        header,
        rows: Vec::new(),
    };
    let Some((_, first, _)) = configs.first() else {
        return t;
    };
    for p in first.iter() {
        let mut row = vec![Cell::Text(p.name.clone())];
        for (_, passes, _) in configs {
            let q = passes.iter().find(|q| q.name == p.name);
            row.push(q.map(|q| q.median_ms).into());
            row.push(q.map(|q| q.min_ms).into());
        }
        t.row(row);
    }
    let mut total = vec![Cell::Text("total".into())];
    for (_, _, (med, min)) in configs {
        total.push((*med).into());
        total.push((*min).into());
    }
    t.row(total);
    t
}

/// Sections of a benchmark: settings, the time table, and a bar plot.
pub fn bench_sections(b: &BenchResult, dir: &Path, prefix: &str) -> Result<Vec<Section>> {
    let name = b.name();
    let skip = ["bench", "passes", "passes_layers_1", "rows", "increment_spread"];
    let mut section = Section::new(format!("bench {name}")).table(settings_table("Settings", b, &skip)?);
    match b {
        BenchResult::Gbuffer(g) => {
            section = section.table(pass_table(
                "GPU time per pass".into(),
                &[("", &g.passes, (g.total_median_ms, g.total_min_ms))],
            ));
            let title = format!("bench {name}: {}", g.run.scene);
            section = passes_figure(section, title, &[("median".into(), &g.passes)], dir, prefix)?;
        }
        BenchResult::Ao(s) | BenchResult::Radiosity(s) | BenchResult::Reflections(s) | BenchResult::Technique(s) => {
            section = stage_section(section, name, s, dir, prefix)?;
        }
        BenchResult::DeepGbuffer(d) => {
            section = deep_section(section, d, dir, prefix)?;
        }
        BenchResult::Ils(b) => {
            let caption = format!(
                "ILS Table 4: speed-up {:.2}x (shading alone {:.2}x)",
                b.speedup, b.shading_speedup
            );
            for (what, s) in [("IS", &b.interleaved), ("no IS (brute force)", &b.brute_force)] {
                section = section.table(pass_table(
                    format!("{caption}: {what}"),
                    &[("", &s.passes, (s.total_median_ms, s.total_min_ms))],
                ));
            }
            let pattern = b.interleaved.settings.get("pattern").and_then(|v| v.as_str());
            let series = [
                (format!("IS {}", pattern.unwrap_or_default()), &b.interleaved.passes[..]),
                ("no IS (brute force)".to_string(), &b.brute_force.passes[..]),
            ];
            let title = format!("bench {name}: {}, speed-up {:.2}x", b.interleaved.run.scene, b.speedup);
            section = passes_figure(section, title, &series, dir, prefix)?;
        }
        BenchResult::Abuffer(b) => {
            for (key, m) in &b.methods {
                let s = &m.stage;
                section = section.table(pass_table(
                    format!(
                        "ABA Table I, {key}: {} fragments, {} dropped, {:.1} MiB",
                        m.fragments,
                        m.dropped,
                        m.memory_bytes as f64 / (1024.0 * 1024.0)
                    ),
                    &[("", &s.passes, (s.total_median_ms, s.total_min_ms))],
                ));
            }
            // Table I as bars: one group per stage, one bar per construction
            let stages = ["clear", "count", "prefix sum", "draw", "resolve", "AO", "AO blur"];
            let series: Vec<(String, Vec<f64>)> = b
                .methods
                .iter()
                .map(|(key, m)| {
                    let v = [
                        m.clear_ms,
                        m.count_ms,
                        m.prefix_sum_ms,
                        m.draw_ms,
                        m.resolve_ms,
                        m.ao_ms,
                        m.ao_blur_ms,
                    ];
                    (key.clone(), v.iter().map(|x| x.unwrap_or(f64::NAN)).collect())
                })
                .collect();
            let scene = b.methods.values().next().map_or("", |m| m.stage.run.scene.as_str());
            let categories: Vec<String> = stages.iter().map(|x| x.to_string()).collect();
            let svg = plot::bars(&format!("bench {name}: {scene}"), "median GPU ms", &categories, &series)?;
            section = section.figures(vec![plot_file(
                dir,
                format!("{prefix}stages.svg"),
                svg,
                "median GPU ms per ABA Table I stage and construction".into(),
            )?]);
        }
        BenchResult::Bzb(b) => {
            for (what, s) in [
                ("bounced z-buffer", &b.visibility),
                ("additive baseline, no visibility", &b.no_visibility),
            ] {
                section = section.table(pass_table(
                    format!(
                        "BZB Table 1, {}, {what}: splat ratio {:.2}x",
                        b.technique, b.splat_ratio
                    ),
                    &[("", &s.passes, (s.total_median_ms, s.total_min_ms))],
                ));
            }
            let series = [
                ("bounced z-buffer".to_string(), &b.visibility.passes[..]),
                ("additive baseline".to_string(), &b.no_visibility.passes[..]),
            ];
            let title = format!("bench {name} {}: {}", b.technique, b.visibility.run.scene);
            section = passes_figure(section, title, &series, dir, prefix)?;
        }
        BenchResult::Reference(_) | BenchResult::Display(_) => {}
    }
    Ok(vec![section])
}

/// Median GPU ms per pass as grouped bars: one group per pass (in first-seen order over the
/// series), one bar per series (a configuration); a pass a series lacks has no bar.
fn pass_bars(title: &str, series: &[(String, &[PassTime])]) -> Result<String> {
    let mut names: Vec<String> = Vec::new();
    for p in series.iter().flat_map(|(_, ps)| ps.iter()) {
        if !names.contains(&p.name) {
            names.push(p.name.clone());
        }
    }
    let values: Vec<(String, Vec<f64>)> = series
        .iter()
        .map(|(label, ps)| {
            let v = names
                .iter()
                .map(|n| ps.iter().find(|p| &p.name == n).map_or(f64::NAN, |p| p.median_ms))
                .collect();
            (label.clone(), v)
        })
        .collect();
    plot::bars(title, "median GPU ms", &names, &values)
}

/// The section's bar plot of `series` ([`pass_bars`]), written as `{prefix}passes.svg`.
fn passes_figure(
    section: Section,
    title: String,
    series: &[(String, &[PassTime])],
    dir: &Path,
    prefix: &str,
) -> Result<Section> {
    let svg = pass_bars(&title, series)?;
    Ok(section.figures(vec![plot_file(
        dir,
        format!("{prefix}passes.svg"),
        svg,
        "median GPU ms per pass".into(),
    )?]))
}

fn stage_section(section: Section, name: &str, s: &StageBench, dir: &Path, prefix: &str) -> Result<Section> {
    let k = s.layers;
    let kname = format!(" (k = {k})");
    let mut configs: Vec<(&str, &[PassTime], (f64, f64))> =
        vec![(&kname, &s.passes, (s.total_median_ms, s.total_min_ms))];
    if let Some(one) = &s.passes_layers_1 {
        configs.push((" (k = 1)", one, (s.layer1_ms, f64::NAN)));
    }
    let mut section = section
        .table(pass_table("GPU time per pass".into(), &configs))
        .text(s.split_line(name));
    if let Some(sp) = &s.increment_spread {
        let mut t = Table::new(
            format!("Per-frame increment of layers 2..{k} (k = {k} − k = 1, same frame)"),
            &[
                "median ms",
                "Q1 ms",
                "Q3 ms",
                "min ms",
                "max ms",
                "frames",
                "within noise",
            ],
        );
        t.row(vec![
            sp.median_ms.into(),
            sp.q1_ms.into(),
            sp.q3_ms.into(),
            sp.min_ms.into(),
            sp.max_ms.into(),
            Cell::Text(sp.frames.to_string()),
            Cell::Text(if sp.includes_zero() { "yes" } else { "no" }.into()),
        ]);
        section = section.table(t);
    }
    let mut series = vec![(format!("k = {k}"), &s.passes[..])];
    if let Some(one) = &s.passes_layers_1 {
        series.push(("k = 1".into(), &one[..]));
    } else {
        series[0].0 = "median".into();
    }
    passes_figure(section, format!("bench {name}: {}", s.run.scene), &series, dir, prefix)
}

fn deep_section(section: Section, d: &DeepBench, dir: &Path, prefix: &str) -> Result<Section> {
    let title = match d.layer_scale {
        1 => format!("Deep G-buffer construction, k = {} (DGB Table 5)", d.layers),
        sc => format!(
            "Deep G-buffer construction, k = {}, layers ≥ 1 at 1/{sc} resolution (DGB Table 5, Fig. 11)",
            d.layers
        ),
    };
    let mut t = Table::new(
        title,
        &[
            "method",
            "layer1 ms",
            "layer2 ms",
            "of which upsampling ms",
            "total ms",
            "l2/l1",
            "mismatch %",
            "submission",
            "multiview ms",
        ],
    );
    for r in &d.rows {
        t.row(vec![
            r.method.clone().into(),
            r.layer1_ms.into(),
            r.layer2_ms.into(),
            r.upsample_ms.into(),
            r.total_ms.into(),
            (r.layer2_ms / r.layer1_ms).into(),
            r.mismatch_pct.into(),
            r.submission.clone().into(),
            r.multiview_total_ms.into(),
        ]);
    }
    let methods: Vec<String> = d.rows.iter().map(|r| r.method.clone()).collect();
    let svg = plot::bars(
        &format!("Deep G-buffer construction ({})", d.run.scene),
        "median GPU ms",
        &methods,
        &[
            ("layer 1".into(), d.rows.iter().map(|r| r.layer1_ms).collect()),
            ("layers 2..k".into(), d.rows.iter().map(|r| r.layer2_ms).collect()),
        ],
    )?;
    Ok(section.table(t).figures(vec![plot_file(
        dir,
        format!("{prefix}methods.svg"),
        svg,
        "median GPU ms per construction method".into(),
    )?]))
}
