//! `strata_render::embed::EmbeddedIls`: interleaved deferred shading (ILS §4, SNSM) of an
//! application's VPLs on its G-buffer. Its output is checked against the renderer's own
//! `ils` of the same frame and VPLs, and against the CPU reference's VPL irradiance on a
//! floor the application draws.

mod common;

#[path = "../examples/embed_ao/app.rs"]
mod app;

use std::sync::Arc;

use glam::{Vec3, Vec4Swizzles};
use strata_reference::vpl::{Vpl, VplSettings};
use strata_reference::Reference;
use strata_render::embed::{AoInputs, EmbeddedIls, EmbeddedIlsConfig, NormalEncoding, NormalSpace, TextureLayer};
use strata_render::packing::{oct16_pack, oct16_unpack};
use strata_render::passes::ils::{blur_weights, GpuVpl, IlsSettings, VplShadows};
use strata_render::passes::interleave::SplitMethod;
use strata_render::GpuContext;
use strata_scene::{procedural, ImageBuf};

fn gpu_vpl(v: &Vpl) -> GpuVpl {
    GpuVpl::new(v.position.into(), v.normal.into(), v.flux.into())
}

/// The embedded ILS at `w`×`h` in world space; `triangles` are the VPL shadow maps'
/// occluders (read with `shadows = vpl`), their maps reaching `occluder_margin` beyond them.
fn embedded_with_margin(
    gpu: &GpuContext,
    [w, h]: [u32; 2],
    settings: IlsSettings,
    normals: NormalEncoding,
    triangles: &[[Vec3; 3]],
    occluder_margin: f32,
) -> EmbeddedIls {
    EmbeddedIls::new(
        &gpu.adapter,
        &gpu.device,
        &gpu.queue,
        EmbeddedIlsConfig {
            width: w,
            height: h,
            settings,
            normals,
            normal_space: NormalSpace::World,
            triangles: triangles.into(),
            occluder_margin,
        },
    )
    .expect("the embedded ILS builds without validation errors")
}

/// [`embedded_with_margin`] with the default margin.
fn embedded(
    gpu: &GpuContext,
    size: [u32; 2],
    settings: IlsSettings,
    normals: NormalEncoding,
    triangles: &[[Vec3; 3]],
) -> EmbeddedIls {
    let margin = EmbeddedIlsConfig::default().occluder_margin;
    embedded_with_margin(gpu, size, settings, normals, triangles, margin)
}

/// The largest |a − b| over the rgb channels relative to b's largest value, and the share
/// of pixels whose difference exceeds 1 % of it.
fn rgb_diff(a: &ImageBuf, b: &ImageBuf) -> (f32, f32) {
    let scale = b.data.iter().cloned().fold(0.0f32, f32::max).max(1e-9);
    let (mut worst, mut over) = (0.0f32, 0usize);
    for (p, q) in a.data.chunks_exact(4).zip(b.data.chunks_exact(4)) {
        let d = (0..3).map(|c| (p[c] - q[c]).abs()).fold(0.0f32, f32::max) / scale;
        worst = worst.max(d);
        over += (d > 0.01) as usize;
    }
    (worst, over as f32 / (a.data.len() / 4) as f32)
}

/// Where the ray through the centre of pixel (x, y) of a `w`×`h` frame (view-projection
/// `view_proj`, wgpu's depth range) meets the floor y = 0, if it does within `half` of the
/// origin in x and z.
fn floor_under_pixel(view_proj: glam::Mat4, [w, h]: [u32; 2], [x, y]: [u32; 2], half: f32) -> Option<Vec3> {
    let inv = view_proj.inverse();
    let ndc = |z: f32| {
        let p = inv
            * glam::Vec4::new(
                (x as f32 + 0.5) / w as f32 * 2.0 - 1.0,
                1.0 - (y as f32 + 0.5) / h as f32 * 2.0,
                z,
                1.0,
            );
        p.xyz() / p.w
    };
    let (a, b) = (ndc(0.0), ndc(1.0));
    let t = a.y / (a.y - b.y);
    let p = a + (b - a) * t;
    (t > 0.0 && t < 1.0 && p.x.abs() < half && p.z.abs() < half).then_some(p)
}

