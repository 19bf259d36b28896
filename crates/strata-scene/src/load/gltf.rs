//! glTF 2.0 (`.gltf`, `.glb`): materials with base colour textures, triangle
//! primitives (lists, strips and fans, converted to lists), the default
//! scene's node hierarchy, its perspective cameras and its
//! `KHR_lights_punctual` lights (see the [`super`] docs for the mapping).
//!
//! Checks: the GLB header, attribute indices, buffers, accessors and images
//! through [`super::gltf_data`] (sizes against the bytes that are there);
//! materials, indices and vertices through [`super::checks`]; attribute
//! counts against POSITION; the node hierarchy must be a tree with finite
//! transforms.

use std::collections::HashMap;
use std::path::Path;

use glam::{Mat4, Vec3};

use crate::camera::Camera;
use crate::error::{short, SceneError};
use crate::files::FileSource;
use crate::model::{Light, Material, Mesh, Object, Scene};
use crate::normals::ensure_normals;

use super::checks::{check_indices, check_material, check_vertices, MaterialSlots};
use super::texture::{decode_texture, TextureCache};
use super::{gltf_data, MeshFile};

/// Loads glTF or GLB contents `bytes` (external buffers and images relative to
/// `path`, read through `files`) without applying defaults.
pub(super) fn mesh_file(bytes: &[u8], path: &Path, files: &dyn FileSource) -> Result<MeshFile, SceneError> {
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
    let mut textures = TextureCache::new();
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
            alpha_cutoff: (m.alpha_mode() == gltf::material::AlphaMode::Mask).then(|| m.alpha_cutoff().unwrap_or(0.5)),
            texture_alpha: m.alpha_mode() != gltf::material::AlphaMode::Opaque,
            glossy: false,
        };
        check_material(path, &mut mat)?;
        let mut uv_set = 0;
        if let Some(info) = pbr.base_color_texture() {
            let source = info.texture().source();
            let image = source.index();
            uv_set = info.tex_coord();
            let ti = textures.get_or_load(&mut scene.textures, image, |&image| {
                let name = source
                    .name()
                    .map(str::to_owned)
                    .unwrap_or_else(|| format!("image{image}"));
                gltf_data::image_bytes(doc, image, &buffers, base, files)
                    .and_then(|data| decode_texture(&data, &name))
                    .map_err(|e| fail(format!("material {mi}: image {image} ('{}'): {e}", short(&name))))
            })?;
            mat.base_color_texture = Some(ti);
        }
        scene.materials.push(mat);
        material_uv_set.push(uv_set);
    }
    let mut slots = MaterialSlots::new(scene.materials.len());

    // Meshes: one of ours per triangle primitive.
    let mut mesh_map: Vec<Vec<usize>> = Vec::new();
    for gm in doc.meshes() {
        let mut ours = Vec::new();
        for prim in gm.primitives() {
            let what = format!(
                "mesh {} ('{}') primitive {}",
                gm.index(),
                short(gm.name().unwrap_or("")),
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
            let material = slots.resolve(prim.material().index());
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
    slots.finish(&mut scene.materials);

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
    let mut cameras = Vec::new();
    let mut lights = Vec::new();
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
                short(node.name().unwrap_or(""))
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
        // From the JSON: `gltf`'s `Camera::projection` panics when `type`
        // names a projection whose object is missing.
        let perspective = node
            .camera()
            .and_then(|cam| doc.as_json().cameras.get(cam.index()))
            .and_then(|c| c.perspective.as_ref());
        if let Some(p) = perspective {
            let eye = world.transform_point3(Vec3::ZERO);
            let fwd = world.transform_vector3(-Vec3::Z).normalize_or_zero();
            let up = world.transform_vector3(Vec3::Y).normalize_or_zero();
            let c = Camera::new(eye, eye + fwd, up, p.yfov.to_degrees(), p.znear);
            if c.validate().is_ok() {
                cameras.push((ni, c));
            }
        }
        if let Some(l) = punctual_light(doc, ni, world).map_err(&fail)? {
            lights.push(l);
        }
        for c in node.children() {
            stack.push((c.index(), world));
        }
    }
    // file order (node index), not traversal order
    cameras.sort_by_key(|(ni, _)| *ni);
    let has_camera = !cameras.is_empty();
    if let Some((_, c)) = cameras.first() {
        scene.camera = *c;
    }
    scene.cameras = cameras.into_iter().map(|(_, c)| c).collect();
    let has_lights = !lights.is_empty();
    scene.lights = lights;
    Ok(MeshFile {
        scene,
        has_camera,
        has_lights,
    })
}

/// Photometric → strata's radiometric units: 683 lm per W (the luminous efficacy
/// at 555 nm, the definition of the candela).
pub const LUMENS_PER_WATT: f32 = 683.0;

/// The `KHR_lights_punctual` light of node `ni` (world transform `world`), if it
/// has one. Units as the extension defines them, converted to strata's:
/// directional lux → sun irradiance lux / 683; point and spot candela → radiant
/// intensity cd / 683; lights shine along the node's −Z; spot cone angles are
/// radians from the axis (inner default 0, outer default π/4), inner < outer ≤
/// π/2. `range` is not modelled (strata's lights fall off as 1/d² without a
/// cutoff) and is ignored.
fn punctual_light(doc: &gltf::Document, ni: usize, world: Mat4) -> Result<Option<Light>, String> {
    use gltf::json::extensions::scene::khr_lights_punctual::Type;
    use gltf::json::validation::Checked;
    let json = doc.as_json();
    let Some(index) = json.nodes[ni]
        .extensions
        .as_ref()
        .and_then(|e| e.khr_lights_punctual.as_ref())
        .map(|k| k.light.value())
    else {
        return Ok(None);
    };
    let all = json
        .extensions
        .as_ref()
        .and_then(|e| e.khr_lights_punctual.as_ref())
        .map_or(&[][..], |k| k.lights.as_slice());
    let light = all.get(index).ok_or_else(|| {
        format!(
            "node {ni}: KHR_lights_punctual light {index} is out of range: the file defines {} light(s)",
            all.len()
        )
    })?;
    let name = light.name.clone().unwrap_or_else(|| format!("light {index}"));
    let valid =
        light.color.iter().all(|c| c.is_finite() && *c >= 0.0) && light.intensity.is_finite() && light.intensity >= 0.0;
    if !valid {
        return Err(format!(
            "KHR_lights_punctual '{}': color and intensity must be finite and >= 0",
            short(&name)
        ));
    }
    let position = world.transform_point3(Vec3::ZERO);
    let direction = world.transform_vector3(-Vec3::Z).normalize_or_zero();
    let color = light.color;
    let radiometric = light.intensity / LUMENS_PER_WATT;
    let needs_direction = || {
        if direction == Vec3::ZERO || !direction.is_finite() {
            Err(format!(
                "KHR_lights_punctual '{}' on node {ni}: the node's transform collapses its −Z direction",
                short(&name)
            ))
        } else {
            Ok(())
        }
    };
    Ok(Some(match light.type_ {
        Checked::Valid(Type::Directional) => {
            needs_direction()?;
            Light::Sun {
                direction,
                color,
                illuminance: radiometric,
            }
        }
        Checked::Valid(Type::Point) => Light::Point {
            position,
            color,
            intensity: radiometric,
        },
        Checked::Valid(Type::Spot) => {
            needs_direction()?;
            let (inner, outer) = light.spot.as_ref().map_or((0.0, std::f32::consts::FRAC_PI_4), |s| {
                (s.inner_cone_angle, s.outer_cone_angle)
            });
            if !(inner >= 0.0 && inner < outer && outer <= std::f32::consts::FRAC_PI_2) {
                return Err(format!(
                    "KHR_lights_punctual '{}': spot cone angles inner {inner} and outer {outer} are out of range: \
                     must satisfy 0 <= inner < outer <= π/2",
                    short(&name)
                ));
            }
            Light::Spot {
                position,
                direction,
                color,
                intensity: radiometric,
                inner_deg: inner.to_degrees(),
                outer_deg: outer.to_degrees(),
            }
        }
        Checked::Invalid => {
            return Err(format!(
                "KHR_lights_punctual '{}': unknown light type: must be directional, point or spot",
                short(&name)
            ))
        }
    }))
}

/// The triangle list of a triangle strip (every other triangle flipped to keep
/// the winding).
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

/// The triangle list of a triangle fan.
fn fan_to_list(s: &[u32]) -> Vec<u32> {
    let mut out = Vec::new();
    for i in 2..s.len() {
        out.extend_from_slice(&[s[0], s[i - 1], s[i]]);
    }
    out
}
