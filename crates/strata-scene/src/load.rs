//! Scene files: glTF 2.0 (`.gltf`, `.glb`), Wavefront OBJ/MTL (`.obj`) and
//! TOML scene descriptions (`.toml`). Every error names the file concerned.
//!
//! # Mesh files (glTF, OBJ)
//!
//! - **glTF 2.0** (`gltf::import`: embedded or external buffers and images,
//!   `.glb`): each triangle primitive (mode TRIANGLES, TRIANGLE_STRIP or
//!   TRIANGLE_FAN; points and lines are skipped with a warning) becomes a
//!   [`Mesh`]; every node of the default scene that has a mesh becomes one
//!   [`Object`] per primitive, with the node hierarchy's world transform.
//!   Materials: `baseColorFactor` (linear RGB; its alpha is the opacity unless
//!   `alphaMode` is OPAQUE), `baseColorTexture` (converted to RGBA8),
//!   `emissiveFactor` × `KHR_materials_emissive_strength`, roughness, metallic.
//!   The first perspective camera node becomes the camera. `KHR_lights_punctual`
//!   is not read.
//! - **OBJ/MTL** (`tobj`, triangulated, single index): one [`Mesh`] per
//!   object/group and material. `Kd` → base colour, `map_Kd` → texture
//!   (relative to the MTL file's folder; a missing file is an error naming it),
//!   `Ke` → emission, `d` (or `1 − Tr`) → opacity, `Ns` → roughness
//!   `sqrt(2 / (Ns + 2))`, metallic 0. OBJ texture coordinates are flipped
//!   (`v → 1 − v`) to the top-down convention of [`Texture`] and glTF.
//!   Face indices are checked: an out-of-range index is an error.
//!
//! Both: missing normals are generated (area-weighted smooth), missing UVs are
//! zeros. Without a camera in the file, [`default_camera`] frames the bounds;
//! without lights, [`default_sun`] is added. Settings are scaled to the scene
//! ([`default_settings`]).
//!
//! # Malformed and degenerate input
//!
//! Any input gives a scene or a one-line error naming the file (and the
//! element and valid range where there is one); the loaders are fuzzed
//! (`crates/strata-fuzz`, `docs/reliability.md`).
//!
//! - Sizes read from a file are checked against the bytes that are there
//!   before anything is allocated: glTF accessor counts, offsets and strides
//!   against their buffer views, views against buffers, buffers against their
//!   `byteLength`; an accessor without a buffer view (sparse only) may have at
//!   most [`MAX_ZERO_ACCESSOR`] elements. Textures: see
//!   [`crate::files::decode_texture`] (at most 16384 texels a side, decoded
//!   size bounded by the encoded size).
//! - Referenced files (MTL, textures, glTF buffers and images) must be regular
//!   files ([`DiskFiles`]); `data:` URIs are decoded.
//! - A non-finite vertex position, normal or texture coordinate, or a position
//!   coordinate outside ±[`MAX_COORDINATE`], is an error naming the mesh and the
//!   vertex (OBJ: the line and the `v`/`vn`/`vt` number). A non-finite material
//!   value or node transform is an error naming the material or node; finite
//!   material values are clamped to their ranges (colours and factors to
//!   [0, 1], emission to >= 0).
//! - Zero-length normals in a file are replaced by the generated smooth normal
//!   of that vertex; missing UVs become zeros.
//! - Zero-area and duplicate triangles are kept as they are: they rasterise to
//!   nothing (zero area) or to the same pixels, add nothing to the
//!   area-weighted normals, and the reference's ray test rejects zero-area
//!   triangles; keeping them keeps the triangle counts of the file.
//! - glTF node hierarchies must be trees: a node reached twice (a cycle or a
//!   node with two parents) is an error.
//! - Every loaded scene passes [`Scene::validate`].
//!
//! # TOML scene files
//!
//! A TOML file wraps one mesh file (or a built-in scene) and sets its camera,
//! lights, camera path, settings and animations. Paths are relative to the
//! TOML file. Unknown keys are errors; every value is range-checked and errors
//! name the file, the key and the valid range.
//!
//! ```toml
//! name = "cornell (shared OBJ)"        # optional, default: the file stem
//! mesh = "../../shared/scenes/cornell_box/cornell_box.obj"  # .obj, .gltf or .glb
//! # builtin = "atrium"                  # instead of `mesh`: a built-in scene
//! scale = 0.001                         # optional uniform scale (> 0) of the mesh
//! translate = [0.0, 0.0, 0.0]           # optional translation applied after scaling
//!
//! [camera]                # optional; default: the file's camera or one framing the bounds
//! eye = [0.278, 0.273, -0.8]
//! target = [0.278, 0.273, -0.799]
//! up = [0.0, 1.0, 0.0]    # optional, default +Y
//! fov = 39.3077           # vertical degrees in (0, 180), default 60
//! near = 0.01             # > 0, default: the base scene's near
//!
//! [[light]]               # any number; when present they replace the base scene's lights
//! type = "sun"            # "sun" | "point" | "spot" | "rect"
//! direction = [-0.3, -1.0, -0.4]   # sun, spot: the way photons travel
//! color = [1.0, 1.0, 1.0] # optional, default white, components >= 0
//! illuminance = 3.0       # sun (> 0)
//! # point / spot: position = [x, y, z], intensity = 100.0 (> 0)
//! # spot: inner_deg = 20.0, outer_deg = 30.0 (0 < inner <= outer < 90)
//! # rect: center, half_u, half_v (normal = half_u × half_v), radiance = [r, g, b],
//! #       emitter = true to also add matching emissive geometry
//!
//! [camera_path]           # optional; frames strictly increasing after sorting
//! keyframes = [
//!   { frame = 0, eye = [0.0, 1.0, 5.0], target = [0.0, 1.0, 0.0] },
//!   { frame = 60, eye = [2.0, 1.0, 5.0], target = [0.0, 1.0, 0.0] },
//! ]
//!
//! [settings]              # any subset; the rest keeps the base scene's values
//! ao_radius = 1.0         # > 0
//! min_separation = 0.5    # > 0
//! radiosity_radius = 8.0  # > 0
//! exposure = 1.0          # > 0
//! sky = [0.3, 0.45, 0.75] # >= 0
//! ambient = [0.03, 0.03, 0.03]  # >= 0
//!
//! [ground]                # optional horizontal ground quad (object and material "ground")
//! y = 0.0                 # default: the scene's lowest point
//! size = 10.0             # edge length (> 0), default 3 × the bounds' diagonal
//! color = [0.5, 0.5, 0.5] # albedo, default 0.5 grey
//!
//! [[animate]]             # rigid animation of every object with this name
//! object = "statue"
//! type = "slide"          # "slide": amplitude = [x, y, z], period_frames (> 0)
//! amplitude = [0.0, 0.0, 1.5]
//! period_frames = 60.0
//! # type = "swing": pivot = [x, y, z], axis = [x, y, z], amplitude_deg, period_frames
//! ```
//!
//! A `[camera]` without `[camera_path]` removes a built-in scene's camera path
//! (which would otherwise override the camera). `scale`/`translate` also move
//! the base scene's own camera and lights, but not the TOML's (those are in
//! final world units).