/// The renderer's G-buffer and VPLs in, the renderer's ILS irradiance out: the same passes
/// on the same data, for the paper's blur, no blur, the brute force, `refine`, SSM's VPL
/// shadow maps of the scene's triangles, the compute and block split methods and the
/// `clean-edges` filter.
#[test]
fn embedded_ils_on_the_renderers_gbuffer_is_the_renderers() {
    let gpu = common::gpu();
    let (w, h) = (96u32, 64u32);
    for name in ["cornell", "atrium"] {
        let scene = procedural::builtin(name).unwrap();
        assert!(
            !scene.materials.iter().any(|m| m.glossy),
            "{name}: Lambert receivers only (the embedded ILS shades no glossy ones)"
        );
        let vpls: Arc<[GpuVpl]> = Reference::new(&scene, 0.0)
            .vpls(&VplSettings {
                paths: 240,
                ..Default::default()
            })
            .iter()
            .map(gpu_vpl)
            .collect();
        let base = IlsSettings {
            vpls: vpls.clone(),
            ..IlsSettings::default()
        };
        let base = IlsSettings {
            clamp_distance: Some(base.clamp_distance_for(&scene)),
            ..base
        };
        let cases = [
            ("the paper's blur", base.clone()),
            (
                "no blur",
                IlsSettings {
                    blur: 0.0,
                    ..base.clone()
                },
            ),
            (
                "brute force",
                IlsSettings {
                    brute_force: true,
                    ..base.clone()
                },
            ),
            (
                "refine 0.5",
                IlsSettings {
                    refine: 0.5,
                    ..base.clone()
                },
            ),
            (
                "VPL shadow maps (SSM)",
                IlsSettings {
                    shadows: VplShadows::ShadowMaps,
                    ..base.clone()
                },
            ),
            (
                "compute split and gather",
                IlsSettings {
                    method: SplitMethod::Compute,
                    ..base.clone()
                },
            ),
            (
                "block split (§3.3), clean-edges",
                IlsSettings {
                    method: SplitMethod::Blocks { block: 16 },
                    ..base.clone()
                }
                .with_preset("clean-edges")
                .unwrap(),
            ),
        ];
        let triangles: Vec<[Vec3; 3]> = scene.world_triangles(0.0).iter().map(|t| t.p).collect();
        for (what, settings) in cases {
            let r = common::ils_renderer(&gpu, &scene, settings.clone(), (w, h));
            // margin 0: the renderer's shadow-map range
            let mut ils = embedded_with_margin(
                &gpu,
                [w, h],
                settings.clone(),
                NormalEncoding::Octahedral,
                &triangles,
                0.0,
            );
            let (view, proj) = (scene.camera.view(), scene.camera.projection(w as f32 / h as f32));
            let (depth, normal) = (r.target_texture("depth").unwrap(), r.target_texture("normal").unwrap());
            let layer0 = |t| TextureLayer { texture: t, layer: 0 };
            common::submit_checked(&gpu, |encoder| {
                ils.encode(encoder, &AoInputs::new(layer0(depth), layer0(normal), view, proj))
                    .expect("valid inputs")
            });
            let out = settings.output().name;
            let (a, b) = (ils.read_target(out).unwrap(), r.read_target(&gpu, out).unwrap());
            let (worst, over) = rgb_diff(&a, &b);
            println!("{name}, {what} ({out}): largest difference {worst:.2e} of the image's largest, {:.2} % of pixels over 1 %", 100.0 * over);
            let lit = b.data.chunks_exact(4).filter(|p| p[0] + p[1] + p[2] > 0.0).count();
            assert!(
                lit > (w * h / 5) as usize,
                "{name}: the VPLs light the view ({lit} pixels)"
            );
            // a receiver's z differs from the renderer's by f32 rounding (measured: at most
            // 4.3e-4 of the largest value)
            assert!(
                worst < 5e-3 && over == 0.0,
                "{name}, {what}: largest difference {worst} of the image's largest, {:.2} % of pixels over 1 %",
                100.0 * over
            );
            common::check_pass_timings(&gpu, || ils.timings(), ils.pass_names(), what);
        }
    }
}

