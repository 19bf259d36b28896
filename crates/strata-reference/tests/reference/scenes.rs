//! Hand-built test scenes (independent of the procedural scenes in strata-scene).
#![allow(dead_code)]

use glam::{Mat4, Vec3};
use strata_scene::{Camera, Material, Mesh, Object, Scene};

/// Adds a mesh with flat per-triangle normals from counter-clockwise triangles.
pub fn add_triangles(scene: &mut Scene, name: &str, tris: &[[Vec3; 3]], material: usize) {
    let mut mesh = Mesh {
        name: name.into(),
        material,
        ..Default::default()
    };
    for t in tris {
        let n = (t[1] - t[0]).cross(t[2] - t[0]).normalize();
        for p in t {
            mesh.indices.push(mesh.positions.len() as u32);
            mesh.positions.push(p.to_array());
            mesh.normals.push(n.to_array());
            mesh.uvs.push([0.0, 0.0]);
        }
    }
    scene.meshes.push(mesh);
    scene.objects.push(Object {
        name: name.into(),
        mesh: scene.meshes.len() - 1,
        transform: Mat4::IDENTITY,
        animation: None,
    });
}

/// A quad `c ± u ± v` (front face along `u × v`).
pub fn quad(c: Vec3, u: Vec3, v: Vec3) -> [[Vec3; 3]; 2] {
    let (a, b, cc, d) = (c - u - v, c + u - v, c + u + v, c - u + v);
    [[a, b, cc], [a, cc, d]]
}

/// A square floor quad at y = 0, half-size `h`, facing +Y.
pub fn floor(h: f32) -> [[Vec3; 3]; 2] {
    quad(Vec3::ZERO, Vec3::new(0.0, 0.0, h), Vec3::new(h, 0.0, 0.0))
}

pub fn scene_with(materials: Vec<Material>, camera: Camera) -> Scene {
    Scene {
        name: "test".into(),
        materials,
        camera,
        ..Default::default()
    }
}

/// Camera looking straight down at the origin from height `h`.
pub fn top_camera(h: f32, fov: f32) -> Camera {
    Camera::new(Vec3::new(0.0, h, 0.0), Vec3::ZERO, Vec3::NEG_Z, fov, 0.05)
}

/// Icosphere of radius `r` with triangles wound so their front faces point
/// *inwards* (for a closed "furnace").
pub fn inward_icosphere(r: f32, subdivisions: u32) -> Vec<[Vec3; 3]> {
    let t = (1.0 + 5f32.sqrt()) / 2.0;
    let v: Vec<Vec3> = [
        (-1.0, t, 0.0),
        (1.0, t, 0.0),
        (-1.0, -t, 0.0),
        (1.0, -t, 0.0),
        (0.0, -1.0, t),
        (0.0, 1.0, t),
        (0.0, -1.0, -t),
        (0.0, 1.0, -t),
        (t, 0.0, -1.0),
        (t, 0.0, 1.0),
        (-t, 0.0, -1.0),
        (-t, 0.0, 1.0),
    ]
    .iter()
    .map(|&(x, y, z)| Vec3::new(x, y, z).normalize())
    .collect();
    let f = [
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    let mut tris: Vec<[Vec3; 3]> = f.iter().map(|i| [v[i[0]], v[i[1]], v[i[2]]]).collect();
    for _ in 0..subdivisions {
        let mut next = Vec::with_capacity(tris.len() * 4);
        for [a, b, c] in tris {
            let (ab, bc, ca) = ((a + b).normalize(), (b + c).normalize(), (c + a).normalize());
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        tris = next;
    }
    // Outward CCW → swap two vertices to face inwards; scale.
    tris.iter().map(|t| [t[0] * r, t[2] * r, t[1] * r]).collect()
}

/// Mean of channel `c` over an image.
pub fn mean(img: &strata_scene::ImageBuf, c: u32) -> f64 {
    let n = (img.width * img.height) as usize;
    (0..n)
        .map(|i| img.data[i * img.channels as usize + c as usize] as f64)
        .sum::<f64>()
        / n as f64
}
