//! `strata compare`: two images of the same size with the metrics `eval` uses.
//!
//! Without `--exposure` the values are compared as the files store them
//! (`strata_eval::metrics::compare`, as `eval --technique ao` does): a PNG's bytes are
//! what `eval` hands ꟻLIP, sRGB-encoded display values or ambient visibility's raw
//! 255·AV, so two PNGs, or an AO EXR and its PNG, compare as `eval` would. With
//! `--exposure E` both are EXRs of linear radiance, displayed as the tonemapper does
//! (exposure, ACES, sRGB) for FLIP, with RMSE and MAE of the linear values
//! (`compare_radiance`, as `eval --technique gi` does); a PNG holds display values
//! and is refused there.

use std::path::PathBuf;

use anyhow::{anyhow, bail, Result};
use clap::Args;
use serde_json::json;
use strata_eval::files::check_output_for;
use strata_eval::metrics::{compare, compare_radiance};
use strata_scene::image_buf::is_png;
use strata_scene::ImageBuf;

#[derive(Args)]
pub struct CompareArgs {
    /// Reference image (.exr linear, or .png display values; AO PNGs hold 255·AV).
    pub reference: PathBuf,
    /// Test image, same size.
    pub test: PathBuf,
    /// Treat both as linear radiance: FLIP on exposure × value through ACES and sRGB (as `eval --technique gi`), > 0.
    #[arg(long)]
    pub exposure: Option<f32>,
    /// Write the FLIP error map (PNG).
    #[arg(long)]
    pub map: Option<PathBuf>,
    /// Overwrite an existing --map file.
    #[arg(long)]
    pub force: bool,
    /// Print one JSON object on stdout.
    #[arg(long)]
    pub json: bool,
}

/// RGB (alpha dropped) of an image file, the values it stores (`ImageBuf::load_stored`).
fn load_rgb(path: &std::path::Path) -> Result<ImageBuf> {
    if !path.exists() {
        bail!("{}: no such file", path.display());
    }
    let rgba = ImageBuf::load_stored(path).map_err(|e| anyhow!(e))?;
    let mut out = ImageBuf::new(rgba.width, rgba.height, 3);
    for (o, p) in out.data.chunks_exact_mut(3).zip(rgba.data.chunks_exact(4)) {
        o.copy_from_slice(&p[..3]);
    }
    if let Some(v) = out.data.iter().find(|v| !v.is_finite()) {
        bail!("{}: holds a non-finite value ({v})", path.display());
    }
    Ok(out)
}

fn mean(img: &ImageBuf) -> f64 {
    img.data.iter().map(|&v| v as f64).sum::<f64>() / img.data.len().max(1) as f64
}

pub fn run(a: &CompareArgs) -> Result<()> {
    if let Some(e) = a.exposure {
        if !(e > 0.0 && e.is_finite()) {
            bail!("--exposure {e} is out of range: must be > 0");
        }
    }
    let pngs: Vec<&PathBuf> = [&a.reference, &a.test].into_iter().filter(|p| is_png(p)).collect();
    if let (Some(e), Some(p)) = (a.exposure, pngs.first()) {
        bail!(
            "--exposure {e} compares linear radiance, but {} holds display values (tonemapped, sRGB): compare two EXRs with --exposure, or drop it",
            p.display()
        );
    }
    if let Some(m) = &a.map {
        check_output_for("--map", m, a.force)?;
    }
    let reference = load_rgb(&a.reference)?;
    let test = load_rgb(&a.test)?;
    // an EXR with values above 1 holds radiance, which a PNG's display values never match
    if let (Some(png), 1) = (pngs.first(), pngs.len()) {
        let (exr, img) = if is_png(&a.reference) {
            (&a.test, &test)
        } else {
            (&a.reference, &reference)
        };
        if img.data.iter().any(|&v| v > 1.0) {
            eprintln!(
                "strata: warning: compare: {} holds linear radiance (values above 1) and {} display values: the two do not match whatever the renders; compare two EXRs with --exposure, or two PNGs",
                exr.display(),
                png.display()
            );
        }
    }
    if (reference.width, reference.height) != (test.width, test.height) {
        bail!(
            "{} is {}x{} but {} is {}x{}: images must have the same size",
            a.reference.display(),
            reference.width,
            reference.height,
            a.test.display(),
            test.width,
            test.height
        );
    }
    let (stats, map) = match a.exposure {
        Some(e) => compare_radiance(&reference, &test, e)?,
        None => compare(&reference, &test)?,
    };
    if let Some(m) = &a.map {
        map.save(m, false).map_err(|e| anyhow!(e))?;
    }
    let (mr, mt) = (mean(&reference), mean(&test));
    if a.json {
        println!(
            "{}",
            json!({
                "reference": a.reference,
                "test": a.test,
                "width": reference.width,
                "height": reference.height,
                "mode": if a.exposure.is_some() { "radiance" } else { "values" },
                "exposure": a.exposure,
                "flip": stats.flip,
                "rmse": stats.rmse,
                "mae": stats.mae,
                "mean_reference": mr,
                "mean_test": mt,
                "mean_difference": mt - mr,
            })
        );
    } else {
        println!(
            "FLIP {:.4}  RMSE {:.5}  MAE {:.5}  mean {:.5} (reference) {:.5} (test), difference {:+.5}",
            stats.flip,
            stats.rmse,
            stats.mae,
            mr,
            mt,
            mt - mr
        );
    }
    Ok(())
}
