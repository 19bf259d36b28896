//! Deep G-buffer construction (DGB §2): every variant against the two-pass
//! peel, the peel against the CPU oracle, the minimum-separation invariant,
//! behaviour under camera motion, the Table 1 packing and the guard band.

mod common;

use strata_reference::{LayerSettings, Reference};
use strata_render::frame::FrameCameras;
use strata_render::passes::deep_gbuffer::{DeepGBufferSettings, LayerComparison, Variant};
use strata_render::renderer::GuardBand;
use strata_render::{GpuContext, RenderSettings, Renderer};
use strata_scene::{procedural, Scene};

fn renderer(gpu: &GpuContext, scene: &Scene, w: u32, h: u32, layers: u32, variant: Variant, dz: f32) -> Renderer {
    Renderer::new(
        gpu,
        scene,
        RenderSettings {
            width: w,
            height: h,
            deep: DeepGBufferSettings {
                layers,
                variant,
                min_separation: Some(dz),
                ..Default::default()
            },
            shade: false,
            ..Default::default()
        },
    )
    .unwrap_or_else(|e| panic!("{variant} k={layers}: {e}"))
}

/// Renders a static camera k times (a single-pass variant's layer j tests
/// against last frame's layer j − 1, so layer j settles on frame j + 1) and
/// returns the camera-space depth of every layer.
fn static_layers(gpu: &GpuContext, scene: &Scene, w: u32, h: u32, k: u32, v: Variant, dz: f32) -> Vec<Vec<f32>> {
    let mut r = renderer(gpu, scene, w, h, k, v, dz);
    let cams = FrameCameras::fixed(scene.camera);
    for _ in 0..k.max(2) {
        r.render(gpu, scene, &cams, 0.0)
            .expect("frame renders without validation errors");
    }
    (0..k)
        .map(|j| r.read_target_layer(gpu, "csz", j).unwrap().data)
        .collect()
}

fn static_scenes() -> Vec<Scene> {
    let mut atrium = procedural::builtin("atrium").unwrap();
    // Freeze the animated banner and the camera path: a static frame.
    atrium.camera_path = None;
    for o in &mut atrium.objects {
        o.animation = None;
    }
    vec![procedural::builtin("cornell").unwrap(), atrium]
}

#[test]
fn static_camera_every_variant_equals_the_peel_bit_for_bit() {
    let gpu = common::gpu();
    for scene in static_scenes() {
        let dz = scene.settings.min_separation;
        for k in 2..=4u32 {
            let peel = static_layers(&gpu, &scene, 96, 64, k, Variant::Peel, dz);
            let covered1 = peel[1].iter().filter(|&&z| z > 0.0).count();
            assert!(
                covered1 > 200,
                "{} k={k}: layer 1 nearly empty ({covered1} px)",
                scene.name
            );
            for v in Variant::ALL.into_iter().filter(|v| *v != Variant::Peel) {
                if v.has_predicted_view() && k > 2 {
                    continue;
                }
                let got = static_layers(&gpu, &scene, 96, 64, k, v, dz);
                for j in 1..k as usize {
                    let differ = got[j]
                        .iter()
                        .zip(&peel[j])
                        .filter(|(a, b)| a.to_bits() != b.to_bits())
                        .count();
                    assert_eq!(
                        differ, 0,
                        "{} k={k} {v}: layer {j} differs from the peel at {differ} px",
                        scene.name
                    );
                }
            }
        }
    }
}

/// z_j > z_{j−1} + Δz wherever layer j has a surface, and layer j is empty
/// where layer j − 1 is.
fn assert_min_separation(layers: &[Vec<f32>], dz: f32, what: &str) {
    for j in 1..layers.len() {
        for (i, (&z1, &z0)) in layers[j].iter().zip(&layers[j - 1]).enumerate() {
            if z1 > 0.0 {
                assert!(z0 > 0.0, "{what}: pixel {i} has layer {j} but no layer {}", j - 1);
                assert!(
                    z1 > z0 + dz * (1.0 - 1e-6),
                    "{what}: pixel {i}: z{j} = {z1} <= z{} + Δz = {}",
                    j - 1,
                    z0 + dz
                );
            }
        }
    }
}