use std::cell::RefCell;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

use glam::{Mat4, Vec3};
use serde::Deserialize;

use crate::camera::Camera;
use crate::error::SceneError;
pub use crate::files::{decode_texture, DiskFiles, FileSource, MemFiles};
use crate::gltf_data;
pub use crate::gltf_data::MAX_ZERO_ACCESSOR;
pub use crate::model::MAX_COORDINATE;
use crate::model::{Animation, Light, Material, Mesh, Object, Scene, SceneSettings, Texture};
use crate::normals::ensure_normals;
use crate::path::{CameraPath, Keyframe};
use crate::shapes::MeshBuilder;

/// File extensions [`load_path`] accepts.
pub const EXTENSIONS: &[&str] = &["gltf", "glb", "obj", "toml"];

/// Loads a scene file, dispatching on its extension (case-insensitive):
/// `.gltf`/`.glb` → [`load_gltf`], `.obj` → [`load_obj`], `.toml` → [`load_toml`].
pub fn load_path(path: &Path) -> Result<Scene, SceneError> {
    if !matches!(extension(path).as_deref(), Some("gltf" | "glb" | "obj" | "toml")) {
        return Err(unsupported_extension(path));
    }
    let bytes = read_file(path, &DiskFiles, "scene file")?;
    load_slice(&bytes, path, &DiskFiles)
}

/// Loads a scene file's contents `bytes`, dispatching on the extension of
/// `path` like [`load_path`]. `path` names the file in errors and locates the
/// files it refers to (MTL libraries, textures, glTF buffers and images, a TOML
/// scene's mesh), which are read through `files`.
pub fn load_slice(bytes: &[u8], path: &Path, files: &dyn FileSource) -> Result<Scene, SceneError> {
    match extension(path).as_deref() {
        Some("gltf" | "glb" | "obj") => load_mesh_slice(bytes, path, files).map(|m| m.into_scene(path))?,
        Some("toml") => load_toml_slice(bytes, path, files),
        _ => Err(unsupported_extension(path)),
    }
}

/// Loads glTF/GLB contents (see [`load_slice`]; external files from disk).
pub fn load_gltf_slice(bytes: &[u8], path: &Path) -> Result<Scene, SceneError> {
    load_mesh_slice(bytes, path, &DiskFiles).map(|m| m.into_scene(path))?
}

/// Loads OBJ text (see [`load_slice`]; MTL libraries and textures from disk).
pub fn load_obj_str(text: &str, path: &Path) -> Result<Scene, SceneError> {
    load_mesh_slice(text.as_bytes(), path, &DiskFiles).map(|m| m.into_scene(path))?
}

/// Reads `path` through `files`; the error names the file and what it is.
fn read_file(path: &Path, files: &dyn FileSource, what: &str) -> Result<Vec<u8>, SceneError> {
    files
        .read(path)
        .map_err(|e| SceneError::file(path, format!("cannot read {what}: {e}")))
}

fn extension(path: &Path) -> Option<String> {
    path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase)
}

fn unsupported_extension(path: &Path) -> SceneError {
    let ext = extension(path)
        .map(|e| format!("'.{e}'"))
        .unwrap_or_else(|| "(none)".into());
    SceneError::file(
        path,
        format!("unsupported file extension {ext}: use .gltf, .glb, .obj or .toml"),
    )
}

/// Loads a glTF 2.0 file (`.gltf` or `.glb`) with default camera/light/settings
/// where the file has none (see the module docs).
pub fn load_gltf(path: &Path) -> Result<Scene, SceneError> {
    load_mesh_file(path, &DiskFiles).map(|m| m.into_scene(path))?
}

/// Loads an OBJ file and its MTL libraries with default camera/light/settings
/// (see the module docs).
pub fn load_obj(path: &Path) -> Result<Scene, SceneError> {
    load_mesh_file(path, &DiskFiles).map(|m| m.into_scene(path))?
}

/// Loads a TOML scene description (format in the module docs).
pub fn load_toml(path: &Path) -> Result<Scene, SceneError> {
    let bytes = read_file(path, &DiskFiles, "scene file")?;
    load_toml_slice(&bytes, path, &DiskFiles)
}

/// Parses a TOML scene description. `path` is used for error messages and to
/// resolve the relative `mesh` path (against its folder).
pub fn load_toml_str(text: &str, path: &Path) -> Result<Scene, SceneError> {
    load_toml_text(text, path, &DiskFiles)
}

/// [`load_toml_str`] on bytes (must be UTF-8), reading the mesh through `files`.
pub fn load_toml_slice(bytes: &[u8], path: &Path, files: &dyn FileSource) -> Result<Scene, SceneError> {
    let text = std::str::from_utf8(bytes).map_err(|e| {
        SceneError::file(
            path,
            format!("invalid scene file: not UTF-8 (byte {})", e.valid_up_to()),
        )
    })?;
    load_toml_text(text, path, files)
}

fn load_toml_text(text: &str, path: &Path, files: &dyn FileSource) -> Result<Scene, SceneError> {
    let doc: TomlScene = toml::from_str(text).map_err(|e| {
        let at = e
            .span()
            .map(|s| {
                let upto = &text.as_bytes()[..s.start.min(text.len())];
                let line = upto.iter().filter(|&&b| b == b'\n').count() + 1;
                let col = upto.iter().rev().take_while(|&&b| b != b'\n').count() + 1;
                format!("line {line}, column {col}: ")
            })
            .unwrap_or_default();
        SceneError::file(path, format!("invalid scene file: {at}{}", e.message().trim()))
    })?;
    let scene = build_toml_scene(doc, path, files)?;
    scene.validate().map_err(|e| SceneError::file(path, e))?;
    Ok(scene)
}

/// A camera on the +Z side of the bounds' centre looking down −Z, far enough
/// back that the bounding sphere fits a 60° vertical field of view; near =
/// diagonal × 1e-3.
pub fn default_camera(lo: Vec3, hi: Vec3) -> Camera {
    let centre = 0.5 * (lo + hi);
    let diag = (hi - lo).length().max(1e-6);
    let fov = 60.0f32;
    let dist = 0.5 * diag / (0.5 * fov.to_radians()).sin();
    Camera::new(centre + Vec3::Z * dist, centre, Vec3::Y, fov, diag * 1e-3)
}

/// The default light of mesh files without lights: a white sun from above-front,
/// direction normalize(−0.3, −1, −0.4), illuminance 3.
pub fn default_sun() -> Light {
    Light::Sun {
        direction: Vec3::new(-0.3, -1.0, -0.4).normalize(),
        color: [1.0; 3],
        illuminance: 3.0,
    }
}

/// Settings for a mesh file with the given bounds: AO radius 2.5 %, minimum
/// separation 1.25 % and radiosity radius 20 % of the bounds' diagonal, a dim
/// bluish sky, exposure 1.
pub fn default_settings(lo: Vec3, hi: Vec3) -> SceneSettings {
    let diag = (hi - lo).length();
    let diag = if diag.is_finite() && diag > 0.0 { diag } else { 1.0 };
    SceneSettings {
        ao_radius: 0.025 * diag,
        min_separation: 0.0125 * diag,
        radiosity_radius: 0.2 * diag,
        exposure: 1.0,
        sky: [0.15, 0.18, 0.22],
        ..SceneSettings::default()
    }
}

