//! Scene files: glTF 2.0 (`.gltf`, `.glb`), Wavefront OBJ/MTL (`.obj`) and
//! TOML scene descriptions (`.toml`). Every error names the file concerned.
//!
//! # Mesh files (glTF, OBJ)
//!
//! - **glTF 2.0** (`gltf::import`: embedded or external buffers and images,
//!   `.glb`): each triangle primitive (mode TRIANGLES, TRIANGLE_STRIP or
//!   TRIANGLE_FAN; points and lines are skipped with a warning) becomes a
//!   [`Mesh`](crate::model::Mesh); every node of the default scene that has
//!   a mesh becomes one [`Object`](crate::model::Object) per primitive, with
//!   the node hierarchy's world transform.
//!   Materials: `baseColorFactor` (linear RGB; its alpha is the opacity unless
//!   `alphaMode` is OPAQUE), `alphaMode` MASK → `alpha_cutoff` (`alphaCutoff`,
//!   default 0.5), the texture's alpha multiplies the opacity for BLEND and
//!   MASK (`texture_alpha`; see `Material::fragment_alpha`),
//!   `baseColorTexture` (converted to RGBA8),
//!   `emissiveFactor` × `KHR_materials_emissive_strength`, roughness, metallic.
//!   Every perspective camera node is kept in [`Scene::cameras`](crate::model::Scene)
//!   (node order; the first becomes the camera, `--camera N` picks another).
//!   `KHR_lights_punctual` lights on nodes become strata lights with the node's
//!   world transform (shining along its −Z): directional → `Sun` with
//!   illuminance lux / 683, point → `Point` and spot → `Spot` with radiant
//!   intensity candela / 683 (683 lm/W, the candela's definition), spot cone
//!   angles in radians from the axis; `range` is ignored (strata's lights have no
//!   cutoff). A file with lights gets no default sun; a TOML wrapper's
//!   `[[light]]` entries still replace them.
//! - **OBJ/MTL** (`tobj`, triangulated, single index): one
//!   [`Mesh`](crate::model::Mesh) per object/group and material.
//!   `Kd` → base colour, `map_Kd` → texture
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
//!   [`decode_texture`] (at most 16384 texels a side, decoded
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
//! probe_bounds = [[-3.0, 0.0, -4.0], [3.0, 2.7, 1.5]]  # light-probe volume [lo, hi];
//!                         # default: the scene's bounds inset by 5 %
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

// This file: the public entry points, dispatch by extension, defaults and
// what glTF and OBJ share after parsing (`MeshFile`, `load_mesh_slice`).
mod checks; // checks shared by the glTF and OBJ loaders
mod gltf; // glTF / GLB scenes
mod gltf_data; // bounds-checked glTF buffers, accessors and images
mod obj; // OBJ + MTL
pub(crate) mod texture; // bounded image decoding (re-exported by `files`)
mod toml; // TOML scene descriptions

use std::path::Path;

use glam::Vec3;

use crate::camera::Camera;
use crate::error::SceneError;
pub use crate::files::{DiskFiles, FileSource, MemFiles};
pub use crate::model::MAX_COORDINATE;
use crate::model::{Light, Scene, SceneSettings, Texture};
use crate::normals::ensure_normals;
pub use gltf_data::MAX_ZERO_ACCESSOR;
pub use texture::decode_texture;

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
    toml::load_text(text, path, &DiskFiles)
}

/// [`load_toml_str`] on bytes (must be UTF-8), reading the mesh through `files`.
pub fn load_toml_slice(bytes: &[u8], path: &Path, files: &dyn FileSource) -> Result<Scene, SceneError> {
    let text = std::str::from_utf8(bytes).map_err(|e| {
        SceneError::file(
            path,
            format!("invalid scene file: not UTF-8 (byte {})", e.valid_up_to()),
        )
    })?;
    toml::load_text(text, path, files)
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

/// Loads an image file as an RGBA8 [`Texture`] (8-bit texels kept as stored,
/// i.e. sRGB-encoded for colour maps).
/// Within the limits of [`decode_texture`].
pub fn load_texture(path: &Path) -> Result<Texture, String> {
    texture::read_texture(path, &DiskFiles)
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
        Some("gltf" | "glb") => gltf::mesh_file(bytes, path, files)?,
        Some("obj") => obj::mesh_file(bytes, path, files)?,
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
