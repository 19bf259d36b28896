//! Scene/camera resolution from arguments and safe output writing.

use std::path::Path;

use anyhow::{bail, Context, Result};
use strata_scene::{Camera, ImageBuf, Scene};

use crate::args::SceneArgs;

/// Loads the scene and resolves the camera (scene path at --frame, then flag overrides).
pub fn scene_and_camera(a: &SceneArgs) -> Result<(Scene, Camera, Camera)> {
    let scene = strata_scene::load_scene(&a.scene).map_err(|e| anyhow::anyhow!("--scene: {e}"))?;
    if !a.frame.is_finite() || a.frame < 0.0 {
        bail!("--frame {} is out of range: must be a finite number >= 0", a.frame);
    }
    let apply = |mut c: Camera| {
        if let Some(e) = a.eye {
            c.eye = e;
        }
        if let Some(t) = a.target {
            c.target = t;
        }
        if let Some(u) = a.up {
            c.up = u;
        }
        if let Some(f) = a.fov {
            c.fov_y_deg = f;
        }
        c
    };
    let camera = apply(scene.camera_at(a.frame));
    let prev = apply(scene.camera_at(a.frame - 1.0));
    camera
        .validate()
        .map_err(|e| anyhow::anyhow!("--eye/--target/--up/--fov: {e}"))?;
    for (name, v) in [("--width", a.width), ("--height", a.height)] {
        if !(strata_render::renderer::MIN_SIZE..=strata_render::renderer::MAX_SIZE).contains(&v) {
            bail!(
                "{name} {v} is out of range: must be in {}..={}",
                strata_render::renderer::MIN_SIZE,
                strata_render::renderer::MAX_SIZE
            );
        }
    }
    Ok((scene, camera, prev))
}

/// Refuses to overwrite an existing file unless `force`; creates parent folders.
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

pub fn save(img: &ImageBuf, path: &Path, srgb: bool) -> Result<()> {
    img.save(path, srgb).map_err(|e| anyhow::anyhow!(e))
}
