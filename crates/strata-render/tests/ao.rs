//! Deep-G-buffer AO (DGB §3.1, §3.3, §3.4): analytic cases, the shader against
//! a CPU evaluation of Eq. 1–2 over the same buffers, k layers against the
//! ray-traced obscurance, and the temporal filter.

mod common;

use common::frozen;
use strata_reference::ao::{DiskSampling, ObscuranceSettings};
use strata_reference::Reference;
use strata_render::frame::FrameCameras;
use strata_render::passes::ao::{
    ambient_visibility_cpu, deinterleaved_obscurance_cpu, deinterleaved_visibility_cpu, snap_tap, sub_buffer_taps,
    AoSettings,
};
use strata_render::passes::bilateral::BilateralSettings;
use strata_render::passes::deep_gbuffer::{DeepGBufferSettings, Variant};
use strata_render::passes::temporal::TemporalSettings;
use strata_render::{GpuContext, RenderSettings, Renderer};
use strata_scene::{ImageBuf, Scene};

fn ao_renderer(gpu: &GpuContext, scene: &Scene, w: u32, h: u32, layers: u32, ao: AoSettings) -> Renderer {
    Renderer::new(
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
            shade: false,
            ao: Some(ao),
            ..Default::default()
        },
    )
    .unwrap_or_else(|e| panic!("{} k={layers}: {e}", scene.name))
}

/// AV after reconstruction, one static frame.
fn render_ao(gpu: &GpuContext, scene: &Scene, w: u32, h: u32, layers: u32, ao: AoSettings) -> ImageBuf {
    let mut r = ao_renderer(gpu, scene, w, h, layers, ao);
    r.render(gpu, scene, &FrameCameras::fixed(scene.camera), 0.0)
        .expect("frame renders without validation errors");
    r.read_target(gpu, "ao").unwrap()
}

fn mean(v: &[f32]) -> f32 {
    v.iter().sum::<f32>() / v.len() as f32
}

fn dump(img: &ImageBuf, name: &str) {
    if let Ok(dir) = std::env::var("STRATA_TEST_IMAGES") {
        img.save(&std::path::Path::new(&dir).join(name), true).unwrap();
    }
}

/// At sizes whose MIP levels end in a partial block too (203×117: level 4 is 12×7 texels,
/// covering 192×112 pixels), so taps in the last rows and columns read the level's last
/// texel instead of one past it.
#[test]
fn unoccluded_plane_is_one() {
    let gpu = common::gpu();
    let scene = frozen("plane");
    for (w, h) in [(96, 64), (203, 117)] {
        for layers in [1, 2] {
            let av = render_ao(&gpu, &scene, w, h, layers, AoSettings::default());
            let min = av.data.iter().cloned().fold(f32::INFINITY, f32::min);
            // R16Float output: 1 is exact; the plane's own taps give v·n = 0 < β
            assert!(min >= 1.0 - 1e-3, "{w}x{h} k={layers}: min AV {min}");
        }
    }
}

#[test]
fn cornell_corners_and_under_boxes_are_darker_than_wall_centres() {
    let gpu = common::gpu();
    let scene = frozen("cornell");
    let (w, h) = (128, 128);
    let av = render_ao(&gpu, &scene, w, h, 2, AoSettings::default());
    dump(&av, "cornell-ao.png");
    let at = |x: u32, y: u32| av.pixel(x, y)[0];
    // back-wall centre vs the back wall's corners with floor/ceiling/sides
    let centre = at(w / 2, h / 2 - 20);
    let r = Reference::new(&scene, 0.0);
    let cam = scene.camera;
    let layers = r.layers(&cam, w, h, &strata_reference::LayerSettings::new(1, 0.0));
    let depth = &layers.layers[0].depth;
    // the floor row just above the bottom edge of the back wall: find the
    // darkest pixel along the back wall's lower edge, compare with centre
    let mut corner_min = 1.0f32;
    for y in h / 2..h - 4 {
        for x in 4..w - 4 {
            if depth.pixel(x, y)[0].is_finite() {
                corner_min = corner_min.min(at(x, y));
            }
        }
    }
    assert!(centre > 0.9, "open back wall AV {centre}");
    assert!(
        corner_min < centre - 0.3,
        "darkest lower-half AV {corner_min} vs wall centre {centre}"
    );
}