#[test]
fn min_separation_holds_for_every_variant_and_k() {
    let gpu = common::gpu();
    for scene in static_scenes() {
        for dz in [0.0, scene.settings.min_separation] {
            for k in 2..=4u32 {
                for v in Variant::ALL {
                    if v.has_predicted_view() && k > 2 {
                        continue;
                    }
                    let layers = static_layers(&gpu, &scene, 64, 48, k, v, dz);
                    assert_min_separation(&layers, dz, &format!("{} k={k} {v} Δz={dz}", scene.name));
                }
            }
        }
    }
}

/// Share of pixels where the GPU layer `j` and the CPU oracle agree (both empty,
/// or depths within 1e-3 relative).
fn agreement_with_oracle(scene: &Scene, w: u32, h: u32, dz: f32, j: usize) -> f64 {
    let gpu = common::gpu();
    let gpu_layers = static_layers(&gpu, scene, w, h, (j + 1) as u32, Variant::Peel, dz);
    let oracle = Reference::new(scene, 0.0).with_progress(false).layers(
        &scene.camera,
        w,
        h,
        // the construction's tie rule: surfaces within δ·z are one surface
        &LayerSettings {
            depth_tolerance: strata_render::passes::deep_gbuffer::SURFACE_TOLERANCE,
            ..LayerSettings::new(j + 1, dz)
        },
    );
    let zr = &oracle.layers[j].depth.data;
    let zg = &gpu_layers[j];
    let mut agree = 0;
    let mut covered = 0;
    let mut misses = Vec::new();
    for (i, (a, b)) in zg.iter().zip(zr).enumerate() {
        covered += (*a > 0.0 || b.is_finite()) as usize;
        let ok = if *a <= 0.0 || !b.is_finite() {
            *a <= 0.0 && !b.is_finite()
        } else {
            (a - b).abs() <= 1e-3 * b
        };
        agree += ok as usize;
        if !ok && misses.len() < 4 {
            let oracle_z: Vec<f32> = oracle.layers.iter().map(|l| l.depth.data[i]).collect();
            misses.push(((i as u32 % w, i as u32 / w), *a, oracle_z));
        }
    }
    assert!(
        covered > (w * h / 20) as usize,
        "{}: layer {j} almost empty",
        scene.name
    );
    let frac = agree as f64 / (w * h) as f64;
    eprintln!(
        "{} layer {j} Δz={dz}: {:.3}% agree with the CPU oracle (first misses: pixel, GPU z, oracle layers {misses:?})",
        scene.name,
        100.0 * frac
    );
    frac
}

#[test]
fn peel_second_layer_matches_cpu_oracle() {
    for scene in static_scenes() {
        let dz = scene.settings.min_separation;
        assert!(agreement_with_oracle(&scene, 128, 96, dz, 1) >= 0.99, "{}", scene.name);
    }
}

#[test]
fn zero_separation_is_classic_depth_peeling() {
    // Δz = 0: layer 1 is the second-nearest surface along each pixel's ray.
    for scene in static_scenes() {
        assert!(agreement_with_oracle(&scene, 128, 96, 0.0, 1) >= 0.99, "{}", scene.name);
    }
    // Third layer too (k = 3). Before the construction shared the oracle's tie
    // rule, layer 2 re-captured layer 1's floor wherever the peel interpolated
    // its depth beyond the stored one: 98.9 % on lavapipe, 97.4 % on NVIDIA 580.
    let cornell = procedural::builtin("cornell").unwrap();
    assert!(agreement_with_oracle(&cornell, 96, 96, 0.0, 2) >= 0.995);
}

/// Mismatch percentage of `v`'s layer 1 against the peel of the same frame, per
/// frame of the atrium camera path (frames 1..=n; frame 0 primes the history).
fn path_mismatch(v: Variant, n: u32) -> Vec<f64> {
    let gpu = common::gpu();
    let scene = procedural::builtin("atrium").unwrap();
    let (w, h) = (128, 72);
    let dz = scene.settings.min_separation;
    let mut peel = renderer(&gpu, &scene, w, h, 2, Variant::Peel, dz);
    let mut r = renderer(&gpu, &scene, w, h, 2, v, dz);
    let mut out = Vec::new();
    for f in 0..=n {
        let f = f as f32;
        let cams = FrameCameras::along_path(&scene, f);
        peel.render(&gpu, &scene, &cams, f).unwrap();
        r.render(&gpu, &scene, &cams, f).unwrap();
        if f == 0.0 {
            continue;
        }
        let a = r.read_target_layer(&gpu, "csz", 1).unwrap();
        let b = peel.read_target_layer(&gpu, "csz", 1).unwrap();
        out.push(LayerComparison::new(&a.data, &b.data).percent());
    }
    out
}

