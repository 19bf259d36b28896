//! `strata_render::embed::EmbeddedBzbAo`: bounced-z-buffer AO on an application's G-buffer
//! and triangles. Its output is checked against the renderer's own `bzb-ao` of the same
//! frames, and against the analytic binary AO under a plate the camera never sees.

mod common;

#[path = "../examples/embed_ao/app.rs"]
mod app;

use glam::{Mat4, Vec3};
use strata_render::embed::{
    indexed_triangles, AoInputs, EmbeddedBzbAo, EmbeddedBzbAoConfig, NormalEncoding, NormalSpace, TextureLayer,
};
use strata_render::frame::FrameCameras;
use strata_render::passes::bzb::{self, BzbSettings, Splat};
use strata_render::{GpuContext, RenderSettings, Renderer};
use strata_scene::Scene;

const W: u32 = 160;
const H: u32 = 90;

/// The embedded bounced-z-buffer AO at `w`×`h` over `triangles`, world-space normals.
fn embedded(
    gpu: &GpuContext,
    [w, h]: [u32; 2],
    settings: BzbSettings,
    normals: NormalEncoding,
    triangles: &[[Vec3; 3]],
) -> EmbeddedBzbAo {
    EmbeddedBzbAo::new(
        &gpu.adapter,
        &gpu.device,
        &gpu.queue,
        EmbeddedBzbAoConfig {
            width: w,
            height: h,
            settings,
            normals,
            normal_space: NormalSpace::World,
        },
        triangles,
    )
    .expect("the embedded bzb AO builds without validation errors")
}

/// Records one embedded frame and submits it; validation errors fail the test.
fn run(gpu: &GpuContext, ao: &mut EmbeddedBzbAo, inputs: &AoInputs<'_>) {
    common::submit_checked(gpu, |encoder| ao.encode(encoder, inputs).expect("valid inputs"));
}

fn world_triangles(scene: &Scene) -> Vec<[Vec3; 3]> {
    scene.world_triangles(0.0).iter().map(|t| t.p).collect()
}

/// The renderer's G-buffer and the scene's own triangles in, the renderer's `bzb-ao` out:
/// the same passes on the same data, for AOV splats (one frame, and four with the temporal
/// filter) and for DSS surfels.
#[test]
fn embedded_bzb_ao_on_the_renderers_gbuffer_is_the_renderers() {
    let gpu = common::gpu();
    let scene = common::frozen("atrium");
    let cams = FrameCameras::fixed(scene.camera);
    let (view, proj) = (scene.camera.view(), scene.camera.projection(W as f32 / H as f32));
    let triangles = world_triangles(&scene);
    let radius = scene.settings.ao_radius;
    let base = BzbSettings {
        radius: Some(radius),
        ..BzbSettings::default()
    };
    let cases = [
        ("AOV splats", 1, base.clone()),
        (
            "AOV splats in a compute pass",
            1,
            BzbSettings {
                splat_kernel: common::kernel(true),
                ..base.clone()
            },
        ),
        (
            "AOV splats, temporal filter",
            4,
            BzbSettings {
                temporal: Some(bzb::temporal_filter()),
                ..base.clone()
            },
        ),
        (
            "DSS surfels",
            1,
            BzbSettings {
                splat: Splat::Dss,
                ..base.clone()
            },
        ),
    ];
    for (what, frames, settings) in cases {
        let mut r = Renderer::new(
            &gpu,
            &scene,
            RenderSettings {
                shade: false,
                bzb: Some(settings.clone()),
                ..common::peeled_layers(&scene, W, H, 1)
            },
        )
        .unwrap();
        let mut ao = embedded(&gpu, [W, H], settings, NormalEncoding::Octahedral, &triangles);
        assert_eq!(ao.triangle_count() as usize, triangles.len());
        for _ in 0..frames {
            r.render(&gpu, &scene, &cams, 0.0).unwrap();
            let (depth, normal) = (r.target_texture("depth").unwrap(), r.target_texture("normal").unwrap());
            let layer0 = |t| TextureLayer { texture: t, layer: 0 };
            run(&gpu, &mut ao, &AoInputs::new(layer0(depth), layer0(normal), view, proj));
        }
        let (a, b) = (ao.read_target("ao").unwrap(), r.read_target(&gpu, "ao").unwrap());
        let (mean, over) = common::channel0_diff(&a, &b, 1.0 / 255.0);
        println!(
            "{what}: mean |ΔAV| {mean:.2e}, {:.3} % of pixels over 1/255",
            100.0 * over
        );
        // a receiver's z differs from the renderer's by f32 rounding, which flips a
        // grazing ray's binary hit now and then
        assert!(mean < 1e-3 && over < 0.01, "{what}: mean {mean}, {over} over 1/255");
        let lo = b.data.iter().cloned().fold(1.0f32, f32::min);
        assert!(
            lo < 0.6,
            "{what}: the atrium has occlusion to compare (darkest AV {lo})"
        );
        common::check_pass_timings(&gpu, || ao.timings(), ao.pass_names(), what);
    }
}

