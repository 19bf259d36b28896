//! The GPU G-buffer and shadows against the CPU reference (same camera model,
//! same pixel centres).

mod common;

use glam::Vec3;
use strata_reference::Reference;
use strata_scene::{procedural, Light, Scene};

/// Fraction of pixels where GPU and reference agree on coverage, camera-space depth
/// (relative 1e-3) and normal (within 3°, Oct16 quantisation is ≤ 1.5°).
fn gbuffer_agreement(scene: &Scene, w: u32, h: u32) -> f64 {
    let gpu = common::gpu();
    let cam = scene.camera;
    let r = common::render(&gpu, scene, &cam, w, h);
    let csz = r.read_target(&gpu, "csz").unwrap();
    let normals = r.read_normals(&gpu).unwrap();
    let reference = Reference::new(scene, 0.0).with_progress(false);
    let layer = reference.primary_layer(&cam, w, h);
    let mut agree = 0usize;
    let mut first_bad = None;
    for y in 0..h {
        for x in 0..w {
            let i = (y * w + x) as usize;
            let zg = csz.data[i];
            let zr = layer.depth.data[i];
            let ok = if zg <= 0.0 || !zr.is_finite() {
                zg <= 0.0 && !zr.is_finite()
            } else {
                let ng = Vec3::from_slice(&normals.data[i * 3..i * 3 + 3]);
                let mut nr = Vec3::from_slice(&layer.normal.data[i * 3..i * 3 + 3]);
                if !layer.front_face[i] {
                    nr = -nr;
                }
                (zg - zr).abs() <= 1e-3 * zr && ng.dot(nr) >= 3f32.to_radians().cos()
            };
            if ok {
                agree += 1;
            } else if first_bad.is_none() {
                first_bad = Some((x, y, zg, zr));
            }
        }
    }
    let frac = agree as f64 / (w * h) as f64;
    eprintln!(
        "{}: {:.3}% of pixels agree; first disagreement {:?}",
        scene.name,
        100.0 * frac,
        first_bad
    );
    frac
}

#[test]
fn gbuffer_matches_reference_cornell() {
    let s = procedural::builtin("cornell").unwrap();
    assert!(gbuffer_agreement(&s, 128, 128) >= 0.995);
}

#[test]
fn gbuffer_matches_reference_atrium() {
    let s = procedural::builtin("atrium").unwrap();
    assert!(gbuffer_agreement(&s, 192, 108) >= 0.995);
}

#[test]
fn gbuffer_matches_reference_sponza() {
    if common::shared_scene("dabrovic_sponza/sponza.obj").is_none() {
        return;
    }
    let toml = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/sponza.toml");
    let s = match strata_scene::load::load_path(&toml) {
        Ok(s) => s,
        Err(e) => {
            strata_scene::skip::note_skip("gbuffer_matches_reference_sponza", &e.to_string());
            return;
        }
    };
    assert!(gbuffer_agreement(&s, 160, 90) >= 0.995);
}

/// Sun shadow-map visibility against reference shadow rays, on pixels facing the
/// sun; PCF visibility is thresholded at 0.5.
fn shadow_agreement(scene: &Scene, w: u32, h: u32) -> f64 {
    // light 0: a sun (direction) or a point light (position)
    let to_light = |p: Vec3| -> (Vec3, f32) {
        match scene.lights.first().cloned() {
            Some(Light::Sun { direction, .. }) => (-direction.normalize(), f32::INFINITY),
            Some(Light::Point { position, .. }) => {
                let d = position - p;
                (d.normalize(), d.length())
            }
            _ => panic!("{}: light 0 must be a sun or a point light", scene.name),
        }
    };
    let gpu = common::gpu();
    let cam = scene.camera;
    let r = common::render(&gpu, scene, &cam, w, h);
    let vis = r.read_target(&gpu, "shadow").unwrap();
    let reference = Reference::new(scene, 0.0).with_progress(false);
    let (mut n, mut agree) = (0usize, 0usize);
    for y in 0..h {
        for x in 0..w {
            let Some(hit) = reference.primary_hit(&cam, x, y, w, h) else {
                continue;
            };
            let dir = cam.pixel_dir(x, y, w, h);
            let (ns, ng) = hit.facing_normals(dir);
            let (l, dist) = to_light(hit.position);
            if ns.dot(l) < 0.05 || ng.dot(l) < 0.05 {
                continue; // self-shadowed or grazing: not a shadow-map question
            }
            let origin = hit.position + ng * reference.epsilon();
            let lit_ref = !reference.bvh().occluded(origin, l, 0.0, dist - reference.epsilon());
            let lit_gpu = vis.data[(y * w + x) as usize] > 0.5;
            n += 1;
            agree += (lit_ref == lit_gpu) as usize;
        }
    }
    assert!(
        n > (w * h) as usize / 10,
        "{}: too few light-facing pixels ({n})",
        scene.name
    );
    let frac = agree as f64 / n as f64;
    eprintln!(
        "{}: shadows agree on {:.3}% of {n} light-facing pixels",
        scene.name,
        100.0 * frac
    );
    frac
}

