//! Shared helpers for GPU tests (run on lavapipe when no GPU is present).
#![allow(dead_code)]

pub mod quads;

use strata_render::frame::FrameCameras;
use strata_render::{GpuContext, GpuOptions, RenderSettings, Renderer};
use strata_scene::{Camera, Scene};

/// Opens the GPU. Tests fail (never skip) without one: `scripts/test.sh` installs lavapipe.
pub fn gpu() -> GpuContext {
    GpuContext::new(&GpuOptions::default()).expect("a Vulkan adapter (scripts/test.sh installs Mesa lavapipe)")
}

/// Renders `scene` with `camera` at frame 0; panics on any wgpu validation error.
pub fn render(gpu: &GpuContext, scene: &Scene, camera: &Camera, w: u32, h: u32) -> Renderer {
    let mut r = Renderer::new(
        gpu,
        scene,
        RenderSettings {
            width: w,
            height: h,
            ..Default::default()
        },
    )
    .expect("renderer builds without validation errors");
    r.render(gpu, scene, &FrameCameras::fixed(*camera), 0.0)
        .expect("frame renders without validation errors");
    r
}

/// `../shared/scenes/<rel>` next to the repository, if present.
pub fn shared_scene(rel: &str) -> Option<std::path::PathBuf> {
    let p = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/scenes")
        .join(rel);
    if p.exists() {
        Some(p)
    } else {
        let test = std::thread::current().name().unwrap_or("?").to_string();
        strata_scene::skip::note_skip(&test, &format!("shared scene not found at {}", p.display()));
        None
    }
}

/// World normals of layer `layer` (0 or 1) decoded from a read-back `npack`
/// (Oct16, RGBA8) exactly as the shaders decode them.
pub fn npack_normals(npack: &strata_scene::ImageBuf, layer: usize) -> strata_scene::ImageBuf {
    let mut out = strata_scene::ImageBuf::new(npack.width, npack.height, 3);
    for (o, p) in out.data.chunks_exact_mut(3).zip(npack.data.chunks_exact(4)) {
        let q = |v: f32| (v * 255.0).round() as u8;
        let n = strata_render::packing::oct16_unpack([q(p[2 * layer]), q(p[2 * layer + 1])]);
        o.copy_from_slice(&n.to_array());
    }
    out
}
