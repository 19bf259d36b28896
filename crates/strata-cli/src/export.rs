//! `strata export-scene`: the scene at one frame, with the camera, as files an
//! external renderer can read (used by `scripts/mitsuba_check.py`).
//!
//! Output folder:
//!
//! - `scene.json`: camera (exactly `strata_scene::Camera` plus the image size),
//!   materials, lights, scene settings, bounds and the reference's ray epsilon;
//! - `mesh-NNN.ply`, one per material NNN that has triangles: binary
//!   little-endian PLY, world-space triangles at the frame **unshared** (vertex
//!   `3i + k` is corner k of triangle i, in the order of
//!   `Scene::world_triangles` restricted to that material), per vertex
//!   `x y z nx ny nz u v` (float32), faces `vertex_indices` (uchar count, int32
//!   indices), counter-clockwise = front face, as in strata. Normals are the
//!   per-vertex shading normals; a zero normal (which strata's reference would
//!   replace by the geometric normal) is written as the triangle's geometric
//!   normal so a reader never has to normalise a zero vector.

use std::fmt::Write as _;
use std::path::PathBuf;

use anyhow::{anyhow, bail, Context, Result};
use clap::Args;
use glam::Vec3;
use serde_json::json;
use strata_reference::Reference;
use strata_scene::{Scene, WorldTriangle};

use crate::args::SceneArgs;
use crate::output::scene_and_camera;

/// Version tag written into `scene.json` (bump when the layout changes).
pub const FORMAT: &str = "strata-export/1";

#[derive(Args)]
pub struct ExportArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    /// Output folder: scene.json and one mesh-NNN.ply per material with triangles.
    #[arg(long)]
    pub out: PathBuf,
    /// Overwrite existing files in the output folder.
    #[arg(long)]
    pub force: bool,
    /// Print the summary (triangles, files) as one JSON object on stdout.
    #[arg(long)]
    pub json: bool,
}

pub fn run(a: &ExportArgs) -> Result<()> {
    let (scene, cams) = scene_and_camera(&a.scene)?;
    let camera = cams.current;
    let frame = a.scene.frame;
    let tris = scene.world_triangles(frame);

    // Group the triangles by material (indices past the table use the default
    // material in the reference; they are exported under their own index).
    let mut by_material: std::collections::BTreeMap<u32, Vec<&WorldTriangle>> = Default::default();
    for t in &tris {
        by_material.entry(t.material).or_default().push(t);
    }
    let mesh_name = |m: u32| format!("mesh-{m:03}.ply");

    let json_path = a.out.join("scene.json");
    let mut outputs = vec![json_path.clone()];
    outputs.extend(by_material.keys().map(|&m| a.out.join(mesh_name(m))));
    if a.out.exists() && !a.out.is_dir() {
        bail!("--out {}: exists and is not a folder", a.out.display());
    }
    if !a.force {
        if let Some(p) = outputs.iter().find(|p| p.exists()) {
            bail!(
                "--out {}: {} exists; pass --force to overwrite it",
                a.out.display(),
                p.display()
            );
        }
    }
    std::fs::create_dir_all(&a.out).with_context(|| format!("--out: cannot create folder {}", a.out.display()))?;

    // The reference's ray epsilon (needs the BVH bounds; the same formula as the oracle).
    let epsilon = Reference::new(&scene, frame).epsilon();

    let mut files = Vec::new();
    for (&m, list) in &by_material {
        let path = a.out.join(mesh_name(m));
        strata_scene::atomic::write(&path, &ply_bytes(list)).map_err(|e| anyhow!(e))?;
        files.push(mesh_name(m));
    }

    let (lo, hi) = bounds(&tris);
    let doc = json!({
        "format": FORMAT,
        "scene": scene.name,
        "source": a.scene.scene,
        "frame": frame,
        "camera": camera_json(&camera, a.scene.width, a.scene.height),
        "materials": materials_json(&scene, &by_material, mesh_name),
        "lights": scene.lights,
        "settings": {
            "sky": scene.settings.sky,
            "ao_radius": scene.settings.ao_radius,
            "exposure": scene.settings.exposure,
            "ambient": scene.settings.ambient,
            "min_separation": scene.settings.min_separation,
            "radiosity_radius": scene.settings.radiosity_radius,
        },
        "triangles": tris.len(),
        "bounds": { "min": lo, "max": hi },
        "ray_epsilon": epsilon,
        "ply": {
            "layout": "binary_little_endian; vertex: float x y z nx ny nz u v; face: list uchar int vertex_indices; \
                       unshared vertices (3 per triangle, in scene order); counter-clockwise = front face",
        },
    });
    let text = serde_json::to_string_pretty(&doc)? + "\n";
    strata_scene::atomic::write(&json_path, text.as_bytes()).map_err(|e| anyhow!(e))?;

    if a.json {
        println!(
            "{}",
            json!({ "out": a.out, "triangles": tris.len(), "materials": scene.materials.len(), "meshes": files })
        );
    } else {
        eprintln!(
            "wrote {} ({} triangles in {} mesh file(s))",
            json_path.display(),
            tris.len(),
            files.len()
        );
    }
    Ok(())
}

