//! One page from a folder of results (the demo's report): the device description (`info.txt`),
//! groups of images, every benchmark and evaluation JSON file as tables and SVG plots (other JSON
//! files as a name/value table), and links to the evaluation reports in subfolders.

use std::fs;
use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};

use super::{sections, Block, Page, ReportImage, Section, Table};
use crate::results::{BenchResult, EvalResult};

/// What to stitch.
#[derive(Clone, Debug)]
pub struct StitchSettings {
    /// The folder holding the results (`*.json`, `info.txt`, subfolders with `index.html`).
    pub from: PathBuf,
    /// The page to write; images are referenced relative to its folder and plots written there.
    pub out: PathBuf,
    pub title: String,
    /// Sections of images: a title and image files (relative to `out`'s folder).
    pub figures: Vec<(String, Vec<String>)>,
    /// Overwrite an existing page.
    pub force: bool,
}

/// A result file of the folder.
enum Parsed {
    Eval(Box<EvalResult>),
    /// `eval --technique full --views` (issue 14's final-frame measurements).
    Views(Box<crate::eval::views::ViewsEval>),
    Bench(Box<BenchResult>),
    Other(serde_json::Value),
}

fn parse(text: &str) -> Result<Parsed> {
    let v: serde_json::Value = serde_json::from_str(text)?;
    if v.get("technique").is_some() {
        if let Ok(e) = serde_json::from_value(v.clone()) {
            return Ok(Parsed::Eval(Box::new(e)));
        }
    }
    if v.get("views").is_some() && v.get("regions").is_some() {
        if let Ok(e) = serde_json::from_value(v.clone()) {
            return Ok(Parsed::Views(Box::new(e)));
        }
    }
    if v.get("bench").is_some() || v.get("rows").is_some() {
        let mut tagged = v.clone();
        if let Some(m) = tagged.as_object_mut() {
            // `bench deep-gbuffer` output from before the tag was added
            m.entry("bench").or_insert_with(|| "deep-gbuffer".into());
        }
        if let Ok(b) = serde_json::from_value(tagged) {
            return Ok(Parsed::Bench(Box::new(b)));
        }
    }
    Ok(Parsed::Other(v))
}