#[test]
fn moving_camera_delay_is_exact_and_reproject_beats_previous() {
    let gpu = common::gpu();
    let scene = procedural::builtin("atrium").unwrap();
    let (w, h) = (128, 72);
    let dz = scene.settings.min_separation;
    let mut peel = renderer(&gpu, &scene, w, h, 2, Variant::Peel, dz);
    let mut delay = renderer(&gpu, &scene, w, h, 2, Variant::Delay, dz);
    for f in 0..6 {
        let f = f as f32;
        let cams = FrameCameras::along_path(&scene, f);
        peel.render(&gpu, &scene, &cams, f).unwrap();
        delay.render(&gpu, &scene, &cams, f).unwrap();
        if f >= 1.0 {
            let a = delay.read_target_layer(&gpu, "csz", 1).unwrap();
            let b = peel.read_target_layer(&gpu, "csz", 1).unwrap();
            let c = LayerComparison::new(&a.data, &b.data);
            assert_eq!(
                c.mismatched, 0,
                "frame {f}: Delay differs from the peel at {} px",
                c.mismatched
            );
        }
    }
    let previous: f64 = path_mismatch(Variant::Previous, 4).iter().sum();
    let reproject: f64 = path_mismatch(Variant::Reproject, 4).iter().sum();
    eprintln!("atrium path mismatch (sum over 4 frames): previous {previous:.2}%, reproject {reproject:.2}%");
    assert!(
        previous > 0.5,
        "the camera path should move enough for Previous to err ({previous:.3}%)"
    );
    assert!(
        reproject < previous,
        "reproject {reproject:.3}% vs previous {previous:.3}%"
    );
}

#[test]
fn packed_layout_holds_both_layers() {
    let gpu = common::gpu();
    let scene = procedural::builtin("cornell").unwrap();
    for k in [2u32, 4] {
        let mut r = renderer(&gpu, &scene, 48, 40, k, Variant::Peel, 0.0);
        r.render(&gpu, &scene, &FrameCameras::fixed(scene.camera), 0.0).unwrap();
        for (pack_z, pack_n, first) in [("zpack", "npack", 0u32), ("zpack23", "npack23", 2)] {
            if first >= k {
                continue;
            }
            let zp = r.read_target(&gpu, pack_z).unwrap();
            let np = r.read_target(&gpu, pack_n).unwrap();
            for j in 0..2 {
                let z = r.read_target_layer(&gpu, "csz", first + j).unwrap();
                let n = r.read_target_layer(&gpu, "normal", first + j).unwrap();
                for i in 0..z.data.len() {
                    assert_eq!(
                        zp.data[2 * i + j as usize].to_bits(),
                        z.data[i].to_bits(),
                        "{pack_z} layer {j}"
                    );
                    for c in 0..2 {
                        assert_eq!(
                            np.data[4 * i + 2 * j as usize + c],
                            n.data[4 * i + c],
                            "{pack_n} layer {j}"
                        );
                    }
                }
            }
        }
    }
}