/// A loaded mesh file: the scene plus what the file itself provided.
struct MeshFile {
    scene: Scene,
    has_camera: bool,
    has_lights: bool,
}

impl MeshFile {
    /// Fills in the defaults (camera, sun, settings) the file lacks and checks
    /// the result ([`Scene::validate`]).
    fn into_scene(mut self, path: &Path) -> Result<Scene, SceneError> {
        let (lo, hi) = self.scene.bounds(0.0);
        if !self.has_camera {
            self.scene.camera = default_camera(lo, hi);
        }
        if !self.has_lights {
            self.scene.lights = vec![default_sun()];
        }
        self.scene.settings = default_settings(lo, hi);
        self.scene.validate().map_err(|e| SceneError::file(path, e))?;
        Ok(self.scene)
    }
}

/// Loads a glTF or OBJ file without applying defaults.
fn load_mesh_file(path: &Path, files: &dyn FileSource) -> Result<MeshFile, SceneError> {
    if !matches!(extension(path).as_deref(), Some("gltf" | "glb" | "obj")) {
        return Err(SceneError::file(
            path,
            "unsupported mesh file extension: use .gltf, .glb or .obj",
        ));
    }
    let bytes = read_file(path, files, "mesh file")?;
    load_mesh_slice(&bytes, path, files)
}

/// Loads glTF or OBJ contents without applying defaults.
fn load_mesh_slice(bytes: &[u8], path: &Path, files: &dyn FileSource) -> Result<MeshFile, SceneError> {
    let mut file = match extension(path).as_deref() {
        Some("gltf" | "glb") => gltf_file(bytes, path, files)?,
        Some("obj") => obj_file(bytes, path, files)?,
        _ => {
            return Err(SceneError::file(
                path,
                "unsupported mesh file extension: use .gltf, .glb or .obj",
            ));
        }
    };
    if file.scene.triangle_count() == 0 {
        return Err(SceneError::file(path, "the file contains no triangles"));
    }
    for m in &mut file.scene.meshes {
        ensure_normals(m);
        if m.uvs.len() != m.positions.len() {
            m.uvs = vec![[0.0; 2]; m.positions.len()];
        }
    }
    let (lo, hi) = file.scene.bounds(0.0);
    let extent = (hi - lo).abs().max(lo.abs()).max(hi.abs()).max_element();
    if extent.is_nan() || extent > MAX_COORDINATE {
        return Err(SceneError::file(
            path,
            format!("the scene's world-space bounds {lo}..{hi} are out of range: coordinates must be within ±{MAX_COORDINATE:e}"),
        ));
    }
    if file.scene.name.is_empty() {
        file.scene.name = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
    }
    Ok(file)
}

/// Checks a mesh's vertex data: positions finite and within ±[`MAX_COORDINATE`],
/// normals and UVs finite. `what` names the mesh.
fn check_vertices(path: &Path, what: &str, m: &Mesh) -> Result<(), SceneError> {
    for (i, p) in m.positions.iter().enumerate() {
        if !p.iter().all(|c| c.is_finite()) {
            return Err(SceneError::file(
                path,
                format!("{what}: vertex {i} has a non-finite position {p:?}"),
            ));
        }
        if !p.iter().all(|c| c.abs() <= MAX_COORDINATE) {
            return Err(SceneError::file(
                path,
                format!(
                    "{what}: vertex {i} position {p:?} is out of range: coordinates must be within ±{MAX_COORDINATE:e}"
                ),
            ));
        }
    }
    if let Some((i, n)) = m
        .normals
        .iter()
        .enumerate()
        .find(|(_, n)| !n.iter().all(|c| c.is_finite()))
    {
        return Err(SceneError::file(
            path,
            format!("{what}: vertex {i} has a non-finite normal {n:?}"),
        ));
    }
    if let Some((i, t)) = m.uvs.iter().enumerate().find(|(_, t)| !t.iter().all(|c| c.is_finite())) {
        return Err(SceneError::file(
            path,
            format!("{what}: vertex {i} has a non-finite texture coordinate {t:?}"),
        ));
    }
    Ok(())
}

/// Checks a material's values (an error for non-finite ones) and clamps them
/// to their ranges: base colour, opacity, roughness, metallic to [0, 1],
/// emission to >= 0.
fn check_material(path: &Path, m: &mut Material) -> Result<(), SceneError> {
    let named = |field: &str, v: &dyn std::fmt::Debug| {
        SceneError::file(
            path,
            format!(
                "material '{}': {field} {v:?} is out of range: must be finite",
                gltf_data::short(&m.name)
            ),
        )
    };
    if !m.base_color.iter().all(|c| c.is_finite()) {
        return Err(named("base colour", &m.base_color));
    }
    if !m.emission.iter().all(|c| c.is_finite()) {
        return Err(named("emission", &m.emission));
    }
    for (field, v) in [
        ("opacity", m.opacity),
        ("roughness", m.roughness),
        ("metallic", m.metallic),
    ] {
        if !v.is_finite() {
            return Err(named(field, &v));
        }
    }
    m.base_color = m.base_color.map(|c| c.clamp(0.0, 1.0));
    m.emission = m.emission.map(|c| c.max(0.0));
    m.opacity = m.opacity.clamp(0.0, 1.0);
    m.roughness = m.roughness.clamp(0.0, 1.0);
    m.metallic = m.metallic.clamp(0.0, 1.0);
    Ok(())
}

/// Checks every index of `indices` against `vertex_count`.
fn check_indices(path: &Path, what: &str, indices: &[u32], vertex_count: usize) -> Result<(), SceneError> {
    if let Some(&bad) = indices.iter().find(|&&i| i as usize >= vertex_count) {
        return Err(SceneError::file(
            path,
            format!("{what}: vertex index {bad} is out of range (the mesh has {vertex_count} vertices)"),
        ));
    }
    if !indices.len().is_multiple_of(3) {
        return Err(SceneError::file(
            path,
            format!("{what}: index count {} is not a multiple of 3", indices.len()),
        ));
    }
    Ok(())
}

// ---------------------------------------------------------------------------
// glTF

