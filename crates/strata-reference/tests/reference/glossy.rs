//! The GGX (glossy) path of the GI tracer: white furnaces, the NEE + MIS
//! estimator against quadrature, and non-glossy materials unchanged.

use glam::Vec3;
use strata_reference::brdf::Ggx;
use strata_reference::sampling::{cosine_hemisphere, Rng};
use strata_reference::{GiSettings, Reference};
use strata_scene::{Camera, Material};

use crate::scenes::*;

fn outward_icosphere(r: f32, subdivisions: u32) -> Vec<[Vec3; 3]> {
    inward_icosphere(r, subdivisions)
        .into_iter()
        .map(|t| [t[0], t[2], t[1]])
        .collect()
}

fn settings(spp: u32, bounces: u32) -> GiSettings {
    GiSettings {
        spp,
        bounces,
        russian_roulette: false,
        ..Default::default()
    }
}

fn sphere_in_white_sky(m: Material) -> strata_scene::Scene {
    let cam = Camera::new(Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO, Vec3::Y, 45.0, 0.01);
    let mut scene = scene_with(vec![m], cam);
    add_triangles(&mut scene, "sphere", &outward_icosphere(1.0, 3), 0);
    scene.settings.sky = [1.0; 3];
    scene
}

/// White furnace, plane version: a white metal (F0 = 1, so F ≡ 1) of
/// roughness 1 (α = 1) under a uniform sky of radiance 1, seen head-on. GGX with
/// α = 1 has D = 1/π and Λ(l) = (1/cos θ_l − 1)/2, so at normal incidence its
/// single-scattering albedo is ∫ D G2 / (4 cos θ_l) cos θ_l dω = 1 − ln 2 ≈
/// 0.3069 (the energy single-scattering GGX loses, which a multiple-scattering
/// model would return). Asserted: every pixel's radiance within 0.01 of
/// 1 − ln 2 (fov 2°, so the view is normal to 0.03 %; 512 samples per pixel
/// with per-sample weight G1(l) ∈ [0, 1]: σ ≈ 0.013 per pixel → tolerance on
/// the image mean 0.003, per pixel 0.06), and ≤ 1.
#[test]
fn furnace_plane_rough_white_metal_reflects_one_minus_ln2() {
    let mut scene = scene_with(
        vec![Material::glossy("metal", [1.0; 3], 1.0, 1.0)],
        top_camera(2.0, 2.0),
    );
    add_triangles(&mut scene, "floor", &floor(100.0), 0);
    scene.settings.sky = [1.0; 3];
    let r = Reference::new(&scene, 0.0);
    let gi = r.gi(&r.camera(), 8, 8, &settings(512, 3));
    let want = 1.0 - std::f64::consts::LN_2;
    let m = mean(&gi.total, 0);
    eprintln!("rough white metal furnace: {m:.4} (1 − ln 2 = {want:.4})");
    assert!((m - want).abs() < 0.003, "mean {m} vs {want}");
    for v in &gi.total.data {
        assert!((*v as f64 - want).abs() < 0.06 && *v <= 1.0, "{v}");
    }
}

