//! Bad input gives errors that name the file (and the key/range or missing
//! file), never panics.

mod common;

use std::path::{Path, PathBuf};

use strata_scene::load::load_path;
use strata_scene::{load_scene, SceneError};

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

fn err(p: &Path) -> String {
    let e = err_inner(p);
    eprintln!("{e}");
    e
}

fn err_inner(p: &Path) -> String {
    let r = std::panic::catch_unwind(|| load_path(p)).unwrap_or_else(|_| panic!("panic loading {}", p.display()));
    match r {
        Ok(_) => panic!("{} loaded but should not", p.display()),
        Err(e) => e.to_string(),
    }
}

const TRI: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";

#[test]
fn obj_index_out_of_range() {
    let dir = common::temp_dir("obj-index");
    for (name, face) in [
        ("pos.obj", "f 1 2 5\n"),
        ("neg.obj", "f -1 -2 -9\n"),
        ("zero.obj", "f 0 1 2\n"),
    ] {
        let p = write(&dir, name, &format!("{TRI}{face}"));
        let e = err(&p);
        assert!(e.contains(name), "{e}");
        assert!(
            e.contains("out of") || e.contains("index") || e.contains("parse"),
            "{e}"
        );
    }
    // Texture-coordinate and normal indices too.
    let p = write(&dir, "vt.obj", &format!("{TRI}vt 0 0\nf 1/1 2/2 3/3\n"));
    assert!(err(&p).contains("vt.obj"));
    let p = write(&dir, "vn.obj", &format!("{TRI}vn 0 0 1\nf 1//1 2//1 3//4\n"));
    assert!(err(&p).contains("vn.obj"));
}

#[test]
fn obj_missing_texture_names_it() {
    let dir = common::temp_dir("obj-tex");
    write(
        &dir,
        "m.mtl",
        "newmtl wood\nKd 0.5 0.4 0.3\nmap_Kd textures/no_such_wood.png\n",
    );
    let p = write(&dir, "scene.obj", &format!("mtllib m.mtl\n{TRI}usemtl wood\nf 1 2 3\n"));
    let e = err(&p);
    assert!(e.contains("no_such_wood.png"), "{e}");
    assert!(e.contains("scene.obj") && e.contains("m.mtl"), "{e}");
}

#[test]
fn obj_texture_is_loaded_relative_to_mtl() {
    let dir = common::temp_dir("obj-tex-ok");
    std::fs::create_dir_all(dir.join("mat/tex")).unwrap();
    image::RgbaImage::from_raw(1, 2, vec![10, 20, 30, 255, 40, 50, 60, 255])
        .unwrap()
        .save(dir.join("mat/tex/t.png"))
        .unwrap();
    write(
        &dir,
        "mat/m.mtl",
        "newmtl a\nKd 1 1 1\nKe 2 3 4\nd 0.25\nNs 98\nmap_Kd tex/t.png\nnewmtl b\nKd 0.1 0.2 0.3\nTr 0.75\n",
    );
    let obj = format!(
        "mtllib mat/m.mtl\n{TRI}vt 0 0\nvt 1 0\nvt 0 1\nusemtl a\nf 1/1 2/2 3/3\nusemtl b\nf 1 3 2\no plain\nusemtl nonexistent\nf 1 2 3\n"
    );
    let p = write(&dir, "ok.obj", &obj);
    let s = load_path(&p).expect("loads");
    let a = s.materials.iter().find(|m| m.name == "a").unwrap();
    assert_eq!(
        (a.base_color, a.emission, a.opacity, a.metallic),
        ([1.0; 3], [2.0, 3.0, 4.0], 0.25, 0.0)
    );
    assert!((a.roughness - 0.02f32.sqrt()).abs() < 1e-6);
    let t = &s.textures[a.base_color_texture.unwrap()];
    assert_eq!((t.width, t.height, &t.rgba8[..4]), (1, 2, &[10u8, 20, 30, 255][..]));
    let b = s.materials.iter().find(|m| m.name == "b").unwrap();
    assert!((b.opacity - 0.25).abs() < 1e-6);
    // OBJ v is flipped to the top-down texture convention.
    let ma = s.meshes.iter().find(|m| s.materials[m.material].name == "a").unwrap();
    assert!(ma.uvs.contains(&[0.0, 1.0]) && ma.uvs.contains(&[0.0, 0.0]));
    // A face whose material is unknown gets the default material.
    assert!(s.meshes.iter().any(|m| s.materials[m.material].name == "default"));
    // Generated normals: the CCW face in XY points +Z, the reversed one −Z.
    let mb = s.meshes.iter().find(|m| s.materials[m.material].name == "b").unwrap();
    assert!(ma.normals.iter().all(|n| n[2] > 0.999) && mb.normals.iter().all(|n| n[2] < -0.999));
}

