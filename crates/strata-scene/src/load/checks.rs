//! Checks shared by the mesh loaders ([`super::gltf`], [`super::obj`]):
//! vertex data (finite positions within ±[`MAX_COORDINATE`], finite normals
//! and texture coordinates), material values (finite, then clamped to their
//! ranges), triangle indices against the vertex count, material indices
//! against the file's materials ([`MaterialSlots`]). Errors name the file and
//! the mesh or material.

use std::path::Path;

use crate::error::{short, SceneError};
use crate::model::{Material, Mesh, MAX_COORDINATE};

/// Checks a mesh's vertex data: positions finite and within ±[`MAX_COORDINATE`],
/// normals and UVs finite. `what` names the mesh.
pub(super) fn check_vertices(path: &Path, what: &str, m: &Mesh) -> Result<(), SceneError> {
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
/// to their ranges: base colour, opacity, roughness, metallic, alpha cutoff to [0, 1],
/// emission to >= 0.
pub(super) fn check_material(path: &Path, m: &mut Material) -> Result<(), SceneError> {
    let named = |field: &str, v: &dyn std::fmt::Debug| {
        SceneError::file(
            path,
            format!(
                "material '{}': {field} {v:?} is out of range: must be finite",
                short(&m.name)
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
    if let Some(c) = m.alpha_cutoff {
        if !c.is_finite() {
            return Err(named("alpha cutoff", &c));
        }
        m.alpha_cutoff = Some(c.clamp(0.0, 1.0));
    }
    m.base_color = m.base_color.map(|c| c.clamp(0.0, 1.0));
    m.emission = m.emission.map(|c| c.max(0.0));
    m.opacity = m.opacity.clamp(0.0, 1.0);
    m.roughness = m.roughness.clamp(0.0, 1.0);
    m.metallic = m.metallic.clamp(0.0, 1.0);
    Ok(())
}

/// Checks every index of `indices` against `vertex_count`.
pub(super) fn check_indices(path: &Path, what: &str, indices: &[u32], vertex_count: usize) -> Result<(), SceneError> {
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

/// Material indices of a mesh file's meshes: one of the file's `count`
/// materials, or a default material appended after them when a mesh has no
/// material or an out-of-range one.
pub(super) struct MaterialSlots {
    count: usize,
    default_used: bool,
}

impl MaterialSlots {
    /// Slots for a scene whose first `count` materials are the file's.
    pub(super) fn new(count: usize) -> Self {
        MaterialSlots {
            count,
            default_used: false,
        }
    }

    /// The material of a mesh that names material `index`.
    pub(super) fn resolve(&mut self, index: Option<usize>) -> usize {
        match index {
            Some(i) if i < self.count => i,
            _ => {
                self.default_used = true;
                self.count
            }
        }
    }

    /// Appends the default material to `materials` when a mesh uses it.
    pub(super) fn finish(self, materials: &mut Vec<Material>) {
        if self.default_used {
            materials.push(Material::default());
        }
    }
}
