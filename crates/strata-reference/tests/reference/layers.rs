use glam::Vec3;
use strata_reference::{LayerSettings, Reference, NO_ID};
use strata_scene::{Camera, Material, Scene};

use crate::scenes::*;

/// Camera at the origin looking down −Z; quads facing the camera at the given
/// depths (one material and object each, in order).
fn stacked_quads(depths: &[f32]) -> Scene {
    let materials = depths
        .iter()
        .map(|d| Material::diffuse(&format!("at {d}"), [0.1 * d, 0.5, 0.2]))
        .collect();
    let mut s = scene_with(materials, Camera::new(Vec3::ZERO, Vec3::NEG_Z, Vec3::Y, 60.0, 0.05));
    for (i, &d) in depths.iter().enumerate() {
        add_triangles(
            &mut s,
            &format!("quad {i}"),
            &quad(Vec3::new(0.0, 0.0, -d), Vec3::X * 10.0, Vec3::Y * 10.0),
            i,
        );
    }
    s
}

fn layer_depths(scene: &Scene, settings: LayerSettings) -> Vec<Vec<f32>> {
    let r = Reference::new(scene, 0.0);
    let l = r.layers(&r.camera(), 16, 16, &settings);
    l.layers.iter().map(|l| l.depth.data.clone()).collect()
}

fn all_eq(v: &[f32], want: f32) -> bool {
    v.iter().all(|&d| {
        if want.is_finite() {
            (d - want).abs() < 1e-5 * want
        } else {
            d == want
        }
    })
}

#[test]
fn minimum_separation_selects_the_right_surface() {
    let s = stacked_quads(&[2.0, 3.0]);
    let d = layer_depths(&s, LayerSettings::new(2, 0.5));
    assert!(
        all_eq(&d[0], 2.0) && all_eq(&d[1], 3.0),
        "Δz = 0.5 → layer 1 at depth 3"
    );
    let d = layer_depths(&s, LayerSettings::new(2, 1.5));
    assert!(
        all_eq(&d[0], 2.0) && all_eq(&d[1], f32::INFINITY),
        "Δz = 1.5 → no layer 1"
    );
    let d = layer_depths(&s, LayerSettings::new(3, 0.0));
    assert!(
        all_eq(&d[1], 3.0) && all_eq(&d[2], f32::INFINITY),
        "Δz = 0 → second-nearest surface"
    );
}

#[test]
fn separation_is_measured_from_the_previous_layer() {
    let s = stacked_quads(&[2.0, 3.0, 3.2, 4.0]);
    let d = layer_depths(&s, LayerSettings::new(4, 0.0));
    for (j, want) in [2.0, 3.0, 3.2, 4.0].into_iter().enumerate() {
        assert!(all_eq(&d[j], want), "depth peeling layer {j}");
    }
    let d = layer_depths(&s, LayerSettings::new(3, 0.5));
    assert!(
        all_eq(&d[1], 3.0) && all_eq(&d[2], 4.0),
        "3.2 is within 0.5 of 3.0; 4.0 is not"
    );
}

#[test]
fn coplanar_duplicates_do_not_stall_depth_peeling() {
    let s = stacked_quads(&[2.0, 2.0, 3.0]);
    let d = layer_depths(&s, LayerSettings::new(2, 0.0));
    assert!(all_eq(&d[0], 2.0) && all_eq(&d[1], 3.0));
}

#[test]
fn layer_attributes_and_primary_layer() {
    let s = stacked_quads(&[2.0, 3.0]);
    let r = Reference::new(&s, 0.0);
    let cam = r.camera();
    let l = r.layers(&cam, 8, 8, &LayerSettings::new(2, 0.5));
    let (l0, l1) = (&l.layers[0], &l.layers[1]);
    assert!(l0.material.iter().all(|&m| m == 0) && l1.material.iter().all(|&m| m == 1));
    assert!(l1.object.iter().all(|&o| o == 1));
    assert!(l0.front_face.iter().all(|&f| f));
    assert!(l0.normal.data.chunks(3).all(|n| n == [0.0, 0.0, 1.0]));
    assert!(l1
        .albedo
        .data
        .chunks(3)
        .all(|a| (a[0] - 0.3).abs() < 1e-6 && a[1] == 0.5));
    // Layer depth is camera-space depth of the hit point.
    for y in 0..8 {
        for x in 0..8 {
            let h = r.primary_hit(&cam, x, y, 8, 8).unwrap();
            assert!((cam.depth_of(h.position) - l0.depth.pixel(x, y)[0]).abs() < 1e-5);
        }
    }
    assert_eq!(&r.primary_layer(&cam, 8, 8), l0);

    // Back-face culling: seen from behind (camera at z = −6 looking towards +Z),
    // the quads show their back faces and vanish when culled.
    let behind = Camera::new(Vec3::new(0.0, 0.0, -6.0), Vec3::ZERO, Vec3::Y, 60.0, 0.05);
    let culled = LayerSettings {
        cull_back_faces: true,
        ..LayerSettings::new(2, 0.0)
    };
    let l = r.layers(&behind, 4, 4, &culled);
    assert!(l.layers[0].material.iter().all(|&m| m == NO_ID));
    let l = r.layers(&behind, 4, 4, &LayerSettings::new(2, 0.0));
    assert!(l.layers[0].front_face.iter().all(|&f| !f));
    assert!(all_eq(&l.layers[0].depth.data, 3.0) && all_eq(&l.layers[1].depth.data, 4.0));
}
