//! Scenes of axis-aligned quads for the A-buffer tests.

use glam::{Mat4, Vec3};
use strata_scene::shapes::MeshBuilder;
use strata_scene::{Camera, Light, Material, Object, Scene, SceneSettings};

pub fn v(x: f32, y: f32, z: f32) -> Vec3 {
    Vec3::new(x, y, z)
}

/// Camera at z = 5 looking down −z (45° vertical field of view).
pub fn camera() -> Camera {
    Camera::new(v(0.0, 0.0, 5.0), v(0.0, 0.0, 0.0), Vec3::Y, 45.0, 0.05)
}

/// A scene of axis-aligned quads facing +z: (z, x range, y range, material);
/// one sun shining along −z, constant ambient, a blue-grey sky.
pub fn quads(materials: Vec<Material>, quads: &[(f32, [f32; 2], [f32; 2], usize)]) -> Scene {
    let mut meshes = Vec::new();
    for (i, &(z, [x0, x1], [y0, y1], m)) in quads.iter().enumerate() {
        let mut b = MeshBuilder::new();
        b.quad_facing([v(x0, y0, z), v(x1, y0, z), v(x1, y1, z), v(x0, y1, z)], Vec3::Z);
        meshes.push(b.build(&format!("quad{i}"), m));
    }
    let objects = (0..meshes.len())
        .map(|i| Object {
            name: format!("quad{i}"),
            mesh: i,
            transform: Mat4::IDENTITY,
            animation: None,
        })
        .collect();
    Scene {
        name: "abuffer-test".into(),
        meshes,
        objects,
        materials,
        lights: vec![Light::Sun {
            direction: v(0.0, 0.0, -1.0),
            color: [1.0, 0.95, 0.9],
            illuminance: 2.0,
        }],
        camera: camera(),
        settings: SceneSettings {
            sky: [0.2, 0.3, 0.5],
            ambient: [0.05, 0.05, 0.05],
            ..Default::default()
        },
        ..Default::default()
    }
}

pub fn glass(name: &str, rgb: [f32; 3], alpha: f32) -> Material {
    Material {
        opacity: alpha,
        ..Material::diffuse(name, rgb)
    }
}