/// Reads back every buffer the AO shader read and re-evaluates Eq. 1–2 on the
/// CPU with the same taps: the shader is the equation. The last two rows run the
/// pass as compute (`ao-kernel=compute`), the others as a fragment pass.
#[test]
fn gpu_ao_equals_cpu_eq1_eq2_over_the_same_buffers() {
    use strata_render::passes::Kernel;
    let gpu = common::gpu();
    // 203×117: MIP levels end in partial blocks (`depth_mip::mip_texel`)
    for (name, layers, kernel, (w, h)) in [
        ("atrium", 2u32, Kernel::Fragment, (96u32, 64u32)),
        ("cornell", 2, Kernel::Fragment, (96, 64)),
        ("column-wall", 1, Kernel::Fragment, (96, 64)),
        ("atrium", 3, Kernel::Fragment, (96, 64)),
        ("atrium", 2, Kernel::Compute, (96, 64)),
        ("column-wall", 1, Kernel::Compute, (96, 64)),
        ("atrium", 2, Kernel::Fragment, (203, 117)),
    ] {
        let scene = frozen(name);
        // DGB's order: `ao-raw` holds Eq. 1's AV (with the default filter_obscurance it holds S,
        // checked by `filtered_obscurance_is_eq1_before_the_square_root_and_resolves_to_av`)
        let settings = AoSettings {
            filter_obscurance: false,
            kernel,
            ..AoSettings::default()
        };
        let mut r = ao_renderer(&gpu, &scene, w, h, layers, settings);
        r.render(&gpu, &scene, &FrameCameras::fixed(scene.camera), 0.0)
            .expect("frame renders without validation errors");
        let raw = r.read_target_full(&gpu, "ao-raw", 0).unwrap();
        let u = r.ao_uniforms().unwrap();
        let zmip: Vec<ImageBuf> = (0..=u.max_mip)
            .map(|m| r.read_target_mip(&gpu, "zmip", m).unwrap())
            .collect();
        assert_eq!(zmip.len(), 5, "default chain has 5 levels");
        let npack = r.read_target_full(&gpu, "npack", 0).unwrap();
        let normals = common::npack_normals(&npack, 0);
        let f = r.frame_uniforms();
        let (mut close, mut occluded, mut worst) = (0usize, 0usize, 0.0f32);
        for y in 0..h {
            for x in 0..w {
                let cpu = ambient_visibility_cpu(&zmip, &normals, &f, &u, layers, x, y);
                let d = (cpu - raw.pixel(x, y)[0]).abs();
                worst = worst.max(d);
                close += (d < 1e-4) as usize;
                occluded += (cpu < 0.99) as usize;
            }
        }
        let n = (w * h) as usize;
        // every pixel on lavapipe: a tap's MIP level may differ between the pixels of a quad,
        // which its textureDimensions(t, level) got wrong (`mip_size` in common/spiral.wgsl)
        assert!(
            close >= common::twin_pixels_required(&gpu, n),
            "{name} k={layers} {kernel:?}: only {close}/{n} pixels within 1e-4 (worst {worst})"
        );
        assert!(
            occluded > n / 10,
            "{name}: test is weak, only {occluded} occluded pixels"
        );
        eprintln!("{name} k={layers} {kernel:?}: {close}/{n} within 1e-4, worst {worst}");
    }
}

/// Reduced-resolution AO (`ao-scale`, not in the paper), on the second frame (seed 1):
/// each texel of `ao-raw-low` equals Eq. 1–2 on the CPU at the pixel it shades
/// (`block_pixel`), and `ao-raw` equals the CPU twin of the joint bilateral upsampling of
/// the read-back `ao-raw-low`, at scales 2 and 3, one and two layers, the AO pass as a
/// fragment and as a compute pass.
#[test]
fn reduced_resolution_ao_and_upsampling_match_their_cpu_twins() {
    use strata_render::passes::upsample::upsample_cpu;
    use strata_render::passes::Kernel;
    let gpu = common::gpu();
    for (name, layers, scale, kernel) in [
        ("atrium", 2u32, 2u32, Kernel::Fragment),
        ("column-wall", 1, 3, Kernel::Fragment),
        ("cornell", 2, 2, Kernel::Compute),
    ] {
        let scene = frozen(name);
        let (w, h) = (96u32, 64u32);
        let settings = AoSettings {
            filter_obscurance: false,
            scale,
            kernel,
            ..AoSettings::default()
        };
        let mut r = ao_renderer(&gpu, &scene, w, h, layers, settings);
        for _ in 0..2 {
            r.render(&gpu, &scene, &FrameCameras::fixed(scene.camera), 0.0)
                .expect("frame renders without validation errors");
        }
        let u = r.ao_uniforms().unwrap();
        let up = r.ao_upsample_uniforms().expect("an upsampling pass at scale > 1");
        assert_eq!(
            (up.scale, up.seed, u.seed),
            (scale, 1, 1),
            "{name}: the second frame's seed"
        );
        let zmip: Vec<ImageBuf> = (0..=u.max_mip)
            .map(|m| r.read_target_mip(&gpu, "zmip", m).unwrap())
            .collect();
        let normals = common::npack_normals(&r.read_target_full(&gpu, "npack", 0).unwrap(), 0);
        let f = r.frame_uniforms();
        let low = r.read_target_full(&gpu, "ao-raw-low", 0).unwrap();
        assert_eq!((low.width, low.height), (w.div_ceil(scale), h.div_ceil(scale)));
        let (mut close, mut occluded) = (0usize, 0usize);
        for ty in 0..low.height {
            for tx in 0..low.width {
                let p = strata_render::spiral::block_pixel([tx, ty], scale, u.seed, [w, h]);
                let cpu = ambient_visibility_cpu(&zmip, &normals, &f, &u, layers, p[0], p[1]);
                close += ((cpu - low.pixel(tx, ty)[0]).abs() < 1e-4) as usize;
                occluded += (cpu < 0.99) as usize;
            }
        }
        let m = (low.width * low.height) as usize;
        eprintln!("{name} s={scale}: {close}/{m} texels match, {occluded} occluded");
        assert!(
            close >= common::twin_pixels_required(&gpu, m),
            "{name} s={scale}: {close}/{m} texels"
        );
        assert!(occluded > m / 10, "{name}: weak test, {occluded} occluded texels");

        let want = upsample_cpu(&low, &zmip[0], &normals, &f, &up, 0);
        let got = r.read_target_full(&gpu, "ao-raw", 0).unwrap();
        let n = (w * h) as usize;
        let close = (0..n).filter(|&i| (got.data[i] - want.data[i]).abs() < 1e-4).count();
        let varied = (0..n).filter(|&i| want.data[i] < 0.99).count();
        // no surface: unoccluded (AV 1), as at full resolution
        let z0 = &zmip[0];
        let empty: Vec<usize> = (0..n).filter(|&i| z0.data[i * z0.channels as usize] <= 0.0).collect();
        assert!(empty.iter().all(|&i| got.data[i] == 1.0), "{name}: AV of empty pixels");
        eprintln!("{name} s={scale}: {close}/{n} upsampled pixels match, {varied} occluded");
        assert!(close as f32 >= 0.995 * n as f32, "{name} s={scale}: {close}/{n} pixels");
        assert!(varied > n / 10, "{name}: weak test, {varied} occluded pixels");
    }
}