/// What BZB exists for (§1, Fig. 1): an occluder the camera never sees still occludes.
/// The camera looks down at a floor from just under a large plate at height h; the plate
/// is above the frustum, so the G-buffer holds the floor alone. Binary AO within r of a
/// floor point under an infinite plane at height h < r is (h/r)² (the cosine-weighted
/// directions with cos θ > h/r hit it within r). The embedded AO reads the application's
/// G-buffer, drawn by `app.rs` (standard depth, signed normals), and the triangles given:
/// floor alone → AV 1; floor and plate → (h/r)²; the plate moved up in place → the new
/// (h/r)² once the history restarts; back to the floor alone (another count: a rebuild) → 1.
#[test]
fn an_occluder_off_screen_occludes_as_the_analytic_value() {
    use glam::camera::rh;
    let gpu = common::gpu();
    let (w, h) = (128u32, 96u32);
    let r = 0.5f32;
    let grey = Vec3::splat(0.5);
    let floor = app::cuboid(Vec3::new(-20.0, -0.1, -20.0), Vec3::new(20.0, 0.0, 20.0), grey);
    let plate = |y: f32| {
        world_of(&app::cuboid(
            Vec3::new(-20.0, y, -20.0),
            Vec3::new(20.0, y + 0.02, 20.0),
            grey,
        ))
    };
    let eye = Vec3::new(0.0, 0.22, 0.0);
    let view = rh::view::look_at_mat4(eye, Vec3::new(0.0, 0.0, -0.6), Vec3::Y);
    let proj = rh::proj::directx::perspective(40f32.to_radians(), w as f32 / h as f32, 0.01, 50.0);
    let layout = app::Layout::standard();
    let gbuffer = app::GBuffer::new(&gpu.device, [w, h], layout, &floor);
    let floor_only = world_of(&floor);
    let settings = BzbSettings {
        radius: Some(r),
        directions: 16,
        temporal: Some(bzb::temporal_filter()),
        ..BzbSettings::default()
    };
    let mut ao = embedded(&gpu, [w, h], settings.clone(), NormalEncoding::Signed, &floor_only);
    let mean_av = |ao: &mut EmbeddedBzbAo| {
        for _ in 0..8 {
            common::submit_checked(&gpu, |e| {
                gbuffer.draw(&gpu.queue, e, view, proj);
                ao.encode(e, &gbuffer.inputs(view, proj)).unwrap();
            });
        }
        let av = ao.read_target("ao").unwrap();
        let z = ao.read_target("csz").unwrap();
        // floor points, all far from the plate's edges (the plate spans ±20)
        let floor_px: Vec<f32> = (0..av.data.len())
            .filter(|i| z.data[*i] > 0.0)
            .map(|i| av.data[i])
            .collect();
        assert!(floor_px.len() > (w * h / 2) as usize, "the floor fills the view");
        floor_px.iter().sum::<f32>() / floor_px.len() as f32
    };
    let clear = mean_av(&mut ao);
    let mut with_plate = floor_only.clone();
    with_plate.extend(plate(0.3));
    ao.set_triangles(&with_plate).unwrap();
    let under_03 = mean_av(&mut ao);
    let mut moved = floor_only.clone();
    moved.extend(plate(0.4));
    // only the plate's range is written (set_triangles would write all, in place)
    ao.set_triangle_range(floor_only.len() as u32, &plate(0.4)).unwrap();
    // written in place, the temporal history stays (it follows receivers, not occluders):
    // a jump this large wants a fresh start
    ao.reset_history();
    let under_04 = mean_av(&mut ao);
    ao.set_triangles(&floor_only).unwrap();
    let cleared = mean_av(&mut ao);
    // the range write leaves exactly what an instance built with the moved plate has
    // (both run the same frames from their first)
    let mut ranged = embedded(&gpu, [w, h], settings.clone(), NormalEncoding::Signed, &with_plate);
    ranged.set_triangle_range(floor_only.len() as u32, &plate(0.4)).unwrap();
    let mut fresh = embedded(&gpu, [w, h], settings, NormalEncoding::Signed, &moved);
    let (ranged_av, fresh_av) = (mean_av(&mut ranged), mean_av(&mut fresh));
    let (a, b) = (ranged.read_target("ao").unwrap(), fresh.read_target("ao").unwrap());
    assert!(
        a.data == b.data,
        "the plate's range written in place gives the AV of a fresh build ({ranged_av} against {fresh_av})"
    );
    let expect = |h: f32| (h / r) * (h / r);
    println!(
        "floor alone {clear:.4}; plate at 0.3: {under_03:.4} (analytic {:.4}); at 0.4: {under_04:.4} ({:.4}); removed {cleared:.4}",
        expect(0.3),
        expect(0.4)
    );
    assert!(
        clear > 0.995 && cleared > 0.995,
        "an unoccluded floor is 1: {clear}, {cleared}"
    );
    assert!((under_03 - expect(0.3)).abs() < 0.03, "plate at 0.3: {under_03}");
    assert!((under_04 - expect(0.4)).abs() < 0.03, "plate at 0.4: {under_04}");
}