/// A floor drawn by the application (`app.rs`: standard depth, signed normals) under
/// n·m = 48 copies of one VPL, each carrying 1/48 of the flux Φ. Every sub-buffer then
/// shades one copy scaled by 48 (§4.3), so the interleaved estimate is exactly one VPL of
/// flux Φ, E(x) = Φ/π · cos θ_y cos θ_x / d² (clamped at d_c), at every pixel: the CPU
/// reference's `Vpl::irradiance_at` at the floor point under the pixel centre, with the
/// normal as the G-buffer's 8-bit Oct16 holds it. With the blur (§4.5), that E averaged
/// with the blur's weights over the pixel's window. Per pixel within 0.2 % (0.5 % with the
/// blur's bilinear taps) + 0.02 % of the largest. Then `set_vpls` moves the light, and a
/// `resize` keeps the moved one.
#[test]
fn the_interleaved_estimate_of_copies_of_one_vpl_is_its_irradiance() {
    use glam::camera::rh;
    let gpu = common::gpu();
    let (w, h) = (96u32, 64u32);
    let floor = app::cuboid(
        Vec3::new(-20.0, -0.1, -20.0),
        Vec3::new(20.0, 0.0, 20.0),
        Vec3::splat(0.5),
    );
    let eye = Vec3::new(0.0, 1.5, 2.5);
    let view = rh::view::look_at_mat4(eye, Vec3::new(0.0, 0.0, -1.0), Vec3::Y);
    let proj = rh::proj::directx::perspective(50f32.to_radians(), w as f32 / h as f32, 0.05, 100.0);
    let gbuffer = app::GBuffer::new(&gpu.device, [w, h], app::Layout::standard(), &floor);
    let light = |position: Vec3| Vpl {
        position,
        normal: Vec3::NEG_Y,
        flux: Vec3::new(4.0, 3.0, 2.0),
        albedo: Vec3::ONE,
        bounce: 1,
    };
    let copies = |v: &Vpl| -> Vec<GpuVpl> {
        let share = Vpl {
            flux: v.flux / 48.0,
            ..*v
        };
        vec![gpu_vpl(&share); 48]
    };
    let d_c = 0.05f32;
    let max_g = 1.0 / (d_c * d_c);
    // the floor point under each pixel centre, away from the floor's far edge
    let floor_point = |x: u32, y: u32| floor_under_pixel(proj * view, [w, h], [x, y], 19.5);
    let run = |ils: &mut EmbeddedIls| {
        common::submit_checked(&gpu, |e| {
            gbuffer.draw(&gpu.queue, e, view, proj);
            ils.encode(e, &gbuffer.inputs(view, proj)).unwrap();
        });
        ils.read_target(ils.config().settings.output().name).unwrap()
    };
    // the floor's normal as the G-buffer holds it: Oct16 in 8-bit channels (DGB Table 1)
    let up = oct16_unpack(oct16_pack(Vec3::Y));
    // E at every pixel's floor point (None off the floor); with the blur, E averaged with
    // the blur's own weights (`blur_weights`: Gaussian, equal per sub-buffer, §4.5) over
    // windows that lie on the floor, the others skipped
    let expected = |v: &Vpl, blur: Option<([u32; 2], [u32; 2])>| -> Vec<Option<Vec3>> {
        let e: Vec<Option<Vec3>> = (0..w * h)
            .map(|i| floor_point(i % w, i / w).map(|p| v.irradiance_at(p, up, max_g)))
            .collect();
        let Some(([rx, ry], [n, m])) = blur else { return e };
        let (wx, wy) = (
            blur_weights(rx, rx.max(1) as f32, n),
            blur_weights(ry, ry.max(1) as f32, m),
        );
        (0..w * h)
            .map(|i| {
                let (x, y) = ((i % w) as i32, (i / w) as i32);
                let (mut sum, mut total) = (Vec3::ZERO, 0.0);
                for dy in -(ry as i32)..=ry as i32 {
                    for dx in -(rx as i32)..=rx as i32 {
                        let (u, t) = (x + dx, y + dy);
                        if u < 0 || t < 0 || u >= w as i32 || t >= h as i32 {
                            return None;
                        }
                        let k = wx[dx.unsigned_abs() as usize] * wy[dy.unsigned_abs() as usize];
                        sum += e[(t as u32 * w + u as u32) as usize]? * k;
                        total += k;
                    }
                }
                Some(sum / total)
            })
            .collect()
    };
    // with the blur, pixels whose window the discontinuity test cut (the far floor, seen at
    // a grazing angle: alpha, the share of the subsets averaged, below 1) are skipped
    let check = |img: &ImageBuf, want: &[Option<Vec3>], blurred: bool, what: &str| {
        let scale = want.iter().flatten().fold(0.0f32, |a, e| a.max(e.max_element()));
        let (mut worst, mut n, mut cut) = (0.0f32, 0, 0);
        let mut worst_at = (0, Vec3::ZERO, Vec3::ZERO);
        for (i, e) in want.iter().enumerate() {
            let Some(e) = e else { continue };
            if blurred && img.data[i * 4 + 3] < 0.999 {
                cut += 1;
                continue;
            }
            let got = Vec3::from_slice(&img.data[i * 4..i * 4 + 3]);
            let err = (got - *e).abs().max_element();
            // f16 storage and the GPU's position reconstruction; the blur's bilinear taps
            // add up to 0.4 % (the bound of the ILS unit test
            // `equal_subset_weights_remove_the_interleaved_pattern`)
            let tol = if blurred { 0.005 } else { 0.002 } * e.max_element() + 2e-4 * scale;
            if err / tol > worst {
                worst = err / tol;
                worst_at = (i, got, *e);
            }
            n += 1;
            assert!(err <= tol, "{what}: pixel {i}: got {got}, want {e} (largest {scale})");
        }
        println!("{what}: {n} floor pixels ({cut} with a cut window), worst error {worst:.3} of the tolerance at {worst_at:?} (largest E {scale:.4})");
        assert!(
            n > (w * h / 2) as usize && scale > 0.0,
            "{what}: the floor fills the view and is lit"
        );
    };
    let here = light(Vec3::new(0.2, 2.5, -0.5));
    let there = light(Vec3::new(-0.6, 2.0, -1.5));
    let blur = IlsSettings::default().blur;
    for (what, blur, normals) in [
        ("no blur", 0.0, NormalEncoding::Signed),
        ("the paper's blur", blur, NormalEncoding::Signed),
        // no normal buffer: the import reconstructs the floor's normal from its depth
        ("no blur, normals from depth", 0.0, NormalEncoding::FromDepth),
    ] {
        let settings = IlsSettings {
            vpls: copies(&here).into(),
            clamp_distance: Some(d_c),
            blur,
            ..IlsSettings::default()
        };
        let window = settings.blurs().then(|| (settings.blur_radius(), settings.pattern));
        let mut ils = embedded(&gpu, [w, h], settings, normals, &[]);
        check(&run(&mut ils), &expected(&here, window), window.is_some(), what);
        // the light moves: written in place
        ils.set_vpls(&copies(&there)).unwrap();
        assert_eq!(ils.vpl_capacity(), 48);
        check(
            &run(&mut ils),
            &expected(&there, window),
            window.is_some(),
            &format!("{what}, moved"),
        );
        // a resize rebuilds from the config, which holds the moved light, not the first
        ils.resize(w, h).unwrap();
        check(
            &run(&mut ils),
            &expected(&there, window),
            window.is_some(),
            &format!("{what}, moved, resized"),
        );
    }
}