fn gltf_file(bytes: &[u8], path: &Path, files: &dyn FileSource) -> Result<MeshFile, SceneError> {
    let fail = |m: String| SceneError::file(path, m);
    gltf_data::check_glb_header(bytes).map_err(|e| fail(format!("cannot load glTF: {e}")))?;
    let gltf = gltf::Gltf::from_slice_without_validation(bytes).map_err(|e| fail(format!("cannot load glTF: {e}")))?;
    // gltf-json's validation indexes the accessors with each primitive's
    // POSITION index before checking it (a panic when out of range): check
    // attribute indices first.
    let json = gltf.document.into_json();
    gltf_data::check_attribute_indices(&json).map_err(|e| fail(format!("cannot load glTF: {e}")))?;
    let document = gltf::Document::from_json(json).map_err(|e| fail(format!("cannot load glTF: {e}")))?;
    let doc = &document;
    let base = path.parent().unwrap_or(Path::new(""));
    let buffers =
        gltf_data::load_buffers(doc, gltf.blob.as_deref(), base, files).map_err(|e| fail(format!("glTF {e}")))?;
    let mut scene = Scene::default();

    // Materials (+ base colour textures, one per referenced image).
    let mut image_to_texture: HashMap<usize, usize> = HashMap::new();
    let mut material_uv_set: Vec<u32> = Vec::new();
    for (mi, m) in doc.materials().enumerate() {
        let pbr = m.pbr_metallic_roughness();
        let f = pbr.base_color_factor();
        let strength = m.emissive_strength().unwrap_or(1.0);
        let mut mat = Material {
            name: m.name().map(str::to_owned).unwrap_or_else(|| format!("material{mi}")),
            base_color: [f[0], f[1], f[2]],
            base_color_texture: None,
            emission: m.emissive_factor().map(|e| e * strength),
            opacity: if m.alpha_mode() == gltf::material::AlphaMode::Opaque {
                1.0
            } else {
                f[3]
            },
            roughness: pbr.roughness_factor(),
            metallic: pbr.metallic_factor(),
        };
        check_material(path, &mut mat)?;
        let mut uv_set = 0;
        if let Some(info) = pbr.base_color_texture() {
            let source = info.texture().source();
            let image = source.index();
            uv_set = info.tex_coord();
            let ti = match image_to_texture.get(&image) {
                Some(&ti) => ti,
                None => {
                    let name = source
                        .name()
                        .map(str::to_owned)
                        .unwrap_or_else(|| format!("image{image}"));
                    let texture = gltf_data::image_bytes(doc, image, &buffers, base, files)
                        .and_then(|data| decode_texture(&data, &name))
                        .map_err(|e| {
                            fail(format!(
                                "material {mi}: image {image} ('{}'): {e}",
                                gltf_data::short(&name)
                            ))
                        })?;
                    scene.textures.push(texture);
                    image_to_texture.insert(image, scene.textures.len() - 1);
                    scene.textures.len() - 1
                }
            };
            mat.base_color_texture = Some(ti);
        }
        scene.materials.push(mat);
        material_uv_set.push(uv_set);
    }
    let default_material = scene.materials.len();
    let mut default_used = false;

    // Meshes: one of ours per triangle primitive.
    let mut mesh_map: Vec<Vec<usize>> = Vec::new();
    for gm in doc.meshes() {
        let mut ours = Vec::new();
        for prim in gm.primitives() {
            let what = format!(
                "mesh {} ('{}') primitive {}",
                gm.index(),
                gltf_data::short(gm.name().unwrap_or("")),
                prim.index()
            );
            use gltf::mesh::Mode;
            use gltf::Semantic;
            let mode = prim.mode();
            if !matches!(mode, Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan) {
                eprintln!(
                    "warning: {}: {what}: skipping non-triangle primitive ({mode:?})",
                    path.display()
                );
                continue;
            }
            let pos_acc = prim
                .get(&Semantic::Positions)
                .ok_or_else(|| fail(format!("{what}: no POSITION attribute")))?;
            let positions =
                gltf_data::read_vectors::<3>(&pos_acc, &buffers).map_err(|e| fail(format!("{what}: POSITION: {e}")))?;
            let n = positions.len();
            let material = match prim.material().index() {
                Some(i) if i < default_material => i,
                _ => {
                    default_used = true;
                    default_material
                }
            };
            let uv_set = material_uv_set.get(material).copied().unwrap_or(0);
            let normals = match prim.get(&Semantic::Normals) {
                Some(a) => {
                    gltf_data::read_vectors::<3>(&a, &buffers).map_err(|e| fail(format!("{what}: NORMAL: {e}")))?
                }
                None => Vec::new(),
            };
            let uv_acc = prim
                .get(&Semantic::TexCoords(uv_set))
                .or_else(|| prim.get(&Semantic::TexCoords(0)));
            let uvs = match uv_acc {
                Some(a) => {
                    gltf_data::read_vectors::<2>(&a, &buffers).map_err(|e| fail(format!("{what}: TEXCOORD: {e}")))?
                }
                None => Vec::new(),
            };
            for (label, len) in [("NORMAL", normals.len()), ("TEXCOORD", uvs.len())] {
                if len != 0 && len != n {
                    return Err(fail(format!(
                        "{what}: {label} has {len} elements but POSITION has {n} (they must match)"
                    )));
                }
            }
            let raw: Vec<u32> = match prim.indices() {
                Some(a) => gltf_data::read_indices(&a, &buffers).map_err(|e| fail(format!("{what}: indices: {e}")))?,
                None => (0..n as u32).collect(),
            };
            let indices = match mode {
                Mode::TriangleStrip => strip_to_list(&raw),
                Mode::TriangleFan => fan_to_list(&raw),
                _ => raw,
            };
            check_indices(path, &what, &indices, n)?;
            let name = gm
                .name()
                .map(str::to_owned)
                .unwrap_or_else(|| format!("mesh{}", gm.index()));
            let name = if gm.primitives().len() > 1 {
                format!("{name}.{}", prim.index())
            } else {
                name
            };
            let mut mesh = Mesh {
                name,
                positions,
                normals,
                uvs,
                indices,
                material,
            };
            check_vertices(path, &what, &mesh)?;
            // Before any mirrored copy is made (normals follow the original winding).
            ensure_normals(&mut mesh);
            scene.meshes.push(mesh);
            ours.push(scene.meshes.len() - 1);
        }
        mesh_map.push(ours);
    }
    if default_used {
        scene.materials.push(Material::default());
    }

    // Nodes of the default scene (or all root nodes when there is no scene).
    let mut roots: Vec<usize> = match doc.default_scene().or_else(|| doc.scenes().next()) {
        Some(s) => s.nodes().map(|n| n.index()).collect(),
        None => {
            let mut is_child = vec![false; doc.nodes().len()];
            for n in doc.nodes() {
                for c in n.children() {
                    is_child[c.index()] = true;
                }
            }
            doc.nodes()
                .filter(|n| !is_child[n.index()])
                .map(|n| n.index())
                .collect()
        }
    };
    {
        let mut seen = vec![false; doc.nodes().len()];
        roots.retain(|&r| !std::mem::replace(&mut seen[r], true));
    }
    let nodes: Vec<gltf::Node> = doc.nodes().collect();
    let mut visited = vec![false; nodes.len()];
    let mut camera = None;
    let mut flipped: HashMap<usize, usize> = HashMap::new();
    let mut stack: Vec<(usize, Mat4)> = roots.into_iter().map(|n| (n, Mat4::IDENTITY)).collect();
    while let Some((ni, parent)) = stack.pop() {
        let node = &nodes[ni];
        if std::mem::replace(&mut visited[ni], true) {
            return Err(fail(format!(
                "node {ni} is reached twice: the node hierarchy must be a tree (a cycle or a node with two parents)"
            )));
        }
        let local = Mat4::from_cols_array_2d(&node.transform().matrix());
        let world = parent * local;
        if !local.is_finite() || !world.is_finite() {
            return Err(fail(format!(
                "node {ni} ('{}'): transform is out of range: its matrix (and its product with the parents') must be finite",
                gltf_data::short(node.name().unwrap_or(""))
            )));
        }
        if let Some(gm) = node.mesh() {
            let name = node
                .name()
                .map(str::to_owned)
                .unwrap_or_else(|| format!("node{}", node.index()));
            for &mi in mesh_map.get(gm.index()).map(Vec::as_slice).unwrap_or(&[]) {
                // A mirroring transform turns counter-clockwise faces clockwise:
                // use a copy of the mesh with reversed winding.
                let mesh = if world.determinant() < 0.0 {
                    *flipped.entry(mi).or_insert_with(|| {
                        let mut m = scene.meshes[mi].clone();
                        for t in m.indices.chunks_exact_mut(3) {
                            t.swap(1, 2);
                        }
                        m.name.push_str(".mirrored");
                        scene.meshes.push(m);
                        scene.meshes.len() - 1
                    })
                } else {
                    mi
                };
                scene.objects.push(Object {
                    name: name.clone(),
                    mesh,
                    transform: world,
                    animation: None,
                });
            }
        }
        if camera.is_none() {
            // From the JSON: `gltf`'s `Camera::projection` panics when `type`
            // names a projection whose object is missing.
            let perspective = node
                .camera()
                .and_then(|cam| doc.as_json().cameras.get(cam.index()))
                .and_then(|c| c.perspective.as_ref());
            if let Some(p) = perspective {
                {
                    let eye = world.transform_point3(Vec3::ZERO);
                    let fwd = world.transform_vector3(-Vec3::Z).normalize_or_zero();
                    let up = world.transform_vector3(Vec3::Y).normalize_or_zero();
                    let c = Camera::new(eye, eye + fwd, up, p.yfov.to_degrees(), p.znear);
                    if c.validate().is_ok() {
                        camera = Some(c);
                    }
                }
            }
        }
        for c in node.children() {
            stack.push((c.index(), world));
        }
    }
    let has_camera = camera.is_some();
    if let Some(c) = camera {
        scene.camera = c;
    }
    Ok(MeshFile {
        scene,
        has_camera,
        has_lights: false,
    })
}

