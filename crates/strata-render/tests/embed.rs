//! `strata_render::embed`: deep-G-buffer AO on an application's own G-buffer. Its output is
//! checked against the renderer's own AO of the same frames (`strata render --technique
//! ao`), fed first with the renderer's G-buffer and then with G-buffers drawn the ways
//! applications draw them (standard or reversed depth, left- or right-handed cameras,
//! signed, unsigned or view-space normals).

mod common;

use glam::{Mat4, Vec3};
use strata_render::embed::{AoInputs, EmbeddedAo, EmbeddedAoConfig, NormalEncoding, NormalSpace, TextureLayer};
use strata_render::frame::FrameCameras;
use strata_render::passes::ao::AoSettings;
use strata_render::passes::Kernel;
use strata_render::{GpuContext, RenderSettings, Renderer};
use strata_scene::Scene;

const W: u32 = 160;
const H: u32 = 90;
const FRAMES: u32 = 4;

/// The atrium held still: no camera path, no animation.
fn still_atrium() -> Scene {
    common::frozen("atrium")
}

/// The renderer's AO with `ao` and `layers` peeled layers (no guard band).
fn renderer(gpu: &GpuContext, scene: &Scene, layers: u32, ao: AoSettings) -> Renderer {
    let settings = RenderSettings {
        ao: Some(ao),
        ..common::peeled_layers(scene, W, H, layers)
    };
    Renderer::new(gpu, scene, settings).unwrap()
}

/// The embedded AO with `ao` and the scene's radius.
fn embedded(
    gpu: &GpuContext,
    scene: &Scene,
    layers: u32,
    ao: AoSettings,
    normals: NormalEncoding,
    space: NormalSpace,
) -> EmbeddedAo {
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
                ..ao
            },
            normals,
            normal_space: space,
        },
    )
    .expect("the embedded AO builds without validation errors")
}

/// Records one embedded frame and submits it; validation errors fail the test.
fn run(gpu: &GpuContext, ao: &mut EmbeddedAo, inputs: &AoInputs<'_>) {
    common::submit_checked(gpu, |encoder| ao.encode(encoder, inputs).expect("valid inputs"));
}

#[test]
fn embedded_ao_on_the_renderers_gbuffer_is_the_renderers_ao() {
    let gpu = common::gpu();
    let scene = still_atrium();
    let cams = FrameCameras::fixed(scene.camera);
    let (view, proj) = (scene.camera.view(), scene.camera.projection(W as f32 / H as f32));
    // the AO pass as a fragment pass (lavapipe's Auto) and as compute (GPUs' Auto), at half
    // resolution, and deinterleaved: every AoSettings variant runs on the imported layers
    let cases = [
        (1, "default", AoSettings::default()),
        (2, "default", AoSettings::default()),
        (
            2,
            "compute",
            AoSettings {
                kernel: Kernel::Compute,
                ..AoSettings::default()
            },
        ),
        (
            2,
            "ao-scale 2",
            AoSettings {
                scale: 2,
                ..AoSettings::default()
            },
        ),
        (
            2,
            "deinterleave 2x2",
            AoSettings {
                deinterleave: Some([2, 2]),
                ..AoSettings::default()
            },
        ),
    ];
    for (layers, what, settings) in cases {
        let mut r = renderer(&gpu, &scene, layers, settings.clone());
        let mut ao = embedded(
            &gpu,
            &scene,
            layers,
            settings,
            NormalEncoding::Octahedral,
            NormalSpace::World,
        );
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
        let (mean, over) = common::channel0_diff(&a, &b, 1.0 / 255.0);
        println!(
            "k = {layers}, {what}: mean |ΔAV| {mean:.2e}, {:.3} % of pixels over 1/255",
            100.0 * over
        );
        assert!(
            mean < 2e-4 && over < 0.002,
            "k = {layers}, {what}: mean {mean}, {over} over 1/255"
        );
        common::check_pass_timings(&gpu, || ao.timings(), ao.pass_names(), what);
        let lo = b.data.iter().cloned().fold(1.0f32, f32::min);
        assert!(lo < 0.6, "the atrium has occlusion to compare (darkest AV {lo})");
    }
}

#[path = "../examples/embed_ao/app.rs"]
mod app;