/// SSM (§4.3): a plate hangs between the VPL (48 copies, as above) and the floor. The
/// application's G-buffer holds the floor alone; the plate is among the triangles given for
/// the VPL shadow maps. Floor points whose segment to the VPL crosses the plate 5 cm or more
/// inside its outline get no light (below 0.5 % of the largest E); those whose segment
/// passes 5 cm or more outside it get the unshadowed E within 1 % + 0.05 % of the largest
/// (the maps' PCF and bias). Without the maps (SNSM) the shadowed points are lit: the
/// control. The plate then moves (in place inside the maps' box, rebuilt outside it:
/// each a fresh build's image), and `set_triangles` takes it away, and the shadow goes.
#[test]
fn vpl_shadow_maps_of_the_applications_triangles_shadow_the_floor() {
    use glam::camera::rh;
    let gpu = common::gpu();
    let (w, h) = (96u32, 64u32);
    let floor = app::cuboid(Vec3::new(-6.0, -0.1, -6.0), Vec3::new(6.0, 0.0, 6.0), Vec3::splat(0.5));
    let (lo, hi) = (Vec3::new(-0.8, 1.0, -1.6), Vec3::new(0.6, 1.02, -0.4));
    let plate = app::cuboid(lo, hi, Vec3::splat(0.5));
    let eye = Vec3::new(0.0, 0.6, 2.5);
    let view = rh::view::look_at_mat4(eye, Vec3::new(0.0, 0.0, -1.0), Vec3::Y);
    let proj = rh::proj::directx::perspective(50f32.to_radians(), w as f32 / h as f32, 0.05, 100.0);
    let gbuffer = app::GBuffer::new(&gpu.device, [w, h], app::Layout::standard(), &floor);
    let light = Vpl {
        position: Vec3::new(-0.1, 2.0, -1.0),
        normal: Vec3::NEG_Y,
        flux: Vec3::new(4.0, 3.0, 2.0),
        albedo: Vec3::ONE,
        bounce: 1,
    };
    let copies = vec![
        gpu_vpl(&Vpl {
            flux: light.flux / 48.0,
            ..light
        });
        48
    ];
    let d_c = 0.05f32;
    let up = oct16_unpack(oct16_pack(Vec3::Y));
    let floor_point = |x: u32, y: u32| floor_under_pixel(proj * view, [w, h], [x, y], 5.5);
    // where the segment from p to the VPL meets the plate's height: its distance inside
    // (> 0) or outside (< 0) the plate's outline
    let inside = |p: Vec3| {
        let q = p + (light.position - p) * ((lo.y - p.y) / (light.position.y - p.y));
        ((q.x - lo.x).min(hi.x - q.x)).min((q.z - lo.z).min(hi.z - q.z))
    };
    let world = |t: &[app::Triangle]| t.iter().map(|t| t.0).collect::<Vec<[Vec3; 3]>>();
    let mut occluders = world(&floor);
    occluders.extend(world(&plate));
    let frame = |ils: &mut EmbeddedIls| {
        common::submit_checked(&gpu, |e| {
            gbuffer.draw(&gpu.queue, e, view, proj);
            ils.encode(e, &gbuffer.inputs(view, proj)).unwrap();
        });
        ils.read_target(ils.config().settings.output().name).unwrap()
    };
    let settings = |shadows| IlsSettings {
        vpls: copies.clone().into(),
        clamp_distance: Some(d_c),
        blur: 0.0,
        shadows,
        ..IlsSettings::default()
    };
    let max_g = 1.0 / (d_c * d_c);
    let scale = (0..w * h)
        .filter_map(|i| floor_point(i % w, i / w))
        .map(|p| light.irradiance_at(p, up, max_g).max_element())
        .fold(0.0f32, f32::max);
    // (shadowed pixels' largest E, the largest error of the lit ones over their tolerance,
    // shadowed count, lit count)
    let measure = |img: &ImageBuf| {
        let (mut dark, mut worst, mut shadowed, mut lit) = (0.0f32, 0.0f32, 0, 0);
        for i in 0..(w * h) as usize {
            let Some(p) = floor_point(i as u32 % w, i as u32 / w) else {
                continue;
            };
            let got = Vec3::from_slice(&img.data[i * 4..i * 4 + 3]);
            let e = light.irradiance_at(p, up, max_g);
            match inside(p) {
                d if d > 0.05 => {
                    dark = dark.max(got.max_element());
                    shadowed += 1;
                }
                d if d < -0.05 => {
                    let tol = 0.01 * e.max_element() + 5e-4 * scale;
                    worst = worst.max((got - e).abs().max_element() / tol);
                    lit += 1;
                }
                _ => {}
            }
        }
        (dark, worst, shadowed, lit)
    };
    let mut ssm = embedded(
        &gpu,
        [w, h],
        settings(VplShadows::ShadowMaps),
        NormalEncoding::Signed,
        &occluders,
    );
    let (dark, worst, shadowed, lit) = measure(&frame(&mut ssm));
    println!("SSM: {shadowed} shadowed pixels, brightest {dark:.2e} (largest E {scale:.3}); {lit} lit, worst {worst:.3} of the tolerance");
    assert!(
        shadowed > 200 && lit > 2000,
        "the plate shadows part of the floor: {shadowed}, {lit}"
    );
    assert!(
        dark < 0.005 * scale,
        "SSM: a shadowed pixel is lit: {dark} (largest {scale})"
    );
    assert!(worst <= 1.0, "SSM: a lit pixel is off by {worst} of the tolerance");
    let mut snsm = embedded(&gpu, [w, h], settings(VplShadows::None), NormalEncoding::Signed, &[]);
    let (dark_snsm, worst_snsm, ..) = measure(&frame(&mut snsm));
    println!("SNSM: brightest shadowed pixel {dark_snsm:.3}, lit worst {worst_snsm:.3}");
    assert!(
        dark_snsm > 0.1 * scale,
        "without visibility the plate does not shadow: {dark_snsm}"
    );
    // Moving occluders. Triangles inside the box the maps were built for are written in
    // place (the same output texture: nothing was rebuilt); others rebuild. Either way the
    // output is that of a fresh EmbeddedIls built with those triangles, bit for bit.
    let before = frame(&mut ssm);
    let output = ssm.output().clone();
    let moved = |d: Vec3| {
        let mut t = world(&floor);
        t.extend(world(&plate).iter().map(|t| t.map(|p| p + d)));
        t
    };
    let fresh = |t: &[[Vec3; 3]]| {
        let mut e = embedded(
            &gpu,
            [w, h],
            settings(VplShadows::ShadowMaps),
            NormalEncoding::Signed,
            t,
        );
        frame(&mut e)
    };
    let sideways = moved(Vec3::new(0.5, 0.0, 0.3));
    ssm.set_triangles(&sideways).unwrap();
    let shifted = frame(&mut ssm);
    assert!(*ssm.output() == output, "inside the box: written in place");
    assert!(shifted.data != before.data, "the shadow moves with the plate");
    assert!(shifted.data == fresh(&sideways).data, "in place = a fresh build");
    // the plate's triangles alone, back where they were: the first image again
    ssm.set_triangle_range(floor.len(), &world(&plate)).unwrap();
    assert!(*ssm.output() == output, "a range inside the box: in place");
    assert!(
        frame(&mut ssm).data == before.data,
        "set_triangle_range restores the frame"
    );
    assert!(
        ssm.set_triangle_range(floor.len() + 1, &world(&plate)).is_err(),
        "a range past the end is refused"
    );
    // raised 0.5 m above the built box (its top is the plate's): within a margin of 0.1 ×
    // the box's 17 m diagonal it is written in place, and a fresh build of those
    // triangles (whose maps span a slightly different range) gives nearly the same image
    let raised = moved(Vec3::new(0.0, 0.5, 0.0));
    let with_margin = |t: &[[Vec3; 3]]| {
        embedded_with_margin(
            &gpu,
            [w, h],
            settings(VplShadows::ShadowMaps),
            NormalEncoding::Signed,
            t,
            0.1,
        )
    };
    let mut margin = with_margin(&occluders);
    frame(&mut margin);
    let kept = margin.output().clone();
    margin.set_triangles(&raised).unwrap();
    let high = frame(&mut margin);
    assert!(*margin.output() == kept, "within the margin: written in place");
    let (worst, over) = rgb_diff(&high, &frame(&mut with_margin(&raised)));
    println!(
        "raised within the margin: largest difference from a fresh build {worst:.2e}, {over:.4} of pixels over 1 %"
    );
    assert!(worst < 0.01, "raised in place: {worst} from a fresh build");
    // beyond the box: rebuilt, and a fresh build's image bit for bit
    let away = moved(Vec3::new(0.0, 0.5, 0.0));
    ssm.set_triangles(&away).unwrap();
    let far = frame(&mut ssm);
    assert!(*ssm.output() != output, "outside the box: rebuilt");
    assert!(far.data == fresh(&away).data, "rebuilt = a fresh build");
    // the plate taken away: the floor alone casts no shadow on itself
    ssm.set_triangles(&world(&floor)).unwrap();
    let (dark_gone, worst_gone, ..) = measure(&frame(&mut ssm));
    println!("SSM without the plate: brightest formerly shadowed pixel {dark_gone:.3}, lit worst {worst_gone:.3}");
    assert!(
        dark_gone > 0.1 * scale && worst_gone <= 1.0,
        "the shadow goes with the plate"
    );
}

