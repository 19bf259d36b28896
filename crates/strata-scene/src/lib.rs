//! strata-scene: the scene model shared by the GPU renderer and the CPU reference.
//!
//! - [`model`]: meshes, materials, textures, lights, objects with rigid animation;
//! - [`camera`]: the one camera model (pixel centres, camera-space depth);
//! - [`path`]: camera paths;
//! - [`load`]: glTF 2.0, OBJ/MTL and TOML scene files;
//! - [`files`]: where loaders read referenced files (and, re-exported, bounded texture decoding);
//! - [`procedural`]: built-in scenes (`cornell`, `atrium`, `warehouse`, …);
//! - [`shapes`]: mesh builders (boxes, quads, cylinders, arches) for procedural scenes;
//! - [`normals`]: smooth/flat normal generation.

pub mod atomic;
pub mod camera;
pub mod environment;
pub mod error;
pub mod files;
pub mod image_buf;
pub mod load;
pub mod model;
pub mod normals;
pub mod oct;
pub mod path;
pub mod probes;
pub mod procedural;
pub mod shapes;
pub mod skip;

pub use camera::Camera;
pub use error::SceneError;
pub use image_buf::ImageBuf;
pub use model::*;
pub use path::{CameraPath, Keyframe};

/// Loads a scene by built-in name or file path (.gltf, .glb, .obj, .toml).
///
/// A name that is neither a built-in scene nor an existing file and has no
/// extension gives [`SceneError::Unknown`] (listing the built-in names).
pub fn load_scene(name_or_path: &str) -> Result<Scene, SceneError> {
    if let Some(s) = procedural::builtin(name_or_path) {
        return Ok(s);
    }
    let path = std::path::Path::new(name_or_path);
    if path.extension().is_none() && !path.exists() {
        return Err(SceneError::Unknown(name_or_path.to_string()));
    }
    load::load_path(path)
}