/// G-buffers drawn as applications draw them: the embedded AO of each matches the renderer's
/// AO of the same camera. The left-handed case mirrors the world (z → −z) and looks at it
/// with `look_at_lh`, which gives the same image (and the same winding on screen); AO is
/// unchanged by the mirror.
#[test]
fn embedded_ao_takes_the_depth_and_normal_conventions_applications_use() {
    use glam::camera::{lh, rh};
    use wgpu::TextureFormat as F;
    let gpu = common::gpu();
    let scene = still_atrium();
    let cam = scene.camera;
    let aspect = W as f32 / H as f32;
    let fov = cam.fov_y_deg.to_radians();
    let mut r = renderer(&gpu, &scene, 1, AoSettings::default());
    for _ in 0..FRAMES {
        r.render(&gpu, &scene, &FrameCameras::fixed(cam), 0.0).unwrap();
    }
    let reference = r.read_target(&gpu, "ao").unwrap();
    let tris = |mirror: Vec3| -> Vec<app::Triangle> {
        app::scene_triangles(&scene)
            .into_iter()
            .map(|(p, n, albedo)| (p.map(|p| p * mirror), n.map(|n| n * mirror), albedo))
            .collect()
    };
    let flip = Vec3::new(1.0, 1.0, -1.0);
    struct Case {
        name: &'static str,
        layout: app::Layout,
        encoding: NormalEncoding,
        space: NormalSpace,
        mirror: bool,
        view: Mat4,
        proj: Mat4,
    }
    let layout = |depth, normal, normals, reversed| app::Layout {
        depth,
        normal,
        normals,
        reversed,
    };
    let cases = [
        Case {
            name: "right-handed, standard depth, signed world normals",
            layout: layout(F::Depth32Float, F::Rgba16Float, app::Normals::WorldSigned, false),
            encoding: NormalEncoding::Signed,
            space: NormalSpace::World,
            mirror: false,
            view: cam.view(),
            proj: rh::proj::directx::perspective(fov, aspect, cam.near, 500.0),
        },
        Case {
            name: "right-handed, reversed infinite depth, unsigned view-space normals",
            layout: layout(F::Depth24Plus, F::Rgba8Unorm, app::Normals::ViewUnsigned, true),
            encoding: NormalEncoding::Unsigned,
            space: NormalSpace::View,
            mirror: false,
            view: cam.view(),
            proj: rh::proj::directx::perspective_infinite_reverse(fov, aspect, cam.near),
        },
        Case {
            name: "left-handed, standard depth, signed view-space normals",
            layout: layout(F::Depth32Float, F::Rgba16Float, app::Normals::ViewSigned, false),
            encoding: NormalEncoding::Signed,
            space: NormalSpace::View,
            mirror: true,
            view: lh::view::look_at_mat4(cam.eye * flip, cam.target * flip, cam.up * flip),
            proj: lh::proj::directx::perspective(fov, aspect, cam.near, 500.0),
        },
    ];
    for c in cases {
        let app = app::GBuffer::new(
            &gpu.device,
            [W, H],
            c.layout,
            &tris(if c.mirror { flip } else { Vec3::ONE }),
        );
        let mut ao = embedded(&gpu, &scene, 1, AoSettings::default(), c.encoding, c.space);
        for _ in 0..FRAMES {
            let mut encoder = gpu.device.create_command_encoder(&Default::default());
            app.draw(&gpu.queue, &mut encoder, c.view, c.proj);
            ao.encode(
                &mut encoder,
                &AoInputs::new((&app.depth).into(), (&app.normals).into(), c.view, c.proj),
            )
            .expect("valid inputs");
            gpu.queue.submit([encoder.finish()]);
            gpu.check_errors().expect("no wgpu validation errors");
        }
        let (za, zb) = (ao.read_target("zpack").unwrap(), r.read_target(&gpu, "zpack").unwrap());
        let (mut worst, mut missed) = (0.0f32, 0usize);
        for (a, b) in za.data.iter().zip(&zb.data).step_by(2) {
            if (*a > 0.0) != (*b > 0.0) {
                missed += 1;
            } else if *b > 0.0 {
                worst = worst.max((a - b).abs() / b);
            }
        }
        let a = ao.read_target("ao").unwrap();
        let (mean, over) = common::channel0_diff(&a, &reference, 4.0 / 255.0);
        println!(
            "{}: z within {worst:.1e} relative, {missed} pixels' coverage differs; mean |ΔAV| {mean:.2e}, {:.2} % over 4/255",
            c.name,
            100.0 * over
        );
        assert!(missed <= 4 && worst < 1e-3, "{}: depth import off", c.name);
        assert!(mean < 2e-3 && over < 0.01, "{}: AO differs from the renderer's", c.name);
    }
}

