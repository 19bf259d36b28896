//! `strata report`: one HTML page from a folder of results (`strata_eval::report::stitch`).

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use strata_eval::report::stitch::{stitch, StitchSettings};

#[derive(Args)]
pub struct ReportArgs {
    /// Folder of results: `*.json` written by `strata bench … --json` / `strata eval … --json`,
    /// `info.txt`, and subfolders holding an `index.html` (linked).
    #[arg(long)]
    pub from: PathBuf,
    /// The page to write (plots are written beside it; images are relative to its folder).
    #[arg(long)]
    pub out: PathBuf,
    /// Page title.
    #[arg(long, default_value = "strata report")]
    pub title: String,
    /// A section of images: "Title=a.png,b.png" (files relative to --out's folder); repeatable.
    #[arg(long = "figures", value_parser = parse_figures)]
    pub figures: Vec<(String, Vec<String>)>,
    /// Overwrite an existing page.
    #[arg(long)]
    pub force: bool,
}

fn parse_figures(s: &str) -> Result<(String, Vec<String>), String> {
    let (title, files) = s
        .split_once('=')
        .ok_or_else(|| format!("'{s}' is not a figure section: expected \"Title=a.png,b.png\""))?;
    let files = files
        .split(',')
        .map(str::trim)
        .filter(|f| !f.is_empty())
        .map(String::from)
        .collect();
    Ok((title.trim().to_string(), files))
}

pub fn run(a: &ReportArgs) -> Result<()> {
    let path = stitch(&StitchSettings {
        from: a.from.clone(),
        out: a.out.clone(),
        title: a.title.clone(),
        figures: a.figures.clone(),
        force: a.force,
    })?;
    eprintln!("wrote {}", path.display());
    Ok(())
}
