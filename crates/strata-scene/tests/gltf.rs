//! glTF loading from a small GLB built here: materials, textures, node
//! transforms, cameras; and truncated/corrupt files give errors, not panics.

mod common;

use glam::{Mat4, Vec3};
use strata_scene::load::load_path;
use strata_scene::SceneError;

/// Little-endian bytes of a float slice.
fn f32_bytes(v: &[f32]) -> Vec<u8> {
    v.iter().flat_map(|x| x.to_le_bytes()).collect()
}

/// A 2×1 PNG: one red and one half-transparent blue texel.
fn png() -> Vec<u8> {
    let img = image::RgbaImage::from_raw(2, 1, vec![255, 0, 0, 255, 0, 0, 255, 128]).unwrap();
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png).unwrap();
    out.into_inner()
}

/// Packs a JSON string and a binary buffer into a GLB container.
fn glb(json: &str, bin: &[u8]) -> Vec<u8> {
    let mut j = json.as_bytes().to_vec();
    while !j.len().is_multiple_of(4) {
        j.push(b' ');
    }
    let mut b = bin.to_vec();
    while !b.len().is_multiple_of(4) {
        b.push(0);
    }
    let total = 12 + 8 + j.len() + 8 + b.len();
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(j.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&j);
    out.extend_from_slice(&(b.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(&b);
    out
}

/// A unit quad (two triangles, no normals) in the XY plane, under a parent node
/// translated by (1, 0, 0) and a child scale of 2, plus a camera node at
/// (0, 0, 5) and a second instance mirrored in x. `max_index` is the last index value.
fn tiny_glb(last_index: u16) -> Vec<u8> {
    tiny_glb_with(last_index, "", "", "")
}

/// [`tiny_glb`] with `root` inserted at the top level of the JSON, `nodes`
/// appended to the node list (indices 4, 5, …) and `scene_nodes` appended to
/// the scene's root nodes.
fn tiny_glb_with(last_index: u16, root: &str, nodes: &str, scene_nodes: &str) -> Vec<u8> {
    tiny_glb_alpha(last_index, root, nodes, scene_nodes, r#""alphaMode": "BLEND""#)
}

/// [`tiny_glb_with`] with the material's `alphaMode` entry (and its cutoff) given as JSON.
fn tiny_glb_alpha(last_index: u16, root: &str, nodes: &str, scene_nodes: &str, alpha: &str) -> Vec<u8> {
    let positions = f32_bytes(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 1.0, 0.0]);
    let uvs = f32_bytes(&[0.0, 1.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0]);
    let indices: Vec<u8> = [0u16, 1, 2, 0, 2, last_index]
        .iter()
        .flat_map(|i| i.to_le_bytes())
        .collect();
    let png = png();
    let mut bin = Vec::new();
    bin.extend_from_slice(&positions); // 0..48
    bin.extend_from_slice(&uvs); // 48..80
    bin.extend_from_slice(&indices); // 80..92
    bin.extend_from_slice(&png); // 92..
    let json = format!(
        r#"{{
  "asset": {{"version": "2.0"}},
  "extensionsUsed": ["KHR_materials_emissive_strength"],
  "scene": 0,
  {root}
  "scenes": [{{"nodes": [0, 2, 3{scene_nodes}]}}],
  "nodes": [
    {{"name": "parent", "translation": [1, 0, 0], "children": [1]}},
    {{"name": "quad", "mesh": 0, "scale": [2, 2, 2]}},
    {{"name": "cam", "camera": 0, "translation": [0, 0, 5]}},
    {{"name": "mirrored", "mesh": 0, "scale": [-1, 1, 1]}}{nodes}
  ],
  "cameras": [{{"type": "perspective", "perspective": {{"yfov": 0.8, "znear": 0.1}}}}],
  "meshes": [{{"name": "quadmesh", "primitives": [{{"attributes": {{"POSITION": 0, "TEXCOORD_0": 1}}, "indices": 2, "material": 0}}]}}],
  "materials": [{{
    "name": "mat",
    "pbrMetallicRoughness": {{"baseColorFactor": [0.5, 0.25, 1.0, 0.5], "baseColorTexture": {{"index": 0}}, "metallicFactor": 0.3, "roughnessFactor": 0.6}},
    "emissiveFactor": [1.0, 0.5, 0.0],
    "extensions": {{"KHR_materials_emissive_strength": {{"emissiveStrength": 4.0}}}},
    {alpha}
  }}],
  "textures": [{{"source": 0}}],
  "images": [{{"bufferView": 3, "mimeType": "image/png"}}],
  "buffers": [{{"byteLength": {len}}}],
  "bufferViews": [
    {{"buffer": 0, "byteOffset": 0, "byteLength": 48}},
    {{"buffer": 0, "byteOffset": 48, "byteLength": 32}},
    {{"buffer": 0, "byteOffset": 80, "byteLength": 12}},
    {{"buffer": 0, "byteOffset": 92, "byteLength": {png_len}}}
  ],
  "accessors": [
    {{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]}},
    {{"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC2"}},
    {{"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"}}
  ]
}}"#,
        len = bin.len(),
        png_len = png.len(),
    );
    glb(&json, &bin)
}