/// `ao-scale` outside 1..=4, or above 1 with the deinterleaved AO (which shades every
/// pixel), is a one-line error naming the setting and what is valid.
#[test]
fn ao_scale_out_of_range_or_with_deinterleave_is_refused() {
    for (scale, deinterleave, want) in [
        (0, None, "AO scale 0 is out of range: must be in 1..=4"),
        (5, None, "AO scale 5 is out of range: must be in 1..=4"),
        (2, Some([2, 2]), "AO scale (ao-scale) 2 needs deinterleave off"),
    ] {
        let e = AoSettings {
            scale,
            deinterleave,
            ..AoSettings::default()
        }
        .validate()
        .unwrap_err();
        assert!(e.contains(want) && !e.contains('\n'), "{e}");
    }
    for scale in 1..=4 {
        let ok = AoSettings {
            scale,
            ..AoSettings::default()
        };
        assert_eq!(ok.validate(), Ok(()), "scale {scale}");
    }
}

fn reference_av(scene: &Scene, w: u32, h: u32, ao: &AoSettings) -> ImageBuf {
    let (radius, beta, epsilon) = ao.resolve(scene);
    let s = ObscuranceSettings {
        radius,
        beta,
        epsilon,
        spp: 256,
        disk: DiskSampling::SpiralRadius,
        ..ObscuranceSettings::new(radius)
    };
    Reference::new(scene, 0.0).ao_obscurance(&scene.camera, w, h, &s)
}

fn mae(a: &ImageBuf, b: &ImageBuf) -> f32 {
    let d: Vec<f32> = a.data.iter().zip(&b.data).map(|(x, y)| (x - y).abs()).collect();
    mean(&d)
}

/// Occluders hidden behind the first layer (the wall behind a column, the
/// atrium's arcade) are seen by the second layer: its AO error against the
/// ray-traced obscurance (same r, β, ε, infinitely many layers) is lower.
#[test]
fn two_layers_beat_one_against_the_ray_traced_obscurance() {
    let gpu = common::gpu();
    // measured at 128×96 (lavapipe): column-wall 0.058 → 0.033, atrium 0.048 → 0.044
    for (name, margin) in [("column-wall", 0.75), ("atrium", 0.95)] {
        let scene = frozen(name);
        let (w, h) = (128, 96);
        let ao = AoSettings::default();
        let reference = reference_av(&scene, w, h, &ao);
        let one = render_ao(&gpu, &scene, w, h, 1, ao.clone());
        let two = render_ao(&gpu, &scene, w, h, 2, ao.clone());
        dump(&reference, &format!("{name}-ref.png"));
        dump(&one, &format!("{name}-k1.png"));
        dump(&two, &format!("{name}-k2.png"));
        let (e1, e2) = (mae(&one, &reference), mae(&two, &reference));
        eprintln!("{name}: MAE k=1 {e1:.4}, k=2 {e2:.4}");
        assert!(
            e2 < margin * e1,
            "{name}: k=2 MAE {e2} not below {margin} × k=1 MAE {e1}"
        );
    }
}

fn temporal_settings(alpha: f32) -> AoSettings {
    AoSettings {
        temporal_noise: true,
        temporal: Some(TemporalSettings {
            alpha,
            ..Default::default()
        }),
        blur: BilateralSettings {
            radius: 0,
            ..Default::default()
        },
        ..Default::default()
    }
}

/// Per-frame rotated noise on a static view: after warm-up the filtered
/// estimate varies far less from frame to frame than the raw one (an EWMA
/// leaves (1 − α)/(1 + α) ≈ 0.08 of the variance for α = 0.85).
#[test]
fn temporal_filter_reduces_per_pixel_variance_on_a_static_view() {
    let gpu = common::gpu();
    let scene = frozen("cornell");
    let (w, h) = (64, 64);
    let mut r = ao_renderer(&gpu, &scene, w, h, 2, temporal_settings(0.85));
    let cams = FrameCameras::fixed(scene.camera);
    let (mut raw, mut filtered) = (Vec::new(), Vec::new());
    for f in 0..24 {
        r.render(&gpu, &scene, &cams, f as f32).unwrap();
        if f >= 12 {
            raw.push(r.read_target(&gpu, "ao-raw").unwrap().data);
            filtered.push(r.read_target(&gpu, "ao-temporal").unwrap().data);
        }
    }
    let variance = |frames: &[Vec<f32>]| {
        let n = frames.len() as f32;
        let mut total = 0.0;
        for p in 0..frames[0].len() {
            let m = frames.iter().map(|f| f[p]).sum::<f32>() / n;
            total += frames.iter().map(|f| (f[p] - m).powi(2)).sum::<f32>() / n;
        }
        total / frames[0].len() as f32
    };
    let (vr, vf) = (variance(&raw), variance(&filtered));
    eprintln!("temporal variance raw {vr:.3e}, filtered {vf:.3e}");
    assert!(vr > 1e-4, "the noise is not varying per frame ({vr})");
    assert!(vf < 0.2 * vr, "filtered variance {vf} vs raw {vr}");
}

