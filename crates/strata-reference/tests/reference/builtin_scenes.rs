//! Properties of the built-in `still-life` and `dominoes` scenes (bounced
//! z-buffer paper, Figs. 1 and 8) checked with the CPU tracer.

use glam::Vec3;
use strata_reference::{GiSettings, Reference};
use strata_scene::procedural::{builtin, still_life_dims::*, DOMINO_COUNT};

/// Aspect ratios the emitter must stay hidden at (square to 2:1).
const SIZES: [(u32, u32); 4] = [(96, 96), (128, 96), (160, 90), (192, 96)];

fn in_cavity(p: Vec3, margin: f32) -> bool {
    let (lo, hi, t) = (SKULL_MIN, SKULL_MAX, SKULL_WALL);
    let (a, b) = (
        lo + Vec3::splat(t) - margin,
        Vec3::new(hi.x - t, hi.y - t, hi.z) + margin,
    );
    p.cmpge(a).all() && p.cmple(b).all()
}

#[test]
fn dominoes_has_about_1400_triangles_and_a_glossy_floor() {
    let s = builtin("dominoes").unwrap();
    let n = s.triangle_count();
    assert!((1300..=1500).contains(&n), "{n} triangles");
    assert_eq!(n, DOMINO_COUNT * 12 + 2);
    let floor = s.materials.iter().find(|m| m.name == "floor").unwrap();
    assert!(floor.glossy && floor.roughness <= 0.2 && floor.metallic > 0.5);
    let colours: std::collections::HashSet<_> = s
        .materials
        .iter()
        .filter(|m| m.name.starts_with("domino"))
        .map(|m| m.base_color.map(f32::to_bits))
        .collect();
    assert!(colours.len() >= 5, "{} colours", colours.len());
    assert!(s.settings.ao_radius > 0.0 && s.settings.ao_radius < 0.5);
    // every domino stands on the floor and is seen: the camera's rays hit many of them
    let r = Reference::new(&s, 0.0);
    let (w, h) = (160, 90);
    let mut objects = std::collections::HashSet::new();
    for y in 0..h {
        for x in 0..w {
            if let Some(hit) = r.primary_hit(&r.camera(), x, y, w, h) {
                objects.insert(hit.material);
            }
        }
    }
    assert_eq!(objects.len(), s.materials.len(), "every material visible");
}

/// The emitter is hidden from the camera: no primary ray through any pixel
/// centre at 1:1 … 2:1 aspect hits an emissive triangle; yet it lights the
/// scene (a quarter of the visible points see some of it).
#[test]
fn still_life_emitter_is_hidden_from_the_camera_but_lights_the_objects() {
    let s = builtin("still-life").unwrap();
    let r = Reference::new(&s, 0.0);
    let emissive = |m: u32| s.materials[m as usize].is_emissive();
    assert!(s.materials.iter().any(|m| m.is_emissive()));
    for (w, h) in SIZES {
        for y in 0..h {
            for x in 0..w {
                if let Some(hit) = r.primary_hit(&r.camera(), x, y, w, h) {
                    assert!(!emissive(hit.material), "pixel ({x}, {y}) of {w}x{h} sees the emitter");
                }
            }
        }
    }
    let (w, h) = (64, 36);
    let (mut lit, mut seen) = (0, 0);
    for y in 0..h {
        for x in 0..w {
            let Some(hit) = r.primary_hit(&r.camera(), x, y, w, h) else {
                continue;
            };
            seen += 1;
            let (_, ng) = hit.facing_normals(r.camera().pixel_dir(x, y, w, h));
            let p = hit.position + ng * r.epsilon();
            let any = (0..9).any(|k| {
                let q = EMITTER_CENTRE
                    + Vec3::new(0.01, (k / 3) as f32 - 1.0, 0.0) * EMITTER_HALF_Y * 0.9
                    + Vec3::new(0.0, 0.0, (k % 3) as f32 - 1.0) * EMITTER_HALF_Z * 0.9;
                let d = q - p;
                d.x < 0.0 && ng.dot(d) > 0.0 && !r.bvh().occluded(p, d.normalize(), 0.0, d.length() - 1e-3)
            });
            lit += any as u32;
        }
    }
    assert!(lit * 4 > seen, "{lit} of {seen} visible points see the emitter");
}

/// The skull's inside is not visible from the emitter: no segment from a
/// 12 × 12 grid on the emitter to a 6 × 6 × 6 grid filling the cavity is
/// free; the camera does see into the cavity; and the reference's direct
/// light there is exactly 0 (only indirect light may reach it).
#[test]
fn still_life_skull_inside_is_hidden_from_the_emitter() {
    let s = builtin("still-life").unwrap();
    let r = Reference::new(&s, 0.0);
    let (lo, hi, t) = (SKULL_MIN, SKULL_MAX, SKULL_WALL);
    let (a, b) = (
        lo + Vec3::splat(t + 0.005),
        Vec3::new(hi.x - t - 0.005, hi.y - t - 0.005, hi.z - 0.005),
    );
    let mut pairs = 0;
    for i in 0..12 {
        for j in 0..12 {
            let e = EMITTER_CENTRE
                + Vec3::new(1e-3, (2.0 * (i as f32 + 0.5) / 12.0 - 1.0) * EMITTER_HALF_Y, 0.0)
                + Vec3::new(0.0, 0.0, (2.0 * (j as f32 + 0.5) / 12.0 - 1.0) * EMITTER_HALF_Z);
            for k in 0..216 {
                let f = Vec3::new((k % 6) as f32, (k / 6 % 6) as f32, (k / 36) as f32) / 5.0;
                let q = a + (b - a) * f;
                let d = q - e;
                assert!(
                    r.bvh().occluded(e, d.normalize(), 0.0, d.length()),
                    "emitter point {e} sees the skull's inside at {q}"
                );
                pairs += 1;
            }
        }
    }
    assert_eq!(pairs, 144 * 216);
    let (w, h) = (160, 90);
    let gi = r.gi(
        &r.camera(),
        w,
        h,
        &GiSettings {
            spp: 16,
            bounces: 0,
            ..Default::default()
        },
    );
    let mut inside = 0;
    for y in 0..h {
        for x in 0..w {
            let Some(hit) = r.primary_hit(&r.camera(), x, y, w, h) else {
                continue;
            };
            if in_cavity(hit.position, 1e-4) {
                inside += 1;
                let i = 3 * (y * w + x) as usize;
                assert_eq!(
                    &gi.direct.data[i..i + 3],
                    &[0.0; 3],
                    "direct light inside the skull at ({x}, {y})"
                );
            }
        }
    }
    assert!(inside >= 20, "the camera sees {inside} pixels of the skull's inside");
}

#[test]
fn still_life_has_glossy_and_diffuse_materials() {
    let s = builtin("still-life").unwrap();
    let glossy: Vec<_> = s.materials.iter().filter(|m| m.glossy).collect();
    assert!(
        glossy.iter().any(|m| m.metallic == 1.0 && m.roughness < 0.5),
        "a glossy metal"
    );
    assert!(
        glossy.iter().any(|m| m.metallic == 0.0 && m.roughness < 0.5),
        "a glossy dielectric"
    );
    assert!(
        s.materials.iter().any(|m| !m.glossy && !m.is_emissive()),
        "diffuse objects"
    );
    assert!(s.settings.ao_radius > 0.0 && s.settings.ao_radius < 1.0);
}
