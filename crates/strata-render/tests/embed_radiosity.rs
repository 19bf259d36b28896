//! `strata_render::embed::EmbeddedRadiosity`: DGB's screen-space radiosity on an
//! application's G-buffer. Fed the renderer's own layers (depth, Oct16 normals, albedo and
//! the lighting's radiosity B), it gives the renderer's indirect irradiance; bad inputs are
//! one-line errors.

mod common;

use strata_render::embed::{AoInputs, EmbeddedRadiosity, EmbeddedRadiosityConfig, NormalEncoding, TextureLayer};
use strata_render::frame::FrameCameras;
use strata_render::passes::deep_gbuffer::{DeepGBufferSettings, Variant};
use strata_render::passes::radiosity::RadiositySettings;
use strata_render::{GpuContext, RenderSettings, Renderer};
use strata_scene::Scene;

const W: u32 = 160;
const H: u32 = 90;

/// A built-in scene held still, without sky or ambient light (the embedded radiosity has
/// neither: the application's radiance carries all light).
fn still(name: &str) -> Scene {
    let mut scene = strata_scene::procedural::builtin(name).unwrap();
    scene.camera_path = None;
    for o in &mut scene.objects {
        o.animation = None;
    }
    scene.settings.sky = [0.0; 3];
    scene.settings.ambient = [0.0; 3];
    scene
}

fn renderer(gpu: &GpuContext, scene: &Scene, layers: u32, rs: RadiositySettings) -> Renderer {
    Renderer::new(
        gpu,
        scene,
        RenderSettings {
            width: W,
            height: H,
            deep: DeepGBufferSettings {
                layers,
                variant: Variant::Peel,
                min_separation: Some(scene.settings.min_separation),
                ..Default::default()
            },
            radiosity: Some(rs),
            ..Default::default()
        },
    )
    .unwrap()
}

fn embedded(gpu: &GpuContext, scene: &Scene, layers: u32, rs: RadiositySettings) -> EmbeddedRadiosity {
    EmbeddedRadiosity::new(
        &gpu.adapter,
        &gpu.device,
        &gpu.queue,
        EmbeddedRadiosityConfig {
            width: W,
            height: H,
            layers,
            settings: RadiositySettings {
                radius: Some(scene.settings.radiosity_radius),
                ..rs
            },
            min_separation: scene.settings.min_separation,
            normals: NormalEncoding::Octahedral,
            ..EmbeddedRadiosityConfig::default()
        },
    )
    .expect("the embedded radiosity builds without validation errors")
}

#[test]
fn embedded_radiosity_on_the_renderers_layers_is_the_renderers_indirect_light() {
    let gpu = common::gpu();
    for (name, layers) in [("cornell", 1), ("warehouse", 2)] {
        let scene = still(name);
        let cams = FrameCameras::fixed(scene.camera);
        let (view, proj) = (scene.camera.view(), scene.camera.projection(W as f32 / H as f32));
        let rs = RadiositySettings::default();
        let mut r = renderer(&gpu, &scene, layers, rs.clone());
        let mut gi = embedded(&gpu, &scene, layers, rs);
        // enough frames for the progressive bounces (DGB §3.3) and the temporal filter
        for _ in 0..6 {
            r.render(&gpu, &scene, &cams, 0.0).unwrap();
            let t = |n| r.target_texture(n).unwrap();
            let layer = |n, layer| TextureLayer { texture: t(n), layer };
            let inputs = strata_render::embed::RadiosityInputs {
                gbuffer: AoInputs {
                    second: (layers == 2).then(|| (layer("depth", 1), layer("normal", 1))),
                    ..AoInputs::new(layer("depth", 0), layer("normal", 0), view, proj)
                },
                albedo: layer("albedo", 0),
                radiance: layer("radiosity0", 0),
                second: (layers == 2).then(|| (layer("albedo", 1), layer("radiosity1", 0))),
            };
            let mut encoder = gpu.device.create_command_encoder(&Default::default());
            gi.encode(&mut encoder, &inputs).expect("valid inputs");
            gpu.queue.submit([encoder.finish()]);
            gpu.check_errors().expect("no wgpu validation errors");
        }
        for target in ["radiosity0", "indirect"] {
            let (a, b) = (gi.read_target(target).unwrap(), r.read_target(&gpu, target).unwrap());
            let c = a.channels as usize;
            let (mut sum, mut ref_sum, mut worst) = (0.0f64, 0.0f64, 0.0f32);
            for (pa, pb) in a.data.chunks(c).zip(b.data.chunks(c)) {
                for k in 0..3 {
                    let d = (pa[k] - pb[k]).abs();
                    sum += d as f64;
                    ref_sum += pb[k].abs() as f64;
                    worst = worst.max(d / pb[k].abs().max(0.05));
                }
            }
            let rel = sum / ref_sum.max(1e-9);
            println!("{name}, k = {layers}, {target}: mean |Δ| / mean = {rel:.2e}, worst {worst:.2e}");
            assert!(ref_sum > 0.0, "{name}: light to compare");
            assert!(
                rel < 2e-3,
                "{name} k = {layers}: {target} differs from the renderer's ({rel})"
            );
        }
    }
}