/// With the true previous camera every pixel blends (1 − α₁)·E + α₁·E_{t−1} — α₁ = α, or
/// 1/2 with the start-up ramp (the mean of the first two frames) — the history first
/// clamped to the range of E's 3×3 neighbourhood when `clamp_history` is on (the
/// default); when the previous camera is far from where the history was rendered, every
/// reprojected point misses both layers and takes the current value.
#[test]
fn temporal_filter_blends_valid_and_rejects_failed_reprojections() {
    let gpu = common::gpu();
    let scene = frozen("cornell");
    let (w, h) = (64, 64);
    let alpha = 0.85;
    let cam = scene.camera;
    let mut moved = cam;
    let shift = (cam.target - cam.eye).normalize() * -2.0;
    moved.eye += shift;
    moved.target += shift;
    for (clamp_history, ramp) in [(false, false), (true, true)] {
        let weight = if ramp { 0.5 } else { alpha };
        for (previous, expect_blend) in [(cam, true), (moved, false)] {
            let mut settings = temporal_settings(alpha);
            let t = settings.temporal.as_mut().unwrap();
            t.clamp_history = clamp_history;
            t.ramp = ramp;
            assert_eq!(t.history_weight(1), weight);
            let mut r = ao_renderer(&gpu, &scene, w, h, 2, settings);
            r.render(&gpu, &scene, &FrameCameras::fixed(cam), 0.0).unwrap();
            let e0 = r.read_target(&gpu, "ao-temporal").unwrap();
            let cams = FrameCameras {
                previous,
                ..FrameCameras::fixed(cam)
            };
            r.render(&gpu, &scene, &cams, 1.0).unwrap();
            let e1 = r.read_target(&gpu, "ao-raw").unwrap();
            let out = r.read_target(&gpu, "ao-temporal").unwrap();
            let csz = r.read_target(&gpu, "csz").unwrap();
            let (mut checked, mut differs, mut clamped) = (0, 0, 0);
            for y in 0..h as i32 {
                for x in 0..w as i32 {
                    let i = (y * w as i32 + x) as usize;
                    if csz.data[i] <= 0.0 {
                        continue;
                    }
                    checked += 1;
                    // the current estimate's range over the 3×3 neighbourhood (clamped edges)
                    let (mut lo, mut hi) = (f32::INFINITY, f32::NEG_INFINITY);
                    for (dx, dy) in (-1..=1).flat_map(|dy| (-1..=1).map(move |dx| (dx, dy))) {
                        let (qx, qy) = ((x + dx).clamp(0, w as i32 - 1), (y + dy).clamp(0, h as i32 - 1));
                        let v = e1.data[(qy * w as i32 + qx) as usize];
                        lo = lo.min(v);
                        hi = hi.max(v);
                    }
                    let history = if clamp_history {
                        e0.data[i].clamp(lo, hi)
                    } else {
                        e0.data[i]
                    };
                    clamped += (history != e0.data[i]) as usize;
                    let want = if expect_blend {
                        (1.0 - weight) * e1.data[i] + weight * history
                    } else {
                        e1.data[i]
                    };
                    assert!(
                        (out.data[i] - want).abs() < 1e-5,
                        "pixel ({x}, {y}): got {} want {want} (blend {expect_blend}, clamp {clamp_history}, ramp {ramp})",
                        out.data[i]
                    );
                    differs += ((e1.data[i] - e0.data[i]).abs() > 1e-3) as usize;
                }
            }
            assert!(
                checked > 1000 && differs > 100,
                "weak test: {checked} px, {differs} differ"
            );
            if clamp_history {
                assert!(clamped > 10, "weak test: the clamp moved only {clamped} histories");
            }
        }
    }
}

/// The start-up ramp counts per pixel: a frame whose reprojection fails everywhere (the
/// previous camera far away) resets every pixel's count to 0, so the next frame blends
/// with weight 1/2 again (a frame counter would give 2/3), and the count then grows by one
/// per accepted frame.
#[test]
fn temporal_ramp_restarts_per_pixel_after_a_failed_reprojection() {
    let gpu = common::gpu();
    let scene = frozen("cornell");
    let (w, h) = (64, 64);
    let mut settings = temporal_settings(0.85);
    settings.temporal.as_mut().unwrap().clamp_history = false;
    let mut r = ao_renderer(&gpu, &scene, w, h, 2, settings);
    let cam = scene.camera;
    let mut moved = cam;
    let shift = (cam.target - cam.eye).normalize() * -2.0;
    moved.eye += shift;
    moved.target += shift;
    let still = FrameCameras::fixed(cam);
    r.render(&gpu, &scene, &still, 0.0).unwrap();
    r.render(&gpu, &scene, &still, 1.0).unwrap();
    let frames = |r: &Renderer| r.read_target(&gpu, "ao-temporal-frames").unwrap().data;
    let csz = r.read_target(&gpu, "csz").unwrap().data;
    let covered: Vec<usize> = (0..csz.len()).filter(|&i| csz[i] > 0.0).collect();
    assert!(covered.len() > 1000);
    assert!(covered.iter().all(|&i| frames(&r)[i] == 1.0), "one accepted frame");
    // every reprojection fails: the counts restart
    r.render(
        &gpu,
        &scene,
        &FrameCameras {
            previous: moved,
            ..still
        },
        2.0,
    )
    .unwrap();
    assert!(
        frames(&r).iter().all(|&n| n == 0.0),
        "a failed reprojection keeps no count"
    );
    let history = r.read_target(&gpu, "ao-temporal").unwrap().data;
    r.render(&gpu, &scene, &still, 3.0).unwrap();
    let (e, out, n) = (
        r.read_target(&gpu, "ao-raw").unwrap().data,
        r.read_target(&gpu, "ao-temporal").unwrap().data,
        frames(&r),
    );
    let mut differs = 0;
    for &i in &covered {
        assert_eq!(n[i], 1.0, "pixel {i}: count {}", n[i]);
        let want = 0.5 * e[i] + 0.5 * history[i];
        assert!((out[i] - want).abs() < 1e-5, "pixel {i}: {} vs {want}", out[i]);
        differs += ((e[i] - history[i]).abs() > 1e-3) as usize;
    }
    assert!(differs > 100, "weak test: {differs} pixels differ from their history");
    r.render(&gpu, &scene, &still, 4.0).unwrap();
    assert!(covered.iter().all(|&i| frames(&r)[i] == 2.0), "two accepted frames");
}

