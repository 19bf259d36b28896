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
