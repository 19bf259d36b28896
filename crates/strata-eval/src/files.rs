//! Image outputs that refuse to overwrite existing files unless forced.

use std::path::Path;

use anyhow::{bail, Context, Result};
use strata_scene::ImageBuf;

/// Refuses to overwrite an existing file unless `force`, a folder in the file's place, and
/// formats other than PNG and EXR; creates the parent folders. Errors name `--out`.
pub fn check_output(path: &Path, force: bool) -> Result<()> {
    check_output_for("--out", path, force)
}

/// [`check_output`] for an image named by the command-line flag `flag` (e.g. `--images`).
pub fn check_output_for(flag: &str, path: &Path, force: bool) -> Result<()> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase());
    if !matches!(ext.as_deref(), Some("png") | Some("exr")) {
        bail!(
            "{flag} {}: unsupported format: use a .png or .exr file name",
            path.display()
        );
    }
    refuse_existing(flag, path, force)?;
    if let Some(dir) = path.parent() {
        if !dir.as_os_str().is_empty() {
            std::fs::create_dir_all(dir).with_context(|| format!("{flag}: cannot create folder {}", dir.display()))?;
        }
    }
    Ok(())
}

/// Refuses a folder where the file `path` (named by `flag`) is to go, before any work is done
/// (`--force` replaces files, never folders), and an existing file unless `force`.
pub fn refuse_existing(flag: &str, path: &Path, force: bool) -> Result<()> {
    if path.is_dir() {
        bail!("{flag} {}: is a folder; name a file", path.display());
    }
    if path.exists() && !force {
        bail!("{flag} {}: file exists; pass --force to overwrite it", path.display());
    }
    Ok(())
}

/// Saves `img` (atomically, by `ImageBuf::save`); `srgb` encodes linear values for PNG.
pub fn save(img: &ImageBuf, path: &Path, srgb: bool) -> Result<()> {
    img.save(path, srgb).map_err(|e| anyhow::anyhow!(e))
}