/// Bad configurations and inputs are one-line errors naming the parameter and its valid
/// range, and record nothing: the device sees no validation error.
#[test]
fn bad_embedded_ao_input_is_a_one_line_error() {
    use wgpu::TextureFormat as F;
    let gpu = common::gpu();
    let build = |f: &dyn Fn(&mut EmbeddedAoConfig)| {
        let mut c = EmbeddedAoConfig {
            width: W,
            height: H,
            settings: AoSettings {
                radius: Some(0.5),
                ..AoSettings::default()
            },
            ..EmbeddedAoConfig::default()
        };
        f(&mut c);
        EmbeddedAo::new(&gpu.adapter, &gpu.device, &gpu.queue, c)
    };
    let config = |f: &dyn Fn(&mut EmbeddedAoConfig)| build(f).err().map(|e| e.to_string());
    let one_line = |e: Option<String>, words: &[&str]| common::assert_one_line(&e.expect("an error"), words);
    one_line(config(&|c| c.settings.radius = None), &["settings.radius", "> 0"]);
    one_line(config(&|c| c.settings.radius = Some(-1.0)), &["radius", "> 0"]);
    one_line(config(&|c| c.layers = 3), &["layers 3", "1..=2"]);
    one_line(config(&|c| c.width = 0), &["size 0x90", "width and height"]);
    one_line(
        config(&|c| c.settings.samples = 0),
        &["embedded AO: ", "samples", "1..=256"],
    );

    let texture = |size, format, usage, samples| common::app_texture(&gpu, size, format, usage, samples);
    let usage = wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::RENDER_ATTACHMENT;
    let depth = texture([W, H], F::Depth32Float, usage, 1);
    let normals = texture([W, H], F::Rgba16Float, usage, 1);
    let small = texture([W / 2, H / 2], F::Depth32Float, usage, 1);
    let half_normals = texture([W / 2, H / 2], F::Rgba16Float, usage, 1);
    let unbound = texture([W, H], F::Depth32Float, wgpu::TextureUsages::RENDER_ATTACHMENT, 1);
    let msaa = texture([W, H], F::Depth32Float, usage, 4);
    let integer = texture([W, H], F::Rgba8Uint, usage, 1);
    let srgb = texture([W, H], F::Rgba8UnormSrgb, usage, 1);
    let cam = strata_scene::Camera::default();
    let (view, proj) = (cam.view(), cam.projection(W as f32 / H as f32));
    let mut ao = build(&|_| {}).unwrap();
    let mut encode = |i: AoInputs<'_>| {
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        let e = ao.encode(&mut encoder, &i).err().map(|e| e.to_string());
        gpu.queue.submit([encoder.finish()]);
        e
    };
    let ok = AoInputs::new((&depth).into(), (&normals).into(), view, proj);
    let ortho = glam::camera::rh::proj::directx::orthographic(-1.0, 1.0, -1.0, 1.0, 0.1, 10.0);
    // 3 pixels off centre: an asymmetric frustum, not a TAA jitter
    let mut off_centre = proj;
    off_centre.z_axis.x = 6.0 / W as f32;
    let vulkan = glam::camera::rh::proj::vulkan::perspective(1.0, 1.0, 0.1, 10.0);
    let layer1 = TextureLayer {
        texture: &normals,
        layer: 1,
    };
    let with_depth = |t| AoInputs {
        depth: TextureLayer::from(t),
        ..ok
    };
    let with_normals = |t| AoInputs {
        normals: TextureLayer::from(t),
        ..ok
    };
    let bad: [(AoInputs<'_>, &[&str]); 13] = [
        (with_depth(&small), &["depth is 80x45", "160x90"]),
        (with_depth(&unbound), &["depth", "TEXTURE_BINDING"]),
        (with_depth(&msaa), &["depth has 4 samples", "resolve"]),
        (with_depth(&normals), &["depth has format Rgba16Float", "depth format"]),
        (
            with_normals(&integer),
            &["normals has format Rgba8Uint", "float, unorm or snorm"],
        ),
        (AoInputs { normals: layer1, ..ok }, &["normals layer 1", "0..1"]),
        (
            AoInputs {
                second: Some(((&depth).into(), (&normals).into())),
                ..ok
            },
            &["AoInputs::second", "1 layer"],
        ),
        (AoInputs { proj: ortho, ..ok }, &["proj", "perspective"]),
        (
            AoInputs { proj: off_centre, ..ok },
            &["proj", "off-centre by (3.00, 0.00) pixels"],
        ),
        (AoInputs { proj: vulkan, ..ok }, &["proj", "y up"]),
        (AoInputs { view: Mat4::ZERO, ..ok }, &["view", "rigid"]),
        (
            AoInputs {
                view: Mat4::from_scale(Vec3::splat(2.0)) * view,
                ..ok
            },
            &["view", "without scale"],
        ),
        (with_normals(&srgb), &["normals has format Rgba8UnormSrgb", "linear"]),
    ];
    for (inputs, words) in bad {
        one_line(encode(inputs), words);
    }
    // none of them recorded anything; a good frame still runs
    assert_eq!(encode(ok), None);
    gpu.check_errors().expect("no wgpu validation errors");

    // a resized window: the new size is the one checked, a bad size keeps the old one
    ao.resize(W / 2, H / 2).unwrap();
    let half = AoInputs::new((&small).into(), (&half_normals).into(), view, proj);
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    ao.encode(&mut encoder, &half).expect("the new size");
    let e = ao.encode(&mut encoder, &ok).unwrap_err().to_string();
    assert!(e.contains("depth is 160x90") && e.contains("80x45"), "{e}");
    gpu.queue.submit([encoder.finish()]);
    let e = ao.resize(0, 10).unwrap_err().to_string();
    assert!(e.contains("size 0x10"), "{e}");
    assert_eq!((ao.config().width, ao.config().height), (W / 2, H / 2));
    gpu.check_errors().expect("no wgpu validation errors");

    // the smallest windows build and run (one MIP level, a blur wider than the image)
    for size in [[1, 1], [3, 2]] {
        let mut ao = build(&|c| [c.width, c.height] = size).unwrap();
        let (d, n) = (
            texture(size, F::Depth32Float, usage, 1),
            texture(size, F::Rgba16Float, usage, 1),
        );
        let proj = cam.projection(size[0] as f32 / size[1] as f32);
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        ao.encode(&mut encoder, &AoInputs::new((&d).into(), (&n).into(), view, proj))
            .unwrap();
        gpu.queue.submit([encoder.finish()]);
        gpu.check_errors().expect("no wgpu validation errors");
        // depth 0 in a reversed projection: no surface, fully visible
        assert!(ao.read_target("ao").unwrap().data.iter().all(|v| *v == 1.0));
    }
}