/// The app's triangles without their surfaces.
fn world_of(t: &[app::Triangle]) -> Vec<[Vec3; 3]> {
    t.iter().map(|t| t.0).collect()
}

/// Bad configs and triangles are one-line errors naming the parameter; nothing panics.
#[test]
fn bad_embedded_bzb_input_is_a_one_line_error() {
    let gpu = common::gpu();
    let quad = [[Vec3::ZERO, Vec3::X, Vec3::Y]];
    let config = |settings| EmbeddedBzbAoConfig {
        width: 64,
        height: 48,
        settings,
        ..EmbeddedBzbAoConfig::default()
    };
    let new = |c: EmbeddedBzbAoConfig, t: &[[Vec3; 3]]| EmbeddedBzbAo::new(&gpu.adapter, &gpu.device, &gpu.queue, c, t);
    let err = |r: Result<EmbeddedBzbAo, strata_render::RenderError>| match r {
        Ok(_) => panic!("accepted"),
        Err(e) => e.to_string(),
    };
    let r1 = || BzbSettings {
        radius: Some(1.0),
        ..BzbSettings::default()
    };
    let cases = [
        (
            err(new(config(BzbSettings::default()), &quad)),
            "settings.radius is required",
        ),
        (
            err(new(config(BzbSettings { directions: 0, ..r1() }), &quad)),
            "directions 0 is out of range",
        ),
        (
            err(new(
                EmbeddedBzbAoConfig {
                    width: 0,
                    ..config(r1())
                },
                &quad,
            )),
            "size 0x48 is out of range",
        ),
        (
            err(new(
                config(r1()),
                &[[Vec3::ZERO, Vec3::new(f32::NAN, 0.0, 0.0), Vec3::Y]],
            )),
            "triangles[0] has a non-finite vertex",
        ),
    ];
    for (e, want) in cases {
        println!("{e}");
        assert!(e.contains(want) && !e.contains('\n'), "'{e}' lacks '{want}'");
    }
    // set_triangles refuses bad triangles and keeps the old ones
    let mut ao = new(config(r1()), &quad).unwrap();
    let e = ao
        .set_triangles(&[[Vec3::ZERO, Vec3::X, Vec3::splat(f32::INFINITY)]])
        .unwrap_err();
    assert!(e.to_string().contains("triangles[0]"), "{e}");
    assert_eq!(ao.triangle_count(), 1);
    // a range must lie within the triangles, and names the bad triangle by its index
    let mut two = new(config(r1()), &[quad[0], quad[0]]).unwrap();
    for (first, tris, want) in [
        (
            1,
            vec![quad[0]; 2],
            "triangle range 1..3 is out of range: must lie within 0..2",
        ),
        (u32::MAX, vec![quad[0]], "is out of range: must lie within 0..2"),
        (
            1,
            vec![[Vec3::ZERO, Vec3::X, Vec3::splat(f32::NAN)]],
            "triangles[1] has a non-finite vertex",
        ),
    ] {
        let e = two.set_triangle_range(first, &tris).unwrap_err().to_string();
        println!("{e}");
        assert!(e.contains(want) && !e.contains('\n'), "'{e}' lacks '{want}'");
    }
    two.set_triangle_range(2, &[])
        .expect("an empty range at the end is nothing to write");
    assert_eq!(two.triangle_count(), 2);
    // a second layer is not read: an AoInputs with one is refused
    let e = common::second_layer_error(&gpu, [64, 48], |enc, inputs| ao.encode(enc, inputs));
    assert!(e.contains("AoInputs::second"), "{e}");
    // a refused resize keeps the instance as it was, triangles included
    let e = ao.resize(0, 48).unwrap_err().to_string();
    assert!(e.contains("size 0x48 is out of range"), "{e}");
    ao.resize(32, 24).unwrap();
    assert_eq!((ao.config().width, ao.triangle_count()), (32, 1));
    // indexed meshes: an index out of range names it
    let e = indexed_triangles(&[Vec3::ZERO, Vec3::X], &[0, 1, 2], Mat4::IDENTITY).unwrap_err();
    assert!(
        e.to_string().contains("index 2 is out of range: must be in 0..2"),
        "{e}"
    );
    let tris = indexed_triangles(
        &[Vec3::ZERO, Vec3::X, Vec3::Y],
        &[0, 1, 2],
        Mat4::from_translation(Vec3::Z),
    )
    .unwrap();
    assert_eq!(
        tris,
        vec![[Vec3::Z, Vec3::new(1.0, 0.0, 1.0), Vec3::new(0.0, 1.0, 1.0)]]
    );
    // the compute splats: a device without 64-bit atomics, and one whose storage buffers
    // cannot hold the keys (8 bytes for each of the 128 x 96 texels: 98,304 bytes)
    let compute = || BzbSettings {
        splat_kernel: common::kernel(true),
        ..r1()
    };
    let (plain, plain_queue) = pollster::block_on(gpu.adapter.request_device(&Default::default())).unwrap();
    let atomics = wgpu::Features::SHADER_INT64 | wgpu::Features::SHADER_INT64_ATOMIC_MIN_MAX;
    let small = wgpu::Limits {
        max_storage_buffer_binding_size: 65_536,
        ..wgpu::Limits::default()
    };
    let (narrow, narrow_queue) = pollster::block_on(gpu.adapter.request_device(&wgpu::DeviceDescriptor {
        required_features: atomics,
        required_limits: small,
        ..Default::default()
    }))
    .unwrap();
    for (device, queue, want) in [
        (&plain, &plain_queue, "splat-kernel=compute needs 64-bit atomics (SHADER_INT64_ATOMIC_MIN_MAX)"),
        (
            &narrow,
            &narrow_queue,
            "splat-kernel=compute: the keys of 12288 bounced-z-buffer texels (98304 bytes) exceed the adapter's largest storage buffer (65536 bytes)",
        ),
    ] {
        let e = err(EmbeddedBzbAo::new(&gpu.adapter, device, queue, config(compute()), &quad));
        println!("{e}");
        assert!(e.contains(want) && !e.contains('\n'), "'{e}' lacks '{want}'");
        // `auto` takes the rasteriser there
        EmbeddedBzbAo::new(&gpu.adapter, device, queue, config(r1()), &quad).expect("auto falls back to fragment");
    }
    gpu.check_errors().expect("no wgpu validation errors");
}