/// Per-object velocities (DGB §3.3 reprojects "to account for motion"): the whole Cornell
/// box slides 6 cm towards the still camera between two frames.
/// - The deep G-buffer's `motion` holds that displacement on every surface pixel, and 0
///   when the same frame is drawn again.
/// - With `object_motion` each pixel moves its point back by `motion`, reprojects it, and
///   blends the history read there wherever last frame's layers hold the point: the CPU
///   twin of reproject.wgsl (`temporal::reproject`, `matching_layer`, `bilinear_at`).
/// - With the camera's motion only, the walls facing the camera fail the 1 cm test.
#[test]
fn temporal_filter_follows_moving_objects_with_their_motion() {
    use strata_render::passes::temporal::{bilinear_at, matching_layer, reproject};
    let gpu = common::gpu();
    let (scene, slide) = common::sliding_cornell(0.06);
    let cam = scene.camera;
    let (w, h) = (64, 64);
    let alpha = 0.85;
    let still = FrameCameras::fixed(cam);
    let mut accepted_by_mode = Vec::new();
    for object_motion in [true, false] {
        let mut settings = temporal_settings(alpha);
        let t = settings.temporal.as_mut().unwrap();
        (t.clamp_history, t.ramp, t.object_motion) = (false, false, object_motion);
        let mut r = ao_renderer(&gpu, &scene, w, h, 2, settings);
        r.render(&gpu, &scene, &still, 0.0).unwrap();
        let e0 = r.read_target(&gpu, "ao-temporal").unwrap();
        let csz0: Vec<ImageBuf> = (0..2).map(|j| r.read_target_layer(&gpu, "csz", j).unwrap()).collect();
        r.render(&gpu, &scene, &still, 1.0).unwrap();
        let f = r.frame_uniforms();
        let (e1, out) = (
            r.read_target(&gpu, "ao-raw").unwrap(),
            r.read_target(&gpu, "ao-temporal").unwrap(),
        );
        let (csz, motion) = (
            r.read_target_layer(&gpu, "csz", 0).unwrap(),
            r.read_target_layer(&gpu, "motion", 0).unwrap(),
        );
        let (mut covered, mut accepted, mut mismatched, mut moved_history) = (0, 0, 0, 0);
        for y in 0..h {
            for x in 0..w {
                let z = csz.pixel(x, y)[0];
                if z <= 0.0 {
                    continue;
                }
                covered += 1;
                let m = glam::Vec3::from_slice(&motion.pixel(x, y)[..3]);
                assert!(
                    (m - slide).length() < 1e-4,
                    "pixel ({x}, {y}): motion {m} for a slide of {slide}"
                );
                let mut p = strata_render::passes::ao::world_from_csz(&f, [x as f32 + 0.5, y as f32 + 0.5], z);
                if object_motion {
                    p -= m;
                }
                let rp = reproject(&f, p);
                let (cur, got) = (e1.pixel(x, y)[0], out.pixel(x, y)[0]);
                let want = match matching_layer(&csz0, rp, 0.01) {
                    Some(_) => {
                        accepted += 1;
                        let (c, _) = rp.unwrap();
                        let h = bilinear_at(&e0, c, 0);
                        moved_history += ((h - e0.pixel(x, y)[0]).abs() > 1e-3) as usize;
                        (1.0 - alpha) * cur + alpha * h
                    }
                    None => cur,
                };
                mismatched += ((got - want).abs() > 1e-4) as usize;
            }
        }
        eprintln!(
            "object motion {object_motion}: {accepted} of {covered} pixels accepted, {mismatched} differ from the twin, {moved_history} read a moved history"
        );
        assert!(covered > 3000, "weak test: {covered} pixels");
        // reprojection at a 1 cm threshold: a handful may fall on the other side in f32
        assert!(
            mismatched * 200 <= covered,
            "{mismatched} of {covered} pixels differ from the CPU twin"
        );
        if object_motion {
            assert!(
                moved_history > 300,
                "weak test: {moved_history} histories read elsewhere"
            );
        }
        accepted_by_mode.push(accepted as f32 / covered as f32);
        // the same frame again: nothing moved since the last one drawn
        r.render(&gpu, &scene, &still, 1.0).unwrap();
        let motion = r.read_target_layer(&gpu, "motion", 0).unwrap();
        assert!(motion.data.iter().all(|&v| v == 0.0), "motion without movement");
    }
    let (on, off) = (accepted_by_mode[0], accepted_by_mode[1]);
    assert!(
        on > 0.95,
        "with object motion only {on} of the pixels keep their history"
    );
    assert!(
        off < on - 0.3,
        "the camera's motion alone accepts {off} (with object motion {on})"
    );
}