#[test]
fn obj_missing_mtl_or_file() {
    let dir = common::temp_dir("obj-mtl");
    let p = write(&dir, "lonely.obj", &format!("mtllib gone.mtl\n{TRI}f 1 2 3\n"));
    let e = err(&p);
    assert!(e.contains("lonely.obj") && e.contains("gone.mtl"), "{e}");
    let missing = dir.join("absent.obj");
    assert!(err(&missing).contains("absent.obj"));
    let missing = dir.join("absent.glb");
    assert!(err(&missing).contains("absent.glb"));
    let empty = write(&dir, "empty.obj", "# nothing\n");
    assert!(err(&empty).contains("no triangles"));
}

#[test]
fn unsupported_extension_and_unknown_name() {
    let dir = common::temp_dir("ext");
    let p = write(&dir, "mesh.ply", "ply\n");
    let e = err(&p);
    assert!(
        e.contains("mesh.ply") && e.contains(".gltf") && e.contains(".obj") && e.contains(".toml"),
        "{e}"
    );
    let e = load_scene("no-such-builtin").expect_err("unknown name");
    assert!(matches!(e, SceneError::Unknown(_)));
    assert!(e.to_string().contains("cornell") && e.to_string().contains("no-such-builtin"));
}

#[test]
fn toml_syntax_error_names_the_file() {
    let dir = common::temp_dir("toml-syntax");
    let p = write(&dir, "broken.toml", "name = \"x\"\nmesh = [\n");
    let e = err(&p);
    assert!(e.contains("broken.toml"), "{e}");
    assert!(e.contains("line 2") || e.contains("2 |"), "no location in: {e}");
}

#[test]
fn toml_unknown_keys_are_named() {
    let dir = common::temp_dir("toml-keys");
    for (file, text, key) in [
        ("top.toml", "builtin = \"plane\"\ncolour = 1\n", "colour"),
        ("cam.toml", "builtin = \"plane\"\n[camera]\neye = [0, 1, 5]\ntarget = [0, 0, 0]\nfovy = 30\n", "fovy"),
        ("light.toml", "builtin = \"plane\"\n[[light]]\ntype = \"sun\"\ndirection = [0, -1, 0]\nilluminance = 1\nradius = 2\n", "radius"),
        ("ltype.toml", "builtin = \"plane\"\n[[light]]\ntype = \"laser\"\n", "laser"),
        ("set.toml", "builtin = \"plane\"\n[settings]\nao = 1\n", "ao"),
        ("anim.toml", "builtin = \"plane\"\n[[animate]]\nobject = \"grey\"\ntype = \"slide\"\namplitude = [1, 0, 0]\nperiod_frames = 10\nphase = 1\n", "phase"),
    ] {
        let p = write(&dir, file, text);
        let e = err(&p);
        assert!(e.contains(file) && e.contains(key), "{file}: {e}");
    }
}