#[test]
fn radiosity_target_is_r11g11b10_direct_light() {
    let gpu = common::gpu();
    let scene = procedural::builtin("cornell").unwrap();
    let r = common::render(&gpu, &scene, &scene.camera, 64, 64);
    assert_eq!(
        r.targets.get("radiosity0").desc.format,
        wgpu::TextureFormat::Rg11b10Ufloat,
        "DGB Table 1 stores radiosity as R11G11B10F"
    );
    let b = r.read_target(&gpu, "radiosity0").unwrap();
    let d = r.read_target(&gpu, "direct-diffuse").unwrap();
    let e = r.read_target(&gpu, "emission").unwrap();
    // Cornell's emitter is also a Rect light, whose direct term already
    // carries its light: its emission stays out of B (no double counting).
    let emission_in_b = !scene
        .lights
        .iter()
        .any(|l| matches!(l, strata_scene::Light::Rect { .. }));
    assert!(
        !emission_in_b && e.data.iter().any(|&v| v > 1.0),
        "test needs the emitter in view"
    );
    let mut lit = 0;
    for i in 0..(64 * 64) {
        for c in 0..3 {
            let want = d.data[4 * i + c] + e.data[4 * i + c] * emission_in_b as u32 as f32;
            let got = b.data[3 * i + c];
            // 5-bit mantissa (blue) → ≤ 2^-5 relative; plus half-float inputs.
            assert!(
                (got - want).abs() <= want * 0.04 + 1e-3,
                "pixel {i} ch {c}: {got} vs {want}"
            );
            lit += (want > 0.01) as usize;
        }
    }
    assert!(lit > 1000, "the Cornell box should be lit ({lit} channels)");
}

#[test]
fn guard_band_crops_to_the_same_image() {
    let gpu = common::gpu();
    let scene = static_scenes().remove(1);
    let (w, h) = (96, 64);
    let plain = static_layers(&gpu, &scene, w, h, 2, Variant::Reproject, 0.5);
    let mut r = Renderer::new(
        &gpu,
        &scene,
        RenderSettings {
            width: w,
            height: h,
            deep: DeepGBufferSettings {
                layers: 2,
                variant: Variant::Reproject,
                min_separation: Some(0.5),
                ..Default::default()
            },
            guard_band: GuardBand::Pixels(12),
            shade: false,
            ..Default::default()
        },
    )
    .unwrap();
    assert_eq!((r.targets.width, r.targets.height), (w + 24, h + 24));
    let cams = FrameCameras::fixed(scene.camera);
    r.render(&gpu, &scene, &cams, 0.0).unwrap();
    r.render(&gpu, &scene, &cams, 0.0).unwrap();
    for j in 0..2 {
        let z = r.read_target_layer(&gpu, "csz", j).unwrap();
        assert_eq!((z.width, z.height), (w, h));
        let c = LayerComparison::new(&z.data, &plain[j as usize]);
        assert!(
            c.percent() < 0.5,
            "layer {j}: {:.3}% of pixels differ with the guard band",
            c.percent()
        );
        assert!(c.counted > 1000);
    }
}

#[test]
fn invalid_settings_are_errors_naming_the_parameter() {
    let gpu = common::gpu();
    let scene = procedural::builtin("plane").unwrap();
    let try_new = |deep: DeepGBufferSettings, guard_band| {
        Renderer::new(
            &gpu,
            &scene,
            RenderSettings {
                width: 32,
                height: 32,
                deep,
                guard_band,
                ..Default::default()
            },
        )
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default()
    };
    let d = DeepGBufferSettings::default();
    assert!(try_new(DeepGBufferSettings { layers: 0, ..d }, GuardBand::default()).contains("layers 0"));
    assert!(try_new(DeepGBufferSettings { layers: 5, ..d }, GuardBand::default()).contains("1..=4"));
    let e = try_new(
        DeepGBufferSettings {
            layers: 3,
            variant: Variant::Delay,
            ..d
        },
        GuardBand::default(),
    );
    assert!(e.contains("delay"), "{e}");
    let e = try_new(
        DeepGBufferSettings {
            min_separation: Some(-1.0),
            ..d
        },
        GuardBand::default(),
    );
    assert!(e.contains("min-separation"), "{e}");
    for scale in [0, 5] {
        let e = try_new(
            DeepGBufferSettings {
                layer_scale: scale,
                ..d
            },
            GuardBand::default(),
        );
        assert!(
            e.contains(&format!("layer-scale {scale}")) && e.contains("1..=4"),
            "{e}"
        );
    }
    let e = try_new(
        DeepGBufferSettings {
            layer_scale: 2,
            submission: strata_render::passes::deep_gbuffer::Submission::Multiview,
            ..d
        },
        GuardBand::default(),
    );
    assert!(e.contains("layer-scale 2") && e.contains("multiview"), "{e}");
    let e = try_new(d, GuardBand::Pixels(9000));
    assert!(e.contains("guard band 9000 px") && e.contains("at most 4092"), "{e}");
    assert!(!e.contains('\n'), "{e}");
    // the largest size with the default guard band: the error says what fits
    let e = RenderSettings {
        width: 8192,
        height: 8,
        guard_band: GuardBand::Pixels(1),
        ..Default::default()
    }
    .validate()
    .unwrap_err()
    .to_string();
    assert!(e.contains("8194x10") && e.contains("8..=8190"), "{e}");
    assert!("12%".parse::<GuardBand>().unwrap() == GuardBand::Fraction(0.12));
    assert!("abc".parse::<GuardBand>().is_err());
    assert!("nope".parse::<Variant>().unwrap_err().contains("reproject"));
}