fn strip_to_list(s: &[u32]) -> Vec<u32> {
    let mut out = Vec::new();
    for i in 2..s.len() {
        if i % 2 == 0 {
            out.extend_from_slice(&[s[i - 2], s[i - 1], s[i]]);
        } else {
            out.extend_from_slice(&[s[i - 1], s[i - 2], s[i]]);
        }
    }
    out
}

fn fan_to_list(s: &[u32]) -> Vec<u32> {
    let mut out = Vec::new();
    for i in 2..s.len() {
        out.extend_from_slice(&[s[0], s[i - 1], s[i]]);
    }
    out
}

// ---------------------------------------------------------------------------
// OBJ / MTL

/// Checks the numbers of the `v`, `vn` and `vt` lines of OBJ text: a
/// non-finite one is an error naming the line and the vertex.
fn obj_check_numbers(path: &Path, bytes: &[u8]) -> Result<(), SceneError> {
    let mut counts = [0usize; 3];
    for (li, line) in bytes.split(|&b| b == b'\n').enumerate() {
        let Ok(line) = std::str::from_utf8(line) else {
            continue;
        };
        let mut words = line.split_whitespace();
        let (k, what) = match words.next() {
            Some("v") => (0, "position"),
            Some("vn") => (1, "normal"),
            Some("vt") => (2, "texture coordinate"),
            _ => continue,
        };
        counts[k] += 1;
        if words.any(|w| w.parse::<f32>().is_ok_and(|x| !x.is_finite())) {
            return Err(SceneError::file(
                path,
                format!(
                    "line {}: vertex {} has a non-finite {what} ('{}'): values must be finite f32",
                    li + 1,
                    counts[k],
                    gltf_data::short(line.trim())
                ),
            ));
        }
    }
    Ok(())
}

/// Checks what `tobj` would panic on in an MTL file: a colour (`Ka`, `Kd`,
/// `Ks`, `Ke`) with fewer than 3 numbers.
fn check_mtl(bytes: &[u8]) -> Result<(), String> {
    for (li, line) in bytes.split(|&b| b == b'\n').enumerate() {
        let Ok(line) = std::str::from_utf8(line) else {
            continue;
        };
        let mut words = line.split_whitespace();
        if let Some(key @ ("Ka" | "Kd" | "Ks" | "Ke")) = words.next() {
            let n = words.count();
            if n < 3 {
                return Err(format!(
                    "line {}: '{key}' has {n} values: it needs 3 numbers (r g b)",
                    li + 1
                ));
            }
        }
    }
    Ok(())
}