/// Issue 17: a point light's omnidirectional (cube) shadow map against traced
/// visibility: the atrium lit by one point light among the columns, so every
/// cube face casts shadows into the view.
#[test]
fn point_light_shadows_match_reference_visibility_atrium() {
    let mut s = procedural::builtin("atrium").unwrap();
    s.lights = vec![Light::Point {
        position: s.camera.eye + (s.camera.target - s.camera.eye).normalize() * 6.0 + Vec3::Y * 1.5,
        color: [1.0; 3],
        intensity: 40.0,
    }];
    assert!(shadow_agreement(&s, 192, 108) >= 0.98);
}

#[test]
fn sun_shadows_match_reference_visibility_atrium() {
    let s = procedural::builtin("atrium").unwrap();
    assert!(shadow_agreement(&s, 192, 108) >= 0.98);
}

#[test]
fn sun_shadows_match_reference_visibility_column_wall() {
    let s = procedural::builtin("column-wall").unwrap();
    if !matches!(s.lights.first(), Some(Light::Sun { .. })) {
        panic!("column-wall's first light must be a sun for this test");
    }
    assert!(shadow_agreement(&s, 128, 128) >= 0.98);
}

/// A floor (y = 0) and a back wall (z = −3), grey, with `light` and, for a rect
/// light, its emissive quad; camera above and in front; no sky, no ambient.
fn light_test_scene(light: Light) -> Scene {
    use strata_scene::shapes::MeshBuilder;
    use strata_scene::{Camera, Material, Object, SceneSettings};
    let mut s = Scene {
        name: "light-test".into(),
        materials: vec![Material::diffuse("grey", [0.5; 3])],
        camera: Camera::new(Vec3::new(0.0, 2.5, 4.0), Vec3::new(0.0, 0.5, -1.0), Vec3::Y, 60.0, 0.05),
        settings: SceneSettings {
            sky: [0.0; 3],
            ambient: [0.0; 3],
            ..Default::default()
        },
        ..Default::default()
    };
    let mut geo = MeshBuilder::new();
    geo.rect(Vec3::ZERO, Vec3::new(0.0, 0.0, 5.0), Vec3::new(5.0, 0.0, 0.0)); // floor, +Y
    geo.rect(
        Vec3::new(0.0, 2.5, -3.0),
        Vec3::new(5.0, 0.0, 0.0),
        Vec3::new(0.0, 2.5, 0.0),
    ); // wall, +Z
    s.meshes.push(geo.build("room", 0));
    s.objects.push(Object {
        name: "room".into(),
        mesh: 0,
        transform: glam::Mat4::IDENTITY,
        animation: None,
    });
    if let Light::Rect {
        center,
        half_u,
        half_v,
        radiance,
    } = light
    {
        s.materials.push(Material::emissive("lamp", radiance));
        let mut q = MeshBuilder::new();
        q.rect(center, half_u, half_v);
        s.meshes.push(q.build("lamp", 1));
        s.objects.push(Object {
            name: "lamp".into(),
            mesh: 1,
            transform: glam::Mat4::IDENTITY,
            animation: None,
        });
    }
    s.lights = vec![light];
    s
}