/// DGB §3.2: layer 1's initial radiosity B is its direct light + emission. With
/// an (unshadowed) point light, removing the column that hides part of the wall
/// must show that wall part in layer 0 with the same B (Δz = 0.7 m > the
/// column's 0.6 m diameter, so layer 1 behind the column is the wall or floor).
#[test]
fn layer1_radiosity_equals_the_same_surface_seen_directly() {
    let gpu = common::gpu();
    let mut scene = procedural::builtin("column-wall").unwrap();
    scene.lights = vec![strata_scene::model::Light::Point {
        position: glam::Vec3::new(0.5, 3.0, 1.0),
        color: [1.0, 0.9, 0.8],
        intensity: 8.0,
    }];
    let (w, h) = (96, 64);
    let render = |scene: &Scene, layers: u32| {
        let mut r = Renderer::new(
            &gpu,
            scene,
            RenderSettings {
                width: w,
                height: h,
                deep: DeepGBufferSettings {
                    layers,
                    variant: Variant::Peel,
                    min_separation: Some(0.7),
                    ..Default::default()
                },
                // unshadowed point light: B of the hidden wall must not depend on the column
                shadow: strata_render::passes::shadow::ShadowSettings {
                    point_lights: 0,
                    ..Default::default()
                },
                ..Default::default()
            },
        )
        .unwrap();
        r.render(&gpu, scene, &FrameCameras::fixed(scene.camera), 0.0).unwrap();
        r
    };
    let deep = render(&scene, 2);
    let b1 = deep.read_target(&gpu, "radiosity1").unwrap();
    let z1 = deep.read_target_layer(&gpu, "csz", 1).unwrap();
    let mut without = scene.clone();
    without.objects.retain(|o| o.name != "column");
    assert!(without.objects.len() < scene.objects.len(), "column object not found");
    let flat = render(&without, 1);
    let b0 = flat.read_target(&gpu, "radiosity0").unwrap();
    let z0 = flat.read_target(&gpu, "csz").unwrap();
    let deep_z0 = deep.read_target(&gpu, "csz").unwrap();
    let (n1, n0) = (
        deep.read_normals_layer(&gpu, 1).unwrap(),
        flat.read_normals(&gpu).unwrap(),
    );
    let (a1, a0) = (
        deep.read_target_layer(&gpu, "albedo", 1).unwrap(),
        flat.read_target(&gpu, "albedo").unwrap(),
    );
    let mut compared = 0;
    for i in 0..(w * h) as usize {
        // pixels where the column was in front and the wall/floor is layer 1
        let hidden = (deep_z0.data[i] - z0.data[i]).abs() > 0.1;
        let same_normal = (0..3).map(|c| n1.data[3 * i + c] * n0.data[3 * i + c]).sum::<f32>() > 0.99;
        let same_albedo = (0..3).all(|c| a1.data[4 * i + c] == a0.data[4 * i + c]);
        // same surface: same depth, normal and albedo (the column's back face
        // and its bottom cap, coplanar with the floor, meet the floor at its base)
        let same_depth = (z1.data[i] - z0.data[i]).abs() < 1e-4 * z0.data[i];
        if !(hidden && z1.data[i] > 0.0 && same_depth && same_normal && same_albedo) {
            continue;
        }
        compared += 1;
        for c in 0..3 {
            let (a, b) = (b1.data[3 * i + c], b0.data[3 * i + c]);
            assert!(
                (a - b).abs() <= 0.02 * b + 1e-4,
                "pixel {i} ch {c}: layer-1 B {a} vs direct B {b}"
            );
        }
    }
    assert!(compared > 100, "only {compared} hidden pixels compared");
}