/// Bad configs and VPLs are one-line errors naming the parameter; nothing panics, and a
/// refused call changes nothing.
#[test]
fn bad_embedded_ils_input_is_a_one_line_error() {
    let gpu = common::gpu();
    let one = GpuVpl::new([0.0, 1.0, 0.0], [0.0, -1.0, 0.0], [1.0; 3]);
    let good = || IlsSettings {
        vpls: vec![one; 4].into(),
        clamp_distance: Some(0.1),
        ..IlsSettings::default()
    };
    let config = |settings| EmbeddedIlsConfig {
        width: 64,
        height: 48,
        settings,
        ..EmbeddedIlsConfig::default()
    };
    let new = |c: EmbeddedIlsConfig| EmbeddedIls::new(&gpu.adapter, &gpu.device, &gpu.queue, c);
    let err = |r: Result<EmbeddedIls, strata_render::RenderError>| match r {
        Ok(_) => panic!("accepted"),
        Err(e) => e.to_string(),
    };
    let mut nan = one;
    nan.flux[1] = f32::NAN;
    let cases = [
        (
            err(new(config(IlsSettings {
                clamp_distance: None,
                ..good()
            }))),
            "settings.clamp_distance is required",
        ),
        (
            err(new(config(IlsSettings {
                shadows: VplShadows::ShadowMaps,
                ..good()
            }))),
            "settings.shadows 'vpl' needs config.triangles",
        ),
        (
            err(new(EmbeddedIlsConfig {
                triangles: vec![[Vec3::ZERO, Vec3::X, Vec3::splat(f32::INFINITY)]].into(),
                ..config(IlsSettings {
                    shadows: VplShadows::ShadowMaps,
                    ..good()
                })
            })),
            "embedded ILS: triangles[0] has a non-finite vertex",
        ),
        (
            err(new(EmbeddedIlsConfig {
                occluder_margin: -0.5,
                ..config(good())
            })),
            "embedded ILS: occluder_margin -0.5 is out of range",
        ),
        (
            err(new(config(IlsSettings {
                vpls: Vec::new().into(),
                ..good()
            }))),
            "settings.vpls is empty",
        ),
        (
            err(new(config(IlsSettings {
                vpls: vec![one, nan].into(),
                ..good()
            }))),
            "embedded ILS: vpls[1] is invalid: position, normal and flux must be finite",
        ),
        (
            err(new(config(IlsSettings {
                pattern: [0, 6],
                ..good()
            }))),
            "embedded ILS: ",
        ),
        (
            err(new(config(IlsSettings {
                clamp_distance: Some(-1.0),
                ..good()
            }))),
            "clamp-distance -1 is out of range",
        ),
        (
            err(new(EmbeddedIlsConfig {
                width: 0,
                ..config(good())
            })),
            "size 0x48 is out of range",
        ),
    ];
    for (e, want) in cases {
        println!("{e}");
        assert!(e.contains(want) && !e.contains('\n'), "'{e}' lacks '{want}'");
    }
    let mut ils = new(config(good())).unwrap();
    for (vpls, want) in [
        (Vec::new(), "set_vpls was given no VPLs"),
        (vec![one, one, nan], "embedded ILS: vpls[2] is invalid"),
    ] {
        let e = ils.set_vpls(&vpls).unwrap_err().to_string();
        println!("{e}");
        assert!(e.contains(want) && !e.contains('\n'), "'{e}' lacks '{want}'");
    }
    assert_eq!(ils.vpl_capacity(), 4);
    // fewer VPLs are written in place; more rebuild with the new count as the capacity
    ils.set_vpls(&[one; 2]).unwrap();
    assert_eq!(ils.vpl_capacity(), 4);
    ils.set_vpls(&[one; 9]).unwrap();
    assert_eq!(ils.vpl_capacity(), 9);
    // a resize keeps the VPLs; a refused one keeps the old size
    ils.resize(40, 30).unwrap();
    assert_eq!((ils.config().width, ils.vpl_capacity()), (40, 9));
    let e = ils.resize(0, 30).unwrap_err().to_string();
    assert!(e.contains("size 0x30 is out of range"), "{e}");
    assert_eq!(ils.config().width, 40);
    // one layer only
    let e = common::second_layer_error(&gpu, [40, 30], |enc, inputs| ils.encode(enc, inputs));
    assert!(e.contains("AoInputs::second is given") && !e.contains('\n'), "{e}");
    // SSM keeps a shadow-map layer per VPL: more VPLs than the device's array layers are
    // refused, at `new` and at a `set_vpls` that would rebuild, which keeps the old ones
    let layers = gpu.device.limits().max_texture_array_layers as usize;
    let quad = [[Vec3::ZERO, Vec3::X, Vec3::Z]];
    let ssm = |n: usize| EmbeddedIlsConfig {
        triangles: quad.as_slice().into(),
        ..config(IlsSettings {
            vpls: vec![one; n].into(),
            shadows: VplShadows::ShadowMaps,
            ..good()
        })
    };
    let want = format!("embedded ILS: shadows vpl needs one shadow-map layer per VPL ({} VPLs): vpls must be in 1..={layers} on this device", layers + 1);
    let e = err(new(ssm(layers + 1)));
    assert!(e.contains(&want) && !e.contains('\n'), "'{e}' lacks '{want}'");
    let mut shadowed = new(ssm(4)).unwrap();
    let e = shadowed.set_vpls(&vec![one; layers + 1]).unwrap_err().to_string();
    assert!(e.contains(&want), "'{e}' lacks '{want}'");
    assert_eq!(shadowed.vpl_capacity(), 4);
}
