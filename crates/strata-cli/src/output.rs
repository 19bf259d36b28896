//! Scene/camera resolution from arguments and safe output writing.

use std::path::Path;

use anyhow::{bail, Context, Result};
use strata_render::frame::FrameCameras;
use strata_scene::{Camera, ImageBuf, Scene};

use crate::args::SceneArgs;

/// Loads the scene and resolves the cameras of frames --frame − 1, --frame and
/// --frame + 1 (the scene's path, then flag overrides).
pub fn scene_and_camera(a: &SceneArgs) -> Result<(Scene, FrameCameras)> {
    let scene = strata_scene::load_scene(&a.scene).map_err(|e| anyhow::anyhow!("--scene: {e}"))?;
    if !a.frame.is_finite() || a.frame < 0.0 {
        bail!("--frame {} is out of range: must be a finite number >= 0", a.frame);
    }
    let cams = cameras_at(&scene, a, a.frame);
    let camera = cams.current;
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
    Ok((scene, cams))
}

/// The cameras of frames `f − 1`, `f`, `f + 1` with the flag overrides applied.
pub fn cameras_at(scene: &Scene, a: &SceneArgs, f: f32) -> FrameCameras {
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
        if let Some(fov) = a.fov {
            c.fov_y_deg = fov;
        }
        c
    };
    FrameCameras {
        previous: apply(scene.camera_at(f - 1.0)),
        current: apply(scene.camera_at(f)),
        next_view: apply(scene.camera_at(f + 1.0)).view(),
    }
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
