//! `strata_render::embed`: deep-G-buffer AO on an application's own G-buffer. Its output is
//! checked against the renderer's own AO of the same frames (`strata render --technique
//! ao`), fed first with the renderer's G-buffer and then with G-buffers drawn the ways
//! applications draw them (standard or reversed depth, left- or right-handed cameras,
//! signed, unsigned or view-space normals).

mod common;

use strata_render::embed::{AoInputs, EmbeddedAo, EmbeddedAoConfig, NormalEncoding, NormalSpace, TextureLayer};
use strata_render::frame::FrameCameras;
use strata_render::passes::ao::AoSettings;
use strata_render::passes::deep_gbuffer::{DeepGBufferSettings, Variant};
use strata_render::{GpuContext, RenderSettings, Renderer};
use strata_scene::{ImageBuf, Scene};

const W: u32 = 160;
const H: u32 = 90;
const FRAMES: u32 = 4;

/// The atrium held still: no camera path, no animation.
fn still_atrium() -> Scene {
    let mut scene = strata_scene::procedural::builtin("atrium").unwrap();
    scene.camera_path = None;
    for o in &mut scene.objects {
        o.animation = None;
    }
    scene
}

/// The renderer's AO of `FRAMES` still frames with `layers` peeled layers (no guard band).
fn renderer(gpu: &GpuContext, scene: &Scene, layers: u32) -> Renderer {
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
            ao: Some(AoSettings::default()),
            ..Default::default()
        },
    )
    .unwrap()
}

fn embedded(gpu: &GpuContext, scene: &Scene, layers: u32, normals: NormalEncoding, space: NormalSpace) -> EmbeddedAo {
    EmbeddedAo::new(
        &gpu.adapter,
        &gpu.device,
        &gpu.queue,
        EmbeddedAoConfig {
            width: W,
            height: H,
            layers,
            settings: AoSettings {
                radius: Some(scene.settings.ao_radius),
                ..AoSettings::default()
            },
            normals,
            normal_space: space,
        },
    )
    .expect("the embedded AO builds without validation errors")
}

/// Records one embedded frame and submits it; validation errors fail the test.
fn run(gpu: &GpuContext, ao: &mut EmbeddedAo, inputs: &AoInputs<'_>) {
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    ao.encode(&mut encoder, inputs).expect("valid inputs");
    gpu.queue.submit([encoder.finish()]);
    gpu.check_errors().expect("no wgpu validation errors");
}

/// (mean |a − b|, fraction of pixels with |a − b| > `tol`) over channel 0.
fn diff(a: &ImageBuf, b: &ImageBuf, tol: f32) -> (f64, f64) {
    assert_eq!((a.width, a.height), (b.width, b.height));
    let n = (a.width * a.height) as usize;
    let (mut sum, mut over) = (0.0f64, 0usize);
    for i in 0..n {
        let d = (a.data[i * a.channels as usize] - b.data[i * b.channels as usize]).abs();
        sum += d as f64;
        over += (d > tol) as usize;
    }
    (sum / n as f64, over as f64 / n as f64)
}

#[test]
fn embedded_ao_on_the_renderers_gbuffer_is_the_renderers_ao() {
    let gpu = common::gpu();
    let scene = still_atrium();
    let cams = FrameCameras::fixed(scene.camera);
    let (view, proj) = (scene.camera.view(), scene.camera.projection(W as f32 / H as f32));
    for layers in [1, 2] {
        let mut r = renderer(&gpu, &scene, layers);
        let mut ao = embedded(&gpu, &scene, layers, NormalEncoding::Octahedral, NormalSpace::World);
        for _ in 0..FRAMES {
            r.render(&gpu, &scene, &cams, 0.0).unwrap();
            let (depth, normal) = (r.target_texture("depth").unwrap(), r.target_texture("normal").unwrap());
            let layer = |t, layer| TextureLayer { texture: t, layer };
            let inputs = AoInputs {
                second: (layers == 2).then(|| (layer(depth, 1), layer(normal, 1))),
                ..AoInputs::new(layer(depth, 0), layer(normal, 0), view, proj)
            };
            run(&gpu, &mut ao, &inputs);
        }
        // the import: camera-space z from the reversed depth to f32 precision, normals as they are
        let (za, zb) = (ao.read_target("zpack").unwrap(), r.read_target(&gpu, "zpack").unwrap());
        let (mut surfaces, mut worst) = ([0usize; 2], 0.0f32);
        for (i, (a, b)) in za.data.iter().zip(&zb.data).enumerate() {
            assert_eq!(
                *a > 0.0,
                *b > 0.0,
                "k = {layers}: a surface in one zpack only ({a} vs {b})"
            );
            if *b > 0.0 {
                worst = worst.max((a - b).abs() / b);
                surfaces[i % zb.channels as usize] += 1;
            }
        }
        println!("k = {layers}: zpack relative error at most {worst:.1e}");
        // lavapipe interpolates depth less precisely than the perspective-correct csz
        assert!(worst < 1e-4, "k = {layers}: zpack off by {worst} relative");
        let px = (W * H) as usize;
        assert!(
            surfaces[0] > px / 2 && (layers == 1 || surfaces[1] > px / 4),
            "k = {layers}: the layers hold surfaces ({surfaces:?} of {px})"
        );
        assert_eq!(
            ao.read_target("npack").unwrap().data,
            r.read_target(&gpu, "npack").unwrap().data,
            "k = {layers}: Oct16 world normals pass through"
        );
        // the same passes on the same data: the same AO but for f32 rounding of z
        let (a, b) = (ao.read_target("ao").unwrap(), r.read_target(&gpu, "ao").unwrap());
        let (mean, over) = diff(&a, &b, 1.0 / 255.0);
        println!(
            "k = {layers}: mean |ΔAV| {mean:.2e}, {:.3} % of pixels over 1/255",
            100.0 * over
        );
        assert!(
            mean < 2e-4 && over < 0.002,
            "k = {layers}: mean {mean}, {over} over 1/255"
        );
        let lo = b.data.iter().cloned().fold(1.0f32, f32::min);
        assert!(lo < 0.6, "the atrium has occlusion to compare (darkest AV {lo})");
    }
}