fn obj_file(bytes: &[u8], path: &Path, files: &dyn FileSource) -> Result<MeshFile, SceneError> {
    obj_check_numbers(path, bytes)?;
    let dir = path.parent().unwrap_or(Path::new("")).to_path_buf();
    // MTL libraries in load order: (path, number of materials or the error).
    let libraries: RefCell<Vec<(PathBuf, Result<usize, String>)>> = RefCell::new(Vec::new());
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ..Default::default()
    };
    let (models, materials) = tobj::load_obj_buf(&mut std::io::Cursor::new(bytes), &options, |mtl| {
        let full = dir.join(mtl);
        let result = match files.read(&full) {
            Ok(text) => match check_mtl(&text) {
                // tobj panics on a colour line with fewer than 3 numbers.
                Err(why) => Err((tobj::LoadError::MaterialParseError, why)),
                Ok(()) => tobj::load_mtl_buf(&mut std::io::Cursor::new(text)).map_err(|e| (e, e.to_string())),
            },
            Err(why) => Err((tobj::LoadError::OpenFileFailed, format!("cannot open it: {why}"))),
        };
        libraries.borrow_mut().push((
            full,
            result.as_ref().map(|(m, _)| m.len()).map_err(|(_, why)| why.clone()),
        ));
        result.map_err(|(e, _)| e)
    })
    .map_err(|e| SceneError::file(path, format!("invalid OBJ file: {e}")))?;
    let libraries = libraries.into_inner();
    for (lib, result) in &libraries {
        if let Err(why) = result {
            return Err(SceneError::file(
                path,
                format!("material library {}: {why}", lib.display()),
            ));
        }
    }
    let materials = materials.unwrap_or_default();
    // Folder of the MTL each material came from (for its texture paths).
    let mut material_dirs = Vec::with_capacity(materials.len());
    let mut material_libs = Vec::with_capacity(materials.len());
    for (lib, result) in &libraries {
        for _ in 0..*result.as_ref().unwrap_or(&0) {
            material_dirs.push(lib.parent().unwrap_or(Path::new("")).to_path_buf());
            material_libs.push(lib.clone());
        }
    }

    let mut scene = Scene::default();
    let mut textures: HashMap<PathBuf, usize> = HashMap::new();
    for (i, m) in materials.iter().enumerate() {
        let mut mat = Material {
            name: m.name.clone(),
            ..Default::default()
        };
        if let Some(kd) = m.diffuse {
            mat.base_color = kd;
        }
        if let Some(ke) = m.emissive {
            mat.emission = ke;
        }
        if let Some(d) = m.dissolve {
            mat.opacity = d.clamp(0.0, 1.0);
        } else if let Some(tr) = m.unknown_param.get("Tr").and_then(|t| t.trim().parse::<f32>().ok()) {
            mat.opacity = (1.0 - tr).clamp(0.0, 1.0);
        }
        if let Some(ns) = m.shininess {
            mat.roughness = (2.0 / (ns.max(0.0) + 2.0)).sqrt();
        }
        mat.metallic = 0.0;
        check_material(path, &mut mat)?;
        if let Some(tex) = &m.diffuse_texture {
            let rel = texture_file_name(tex);
            let base = material_dirs.get(i).cloned().unwrap_or_else(|| dir.clone());
            let full = base.join(&rel);
            let ti = match textures.get(&full) {
                Some(&ti) => ti,
                None => {
                    let lib = material_libs
                        .get(i)
                        .map(|l| l.display().to_string())
                        .unwrap_or_default();
                    let texture = read_texture(&full, files).map_err(|e| {
                        SceneError::file(
                            path,
                            format!(
                                "material '{}' in {lib}: texture {} (map_Kd {rel}): {e}",
                                m.name,
                                full.display()
                            ),
                        )
                    })?;
                    scene.textures.push(texture);
                    textures.insert(full, scene.textures.len() - 1);
                    scene.textures.len() - 1
                }
            };
            mat.base_color_texture = Some(ti);
        }
        scene.materials.push(mat);
    }
    let default_material = scene.materials.len();
    let mut default_used = false;

    for model in models {
        let m = model.mesh;
        if m.indices.is_empty() {
            continue;
        }
        let what = format!("object '{}'", gltf_data::short(&model.name));
        if m.positions.len() % 3 != 0 {
            return Err(SceneError::file(path, format!("{what}: malformed positions")));
        }
        let n = m.positions.len() / 3;
        check_indices(path, &what, &m.indices, n)?;
        let positions: Vec<[f32; 3]> = m.positions.chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect();
        let normals: Vec<[f32; 3]> = if m.normals.len() == 3 * n {
            m.normals.chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect()
        } else {
            Vec::new()
        };
        let uvs: Vec<[f32; 2]> = if m.texcoords.len() == 2 * n {
            m.texcoords.chunks_exact(2).map(|t| [t[0], 1.0 - t[1]]).collect()
        } else {
            Vec::new()
        };
        let material = match m.material_id {
            Some(i) if i < default_material => i,
            _ => {
                default_used = true;
                default_material
            }
        };
        let mesh = Mesh {
            name: model.name.clone(),
            positions,
            normals,
            uvs,
            indices: m.indices,
            material,
        };
        check_vertices(path, &what, &mesh)?;
        scene.meshes.push(mesh);
        scene.objects.push(Object {
            name: model.name,
            mesh: scene.meshes.len() - 1,
            transform: Mat4::IDENTITY,
            animation: None,
        });
    }
    if default_used {
        scene.materials.push(Material::default());
    }
    Ok(MeshFile {
        scene,
        has_camera: false,
        has_lights: false,
    })
}

/// The file name in a `map_Kd` value: options (`-s 1 1 1 file.png`) are
/// skipped by taking the last word; backslashes become slashes.
fn texture_file_name(value: &str) -> String {
    let v = value.trim();
    let v = if v.starts_with('-') {
        v.split_whitespace().last().unwrap_or(v)
    } else {
        v
    };
    v.replace('\\', "/")
}

/// Loads an image file as an RGBA8 [`Texture`] (8-bit texels kept as stored,
/// i.e. sRGB-encoded for colour maps).
/// Within the limits of [`decode_texture`].
pub fn load_texture(path: &Path) -> Result<Texture, String> {
    read_texture(path, &DiskFiles)
}

fn read_texture(path: &Path, files: &dyn FileSource) -> Result<Texture, String> {
    let bytes = files.read(path)?;
    let name = path
        .file_name()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    decode_texture(&bytes, &name)
}