/// Textures are filtered anisotropically: a floor seen at a grazing angle keeps the
/// stripes that run towards the horizon. The floor's texture varies across the view
/// only (stripes along world z, 1.25 m apart); an isotropic trilinear filter picks
/// its MIP by the footprint's long (depth) axis and blurs them to grey. Truth: the CPU
/// average of the nearest texel over 8×8 points of each pixel (the footprint, as the
/// path tracer's many samples per pixel average it). In every floor row beyond 4 m the
/// G-buffer albedo's spread along the row must reach 85 % of the truth's.
#[test]
fn grazing_floor_texture_keeps_its_detail() {
    use glam::Vec3;
    let gpu = common::gpu();
    let mut scene = procedural::builtin("plane").unwrap();
    // v runs along world x over the 40 m floor (`rect`'s corners (0,0), (1,0), (0,1)
    // at (−20, −20), (−20, 20), (20, −20) in x, z): 32 stripes of 8 texel rows
    let (tw, th) = (4u32, 512u32);
    let mut rgba8 = Vec::new();
    for y in 0..th {
        for _ in 0..tw {
            let c = if (y / 8) % 2 == 0 { 230 } else { 25 };
            rgba8.extend([c, c, c, 255]);
        }
    }
    scene.textures.push(strata_scene::Texture {
        name: "stripes".into(),
        width: tw,
        height: th,
        rgba8,
    });
    scene.materials[0].base_color = [1.0, 1.0, 1.0];
    scene.materials[0].base_color_texture = Some(scene.textures.len() - 1);
    let camera = strata_scene::Camera::new(
        Vec3::new(0.0, 0.6, 8.0),
        Vec3::new(0.0, 0.0, -12.0),
        Vec3::Y,
        45.0,
        0.05,
    );
    let (w, h) = (256u32, 128u32);
    let r = common::render(&gpu, &scene, &camera, w, h);
    let albedo = r.read_target(&gpu, "albedo").unwrap();
    let tex = &scene.textures[0];
    let spread = |v: &[f32]| {
        let m = v.iter().sum::<f32>() / v.len() as f32;
        (v.iter().map(|x| (x - m) * (x - m)).sum::<f32>() / v.len() as f32).sqrt()
    };
    let (mut gpu_sum, mut truth_sum, mut rows, mut worst) = (0.0f32, 0.0f32, 0, f32::INFINITY);
    for y in 0..h {
        let (mut g, mut t) = (Vec::new(), Vec::new());
        for x in 0..w {
            // the footprint's mean albedo; a pixel that is not all floor is skipped
            let mut sum = 0.0;
            let mut all_floor = true;
            let mut far = true;
            for sy in 0..8 {
                for sx in 0..8 {
                    let d = camera.pixel_dir_f(
                        x as f32 + (sx as f32 + 0.5) / 8.0,
                        y as f32 + (sy as f32 + 0.5) / 8.0,
                        w,
                        h,
                    );
                    let s = -camera.eye.y / d.y;
                    let p = camera.eye + d * s;
                    if d.y >= 0.0 || d.y.is_nan() || p.x.abs() >= 20.0 || p.z.abs() >= 20.0 {
                        all_floor = false;
                        break;
                    }
                    far &= camera.depth_of(p) > 4.0;
                    let uv = [(p.z + 20.0) / 40.0, (p.x + 20.0) / 40.0];
                    sum += tex.sample_linear(uv)[0];
                }
                if !all_floor {
                    break;
                }
            }
            if all_floor && far {
                t.push(sum / 64.0);
                g.push(albedo.pixel(x, y)[0]);
            }
        }
        if t.len() >= w as usize / 2 {
            let (sg, st) = (spread(&g), spread(&t));
            if st > 0.05 {
                worst = worst.min(sg / st);
                gpu_sum += sg;
                truth_sum += st;
                rows += 1;
            }
        }
    }
    eprintln!(
        "grazing floor: {rows} rows, albedo spread along a row {gpu_sum:.3} (GPU) vs {truth_sum:.3} (footprint truth), worst row {worst:.3}"
    );
    assert!(rows >= 10, "only {rows} far floor rows with detail");
    // measured: anisotropic ≥ 0.93 in every row; isotropic trilinear 0.58 in the farthest
    assert!(
        worst >= 0.85,
        "the G-buffer blurs the grazing floor: a row keeps {worst:.3} of its detail"
    );
}