/// White furnace, sphere version (convex flat-faceted icosphere in a sky of
/// radiance 1, so every reflected ray escapes and L(v) = directional albedo):
///
/// - Lambert white (not glossy): exactly 1 everywhere (the non-absorbing case:
///   every path weight is 1, no variance);
/// - smooth white metal (roughness 0.05): each sample's weight F G2/G1(v) ≤ 1
///   with F ≡ 1, so every pixel ≤ 1 (+1e-5 rounding) — never energy gain —
///   and the sphere's mean ≥ 0.97 (a near-mirror loses only what Smith
///   masking takes at grazing angles);
/// - glossy white dielectric (roughness 0.5): each pixel's radiance equals the
///   BRDF's directional albedo at that pixel's (n, v), computed independently
///   by cosine sampling of f (30k samples) — the image mean within 1 % — and
///   nothing exceeds 1 by more than 4σ of its pixel.
#[test]
fn furnace_sphere_reflects_at_most_one_and_its_albedo() {
    let settings = settings(256, 4);
    let (w, h) = (24, 24);
    let lambert = sphere_in_white_sky(Material::diffuse("white", [1.0; 3]));
    let r = Reference::new(&lambert, 0.0);
    let gi = r.gi(&r.camera(), w, h, &settings);
    assert!(gi.total.data.iter().all(|v| (v - 1.0).abs() < 1e-5));

    let metal = sphere_in_white_sky(Material::glossy("metal", [1.0; 3], 0.05, 1.0));
    let r = Reference::new(&metal, 0.0);
    let gi = r.gi(&r.camera(), w, h, &settings);
    let (mut sum, mut count) = (0.0f64, 0);
    for y in 0..h {
        for x in 0..w {
            let v = gi.total.data[3 * (y * w + x) as usize];
            assert!(v <= 1.0 + 1e-5, "pixel ({x}, {y}): {v}");
            if r.primary_hit(&r.camera(), x, y, w, h).is_some() {
                sum += v as f64;
                count += 1;
            }
        }
    }
    let metal_mean = sum / count as f64;
    eprintln!("smooth white metal sphere: mean {metal_mean:.4} over {count} pixels");
    assert!(metal_mean >= 0.97 && count > 100);

    let (rough, metallic) = (0.5, 0.0);
    let diel = sphere_in_white_sky(Material::glossy("dielectric", [1.0; 3], rough, metallic));
    let r = Reference::new(&diel, 0.0);
    let spp = 1024;
    let gi = r.gi(&r.camera(), w, h, &GiSettings { spp, ..settings });
    let (mut traced, mut oracle, mut n) = (0.0f64, 0.0f64, 0);
    let mut rng = Rng::new(3);
    for y in 0..h {
        for x in 0..w {
            let Some(hit) = r.primary_hit(&r.camera(), x, y, w, h) else {
                continue;
            };
            let dir = r.camera().pixel_dir(x, y, w, h);
            let (nrm, _) = hit.facing_normals(dir);
            let g = Ggx::new(nrm, -dir, Vec3::ONE, rough, metallic);
            let k = 30_000;
            let a: f64 = (0..k)
                .map(|_| (g.eval(cosine_hemisphere(nrm, rng.next_2d())).x * std::f32::consts::PI) as f64)
                .sum::<f64>()
                / k as f64;
            let v = gi.total.data[3 * (y * w + x) as usize] as f64;
            // per-path weights of this lobe mix lie in [0, ~1.3]: σ ≤ 0.65/√spp
            assert!(v <= 1.0 + 4.0 * 0.65 / (spp as f64).sqrt(), "pixel ({x}, {y}): {v}");
            traced += v;
            oracle += a;
            n += 1;
        }
    }
    let (traced, oracle) = (traced / n as f64, oracle / n as f64);
    eprintln!("white dielectric (roughness 0.5) sphere: traced {traced:.4}, albedo oracle {oracle:.4}");
    assert!((traced - oracle).abs() < 0.01 * oracle, "traced {traced} vs {oracle}");
    assert!(traced < 1.0);
}