/// The camera exactly as `strata_scene::Camera` models it, with its derived basis
/// and the convention spelled out.
fn camera_json(c: &strata_scene::Camera, width: u32, height: u32) -> serde_json::Value {
    let (right, up, forward) = c.basis();
    json!({
        "eye": c.eye,
        "target": c.target,
        "up": c.up,
        "forward": forward,
        "right": right,
        "true_up": up,
        "fov_y_deg": c.fov_y_deg,
        "near": c.near,
        "width": width,
        "height": height,
        "convention": "right-handed, +Y up; forward = normalize(target - eye), right = normalize(forward x up), \
                       true_up = right x forward; fov_y_deg is the vertical field of view; pixel (x, y) has its \
                       centre at (x + 0.5, y + 0.5), y grows downwards; the ray through it is \
                       forward + right * ndc_x * tan(fov_y/2) * width/height + true_up * ndc_y * tan(fov_y/2), \
                       ndc_x = 2 (x + 0.5)/width - 1, ndc_y = 1 - 2 (y + 0.5)/height (unit component along \
                       forward, so its ray parameter is camera-space depth); primary hits need depth > near",
    })
}

fn materials_json(
    scene: &Scene,
    by_material: &std::collections::BTreeMap<u32, Vec<&WorldTriangle>>,
    mesh_name: impl Fn(u32) -> String,
) -> serde_json::Value {
    let default = strata_scene::Material::default();
    let mut indices: Vec<u32> = (0..scene.materials.len() as u32).collect();
    indices.extend(
        by_material
            .keys()
            .copied()
            .filter(|&m| m as usize >= scene.materials.len()),
    );
    let list: Vec<_> = indices
        .into_iter()
        .map(|i| {
            let m = scene.materials.get(i as usize).unwrap_or(&default);
            let texture = m
                .base_color_texture
                .and_then(|t| scene.textures.get(t).map(|tex| (t, tex)));
            let count = by_material.get(&i).map_or(0, |v| v.len());
            json!({
                "index": i,
                "name": m.name,
                "albedo": m.base_color,
                "textured": texture.is_some(),
                "texture": texture.map(|(t, tex)| json!({ "index": t, "width": tex.width, "height": tex.height })),
                "emission": m.emission,
                "emissive": m.is_emissive(),
                "triangles": count,
                "mesh": (count > 0).then(|| mesh_name(i)),
            })
        })
        .collect();
    serde_json::Value::Array(list)
}

fn bounds(tris: &[WorldTriangle]) -> (Vec3, Vec3) {
    let mut lo = Vec3::splat(f32::INFINITY);
    let mut hi = Vec3::splat(f32::NEG_INFINITY);
    for t in tris {
        for p in t.p {
            lo = lo.min(p);
            hi = hi.max(p);
        }
    }
    if tris.is_empty() {
        (Vec3::ZERO, Vec3::ZERO)
    } else {
        (lo, hi)
    }
}

/// Binary little-endian PLY of unshared triangles.
fn ply_bytes(tris: &[&WorldTriangle]) -> Vec<u8> {
    let mut header = String::new();
    let _ = write!(
        header,
        "ply\nformat binary_little_endian 1.0\ncomment strata export-scene ({FORMAT})\n\
         element vertex {}\nproperty float x\nproperty float y\nproperty float z\n\
         property float nx\nproperty float ny\nproperty float nz\nproperty float u\nproperty float v\n\
         element face {}\nproperty list uchar int vertex_indices\nend_header\n",
        tris.len() * 3,
        tris.len()
    );
    let mut out = header.into_bytes();
    out.reserve(tris.len() * (3 * 32 + 13));
    for t in tris {
        let ng = (t.p[1] - t.p[0]).cross(t.p[2] - t.p[0]).normalize_or_zero();
        for k in 0..3 {
            let n = if t.n[k] == Vec3::ZERO || !t.n[k].is_finite() {
                ng
            } else {
                t.n[k]
            };
            for v in [t.p[k].x, t.p[k].y, t.p[k].z, n.x, n.y, n.z, t.uv[k][0], t.uv[k][1]] {
                out.extend_from_slice(&v.to_le_bytes());
            }
        }
    }
    for i in 0..tris.len() as u32 {
        out.push(3);
        for k in 0..3 {
            out.extend_from_slice(&(3 * i + k).to_le_bytes());
        }
    }
    out
}
