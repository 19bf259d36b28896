//! `strata_render::embed::EmbeddedRadiosity`: DGB's screen-space radiosity on an
//! application's G-buffer. Fed the renderer's own layers (depth, Oct16 normals, albedo and
//! the lighting's radiosity B), it gives the renderer's indirect irradiance; bad inputs are
//! one-line errors.

mod common;

use strata_render::embed::{AoInputs, EmbeddedRadiosity, EmbeddedRadiosityConfig, NormalEncoding, TextureLayer};
use strata_render::frame::FrameCameras;
use strata_render::passes::radiosity::RadiositySettings;
use strata_render::{GpuContext, RenderSettings, Renderer};
use strata_scene::Scene;

const W: u32 = 160;
const H: u32 = 90;

/// A built-in scene held still, without sky or ambient light (the embedded radiosity has
/// neither: the application's radiance carries all light).
fn still(name: &str) -> Scene {
    let mut scene = common::frozen(name);
    scene.settings.sky = [0.0; 3];
    scene.settings.ambient = [0.0; 3];
    scene
}

fn renderer(gpu: &GpuContext, scene: &Scene, layers: u32, rs: RadiositySettings) -> Renderer {
    let settings = RenderSettings {
        radiosity: Some(rs),
        ..common::peeled_layers(scene, W, H, layers)
    };
    Renderer::new(gpu, scene, settings).unwrap()
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

/// Bad configurations and inputs are one-line errors naming the parameter; an sRGB albedo
/// (decoded to linear, as albedo should be) is taken.
#[test]
fn bad_embedded_radiosity_input_is_a_one_line_error() {
    use wgpu::TextureFormat as F;
    let gpu = common::gpu();
    let config = EmbeddedRadiosityConfig {
        width: W,
        height: H,
        settings: RadiositySettings {
            radius: Some(2.0),
            ..RadiositySettings::default()
        },
        ..EmbeddedRadiosityConfig::default()
    };
    let new = |f: &dyn Fn(&mut EmbeddedRadiosityConfig)| {
        let mut c = config.clone();
        f(&mut c);
        EmbeddedRadiosity::new(&gpu.adapter, &gpu.device, &gpu.queue, c)
    };
    let one_line = |e: String, words: &[&str]| common::assert_one_line(&e, words);
    let err = |f: &dyn Fn(&mut EmbeddedRadiosityConfig)| new(f).err().expect("an error").to_string();
    one_line(
        err(&|c| c.settings.radius = None),
        &["embedded radiosity", "settings.radius", "> 0"],
    );
    one_line(err(&|c| c.min_separation = -1.0), &["min_separation -1", ">= 0"]);
    one_line(err(&|c| c.layers = 0), &["layers 0", "1..=2"]);
    one_line(err(&|c| c.settings.samples = 0), &["embedded radiosity: ", "samples"]);

    let texture = |format| common::app_texture(&gpu, [W, H], format, wgpu::TextureUsages::TEXTURE_BINDING, 1);
    let (depth, normals) = (texture(F::Depth32Float), texture(F::Rgba16Float));
    let (srgb, hdr, integer) = (texture(F::Rgba8UnormSrgb), texture(F::Rgba16Float), texture(F::R32Uint));
    let cam = strata_scene::Camera::default();
    let gbuffer = AoInputs::new(
        (&depth).into(),
        (&normals).into(),
        cam.view(),
        cam.projection(W as f32 / H as f32),
    );
    let ok = strata_render::embed::RadiosityInputs {
        gbuffer,
        albedo: (&srgb).into(),
        radiance: (&hdr).into(),
        second: None,
    };
    let mut gi = new(&|_| {}).unwrap();
    let mut encode = |i: strata_render::embed::RadiosityInputs<'_>| {
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        let e = gi.encode(&mut encoder, &i).err().map(|e| e.to_string());
        gpu.queue.submit([encoder.finish()]);
        e
    };
    one_line(
        encode(strata_render::embed::RadiosityInputs {
            radiance: (&integer).into(),
            ..ok
        })
        .expect("an error"),
        &[
            "embedded radiosity: radiance has format R32Uint",
            "float, unorm or snorm",
        ],
    );
    one_line(
        encode(strata_render::embed::RadiosityInputs {
            second: Some(((&srgb).into(), (&hdr).into())),
            ..ok
        })
        .expect("an error"),
        &["RadiosityInputs::second", "1 layer"],
    );
    one_line(
        encode(strata_render::embed::RadiosityInputs {
            gbuffer: AoInputs {
                normals: (&srgb).into(),
                ..gbuffer
            },
            ..ok
        })
        .expect("an error"),
        &["embedded radiosity: normals has format Rgba8UnormSrgb"],
    );
    // the sRGB albedo is taken, and nothing above reached the device
    assert_eq!(encode(ok), None);
    gpu.check_errors().expect("no wgpu validation errors");
    // a device opened without R11G11B10 render targets (DGB Table 1's radiosity format)
    let (plain, plain_queue) = pollster::block_on(gpu.adapter.request_device(&Default::default())).unwrap();
    let e = EmbeddedRadiosity::new(&gpu.adapter, &plain, &plain_queue, config.clone())
        .err()
        .expect("an error");
    one_line(e.to_string(), &["RG11B10UFLOAT_RENDERABLE", "request it"]);

    let mut two = new(&|c| c.layers = 2).unwrap();
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    let e = two.encode(&mut encoder, &ok).unwrap_err().to_string();
    one_line(e, &["2 layers need RadiosityInputs::second"]);
}