/// Direct light on a glossy floor from an emissive quad (nothing else in the
/// scene, black sky): the tracer's NEE + MIS estimate (0 bounces) against
/// ∫_quad f(v, l) Le cos θ cos θ_l / d² dA by a 160 × 160 midpoint rule,
/// per pixel within 4 % + 2 % of the image's peak (noise of 2048 paths), and
/// the image means within 1.5 %. Two roughnesses: the narrow lobe (0.2)
/// exercises the BRDF-sampled emitter hits, the wide one (0.6) the light samples.
#[test]
fn glossy_direct_light_matches_quadrature() {
    let le = Vec3::new(6.0, 4.0, 2.0);
    let (c, hu, hv) = (
        Vec3::new(0.6, 0.8, 0.0),
        Vec3::new(0.25, 0.0, 0.0),
        Vec3::new(0.0, 0.0, 0.2),
    );
    for (rough, metallic) in [(0.2f32, 0.7f32), (0.6, 0.2)] {
        let cam = Camera::new(
            Vec3::new(-1.0, 0.7, 0.0),
            Vec3::new(0.35, 0.0, 0.0),
            Vec3::Y,
            40.0,
            0.01,
        );
        let mut scene = scene_with(
            vec![
                Material::glossy("floor", [0.8, 0.5, 0.3], rough, metallic),
                Material::emissive("light", le.to_array()),
            ],
            cam,
        );
        add_triangles(&mut scene, "floor", &floor(5.0), 0);
        // front face along hu × hv = −Y: facing down
        add_triangles(&mut scene, "light", &quad(c, hu, hv), 1);
        let r = Reference::new(&scene, 0.0);
        let (w, h) = (12, 12);
        let gi = r.gi(&r.camera(), w, h, &settings(2048, 0));
        let q = 160;
        let mut want = vec![0.0f64; (w * h) as usize];
        for y in 0..h {
            for x in 0..w {
                let Some(hit) = r.primary_hit(&r.camera(), x, y, w, h) else {
                    continue;
                };
                if hit.material != 0 {
                    continue;
                }
                let dir = r.camera().pixel_dir(x, y, w, h);
                let (n, _) = hit.facing_normals(dir);
                let g = Ggx::new(n, -dir, Vec3::new(0.8, 0.5, 0.3), rough, metallic);
                let da = (4.0 * hu.length() * hv.length()) as f64 / (q * q) as f64;
                let mut s = 0.0f64;
                for i in 0..q {
                    for j in 0..q {
                        let a = -1.0 + 2.0 * (i as f32 + 0.5) / q as f32;
                        let b = -1.0 + 2.0 * (j as f32 + 0.5) / q as f32;
                        let p = c + hu * a + hv * b;
                        let d = p - hit.position;
                        let d2 = d.length_squared();
                        let l = d / d2.sqrt();
                        let (cx, cl) = (n.dot(l), l.y);
                        if cx > 0.0 && cl > 0.0 {
                            s += (g.eval(l).x * le.x * cx * cl / d2) as f64 * da;
                        }
                    }
                }
                want[(y * w + x) as usize] = s;
            }
        }
        let peak = want.iter().cloned().fold(0.0, f64::max);
        let (mut sg, mut sw) = (0.0, 0.0);
        for (i, &wv) in want.iter().enumerate() {
            let hit = r.primary_hit(&r.camera(), i as u32 % w, i as u32 / w, w, h);
            if hit.map(|h| h.material) != Some(0) {
                continue;
            }
            let got = gi.direct.data[3 * i] as f64;
            assert!(
                (got - wv).abs() <= 0.04 * wv + 0.02 * peak,
                "roughness {rough}, pixel {i}: traced {got} vs quadrature {wv}"
            );
            sg += got;
            sw += wv;
        }
        eprintln!("roughness {rough}: traced mean {sg:.4}, quadrature {sw:.4} (peak pixel {peak:.3})");
        assert!((sg - sw).abs() < 0.015 * sw, "roughness {rough}: {sg} vs {sw}");
    }
}

/// Materials that are not `glossy` are Lambert whatever their metallic and
/// roughness: the images are bit-identical (cached references stay valid).
#[test]
fn non_glossy_materials_ignore_metallic_and_roughness() {
    let scene = strata_scene::procedural::builtin("cornell").unwrap();
    let mut metal = scene.clone();
    for m in &mut metal.materials {
        m.metallic = 1.0;
        m.roughness = 0.0;
    }
    let s = settings(8, 2);
    let a = Reference::new(&scene, 0.0);
    let b = Reference::new(&metal, 0.0);
    assert_eq!(a.gi(&a.camera(), 16, 16, &s), b.gi(&b.camera(), 16, 16, &s));
}
