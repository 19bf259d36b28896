//! TOML scene files: overrides of camera, lights, settings, path, animation,
//! placement and ground on top of a built-in scene or a mesh file.

mod common;

use glam::{Mat4, Vec3};
use strata_scene::load::{load_path, load_toml_str};
use strata_scene::procedural::builtin;
use strata_scene::{Animation, Light};

#[test]
fn overrides_on_a_builtin() {
    let text = r#"
name = "my plane"
builtin = "plane"

[camera]
eye = [0, 2, 6]
target = [0, 0, 0]
fov = 50

[[light]]
type = "point"
position = [0, 3, 0]
intensity = 40

[[light]]
type = "rect"
center = [0, 2, 0]
half_u = [0.5, 0, 0]
half_v = [0, 0, 0.5]
radiance = [5, 5, 5]
emitter = true

[settings]
exposure = 2.0

[camera_path]
keyframes = [
  { frame = 10, eye = [1, 2, 6], target = [0, 0, 0] },
  { frame = 0, eye = [0, 2, 6], target = [0, 0, 0] },
]

[[animate]]
object = "grey"
type = "swing"
pivot = [0, 0, 0]
axis = [0, 0, 1]
amplitude_deg = 10
period_frames = 40
"#;
    let s = load_toml_str(text, std::path::Path::new("inline.toml")).expect("loads");
    let base = builtin("plane").unwrap();
    assert_eq!(s.name, "my plane");
    assert_eq!(s.camera.eye, Vec3::new(0.0, 2.0, 6.0));
    assert_eq!((s.camera.fov_y_deg, s.camera.up), (50.0, Vec3::Y));
    assert_eq!(s.camera.near, base.camera.near, "near defaults to the base scene's");
    // Lights replace the builtin's (sun gone); the rect adds a downward-facing emitter.
    assert_eq!(s.lights.len(), 2);
    assert!(matches!(s.lights[0], Light::Point { intensity, color, .. } if intensity == 40.0 && color == [1.0; 3]));
    assert_eq!(s.triangle_count(), base.triangle_count() + 2);
    let em = s
        .materials
        .iter()
        .position(|m| m.emission == [5.0; 3])
        .expect("emitter material") as u32;
    let tris: Vec<_> = s
        .world_triangles(0.0)
        .into_iter()
        .filter(|t| t.material == em)
        .collect();
    assert!(tris.len() == 2 && tris.iter().all(|t| t.n[0].abs_diff_eq(-Vec3::Y, 1e-6)));
    // Settings: exposure changed, the rest kept.
    assert_eq!(s.settings.exposure, 2.0);
    assert_eq!(s.settings.ao_radius, base.settings.ao_radius);
    assert_eq!(s.settings.sky, base.settings.sky);
    // Path sorted by frame; animation attached.
    let p = s.camera_path.as_ref().unwrap();
    assert_eq!((p.first_frame(), p.last_frame()), (0.0, 10.0));
    assert!(s.camera_at(10.0).eye.abs_diff_eq(Vec3::new(1.0, 2.0, 6.0), 1e-6));
    let grey = s.objects.iter().find(|o| o.name == "grey").unwrap();
    assert!(matches!(grey.animation, Some(Animation::Swing { .. })));
    assert!(!grey.transform_at(0.0).abs_diff_eq(grey.transform_at(10.0), 1e-4));
}

#[test]
fn camera_without_path_drops_builtin_path() {
    let s = load_toml_str(
        "builtin = \"atrium\"\n[camera]\neye = [0, 2, 0]\ntarget = [5, 2, 0]\n",
        std::path::Path::new("a.toml"),
    )
    .unwrap();
    assert!(s.camera_path.is_none());
    assert_eq!(s.camera_at(50.0).eye, Vec3::new(0.0, 2.0, 0.0));
    assert_eq!(s.name, "a");
    // Without [camera], the builtin's path stays.
    let s = load_toml_str("builtin = \"atrium\"\n", std::path::Path::new("b.toml")).unwrap();
    assert!(s.camera_path.is_some());
}

#[test]
fn scale_and_translate_move_everything() {
    let s = load_toml_str(
        "builtin = \"atrium\"\nscale = 0.5\ntranslate = [1, 0, 0]\n",
        std::path::Path::new("half.toml"),
    )
    .unwrap();
    let base = builtin("atrium").unwrap();
    let xf = Mat4::from_translation(Vec3::X) * Mat4::from_scale(Vec3::splat(0.5));
    let (lo, hi) = s.bounds(0.0);
    let (blo, bhi) = base.bounds(0.0);
    assert!(lo.abs_diff_eq(xf.transform_point3(blo), 1e-4) && hi.abs_diff_eq(xf.transform_point3(bhi), 1e-4));
    assert!(s.camera.eye.abs_diff_eq(xf.transform_point3(base.camera.eye), 1e-5));
    assert!(s
        .camera_at(60.0)
        .eye
        .abs_diff_eq(xf.transform_point3(base.camera_at(60.0).eye), 1e-4));
    assert_eq!(s.settings.ao_radius, 0.5 * base.settings.ao_radius);
    // Animated objects stay consistent: world position at frame 7 is transformed too.
    let (a, b) = (
        s.objects.iter().find(|o| o.animation.is_some()).unwrap(),
        base.objects.iter().find(|o| o.animation.is_some()).unwrap(),
    );
    let p = Vec3::new(0.1, 0.2, 0.3);
    let want = xf.transform_point3(b.transform_at(7.0).transform_point3(p));
    assert!(a.transform_at(7.0).transform_point3(p).abs_diff_eq(want, 1e-4));
}

