use std::f32::consts::PI;

use glam::Vec3;
use strata_reference::{GiSettings, Reference};
use strata_scene::{Camera, Light, Material};

use crate::scenes::*;

#[test]
fn sunlit_plane_is_exact_lambert() {
    let rho = [0.2f32, 0.5, 0.8];
    let mut scene = scene_with(vec![Material::diffuse("albedo", rho)], top_camera(3.0, 60.0));
    add_triangles(&mut scene, "floor", &floor(50.0), 0);
    let theta = 35f32.to_radians();
    let (e, color) = (3.0f32, [1.0f32, 0.9, 0.5]);
    scene.lights.push(Light::Sun {
        direction: Vec3::new(theta.sin(), -theta.cos(), 0.0),
        color,
        illuminance: e,
    });
    // A Rect light is a GPU hint only: it must not change the reference.
    scene.lights.push(Light::Rect {
        center: Vec3::Y,
        half_u: Vec3::X,
        half_v: Vec3::Z,
        radiance: [100.0; 3],
    });
    let r = Reference::new(&scene, 0.0);
    let gi = r.gi(
        &r.camera(),
        16,
        16,
        &GiSettings {
            spp: 4,
            bounces: 3,
            ..Default::default()
        },
    );
    for i in 0..256 {
        for c in 0..3 {
            let want = rho[c] / PI * e * color[c] * theta.cos();
            let got = gi.direct.data[3 * i + c];
            assert!(
                (got - want).abs() <= 1e-5 * want,
                "pixel {i} channel {c}: {got} vs {want}"
            );
            assert_eq!(gi.indirect.data[3 * i + c], 0.0);
            assert_eq!(gi.total.data[3 * i + c], got);
        }
    }
}

#[test]
fn point_and_spot_lights_follow_inverse_square() {
    let rho = 0.6;
    let mut scene = scene_with(vec![Material::diffuse("grey", [rho; 3])], top_camera(5.0, 70.0));
    add_triangles(&mut scene, "floor", &floor(50.0), 0);
    let (pos, i0) = (Vec3::new(0.3, 2.0, -0.2), 5.0);
    scene.lights.push(Light::Point {
        position: pos,
        color: [1.0; 3],
        intensity: i0,
    });
    let r = Reference::new(&scene, 0.0);
    let cam = r.camera();
    let gi = r.gi(
        &cam,
        16,
        16,
        &GiSettings {
            spp: 1,
            bounces: 0,
            ..Default::default()
        },
    );
    // Spot pointing straight down: full inside the inner cone, zero outside the outer.
    let mut spot_scene = scene.clone();
    spot_scene.lights = vec![Light::Spot {
        position: pos,
        direction: -Vec3::Y,
        color: [1.0; 3],
        intensity: i0,
        inner_deg: 20.0,
        outer_deg: 30.0,
    }];
    let rs = Reference::new(&spot_scene, 0.0);
    let spot = rs.gi(
        &cam,
        16,
        16,
        &GiSettings {
            spp: 1,
            bounces: 0,
            ..Default::default()
        },
    );
    let (c_in, c_out) = (20f32.to_radians().cos(), 30f32.to_radians().cos());
    for y in 0..16 {
        for x in 0..16 {
            let h = r.primary_hit(&cam, x, y, 16, 16).unwrap();
            let d = pos - h.position;
            let want = rho / PI * i0 * (d.y / d.length()) / d.length_squared();
            let got = gi.direct.pixel(x, y)[0];
            assert!((got - want).abs() <= 2e-5 * want, "({x},{y}): {got} vs {want}");
            let cos_axis = d.y / d.length();
            let s = spot.direct.pixel(x, y)[0];
            if cos_axis >= c_in + 1e-4 {
                assert!((s - want).abs() <= 2e-5 * want);
            } else if cos_axis <= c_out - 1e-4 {
                assert_eq!(s, 0.0);
            } else {
                assert!(s > 0.0 && s < want);
            }
        }
    }
}

/// Irradiance below the centre of a 2a × 2a emitter of radiance Le at height h
/// (four corner rectangles of the differential-area-to-parallel-rectangle form factor).
fn square_emitter_irradiance(le: f64, a: f64, h: f64) -> f64 {
    let x = a / h;
    let s = (1.0 + x * x).sqrt();
    let f_corner = 1.0 / (2.0 * std::f64::consts::PI) * 2.0 * (x / s * (x / s).atan());
    std::f64::consts::PI * le * 4.0 * f_corner
}

