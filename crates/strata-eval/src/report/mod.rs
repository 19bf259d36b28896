//! Self-contained HTML reports: a title, sections of text, real tables (rows and columns with
//! the numbers right-aligned), SVG plots made with `plotters` ([`plot`]) and rows of images with
//! captions. No scripts, no external resources; images and plots are files beside the page,
//! referenced by relative paths. Every file is written atomically.
//!
//! [`sections`] turns benchmark and evaluation results into tables and plots; [`stitch`] builds
//! one page from a folder of result JSON files (the demo's report).

use std::fmt::Write as _;
use std::fs;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use serde_json::Value;

pub mod plot;
pub mod sections;
pub mod stitch;

/// One image (or plot) of a section.
#[derive(Clone, Debug, PartialEq)]
pub struct ReportImage {
    pub caption: String,
    /// Path of the image relative to the page's directory.
    pub file: String,
}

/// A table cell.
#[derive(Clone, Debug, PartialEq)]
pub enum Cell {
    Text(String),
    /// Printed to 4 significant digits, right-aligned.
    Num(f64),
    /// Printed as "–".
    Missing,
}

impl From<&str> for Cell {
    fn from(s: &str) -> Self {
        Cell::Text(s.into())
    }
}

impl From<String> for Cell {
    fn from(s: String) -> Self {
        Cell::Text(s)
    }
}

impl From<f64> for Cell {
    fn from(x: f64) -> Self {
        Cell::Num(x)
    }
}

impl From<f32> for Cell {
    fn from(x: f32) -> Self {
        Cell::Num(x as f64)
    }
}

impl<T: Into<Cell>> From<Option<T>> for Cell {
    fn from(x: Option<T>) -> Self {
        x.map_or(Cell::Missing, Into::into)
    }
}

/// A table with a header row; the first column is a row label.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Table {
    pub caption: String,
    pub header: Vec<String>,
    pub rows: Vec<Vec<Cell>>,
}

impl Table {
    pub fn new(caption: impl Into<String>, header: &[&str]) -> Self {
        Self {
            caption: caption.into(),
            header: header.iter().map(|h| h.to_string()).collect(),
            rows: Vec::new(),
        }
    }

    pub fn row(&mut self, cells: Vec<Cell>) -> &mut Self {
        self.rows.push(cells);
        self
    }

    /// A two-column `name | value` table of a JSON object, nested keys flattened into dotted
    /// names such as `layers_1.flip`.
    pub fn key_values(caption: impl Into<String>, numbers: &Value) -> Self {
        let mut rows = Vec::new();
        flatten("", numbers, &mut rows);
        let mut t = Table::new(caption, &["name", "value"]);
        for (k, v) in rows {
            t.row(vec![Cell::Text(k), v]);
        }
        t
    }
}

/// A piece of a section.
#[derive(Clone, Debug, PartialEq)]
pub enum Block {
    /// A paragraph (line breaks kept).
    Text(String),
    /// Preformatted text.
    Pre(String),
    Table(Table),
    /// A row of images or plots with captions.
    Figures(Vec<ReportImage>),
    /// A link to another page.
    Link {
        href: String,
        text: String,
    },
}

/// A heading and its blocks.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Section {
    pub title: String,
    pub blocks: Vec<Block>,
}

impl Section {
    pub fn new(title: impl Into<String>) -> Self {
        Self {
            title: title.into(),
            blocks: Vec::new(),
        }
    }

    pub fn text(mut self, text: impl Into<String>) -> Self {
        let text = text.into();
        if !text.is_empty() {
            self.blocks.push(Block::Text(text));
        }
        self
    }

    pub fn table(mut self, t: Table) -> Self {
        self.blocks.push(Block::Table(t));
        self
    }

    pub fn figures(mut self, images: Vec<ReportImage>) -> Self {
        if !images.is_empty() {
            self.blocks.push(Block::Figures(images));
        }
        self
    }
}

/// A whole page.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Page {
    pub title: String,
    pub sections: Vec<Section>,
}