/// DGB's second layer drawn by the application (a depth peel with the minimum separation,
/// `examples/embed_ao/app.rs`): the embedded 2-layer AO matches the renderer's 2-layer
/// AO (peeled, `Variant::Peel`), and differs from the 1-layer AO where the layer matters.
#[test]
fn embedded_two_layer_ao_from_an_applications_peel_is_the_renderers() {
    use glam::camera::rh;
    let gpu = common::gpu();
    let scene = still_atrium();
    let cam = scene.camera;
    let mut r2 = renderer(&gpu, &scene, 2, AoSettings::default());
    let mut r1 = renderer(&gpu, &scene, 1, AoSettings::default());
    for _ in 0..FRAMES {
        r2.render(&gpu, &scene, &FrameCameras::fixed(cam), 0.0).unwrap();
        r1.render(&gpu, &scene, &FrameCameras::fixed(cam), 0.0).unwrap();
    }
    let view = cam.view();
    let proj = rh::proj::directx::perspective(cam.fov_y_deg.to_radians(), W as f32 / H as f32, cam.near, 500.0);
    let tris = app::scene_triangles(&scene);
    let layout = app::Layout::standard();
    let first = app::GBuffer::new(&gpu.device, [W, H], layout, &tris);
    let second = app::GBuffer::second_layer(&gpu.device, &first, scene.settings.min_separation, &tris);
    let mut ao = embedded(
        &gpu,
        &scene,
        2,
        AoSettings::default(),
        NormalEncoding::Signed,
        NormalSpace::World,
    );
    for _ in 0..FRAMES {
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        first.draw(&gpu.queue, &mut encoder, view, proj);
        second.draw(&gpu.queue, &mut encoder, view, proj);
        let inputs = AoInputs {
            second: Some(((&second.depth).into(), (&second.normals).into())),
            ..AoInputs::new((&first.depth).into(), (&first.normals).into(), view, proj)
        };
        ao.encode(&mut encoder, &inputs).expect("valid inputs");
        gpu.queue.submit([encoder.finish()]);
        gpu.check_errors().expect("no wgpu validation errors");
    }
    // the second layer's coverage: the same pixels but where the peel's threshold rounds apart
    let (za, zb) = (ao.read_target("zpack").unwrap(), r2.read_target(&gpu, "zpack").unwrap());
    let (mut both, mut apart) = (0usize, 0usize);
    for (a, b) in za.data.iter().zip(&zb.data).skip(1).step_by(2) {
        match (*a > 0.0, *b > 0.0) {
            (true, true) => both += 1,
            (false, false) => {}
            _ => apart += 1,
        }
    }
    let (a, b2, b1) = (
        ao.read_target("ao").unwrap(),
        r2.read_target(&gpu, "ao").unwrap(),
        r1.read_target(&gpu, "ao").unwrap(),
    );
    let (mean, over) = common::channel0_diff(&a, &b2, 4.0 / 255.0);
    let (mean1, _) = common::channel0_diff(&b1, &b2, 4.0 / 255.0);
    println!(
        "second layer: {both} pixels in both, {apart} in one; mean |ΔAV| {mean:.2e} ({:.2} % over 4/255), 1 vs 2 layers {mean1:.2e}",
        100.0 * over
    );
    assert!(
        both > (W * H / 4) as usize && apart * 200 < both,
        "layer 1 coverage: {both} vs {apart}"
    );
    assert!(mean < 2e-3 && over < 0.01, "2-layer AO differs from the renderer's");
    assert!(
        mean1 > 5.0 * mean,
        "the second layer changes the AO ({mean1} vs {mean})"
    );
}

