//! Degenerate input: non-finite vertex data is an error naming the file and
//! the element; zero-area/duplicate triangles, zero-length normals and missing
//! UVs load without producing NaN; bad cameras are errors with the valid range.

use std::path::Path;

use glam::Vec3;
use strata_scene::load::{load_slice, load_toml_str, MemFiles};
use strata_scene::{CameraPath, Keyframe, Scene};

fn load(name: &str, text: &[u8]) -> Result<Scene, String> {
    load_slice(text, Path::new(name), &MemFiles::new()).map_err(|e| e.to_string())
}

fn err(name: &str, text: &[u8]) -> String {
    match load(name, text) {
        Ok(_) => panic!("{name} loaded but should not"),
        Err(e) => {
            assert!(!e.contains('\n'), "not one line: {e:?}");
            assert!(e.contains(name), "does not name the file: {e}");
            e
        }
    }
}

/// All normals finite unit vectors, UVs finite and as many as positions.
fn assert_clean(s: &Scene) {
    s.validate().expect("valid scene");
    for m in &s.meshes {
        assert_eq!(m.normals.len(), m.positions.len());
        assert_eq!(m.uvs.len(), m.positions.len());
        for n in &m.normals {
            let l = Vec3::from(*n).length();
            assert!((l - 1.0).abs() < 1e-4, "{}: normal {n:?}", m.name);
        }
        assert!(m.uvs.iter().flatten().all(|x| x.is_finite()));
    }
}

fn f32_bytes(v: &[f32]) -> Vec<u8> {
    v.iter().flat_map(|x| x.to_le_bytes()).collect()
}

fn base64(data: &[u8]) -> String {
    const A: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::new();
    for c in data.chunks(3) {
        let b = [c[0], *c.get(1).unwrap_or(&0), *c.get(2).unwrap_or(&0)];
        let n = (b[0] as u32) << 16 | (b[1] as u32) << 8 | b[2] as u32;
        for k in 0..4 {
            out.push(if k <= c.len() {
                A[(n >> (18 - 6 * k) & 63) as usize] as char
            } else {
                '='
            });
        }
    }
    out
}

/// A one-triangle glTF with the given positions and normals.
fn gltf_triangle(positions: [f32; 9], normals: [f32; 9]) -> Vec<u8> {
    let mut bin = f32_bytes(&positions);
    bin.extend(f32_bytes(&normals));
    format!(
        r#"{{"asset":{{"version":"2.0"}},"nodes":[{{"mesh":0}}],"meshes":[{{"name":"tri","primitives":[{{"attributes":{{"POSITION":0,"NORMAL":1}}}}]}}],
"accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}},{{"bufferView":1,"componentType":5126,"count":3,"type":"VEC3"}}],
"bufferViews":[{{"buffer":0,"byteLength":36}},{{"buffer":0,"byteOffset":36,"byteLength":36}}],
"buffers":[{{"byteLength":72,"uri":"data:application/octet-stream;base64,{}"}}]}}"#,
        base64(&bin)
    )
    .into_bytes()
}

const UP: [f32; 9] = [0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0];
const TRI: [f32; 9] = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0];

#[test]
fn non_finite_obj_vertex_data_names_line_and_vertex() {
    for (text, what) in [
        (
            "v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n",
            "line 3: vertex 3 has a non-finite position",
        ),
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 inf 0\nf 1 2 3\n",
            "line 4: vertex 4 has a non-finite position",
        ),
        (
            "v 0 0 0\nv 1 0 0\nv 0 1e39 0\nf 1 2 3\n",
            "line 3: vertex 3 has a non-finite position",
        ),
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nvn NaN 0 1\nf 1//1 2//2 3//1\n",
            "line 5: vertex 2 has a non-finite normal",
        ),
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 -inf\nf 1/1 2/1 3/1\n",
            "line 4: vertex 1 has a non-finite texture coordinate",
        ),
    ] {
        let e = err("bad.obj", text.as_bytes());
        assert!(e.contains(what), "{e}");
    }
}

#[test]
fn non_finite_gltf_vertex_data_names_mesh_and_vertex() {
    let mut p = TRI;
    p[4] = f32::NAN;
    let e = err("nan.gltf", &gltf_triangle(p, UP));
    assert!(
        e.contains("mesh 0 ('tri') primitive 0: vertex 1 has a non-finite position"),
        "{e}"
    );
    let mut n = UP;
    n[8] = f32::INFINITY;
    let e = err("inf.gltf", &gltf_triangle(TRI, n));
    assert!(
        e.contains("mesh 0 ('tri') primitive 0: vertex 2 has a non-finite normal"),
        "{e}"
    );
    let mut p = TRI;
    p[0] = 1e30;
    let e = err("far.gltf", &gltf_triangle(p, UP));
    assert!(e.contains("vertex 0 position") && e.contains("within ±1e18"), "{e}");
}