fn write(name: &str, bytes: &[u8]) -> std::path::PathBuf {
    let p = common::temp_dir("gltf").join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

#[test]
fn tiny_glb_loads_everything() {
    let p = write("tiny.glb", &tiny_glb(3));
    let s = load_path(&p).expect("tiny glb");
    assert_eq!(s.triangle_count(), 4, "two instances of the 2-triangle quad");
    assert_eq!(s.objects.len(), 2);
    // Material.
    assert_eq!(s.materials.len(), 1);
    let m = &s.materials[0];
    assert_eq!(m.name, "mat");
    assert_eq!(m.base_color, [0.5, 0.25, 1.0]);
    assert_eq!(m.opacity, 0.5);
    assert_eq!(m.emission, [4.0, 2.0, 0.0]);
    assert_eq!((m.roughness, m.metallic), (0.6, 0.3));
    // Texture → RGBA8.
    let t = &s.textures[m.base_color_texture.expect("texture")];
    assert_eq!((t.width, t.height), (2, 1));
    assert_eq!(t.rgba8, vec![255, 0, 0, 255, 0, 0, 255, 128]);
    // Node hierarchy: parent translation × child scale.
    let quad = s.objects.iter().find(|o| o.name == "quad").unwrap();
    let expect = Mat4::from_translation(Vec3::X) * Mat4::from_scale(Vec3::splat(2.0));
    assert!(quad.transform.abs_diff_eq(expect, 1e-6));
    let (lo, hi) = s.bounds(0.0);
    assert!(lo.abs_diff_eq(Vec3::new(-1.0, 0.0, 0.0), 1e-6) && hi.abs_diff_eq(Vec3::new(3.0, 2.0, 0.0), 1e-6));
    // Generated normals face +Z for both instances (the mirrored one has its winding flipped).
    for t in s.world_triangles(0.0) {
        let g = (t.p[1] - t.p[0]).cross(t.p[2] - t.p[0]).normalize();
        assert!(g.abs_diff_eq(Vec3::Z, 1e-5), "object {} winding {g}", t.object);
        assert!(t.n.iter().all(|n| n.abs_diff_eq(Vec3::Z, 1e-5)));
    }
    // Camera from the camera node.
    assert_eq!(s.camera.eye, Vec3::new(0.0, 0.0, 5.0));
    assert!(s.camera.forward().abs_diff_eq(-Vec3::Z, 1e-6));
    assert!((s.camera.fov_y_deg - 0.8f32.to_degrees()).abs() < 1e-4 && s.camera.near == 0.1);
    // Default sun.
    assert_eq!(s.lights.len(), 1);
}

/// `KHR_lights_punctual`: one light of each type on nodes (one under a
/// translated parent), a second camera; units converted as documented.
fn lit_glb(spot: &str) -> Vec<u8> {
    let s = std::f32::consts::FRAC_1_SQRT_2;
    let root = format!(
        r#""extensions": {{"KHR_lights_punctual": {{"lights": [
    {{"name": "sun", "type": "directional", "color": [1.0, 0.9, 0.8], "intensity": 683.0}},
    {{"name": "bulb", "type": "point", "intensity": 1366.0, "range": 5.0}},
    {{"name": "cone", "type": "spot", "color": [0.5, 1.0, 1.0], "intensity": 68.3{spot}}}
  ]}}}},"#
    );
    // node 4: the sun pointing down (rotated −90° about X: −Z → −Y); node 5:
    // parent at (0, 3, 0) of node 6, the bulb at +1 in x; node 7: the spot;
    // node 8: a second camera.
    let nodes = format!(
        r#",
    {{"name": "sun", "rotation": [{n}, 0, 0, {s}], "extensions": {{"KHR_lights_punctual": {{"light": 0}}}}}},
    {{"name": "lamp", "translation": [0, 3, 0], "children": [6]}},
    {{"name": "bulb", "translation": [1, 0, 0], "extensions": {{"KHR_lights_punctual": {{"light": 1}}}}}},
    {{"name": "cone", "translation": [0, 2, 0], "extensions": {{"KHR_lights_punctual": {{"light": 2}}}}}},
    {{"name": "cam2", "camera": 0, "translation": [0, 1, 7]}}"#,
        n = -s
    );
    tiny_glb_with(3, &root, &nodes, ", 4, 5, 7, 8")
}