const STYLE: &str = "body{font-family:sans-serif;margin:1.5em;color:#222;background:#fafafa;max-width:1400px}\
table{border-collapse:collapse;margin:0.5em 0 1.5em}\
caption{text-align:left;font-weight:bold;padding:2px 0}\
td,th{border:1px solid #ccc;padding:2px 8px;text-align:left}\
th{background:#eee}\
td.num{text-align:right;font-family:monospace}\
.text{white-space:pre-wrap}\
pre{background:#f0f0f0;padding:6px;overflow-x:auto}\
.row{display:flex;flex-wrap:wrap;gap:8px;align-items:flex-start}\
figure{margin:0;flex:1 1 320px;max-width:640px}\
img{width:100%;height:auto;image-rendering:pixelated;display:block;background:#000}\
img.plot{image-rendering:auto;background:#fff}\
figcaption{font-size:90%;padding:2px 0}";

impl Page {
    pub fn new(title: impl Into<String>) -> Self {
        Self {
            title: title.into(),
            sections: Vec::new(),
        }
    }

    /// The page's HTML. Every piece of text is escaped.
    pub fn render(&self) -> String {
        let t = escape(&self.title);
        let mut h = String::new();
        // `write!` into a String cannot fail.
        let _ = write!(
            h,
            "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>{t}</title>\n\
             <style>{STYLE}</style>\n</head>\n<body>\n<h1>{t}</h1>\n"
        );
        for s in &self.sections {
            let _ = writeln!(h, "<section>\n<h2>{}</h2>", escape(&s.title));
            for b in &s.blocks {
                render_block(&mut h, b);
            }
            h.push_str("</section>\n");
        }
        h.push_str("</body>\n</html>\n");
        h
    }

    /// Writes the page to `path` atomically (creating its folder); returns `path`.
    pub fn write(&self, path: &Path) -> Result<PathBuf> {
        write_file(path, self.render().as_bytes())?;
        Ok(path.to_path_buf())
    }
}

/// Writes `bytes` to `path` atomically, creating the parent folder.
pub fn write_file(path: &Path, bytes: &[u8]) -> Result<()> {
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        fs::create_dir_all(dir).with_context(|| format!("{}: cannot create the report directory", dir.display()))?;
    }
    strata_scene::atomic::write(path, bytes).map_err(|e| anyhow::anyhow!("cannot write the report: {e}"))
}

fn render_block(h: &mut String, b: &Block) {
    match b {
        Block::Text(t) => {
            let _ = writeln!(h, "<p class=\"text\">{}</p>", escape(t));
        }
        Block::Pre(t) => {
            let _ = writeln!(h, "<pre>{}</pre>", escape(t));
        }
        Block::Link { href, text } => {
            let _ = writeln!(h, "<p><a href=\"{}\">{}</a></p>", escape(href), escape(text));
        }
        Block::Table(t) => render_table(h, t),
        Block::Figures(images) => {
            h.push_str("<div class=\"row\">\n");
            for img in images {
                let (file, caption) = (escape(&img.file), escape(&img.caption));
                let class = if img.file.ends_with(".svg") {
                    " class=\"plot\""
                } else {
                    ""
                };
                let _ = writeln!(
                    h,
                    "<figure><a href=\"{file}\"><img{class} src=\"{file}\" alt=\"{caption}\"></a>\
                     <figcaption>{caption}</figcaption></figure>"
                );
            }
            h.push_str("</div>\n");
        }
    }
}

fn render_table(h: &mut String, t: &Table) {
    h.push_str("<table>\n");
    if !t.caption.is_empty() {
        let _ = writeln!(h, "<caption>{}</caption>", escape(&t.caption));
    }
    if !t.header.is_empty() {
        h.push_str("<tr>");
        for c in &t.header {
            let _ = write!(h, "<th>{}</th>", escape(c));
        }
        h.push_str("</tr>\n");
    }
    for row in &t.rows {
        h.push_str("<tr>");
        for c in row {
            match c {
                Cell::Text(s) => {
                    let _ = write!(h, "<td>{}</td>", escape(s));
                }
                Cell::Num(x) => {
                    let _ = write!(h, "<td class=\"num\">{}</td>", escape(&sig4(*x)));
                }
                Cell::Missing => h.push_str("<td class=\"num\">–</td>"),
            }
        }
        h.push_str("</tr>\n");
    }
    h.push_str("</table>\n");
}

