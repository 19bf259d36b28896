//! Deep-G-buffer mirror reflections (DGB §3.6).

mod common;

use strata_render::frame::FrameCameras;
use strata_render::passes::deep_gbuffer::{DeepGBufferSettings, Variant};
use strata_render::passes::reflections::ReflectionSettings;
use strata_render::{GpuContext, RenderSettings, Renderer};
use strata_scene::{procedural, ImageBuf, Scene};

fn reflect(gpu: &GpuContext, scene: &Scene, layers: u32, w: u32, h: u32) -> (ImageBuf, Renderer) {
    let mut r = Renderer::new(
        gpu,
        scene,
        RenderSettings {
            width: w,
            height: h,
            deep: DeepGBufferSettings {
                layers,
                variant: Variant::Peel,
                ..Default::default()
            },
            reflections: Some(ReflectionSettings::default()),
            ..Default::default()
        },
    )
    .unwrap();
    r.render(gpu, scene, &FrameCameras::fixed(scene.camera), 0.0).unwrap();
    (r.read_target(gpu, "reflection").unwrap(), r)
}

/// The `mirror` scene's red panel is hidden from the camera by a board but seen
/// in the mirror floor under the board's edge: only the second layer holds it,
/// so only 2 layers reflect it.
#[test]
fn mirror_reflects_a_surface_hidden_from_layer_0_only_with_two_layers() {
    let gpu = common::gpu();
    let scene = procedural::builtin("mirror").unwrap();
    let (w, h) = (128, 96);
    let count = |img: &ImageBuf, code: f32| img.data.chunks_exact(4).filter(|p| p[3] == code).count();
    let red = |img: &ImageBuf| {
        img.data
            .chunks_exact(4)
            .filter(|p| p[3] == 3.0 && p[0] > 2.0 * p[1] && p[0] > 0.5)
            .count()
    };
    let (one, _) = reflect(&gpu, &scene, 1, w, h);
    let (two, r) = reflect(&gpu, &scene, 2, w, h);
    let mirrors = one.data.chunks_exact(4).filter(|p| p[3] > 0.0).count();
    eprintln!(
        "mirror px {mirrors}; k=1: env {} l0 {} l1 {}; k=2: env {} l0 {} l1 {} (red {})",
        count(&one, 1.0),
        count(&one, 2.0),
        count(&one, 3.0),
        count(&two, 1.0),
        count(&two, 2.0),
        count(&two, 3.0),
        red(&two)
    );
    assert!(
        mirrors > (w * h) as usize / 5,
        "mirror floor covers too little ({mirrors} px)"
    );
    assert_eq!(count(&one, 3.0), 0, "one layer cannot hit layer 1");
    assert!(
        red(&two) > 20,
        "2 layers: the hidden red panel is not reflected ({} px)",
        red(&two)
    );
    // and the composed image shows it
    let hdr = r.read_target(&gpu, "hdr-reflected").unwrap();
    let base = r.read_target(&gpu, "hdr").unwrap();
    let brighter = hdr
        .data
        .chunks_exact(4)
        .zip(base.data.chunks_exact(4))
        .zip(two.data.chunks_exact(4))
        .filter(|((a, b), t)| t[3] == 3.0 && a[0] > b[0] + 0.1)
        .count();
    assert!(brighter > 20, "reflections are not composed into hdr-reflected");
}

/// Rays that leave the (guard-banded) buffer return the environment: a mirror
/// floor with nothing above it reflects exactly the sky.
#[test]
fn rays_leaving_the_buffer_take_the_environment() {
    let gpu = common::gpu();
    let mut scene = procedural::builtin("mirror").unwrap();
    scene.objects.retain(|o| o.name == "mirror_floor");
    let sky = scene.settings.sky;
    let (img, _) = reflect(&gpu, &scene, 2, 96, 64);
    let mut env = 0;
    for p in img.data.chunks_exact(4) {
        if p[3] == 0.0 {
            continue;
        }
        assert_eq!(p[3], 1.0, "a ray hit something above an empty mirror");
        for c in 0..3 {
            assert!((p[c] - sky[c]).abs() < 1e-3, "environment {} vs sky {}", p[c], sky[c]);
        }
        env += 1;
    }
    assert!(env > 1000, "only {env} mirror pixels");
}