/// A reduced-resolution layer (DGB Fig. 11, `layer_scale` s > 1) at a static camera:
/// rendered `k.max(2)` frames; returns the renderer.
fn reduced_renderer(gpu: &GpuContext, scene: &Scene, k: u32, v: Variant, scale: u32) -> Renderer {
    let mut r = Renderer::new(
        gpu,
        scene,
        RenderSettings {
            // odd: every scale leaves a partial last column and row
            width: 641,
            height: 361,
            deep: DeepGBufferSettings {
                layers: k,
                variant: v,
                layer_scale: scale,
                ..Default::default()
            },
            shade: false,
            ..Default::default()
        },
    )
    .unwrap_or_else(|e| panic!("{v} k={k} s={scale}: {e}"));
    let cams = FrameCameras::fixed(scene.camera);
    for _ in 0..k.max(2) {
        r.render(gpu, scene, &cams, 0.0)
            .expect("frame renders without validation errors");
    }
    r
}

#[test]
fn reduced_layers_keep_the_separation_and_equal_their_cpu_twin() {
    use strata_render::passes::deep_gbuffer::{texel_plane_depth, upsample_depth, upsample_pick, SURFACE_TOLERANCE};
    let gpu = common::gpu();
    let atrium = static_scenes().pop().unwrap();
    let dz = atrium.settings.min_separation;
    let mut lost = Vec::new();
    for (k, v, s) in [
        (2, Variant::Peel, 2),
        (2, Variant::Reproject, 2),
        (2, Variant::Peel, 3),
        (3, Variant::Peel, 2),
        (2, Variant::Delay, 4),
    ] {
        let what = format!("{v} k={k} s={s}");
        let r = reduced_renderer(&gpu, &atrium, k, v, s);
        let layer = |name: &str, j: u32| r.read_target_full(&gpu, name, j).unwrap();
        let csz: Vec<_> = (0..k).map(|j| layer("csz", j).data).collect();
        assert_min_separation(&csz, dz, &what);
        // the last layer is the one the reduced targets still hold
        let j = (k - 1) as usize;
        let reduced = layer("reduced-csz", 0);
        let full = layer("csz", 0);
        let (w, h) = (full.width, full.height);
        assert_eq!(
            [reduced.width, reduced.height],
            [w.div_ceil(s), h.div_ceil(s)],
            "{what}: reduced size"
        );
        let (albedo, reduced_albedo) = (layer("albedo", j as u32), layer("reduced-albedo", 0));
        let reduced_normal = layer("reduced-normal", 0);
        let f = r.frame_uniforms();
        let (mut taken, mut planar, mut edges) = (0, 0, 0);
        for y in 0..h {
            for x in 0..w {
                let i = (y * w + x) as usize;
                let pick = upsample_pick(
                    &reduced.data,
                    [reduced.width, reduced.height],
                    [x, y],
                    csz[j - 1][i],
                    s,
                    dz,
                );
                match pick {
                    None => assert_eq!(csz[j][i], 0.0, "{what}: pixel ({x}, {y}) should be empty"),
                    Some([qx, qy]) => {
                        taken += 1;
                        let q = (qy * reduced.width + qx) as usize;
                        let nq = &reduced_normal.data[q * 4..q * 4 + 2];
                        let n = strata_render::packing::oct_decode(glam::Vec2::new(nq[0], nq[1]));
                        let (zt, front) = (reduced.data[q], csz[j - 1][i]);
                        let want = upsample_depth(&f, [qx, qy], s, zt, n, [x, y], front, dz);
                        let got = csz[j][i];
                        let close = |a: f32, b: f32| (a - b).abs() <= 1e-4 * b.abs();
                        // where the plane's depth lies on a threshold (the separation, or the
                        // largest change), GPU and CPU rounding may decide either way
                        let plane = texel_plane_depth(&f, [qx, qy], s, zt, n, [x, y]);
                        let knife_edge = close(plane, front + dz + SURFACE_TOLERANCE * front)
                            || close((plane - zt).abs(), 0.25 * zt);
                        assert!(
                            close(got, want) || (knife_edge && (close(got, plane) || got == zt)),
                            "{what}: pixel ({x}, {y}) takes texel ({qx}, {qy}): depth {got} vs {want}"
                        );
                        edges += (!close(got, want)) as usize;
                        planar += (want != reduced.data[q]) as usize;
                        for c in 0..4 {
                            let (a, b) = (albedo.data[i * 4 + c], reduced_albedo.data[q * 4 + c]);
                            assert!((a - b).abs() <= 0.5 / 255.0, "{what}: albedo of ({x}, {y}): {a} vs {b}");
                        }
                    }
                }
            }
        }
        assert!(
            taken > (w * h / 10) as usize,
            "{what}: layer {j} nearly empty ({taken} px)"
        );
        assert!(
            edges * 1000 < taken,
            "{what}: {edges} of {taken} pixels decided differently"
        );
        // most pixels take their depth from the texel's plane, not its centre
        assert!(
            planar * 2 > taken,
            "{what}: {planar} of {taken} pixels on their texel's plane"
        );
        // its hardware depth is that of the same point: reversed-Z infinite, near / z
        let depth = layer("depth", j as u32).data;
        let near = atrium.camera.near;
        for (i, (&d, &z)) in depth.iter().zip(&csz[j]).enumerate() {
            let want = if z > 0.0 { near / z } else { 0.0 };
            assert!(
                (d - want).abs() <= 1e-6 * want,
                "{what}: depth of pixel {i}: {d} vs {want}"
            );
        }
        // the peel's oracle at a reduced fragment: layer j − 1 at the full-resolution pixel a
        // quarter pixel up-left of its centre (i + 1/2)·s; a partial last column or row (past
        // ⌊w/s⌋, ⌊h/s⌋) is scissored off
        if v == Variant::Peel {
            for qy in 0..reduced.height {
                for qx in 0..reduced.width {
                    let z = reduced.data[(qy * reduced.width + qx) as usize];
                    if qx >= w / s || qy >= h / s {
                        assert_eq!(z, 0.0, "{what}: texel ({qx}, {qy}) lies in a partial column or row");
                        continue;
                    }
                    let c = [(qx as f32 + 0.5) * s as f32 - 0.25, (qy as f32 + 0.5) * s as f32 - 0.25];
                    let zc = csz[j - 1][(c[1] as u32 * w + c[0] as u32) as usize];
                    if z > 0.0 {
                        assert!(
                            zc > 0.0 && z > zc + dz + SURFACE_TOLERANCE * zc,
                            "{what}: texel ({qx}, {qy}) at z {z} is within Δz of the oracle's {zc}"
                        );
                    }
                }
            }
        }
        // what the reduction loses: the full-resolution layer's surfaces it keeps
        let exact = reduced_renderer(&gpu, &atrium, k, v, 1);
        let exact_z = exact.read_target_full(&gpu, "csz", j as u32).unwrap().data;
        // (a reduced texel's depth is that of a point up to s pixels away: the same surface
        // within 3 % of its depth, or a different one)
        let (mut counted, mut differ) = (0, 0);
        for (&a, &b) in csz[j].iter().zip(&exact_z) {
            if a > 0.0 || b > 0.0 {
                counted += 1;
                differ += (a == 0.0 || b == 0.0 || (a - b).abs() > 0.03 * a.max(b)) as u32;
            }
        }
        let pct = 100.0 * differ as f64 / counted as f64;
        println!("{what}: {pct:.1} % of layer {j}'s pixels hold another surface than at full resolution");
        // 641×361 (2026-11-29): 6.6 % at s = 2, 8.3 % at s = 3, 11.7 % at s = 4 (k = 2)
        assert!(pct < 6.0 * s as f64, "{what}: {pct:.1} % of layer {j} lost");
        lost.push(pct);
    }
    // a coarser layer loses more: peel k = 2 at s = 2 against s = 3
    assert!(lost[0] < lost[2], "{lost:?}");
}