/// DSS surfels live in buffers of fixed capacity (BZB §4.3 streams them out; here atomic
/// appends). Triangles that fill them are reported as a one-line message naming the full
/// buffer, its capacity and the setting to change, never dropped in silence; once the
/// triangles fit again the message goes.
#[test]
fn dss_surfel_overflow_is_reported_and_clears() {
    use glam::camera::rh;
    let gpu = common::gpu();
    let (w, h) = (96u32, 64u32);
    let grey = Vec3::splat(0.5);
    let floor = app::cuboid(Vec3::new(-4.0, -0.1, -4.0), Vec3::new(4.0, 0.0, 4.0), grey);
    let floor_only = world_of(&floor);
    let eye = Vec3::new(0.0, 0.5, 1.0);
    let view = rh::view::look_at_mat4(eye, Vec3::new(0.0, 0.0, -1.0), Vec3::Y);
    let proj = rh::proj::directx::perspective(60f32.to_radians(), w as f32 / h as f32, 0.01, 50.0);
    let gbuffer = app::GBuffer::new(&gpu.device, [w, h], app::Layout::standard(), &floor);
    let settings = BzbSettings {
        radius: Some(0.3),
        directions: 1,
        splat: Splat::Dss,
        ..BzbSettings::default()
    };
    // large triangles under the floor, right below the eye: each is pre-tessellated into
    // the most sub-triangles (64²) of the most fine surfels (64); under the floor's
    // tangent plane they occlude nothing
    let sheet = |i: usize| {
        let y = -0.2 - 0.01 * i as f32;
        [
            Vec3::new(-50.0, y, -50.0),
            Vec3::new(50.0, y, -50.0),
            Vec3::new(0.0, y, 50.0),
        ]
    };
    let mut sheets = floor_only.clone();
    sheets.extend((0..20).map(sheet));
    let mut ao = embedded(&gpu, [w, h], settings, NormalEncoding::Signed, &floor_only);
    let frame = |ao: &mut EmbeddedBzbAo| {
        common::submit_checked(&gpu, |e| {
            gbuffer.draw(&gpu.queue, e, view, proj);
            ao.encode(e, &gbuffer.inputs(view, proj)).unwrap();
        });
        let c = ao.dss_counts().expect("DSS counts").unwrap();
        println!("{c:?}");
        (c, ao.dss_overflow().unwrap())
    };
    let (fits, none) = frame(&mut ao);
    assert!(
        fits.surfels > 0 && none.is_none(),
        "the floor alone fits: {fits:?}, {none:?}"
    );
    ao.set_triangles(&sheets).unwrap();
    let (full, message) = frame(&mut ao);
    let message = message.expect("the sheets overflow a surfel buffer");
    println!("{message}");
    assert!(
        message.starts_with("embedded bzb AO: dss surfelization overflowed (")
            && message.contains("sub-triangles for a buffer of 65536")
            && message.contains("surfel-size (0.5..=16 px)")
            && !message.contains('\n'),
        "{message}"
    );
    assert!(full.subtriangles > 65536, "{full:?}");
    ao.set_triangles(&floor_only).unwrap();
    let (again, none) = frame(&mut ao);
    assert!(
        none.is_none() && again == fits,
        "the floor alone fits again: {again:?}, {none:?}"
    );
}
