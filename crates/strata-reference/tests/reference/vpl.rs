//! Instant radiosity VPLs: their flux against closed forms, the cosine-emitter
//! falloff of one VPL, energy per bounce in a closed room, determinism.

use glam::Vec3;
use strata_reference::{Reference, Vpl, VplSettings};
use strata_scene::{Camera, Light, Material};

use crate::scenes::*;

fn total_flux(vpls: &[Vpl], bounce: u32) -> Vec3 {
    vpls.iter()
        .filter(|v| v.bounce == bounce)
        .fold(Vec3::ZERO, |a, v| a + v.flux)
}

/// A sun at 40° from the normal of a lone 10 × 10 m plane (albedo 0.5): the VPLs
/// carry the reflected power ρ·E·A·cos θ.
#[test]
fn sun_on_a_plane_reflected_power() {
    let mut s = scene_with(vec![Material::diffuse("grey", [0.5; 3])], top_camera(5.0, 60.0));
    add_triangles(&mut s, "floor", &floor(5.0), 0);
    let theta = 40f32.to_radians();
    s.lights.push(Light::Sun {
        direction: Vec3::new(theta.sin(), -theta.cos(), 0.0),
        color: [1.0, 0.9, 0.8],
        illuminance: 3.0,
    });
    let r = Reference::new(&s, 0.0);
    let vpls = r.vpls(&VplSettings {
        paths: 8192,
        ..Default::default()
    });
    let expected = Vec3::new(1.0, 0.9, 0.8) * (0.5 * 3.0 * 100.0 * theta.cos());
    let got = total_flux(&vpls, 1);
    assert!(vpls
        .iter()
        .all(|v| v.bounce == 1 && (v.normal - Vec3::Y).length() < 1e-5));
    assert!(
        ((got - expected) / expected).abs().max_element() < 0.01,
        "flux {got} vs ρ E A cos θ = {expected}"
    );
}

/// A point light 2 m above the centre of a 4 × 4 m plane: the plane receives
/// I·Ω, Ω = 4·asin(a²/(a² + h²)) the square's solid angle; VPLs carry ρ·I·Ω.
#[test]
fn point_light_over_a_square_reflected_power() {
    let mut s = scene_with(vec![Material::diffuse("grey", [0.8; 3])], top_camera(5.0, 60.0));
    add_triangles(&mut s, "floor", &floor(2.0), 0);
    s.lights.push(Light::Point {
        position: Vec3::new(0.0, 2.0, 0.0),
        color: [1.0; 3],
        intensity: 10.0,
    });
    let r = Reference::new(&s, 0.0);
    let vpls = r.vpls(&VplSettings {
        paths: 16384,
        ..Default::default()
    });
    let omega = 4.0 * (4.0f32 / 8.0).asin();
    let expected = 0.8 * 10.0 * omega;
    let got = total_flux(&vpls, 1).x;
    assert!((got - expected).abs() < 0.01 * expected, "{got} vs {expected}");
    // all light leaves the point: the powers are 4π·I
    assert!((r.light_powers()[0].x - 40.0 * std::f32::consts::PI).abs() < 1e-3);
}

/// Inside a closed sphere of albedo ρ every light path hits a wall at every
/// bounce, so the VPLs of bounce b carry P·ρ^b exactly (no loss: cosine
/// bounces about the facet normal never go below it).
#[test]
fn closed_room_keeps_energy_per_bounce() {
    let rho = 0.6;
    let mut s = scene_with(
        vec![Material::diffuse("wall", [rho; 3])],
        Camera::new(Vec3::ZERO, Vec3::Z, Vec3::Y, 60.0, 0.01),
    );
    add_triangles(&mut s, "sphere", &inward_icosphere(3.0, 2), 0);
    s.lights.push(Light::Point {
        position: Vec3::new(0.3, -0.2, 0.1),
        color: [1.0; 3],
        intensity: 2.0,
    });
    let r = Reference::new(&s, 0.0);
    let vpls = r.vpls(&VplSettings {
        paths: 1000,
        bounces: 3,
        seed: 5,
    });
    let p = 2.0 * 4.0 * std::f32::consts::PI;
    for b in 1..=3u32 {
        let got = total_flux(&vpls, b).x;
        let expected = p * rho.powi(b as i32);
        assert!(
            (got - expected).abs() < 1e-4 * expected,
            "bounce {b}: {got} vs {expected}"
        );
        assert_eq!(vpls.iter().filter(|v| v.bounce == b).count(), 1000);
    }
}

/// One VPL 1 m above a plane, facing down: the irradiance term at distance r
/// from its foot is Φ/π · h² / (h² + r²)² (cos θ_y = cos θ_x = h/d).
#[test]
fn one_vpl_falls_off_as_cosines_over_distance_squared() {
    let v = Vpl {
        position: Vec3::new(0.0, 1.0, 0.0),
        normal: -Vec3::Y,
        flux: Vec3::splat(std::f32::consts::PI),
        albedo: Vec3::ONE,
        bounce: 1,
    };
    for r in [0.0f32, 0.5, 1.0, 3.0] {
        let e = v.irradiance_at(Vec3::new(r, 0.0, 0.0), Vec3::Y, f32::INFINITY).x;
        let exact = 1.0 / (1.0 + r * r).powi(2);
        assert!((e - exact).abs() < 1e-6, "r = {r}: {e} vs {exact}");
    }
    // behind the VPL or facing away: nothing; the clamp bounds the geometry term
    assert_eq!(
        v.irradiance_at(Vec3::new(0.0, 2.0, 0.0), -Vec3::Y, f32::INFINITY),
        Vec3::ZERO
    );
    assert_eq!(v.irradiance_at(Vec3::ZERO, -Vec3::Y, f32::INFINITY), Vec3::ZERO);
    let close = v.irradiance_at(Vec3::new(0.0, 0.9, 0.0), Vec3::Y, 10.0).x;
    assert!((close - 10.0).abs() < 1e-5, "{close}");
}

/// Same seed, same VPLs; another seed moves them. Emissive triangles and
/// spots deposit VPLs too (Cornell box; warehouse).
#[test]
fn vpls_are_reproducible_and_every_light_kind_emits() {
    let cornell = strata_scene::procedural::builtin("cornell").unwrap();
    let r = Reference::new(&cornell, 0.0);
    let a = r.vpls(&VplSettings::default());
    assert_eq!(a, r.vpls(&VplSettings::default()));
    assert_ne!(
        a,
        r.vpls(&VplSettings {
            seed: 1,
            ..Default::default()
        })
    );
    // the box is open towards the camera: some paths leave it
    assert!(a.len() > 300 && a.len() < 480, "{} of 480 paths hit the box", a.len());
    let warehouse = strata_scene::procedural::builtin("warehouse").unwrap();
    let r = Reference::new(&warehouse, 0.0);
    let powers = r.light_powers();
    assert_eq!(powers.len(), 2, "spot + point");
    let v = r.vpls(&VplSettings::default());
    // the spot lights the red patch: some VPLs are red
    assert!(v.iter().any(|v| v.albedo.x > 0.8 && v.albedo.y < 0.1));
    assert!(v.iter().all(|v| v.flux.is_finite() && v.flux.min_element() >= 0.0));
}