/// TAA: the application draws a frame with a sub-pixel jitter and passes that projection.
/// Each pixel's imported camera-space z is the one a ray through the jittered pixel centre
/// meets (ray-traced on the CPU). A perspective depth depends on z alone, so the jitter
/// changes which point a pixel sees, not how its depth inverts: the unjittered matrix gives
/// the same z, and the AO (whose camera model drops the jitter) the same bits.
#[test]
fn embedded_ao_takes_a_taa_jittered_projection() {
    use glam::camera::rh;
    let gpu = common::gpu();
    let scene = still_atrium();
    let cam = scene.camera;
    let view = cam.view();
    let proj = rh::proj::directx::perspective(cam.fov_y_deg.to_radians(), W as f32 / H as f32, cam.near, 500.0);
    // a jitter of (jx, jy) pixels, right and down: NDC (2jx/W, −2jy/H); w = −z_view
    let (jx, jy) = (0.37f32, -0.29f32);
    let mut jittered = proj;
    jittered.z_axis.x = -2.0 * jx / W as f32;
    jittered.z_axis.y = 2.0 * jy / H as f32;
    let tris = app::scene_triangles(&scene);
    let layout = app::Layout::standard();
    let app = app::GBuffer::new(&gpu.device, [W, H], layout, &tris);
    // the oracle: pixel centre c shows the point the unjittered camera sees at c − j
    let reference = strata_reference::Reference::new(&scene, 0.0);
    let oracle: Vec<f32> = (0..W * H)
        .map(|i| {
            let (x, y) = ((i % W) as f32 + 0.5 - jx, (i / W) as f32 + 0.5 - jy);
            let dir = cam.pixel_dir_f(x, y, W, H);
            reference
                .bvh()
                .intersect(cam.eye, dir, cam.near, f32::INFINITY)
                .map_or(0.0, |h| h.t)
        })
        .collect();
    let (mut exact, mut av) = (Vec::new(), Vec::new());
    for given in [jittered, proj] {
        let settings = AoSettings::default();
        let mut ao = embedded(&gpu, &scene, 1, settings, NormalEncoding::Signed, NormalSpace::World);
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        app.draw(&gpu.queue, &mut encoder, view, jittered);
        let inputs = AoInputs::new((&app.depth).into(), (&app.normals).into(), view, given);
        ao.encode(&mut encoder, &inputs).expect("a sub-pixel jitter is taken");
        gpu.queue.submit([encoder.finish()]);
        gpu.check_errors().expect("no wgpu validation errors");
        let z = ao.read_target("zpack").unwrap();
        // pixels whose z is within 10⁻³ of the ray's (of those where both see a surface)
        let (mut within, mut both) = (0usize, 0usize);
        for (i, t) in oracle.iter().enumerate() {
            let zi = z.data[2 * i];
            if zi > 0.0 && *t > 0.0 {
                both += 1;
                within += ((zi - t).abs() <= 1e-3 * t) as usize;
            }
        }
        let share = within as f64 / both as f64;
        println!(
            "jittered depth, {} projection given: z within 10⁻³ of the ray's at {:.2} % of {both} pixels",
            if exact.is_empty() {
                "the jittered"
            } else {
                "the unjittered"
            },
            100.0 * share
        );
        exact.push(share);
        av.push(ao.read_target("ao").unwrap().data);
    }
    assert!(
        exact[0] > 0.999,
        "the jittered projection's z is the ray's ({})",
        exact[0]
    );
    assert_eq!(exact[0], exact[1], "z does not depend on the jitter");
    assert!(av[0] == av[1], "nor does the AO's camera model");
}

