//! Helpers shared by the integration tests.
#![allow(dead_code)]

use std::path::PathBuf;
use std::sync::atomic::{AtomicU32, Ordering};

use glam::Vec3;
use strata_scene::{Camera, Scene, WorldTriangle};

/// `<repo>/../shared/scenes`, or `None` (with a note on stderr) when absent.
pub fn shared_scenes() -> Option<PathBuf> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/scenes");
    if dir.is_dir() {
        Some(dir)
    } else {
        let test = std::thread::current().name().unwrap_or("?").to_string();
        strata_scene::skip::note_skip(&test, &format!("../shared not found at {}", dir.display()));
        None
    }
}

/// `<repo>/scenes` (the TOML scene files).
pub fn repo_scenes() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes")
}

/// A fresh, empty temporary directory unique to this test process and call.
pub fn temp_dir(tag: &str) -> PathBuf {
    static N: AtomicU32 = AtomicU32::new(0);
    let n = N.fetch_add(1, Ordering::Relaxed);
    let dir = std::env::temp_dir().join(format!("strata-scene-test-{}-{tag}-{n}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("create temp dir");
    dir
}

/// Möller–Trumbore ray/triangle intersection: distance along `d` (not necessarily unit) or None.
pub fn intersect(o: Vec3, d: Vec3, t: &WorldTriangle) -> Option<f32> {
    let e1 = t.p[1] - t.p[0];
    let e2 = t.p[2] - t.p[0];
    let p = d.cross(e2);
    let det = e1.dot(p);
    if det.abs() < 1e-12 {
        return None;
    }
    let inv = 1.0 / det;
    let s = o - t.p[0];
    let u = s.dot(p) * inv;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let q = s.cross(e1);
    let v = d.dot(q) * inv;
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    let dist = e2.dot(q) * inv;
    (dist > 0.0).then_some(dist)
}

/// Is the segment from `a` to `b` blocked by any triangle (ignoring hits within `eps` of `b`)?
pub fn occluded(tris: &[WorldTriangle], a: Vec3, b: Vec3, eps: f32) -> bool {
    let d = b - a;
    let len = d.length();
    let limit = 1.0 - eps / len;
    tris.iter().any(|t| intersect(a, d, t).is_some_and(|s| s < limit))
}

/// Does world point `p` project inside a `aspect`-wide view of `cam` (in front of the near plane)?
pub fn in_frustum(cam: &Camera, p: Vec3, aspect: f32) -> bool {
    let (r, u, f) = cam.basis();
    let rel = p - cam.eye;
    let z = rel.dot(f);
    if z <= cam.near {
        return false;
    }
    let t = (0.5 * cam.fov_y_deg.to_radians()).tan();
    (rel.dot(r) / z).abs() <= t * aspect && (rel.dot(u) / z).abs() <= t
}

/// Points on a grid over the faces of `scene`'s triangles of material `material`
/// that face the camera, offset by `lift` along the face normal.
pub fn samples_facing(scene: &Scene, material: &str, cam: &Camera, per_tri: u32, lift: f32) -> Vec<Vec3> {
    let mi = scene
        .materials
        .iter()
        .position(|m| m.name == material)
        .expect("material exists") as u32;
    let mut out = Vec::new();
    for t in scene.world_triangles(0.0).iter().filter(|t| t.material == mi) {
        let n = (t.p[1] - t.p[0]).cross(t.p[2] - t.p[0]).normalize();
        let c = (t.p[0] + t.p[1] + t.p[2]) / 3.0;
        if n.dot(cam.eye - c) <= 0.0 {
            continue;
        }
        for i in 0..per_tri {
            for j in 0..per_tri - i {
                let a = (i as f32 + 0.33) / per_tri as f32;
                let b = (j as f32 + 0.33) / per_tri as f32;
                if a + b >= 1.0 {
                    continue;
                }
                out.push(t.p[0] + a * (t.p[1] - t.p[0]) + b * (t.p[2] - t.p[0]) + n * lift);
            }
        }
    }
    out
}
