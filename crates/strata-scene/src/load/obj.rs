//! Wavefront OBJ with its MTL material libraries (through `tobj`,
//! triangulated, single index): one mesh per object/group and material, MTL
//! colours, opacity, shininess and `map_Kd` textures (see the [`super`] docs
//! for the mapping).
//!
//! Checks: `v`/`vn`/`vt` numbers must be finite (the error names the line),
//! MTL colour lines need 3 numbers (`tobj` would panic), a missing or
//! unreadable MTL library or texture is an error naming it; materials,
//! indices and vertices through [`super::checks`].

use std::cell::RefCell;
use std::path::{Path, PathBuf};

use glam::Mat4;

use crate::error::{short, SceneError};
use crate::files::FileSource;
use crate::model::{Material, Mesh, Object, Scene};

use super::checks::{check_indices, check_material, check_vertices, MaterialSlots};
use super::texture::{read_texture, TextureCache};
use super::MeshFile;

/// The lines of `bytes` that are valid UTF-8, with their 0-based numbers.
fn utf8_lines(bytes: &[u8]) -> impl Iterator<Item = (usize, &str)> {
    bytes
        .split(|&b| b == b'\n')
        .enumerate()
        .filter_map(|(i, line)| Some((i, std::str::from_utf8(line).ok()?)))
}

/// Checks the numbers of the `v`, `vn` and `vt` lines of OBJ text: a
/// non-finite one is an error naming the line and the vertex.
fn obj_check_numbers(path: &Path, bytes: &[u8]) -> Result<(), SceneError> {
    let mut counts = [0usize; 3];
    for (li, line) in utf8_lines(bytes) {
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
                    short(line.trim())
                ),
            ));
        }
    }
    Ok(())
}

/// Checks what `tobj` would panic on in an MTL file: a colour (`Ka`, `Kd`,
/// `Ks`, `Ke`) with fewer than 3 numbers.
fn check_mtl(bytes: &[u8]) -> Result<(), String> {
    for (li, line) in utf8_lines(bytes) {
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

/// Loads OBJ contents `bytes` (MTL libraries and textures relative to `path`,
/// read through `files`) without applying defaults.
pub(super) fn mesh_file(bytes: &[u8], path: &Path, files: &dyn FileSource) -> Result<MeshFile, SceneError> {
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
    let mut textures = TextureCache::new();
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
            let ti = textures.get_or_load(&mut scene.textures, base.join(&rel), |full| {
                let lib = material_libs
                    .get(i)
                    .map(|l| l.display().to_string())
                    .unwrap_or_default();
                read_texture(full, files).map_err(|e| {
                    SceneError::file(
                        path,
                        format!(
                            "material '{}' in {lib}: texture {} (map_Kd {rel}): {e}",
                            m.name,
                            full.display()
                        ),
                    )
                })
            })?;
            mat.base_color_texture = Some(ti);
        }
        scene.materials.push(mat);
    }
    let mut slots = MaterialSlots::new(scene.materials.len());

    for model in models {
        let m = model.mesh;
        if m.indices.is_empty() {
            continue;
        }
        let what = format!("object '{}'", short(&model.name));
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
        let material = slots.resolve(m.material_id);
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
    slots.finish(&mut scene.materials);
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