/// An application without a normal buffer (a forward renderer with a depth prepass):
/// `NormalEncoding::FromDepth` reconstructs each layer's normal from its depth.
/// - Cornell (flat boxes: the geometric normals are the shading normals): the normals are
///   within 2° of the renderer's at ≥ 98 % of layer 0's covered pixels and ≥ 85 % of the
///   patchier second layer's; the rest are edge pixels, where no neighbour lies on the
///   pixel's own plane.
/// - Both against the CPU reference AO (DGB obscurance, 256 samples): on Cornell the AO
///   from depth is as far from it as with true normals (≤ 1.05×); on the atrium, whose
///   columns and arches are smooth-shaded and whose cornices are one pixel wide at
///   160×90, at most 1.6× as far.
#[test]
fn embedded_ao_from_depth_alone_reconstructs_the_normals() {
    let gpu = common::gpu();
    let settings = AoSettings::default();
    for name in ["cornell", "atrium"] {
        let scene = common::frozen(name);
        let cams = FrameCameras::fixed(scene.camera);
        let (view, proj) = (scene.camera.view(), scene.camera.projection(W as f32 / H as f32));
        let mut results = Vec::new();
        for layers in [1, 2] {
            let mut r = renderer(&gpu, &scene, layers, settings.clone());
            let mut ao = embedded(
                &gpu,
                &scene,
                layers,
                settings.clone(),
                NormalEncoding::FromDepth,
                NormalSpace::World,
            );
            for _ in 0..FRAMES {
                r.render(&gpu, &scene, &cams, 0.0).unwrap();
                let depth = r.target_texture("depth").unwrap();
                let layer = |layer| TextureLayer { texture: depth, layer };
                let inputs = AoInputs {
                    second: (layers == 2).then(|| (layer(1), layer(1))),
                    ..AoInputs::depth_only(layer(0), view, proj)
                };
                run(&gpu, &mut ao, &inputs);
            }
            let npack = (ao.read_target("npack").unwrap(), r.read_target(&gpu, "npack").unwrap());
            let zpack = r.read_target(&gpu, "zpack").unwrap();
            let mut shares = Vec::new();
            for j in 0..layers as usize {
                let (ours, theirs) = (common::npack_normals(&npack.0, j), common::npack_normals(&npack.1, j));
                let (mut covered, mut within) = (0usize, 0usize);
                for i in 0..(W * H) as usize {
                    if zpack.data[i * 2 + j] <= 0.0 {
                        continue;
                    }
                    covered += 1;
                    let a = glam::Vec3::from_slice(&ours.data[i * 3..i * 3 + 3]);
                    let b = glam::Vec3::from_slice(&theirs.data[i * 3..i * 3 + 3]);
                    within += (a.dot(b) >= 2f32.to_radians().cos()) as usize;
                }
                shares.push(within as f64 / covered as f64);
            }
            let (a, b) = (ao.read_target("ao").unwrap(), r.read_target(&gpu, "ao").unwrap());
            let (mean, over) = common::channel0_diff(&a, &b, 4.0 / 255.0);
            println!(
                "{name}, k = {layers}: normals within 2° per layer {shares:.3?}; mean |ΔAV| {mean:.2e} against the renderer's, {:.2} % of pixels over 4/255",
                100.0 * over
            );
            if name == "cornell" {
                // the second layer is patchier: more of its pixels lie at its edges
                assert!(
                    shares[0] >= 0.98 && shares.get(1).is_none_or(|s| *s >= 0.85),
                    "{name}, k = {layers}: {shares:?}"
                );
            }
            results.push((b, mean, a));
        }
        let (between_layers, _) = common::channel0_diff(&results[0].0, &results[1].0, 4.0 / 255.0);
        println!("{name}: the renderer's AO, 1 against 2 layers: mean |ΔAV| {between_layers:.2e}");
        // against the CPU reference (DGB obscurance over the whole scene, shading normals)
        let (radius, beta, epsilon) = settings.resolve(&scene);
        let s = strata_reference::ao::ObscuranceSettings {
            radius,
            beta,
            epsilon,
            spp: 256,
            disk: strata_reference::ao::DiskSampling::SpiralRadius,
            ..strata_reference::ao::ObscuranceSettings::new(radius)
        };
        let reference = strata_reference::Reference::new(&scene, 0.0).ao_obscurance(&scene.camera, W, H, &s);
        for (k, (true_normals, _, _)) in results.iter().enumerate() {
            let from_depth = &results[k].2;
            let (e_true, _) = common::channel0_diff(true_normals, &reference, 1.0);
            let (e_depth, _) = common::channel0_diff(from_depth, &reference, 1.0);
            println!(
                "{name}, k = {}: AV error against the CPU reference: true normals {e_true:.4}, from depth {e_depth:.4}",
                k + 1
            );
            // flat boxes: the same AO; the atrium at 160×90: its one-pixel cornices and
            // smooth-shaded columns cost some (1.13× at 640×360, docs/embed.md)
            let bound = if name == "cornell" { 1.05 } else { 1.6 };
            assert!(
                e_depth <= bound * e_true,
                "{name}, k = {}: {e_depth} against {e_true} with true normals",
                k + 1
            );
        }
    }
}