#[test]
fn gltf_punctual_lights_and_cameras_load_with_the_extension_units() {
    let p = write(
        "lit.glb",
        &lit_glb(r#", "spot": {"innerConeAngle": 0.2, "outerConeAngle": 0.5}"#),
    );
    let s = load_path(&p).expect("lit glb");
    assert_eq!(
        s.lights.len(),
        3,
        "the file's lights replace the default sun: {:?}",
        s.lights
    );
    let sun = s.lights.iter().find_map(|l| match l {
        strata_scene::Light::Sun {
            direction,
            color,
            illuminance,
        } => Some((*direction, *color, *illuminance)),
        _ => None,
    });
    let (dir, color, lux) = sun.expect("a sun");
    assert!(dir.abs_diff_eq(-Vec3::Y, 1e-5), "{dir}");
    assert_eq!(color, [1.0, 0.9, 0.8]);
    assert!((lux - 1.0).abs() < 1e-6, "683 lux = 1 W/m²: {lux}");
    let point = s.lights.iter().find_map(|l| match l {
        strata_scene::Light::Point {
            position,
            intensity,
            color,
        } => Some((*position, *intensity, *color)),
        _ => None,
    });
    let (pos, cd, white) = point.expect("a point light");
    assert!(
        pos.abs_diff_eq(Vec3::new(1.0, 3.0, 0.0), 1e-6),
        "parent × child translation: {pos}"
    );
    assert!((cd - 2.0).abs() < 1e-6 && white == [1.0; 3]);
    let spot = s.lights.iter().find_map(|l| match l {
        strata_scene::Light::Spot {
            position,
            direction,
            intensity,
            inner_deg,
            outer_deg,
            ..
        } => Some((*position, *direction, *intensity, *inner_deg, *outer_deg)),
        _ => None,
    });
    let (pos, dir, i, inner, outer) = spot.expect("a spot");
    assert!(pos.abs_diff_eq(Vec3::new(0.0, 2.0, 0.0), 1e-6) && dir.abs_diff_eq(-Vec3::Z, 1e-6));
    assert!(
        (i - 0.1).abs() < 1e-6
            && (inner - 0.2f32.to_degrees()).abs() < 1e-4
            && (outer - 0.5f32.to_degrees()).abs() < 1e-4
    );
    // both cameras, in node order; the first is the camera
    assert_eq!(s.cameras.len(), 2);
    assert_eq!(s.camera, s.cameras[0]);
    assert_eq!(s.cameras[1].eye, Vec3::new(0.0, 1.0, 7.0));
    // a file without the extension keeps the default sun and has one camera
    let plain = load_path(&write("plain.glb", &tiny_glb(3))).unwrap();
    assert_eq!(plain.lights.len(), 1);
    assert_eq!(plain.cameras.len(), 1);
}

#[test]
fn bad_punctual_lights_are_one_line_errors() {
    for (spot, words) in [
        (
            r#", "spot": {"innerConeAngle": 0.6, "outerConeAngle": 0.5}"#,
            &["cone", "inner < outer"][..],
        ),
        (
            r#", "spot": {"innerConeAngle": 0.1, "outerConeAngle": 2.0}"#,
            &["π/2"][..],
        ),
    ] {
        let p = write("badspot.glb", &lit_glb(spot));
        let e = load_path(&p).unwrap_err().to_string();
        assert!(!e.contains('\n') && words.iter().all(|w| e.contains(w)), "{e}");
        assert!(e.contains("badspot.glb"), "names the file: {e}");
    }
}

#[test]
fn truncated_glb_is_an_error_not_a_panic() {
    let full = tiny_glb(3);
    let dir = common::temp_dir("trunc");
    let mut n = 0;
    for len in (0..full.len()).step_by(3).chain([full.len() - 1]) {
        let p = dir.join(format!("t{len}.glb"));
        std::fs::write(&p, &full[..len]).unwrap();
        let r = std::panic::catch_unwind(|| load_path(&p));
        let r = r.unwrap_or_else(|_| panic!("panic on a GLB truncated to {len} bytes"));
        let e = r.err().unwrap_or_else(|| panic!("GLB truncated to {len} bytes loaded"));
        assert!(e.to_string().contains(&format!("t{len}.glb")), "{e}");
        n += 1;
    }
    assert!(n > 50);
}

#[test]
fn truncated_dragon_is_an_error() {
    let Some(dir) = common::shared_scenes() else { return };
    let bytes = std::fs::read(dir.join("stanford_dragon/dragon_vrip_full.glb")).unwrap();
    for len in [20, 1000, bytes.len() / 2, bytes.len() - 4] {
        let p = write(&format!("dragon{len}.glb"), &bytes[..len]);
        let e = load_path(&p).expect_err("truncated dragon loaded");
        assert!(matches!(&e, SceneError::File { path, .. } if *path == p), "{e}");
    }
}

#[test]
fn glb_index_out_of_range_is_an_error() {
    let p = write("badindex.glb", &tiny_glb(7));
    let e = load_path(&p).expect_err("bad index loaded").to_string();
    assert!(e.contains("badindex.glb") && e.contains("out of range"), "{e}");
}

#[test]
fn garbage_gltf_is_an_error() {
    let p = write("garbage.gltf", b"{ this is not json");
    let e = load_path(&p).expect_err("garbage loaded").to_string();
    assert!(e.contains("garbage.gltf"), "{e}");
    let p = write(
        "missing_buffer.gltf",
        br#"{"asset":{"version":"2.0"},"buffers":[{"byteLength":12,"uri":"nope.bin"}]}"#,
    );
    let e = load_path(&p).expect_err("missing buffer loaded").to_string();
    assert!(e.contains("missing_buffer.gltf"), "{e}");
}

#[test]
fn alpha_modes_set_cutoff_and_texture_alpha() {
    // BLEND: opacity = factor alpha, texture alpha multiplies it, no cutoff.
    let s = load_path(&write("blend.glb", &tiny_glb(3))).unwrap();
    let m = &s.materials[0];
    assert_eq!((m.opacity, m.alpha_cutoff, m.texture_alpha), (0.5, None, true));
    assert_eq!(m.fragment_alpha(0.5), Some(0.25));
    // MASK with an explicit cutoff: kept iff 0.5 × texture alpha ≥ 0.3, then opaque.
    let mask = tiny_glb_alpha(3, "", "", "", r#""alphaMode": "MASK", "alphaCutoff": 0.3"#);
    let s = load_path(&write("mask.glb", &mask)).unwrap();
    let m = &s.materials[0];
    assert_eq!((m.alpha_cutoff, m.texture_alpha), (Some(0.3), true));
    assert_eq!(m.fragment_alpha(1.0), Some(1.0));
    assert_eq!(m.fragment_alpha(0.5), None);
    assert!(!m.is_opaque());
    // MASK without a cutoff: the glTF default 0.5.
    let mask = tiny_glb_alpha(3, "", "", "", r#""alphaMode": "MASK""#);
    let s = load_path(&write("mask5.glb", &mask)).unwrap();
    assert_eq!(s.materials[0].alpha_cutoff, Some(0.5));
    assert_eq!(s.materials[0].fragment_alpha(1.0), Some(1.0));
    assert_eq!(s.materials[0].fragment_alpha(0.99), None, "0.5 × 0.99 < 0.5");
    // OPAQUE: factor and texture alpha are both ignored.
    let opaque = tiny_glb_alpha(3, "", "", "", r#""alphaMode": "OPAQUE""#);
    let s = load_path(&write("opaque.glb", &opaque)).unwrap();
    let m = &s.materials[0];
    assert_eq!((m.opacity, m.alpha_cutoff, m.texture_alpha), (1.0, None, false));
    assert_eq!(m.fragment_alpha(0.0), Some(1.0));
    assert!(m.is_opaque());
}