/// A single-pass variant's first frame has no oracle, so its layer 1 (and the
/// AO computed from it) is wrong; the next frame must not average it in.
#[test]
fn temporal_filter_ignores_history_from_an_oracle_less_first_frame() {
    let gpu = common::gpu();
    let scene = frozen("column-wall");
    let mut r = Renderer::new(
        &gpu,
        &scene,
        RenderSettings {
            width: 64,
            height: 48,
            deep: DeepGBufferSettings {
                layers: 2,
                variant: Variant::Reproject,
                ..Default::default()
            },
            shade: false,
            ao: Some(temporal_settings(0.85)),
            ..Default::default()
        },
    )
    .unwrap();
    let cams = FrameCameras::fixed(scene.camera);
    let mut outs = Vec::new();
    for f in 0..3 {
        r.render(&gpu, &scene, &cams, f as f32).unwrap();
        outs.push((
            r.read_target(&gpu, "ao-raw").unwrap().data,
            r.read_target(&gpu, "ao-temporal").unwrap().data,
        ));
    }
    // frame 1: history (frame 0) came from oracle-less layers → current value only
    assert_eq!(outs[1].0, outs[1].1, "frame 1 averaged frame 0's oracle-less AO");
    // frame 2: frame 1's layers were exact → blended, as the first frame with a history
    // (the start-up ramp's weight 1/2: the count restarted after the rejected frame)
    let a = TemporalSettings::default().history_weight(1);
    assert_eq!(a, 0.5);
    let blended = outs[2]
        .0
        .iter()
        .zip(&outs[2].1)
        .zip(&outs[1].1)
        .filter(|((e, t), h)| (*t - ((1.0 - a) * *e + a * *h)).abs() < 1e-5 && (*e - *h).abs() > 1e-3)
        .count();
    assert!(blended > 100, "frame 2 did not blend ({blended} px)");
}

// ---- Deinterleaved AO (issue 11 item 8, docs/ao.md "Deinterleaved AO") ----

/// Deinterleaved AO in DGB's order (AV filtered, `ao-raw` = AV), which the twins compute.
fn deint(pattern: Option<[u32; 2]>) -> AoSettings {
    AoSettings {
        deinterleave: pattern,
        filter_obscurance: false,
        ..AoSettings::default()
    }
}

/// The tap assignment: the n·m sub-buffers of a pattern cell evaluate each of
/// the N spiral taps exactly once, with N_s = ⌈(N − s)/(n·m)⌉ taps each; the
/// snap moves a tap at most n/2 (m/2) pixels onto the sub-buffer's lattice
/// and is the identity for 1×1.
#[test]
fn deinterleaved_taps_partition_the_spiral_and_snap_onto_the_lattice() {
    for samples in [1u32, 4, 16, 19, 32, 57] {
        for pattern @ [n, m] in [[1u32, 1], [2, 2], [3, 2], [4, 4], [2, 1]] {
            if n * m > samples {
                continue;
            }
            let mut seen = vec![0u32; samples as usize];
            for j in 0..m {
                for i in 0..n {
                    let (taps, count) = sub_buffer_taps(samples, pattern, i, j);
                    let taps: Vec<u32> = taps.collect();
                    assert_eq!(taps.len() as u32, count, "N={samples} {n}x{m} ({i},{j})");
                    assert!(count >= 1);
                    for k in taps {
                        assert_eq!(k % (n * m), i + n * j);
                        seen[k as usize] += 1;
                    }
                }
            }
            assert!(seen.iter().all(|&c| c == 1), "N={samples} {n}x{m}: {seen:?}");
        }
    }
    for dx in -40..=40 {
        for dy in [-7, -1, 0, 1, 6] {
            assert_eq!(snap_tap([dx, dy], [1, 1]), [dx, dy]);
            for pattern @ [n, m] in [[2u32, 2], [3, 2], [4, 4]] {
                let [lx, ly] = snap_tap([dx, dy], pattern);
                let (ex, ey) = (lx * n as i32 - dx, ly * m as i32 - dy);
                // ⌊d/n + ½⌋: within (−n/2, n/2] of the spiral's pixel
                assert!(2 * ex > -(n as i32) && 2 * ex <= n as i32, "{dx} {n}: {lx}");
                assert!(2 * ey > -(m as i32) && 2 * ey <= m as i32, "{dy} {m}: {ly}");
            }
        }
    }
}

/// 1×1 runs the whole deinterleaved path (copy, splits, `ao-deint`, gather)
/// and must reproduce today's single-pass AO: `ao-raw` and the filtered `ao`.
#[test]
fn deinterleaved_1x1_equals_the_single_pass_ao() {
    let gpu = common::gpu();
    for (name, layers) in [("atrium", 2u32), ("cornell", 1)] {
        let scene = frozen(name);
        let (w, h) = (96, 64);
        let mut out = Vec::new();
        for pattern in [None, Some([1, 1])] {
            let mut r = ao_renderer(&gpu, &scene, w, h, layers, deint(pattern));
            let passes: Vec<&str> = r.pass_infos().iter().map(|p| p.name).collect();
            assert_eq!(passes.contains(&"ao-deint"), pattern.is_some(), "{passes:?}");
            assert_eq!(passes.contains(&"ao"), pattern.is_none(), "{passes:?}");
            r.render(&gpu, &scene, &FrameCameras::fixed(scene.camera), 0.0)
                .expect("frame renders without validation errors");
            out.push((
                r.read_target_full(&gpu, "ao-raw", 0).unwrap(),
                r.read_target(&gpu, "ao").unwrap(),
            ));
        }
        for (what, a, b) in [("ao-raw", &out[0].0, &out[1].0), ("ao", &out[0].1, &out[1].1)] {
            let worst = a
                .data
                .iter()
                .zip(&b.data)
                .map(|(x, y)| (x - y).abs())
                .fold(0.0f32, f32::max);
            assert!(
                worst <= 1e-6,
                "{name} {what}: 1x1 differs from the single pass by {worst}"
            );
        }
        assert!(mean(&out[0].0.data) < 0.99, "{name}: test is weak, nothing occluded");
    }
}