#[test]
fn mesh_file_with_ground_and_defaults() {
    let dir = common::temp_dir("toml-mesh");
    std::fs::write(dir.join("tri.obj"), "v 0 1 0\nv 1 1 0\nv 0 2 0\nf 1 2 3\n").unwrap();
    std::fs::write(
        dir.join("s.toml"),
        "mesh = \"tri.obj\"\nscale = 2\n[ground]\ncolor = [0.2, 0.3, 0.4]\n",
    )
    .unwrap();
    let s = load_path(&dir.join("s.toml")).expect("loads");
    assert_eq!(s.triangle_count(), 3);
    assert_eq!(s.name, "s");
    let g = s.objects.iter().find(|o| o.name == "ground").expect("ground");
    let gm = &s.meshes[g.mesh];
    assert_eq!(s.materials[gm.material].base_color, [0.2, 0.3, 0.4]);
    // Ground at the lowest point (y = 2 after scaling), facing up.
    assert!(gm.positions.iter().all(|p| (p[1] - 2.0).abs() < 1e-6) && gm.normals.iter().all(|n| n[1] > 0.999));
    // Default camera frames the (scaled) mesh, not the ground; default sun.
    s.camera.validate().unwrap();
    let centre = Vec3::new(1.0, 3.0, 0.0); // bounds (0,2,0)-(2,4,0) after scaling
    assert!((s.camera.target - centre).length() < 1e-4, "{}", s.camera.target);
    assert!(matches!(s.lights[..], [Light::Sun { .. }]));
    assert!(s.settings.ao_radius > 0.0);
}

/// The error text of loading `text` as `name`.
fn toml_err(name: &str, text: &str) -> String {
    load_toml_str(text, std::path::Path::new(name))
        .expect_err("must be rejected")
        .to_string()
}

#[test]
fn material_overrides_by_name_and_wildcard() {
    let base = builtin("glasshouse").unwrap();
    let s = load_toml_str(
        "builtin = \"glasshouse\"\n\
         [[material]]\nname = \"*\"\nopacity = 0.3\n\
         [[material]]\nname = \"wall\"\nbase_color = [0.1, 0.2, 0.3]\n",
        std::path::Path::new("m.toml"),
    )
    .expect("loads");
    assert_eq!(s.materials.len(), base.materials.len());
    for (m, b) in s.materials.iter().zip(&base.materials) {
        assert_eq!(m.opacity, 0.3, "{}", m.name);
        let want = if m.name == "wall" {
            [0.1, 0.2, 0.3]
        } else {
            b.base_color
        };
        assert_eq!(m.base_color, want, "{}", m.name);
        assert_eq!((m.roughness, m.emission), (b.roughness, b.emission), "{}", m.name);
    }
    // Overrides apply in file order: a later named entry wins over "*".
    let s = load_toml_str(
        "builtin = \"plane\"\n[[material]]\nname = \"*\"\nopacity = 0.3\n[[material]]\nname = \"grey\"\nopacity = 1\n",
        std::path::Path::new("o.toml"),
    )
    .unwrap();
    assert_eq!(s.materials[0].opacity, 1.0);
}

#[test]
fn material_override_errors_name_file_material_and_range() {
    let e = toml_err(
        "bad.toml",
        "builtin = \"plane\"\n[[material]]\nname = \"glass\"\nopacity = 0.5\n",
    );
    assert!(
        e.starts_with("bad.toml") && e.contains("'glass'") && e.contains("grey") && !e.contains('\n'),
        "{e}"
    );
    for (value, shown) in [("1.5", "1.5"), ("-0.1", "-0.1"), ("nan", "NaN")] {
        let e = toml_err(
            "range.toml",
            &format!("builtin = \"plane\"\n[[material]]\nname = \"grey\"\nopacity = {value}\n"),
        );
        assert!(
            e.starts_with("range.toml")
                && e.contains("material[0].opacity")
                && e.contains(shown)
                && e.contains("0..=1"),
            "{e}"
        );
    }
    let e = toml_err(
        "col.toml",
        "builtin = \"plane\"\n[[material]]\nname = \"grey\"\nbase_color = [0.5, 2, 0]\n",
    );
    assert!(e.contains("material[0].base_color") && e.contains("0..=1"), "{e}");
    let e = toml_err(
        "key.toml",
        "builtin = \"plane\"\n[[material]]\nname = \"grey\"\nalpha = 0.5\n",
    );
    assert!(e.starts_with("key.toml") && e.contains("alpha"), "{e}");
}