#[test]
fn toml_out_of_range_values_name_key_and_range() {
    let dir = common::temp_dir("toml-range");
    let cam = "[camera]\neye = [0, 1, 5]\ntarget = [0, 0, 0]\n";
    for (file, text, key, range) in [
        ("fov.toml", format!("builtin = \"plane\"\n{cam}fov = 200\n"), "camera.fov", "(0, 180)"),
        ("fov0.toml", format!("builtin = \"plane\"\n{cam}fov = 0\n"), "camera.fov", "(0, 180)"),
        ("near.toml", format!("builtin = \"plane\"\n{cam}near = -1\n"), "camera.near", "> 0"),
        ("scale.toml", "builtin = \"plane\"\nscale = -2\n".into(), "scale", "> 0"),
        ("exp.toml", "builtin = \"plane\"\n[settings]\nexposure = 0\n".into(), "settings.exposure", "> 0"),
        ("sky.toml", "builtin = \"plane\"\n[settings]\nsky = [0, -1, 0]\n".into(), "settings.sky", ">= 0"),
        ("ill.toml", "builtin = \"plane\"\n[[light]]\ntype = \"sun\"\ndirection = [0, -1, 0]\nilluminance = -3\n".into(), "light[0].illuminance", "> 0"),
        ("pt.toml", "builtin = \"plane\"\n[[light]]\ntype = \"point\"\nposition = [0, 1, 0]\nintensity = 0\n".into(), "light[0].intensity", "> 0"),
        ("spot.toml", "builtin = \"plane\"\n[[light]]\ntype = \"spot\"\nposition = [0, 1, 0]\ndirection = [0, -1, 0]\nintensity = 1\ninner_deg = 40\nouter_deg = 30\n".into(), "light[0].inner_deg", "(0, outer_deg"),
        ("dir.toml", "builtin = \"plane\"\n[[light]]\ntype = \"sun\"\ndirection = [0, 0, 0]\nilluminance = 1\n".into(), "light[0].direction", "non-zero"),
        ("period.toml", "builtin = \"plane\"\n[[animate]]\nobject = \"grey\"\ntype = \"slide\"\namplitude = [1, 0, 0]\nperiod_frames = 0\n".into(), "animate[0].period_frames", "> 0"),
    ] {
        let p = write(&dir, file, &text);
        let e = err(&p);
        assert!(e.contains(file) && e.contains(key) && e.contains(range), "{file}: {e}");
    }
}

#[test]
fn toml_reference_errors() {
    let dir = common::temp_dir("toml-ref");
    let p = write(&dir, "nomesh.toml", "name = \"x\"\n");
    assert!(err(&p).contains("missing: give `mesh"));
    let p = write(&dir, "both.toml", "mesh = \"a.obj\"\nbuiltin = \"plane\"\n");
    assert!(err(&p).contains("not both"));
    let p = write(&dir, "badbuiltin.toml", "builtin = \"moon\"\n");
    let e = err(&p);
    assert!(e.contains("moon") && e.contains("atrium"), "{e}");
    // A missing mesh (e.g. a clone without ../shared) names both files.
    let p = write(
        &dir,
        "missing.toml",
        "mesh = \"../../shared/scenes/nothing/here.obj\"\n",
    );
    let e = err(&p);
    assert!(e.contains("missing.toml") && e.contains("here.obj"), "{e}");
    let p = write(&dir, "nested.toml", "mesh = \"other.toml\"\n");
    assert!(err(&p).contains(".obj, .gltf or .glb"));
    let p = write(&dir, "anim.toml", "builtin = \"plane\"\n[[animate]]\nobject = \"nobody\"\ntype = \"slide\"\namplitude = [1, 0, 0]\nperiod_frames = 5\n");
    let e = err(&p);
    assert!(e.contains("nobody") && e.contains("grey"), "{e}");
    let p = write(&dir, "path.toml", "builtin = \"plane\"\n[camera_path]\nkeyframes = [{ frame = 1, eye = [0, 1, 5], target = [0, 0, 0] }, { frame = 1, eye = [1, 1, 5], target = [0, 0, 0] }]\n");
    assert!(err(&p).contains("distinct"));
    let p = write(
        &dir,
        "emptypath.toml",
        "builtin = \"plane\"\n[camera_path]\nkeyframes = []\n",
    );
    assert!(err(&p).contains("at least one keyframe"));
}

#[test]
fn repo_toml_files_fail_cleanly_without_shared() {
    // Copy the repo's TOML files somewhere ../../shared does not exist: the
    // error must name the TOML file and the missing mesh (no panic).
    let dir = common::temp_dir("noshared").join("a/b");
    std::fs::create_dir_all(&dir).unwrap();
    for name in ["cornell_obj.toml", "sponza.toml", "dragon.toml"] {
        let text = std::fs::read_to_string(common::repo_scenes().join(name)).expect("repo scene file");
        let p = write(&dir, name, &text);
        let e = err(&p);
        assert!(e.contains(name) && e.contains("shared/scenes"), "{e}");
    }
}
