//! The third-party scenes in `<repo>/../shared/scenes` and the TOML files in
//! `<repo>/scenes` that reference them. Skipped (with a note) when ../shared is absent.

mod common;

use glam::Vec3;
use strata_scene::load::load_path;
use strata_scene::{Light, Scene};

fn assert_well_formed(s: &Scene) {
    assert_eq!(s.world_triangles(0.0).len(), s.triangle_count());
    for m in &s.meshes {
        assert_eq!(m.normals.len(), m.positions.len(), "{}", m.name);
        assert_eq!(m.uvs.len(), m.positions.len(), "{}", m.name);
        assert!(
            m.indices.iter().all(|&i| (i as usize) < m.positions.len()),
            "{}",
            m.name
        );
        assert!(m.material < s.materials.len());
        for n in &m.normals {
            let l = Vec3::from(*n).length();
            assert!((l - 1.0).abs() < 1e-3, "{}: normal length {l}", m.name);
        }
    }
    s.camera.validate().expect("camera");
    assert!(!s.lights.is_empty());
}

#[test]
fn cornell_obj_loads() {
    let Some(dir) = common::shared_scenes() else { return };
    let s = load_path(&dir.join("cornell_box/cornell_box.obj")).expect("cornell OBJ");
    assert_eq!(s.triangle_count(), 36);
    assert_well_formed(&s);
    let (lo, hi) = s.bounds(0.0);
    assert!(
        lo.abs_diff_eq(Vec3::ZERO, 1e-3) && hi.abs_diff_eq(Vec3::new(556.0, 548.8, 559.2), 1e-2),
        "{lo} {hi}"
    );
    let light = s.materials.iter().find(|m| m.name == "light").expect("light material");
    assert_eq!(light.emission, [17.0, 12.0, 4.0]);
    let red = s.materials.iter().find(|m| m.name == "red").expect("red");
    assert_eq!(red.base_color, [0.63, 0.065, 0.05]);
    // No camera/light in an OBJ: the defaults frame the bounds and add a sun.
    assert!(matches!(s.lights[..], [Light::Sun { .. }]));
    let c = (lo + hi) * 0.5;
    assert!((s.camera.target - c).length() < 1e-3 && s.camera.eye.z > hi.z);
    assert!((s.camera.near - (hi - lo).length() * 1e-3).abs() < 1e-3);
    // Generated normals of the floor point up (+Y, CCW faces).
    let floor = s.objects.iter().find(|o| o.name == "floor").expect("floor object");
    assert!(s.meshes[floor.mesh].normals.iter().all(|n| n[1] > 0.999));
}

#[test]
fn sponza_obj_loads_with_textures() {
    let Some(dir) = common::shared_scenes() else { return };
    let s = load_path(&dir.join("dabrovic_sponza/sponza.obj")).expect("sponza OBJ");
    assert_eq!(s.triangle_count(), 66_454);
    assert_well_formed(&s);
    assert!(!s.textures.is_empty(), "no texture loaded");
    for t in &s.textures {
        assert!(t.width > 0 && t.height > 0);
        assert_eq!(t.rgba8.len(), (t.width * t.height * 4) as usize, "{}", t.name);
    }
    let textured = s.materials.iter().filter(|m| m.base_color_texture.is_some()).count();
    assert!(textured >= 10, "only {textured} textured materials");
    assert!(s
        .materials
        .iter()
        .all(|m| m.base_color_texture.is_none_or(|t| t < s.textures.len())));
    // Shared texture files are loaded once.
    let mut names: Vec<&str> = s.textures.iter().map(|t| t.name.as_str()).collect();
    names.sort_unstable();
    let n = names.len();
    names.dedup();
    assert_eq!(names.len(), n);
    // Ns 50 → roughness sqrt(2/52).
    let m = s
        .materials
        .iter()
        .find(|m| m.name == "sp_00_luk_mali")
        .expect("material");
    assert!((m.roughness - (2.0f32 / 52.0).sqrt()).abs() < 1e-6);
    let (lo, hi) = s.bounds(0.0);
    assert!(
        (hi.x - lo.x - 34.82).abs() < 0.1 && (hi.y - lo.y - 16.56).abs() < 0.1,
        "{lo} {hi}"
    );
}

#[test]
fn dragon_glb_loads_with_generated_normals() {
    let Some(dir) = common::shared_scenes() else { return };
    let s = load_path(&dir.join("stanford_dragon/dragon_vrip_full.glb")).expect("dragon GLB");
    assert_eq!(s.triangle_count(), 871_414);
    assert_well_formed(&s);
    let verts: usize = s.meshes.iter().map(|m| m.positions.len()).sum();
    assert_eq!(verts, 437_645);
    for m in &s.meshes {
        for n in &m.normals {
            assert!(n.iter().all(|x| x.is_finite()));
            assert!((Vec3::from(*n).length() - 1.0).abs() < 1e-4);
        }
    }
    // Smooth normals face outwards on average: at the top-most vertex the normal points up.
    let m = &s.meshes[0];
    let top = (0..m.positions.len())
        .max_by(|&a, &b| m.positions[a][1].total_cmp(&m.positions[b][1]))
        .unwrap();
    assert!(m.normals[top][1] > 0.5, "normal at the top vertex {:?}", m.normals[top]);
    let (lo, hi) = s.bounds(0.0);
    assert!(
        lo.abs_diff_eq(Vec3::new(-0.108, 0.053, -0.050), 2e-3) && hi.abs_diff_eq(Vec3::new(0.097, 0.197, 0.041), 2e-3)
    );
}