/// Flattens `v` into `(dotted key, formatted value)` rows, in the JSON map's key order (sorted, unless
/// serde_json's `preserve_order` feature is enabled) and array index order.
fn flatten(prefix: &str, v: &Value, out: &mut Vec<(String, Cell)>) {
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
            out.push((key, leaf_cell(leaf)));
        }
    }
}

fn leaf_cell(v: &Value) -> Cell {
    match v {
        Value::Number(n) if n.is_f64() => n.as_f64().map_or_else(|| Cell::Text(n.to_string()), Cell::Num),
        Value::Number(n) => Cell::Text(n.to_string()),
        Value::String(s) => Cell::Text(s.clone()),
        Value::Bool(b) => Cell::Text(b.to_string()),
        Value::Null => Cell::Missing,
        // Containers are flattened before reaching here.
        other => Cell::Text(other.to_string()),
    }
}

/// `x` to 4 significant digits: fixed notation for magnitudes in [1e-3, 1e6), scientific otherwise.
pub fn sig4(x: f64) -> String {
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
pub fn escape(s: &str) -> String {
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
    fn page_escapes_text_and_renders_tables_and_images() {
        let dir = std::env::temp_dir()
            .join(format!("strata-report-test-{}", std::process::id()))
            .join("out");
        let mut t = Table::new("errors <by k>", &["k", "FLIP", "MAE & co"]);
        t.row(vec!["1 <one>".into(), Cell::Num(0.123456789), Cell::Missing]);
        t.row(vec!["2".into(), 12345.678f64.into(), Some(0.0000123456f64).into()]);
        let page = Page {
            title: "eval <cornell>".into(),
            sections: vec![
                Section::new("AO <layers>").text("1 & 2 layers").table(t).figures(vec![
                    ReportImage {
                        caption: "reference \"CPU\" <64 spp>".into(),
                        file: "ref.png".into(),
                    },
                    ReportImage {
                        caption: "plot".into(),
                        file: "errors.svg".into(),
                    },
                ]),
                Section::new("Empty").text(""),
            ],
        };
        let path = page.write(&dir.join("index.html")).unwrap();
        let html = fs::read_to_string(&path).unwrap();
        let _ = fs::remove_dir_all(dir.parent().unwrap());

        assert!(html.contains("<h1>eval &lt;cornell&gt;</h1>"));
        assert!(html.contains("AO &lt;layers&gt;"));
        assert!(html.contains("1 &amp; 2 layers"));
        assert!(html.contains("reference &quot;CPU&quot; &lt;64 spp&gt;"));
        assert!(!html.contains("<64 spp>") && !html.contains("<layers>") && !html.contains("<one>"));
        assert!(html.contains("<caption>errors &lt;by k&gt;</caption>"));
        assert!(html.contains("<tr><th>k</th><th>FLIP</th><th>MAE &amp; co</th></tr>"));
        assert!(html.contains("<tr><td>1 &lt;one&gt;</td><td class=\"num\">0.1235</td><td class=\"num\">–</td></tr>"));
        assert!(html.contains("<td class=\"num\">12350</td><td class=\"num\">1.235e-5</td>"));
        assert!(html.contains("<img src=\"ref.png\""));
        assert!(html.contains("<img class=\"plot\" src=\"errors.svg\""));
        assert_eq!(html.matches("<figure>").count(), 2);
        assert_eq!(html.matches("<p class=\"text\">").count(), 1, "empty text adds nothing");
    }

    #[test]
    fn key_value_tables_flatten_json() {
        let t = Table::key_values(
            "numbers",
            &serde_json::json!({"scene": "cornell", "layers_1": {"flip": 0.5, "pixels": 4096}, "n": null}),
        );
        let html = Page {
            title: "t".into(),
            sections: vec![Section::new("s").table(t)],
        }
        .render();
        assert!(html.contains("<td>layers_1.flip</td><td class=\"num\">0.5000</td>"));
        assert!(html.contains("<td>layers_1.pixels</td><td>4096</td>"));
        assert!(html.contains("<td>scene</td><td>cornell</td>"));
        assert!(html.contains("<td>n</td><td class=\"num\">–</td>"));
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
        assert_eq!(rows[1].1, Cell::Text("true".into()));
    }
}