#[test]
fn repeat_stacks_translated_copies() {
    let base = builtin("plane").unwrap();
    let s = load_toml_str(
        "builtin = \"plane\"\n[repeat]\ncount = 4\noffset = [0, 0.5, -1]\n",
        std::path::Path::new("r.toml"),
    )
    .unwrap();
    assert_eq!(s.objects.len(), 4 * base.objects.len());
    assert_eq!(s.triangle_count(), 4 * base.triangle_count());
    let (blo, bhi) = base.bounds(0.0);
    let (lo, hi) = s.bounds(0.0);
    let off = Vec3::new(0.0, 0.5, -1.0);
    assert!(lo.abs_diff_eq(blo.min(blo + 3.0 * off), 1e-5), "{lo}");
    assert!(hi.abs_diff_eq(bhi.max(bhi + 3.0 * off), 1e-5), "{hi}");
    for (i, o) in s.objects.iter().enumerate() {
        let want = Mat4::from_translation(off * i as f32) * base.objects[0].transform;
        assert!(o.transform.abs_diff_eq(want, 1e-6), "copy {i}");
    }
    // The ground comes after the copies and is not repeated.
    let s = load_toml_str(
        "builtin = \"plane\"\n[repeat]\ncount = 3\noffset = [1, 0, 0]\n[ground]\n",
        std::path::Path::new("g.toml"),
    )
    .unwrap();
    assert_eq!(s.objects.iter().filter(|o| o.name == "ground").count(), 1);
}

#[test]
fn repeat_count_and_offset_are_checked() {
    for count in ["0", "65", "-3"] {
        let e = toml_err(
            "rep.toml",
            &format!("builtin = \"plane\"\n[repeat]\ncount = {count}\noffset = [0, 0, 1]\n"),
        );
        assert!(
            e.starts_with("rep.toml") && e.contains("repeat.count") && e.contains("1..=64") && e.contains(count),
            "{e}"
        );
    }
    let e = toml_err(
        "off.toml",
        "builtin = \"plane\"\n[repeat]\ncount = 2\noffset = [0, inf, 1]\n",
    );
    assert!(e.contains("repeat.offset") && e.contains("finite"), "{e}");
    let e = toml_err("miss.toml", "builtin = \"plane\"\n[repeat]\ncount = 2\n");
    assert!(e.starts_with("miss.toml") && e.contains("offset"), "{e}");
}

#[test]
fn dragon_glass_toml_is_transparent_and_stacked() {
    let Some(_) = common::shared_scenes() else { return };
    let s = load_path(&common::repo_scenes().join("dragon-glass.toml")).expect("dragon-glass.toml");
    let ground = s.objects.iter().filter(|o| o.name == "ground").count();
    let dragons = s.objects.len() - ground;
    assert!(dragons >= 2, "{dragons} dragon copies");
    for o in s.objects.iter().filter(|o| o.name != "ground") {
        let m = &s.materials[s.meshes[o.mesh].material];
        assert_eq!(m.opacity, 0.3, "{}", m.name);
    }
}

#[test]
fn material_override_sets_glossy_roughness_and_metallic_in_range() {
    let s = load_toml_str(
        "builtin = \"plane\"\n[[material]]\nname = \"*\"\nglossy = true\nroughness = 0.2\nmetallic = 1\n",
        std::path::Path::new("g.toml"),
    )
    .unwrap();
    assert!(s
        .materials
        .iter()
        .all(|m| m.glossy && m.roughness == 0.2 && m.metallic == 1.0));
    let base = builtin("plane").unwrap();
    assert!(base.materials.iter().all(|m| !m.glossy), "the override is what set it");
    for f in ["roughness", "metallic"] {
        let e = toml_err(
            "gl.toml",
            &format!("builtin = \"plane\"\n[[material]]\nname = \"grey\"\n{f} = 1.5\n"),
        );
        assert!(
            e.starts_with("gl.toml") && e.contains(&format!("material[0].{f}")) && e.contains("0..=1"),
            "{e}"
        );
    }
}

/// `[settings] probe_bounds` sets the light probes' volume in world units (as the file's
/// camera and lights are); bad bounds are an error naming the key and the rule.
#[test]
fn probe_bounds_are_read_and_checked() {
    let set = load_toml_str(
        "builtin = \"cornell\"\nscale = 2\n[settings]\nprobe_bounds = [[0, 0, 0], [0.5, 0.25, 1]]\n",
        std::path::Path::new("room.toml"),
    )
    .unwrap();
    assert_eq!(set.settings.probe_bounds, Some([[0.0, 0.0, 0.0], [0.5, 0.25, 1.0]]));
    assert_eq!(builtin("cornell").unwrap().settings.probe_bounds, None);
    let e = toml_err(
        "bad.toml",
        "builtin = \"cornell\"\n[settings]\nprobe_bounds = [[0, 1, 0], [1, 0, 1]]\n",
    );
    assert!(
        e.contains("bad.toml") && e.contains("settings.probe_bounds") && e.contains("lo <= hi"),
        "{e}"
    );
}