#[test]
fn emissive_square_matches_form_factor() {
    let (le, a, h, rho) = (2.0f32, 1.0f32, 1.0f32, 0.5f32);
    let mut emitter = Material::emissive("light", [le; 3]);
    emitter.base_color = [0.0; 3];
    let mut scene = scene_with(
        vec![Material::diffuse("floor", [rho; 3]), emitter],
        // Looking up from below? No: look at the floor from just under the light.
        Camera::new(Vec3::new(0.0, 0.5, 0.0), Vec3::ZERO, Vec3::NEG_Z, 10.0, 0.01),
    );
    add_triangles(&mut scene, "floor", &floor(20.0), 0);
    // Ceiling emitter facing down (−Y): u × v must point down.
    add_triangles(
        &mut scene,
        "light",
        &quad(Vec3::new(0.0, h, 0.0), Vec3::new(a, 0.0, 0.0), Vec3::new(0.0, 0.0, a)),
        1,
    );
    let r = Reference::new(&scene, 0.0);
    let gi = r.gi(
        &r.camera(),
        4,
        4,
        &GiSettings {
            spp: 4096,
            bounces: 0,
            ..Default::default()
        },
    );
    // The 10° view covers |x| < 0.044: irradiance is flat to < 0.2 % there.
    let want = rho as f64 / std::f64::consts::PI * square_emitter_irradiance(le as f64, a as f64, h as f64);
    let got = mean(&gi.direct, 1);
    assert!((got - want).abs() < 0.01 * want, "{got} vs {want}");
}

#[test]
fn emitter_seen_by_camera_counts_once() {
    // Looking straight at an emissive quad: radiance = Le, nothing else.
    let mut emitter = Material::emissive("light", [1.5, 0.5, 0.25]);
    emitter.base_color = [0.0; 3];
    let mut scene = scene_with(
        vec![emitter],
        Camera::new(Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO, Vec3::Y, 30.0, 0.05),
    );
    add_triangles(&mut scene, "light", &quad(Vec3::ZERO, Vec3::X * 5.0, Vec3::Y * 5.0), 0);
    let r = Reference::new(&scene, 0.0);
    let gi = r.gi(
        &r.camera(),
        8,
        8,
        &GiSettings {
            spp: 2,
            bounces: 2,
            ..Default::default()
        },
    );
    for p in gi.total.data.chunks(3) {
        assert_eq!(p, &[1.5, 0.5, 0.25]);
    }
}

#[test]
fn white_furnace_converges_to_geometric_series() {
    // Closed sphere, every wall emitting Le with albedo ρ: L = Le Σ ρ^k.
    let (le, rho, bounces) = (1.0f32, 0.5f32, 20u32);
    let wall = Material {
        emission: [le; 3],
        ..Material::diffuse("wall", [rho; 3])
    };
    let mut scene = scene_with(
        vec![wall],
        Camera::new(Vec3::new(0.1, 0.2, 0.3), Vec3::new(1.0, 0.0, 0.0), Vec3::Y, 90.0, 0.01),
    );
    let sphere = inward_icosphere(2.0, 2);
    assert!(sphere
        .iter()
        .all(|t| (t[1] - t[0]).cross(t[2] - t[0]).dot(t[0] + t[1] + t[2]) < 0.0));
    add_triangles(&mut scene, "sphere", &sphere, 0);
    let r = Reference::new(&scene, 0.0);
    let gi = r.gi(
        &r.camera(),
        12,
        12,
        &GiSettings {
            spp: 64,
            bounces,
            ..Default::default()
        },
    );
    // Direct: Le + ρ·Le; total: Le (1 − ρ^(N+2)) / (1 − ρ).
    let want_total = (le * (1.0 - rho.powi(bounces as i32 + 2)) / (1.0 - rho)) as f64;
    let want_direct = (le * (1.0 + rho)) as f64;
    for c in 0..3 {
        let (t, d) = (mean(&gi.total, c), mean(&gi.direct, c));
        assert!((t - want_total).abs() < 0.02 * want_total, "total {t} vs {want_total}");
        assert!(
            (d - want_direct).abs() < 0.02 * want_direct,
            "direct {d} vs {want_direct}"
        );
    }
}

#[test]
fn sky_lights_an_open_plane_directly() {
    // Plane under a uniform sky L: irradiance π L, radiance ρ L, all of it direct.
    let mut scene = scene_with(vec![Material::diffuse("grey", [0.5; 3])], top_camera(2.0, 40.0));
    add_triangles(&mut scene, "floor", &floor(1000.0), 0);
    scene.settings.sky = [2.0, 1.0, 0.5];
    let r = Reference::new(&scene, 0.0);
    let gi = r.gi(
        &r.camera(),
        4,
        4,
        &GiSettings {
            spp: 16,
            bounces: 0,
            ..Default::default()
        },
    );
    for c in 0..3u32 {
        let want = 0.5 * scene.settings.sky[c as usize] as f64;
        assert!((mean(&gi.direct, c) - want).abs() < 1e-3 * want);
        assert_eq!(mean(&gi.indirect, c), 0.0);
    }
}