/// Issue 17: direct Lambertian light, GPU (`direct-diffuse`) against the path
/// tracer's direct term (bounces 0), per light type, on an unoccluded room:
/// sun, point and spot are analytic on both sides; the rect light is the exact
/// polygon integral on the GPU and next-event estimation over the emissive quad
/// on the CPU. Returns the relative mean absolute error over lit surface pixels.
fn direct_light_error(light: Light) -> f64 {
    direct_error_of(&light_test_scene(light), Default::default(), 64, 48)
}

/// Relative mean absolute error of the GPU's direct light (`lighting`) against the
/// path tracer's direct term over the non-emitting surface pixels of `scene`.
fn direct_error_of(scene: &Scene, lighting: strata_render::passes::lighting::LightingSettings, w: u32, h: u32) -> f64 {
    use strata_reference::GiSettings;
    let scene = scene.clone();
    let gpu = common::gpu();
    let cam = scene.camera;
    let mut r = strata_render::Renderer::new(
        &gpu,
        &scene,
        strata_render::RenderSettings {
            width: w,
            height: h,
            lighting,
            ..Default::default()
        },
    )
    .expect("renderer builds without validation errors");
    r.render(&gpu, &scene, &strata_render::frame::FrameCameras::fixed(cam), 0.0)
        .expect("frame renders without validation errors");
    let g = r.read_target(&gpu, "direct-diffuse").unwrap();
    let reference = Reference::new(&scene, 0.0).with_progress(false);
    let rd = reference
        .gi(
            &cam,
            w,
            h,
            &GiSettings {
                spp: 256,
                bounces: 0,
                ..Default::default()
            },
        )
        .direct;
    let (mut err, mut sum) = (0.0f64, 0.0f64);
    for y in 0..h {
        for x in 0..w {
            let Some(hit) = reference.primary_hit(&cam, x, y, w, h) else {
                continue;
            };
            if scene.materials[hit.material as usize].emission != [0.0; 3] {
                continue; // the lamp itself: emission, not reflected light
            }
            let i = (y * w + x) as usize;
            for c in 0..3 {
                let (a, b) = (g.data[i * g.channels as usize + c] as f64, rd.data[i * 3 + c] as f64);
                err += (a - b).abs();
                sum += b;
            }
        }
    }
    assert!(sum > 0.0, "the light must light the room");
    err / sum
}

#[test]
fn direct_light_per_type_matches_the_reference() {
    let cases = [
        (
            "sun",
            Light::Sun {
                direction: Vec3::new(0.3, -1.0, -0.4).normalize(),
                color: [1.0; 3],
                illuminance: 2.0,
            },
            0.015,
        ),
        (
            "point",
            Light::Point {
                position: Vec3::new(0.5, 1.5, -1.0),
                color: [1.0, 0.9, 0.8],
                intensity: 3.0,
            },
            0.015,
        ),
        (
            "spot",
            Light::Spot {
                position: Vec3::new(0.0, 2.0, 0.0),
                direction: Vec3::new(0.0, -1.0, -0.6).normalize(),
                color: [1.0; 3],
                intensity: 5.0,
                inner_deg: 20.0,
                outer_deg: 35.0,
            },
            0.015,
        ),
        (
            // a 1 × 0.6 m panel 1.2 m above the floor, facing down and tilted towards the camera
            "rect",
            Light::Rect {
                center: Vec3::new(0.0, 1.2, -1.5),
                half_u: Vec3::new(0.5, 0.0, 0.0),
                half_v: Vec3::new(0.0, 0.1, 0.3).normalize() * 0.3,
                radiance: [4.0, 4.0, 3.0],
            },
            0.025,
        ),
    ];
    for (name, light, tolerance) in cases {
        let e = direct_light_error(light);
        eprintln!("{name}: relative MAE of the direct light {e:.4}");
        assert!(e < tolerance, "{name}: relative MAE {e:.4} >= {tolerance}");
    }
}