#[test]
fn bunny_obj_loads() {
    let Some(dir) = common::shared_scenes() else { return };
    let s = load_path(&dir.join("stanford_bunny/stanford-bunny.obj")).expect("bunny OBJ");
    assert_eq!(s.triangle_count(), 69_451);
    assert_well_formed(&s);
}

#[test]
fn toml_cornell_matches_builtin() {
    let Some(_) = common::shared_scenes() else { return };
    let s = load_path(&common::repo_scenes().join("cornell_obj.toml")).expect("cornell_obj.toml");
    assert_well_formed(&s);
    let b = strata_scene::procedural::cornell();
    assert_eq!(s.triangle_count(), b.triangle_count());
    let (lo, hi) = s.bounds(0.0);
    let (blo, bhi) = b.bounds(0.0);
    assert!(
        lo.abs_diff_eq(blo, 1e-5) && hi.abs_diff_eq(bhi, 1e-5),
        "{lo} {hi} vs {blo} {bhi}"
    );
    assert_eq!(s.camera, b.camera);
    assert_eq!(s.lights, b.lights);
    assert_eq!(s.settings, b.settings);
    // The OBJ's emissive quad coincides with the rect light.
    let Light::Rect {
        center, half_u, half_v, ..
    } = s.lights[0]
    else {
        panic!("rect")
    };
    let light_mat = s.materials.iter().position(|m| m.is_emissive()).unwrap() as u32;
    for t in s.world_triangles(0.0).iter().filter(|t| t.material == light_mat) {
        for p in t.p {
            let d = p - center;
            assert!(d.dot(half_u.cross(half_v)).abs() < 1e-6);
            assert!((d.dot(half_u) / half_u.length_squared()).abs() <= 1.0 + 1e-4);
            assert!((d.dot(half_v) / half_v.length_squared()).abs() <= 1.0 + 1e-4);
        }
        assert!(t.n[0].dot(half_u.cross(half_v)) > 0.0, "light quad faces the wrong way");
    }
}

#[test]
fn toml_sponza_and_dragon_load() {
    let Some(_) = common::shared_scenes() else { return };
    let s = load_path(&common::repo_scenes().join("sponza.toml")).expect("sponza.toml");
    assert_eq!(s.triangle_count(), 66_454);
    assert_eq!(s.camera.eye, Vec3::new(-14.0, 2.5, 0.5));
    assert_eq!(s.camera.fov_y_deg, 70.0);
    assert!(
        matches!(s.lights[..], [Light::Sun { .. }, Light::Point { position, .. }] if position == Vec3::new(0.0, 12.0, 0.0))
    );
    assert_eq!((s.settings.ao_radius, s.settings.min_separation), (1.0, 0.5));

    // sponza-polished.toml: the same scene with only the stone floor polished
    let p = load_path(&common::repo_scenes().join("sponza-polished.toml")).expect("sponza-polished.toml");
    assert_eq!(
        (p.triangle_count(), p.camera.eye, p.lights.len()),
        (66_454, s.camera.eye, 2)
    );
    for (a, b) in s.materials.iter().zip(&p.materials) {
        if a.name == "sp_00_pod" {
            assert!(b.glossy && (b.roughness, b.metallic) == (0.1, 1.0), "{b:?}");
            assert_eq!(
                (b.base_color, b.base_color_texture),
                (a.base_color, a.base_color_texture)
            );
        } else {
            assert_eq!(a, b, "only the floor changes");
        }
    }

    let d = load_path(&common::repo_scenes().join("dragon.toml")).expect("dragon.toml");
    assert_eq!(d.triangle_count(), 871_414 + 2);
    let (lo, hi) = d.bounds(0.0);
    let dragon = d.objects.iter().find(|o| o.name != "ground").unwrap();
    let m = &d.meshes[dragon.mesh];
    let min_y = m
        .positions
        .iter()
        .map(|p| dragon.transform.transform_point3(Vec3::from(*p)).y)
        .fold(f32::INFINITY, f32::min);
    assert!(min_y.abs() < 2e-3, "dragon floats/sinks: lowest point y = {min_y}");
    assert!((1.8..2.3).contains(&(hi.x.min(1.0) - lo.x.max(-1.2))), "{lo} {hi}");
    assert_well_formed(&d);

    let b = load_path(&common::repo_scenes().join("bunny.toml")).expect("bunny.toml");
    let bunny = b.objects.iter().find(|o| o.name != "ground").unwrap();
    let min_y = b.meshes[bunny.mesh]
        .positions
        .iter()
        .map(|p| bunny.transform.transform_point3(Vec3::from(*p)).y)
        .fold(f32::INFINITY, f32::min);
    assert!(min_y.abs() < 2e-3, "bunny lowest point y = {min_y}");
}