/// The import's bind group is kept while the application passes the same textures (a steady
/// frame creates no views or bind groups). What each frame reads must still be that frame's:
/// another texture, another array layer of the same texture, and new contents of the same
/// texture each give the `zpack` that a fresh `EmbeddedAo` imports from those inputs.
#[test]
fn embedded_ao_reads_each_frames_textures() {
    let gpu = common::gpu();
    let scene = still_atrium();
    let proj = scene.camera.projection(W as f32 / H as f32);
    let mut moved = scene.camera;
    moved.eye += Vec3::new(0.6, 0.3, 0.0);
    let frame = |r: &mut Renderer, cam| {
        r.render(&gpu, &scene, &FrameCameras::fixed(cam), 0.0).unwrap();
    };
    let (mut a, mut b) = (
        renderer(&gpu, &scene, 2, AoSettings::default()),
        renderer(&gpu, &scene, 2, AoSettings::default()),
    );
    frame(&mut a, scene.camera);
    frame(&mut b, moved);
    let make = || {
        embedded(
            &gpu,
            &scene,
            1,
            AoSettings::default(),
            NormalEncoding::Octahedral,
            NormalSpace::World,
        )
    };
    let zpack_of = |ao: &mut EmbeddedAo, r: &Renderer, layer: u32| {
        let (depth, normal) = (r.target_texture("depth").unwrap(), r.target_texture("normal").unwrap());
        let inputs = AoInputs::new(
            TextureLayer { texture: depth, layer },
            TextureLayer { texture: normal, layer },
            scene.camera.view(),
            proj,
        );
        run(&gpu, ao, &inputs);
        ao.read_target("zpack").unwrap().data
    };
    let mut ao = make();
    let first = zpack_of(&mut ao, &a, 0);
    assert!(first == zpack_of(&mut make(), &a, 0), "the first frame");
    assert!(first == zpack_of(&mut ao, &a, 0), "the same textures again");
    let other = zpack_of(&mut ao, &b, 0);
    assert!(other != first, "the two G-buffers differ");
    assert!(other == zpack_of(&mut make(), &b, 0), "another texture");
    let deeper = zpack_of(&mut ao, &a, 1);
    assert!(deeper != first, "the layers differ");
    assert!(
        deeper == zpack_of(&mut make(), &a, 1),
        "another layer of the same texture"
    );
    assert!(first == zpack_of(&mut ao, &a, 0), "back to the first");
    frame(&mut a, moved);
    let redrawn = zpack_of(&mut ao, &a, 0);
    assert!(redrawn != first, "the moved camera sees other depths");
    assert!(
        redrawn == zpack_of(&mut make(), &a, 0),
        "new contents of the same texture"
    );
}