// ---------------------------------------------------------------------------
// TOML

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TomlScene {
    name: Option<String>,
    mesh: Option<String>,
    builtin: Option<String>,
    scale: Option<f32>,
    translate: Option<[f32; 3]>,
    camera: Option<TomlCamera>,
    #[serde(default)]
    light: Vec<TomlLight>,
    camera_path: Option<TomlPath>,
    settings: Option<TomlSettings>,
    ground: Option<TomlGround>,
    #[serde(default)]
    animate: Vec<TomlAnimate>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TomlCamera {
    eye: [f32; 3],
    target: [f32; 3],
    up: Option<[f32; 3]>,
    fov: Option<f32>,
    near: Option<f32>,
}

fn white() -> [f32; 3] {
    [1.0; 3]
}

fn default_inner() -> f32 {
    20.0
}

fn default_outer() -> f32 {
    30.0
}

#[derive(Deserialize)]
#[serde(tag = "type", rename_all = "lowercase", deny_unknown_fields)]
enum TomlLight {
    Sun {
        direction: [f32; 3],
        #[serde(default = "white")]
        color: [f32; 3],
        illuminance: f32,
    },
    Point {
        position: [f32; 3],
        #[serde(default = "white")]
        color: [f32; 3],
        intensity: f32,
    },
    Spot {
        position: [f32; 3],
        direction: [f32; 3],
        #[serde(default = "white")]
        color: [f32; 3],
        intensity: f32,
        #[serde(default = "default_inner")]
        inner_deg: f32,
        #[serde(default = "default_outer")]
        outer_deg: f32,
    },
    Rect {
        center: [f32; 3],
        half_u: [f32; 3],
        half_v: [f32; 3],
        radiance: [f32; 3],
        #[serde(default)]
        emitter: bool,
    },
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TomlPath {
    keyframes: Vec<TomlKeyframe>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TomlKeyframe {
    frame: f32,
    eye: [f32; 3],
    target: [f32; 3],
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TomlSettings {
    ao_radius: Option<f32>,
    min_separation: Option<f32>,
    radiosity_radius: Option<f32>,
    exposure: Option<f32>,
    sky: Option<[f32; 3]>,
    ambient: Option<[f32; 3]>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TomlGround {
    y: Option<f32>,
    size: Option<f32>,
    color: Option<[f32; 3]>,
}

#[derive(Deserialize)]
#[serde(tag = "type", rename_all = "lowercase", deny_unknown_fields)]
enum TomlAnimate {
    Swing {
        object: String,
        pivot: [f32; 3],
        axis: [f32; 3],
        amplitude_deg: f32,
        period_frames: f32,
    },
    Slide {
        object: String,
        amplitude: [f32; 3],
        period_frames: f32,
    },
}

/// Range checks with messages naming the key and the valid range.
struct Check<'a> {
    path: &'a Path,
}

impl Check<'_> {
    fn err(&self, key: &str, msg: impl std::fmt::Display) -> SceneError {
        SceneError::file(self.path, format!("{key}: {msg}"))
    }

    fn positive(&self, key: &str, x: f32) -> Result<f32, SceneError> {
        if x.is_finite() && x > 0.0 {
            Ok(x)
        } else {
            Err(self.err(key, format!("{x} is out of range: must be finite and > 0")))
        }
    }

    fn finite(&self, key: &str, x: f32) -> Result<f32, SceneError> {
        if x.is_finite() {
            Ok(x)
        } else {
            Err(self.err(key, format!("{x} is out of range: must be finite")))
        }
    }

    fn vec(&self, key: &str, v: [f32; 3]) -> Result<Vec3, SceneError> {
        let v = Vec3::from(v);
        if v.is_finite() {
            Ok(v)
        } else {
            Err(self.err(key, format!("{v} is out of range: components must be finite")))
        }
    }

    fn direction(&self, key: &str, v: [f32; 3]) -> Result<Vec3, SceneError> {
        let v = self.vec(key, v)?;
        if v.length() > 1e-12 {
            Ok(v.normalize())
        } else {
            Err(self.err(key, "must be a non-zero vector"))
        }
    }

    fn color(&self, key: &str, c: [f32; 3]) -> Result<[f32; 3], SceneError> {
        if c.iter().all(|x| x.is_finite() && *x >= 0.0) {
            Ok(c)
        } else {
            Err(self.err(
                key,
                format!("{c:?} is out of range: components must be finite and >= 0"),
            ))
        }
    }
}

fn build_toml_scene(doc: TomlScene, path: &Path, files: &dyn FileSource) -> Result<Scene, SceneError> {
    let ck = Check { path };
    let dir = path.parent().unwrap_or(Path::new(""));

    // Base scene.
    let (mut scene, has_camera, from_file) = match (&doc.mesh, &doc.builtin) {
        (Some(_), Some(_)) => return Err(ck.err("mesh", "give either `mesh` or `builtin`, not both")),
        (None, None) => {
            return Err(ck.err(
                "mesh",
                "missing: give `mesh = \"file.obj|.gltf|.glb\"` or `builtin = \"name\"`",
            ));
        }
        (None, Some(name)) => {
            let s = crate::procedural::builtin(name).ok_or_else(|| {
                ck.err(
                    "builtin",
                    format!(
                        "unknown built-in scene '{name}': use one of {}",
                        crate::procedural::BUILTIN_NAMES.join(", ")
                    ),
                )
            })?;
            (s, true, false)
        }
        (Some(mesh), None) => {
            let mesh_path = dir.join(mesh);
            if !matches!(extension(&mesh_path).as_deref(), Some("obj" | "gltf" | "glb")) {
                return Err(ck.err("mesh", format!("'{mesh}' must be a .obj, .gltf or .glb file")));
            }
            let f =
                load_mesh_file(&mesh_path, files).map_err(|e| ck.err("mesh", format!("cannot load '{mesh}': {e}")))?;
            let has_camera = f.has_camera;
            let mut s = f.scene;
            if !f.has_lights {
                s.lights = vec![default_sun()];
            }
            (s, has_camera, true)
        }
    };

    // Placement of the base scene.
    let scale = match doc.scale {
        Some(s) => ck.positive("scale", s)?,
        None => 1.0,
    };
    let translate = match doc.translate {
        Some(t) => ck.vec("translate", t)?,
        None => Vec3::ZERO,
    };
    let place = Mat4::from_translation(translate) * Mat4::from_scale(Vec3::splat(scale));
    if place != Mat4::IDENTITY {
        transform_scene(&mut scene, place, scale);
    }

    // Defaults that depend on the placed geometry (before the ground is added,
    // so that the default camera frames the mesh, not the ground).
    let (lo, hi) = scene.bounds(0.0);
    if from_file {
        scene.settings = default_settings(lo, hi);
        if !has_camera {
            scene.camera = default_camera(lo, hi);
        }
    }

    // Ground quad.
    if let Some(g) = &doc.ground {
        let y = match g.y {
            Some(y) => ck.finite("ground.y", y)?,
            None => lo.y,
        };
        let size = match g.size {
            Some(s) => ck.positive("ground.size", s)?,
            None => 3.0 * (hi - lo).length().max(1e-3),
        };
        let color = ck.color("ground.color", g.color.unwrap_or([0.5; 3]))?;
        let c = 0.5 * (lo + hi);
        let mut b = MeshBuilder::new();
        b.rect(Vec3::new(c.x, y, c.z), Vec3::Z * (0.5 * size), Vec3::X * (0.5 * size)); // z × x = +y
        add_object(&mut scene, "ground", b, Material::diffuse("ground", color));
    }

    // Camera.
    if let Some(c) = &doc.camera {
        let cam = Camera::new(
            ck.vec("camera.eye", c.eye)?,
            ck.vec("camera.target", c.target)?,
            ck.vec("camera.up", c.up.unwrap_or([0.0, 1.0, 0.0]))?,
            c.fov.unwrap_or(60.0),
            c.near.unwrap_or(scene.camera.near),
        );
        if !(cam.fov_y_deg > 0.0 && cam.fov_y_deg < 180.0) {
            return Err(ck.err(
                "camera.fov",
                format!("{} is out of range: must be in (0, 180) degrees", cam.fov_y_deg),
            ));
        }
        if !(cam.near.is_finite() && cam.near > 0.0) {
            return Err(ck.err("camera.near", format!("{} is out of range: must be > 0", cam.near)));
        }
        cam.validate().map_err(|e| ck.err("camera", e))?;
        scene.camera = cam;
        scene.camera_path = None;
    }

    // Camera path.
    if let Some(p) = &doc.camera_path {
        let mut keys = Vec::with_capacity(p.keyframes.len());
        for (i, k) in p.keyframes.iter().enumerate() {
            let key = format!("camera_path.keyframes[{i}]");
            let frame = ck.finite(&format!("{key}.frame"), k.frame)?;
            let eye = ck.vec(&format!("{key}.eye"), k.eye)?;
            let target = ck.vec(&format!("{key}.target"), k.target)?;
            Camera {
                eye,
                target,
                ..scene.camera
            }
            .validate()
            .map_err(|e| ck.err(&key, e))?;
            keys.push(Keyframe { frame, eye, target });
        }
        scene.camera_path = Some(CameraPath::new(keys).map_err(|e| ck.err("camera_path.keyframes", e))?);
    }

    // Lights.
    if !doc.light.is_empty() {
        let mut lights = Vec::with_capacity(doc.light.len());
        for (i, l) in doc.light.iter().enumerate() {
            let k = |f: &str| format!("light[{i}].{f}");
            let light = match l {
                TomlLight::Sun {
                    direction,
                    color,
                    illuminance,
                } => Light::Sun {
                    direction: ck.direction(&k("direction"), *direction)?,
                    color: ck.color(&k("color"), *color)?,
                    illuminance: ck.positive(&k("illuminance"), *illuminance)?,
                },
                TomlLight::Point {
                    position,
                    color,
                    intensity,
                } => Light::Point {
                    position: ck.vec(&k("position"), *position)?,
                    color: ck.color(&k("color"), *color)?,
                    intensity: ck.positive(&k("intensity"), *intensity)?,
                },
                TomlLight::Spot {
                    position,
                    direction,
                    color,
                    intensity,
                    inner_deg,
                    outer_deg,
                } => {
                    if !(*outer_deg > 0.0 && *outer_deg < 90.0) {
                        return Err(ck.err(
                            &k("outer_deg"),
                            format!("{outer_deg} is out of range: must be in (0, 90) degrees"),
                        ));
                    }
                    if !(*inner_deg > 0.0 && inner_deg <= outer_deg) {
                        return Err(ck.err(
                            &k("inner_deg"),
                            format!("{inner_deg} is out of range: must be in (0, outer_deg = {outer_deg}] degrees"),
                        ));
                    }
                    Light::Spot {
                        position: ck.vec(&k("position"), *position)?,
                        direction: ck.direction(&k("direction"), *direction)?,
                        color: ck.color(&k("color"), *color)?,
                        intensity: ck.positive(&k("intensity"), *intensity)?,
                        inner_deg: *inner_deg,
                        outer_deg: *outer_deg,
                    }
                }
                TomlLight::Rect {
                    center,
                    half_u,
                    half_v,
                    radiance,
                    emitter,
                } => {
                    let center = ck.vec(&k("center"), *center)?;
                    let half_u = ck.vec(&k("half_u"), *half_u)?;
                    let half_v = ck.vec(&k("half_v"), *half_v)?;
                    if half_u.cross(half_v).length() <= 1e-12 {
                        return Err(ck.err(&k("half_u"), "half_u and half_v must be non-zero and not parallel"));
                    }
                    let radiance = ck.color(&k("radiance"), *radiance)?;
                    if radiance.iter().all(|&r| r == 0.0) {
                        return Err(ck.err(&k("radiance"), "is out of range: must have a component > 0"));
                    }
                    if *emitter {
                        let mut b = MeshBuilder::new();
                        b.rect(center, half_u, half_v);
                        add_object(
                            &mut scene,
                            &format!("light{i}"),
                            b,
                            Material::emissive(&format!("light{i}"), radiance),
                        );
                    }
                    Light::Rect {
                        center,
                        half_u,
                        half_v,
                        radiance,
                    }
                }
            };
            lights.push(light);
        }
        scene.lights = lights;
    }

    // Settings.
    if let Some(s) = &doc.settings {
        let st = &mut scene.settings;
        if let Some(x) = s.ao_radius {
            st.ao_radius = ck.positive("settings.ao_radius", x)?;
        }
        if let Some(x) = s.min_separation {
            st.min_separation = ck.positive("settings.min_separation", x)?;
        }
        if let Some(x) = s.radiosity_radius {
            st.radiosity_radius = ck.positive("settings.radiosity_radius", x)?;
        }
        if let Some(x) = s.exposure {
            st.exposure = ck.positive("settings.exposure", x)?;
        }
        if let Some(c) = s.sky {
            st.sky = ck.color("settings.sky", c)?;
        }
        if let Some(c) = s.ambient {
            st.ambient = ck.color("settings.ambient", c)?;
        }
    }

    // Animations.
    for (i, a) in doc.animate.iter().enumerate() {
        let k = |f: &str| format!("animate[{i}].{f}");
        let (object, animation) = match a {
            TomlAnimate::Swing {
                object,
                pivot,
                axis,
                amplitude_deg,
                period_frames,
            } => (
                object,
                Animation::Swing {
                    pivot: ck.vec(&k("pivot"), *pivot)?,
                    axis: ck.direction(&k("axis"), *axis)?,
                    amplitude_deg: ck.finite(&k("amplitude_deg"), *amplitude_deg)?,
                    period_frames: ck.positive(&k("period_frames"), *period_frames)?,
                },
            ),
            TomlAnimate::Slide {
                object,
                amplitude,
                period_frames,
            } => (
                object,
                Animation::Slide {
                    amplitude: ck.vec(&k("amplitude"), *amplitude)?,
                    period_frames: ck.positive(&k("period_frames"), *period_frames)?,
                },
            ),
        };
        let mut found = false;
        for o in scene.objects.iter_mut().filter(|o| &o.name == object) {
            o.animation = Some(animation.clone());
            found = true;
        }
        if !found {
            let mut names: Vec<&str> = scene.objects.iter().map(|o| o.name.as_str()).collect();
            names.sort_unstable();
            names.dedup();
            let more = if names.len() > 20 {
                format!(", … ({} in all)", names.len())
            } else {
                String::new()
            };
            names.truncate(20);
            return Err(ck.err(
                &k("object"),
                format!("no object named '{object}' (objects: {}{more})", names.join(", ")),
            ));
        }
    }

    if let Some(n) = doc.name {
        scene.name = n;
    } else if let Some(stem) = path.file_stem() {
        scene.name = stem.to_string_lossy().into_owned();
    }
    Ok(scene)
}

/// Adds a static object with its own mesh and material.
fn add_object(scene: &mut Scene, name: &str, b: MeshBuilder, material: Material) {
    scene.materials.push(material);
    let mi = scene.meshes.len();
    scene.meshes.push(b.build(name, scene.materials.len() - 1));
    scene.objects.push(Object {
        name: name.into(),
        mesh: mi,
        transform: Mat4::IDENTITY,
        animation: None,
    });
}

/// Applies a uniform similarity transform `xf` (uniform scale `scale`) to the
/// objects, camera, camera path, lights and length settings of `scene`.
fn transform_scene(scene: &mut Scene, xf: Mat4, scale: f32) {
    for o in &mut scene.objects {
        o.transform = xf * o.transform;
        o.animation = o.animation.take().map(|a| match a {
            Animation::Swing {
                pivot,
                axis,
                amplitude_deg,
                period_frames,
            } => Animation::Swing {
                pivot: xf.transform_point3(pivot),
                axis,
                amplitude_deg,
                period_frames,
            },
            Animation::Slide {
                amplitude,
                period_frames,
            } => Animation::Slide {
                amplitude: amplitude * scale,
                period_frames,
            },
        });
    }
    let c = &mut scene.camera;
    c.eye = xf.transform_point3(c.eye);
    c.target = xf.transform_point3(c.target);
    c.near *= scale;
    if let Some(p) = &mut scene.camera_path {
        for k in &mut p.keyframes {
            k.eye = xf.transform_point3(k.eye);
            k.target = xf.transform_point3(k.target);
        }
    }
    for l in &mut scene.lights {
        match l {
            Light::Sun { .. } => {}
            Light::Point { position, .. } | Light::Spot { position, .. } => *position = xf.transform_point3(*position),
            Light::Rect {
                center, half_u, half_v, ..
            } => {
                *center = xf.transform_point3(*center);
                *half_u *= scale;
                *half_v *= scale;
            }
        }
    }
    scene.settings.ao_radius *= scale;
    scene.settings.min_separation *= scale;
    scene.settings.radiosity_radius *= scale;
}