/// Writes the page; returns its path.
pub fn stitch(s: &StitchSettings) -> Result<PathBuf> {
    if !s.from.is_dir() {
        bail!("--from {}: not a folder", s.from.display());
    }
    crate::files::refuse_existing("--out", &s.out, s.force)?;
    let out_dir = s
        .out
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let stem = s
        .out
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("report")
        .to_string();
    let mut page = Page::new(s.title.clone());
    let mut intro = Section::new("Run").text(format!("Generated {}.", utc_now()));
    if let Ok(info) = fs::read_to_string(s.from.join("info.txt")) {
        intro.blocks.push(Block::Pre(info.trim_end().to_string()));
    }
    page.sections.push(intro);
    for (title, files) in &s.figures {
        let (present, missing): (Vec<&String>, Vec<&String>) = files.iter().partition(|f| out_dir.join(f).exists());
        let images = present
            .iter()
            .map(|f| ReportImage {
                caption: Path::new(f)
                    .file_stem()
                    .map_or_else(|| f.to_string(), |s| s.to_string_lossy().into_owned()),
                file: f.to_string(),
            })
            .collect();
        let mut section = Section::new(title.clone()).figures(images);
        if !missing.is_empty() {
            let names: Vec<&str> = missing.iter().map(|s| s.as_str()).collect();
            section = section.text(format!("missing: {}", names.join(", ")));
        }
        page.sections.push(section);
    }

    let mut files: Vec<PathBuf> = fs::read_dir(&s.from)
        .with_context(|| format!("--from {}", s.from.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .collect();
    files.sort();
    let mut evals = Vec::new();
    let mut benches = Vec::new();
    let mut links = Vec::new();
    for path in &files {
        let name = path
            .file_name()
            .map_or_else(String::new, |n| n.to_string_lossy().into_owned());
        if path.is_dir() && path.join("index.html").is_file() {
            links.push(Block::Link {
                href: link_to(out_dir, &s.from, &name),
                text: format!("{name}: evaluation report"),
            });
            continue;
        }
        if path.extension().is_none_or(|e| e != "json") {
            continue;
        }
        let text = fs::read_to_string(path).with_context(|| format!("{}", path.display()))?;
        let json_stem = path
            .file_stem()
            .map_or_else(String::new, |n| n.to_string_lossy().into_owned());
        let prefix = format!("{stem}-{json_stem}-");
        let parsed = parse(&text).with_context(|| format!("{}: not JSON", path.display()))?;
        let mut secs = match &parsed {
            Parsed::Eval(e) => sections::eval_sections(e, out_dir, &prefix)?,
            Parsed::Views(e) => sections::views_sections(e, out_dir, &prefix)?,
            Parsed::Bench(b) => sections::bench_sections(b, out_dir, &prefix)?,
            Parsed::Other(v) => vec![Section::new(name.clone()).table(Table::key_values("", v))],
        };
        for sec in &mut secs {
            sec.title = format!("{} ({name})", sec.title);
        }
        match parsed {
            Parsed::Eval(_) | Parsed::Views(_) => evals.extend(secs),
            _ => benches.extend(secs),
        }
    }
    let has_info = s.from.join("info.txt").is_file();
    if evals.is_empty() && benches.is_empty() && links.is_empty() && s.figures.is_empty() && !has_info {
        let hint = if s.from.join("index.html").is_file() {
            format!(
                " (it holds an evaluation report of its own: {})",
                s.from.join("index.html").display()
            )
        } else {
            String::new()
        };
        bail!(
            "--from {}: nothing to report: no *.json from `bench`/`eval --json`, no info.txt and no subfolder with an index.html{hint}",
            s.from.display()
        );
    }
    if !links.is_empty() {
        page.sections.push(Section {
            title: "Evaluation reports (images, FLIP maps)".into(),
            blocks: links,
        });
    }
    page.sections.extend(evals);
    page.sections.extend(benches);
    page.write(&s.out)
}

/// The link from the page's folder to `from/name/index.html`.
fn link_to(out_dir: &Path, from: &Path, name: &str) -> String {
    let same = match (out_dir.canonicalize(), from.canonicalize()) {
        (Ok(a), Ok(b)) => a == b,
        _ => false,
    };
    if same {
        format!("{name}/index.html")
    } else {
        let dir = from.canonicalize().unwrap_or_else(|_| from.to_path_buf());
        format!("{}", dir.join(name).join("index.html").display())
    }
}

/// The current UTC time as `YYYY-MM-DDTHH:MMZ`.
fn utc_now() -> String {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    format_utc(secs)
}

/// `secs` since the Unix epoch as `YYYY-MM-DDTHH:MMZ` (proleptic Gregorian calendar).
fn format_utc(secs: u64) -> String {
    let (days, rem) = ((secs / 86_400) as i64, secs % 86_400);
    // Howard Hinnant's civil_from_days
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z.rem_euclid(146_097);
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + i64::from(m <= 2);
    format!("{y:04}-{m:02}-{d:02}T{:02}:{:02}Z", rem / 3600, rem % 3600 / 60)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn utc_dates() {
        assert_eq!(format_utc(0), "1970-01-01T00:00Z");
        assert_eq!(format_utc(951_782_400 + 3_660), "2000-02-29T01:01Z");
        assert_eq!(format_utc(1_700_000_000), "2023-11-14T22:13Z");
    }

    #[test]
    fn stitches_results_images_and_links() {
        let dir = std::env::temp_dir().join(format!("strata-stitch-test-{}", std::process::id()));
        let _ = fs::remove_dir_all(&dir);
        fs::create_dir_all(dir.join("ao-eval")).unwrap();
        fs::write(dir.join("ao-eval/index.html"), "<html>").unwrap();
        fs::write(dir.join("info.txt"), "adapter <llvmpipe>").unwrap();
        fs::write(dir.join("a.png"), b"png").unwrap();
        let bench = serde_json::json!({
            "bench": "ao", "scene": "atrium", "width": 64, "height": 48, "frames": 2, "layers": 2,
            "triangles": 10, "device": "lavapipe",
            "passes": [{"name": "ao", "median_ms": 1.0, "min_ms": 0.9}, {"name": "ao-blur-h", "median_ms": 0.2, "min_ms": 0.1}],
            "passes_layers_1": [{"name": "ao", "median_ms": 0.8, "min_ms": 0.7}, {"name": "ao-blur-h", "median_ms": 0.2, "min_ms": 0.1}],
            "total_median_ms": 1.2, "total_min_ms": 1.0, "layer1_ms": 1.0, "increment_ms": 0.2,
            "increment_spread": {"median_ms": 0.2, "q1_ms": -0.1, "q3_ms": 0.3, "min_ms": -0.2, "max_ms": 0.4, "frames": 2},
            "increment_within_noise": true, "samples": 19, "variant": "reproject",
        });
        fs::write(dir.join("bench-ao.json"), bench.to_string()).unwrap();
        let deep = serde_json::json!({"scene": "atrium", "width": 64, "height": 48, "frames": 2, "layers": 2,
            "triangles": 10, "device": "lavapipe", "rows": [
            {"method": "peel", "layer1_ms": 1.0, "layer2_ms": 1.0, "total_ms": 2.0, "mismatch_pct": 0.0, "submission": "per-layer"}]});
        fs::write(dir.join("bench-deep.json"), deep.to_string()).unwrap();
        // the other papers' benches: ILS Table 4, ABA Table I, BZB Table 1
        let stage = |passes: &[(&str, f64)]| {
            let total: f64 = passes.iter().map(|p| p.1).sum();
            serde_json::json!({"scene": "atrium", "width": 64, "height": 48, "frames": 2, "triangles": 10,
                "device": "lavapipe", "layers": 1, "total_median_ms": total, "total_min_ms": total,
                "layer1_ms": total, "increment_ms": 0.0, "pattern": "8x6",
                "passes": passes.iter().map(|(n, ms)| serde_json::json!({"name": n, "median_ms": ms, "min_ms": ms})).collect::<Vec<_>>()})
        };
        let ils = serde_json::json!({"bench": "ils", "vpls_generated": 480, "speedup": 3.0, "shading_speedup": 20.0,
            "interleaved": stage(&[("ils-snsm", 1.0), ("ils-blur-h", 0.5)]),
            "brute_force": stage(&[("ils-brute-force", 4.5)])});
        fs::write(dir.join("bench-ils.json"), ils.to_string()).unwrap();
        let method = |draw: f64| {
            serde_json::json!({"clear_ms": 0.1, "count_ms": null, "prefix_sum_ms": null,
            "draw_ms": draw, "resolve_ms": 1.0, "total_ms": draw + 1.1, "memory_bytes": 1024, "fragments": 100,
            "dropped": 0, "stage": stage(&[("aba-draw", draw)])})
        };
        let aba =
            serde_json::json!({"bench": "abuffer", "methods": {"linked-list": method(2.0), "linear": method(3.0)}});
        fs::write(dir.join("bench-abuffer.json"), aba.to_string()).unwrap();
        let bzb = serde_json::json!({"bench": "bzb", "technique": "bzb-gi", "triangles": 10, "directions": 4,
            "splat_ratio": 0.8, "total_ratio": 0.8, "memory_bytes": 1024,
            "visibility": stage(&[("bzb-splat", 0.8)]), "no_visibility": stage(&[("bzb-splat", 1.0)])});
        fs::write(dir.join("bench-bzb.json"), bzb.to_string()).unwrap();
        fs::write(dir.join("other.json"), r#"{"x": 1.5}"#).unwrap();
        let s = StitchSettings {
            from: dir.clone(),
            out: dir.join("report.html"),
            title: "demo <1>".into(),
            figures: vec![("Renders".into(), vec!["a.png".into(), "b.png".into()])],
            force: false,
        };
        let path = stitch(&s).unwrap();
        let html = fs::read_to_string(&path).unwrap();
        assert!(stitch(&s).is_err(), "no overwrite without force");
        assert!(html.contains("<h1>demo &lt;1&gt;</h1>"));
        assert!(html.contains("<pre>adapter &lt;llvmpipe&gt;</pre>"));
        assert!(html.contains("<img src=\"a.png\"") && html.contains("missing: b.png"));
        assert!(html.contains("<a href=\"ao-eval/index.html\">"));
        assert!(html.contains("<th>median ms (k = 2)</th>"), "{html}");
        assert!(html.contains("<td>ao-blur-h</td><td class=\"num\">0.2000</td>"));
        assert!(html.contains("within the frame-to-frame noise"));
        assert!(html.contains("<td>peel</td>"));
        assert!(html.contains("<td>x</td><td class=\"num\">1.500</td>"));
        assert!(!html.contains("\"median_ms\""), "no raw JSON");
        // every bench has its plot; two-configuration plots have a legend naming both
        for (plot, legend) in [
            ("report-bench-ao-passes.svg", &["k = 2", "k = 1"][..]),
            ("report-bench-deep-methods.svg", &[][..]),
            (
                "report-bench-ils-passes.svg",
                &["IS 8x6", "no IS (brute force)", "ils-brute-force"][..],
            ),
            (
                "report-bench-abuffer-stages.svg",
                &["linked-list", "linear", "prefix sum"][..],
            ),
            (
                "report-bench-bzb-passes.svg",
                &["bounced z-buffer", "additive baseline", "bzb-gi"][..],
            ),
        ] {
            assert!(html.contains(plot), "{plot}");
            let svg = fs::read_to_string(dir.join(plot)).unwrap();
            assert!(svg.trim_end().ends_with("</svg>"));
            for l in legend {
                assert!(svg.contains(l), "{plot} names {l}");
            }
        }
        let _ = fs::remove_dir_all(&dir);
    }

    /// A page stitched from a folder (`strata-stitch-NAME-PID`) holding one result `file`;
    /// returns the folder and the page.
    fn stitch_one(name: &str, file: &str, json: &str) -> (PathBuf, String) {
        let dir = std::env::temp_dir().join(format!("strata-stitch-{name}-{}", std::process::id()));
        let _ = fs::remove_dir_all(&dir);
        fs::create_dir_all(&dir).unwrap();
        fs::write(dir.join(file), json).unwrap();
        let s = StitchSettings {
            from: dir.clone(),
            out: dir.join("report.html"),
            title: name.into(),
            figures: Vec::new(),
            force: false,
        };
        let html = fs::read_to_string(stitch(&s).unwrap()).unwrap();
        (dir, html)
    }

    /// `eval --technique ils --progressive K` (a real run: cornell 64×48, K = 16) gets ILS
    /// Table 5 as a table and a log–log plot, and its interleaved and brute-force rows side
    /// by side; the K-long RMS curves are not flattened into the settings table.
    #[test]
    fn an_ils_progressive_eval_gets_table_5_and_its_curves() {
        let (dir, html) = stitch_one(
            "ils",
            "eval-ils.json",
            include_str!("testdata/eval-ils-progressive.json"),
        );
        assert!(!html.contains("<td>progressive."), "curves flattened into the settings");
        assert!(html.contains("ILS Table 5 (§6.3): K = 16 VPL sets"), "{html}");
        for row in [
            "<td>1x1</td>",
            "<td>2x2</td>",
            "<td>ils 8x6</td>",
            "<td>brute force (all N VPLs at every pixel)</td>",
        ] {
            assert!(html.contains(row), "{row}");
        }
        let curves = fs::read_to_string(dir.join("report-eval-ils-progressive.svg")).unwrap();
        for name in [
            "1x1 vs converged",
            "2x2 vs converged",
            "1x1 vs path tracer",
            "target 1 %",
        ] {
            assert!(curves.contains(name), "{name}");
        }
        let bars = fs::read_to_string(dir.join("report-eval-ils-errors.svg")).unwrap();
        assert!(bars.contains("brute force (all N VPLs at every pixel)"));
        let _ = fs::remove_dir_all(&dir);
    }

    /// `eval --technique full --views` (a real run: atrium 320×180) gets its views, ꟻLIP
    /// and region tables and the regions' colour-error plot, not a flattened key list.
    #[test]
    fn a_views_eval_gets_its_tables_and_region_plot() {
        let (dir, html) = stitch_one("views", "eval-views.json", include_str!("testdata/eval-views.json"));
        assert!(html.contains("eval full --views on atrium"), "{html}");
        assert!(!html.contains("<td>regions."), "regions flattened into the settings");
        for row in [
            "<td>final</td>",
            "<td>probe-only</td>",
            "<td>final (blend)</td>",
            "<td>columns-blue-green</td>",
        ] {
            assert!(html.contains(row), "{row}");
        }
        let plot = fs::read_to_string(dir.join("report-eval-views-regions.svg")).unwrap();
        for name in ["soffits-yellow-blue", "probes only", "deep G-buffer only"] {
            assert!(plot.contains(name), "{name}");
        }
        let _ = fs::remove_dir_all(&dir);
    }

    /// A folder with nothing to stitch (or an eval report folder itself) is a one-line error
    /// naming it, and no page is written.
    #[test]
    fn an_empty_folder_is_an_error_not_an_empty_page() {
        let dir = std::env::temp_dir().join(format!("strata-stitch-empty-{}", std::process::id()));
        let _ = fs::remove_dir_all(&dir);
        fs::create_dir_all(&dir).unwrap();
        fs::write(dir.join("a.png"), b"png").unwrap();
        let s = StitchSettings {
            from: dir.clone(),
            out: dir.join("report.html"),
            title: "t".into(),
            figures: Vec::new(),
            force: false,
        };
        let e = stitch(&s).unwrap_err().to_string();
        assert!(
            e.contains("--from") && e.contains("nothing to report") && !e.contains('\n'),
            "{e}"
        );
        assert!(!dir.join("report.html").exists());
        fs::write(dir.join("index.html"), "<html>").unwrap();
        let e = stitch(&s).unwrap_err().to_string();
        assert!(e.contains("evaluation report of its own"), "{e}");
        let _ = fs::remove_dir_all(&dir);
    }
}
