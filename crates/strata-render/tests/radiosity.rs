//! Deep-G-buffer radiosity (DGB §3.2): the gather against a CPU evaluation of
//! Eq. 4–5 over the same buffers, and light that only the second layer sees.

mod common;

use common::frozen;
use glam::{Mat4, Vec3};
use strata_render::frame::FrameCameras;
use strata_render::passes::deep_gbuffer::{DeepGBufferSettings, Variant};
use strata_render::passes::radiosity::{irradiance_cpu, Normalisation, RadiositySettings};
use strata_render::passes::Kernel;
use strata_render::{GpuContext, RenderSettings, Renderer};
use strata_scene::shapes::MeshBuilder;
use strata_scene::{Camera, ImageBuf, Material, Object, Scene};

fn renderer(gpu: &GpuContext, scene: &Scene, w: u32, h: u32, layers: u32, rs: RadiositySettings) -> Renderer {
    Renderer::new(
        gpu,
        scene,
        RenderSettings {
            width: w,
            height: h,
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
    .unwrap_or_else(|e| panic!("{} k={layers}: {e}", scene.name))
}

/// One bounce on the GPU equals Eq. 4–5 evaluated on the CPU over the read-back
/// depth chain, normals and radiosity buffers with the same taps, for layer 0
/// and layer 1 receivers, with and without the n̂_Y test, and with the hidden taps'
/// visibility test (which must then change the light of some pixels); the last rows
/// run the gather as a compute pass (`indirect-kernel=compute`). Fragment and compute
/// gathers each agree with the CPU on ≥ 99.5 % of the pixels; they differ from each
/// other on a few more (atrium, default radius: 44 of 6,144), where a tap lands on a
/// rounding boundary (texel, MIP level) and the two pipelines round differently.
#[test]
fn gpu_gather_equals_cpu_eq4_eq5_over_the_same_buffers() {
    let gpu = common::gpu();
    // (scene, n̂_Y test, solid-angle weights, open sky, hidden taps black, cosine
    // normalisation): the paper's Eq. 4, the default weights and normaliser, and the two
    // non-paper tap rules (the atrium has a sky)
    use Normalisation::*;
    // (…, tap visibility steps, and whether it tests every tap or only the hidden ones;
    // the gather as a compute pass, `indirect-kernel=compute`)
    for (
        name,
        normal_test,
        solid_angle,
        open_sky,
        hidden_black,
        normalisation,
        (tap_visibility, tap_visibility_all),
        compute_gather,
    ) in [
        ("atrium", true, false, false, false, Hemisphere, (0, true), false),
        ("cornell", false, false, false, false, Hemisphere, (0, true), false),
        ("warehouse", true, false, false, false, Hemisphere, (0, true), false),
        ("atrium", true, true, false, false, Hemisphere, (0, true), false),
        ("cornell", false, true, false, false, Bounded, (0, true), false),
        ("warehouse", true, true, false, false, Bounded, (0, true), false),
        ("atrium", true, true, true, true, Cosine, (0, true), false),
        ("warehouse", true, false, true, true, Hemisphere, (0, true), false),
        ("warehouse", true, false, false, true, Cosine, (0, true), false),
        ("warehouse", true, true, false, false, Bounded, (8, false), false),
        ("warehouse", true, true, false, false, Bounded, (8, true), false),
        ("atrium", true, true, false, false, Bounded, (8, true), false),
        ("atrium", true, true, false, false, Bounded, (0, true), true),
        ("cornell", false, false, false, false, Hemisphere, (0, true), true),
        ("warehouse", true, true, false, false, Bounded, (8, true), true),
    ] {
        let scene = frozen(name);
        let (w, h) = (96, 64);
        let rs = RadiositySettings {
            normal_test,
            solid_angle,
            open_sky,
            hidden_black,
            normalisation,
            tap_visibility,
            tap_visibility_all,
            // Eq. 4's rows with the paper's fixed tap radii, the rest jittered
            radius_jitter: solid_angle,
            radius: Some(4.0),
            kernel: if compute_gather {
                Kernel::Compute
            } else {
                Kernel::Fragment
            },
            ..Default::default()
        };
        let mut r = renderer(&gpu, &scene, w, h, 2, rs);
        r.render(&gpu, &scene, &FrameCameras::fixed(scene.camera), 0.0)
            .expect("frame renders without validation errors");
        let buffers = common::GatherBuffers::read(&gpu, &r);
        let inputs = buffers.inputs(None);
        if tap_visibility > 0 {
            // the same buffers without the test: the test must matter somewhere
            let mut off = *inputs.uniforms;
            off.vis_steps = 0;
            let plain = strata_render::passes::radiosity::GatherInputs {
                uniforms: &off,
                ..buffers.inputs(None)
            };
            let changed = (0..h)
                .flat_map(|y| (0..w).map(move |x| (x, y)))
                .filter(|&(x, y)| {
                    let (a, b) = (irradiance_cpu(&inputs, 0, x, y).0, irradiance_cpu(&plain, 0, x, y).0);
                    (a - b).abs().max_element() > 0.01 * b.max_element() + 1e-4
                })
                .count();
            eprintln!("{name}: tap visibility changes {changed} pixels");
            assert!(
                changed >= 20,
                "{name}: the tap visibility test changed {changed} pixels"
            );
        }
        for (receiver, target) in [(0usize, "indirect-raw"), (1, "indirect1-raw")] {
            let gpu_e = r.read_target_full(&gpu, target, 0).unwrap();
            let (mut close, mut lit, mut worst) = (0usize, 0usize, 0.0f32);
            for y in 0..h {
                for x in 0..w {
                    let (e, conf) = irradiance_cpu(&inputs, receiver, x, y);
                    let g = gpu_e.pixel(x, y);
                    // Rgba16Float output: 2^-11 relative
                    let mut ok = (g[3] - conf).abs() < 1e-3;
                    for c in 0..3 {
                        let d = (g[c] - e[c]).abs();
                        worst = worst.max(d / (e[c].abs() + 1e-3));
                        ok &= d <= 2e-3 * e[c].abs() + 1e-4;
                    }
                    close += ok as usize;
                    lit += (e.max_element() > 1e-3) as usize;
                }
            }
            let n = (w * h) as usize;
            eprintln!("{name} (solid angle {solid_angle}, compute {compute_gather}) receiver {receiver}: {close}/{n} match, {lit} lit, worst rel {worst}");
            // every pixel on lavapipe, which answered textureDimensions with a level that
            // differs within a quad wrongly (`mip_size` in common/spiral.wgsl)
            assert!(
                close >= common::twin_pixels_required(&gpu, n),
                "{name} layer {receiver}: {close}/{n} match"
            );
            assert!(lit > n / 20, "{name} layer {receiver}: weak test, {lit} lit pixels");
        }
    }
}

/// The reduced-resolution gather (`gather-scale`, not in the paper), on the second
/// frame (seed 1, so `block_pixel` has moved on from frame 0's pixels): each
/// low-resolution texel equals Eq. 4–5 on the CPU at the pixel it shades, and the
/// full-resolution `indirect-raw` / `indirect1-raw` equal the CPU twin of the joint
/// bilateral upsampling of the read-back low-resolution gather, for both receivers,
/// at scales 2 and 3, as fragment and as compute passes.
#[test]
fn reduced_resolution_gather_and_upsampling_match_their_cpu_twins() {
    use strata_render::passes::upsample::upsample_cpu;
    let gpu = common::gpu();
    for (name, scale, kernel) in [
        ("atrium", 2u32, Kernel::Fragment),
        ("warehouse", 3, Kernel::Compute),
        ("cornell", 2, Kernel::Compute),
    ] {
        let scene = frozen(name);
        let (w, h) = (96u32, 64u32);
        let rs = RadiositySettings {
            gather_scale: scale,
            radius: Some(4.0),
            kernel,
            ..Default::default()
        };
        let mut r = renderer(&gpu, &scene, w, h, 2, rs);
        for _ in 0..2 {
            r.render(&gpu, &scene, &FrameCameras::fixed(scene.camera), 0.0)
                .expect("frame renders without validation errors");
        }
        let mut buffers = common::GatherBuffers::read(&gpu, &r);
        // with progressive bounces the gather reads this frame's B with last frame's E
        // reflected (§3.3), which also makes it gather for layer 1's receiver
        buffers.radiosity = ["bounce0", "bounce1"].map(|b| r.read_target_full(&gpu, b, 0).unwrap());
        let inputs = buffers.inputs(None);
        let up = r.upsample_uniforms().expect("an upsampling pass at scale > 1");
        assert_eq!((up.scale, up.seed), (scale, inputs.uniforms.seed));
        assert_eq!(up.seed, 1, "temporal noise: the second frame's seed");
        let n = (w * h) as usize;
        for (receiver, low_name, full_name) in [
            (0usize, "indirect-raw-low", "indirect-raw"),
            (1, "indirect1-raw-low", "indirect1-raw"),
        ] {
            let low = r.read_target_full(&gpu, low_name, 0).unwrap();
            assert_eq!((low.width, low.height), (w.div_ceil(scale), h.div_ceil(scale)));
            let (mut close, mut lit) = (0usize, 0usize);
            for ty in 0..low.height {
                for tx in 0..low.width {
                    let p = strata_render::spiral::block_pixel([tx, ty], scale, up.seed, [w, h]);
                    let (e, conf) = irradiance_cpu(&inputs, receiver, p[0], p[1]);
                    let g = low.pixel(tx, ty);
                    let mut ok = (g[3] - conf).abs() < 1e-3;
                    for c in 0..3 {
                        ok &= (g[c] - e[c]).abs() <= 2e-3 * e[c].abs() + 1e-4;
                    }
                    close += ok as usize;
                    lit += (e.max_element() > 1e-3) as usize;
                }
            }
            let m = (low.width * low.height) as usize;
            eprintln!("{name} s={scale} receiver {receiver}: gather {close}/{m} match, {lit} lit");
            assert!(
                close >= common::twin_pixels_required(&gpu, m),
                "{name} s={scale} layer {receiver}: {close}/{m}"
            );
            assert!(lit > m / 20, "{name} layer {receiver}: weak test, {lit} lit texels");

            let want = upsample_cpu(
                &low,
                &buffers.zmip[0],
                &buffers.normals[receiver],
                &buffers.frame,
                &up,
                receiver,
            );
            let got = r.read_target_full(&gpu, full_name, 0).unwrap();
            let (mut close, mut lit) = (0usize, 0usize);
            for y in 0..h {
                for x in 0..w {
                    let (a, b) = (got.pixel(x, y), want.pixel(x, y));
                    let ok = (0..4).all(|c| (a[c] - b[c]).abs() <= 2e-3 * b[c].abs() + 1e-4);
                    close += ok as usize;
                    lit += (b[..3].iter().any(|&v| v > 1e-3)) as usize;
                }
            }
            eprintln!("{name} s={scale} receiver {receiver}: upsampled {close}/{n} match, {lit} lit");
            assert!(
                close as f32 >= 0.995 * n as f32,
                "{name} s={scale} layer {receiver}: {close}/{n}"
            );
            assert!(lit > n / 20, "{name} layer {receiver}: weak test, {lit} lit pixels");
        }
    }
}

/// `gather-scale` outside 1..=4 is a one-line error naming the setting and its range.
#[test]
fn gather_scale_out_of_range_is_refused() {
    for scale in [0, 5] {
        let e = RadiositySettings {
            gather_scale: scale,
            ..Default::default()
        }
        .validate()
        .unwrap_err();
        assert_eq!(
            e,
            format!("radiosity gather-scale {scale} is out of range: must be in 1..=4")
        );
    }
    for scale in 1..=4 {
        let ok = RadiositySettings {
            gather_scale: scale,
            ..Default::default()
        };
        assert_eq!(ok.validate(), Ok(()), "scale {scale}");
    }
}

/// A scene of `parts` (one object and material each) with no light source, a black
/// sky and no ambient light (min separation 0.5 m): only emissive parts send light.
fn emitter_only_scene(name: &str, parts: Vec<(MeshBuilder, Material)>, camera: Camera) -> Scene {
    let (meshes, materials): (Vec<_>, Vec<_>) = parts
        .into_iter()
        .enumerate()
        .map(|(i, (mesh, material))| (mesh.build(&material.name, i), material))
        .unzip();
    let objects = materials
        .iter()
        .enumerate()
        .map(|(i, m)| Object {
            name: m.name.clone(),
            mesh: i,
            transform: Mat4::IDENTITY,
            animation: None,
        })
        .collect();
    Scene {
        name: name.into(),
        meshes,
        objects,
        materials,
        lights: vec![],
        camera,
        settings: common::unlit_settings(),
        ..Default::default()
    }
}

/// A floor, an emitter facing the camera and a larger board in front of it that
/// hides it: no light source, black sky. Only the deep G-buffer's layer 1 sees
/// the emitter, so only 2 layers light the floor.
fn hidden_emitter_scene() -> Scene {
    let v = Vec3::new;
    let mut floor = MeshBuilder::new();
    floor.rect(Vec3::ZERO, v(0.0, 0.0, 4.0), v(4.0, 0.0, 0.0));
    let mut emitter = MeshBuilder::new();
    emitter.quad_facing(
        [
            v(-0.5, 0.0, -1.0),
            v(0.5, 0.0, -1.0),
            v(0.5, 1.0, -1.0),
            v(-0.5, 1.0, -1.0),
        ],
        v(0.0, 0.0, 1.0),
    );
    let mut board = MeshBuilder::new();
    board.quad_facing(
        [v(-0.9, 0.0, 0.0), v(0.9, 0.0, 0.0), v(0.9, 1.6, 0.0), v(-0.9, 1.6, 0.0)],
        v(0.0, 0.0, 1.0),
    );
    emitter_only_scene(
        "hidden-emitter",
        vec![
            (floor, Material::diffuse("floor", [0.7, 0.7, 0.7])),
            (emitter, Material::emissive("emitter", [4.0, 3.0, 2.0])),
            (board, Material::diffuse("board", [0.5, 0.5, 0.5])),
        ],
        Camera::new(v(0.0, 1.2, 4.0), v(0.0, 0.4, -0.5), Vec3::Y, 50.0, 0.05),
    )
}

#[test]
fn light_seen_only_by_layer_1_reaches_the_floor_with_two_layers_only() {
    let gpu = common::gpu();
    let scene = hidden_emitter_scene();
    let (w, h) = (96, 64);
    let rs = RadiositySettings {
        radius: Some(3.0),
        temporal: None,
        ..Default::default()
    };
    let mut results = Vec::new();
    for layers in [1, 2] {
        let mut r = renderer(&gpu, &scene, w, h, layers, rs.clone());
        r.render(&gpu, &scene, &FrameCameras::fixed(scene.camera), 0.0).unwrap();
        let b0 = r.read_target(&gpu, "radiosity0").unwrap();
        assert!(
            b0.data.iter().all(|&v| v < 1e-3),
            "k={layers}: the emitter must be hidden from layer 0"
        );
        let e = r.read_target(&gpu, "indirect-raw").unwrap();
        let total: f32 = e.data.chunks_exact(4).map(|p| p[0] + p[1] + p[2]).sum();
        results.push(total / (w * h) as f32);
    }
    eprintln!("mean indirect E: k=1 {:.4}, k=2 {:.4}", results[0], results[1]);
    assert!(results[0] < 1e-4, "1 layer found light it cannot see: {}", results[0]);
    assert!(results[1] > 0.05, "2 layers did not light the floor: {}", results[1]);
}

/// A floor split by a thin wall (4 cm, below the 0.5 m min separation) standing along
/// x = 0, and an emitter beyond it (x > 0) that the camera, above the near side, sees over
/// the wall. No light source, black sky: on the first frame only the emitter sends light,
/// and the wall hides it from the whole near floor (every segment from there crosses x = 0
/// below the wall's top).
fn thin_wall_scene() -> Scene {
    let v = Vec3::new;
    let mut floor = MeshBuilder::new();
    floor.rect(Vec3::ZERO, v(2.5, 0.0, 0.0), v(0.0, 0.0, 2.5));
    let mut emitter = MeshBuilder::new();
    emitter.quad_facing(
        [
            v(0.3, 0.0, -1.5),
            v(1.8, 0.0, -1.5),
            v(1.8, 1.0, -1.5),
            v(0.3, 1.0, -1.5),
        ],
        v(0.0, 0.0, 1.0),
    );
    let mut wall = MeshBuilder::new();
    wall.cuboid(v(-0.02, 0.0, -2.5), v(0.02, 1.2, 2.5));
    emitter_only_scene(
        "thin-wall",
        vec![
            (floor, Material::diffuse("floor", [0.7, 0.7, 0.7])),
            (emitter, Material::emissive("emitter", [4.0, 3.0, 2.0])),
            (wall, Material::diffuse("wall", [0.5, 0.5, 0.5])),
        ],
        Camera::new(v(-1.6, 4.0, 3.5), v(0.3, 0.0, -0.6), Vec3::Y, 60.0, 0.05),
    )
}

/// Tap visibility of the visible senders (`tap_visibility_all`): behind a thin wall, which
/// no test point lands inside, the emitter the camera sees over the wall no longer lights
/// the near floor, which it cannot see; the floor beside the emitter keeps its light.
#[test]
fn tap_visibility_keeps_a_visible_emitters_light_behind_a_thin_wall() {
    let gpu = common::gpu();
    let scene = thin_wall_scene();
    let (w, h) = (128, 96);
    let mut near_far = Vec::new();
    for all in [false, true] {
        let rs = RadiositySettings {
            radius: Some(4.0),
            temporal: None,
            tap_visibility: 8,
            tap_visibility_all: all,
            ..Default::default()
        };
        let mut r = renderer(&gpu, &scene, w, h, 2, rs);
        r.render(&gpu, &scene, &FrameCameras::fixed(scene.camera), 0.0)
            .expect("frame renders without validation errors");
        let e = r.read_target(&gpu, "indirect-raw").unwrap();
        let (mut near, mut far) = ((0.0f64, 0usize), (0.0f64, 0usize));
        for s in common::surface_points(&gpu, &r) {
            if s.n.y < 0.99 || s.p.y > 0.01 {
                continue; // the floor only
            }
            let lum = e.data[s.i * 4..s.i * 4 + 3].iter().sum::<f32>() as f64;
            if s.p.x < -0.3 {
                near = (near.0 + lum, near.1 + 1);
            } else if s.p.x > 0.3 && s.p.z > -1.4 && s.p.z < 0.0 {
                far = (far.0 + lum, far.1 + 1);
            }
        }
        assert!(
            near.1 > 500 && far.1 > 100,
            "weak test: {} near, {} far floor pixels",
            near.1,
            far.1
        );
        near_far.push((near.0 / near.1 as f64, far.0 / far.1 as f64));
    }
    let [(near_hidden, far_hidden), (near_all, far_all)] = near_far[..] else {
        unreachable!()
    };
    eprintln!(
        "near floor E: hidden taps only {near_hidden:.4}, all {near_all:.4}; far floor {far_hidden:.4} / {far_all:.4}"
    );
    assert!(
        near_hidden > 0.05,
        "no light leaks through the wall to begin with: {near_hidden}"
    );
    assert!(
        near_all < 0.1 * near_hidden,
        "the wall still passes the emitter's light: {near_all} vs {near_hidden}"
    );
    assert!(
        far_all > 0.9 * far_hidden,
        "the emitter's own side lost light: {far_all} vs {far_hidden}"
    );
}

/// A closed grey box (albedo ρ) lit by a point light, seen from inside.
fn closed_box(rho: f32) -> Scene {
    let v = Vec3::new;
    let mut walls = MeshBuilder::new();
    walls.cuboid(v(-2.0, 0.0, -2.0), v(2.0, 3.0, 2.0));
    let materials = vec![Material::diffuse("walls", [rho; 3])];
    Scene {
        name: "closed-box".into(),
        meshes: vec![walls.build("walls", 0)],
        objects: vec![Object {
            name: "walls".into(),
            mesh: 0,
            transform: Mat4::IDENTITY,
            animation: None,
        }],
        materials,
        lights: vec![strata_scene::Light::Point {
            position: v(0.5, 2.5, 0.5),
            color: [1.0; 3],
            intensity: 10.0,
        }],
        camera: Camera::new(v(1.5, 1.5, 1.5), v(-2.0, 1.0, -2.0), Vec3::Y, 80.0, 0.05),
        settings: common::unlit_settings(),
        ..Default::default()
    }
}

/// The closed box with every wall emitting L = 1 and no light: E = πL exactly everywhere.
fn glowing_box() -> Scene {
    let mut glowing = closed_box(0.0);
    glowing.materials[0].emission = [1.0; 3];
    glowing.lights.clear();
    glowing
}

/// The paper's estimator (Eq. 4 weights, the same taps every frame: the bounce
/// operator is then one fixed linear map).
fn box_settings(delta: f32) -> RadiositySettings {
    RadiositySettings {
        solid_angle: false,
        normalisation: Normalisation::Hemisphere,
        temporal_noise: false,
        radius: Some(10.0),
        samples: 32,
        min_mip: 0,
        delta,
        boost: false,
        temporal: None,
        blur: strata_render::passes::bilateral::BilateralSettings {
            radius: 0,
            ..Default::default()
        },
        ..Default::default()
    }
}

/// Mean of channel 0 of `indirect` after each of `frames` static frames.
fn mean_indirect_per_frame(gpu: &GpuContext, scene: &Scene, rs: RadiositySettings, frames: u32) -> Vec<f64> {
    let (w, h) = (64, 64);
    let mut r = renderer(gpu, scene, w, h, 2, rs);
    let cams = FrameCameras::fixed(scene.camera);
    (0..frames)
        .map(|f| {
            r.render(gpu, scene, &cams, f as f32).unwrap();
            let e = r.read_target(gpu, "indirect").unwrap();
            e.data.chunks_exact(4).map(|p| p[0] as f64).sum::<f64>() / (w * h) as f64
        })
        .collect()
}

/// The progressive bounce (§3.3) reprojects with per-object velocities: the whole Cornell
/// box slides 6 cm towards the still camera between two frames. Each layer's bounce input
/// must equal direct + δ·ρ/π·E_{t−1} read where the point, moved back by its `motion`,
/// lands on last frame's layers (the CPU twin of reproject.wgsl), and the direct light
/// alone where it does not. With the camera's motion only, the walls facing the camera
/// lose their bounce for that frame.
#[test]
fn propagation_follows_moving_objects_with_their_motion() {
    use strata_render::passes::temporal::{bilinear_at, matching_layer, reproject};
    let gpu = common::gpu();
    let (scene, slide) = common::sliding_cornell(0.06);
    let cam = scene.camera;
    let (w, h) = (64, 64);
    let delta = 0.9;
    let still = FrameCameras::fixed(cam);
    let mut kept = Vec::new();
    for object_motion in [true, false] {
        let mut rs = box_settings(delta);
        rs.temporal = Some(strata_render::passes::temporal::TemporalSettings {
            object_motion,
            ..strata_render::passes::radiosity::indirect_temporal()
        });
        let mut r = renderer(&gpu, &scene, w, h, 2, rs);
        r.render(&gpu, &scene, &still, 0.0).unwrap();
        let e_prev = [
            r.read_target(&gpu, "indirect-history").unwrap(),
            r.read_target(&gpu, "indirect1-history").unwrap(),
        ];
        let csz0: Vec<ImageBuf> = (0..2).map(|j| r.read_target_layer(&gpu, "csz", j).unwrap()).collect();
        r.render(&gpu, &scene, &still, 1.0).unwrap();
        let f = r.frame_uniforms();
        let (mut covered, mut accepted, mut mismatched) = (0, 0, 0);
        for (layer, (direct, bounce)) in [("radiosity0", "bounce0"), ("radiosity1", "bounce1")]
            .into_iter()
            .enumerate()
        {
            let read = |name: &str| r.read_target_layer(&gpu, name, layer as u32).unwrap();
            let (csz, motion, albedo, normal) = (read("csz"), read("motion"), read("albedo"), read("normal"));
            let (direct, bounce) = (
                r.read_target(&gpu, direct).unwrap(),
                r.read_target(&gpu, bounce).unwrap(),
            );
            for y in 0..h {
                for x in 0..w {
                    let z = csz.pixel(x, y)[0];
                    if z <= 0.0 {
                        continue;
                    }
                    covered += 1;
                    let m = Vec3::from_slice(&motion.pixel(x, y)[..3]);
                    assert!((m - slide).length() < 1e-4, "layer {layer} ({x}, {y}): motion {m}");
                    let mut p = strata_render::passes::ao::world_from_csz(&f, [x as f32 + 0.5, y as f32 + 0.5], z);
                    if object_motion {
                        p -= m;
                    }
                    let rp = reproject(&f, p);
                    let rho = 1.0 - normal.pixel(x, y)[3];
                    for c in 0..3 {
                        let mut want = direct.pixel(x, y)[c];
                        if let Some(l) = matching_layer(&csz0, rp, 0.01) {
                            let e = bilinear_at(&e_prev[l], rp.unwrap().0, c);
                            want += delta * albedo.pixel(x, y)[c] * rho / std::f32::consts::PI * e;
                            accepted += (c == 0) as usize;
                        }
                        // bounce and direct are R11G11B10F: 6 mantissa bits
                        let got = bounce.pixel(x, y)[c];
                        mismatched += ((got - want).abs() > 0.02 * want.abs() + 1e-4) as usize;
                    }
                }
            }
        }
        eprintln!(
            "object motion {object_motion}: {accepted} of {covered} receivers kept their bounce, {mismatched} channels differ from the twin"
        );
        assert!(covered > 4000, "weak test: {covered} receivers");
        assert!(
            mismatched * 200 <= 3 * covered,
            "{mismatched} channels differ from the CPU twin"
        );
        kept.push(accepted as f32 / covered as f32);
    }
    assert!(kept[0] > 0.9, "with object motion only {} keep their bounce", kept[0]);
    assert!(
        kept[1] < kept[0] - 0.3,
        "the camera's motion alone keeps {} ({})",
        kept[1],
        kept[0]
    );
}

/// §3.3 progressive bounces with boost = 1 and δ = 1 in a closed box: each
/// frame adds one bounce. The bounce operator is linear, so the per-bounce
/// ratio must equal ρ · g, where g = E/(πL) is the gather's response to a
/// uniformly radiant enclosure (1 for an unbiased estimator; Eq. 4–5 count
/// only the M taps that pass Eq. 5, which over-weights steep directions, g > 1),
/// and the total must stay below the geometric-series bound S_1 / (1 − ρ g).
#[test]
fn multi_bounce_in_a_closed_box_converges_below_the_geometric_bound() {
    let gpu = common::gpu();
    let rho = 0.6;
    // g: every wall emits L = 1, no light, one bounce
    let glowing = glowing_box();
    let g = mean_indirect_per_frame(&gpu, &glowing, box_settings(0.0), 1)[0] / std::f64::consts::PI;
    let s = mean_indirect_per_frame(&gpu, &closed_box(rho), box_settings(1.0), 12);
    let d: Vec<f64> = s.windows(2).map(|p| p[1] - p[0]).collect();
    eprintln!("gather gain g = {g:.4}; mean E per frame: {s:?}");
    eprintln!("increments: {d:?}");
    assert!((0.8..1.6).contains(&g), "gather response to uniform radiance g = {g}");
    assert!(s[0] > 0.01, "no first bounce: {}", s[0]);
    assert!(d.iter().all(|&x| x > 0.0), "bounces decreased the total: {d:?}");
    let r = rho as f64 * g;
    let bound = s[0] / (1.0 - r);
    assert!(
        *s.last().unwrap() <= bound,
        "{} exceeds the geometric bound {bound}",
        s.last().unwrap()
    );
    for k in 3..8 {
        let ratio = d[k] / d[k - 1];
        assert!(
            (ratio - r).abs() < 0.08 * r,
            "bounce ratio {ratio} at {k}, expected ρ·g = {r}"
        );
    }
}

/// Mean and RMS deviation from the mean of channel 0 of `target` after `frames`
/// static frames (64×64).
fn indirect_mean_and_spread(
    gpu: &GpuContext,
    scene: &Scene,
    rs: RadiositySettings,
    frames: u32,
    target: &str,
) -> (f64, f64) {
    let (w, h) = (64, 64);
    let mut r = renderer(gpu, scene, w, h, 2, rs);
    let cams = FrameCameras::fixed(scene.camera);
    for f in 0..frames {
        r.render(gpu, scene, &cams, f as f32).unwrap();
    }
    let e = r.read_target(gpu, target).unwrap();
    let v: Vec<f64> = e.data.chunks_exact(4).map(|p| p[0] as f64).collect();
    let mean = v.iter().sum::<f64>() / v.len() as f64;
    let var = v.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / v.len() as f64;
    (mean, var.sqrt())
}

/// Issue 14, solid-angle weights: inside a closed box whose walls all emit
/// L = 1 the irradiance is exactly πL at every receiver. Eq. 4's equal tap
/// weights over-weight the steep directions (the screen-space spiral is not
/// uniform in solid angle): g = E/(πL) ≈ 1.2; weighting every tap by the solid
/// angle its screen area covers returns the analytic irradiance (within 5 %)
/// — one gather, no bounces, no filters.
#[test]
fn solid_angle_weights_return_the_analytic_irradiance_of_a_uniform_enclosure() {
    let gpu = common::gpu();
    let glowing = glowing_box();
    let pi = std::f64::consts::PI;
    let gain = |solid_angle: bool| {
        let rs = RadiositySettings {
            solid_angle,
            ..box_settings(0.0)
        };
        let (mean, spread) = indirect_mean_and_spread(&gpu, &glowing, rs, 1, "indirect-raw");
        (mean / pi, spread / pi)
    };
    let (g_paper, s_paper) = gain(false);
    let (g_solid, s_solid) = gain(true);
    eprintln!("E/(πL): Eq. 4 {g_paper:.4} (spread {s_paper:.4}), solid-angle {g_solid:.4} (spread {s_solid:.4})");
    assert!(g_paper > 1.1, "Eq. 4's known bias vanished: g = {g_paper}");
    assert!((g_solid - 1.0).abs() < 0.05, "solid-angle weights: E/(πL) = {g_solid}");
}

/// Cosine normalisation, E = π Σ w·B·cos / Σ w·cos, in the glowing box (every wall L = 1,
/// E = πL exactly): πL at every pixel for both tap weightings (Eq. 4's equal weights
/// over-estimate by > 10 %). The bounded form π / max(Σ w·cos, ½ Σ w), the default, is the
/// smaller of cosine and Eq. 4: no pixel above πL, a mean within 15 % below it, and on a
/// real scene never above Eq. 4's estimate from the same taps at any pixel.
#[test]
fn cosine_normalisation_returns_pi_l_in_a_uniform_enclosure_and_bounded_never_exceeds_eq4() {
    let gpu = common::gpu();
    let glowing = glowing_box();
    let pi = std::f32::consts::PI;
    let raw = |scene: &Scene, rs: RadiositySettings| {
        let mut r = renderer(&gpu, scene, 64, 64, 2, rs);
        r.render(&gpu, scene, &FrameCameras::fixed(scene.camera), 0.0).unwrap();
        r.read_target(&gpu, "indirect-raw").unwrap()
    };
    let lit = |img: &ImageBuf| {
        img.data
            .chunks_exact(4)
            .map(|p| p[0])
            .filter(|e| *e > 0.0)
            .collect::<Vec<f32>>()
    };
    let mean = |v: &[f32]| v.iter().map(|e| *e as f64).sum::<f64>() / v.len().max(1) as f64;
    for solid_angle in [false, true] {
        let settings = |normalisation| RadiositySettings {
            solid_angle,
            normalisation,
            ..box_settings(0.0)
        };
        let eq4 = lit(&raw(&glowing, settings(Normalisation::Hemisphere)));
        let cos = lit(&raw(&glowing, settings(Normalisation::Cosine)));
        let bounded = lit(&raw(&glowing, settings(Normalisation::Bounded)));
        let g = |v: &[f32]| mean(v) / pi as f64;
        let max = |v: &[f32]| v.iter().copied().fold(0.0f32, f32::max);
        let min = |v: &[f32]| v.iter().copied().fold(f32::MAX, f32::min);
        eprintln!(
            "solid angle {solid_angle}: E/(πL) Eq. 4 {:.4}, cosine {:.4} [{:.4}, {:.4}], bounded {:.4} (max {:.4})",
            g(&eq4),
            g(&cos),
            min(&cos) / pi,
            max(&cos) / pi,
            g(&bounded),
            max(&bounded) / pi
        );
        assert!(
            cos.len() > 3000 && bounded.len() == cos.len(),
            "weak test: {} lit",
            cos.len()
        );
        // Rgba16Float: 2^-11 relative
        assert!(
            cos.iter().all(|e| (e / pi - 1.0).abs() < 2e-3),
            "cosine normalisation not πL: [{}, {}]",
            min(&cos) / pi,
            max(&cos) / pi
        );
        assert!(max(&bounded) <= pi * 1.002, "bounded: a pixel above πL");
        assert!(
            (0.85..=1.002).contains(&g(&bounded)),
            "bounded: E/(πL) = {}",
            g(&bounded)
        );
        if !solid_angle {
            assert!(g(&eq4) > 1.1, "Eq. 4's known bias vanished: g = {}", g(&eq4));
        }
    }
    let scene = frozen("atrium");
    let rs = |normalisation| RadiositySettings {
        normalisation,
        radius: Some(4.0),
        ..Default::default()
    };
    let (eq4, bounded) = (
        raw(&scene, rs(Normalisation::Hemisphere)),
        raw(&scene, rs(Normalisation::Bounded)),
    );
    let (mut n_lit, mut lower) = (0usize, 0usize);
    for (a, b) in eq4.data.chunks_exact(4).zip(bounded.data.chunks_exact(4)) {
        for c in 0..3 {
            assert!(b[c] <= a[c] * 1.002 + 1e-5, "bounded {} above Eq. 4 {}", b[c], a[c]);
        }
        n_lit += (a[0] > 1e-3) as usize;
        lower += (b[0] < 0.95 * a[0]) as usize;
    }
    eprintln!("atrium: {lower} of {n_lit} lit pixels lowered by > 5 %");
    assert!(
        n_lit > 500 && lower > n_lit / 10,
        "weak test: {lower} of {n_lit} lowered"
    );
}

/// Issue 14, per-frame spiral rotation: with the paper's per-pixel hash a
/// static camera gathers the same taps every frame, so the temporal filter
/// cannot average the pattern's noise away (the blotches of issue 14). Hashing
/// the frame index in too makes the filtered irradiance of the glowing box (exactly
/// uniform) at least 1.5× smoother after 16 frames, at the same mean (±3 %).
#[test]
fn per_frame_rotation_lets_the_temporal_filter_remove_the_pattern_noise() {
    let gpu = common::gpu();
    let glowing = glowing_box();
    let run = |temporal_noise: bool| {
        let rs = RadiositySettings {
            temporal_noise,
            samples: 8,
            temporal: Some(Default::default()),
            ..box_settings(0.0)
        };
        indirect_mean_and_spread(&gpu, &glowing, rs, 16, "indirect")
    };
    let (m_fixed, s_fixed) = run(false);
    let (m_rot, s_rot) = run(true);
    eprintln!(
        "fixed pattern: mean {m_fixed:.4} spread {s_fixed:.4}; per-frame rotation: mean {m_rot:.4} spread {s_rot:.4}"
    );
    assert!(s_rot * 1.5 < s_fixed, "rotation did not smooth: {s_rot} vs {s_fixed}");
    assert!(
        (m_rot / m_fixed - 1.0).abs() < 0.03,
        "means differ: {m_rot} vs {m_fixed}"
    );
}

/// Table 2's "fraction of guard band shaded": outside it the gather leaves
/// E = 0 and confidence 0; inside (and in the whole image) it runs. Both as the
/// fragment pass (a scissor) and as its compute twin (`indirect-kernel=compute`, which
/// stores zero outside), at full resolution and as the reduced gather (`gather-scale=2`,
/// whose upsampling keeps the same rectangle).
#[test]
fn gather_shades_only_the_requested_fraction_of_the_guard_band() {
    let gpu = common::gpu();
    let scene = frozen("cornell");
    let (w, h, g) = (64, 64, 16);
    // the fragment pass (scissor) and its compute twin (`indirect-kernel=compute`: zero outside)
    for (compute_gather, gather_scale) in [(false, 1), (true, 1), (false, 2), (true, 2)] {
        let mut r = Renderer::new(
            &gpu,
            &scene,
            RenderSettings {
                width: w,
                height: h,
                guard_band: strata_render::renderer::GuardBand::Pixels(g),
                deep: DeepGBufferSettings {
                    layers: 2,
                    variant: Variant::Peel,
                    ..Default::default()
                },
                radiosity: Some(RadiositySettings {
                    guard_band_shaded: 0.5,
                    gather_scale,
                    kernel: if compute_gather {
                        Kernel::Compute
                    } else {
                        Kernel::Fragment
                    },
                    ..Default::default()
                }),
                ..Default::default()
            },
        )
        .unwrap();
        r.render(&gpu, &scene, &FrameCameras::fixed(scene.camera), 0.0).unwrap();
        let e = r.read_target_full(&gpu, "indirect-raw", 0).unwrap();
        let (fw, fh) = (w + 2 * g, h + 2 * g);
        let inset = g / 2;
        let (mut outside_nonzero, mut inside_conf) = (0, 0);
        for y in 0..fh {
            for x in 0..fw {
                let p = e.pixel(x, y);
                let inside = x >= inset && y >= inset && x < fw - inset && y < fh - inset;
                if inside {
                    inside_conf += (p[3] > 0.0) as u32;
                } else {
                    outside_nonzero += (p.iter().any(|&v| v != 0.0)) as u32;
                }
            }
        }
        assert_eq!(
            outside_nonzero, 0,
            "compute {compute_gather}, scale {gather_scale}: the unshaded guard band was written"
        );
        assert!(
            inside_conf > (w * h) / 2,
            "compute {compute_gather}, scale {gather_scale}: the shaded region has too few gathered pixels ({inside_conf})"
        );
    }
}

/// Confidence M/N lies in [0, 1]; inside a closed box (gather radius 1.5 m,
/// taps on screen) the taps that reach other walls count, on an open plane
/// under the sky every tap lies in the receiver's own plane and fails Eq. 5.
#[test]
fn confidence_is_high_inside_a_box_and_low_facing_open_sky() {
    let gpu = common::gpu();
    let mean_confidence = |scene: &Scene| {
        let rs = RadiositySettings {
            radius: Some(1.5),
            ..box_settings(0.0)
        };
        let mut r = renderer(&gpu, scene, 64, 64, 2, rs);
        r.render(&gpu, scene, &FrameCameras::fixed(scene.camera), 0.0).unwrap();
        let e = r.read_target(&gpu, "indirect-raw").unwrap();
        let csz = r.read_target(&gpu, "csz").unwrap();
        let c: Vec<f32> = e
            .data
            .chunks_exact(4)
            .zip(&csz.data)
            .filter(|(_, z)| **z > 0.0)
            .map(|(p, _)| p[3])
            .collect();
        assert!(c.iter().all(|v| (0.0..=1.0).contains(v)), "confidence outside [0, 1]");
        c.iter().sum::<f32>() / c.len() as f32
    };
    let inside = mean_confidence(&closed_box(0.5));
    let open = mean_confidence(&frozen("plane"));
    eprintln!("mean confidence: box {inside:.3}, open plane {open:.3}");
    // measured 0.142 vs 0.000: taps in the receiver's own wall fail Eq. 5 too,
    // so only taps reaching other walls count, even in a closed box
    assert!(inside > 0.1, "box interior confidence {inside}");
    assert!(open < 0.01, "open plane confidence {open}");
}

/// The indirect light's bilateral passes (`indirect-blur-h`, `-v`) equal `bilateral_cpu`
/// over the same buffers (red channel, RGBA16F targets), as fragment passes and as
/// their compute twins (`indirect-kernel=compute`, which also runs the gather as
/// compute).
#[test]
fn indirect_blur_matches_its_cpu_twin_in_both_kernels() {
    use strata_render::passes::bilateral::bilateral_cpu;
    let gpu = common::gpu();
    let scene = frozen("atrium");
    let (w, h) = (96u32, 64u32);
    for kernel in [Kernel::Fragment, Kernel::Compute] {
        let rs = RadiositySettings {
            temporal: None,
            kernel,
            ..Default::default()
        };
        let blur = rs.blur;
        let mut r = renderer(&gpu, &scene, w, h, 2, rs);
        r.render(&gpu, &scene, &FrameCameras::fixed(scene.camera), 0.0).unwrap();
        let read = |name: &str| r.read_target_full(&gpu, name, 0).unwrap();
        let (raw, gpu_h, gpu_v) = (read("indirect-raw"), read("indirect-blur-h"), read("indirect"));
        gpu.check_errors().unwrap();
        let zpack = read("zpack");
        let normals = common::npack_normals(&read("npack"), 0);
        let f = r.frame_uniforms();
        let twin = |src: &ImageBuf, vertical| bilateral_cpu(src, &zpack, &normals, &f, &blur, vertical, None);
        let n = (raw.width * raw.height) as usize;
        let near = |g: &ImageBuf, c: &ImageBuf| {
            (0..n)
                .filter(|&i| {
                    let (g, c) = (g.data[i * 4], c.data[i * c.channels as usize]);
                    (g - c).abs() <= 2e-3 + 2e-3 * c.abs()
                })
                .count()
        };
        let (close_h, close_v) = (near(&gpu_h, &twin(&raw, false)), near(&gpu_v, &twin(&gpu_h, true)));
        let changed = (0..n)
            .filter(|&i| (gpu_v.data[i * 4] - raw.data[i * 4]).abs() > 0.01)
            .count();
        eprintln!("{kernel:?}: GPU = twin {close_h}/{n} (h), {close_v}/{n} (v); {changed} pixels moved by > 0.01");
        assert!(close_h as f32 >= 0.995 * n as f32, "{kernel:?} h: {close_h}/{n}");
        assert!(close_v as f32 >= 0.995 * n as f32, "{kernel:?} v: {close_v}/{n}");
        assert!(
            changed >= n / 20,
            "{kernel:?}: weak test, the blur moved {changed} pixels"
        );
    }
}
