//! A minimal, self-contained HTML report for `strata eval`: a title, a table of the run's numbers
//! (flattened from JSON) and sections of side-by-side images with captions. No scripts, no
//! external resources; images are referenced by paths relative to the report's directory.

use std::fmt::Write as _;
use std::fs;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use serde_json::Value;

/// One image of a section.
#[derive(Clone, Debug)]
pub struct ReportImage {
    pub caption: String,
    /// Path of the image relative to the report's directory.
    pub file: String,
}

/// A heading, a paragraph of text and a row of images.
#[derive(Clone, Debug)]
pub struct ReportSection {
    pub title: String,
    pub images: Vec<ReportImage>,
    pub text: String,
}

const STYLE: &str = "body{font-family:sans-serif;margin:1.5em;color:#222;background:#fafafa}\
table{border-collapse:collapse;margin-bottom:1.5em}\
td,th{border:1px solid #ccc;padding:2px 8px;text-align:left}\
td.num{text-align:right;font-family:monospace}\
.text{white-space:pre-wrap}\
.row{display:flex;flex-wrap:wrap;gap:8px;align-items:flex-start}\
figure{margin:0;flex:1 1 320px;max-width:640px}\
img{width:100%;height:auto;image-rendering:pixelated;display:block;background:#000}\
figcaption{font-size:90%;padding:2px 0}";

/// Writes `dir/index.html` (creating `dir` if needed) and returns its path.
///
/// `numbers` is shown as a two-column table: nested objects (and arrays) are flattened into dotted
/// keys such as `layers_1.flip`, and floats are printed to 4 significant digits. Every piece of
/// text is HTML-escaped.
pub fn write_report(dir: &Path, title: &str, sections: &[ReportSection], numbers: &Value) -> Result<PathBuf> {
    fs::create_dir_all(dir).with_context(|| format!("{}: cannot create the report directory", dir.display()))?;
    let path = dir.join("index.html");
    strata_scene::atomic::write(&path, render(title, sections, numbers).as_bytes())
        .map_err(|e| anyhow::anyhow!("cannot write the report: {e}"))?;
    Ok(path)
}

fn render(title: &str, sections: &[ReportSection], numbers: &Value) -> String {
    let t = escape(title);
    let mut h = String::new();
    // `write!` into a String cannot fail.
    let _ = write!(
        h,
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>{t}</title>\n\
         <style>{STYLE}</style>\n</head>\n<body>\n<h1>{t}</h1>\n"
    );

    let mut rows = Vec::new();
    flatten("", numbers, &mut rows);
    if !rows.is_empty() {
        h.push_str("<table>\n<tr><th>metric</th><th>value</th></tr>\n");
        for (k, v) in rows {
            let _ = writeln!(
                h,
                "<tr><td>{}</td><td class=\"num\">{}</td></tr>",
                escape(&k),
                escape(&v)
            );
        }
        h.push_str("</table>\n");
    }

    for s in sections {
        let _ = writeln!(h, "<section>\n<h2>{}</h2>", escape(&s.title));
        if !s.text.is_empty() {
            let _ = writeln!(h, "<p class=\"text\">{}</p>", escape(&s.text));
        }
        if !s.images.is_empty() {
            h.push_str("<div class=\"row\">\n");
            for img in &s.images {
                let (file, caption) = (escape(&img.file), escape(&img.caption));
                let _ = writeln!(
                    h,
                    "<figure><a href=\"{file}\"><img src=\"{file}\" alt=\"{caption}\"></a>\
                     <figcaption>{caption}</figcaption></figure>"
                );
            }
            h.push_str("</div>\n");
        }
        h.push_str("</section>\n");
    }
    h.push_str("</body>\n</html>\n");
    h
}

/// Flattens `v` into `(dotted key, formatted value)` rows, in the JSON map's key order (sorted, unless
/// serde_json's `preserve_order` feature is enabled) and array index order.
fn flatten(prefix: &str, v: &Value, out: &mut Vec<(String, String)>) {
    let join = |k: &str| {
        if prefix.is_empty() {
            k.to_string()
        } else {
            format!("{prefix}.{k}")
        }
    };
    match v {
        Value::Object(map) => map.iter().for_each(|(k, v)| flatten(&join(k), v, out)),
        Value::Array(items) => items
            .iter()
            .enumerate()
            .for_each(|(i, v)| flatten(&join(&i.to_string()), v, out)),
        leaf => {
            let key = if prefix.is_empty() {
                "value".to_string()
            } else {
                prefix.to_string()
            };
            out.push((key, format_leaf(leaf)));
        }
    }
}

