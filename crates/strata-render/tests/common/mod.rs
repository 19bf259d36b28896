//! Shared helpers for GPU tests (run on lavapipe when no GPU is present).
#![allow(dead_code)]

pub mod quads;

/// A scene of flat convex polygons (one mesh each, fan-triangulated, front face by
/// the winding of the first three corners), one grey material, the given camera
/// and AO radius.
pub fn polygons_scene(name: &str, polygons: &[&[glam::Vec3]], camera: Camera, ao_radius: f32) -> Scene {
    use strata_scene::model::{Material, Mesh, Object, SceneSettings};
    let mut meshes = Vec::new();
    let mut objects = Vec::new();
    for (i, p) in polygons.iter().enumerate() {
        let n = (p[1] - p[0]).cross(p[2] - p[0]).normalize();
        meshes.push(Mesh {
            name: format!("{name}-{i}"),
            positions: p.iter().map(|q| q.to_array()).collect(),
            normals: vec![n.to_array(); p.len()],
            uvs: vec![[0.0; 2]; p.len()],
            indices: (1..p.len() as u32 - 1).flat_map(|k| [0, k, k + 1]).collect(),
            material: 0,
        });
        objects.push(Object {
            name: format!("{name}-{i}"),
            mesh: i,
            transform: glam::Mat4::IDENTITY,
            animation: None,
        });
    }
    Scene {
        name: name.into(),
        meshes,
        objects,
        materials: vec![Material::diffuse("grey", [0.5; 3])],
        camera,
        settings: SceneSettings {
            ao_radius,
            ..Default::default()
        },
        ..Default::default()
    }
}

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