/// The deinterleaved shader against its CPU twin over the read-back buffers
/// (sub-buffer taps, lattice snap, level-0 reads from the split, N_s), for
/// patterns that divide the size and ones that leave padding.
#[test]
fn deinterleaved_gpu_ao_equals_its_cpu_twin() {
    let gpu = common::gpu();
    for (name, layers, pattern, (w, h)) in [
        ("atrium", 2u32, [2u32, 2], (96, 64)),
        // 4×4 leaves 1–2 taps per pixel and snaps taps nearer than 2 px onto
        // the pixel itself: a larger image keeps enough pixels occluded
        ("atrium", 2, [4, 4], (192, 128)),
        ("cornell", 2, [3, 2], (97, 61)),
        ("atrium", 3, [2, 2], (90, 61)),
    ] {
        let scene = frozen(name);
        let mut r = ao_renderer(&gpu, &scene, w, h, layers, deint(Some(pattern)));
        r.render(&gpu, &scene, &FrameCameras::fixed(scene.camera), 0.0)
            .expect("frame renders without validation errors");
        let raw = r.read_target_full(&gpu, "ao-raw", 0).unwrap();
        let u = r.ao_uniforms().unwrap();
        let zmip: Vec<ImageBuf> = (0..=u.max_mip)
            .map(|m| r.read_target_mip(&gpu, "zmip", m).unwrap())
            .collect();
        let npack = r.read_target_full(&gpu, "npack", 0).unwrap();
        let normals = common::npack_normals(&npack, 0);
        let f = r.frame_uniforms();
        let (mut close, mut occluded, mut worst, mut differs) = (0usize, 0usize, 0.0f32, 0usize);
        let (fw, fh) = (raw.width, raw.height);
        for y in 0..fh {
            for x in 0..fw {
                let cpu = deinterleaved_visibility_cpu(&zmip, &normals, &f, &u, layers, pattern, x, y);
                let d = (cpu - raw.pixel(x, y)[0]).abs();
                worst = worst.max(d);
                close += (d < 1e-4) as usize;
                occluded += (cpu < 0.99) as usize;
                // the twin is not the single-pass AO (else the test could not tell them apart)
                differs +=
                    ((cpu - ambient_visibility_cpu(&zmip, &normals, &f, &u, layers, x, y)).abs() > 1e-3) as usize;
            }
        }
        let n = (fw * fh) as usize;
        // as for the single pass
        assert!(
            close >= common::twin_pixels_required(&gpu, n),
            "{name} k={layers} {pattern:?}: only {close}/{n} pixels within 1e-4 (worst {worst})"
        );
        eprintln!(
            "{name} k={layers} {pattern:?} {fw}x{fh}: {close}/{n} within 1e-4, worst {worst}, {occluded} occluded, {differs} differ from the single pass"
        );
        assert!(
            occluded > n / 20,
            "{name}: test is weak, only {occluded} occluded pixels"
        );
        assert!(
            differs > n / 20,
            "{name}: only {differs} pixels differ from the single pass"
        );
    }
}

#[test]
fn deinterleaved_unoccluded_plane_is_one() {
    let gpu = common::gpu();
    let scene = frozen("plane");
    for pattern in [[2, 2], [4, 4], [3, 2]] {
        let av = render_ao(&gpu, &scene, 97, 64, 2, deint(Some(pattern)));
        let min = av.data.iter().cloned().fold(f32::INFINITY, f32::min);
        assert!(min >= 1.0 - 1e-3, "{pattern:?}: min AV {min}");
    }
}

#[test]
fn bad_deinterleave_settings_are_one_line_errors() {
    let gpu = common::gpu();
    let scene = frozen("plane");
    for (ao, needle) in [
        (deint(Some([5, 5])), "5x5"),
        (deint(Some([0, 2])), "0x2"),
        (
            AoSettings {
                samples: 8,
                ..deint(Some([4, 4]))
            },
            "samples (8)",
        ),
    ] {
        let settings = RenderSettings {
            width: 32,
            height: 32,
            shade: false,
            ao: Some(ao),
            ..Default::default()
        };
        let e = match Renderer::new(&gpu, &scene, settings) {
            Ok(_) => panic!("{needle}: accepted"),
            Err(e) => e.to_string(),
        };
        assert!(
            e.contains("deinterleave") && e.contains(needle) && !e.contains('\n'),
            "{e}"
        );
    }
    gpu.check_errors().expect("nothing invalid reached wgpu");
    let t = strata_render::technique::find("ao").unwrap();
    let mut s = t.settings(&RenderSettings::default(), None).unwrap();
    let v = t
        .setting_list()
        .find(|i| i.name == "deinterleave")
        .unwrap()
        .parse_value("4x4")
        .unwrap();
    t.set(&mut s, "deinterleave", v).unwrap();
    assert_eq!(s.ao.as_ref().unwrap().deinterleave, Some([4, 4]));
    let e = t.set(&mut s, "deinterleave", 17.0).unwrap_err().to_string();
    assert!(
        e.contains("deinterleave") && e.contains("0..=16") && !e.contains('\n'),
        "{e}"
    );
}