fn format_leaf(v: &Value) -> String {
    match v {
        Value::Number(n) if n.is_f64() => n.as_f64().map_or_else(|| n.to_string(), sig4),
        Value::Number(n) => n.to_string(),
        Value::String(s) => s.clone(),
        Value::Bool(b) => b.to_string(),
        Value::Null => "–".to_string(),
        // Containers are flattened before reaching here.
        other => other.to_string(),
    }
}

/// `x` to 4 significant digits: fixed notation for magnitudes in [1e-3, 1e6), scientific otherwise.
fn sig4(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return x.to_string();
    }
    // Rounding to 4 digits first gives the right exponent for values like 9.99996 (→ 1.000e1).
    let sci = format!("{x:.3e}");
    let exp: i32 = sci.rsplit('e').next().and_then(|e| e.parse().ok()).unwrap_or(0);
    if (-3..=3).contains(&exp) {
        format!("{x:.*}", (3 - exp) as usize)
    } else if (4..6).contains(&exp) {
        // Integer digits beyond the fourth are rounded away: 12345.6 → 12350.
        let unit = 10f64.powi(exp - 3);
        format!("{:.0}", (x / unit).round() * unit)
    } else {
        sci
    }
}

/// Escapes text for HTML element content and double- or single-quoted attributes.
fn escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn report_contains_escaped_text_images_and_flattened_numbers() {
        let dir = std::env::temp_dir()
            .join(format!("strata-report-test-{}", std::process::id()))
            .join("out");
        let sections = vec![
            ReportSection {
                title: "AO <layers>".into(),
                text: "1 & 2 layers".into(),
                images: vec![
                    ReportImage {
                        caption: "reference \"CPU\" <64 spp>".into(),
                        file: "ref.png".into(),
                    },
                    ReportImage {
                        caption: "test".into(),
                        file: "layers_1/flip.png".into(),
                    },
                ],
            },
            ReportSection {
                title: "Empty".into(),
                text: String::new(),
                images: vec![],
            },
        ];
        let numbers = serde_json::json!({
            "scene": "cornell",
            "layers_1": { "flip": 0.123456789, "rmse": 12345.678, "pixels": 4096 },
            "tiny": 0.0000123456,
        });
        let path = write_report(&dir, "eval <cornell>", &sections, &numbers).unwrap();
        assert_eq!(path, dir.join("index.html"));
        let html = fs::read_to_string(&path).unwrap();
        let _ = fs::remove_dir_all(dir.parent().unwrap());

        assert!(html.contains("<h1>eval &lt;cornell&gt;</h1>"));
        assert!(html.contains("AO &lt;layers&gt;"));
        assert!(html.contains("1 &amp; 2 layers"));
        assert!(html.contains("reference &quot;CPU&quot; &lt;64 spp&gt;"));
        assert!(!html.contains("<64 spp>") && !html.contains("<layers>"));
        for file in ["ref.png", "layers_1/flip.png"] {
            assert!(html.contains(&format!("<img src=\"{file}\"")), "{file}");
        }
        assert!(html.contains("image-rendering:pixelated"));
        assert!(html.contains("<td>layers_1.flip</td><td class=\"num\">0.1235</td>"));
        assert!(html.contains("<td>layers_1.rmse</td><td class=\"num\">12350</td>"));
        assert!(html.contains("<td>layers_1.pixels</td><td class=\"num\">4096</td>"));
        assert!(html.contains("<td>tiny</td><td class=\"num\">1.235e-5</td>"));
        assert!(html.contains("<td>scene</td><td class=\"num\">cornell</td>"));
        assert_eq!(html.matches("<figure>").count(), 2);
    }

    #[test]
    fn floats_have_four_significant_digits() {
        assert_eq!(sig4(0.123456), "0.1235");
        assert_eq!(sig4(1.0), "1.000");
        assert_eq!(sig4(9.99996), "10.00");
        assert_eq!(sig4(-42.4242), "-42.42");
        assert_eq!(sig4(0.001), "0.001000");
        assert_eq!(sig4(123456.7), "123500");
        assert_eq!(sig4(1234.56), "1235");
        assert_eq!(sig4(2.5e7), "2.500e7");
        assert_eq!(sig4(0.0), "0");
    }

    #[test]
    fn flatten_names_nested_and_array_entries() {
        let mut rows = Vec::new();
        flatten(
            "",
            &serde_json::json!({"a": {"b": [1, {"c": true}]}, "n": null}),
            &mut rows,
        );
        let keys: Vec<_> = rows.iter().map(|(k, _)| k.as_str()).collect();
        assert_eq!(keys, ["a.b.0", "a.b.1.c", "n"]);
        assert_eq!(rows[1].1, "true");
    }
}