/// Issue 14: the rect light's penumbrae. A 0.5 m plate hangs halfway between a
/// 1 × 0.6 m panel and the floor, so its shadow is all penumbra (no umbra across
/// the panel's long side). PCSS (`area_penumbrae`, the default) must follow the
/// path tracer's direct light, and do clearly better than the hard shadow from the
/// panel's centre, which cuts a sharp, too dark shadow into the penumbra.
#[test]
fn rect_light_penumbrae_follow_the_path_tracer() {
    use strata_render::passes::lighting::LightingSettings;
    use strata_scene::shapes::MeshBuilder;
    let mut scene = light_test_scene(Light::Rect {
        center: Vec3::new(0.0, 1.2, -1.5),
        half_u: Vec3::new(0.5, 0.0, 0.0),
        half_v: Vec3::new(0.0, 0.0, 0.3),
        radiance: [4.0, 4.0, 3.0],
    });
    let mut plate = MeshBuilder::new();
    // a 0.5 × 0.5 m plate 0.6 m above the floor, its upper face towards the panel
    plate.rect(
        Vec3::new(0.1, 0.6, -1.4),
        Vec3::new(0.0, 0.0, 0.25),
        Vec3::new(0.25, 0.0, 0.0),
    );
    scene.meshes.push(plate.build("plate", 0));
    scene.objects.push(strata_scene::Object {
        name: "plate".into(),
        mesh: scene.meshes.len() - 1,
        transform: glam::Mat4::IDENTITY,
        animation: None,
    });
    let (w, h) = (96, 72);
    let soft = direct_error_of(&scene, LightingSettings::default(), w, h);
    let hard = direct_error_of(
        &scene,
        LightingSettings {
            area_penumbrae: false,
            ..Default::default()
        },
        w,
        h,
    );
    eprintln!("rect light over a plate: relative MAE of the direct light, PCSS {soft:.4}, hard {hard:.4}");
    assert!(soft < 0.05, "PCSS: relative MAE {soft:.4} >= 0.05");
    assert!(
        soft < 0.6 * hard,
        "PCSS {soft:.4} is not clearly below the hard shadow's {hard:.4}"
    );
}

/// Issue 17's per-light switch: with `ShadowSettings::unshadowed = [0]` the
/// atrium's sun (light 0) casts no shadow — its visibility is exactly 1 wherever
/// it faces the surface (0 on back-facing pixels, as with shadows on) — while
/// with shadows on, a real share of the pixels is in its shadow; an index past
/// the scene's lights is a one-line error naming the setting.
#[test]
fn per_light_shadow_switch_turns_a_lights_shadow_off() {
    use strata_render::frame::FrameCameras;
    use strata_render::passes::shadow::ShadowSettings;
    use strata_render::{RenderError, RenderSettings, Renderer};
    let scene = procedural::builtin("atrium").unwrap();
    assert!(matches!(scene.lights.first(), Some(Light::Sun { .. })));
    let gpu = common::gpu();
    let (w, h) = (96, 54);
    let settings = |unshadowed: Vec<usize>| RenderSettings {
        width: w,
        height: h,
        shadow: ShadowSettings {
            unshadowed,
            ..Default::default()
        },
        ..Default::default()
    };
    let visibility = |unshadowed: Vec<usize>| -> Vec<f32> {
        let mut r = Renderer::new(&gpu, &scene, settings(unshadowed)).expect("renderer builds");
        r.render(&gpu, &scene, &FrameCameras::fixed(scene.camera), 0.0)
            .expect("frame renders");
        r.read_target(&gpu, "shadow").unwrap().data
    };
    let on = visibility(Vec::new());
    let off = visibility(vec![0]);
    let lifted = on.iter().zip(&off).filter(|(a, b)| **b > **a + 0.5).count();
    eprintln!(
        "atrium: the sun's shadow switched off lifts {:.1}% of the pixels",
        100.0 * lifted as f64 / on.len() as f64
    );
    for (a, b) in on.iter().zip(&off) {
        assert!(
            *b == 0.0 || *b == 1.0,
            "unshadowed visibility must be 0 (back-facing) or 1, got {b}"
        );
        assert!(*b >= *a, "switching a shadow off cannot darken ({a} -> {b})");
    }
    assert!(lifted * 20 > on.len(), "the sun should shadow part of the atrium");
    match Renderer::new(&gpu, &scene, settings(vec![scene.lights.len()])) {
        Err(RenderError::Parameter(m)) => {
            assert!(m.contains("no-shadow light") && !m.contains('\n'), "{m}")
        }
        Err(e) => panic!("wrong error: {e}"),
        Ok(_) => panic!("an out-of-range light index must be refused"),
    }
}