/// `filter_obscurance`: `ao-raw` holds S = π/N_s·Σ (the twin's obscurance
/// mean, 0 where there is no surface), and with no temporal or spatial filter
/// `ao-resolve` turns it into exactly the AV the default order writes.
#[test]
fn filtered_obscurance_is_eq1_before_the_square_root_and_resolves_to_av() {
    let gpu = common::gpu();
    let scene = frozen("atrium");
    let (w, h, layers) = (96u32, 64u32, 2u32);
    for pattern in [None, Some([2u32, 2])] {
        let unfiltered = AoSettings {
            temporal: None,
            blur: BilateralSettings {
                radius: 0,
                ..AoSettings::default().blur
            },
            ..deint(pattern)
        };
        let mut r = ao_renderer(
            &gpu,
            &scene,
            w,
            h,
            layers,
            AoSettings {
                filter_obscurance: true,
                ..unfiltered.clone()
            },
        );
        assert!(r.pass_infos().iter().any(|p| p.name == "ao-resolve"));
        r.render(&gpu, &scene, &FrameCameras::fixed(scene.camera), 0.0)
            .expect("frame renders without validation errors");
        let raw = r.read_target_full(&gpu, "ao-raw", 0).unwrap();
        let u = r.ao_uniforms().unwrap();
        assert_eq!(u.output_obscurance, 1);
        let zmip: Vec<ImageBuf> = (0..=u.max_mip)
            .map(|m| r.read_target_mip(&gpu, "zmip", m).unwrap())
            .collect();
        let normals = common::npack_normals(&r.read_target_full(&gpu, "npack", 0).unwrap(), 0);
        let f = r.frame_uniforms();
        let p = pattern.unwrap_or([1, 1]);
        let (mut close, mut positive) = (0usize, 0usize);
        for y in 0..h {
            for x in 0..w {
                let cpu = deinterleaved_obscurance_cpu(&zmip, &normals, &f, &u, layers, p, x, y);
                close += ((cpu - raw.pixel(x, y)[0]).abs() <= 1e-4 * (1.0 + cpu)) as usize;
                positive += (cpu > 0.01) as usize;
            }
        }
        let n = (w * h) as usize;
        assert!(
            close >= common::twin_pixels_required(&gpu, n),
            "{pattern:?}: {close}/{n} S within 1e-4"
        );
        assert!(
            positive > n / 10,
            "{pattern:?}: test is weak, {positive} pixels with S > 0.01"
        );
        let resolved = r.read_target(&gpu, "ao").unwrap();
        let plain = render_ao(&gpu, &scene, w, h, layers, unfiltered);
        // both through R16F (`ao-obscurance` / `ao`): S to ~5e-4 relative, then 1 − √S
        let worst = resolved
            .data
            .iter()
            .zip(&plain.data)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0f32, f32::max);
        assert!(worst < 2e-3, "{pattern:?}: resolve differs from AV by {worst}");
        eprintln!("{pattern:?}: {close}/{n} S within 1e-4, resolve vs AV worst {worst}");
    }
}

/// The AO's reconstruction with the distance weight (`AoSettings::distance_weight`, the
/// default): each GPU pass equals `bilateral_cpu` over the same buffers, and on the
/// interior (the outside ground seen through the window at a grazing angle, the floor far
/// off) the weight cuts taps that DGB's plane and normal weights accept.
#[test]
fn distance_weighted_reconstruction_matches_its_cpu_twin_and_cuts_far_taps() {
    use strata_render::passes::bilateral::{bilateral_cpu, distance_weight};
    let gpu = common::gpu();
    let scene = frozen("interior");
    let (w, h, layers) = (128u32, 128u32, 2u32);
    let s = AoSettings {
        temporal: None,
        ..AoSettings::default()
    };
    assert!(s.distance_weight, "on by default");
    let mut r = ao_renderer(&gpu, &scene, w, h, layers, s.clone());
    r.render(&gpu, &scene, &FrameCameras::fixed(scene.camera), 0.0)
        .expect("frame renders without validation errors");
    let read = |name: &str| r.read_target_full(&gpu, name, 0).unwrap();
    let (raw, gpu_h, gpu_v) = (read("ao-raw"), read("ao-blur-h"), read("ao-obscurance"));
    let zpack = read("zpack");
    let normals = common::npack_normals(&read("npack"), 0);
    let f = r.frame_uniforms();
    let radius = s.resolve(&scene).0;
    let blur = s.reconstruction(radius);
    assert_eq!(blur.world_radius, Some(radius));
    let twin = |src: &ImageBuf, b, vertical| bilateral_cpu(src, &zpack, &normals, &f, b, vertical, None);
    let n = (w * h) as usize;
    // R16F targets
    let near = |g: &ImageBuf, c: &ImageBuf| {
        (0..n)
            .filter(|&i| {
                let (g, c) = (g.data[i * g.channels as usize], c.data[i]);
                (g - c).abs() <= 2e-3 + 2e-3 * c.abs()
            })
            .count()
    };
    let (close_h, close_v) = (
        near(&gpu_h, &twin(&raw, &blur, false)),
        near(&gpu_v, &twin(&gpu_h, &blur, true)),
    );
    // both passes, with and without the distance weight, from the same raw S
    let with = twin(&twin(&raw, &blur, false), &blur, true);
    let paper = twin(&twin(&raw, &s.blur, false), &s.blur, true);
    let cut = (0..n).filter(|&i| (with.data[i] - paper.data[i]).abs() > 0.01).count();
    eprintln!("GPU = twin: {close_h}/{n} (h), {close_v}/{n} (v); the distance weight moves {cut} pixels by > 0.01");
    assert!(close_h as f32 >= 0.995 * n as f32, "h: {close_h}/{n} GPU = CPU twin");
    assert!(close_v as f32 >= 0.995 * n as f32, "v: {close_v}/{n} GPU = CPU twin");
    assert!(
        cut >= n / 200,
        "test is weak: the distance weight moves only {cut} pixels"
    );
    assert_eq!(distance_weight(0.0, radius), 1.0);
    assert_eq!(distance_weight(radius * radius, radius), 0.0);
    assert_eq!(distance_weight(4.0 * radius * radius, radius), 0.0);
}
