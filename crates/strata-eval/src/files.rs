//! Image outputs that refuse to overwrite existing files unless forced.

use std::path::Path;

use anyhow::{bail, Context, Result};
use strata_scene::ImageBuf;

/// Refuses to overwrite an existing file unless `force` and refuses formats other than PNG and
/// EXR; creates the parent folders.
pub fn check_output(path: &Path, force: bool) -> Result<()> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase());
    if !matches!(ext.as_deref(), Some("png") | Some("exr")) {
        bail!(
            "--out {}: unsupported format: use a .png or .exr file name",
            path.display()
        );
    }
    if path.exists() && !force {
        bail!("--out {}: file exists; pass --force to overwrite it", path.display());
    }
    if let Some(dir) = path.parent() {
        if !dir.as_os_str().is_empty() {
            std::fs::create_dir_all(dir).with_context(|| format!("--out: cannot create folder {}", dir.display()))?;
        }
    }
    Ok(())
}

/// Saves `img` (atomically, by `ImageBuf::save`); `srgb` encodes linear values for PNG.
pub fn save(img: &ImageBuf, path: &Path, srgb: bool) -> Result<()> {
    img.save(path, srgb).map_err(|e| anyhow::anyhow!(e))
}
