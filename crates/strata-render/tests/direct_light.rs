//! Direct light against analytic values.

mod common;

use glam::Vec3;
use strata_scene::{procedural, Light};

/// A Lambertian plane under a sun: outgoing radiance is ρ/π · E · cosθ at every
/// pixel (no shadowing geometry). Checked on the `direct-diffuse` target.
#[test]
fn lambert_plane_under_sun_matches_analytic() {
    let gpu = common::gpu();
    let scene = procedural::builtin("plane").expect("built-in plane");
    let Light::Sun {
        direction,
        color,
        illuminance,
    } = scene.lights[0].clone()
    else {
        panic!("plane has a sun")
    };
    let albedo = scene.materials[scene.meshes[0].material].base_color;
    let srgb = strata_scene::image_buf::linear_to_srgb;
    let cos = Vec3::Y.dot(-direction.normalize()).max(0.0);
    let (w, h) = (96, 64);
    let r = common::render(&gpu, &scene, &scene.camera, w, h);
    let img = r.read_target(&gpu, "direct-diffuse").unwrap();
    let csz = r.read_target(&gpu, "csz").unwrap();
    let stored = r.read_target(&gpu, "albedo").unwrap();
    let mut checked = 0;
    for i in 0..(w * h) as usize {
        if csz.data[i] <= 0.0 {
            continue;
        }
        for c in 0..3 {
            // The G-buffer stores albedo in an sRGB8 target: within one code of the material's.
            let rho = stored.data[i * 4 + c];
            assert!(
                (srgb(rho) - srgb(albedo[c])).abs() <= 1.01 / 255.0,
                "albedo {rho} vs {}",
                albedo[c]
            );
            let expected = rho / std::f32::consts::PI * illuminance * color[c] * cos;
            let got = img.data[i * 4 + c];
            // f16 target: relative error 2^-11; allow 0.5 %.
            assert!(
                (got - expected).abs() <= 0.005 * expected + 1e-4,
                "pixel {i} channel {c}: {got} vs {expected}"
            );
        }
        checked += 1;
    }
    assert!(
        checked > (w * h) as usize / 4,
        "plane covers too few pixels ({checked})"
    );
}

/// Tonemapped output is brighter where the plane faces the sun more (monotone
/// exposure/tonemap) and the image is not uniform.
#[test]
fn exposure_scales_hdr_linearly() {
    let gpu = common::gpu();
    let scene = procedural::builtin("plane").expect("built-in plane");
    let mk = |exposure: f32| {
        let mut r = strata_render::Renderer::new(
            &gpu,
            &scene,
            strata_render::RenderSettings {
                width: 32,
                height: 32,
                exposure: Some(exposure),
                ..Default::default()
            },
        )
        .unwrap();
        r.render(
            &gpu,
            &scene,
            &strata_render::frame::FrameCameras::fixed(scene.camera),
            0.0,
        )
        .unwrap();
        r.read_target(&gpu, "ldr").unwrap()
    };
    let a = mk(0.25);
    let b = mk(1.0);
    let mean = |i: &strata_scene::ImageBuf| i.data.iter().sum::<f32>() / i.data.len() as f32;
    assert!(
        mean(&b) > mean(&a) * 1.5,
        "higher exposure must brighten: {} vs {}",
        mean(&b),
        mean(&a)
    );
}

/// Shadow maps are rendered once for a static scene and every frame for an animated
/// one: a renderer that has drawn earlier frames gives the same direct light (`hdr`,
/// no temporal state) at frame t as a fresh renderer that draws only frame t, on
/// `cornell` (static, cached maps) and on `atrium` (its statue slides, so its shadow
/// moves: frame 0 and frame t must differ, or the test would prove nothing).
#[test]
fn cached_shadow_maps_match_a_fresh_frame_and_follow_animation() {
    use strata_render::frame::FrameCameras;
    use strata_render::{RenderSettings, Renderer};
    let gpu = common::gpu();
    let settings = RenderSettings {
        width: 96,
        height: 64,
        ..Default::default()
    };
    for (name, cached) in [("cornell", true), ("atrium", false)] {
        let scene = procedural::builtin(name).expect("built-in scene");
        // a fixed camera, so that only the scene's own motion changes the frame
        let camera = FrameCameras::fixed(scene.camera);
        let t = 15.0;
        let mut running = Renderer::new(&gpu, &scene, settings.clone()).unwrap();
        assert_eq!(running.shadow_maps_cached(), cached, "{name}");
        running.render(&gpu, &scene, &camera, 0.0).unwrap();
        let first = running.read_target(&gpu, "hdr").unwrap();
        for f in [5.0, 10.0, t] {
            running.render(&gpu, &scene, &camera, f).unwrap();
        }
        let later = running.read_target(&gpu, "hdr").unwrap();
        let mut fresh = Renderer::new(&gpu, &scene, settings.clone()).unwrap();
        fresh.render(&gpu, &scene, &camera, t).unwrap();
        let expected = fresh.read_target(&gpu, "hdr").unwrap();
        let differ = |a: &strata_scene::ImageBuf, b: &strata_scene::ImageBuf| common::values_differing(a, b, 1e-4);
        assert_eq!(differ(&later, &expected), 0, "{name}: frame {t} after earlier frames");
        let moved = differ(&first, &expected);
        eprintln!("{name}: {moved} values change between frame 0 and frame {t}");
        if !cached {
            assert!(moved > 50, "{name}: the animation changed only {moved} values");
        }
    }
}