#[test]
fn zero_area_and_duplicate_triangles_load_without_nan() {
    // Triangle 1: good; 2: repeated index; 3: collinear; 4: duplicate of 1.
    let text = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\nf 1 2 3\nf 1 1 2\nf 1 2 4\nf 1 2 3\n";
    let s = load("degenerate.obj", text).expect("loads");
    assert_eq!(s.triangle_count(), 4, "zero-area and duplicate triangles are kept");
    assert_clean(&s);
    // The smooth normals come from the one non-degenerate face (+Z, twice);
    // vertex 4 is only on the collinear triangle and falls back to +Y.
    let m = &s.meshes[0];
    for (p, n) in m.positions.iter().zip(&m.normals) {
        let want = if *p == [2.0, 0.0, 0.0] { Vec3::Y } else { Vec3::Z };
        assert!((Vec3::from(*n) - want).length() < 1e-5, "{p:?}: {n:?}");
    }
    // Only zero-area triangles: loads; every normal falls back to +Y.
    let s = load("flat.obj", b"v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n").expect("loads");
    assert_clean(&s);
    assert!(s.meshes[0].normals.iter().all(|n| *n == [0.0, 1.0, 0.0]));
}

#[test]
fn zero_length_normals_are_regenerated() {
    let text = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 0\nvn 0 0 2\nf 1//1 2//2 3//1\n";
    let s = load("zero-normal.obj", text).expect("loads");
    assert_clean(&s);
    // The zero normals become the face normal (+Z); the given one is normalised.
    for n in &s.meshes[0].normals {
        assert!((Vec3::from(*n) - Vec3::Z).length() < 1e-5, "{n:?}");
    }
    // glTF: the zero normal of vertex 1 becomes the face normal (+Z).
    let mut n = UP;
    n[3..6].copy_from_slice(&[0.0, 0.0, 0.0]);
    let s = load("zero-normal.gltf", &gltf_triangle(TRI, n)).expect("loads");
    assert_clean(&s);
    assert!((Vec3::from(s.meshes[0].normals[1]) - Vec3::Z).length() < 1e-5);
}

#[test]
fn missing_uvs_are_zeros() {
    let s = load("no-uv.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").expect("loads");
    assert_clean(&s);
    assert!(s.meshes[0].uvs.iter().all(|t| *t == [0.0, 0.0]));
    let s = load("no-uv.gltf", &gltf_triangle(TRI, UP)).expect("loads");
    assert_clean(&s);
    assert_eq!(s.meshes[0].uvs, vec![[0.0, 0.0]; 3]);
}

fn toml_err(text: &str) -> String {
    match load_toml_str(text, Path::new("cam.toml")) {
        Ok(_) => panic!("loaded but should not:\n{text}"),
        Err(e) => {
            let e = e.to_string();
            assert!(!e.contains('\n') && e.contains("cam.toml"), "{e}");
            e
        }
    }
}

#[test]
fn camera_up_parallel_to_view_is_an_error() {
    for (eye, up) in [
        ("[0, 5, 0]", "[0, 1, 0]"),
        ("[0, -5, 0]", "[0, 3, 0]"),
        ("[0, 0, 5]", "[0, 0, -1]"),
    ] {
        let e = toml_err(&format!(
            "builtin = \"plane\"\n[camera]\neye = {eye}\ntarget = [0, 0, 0]\nup = {up}\n"
        ));
        assert!(
            e.contains("parallel to the view direction") && e.contains("angle"),
            "{e}"
        );
    }
    let e = toml_err("builtin = \"plane\"\n[camera]\neye = [0, 1, 5]\ntarget = [0, 0, 0]\nup = [0, 0, 0]\n");
    assert!(e.contains("up") && e.contains("non-zero"), "{e}");
    // A tiny but perpendicular up vector is fine.
    load_toml_str(
        "builtin = \"plane\"\n[camera]\neye = [0, 1, 5]\ntarget = [0, 0, 0]\nup = [0, 1e-5, 0]\n",
        Path::new("cam.toml"),
    )
    .expect("a short up vector is valid");
}

#[test]
fn camera_fov_outside_0_180_is_an_error_with_the_range() {
    for fov in ["0", "180", "-10", "360", "nan", "inf"] {
        let e = toml_err(&format!(
            "builtin = \"plane\"\n[camera]\neye = [0, 1, 5]\ntarget = [0, 0, 0]\nfov = {fov}\n"
        ));
        assert!(e.contains("camera.fov") && e.contains("(0, 180)"), "{fov}: {e}");
    }
    for fov in ["0.5", "179.5"] {
        load_toml_str(
            &format!("builtin = \"plane\"\n[camera]\neye = [0, 1, 5]\ntarget = [0, 0, 0]\nfov = {fov}\n"),
            Path::new("cam.toml"),
        )
        .expect("fov inside (0, 180)");
    }
}

#[test]
fn camera_path_samples_stay_finite() {
    let k = |frame: f32, x: f32| Keyframe {
        frame,
        eye: Vec3::new(x, 1.0, 5.0),
        target: Vec3::new(x, 0.0, 0.0),
    };
    // Far-apart coordinates (differences overflow f32) and a tiny frame spacing.
    let p = CameraPath::new(vec![k(0.0, 1e18), k(1e-6, -1e18), k(1.0, 1e18), k(2.0, -1e18)]).unwrap();
    for i in 0..=400 {
        let (eye, target) = p.sample(i as f32 * 0.005);
        assert!(
            eye.is_finite() && target.is_finite(),
            "frame {}: {eye} {target}",
            i as f32 * 0.005
        );
    }
    // Beyond the coordinate range is an error naming the range.
    let e = CameraPath::new(vec![k(0.0, 3e38), k(1.0, 0.0)]).unwrap_err();
    assert!(e.contains("out of range") && e.contains("1e18"), "{e}");
}
