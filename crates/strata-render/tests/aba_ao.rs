//! ABA multilayer AO (Algorithm 1, Eq. 3–4) over the A-buffer: the GPU equals
//! its CPU twin over the read-back lists (list walk and compressed nodes, one
//! and all layers), an unoccluded plane is 1, an occluder hidden behind the
//! first layer darkens only in multilayer AO, an α-weighted occluder darkens by
//! α × the opaque occlusion, and with α = 1 everywhere the opacity-aware AO
//! equals the opaque multilayer AO. Every frame fails on any wgpu validation
//! error (the renderer checks after each frame).

mod common;

use glam::{Mat4, Vec3};
use strata_render::frame::FrameCameras;
use strata_render::passes::abuffer::ao::{ambient_visibility_cpu, AbaAoSettings, AoKernel, Occluders};
use strata_render::passes::abuffer::{compress, ABufferMethod, ABufferSettings};
use strata_render::renderer::GuardBand;
use strata_render::{GpuContext, RenderSettings, Renderer};
use strata_scene::shapes::MeshBuilder;
use strata_scene::{ImageBuf, Material, Object, Scene};

use common::quads::{glass, quads, v};

const W: u32 = 64;
const H: u32 = 48;

fn aba(multilayer: bool, compress: Option<u32>) -> ABufferSettings {
    aba_with(ABufferMethod::LinkedList, multilayer, compress)
}

fn aba_with(method: ABufferMethod, multilayer: bool, compress: Option<u32>) -> ABufferSettings {
    ABufferSettings {
        method,
        compress,
        ao: Some(AbaAoSettings {
            multilayer,
            ..Default::default()
        }),
        ..Default::default()
    }
}

fn hbao(a: ABufferSettings) -> ABufferSettings {
    let mut a = a;
    a.ao.as_mut().unwrap().kernel = AoKernel::Hbao;
    a
}

fn render(gpu: &GpuContext, scene: &Scene, a: ABufferSettings) -> Renderer {
    render_sized(gpu, scene, a, W, H)
}

fn render_sized(gpu: &GpuContext, scene: &Scene, a: ABufferSettings, width: u32, height: u32) -> Renderer {
    let t = strata_render::technique::find("aba-ao").unwrap();
    let base = RenderSettings {
        width,
        height,
        guard_band: GuardBand::Pixels(0),
        ..Default::default()
    };
    let mut s = t.settings(&base, None).unwrap();
    s.abuffer = Some(a);
    let mut r = Renderer::new(gpu, scene, s).expect("renderer builds without validation errors");
    let timings = r
        .render(gpu, scene, &FrameCameras::fixed(scene.camera), 0.0)
        .expect("frame renders without validation errors");
    if !timings.passes.is_empty() {
        assert!(timings.get("aba-ao").is_some(), "aba-ao is timed: {timings:?}");
    }
    r
}

fn raw(gpu: &GpuContext, r: &Renderer) -> ImageBuf {
    r.read_target(gpu, "ao-raw").unwrap()
}

/// `mesh` of one quad facing `n` (±z) at depth z over x, y ranges.
fn pane(scene: &mut Scene, z: f32, [x0, x1]: [f32; 2], [y0, y1]: [f32; 2], n: Vec3, material: usize) {
    let mut b = MeshBuilder::new();
    b.quad_facing([v(x0, y0, z), v(x1, y0, z), v(x1, y1, z), v(x0, y1, z)], n);
    scene.meshes.push(b.build("pane", material));
    scene.objects.push(Object {
        name: "pane".into(),
        mesh: scene.meshes.len() - 1,
        transform: Mat4::IDENTITY,
        animation: None,
    });
}

/// An opaque plane at z = 0 with panes of every kind in front of it: an
/// opaque box-like occluder, transparent panes (front- and back-facing), so
/// receivers, occluders and the blend all take part.
fn mixed() -> Scene {
    let materials = vec![
        Material::diffuse("plane", [0.6, 0.6, 0.6]),
        Material::diffuse("block", [0.5, 0.4, 0.3]),
        glass("red", [0.9, 0.1, 0.1], 0.5),
        glass("blue", [0.1, 0.2, 0.9], 0.25),
    ];
    let mut s = quads(
        materials,
        &[
            (0.0, [-20.0, 20.0], [-20.0, 20.0], 0),
            (0.4, [-0.9, -0.2], [-0.6, 0.5], 1),
            (0.25, [-0.3, 1.1], [-1.0, 0.2], 2),
        ],
    );
    pane(&mut s, 0.6, [0.2, 1.4], [-0.2, 0.9], -Vec3::Z, 3);
    s.settings.ao_radius = 0.8;
    s
}

#[test]
fn gpu_multilayer_ao_equals_the_cpu_twin_of_algorithm_1() {
    let gpu = common::gpu();
    let scene = mixed();
    let mut cases: Vec<_> = ABufferMethod::ALL.iter().map(|&m| (m, true, None)).collect();
    cases.extend([
        (ABufferMethod::LinkedList, false, None),
        (ABufferMethod::Linear, true, Some(6)),
        (ABufferMethod::FixedArray, false, Some(4)),
    ]);
    let mut cases: Vec<_> = cases.into_iter().map(|(m, ml, c)| (m, ml, c, AoKernel::Ssao)).collect();
    cases.extend([
        (ABufferMethod::LinkedList, true, None, AoKernel::Hbao),
        (ABufferMethod::LinkedList, false, None, AoKernel::Hbao),
        (ABufferMethod::Linear, true, Some(6), AoKernel::Hbao),
    ]);
    for (method, multilayer, compress, kernel) in cases {
        let mut settings = aba_with(method, multilayer, compress);
        settings.ao.as_mut().unwrap().kernel = kernel;
        let r = render(&gpu, &scene, settings);
        let ab = r.abuffer().unwrap();
        let lists = ab.read_lists(&gpu).unwrap();
        assert_eq!(lists.overflow, 0);
        let nodes = ab.read_compressed(&gpu).unwrap();
        let normals = ab.read_compressed_normals(&gpu).unwrap();
        let occ = match (&nodes, &normals) {
            (Some(n), Some(nf)) => Occluders::Compressed {
                nodes: n,
                normals: nf,
                depth_scale: ab.depth_scale(),
            },
            _ => Occluders::Lists,
        };
        if let (Some(nodes), Some(normals)) = (&nodes, &normals) {
            // every kept node carries the normal and facing of its fragment
            let scale = ab.depth_scale();
            for (p, (ns, nfs)) in nodes.iter().zip(normals).enumerate() {
                for (&word, &nf) in ns.iter().zip(nfs) {
                    if word & 0xffff == 0 {
                        continue;
                    }
                    let f = lists.lists[p]
                        .iter()
                        .find(|f| {
                            compress::quantise_depth(f.depth, scale) == word >> 16
                                && compress::quantise_alpha(f.alpha) == word & 0xffff
                        })
                        .expect("a kept node is one of the pixel's fragments");
                    let n = strata_render::packing::oct16_unpack([nf as u8, (nf >> 8) as u8]);
                    assert_eq!(n.to_array(), f.normal, "pixel {p}: node normal");
                    assert_eq!((nf >> 16) & 1 == 1, f.front_facing, "pixel {p}: node facing");
                }
            }
        }
        let u = ab.ao_uniforms().expect("AO uniforms were set");
        let frame = r.frame_uniforms();
        let gpu_av = raw(&gpu, &r);
        let (mut worst, mut sum, mut dark) = (0.0f32, 0.0f64, 0);
        for y in 0..H {
            for x in 0..W {
                let want = ambient_visibility_cpu(&lists, &occ, &frame, &u, x, y);
                let got = gpu_av.pixel(x, y)[0];
                let d = (got - want).abs();
                worst = worst.max(d);
                sum += d as f64;
                dark += (want < 0.9) as u32;
                assert!(
                    d < 2e-3,
                    "{method} {kernel:?} multilayer={multilayer} compress={compress:?}: pixel ({x}, {y}) GPU {got} vs CPU {want}"
                );
            }
        }
        let mean = sum / (W * H) as f64;
        eprintln!("{method} {kernel:?} multilayer={multilayer} compress={compress:?}: |GPU − CPU| max {worst:.2e}, mean {mean:.2e}, {dark} pixels below 0.9");
        assert!(mean < 1e-4, "mean difference {mean}");
        assert!(dark > 50, "the scene occludes: {dark} pixels below 0.9");
    }
}

#[test]
fn an_unoccluded_plane_is_one() {
    let gpu = common::gpu();
    let scene = quads(
        vec![Material::diffuse("plane", [0.6, 0.6, 0.6])],
        &[(0.0, [-20.0, 20.0], [-20.0, 20.0], 0)],
    );
    for compress in [None, Some(6)] {
        let av = raw(&gpu, &render(&gpu, &scene, aba(true, compress)));
        assert!(
            av.data.iter().all(|&a| a == 1.0),
            "compress={compress:?}: min AV {}",
            av.data.iter().cloned().fold(1.0, f32::min)
        );
    }
}

/// A plane at z = 0 (visible left of x = 0), an occluder at z = 0.3 over
/// x ∈ [0, 2] and an opaque pane at z = 2.5 over x ∈ [0, 4] that hides the
/// occluder from the camera (both project right of the image's centre column).
fn hidden_occluder() -> Scene {
    let m = vec![
        Material::diffuse("plane", [0.6, 0.6, 0.6]),
        Material::diffuse("occluder", [0.5, 0.5, 0.5]),
        Material::diffuse("pane", [0.7, 0.7, 0.7]),
    ];
    let mut s = quads(
        m,
        &[
            (0.0, [-20.0, 20.0], [-20.0, 20.0], 0),
            (0.3, [0.0, 2.0], [-2.0, 2.0], 1),
            (2.5, [0.0, 4.0], [-4.0, 4.0], 2),
        ],
    );
    s.settings.ao_radius = 1.0;
    s
}

#[test]
fn an_occluder_hidden_behind_the_first_layer_darkens_only_multilayer_ao() {
    let gpu = common::gpu();
    let scene = hidden_occluder();
    for (multi, single) in [
        (aba(true, None), aba(false, None)),
        (hbao(aba(true, None)), hbao(aba(false, None))),
    ] {
        let kernel = multi.ao.as_ref().unwrap().kernel;
        let multi = raw(&gpu, &render(&gpu, &scene, multi));
        let single = raw(&gpu, &render(&gpu, &scene, single));
        hidden_occluder_darkens(&multi, &single, kernel);
    }
}

fn hidden_occluder_darkens(multi: &ImageBuf, single: &ImageBuf, kernel: AoKernel) {
    // receivers on the plane next to the hidden occluder (left of the centre)
    let near: Vec<(u32, u32)> = (0..H).flat_map(|y| (W / 2 - 4..W / 2).map(move |x| (x, y))).collect();
    let mut darker = 0;
    for &(x, y) in &near {
        let (m, s) = (multi.pixel(x, y)[0], single.pixel(x, y)[0]);
        assert!(m <= s + 1e-6, "{kernel:?} ({x}, {y}): multilayer {m} > single {s}");
        // the single layer sees only the plane and the far pane: unoccluded
        assert_eq!(s, 1.0, "({x}, {y}): single-layer AO sees no occluder");
        darker += (m < s - 0.05) as u32;
    }
    assert!(
        darker as usize > near.len() / 2,
        "{kernel:?}: {darker} of {} receivers darkened",
        near.len()
    );
    // far from the occluder (taps reach ≈ 12 px) both see one layer: equal
    for y in 0..H {
        for x in 0..W / 2 - 16 {
            assert_eq!(multi.pixel(x, y)[0], single.pixel(x, y)[0], "({x}, {y})");
        }
    }
}

#[test]
fn an_alpha_weighted_occluder_darkens_by_alpha_times_the_opaque_occlusion() {
    let gpu = common::gpu();
    // the occluder of `hidden_occluder` without the pane, opaque or α = 0.5
    let scene = |alpha: f32| {
        let mut s = quads(
            vec![
                Material::diffuse("plane", [0.6, 0.6, 0.6]),
                glass("occluder", [0.5, 0.5, 0.5], alpha),
            ],
            &[
                (0.0, [-20.0, 20.0], [-20.0, 20.0], 0),
                (0.3, [0.0, 2.0], [-2.0, 2.0], 1),
            ],
        );
        s.settings.ao_radius = 1.0;
        s
    };
    let alpha = 0.5f32;
    for (kernel, compress) in [
        (AoKernel::Ssao, None),
        (AoKernel::Ssao, Some(6)),
        (AoKernel::Hbao, None),
        (AoKernel::Hbao, Some(6)),
        (AoKernel::HbaoCompute, Some(6)),
    ] {
        let settings = || {
            let mut a = aba(true, compress);
            a.ao.as_mut().unwrap().kernel = kernel;
            a
        };
        let opaque = raw(&gpu, &render(&gpu, &scene(1.0), settings()));
        let half = raw(&gpu, &render(&gpu, &scene(alpha), settings()));
        // the kernel's sum of per-tap (SSAO) or per-direction (HBAO)
        // occlusion, which Algorithm 1 makes linear in the occluder's α: DGB
        // Eq. 1's S = (1 − AV)²·N/π, HBAO's 1 − AV
        let sum = |av: f32| match kernel {
            AoKernel::Ssao => (1.0 - av).powi(2),
            AoKernel::Hbao | AoKernel::HbaoCompute => 1.0 - av,
        };
        let mut checked = 0;
        // receivers on the plane left of the occluder (they see no pane)
        for y in 0..H {
            for x in 0..W / 2 - 1 {
                let s1 = sum(opaque.pixel(x, y)[0]);
                let sa = sum(half.pixel(x, y)[0]);
                if s1 > 1e-3 {
                    checked += 1;
                    assert!(
                        (sa - alpha * s1).abs() <= 1e-3 * s1 + 1e-6,
                        "{kernel:?} compress={compress:?} ({x}, {y}): S_α {sa} vs α·S_1 {}",
                        alpha * s1
                    );
                } else {
                    assert!(sa <= 1e-3, "({x}, {y}): unoccluded when opaque, occluded at α");
                }
            }
        }
        assert!(checked > 50, "{kernel:?}: {checked} occluded receivers");
    }
}

#[test]
fn with_alpha_one_everywhere_the_opacity_aware_ao_is_the_opaque_multilayer_ao() {
    // opaque Algorithm 1 written out without opacity: the nearest fragment is
    // the receiver (exterior hemisphere only), and every fragment of a tap
    // pixel occludes with weight 1 (DGB Eq. 1's max over layers)
    use strata_render::passes::ao::{obscurance, world_from_csz, AoUniforms};
    use strata_render::spiral;
    let gpu = common::gpu();
    let scene = hidden_occluder();
    let r = render(&gpu, &scene, aba(true, None));
    let ab = r.abuffer().unwrap();
    let lists = ab.read_lists(&gpu).unwrap();
    let u = ab.ao_uniforms().unwrap();
    let frame = r.frame_uniforms();
    let got = raw(&gpu, &r);
    assert!(lists.lists.iter().flatten().all(|f| f.alpha == 1.0 && f.front_facing));
    let eq2 = AoUniforms {
        radius: u.radius,
        bias: u.bias,
        epsilon: u.epsilon,
        ..bytemuck::Zeroable::zeroed()
    };
    let mut occluded = 0;
    for y in 0..H {
        for x in 0..W {
            let f = lists.at(x, y)[0];
            let pos = world_from_csz(&frame, [x as f32 + 0.5, y as f32 + 0.5], f.depth);
            let n = Vec3::from(f.normal);
            let phi = spiral::pixel_angle(x, y, u.seed);
            let r_p = u.proj_scale * u.radius / f.depth;
            let mut sum = 0.0f32;
            for i in 0..u.samples {
                let d = spiral::tap_texel(spiral::spiral_tap(i, u.samples, u.tau, r_p, phi).offset);
                let (qx, qy) = (x as i32 + d[0], y as i32 + d[1]);
                if qx < 0 || qy < 0 || qx >= W as i32 || qy >= H as i32 {
                    continue;
                }
                let c = [qx as f32 + 0.5, qy as f32 + 0.5];
                sum += lists
                    .at(qx as u32, qy as u32)
                    .iter()
                    .map(|g| obscurance(&eq2, world_from_csz(&frame, c, g.depth) - pos, n))
                    .fold(0.0, f32::max);
            }
            let want = (1.0 - (u.intensity * std::f32::consts::PI / u.samples as f32 * sum).sqrt()).max(0.0);
            let have = got.pixel(x, y)[0];
            occluded += (want < 0.95) as u32;
            assert!((have - want).abs() < 2e-3, "({x}, {y}): {have} vs opaque {want}");
        }
    }
    assert!(occluded > 50, "{occluded} occluded pixels");
}

#[test]
fn ao_inside_the_blend_and_separate_equal_their_cpu_twins_and_stay_close() {
    use strata_render::passes::abuffer::ao::integrate_cpu;
    let gpu = common::gpu();
    let scene = mixed();
    let mut a = aba(true, None);
    a.ao.as_mut().unwrap().inside = true;
    let r = render(&gpu, &scene, a);
    let ab = r.abuffer().unwrap();
    let lists = ab.read_lists(&gpu).unwrap();
    let (u, frame) = (ab.ao_uniforms().unwrap(), r.frame_uniforms());
    let inside = r.read_target(&gpu, "hdr-aba-inside").unwrap();
    let separate = r.read_target(&gpu, "hdr-aba-separate").unwrap();
    let av = raw(&gpu, &r);
    let (mut diff, mut n) = (0.0f64, 0);
    for y in 0..H {
        for x in 0..W {
            let want = integrate_cpu(&lists, &Occluders::Lists, &frame, &u, x, y);
            assert!((av.pixel(x, y)[0] - want.av).abs() < 2e-3, "({x}, {y}) AV");
            for c in 0..3 {
                let (gi, gs) = (inside.pixel(x, y)[c], separate.pixel(x, y)[c]);
                assert!(
                    (gi - want.inside[c]).abs() <= 2e-3 * want.inside[c].abs().max(1.0),
                    "({x}, {y}) inside {gi} vs {}",
                    want.inside[c]
                );
                assert!(
                    (gs - want.separate[c]).abs() <= 2e-3 * want.separate[c].abs().max(1.0),
                    "({x}, {y}) separate {gs} vs {}",
                    want.separate[c]
                );
                diff += (gi - gs).abs() as f64 / gi.abs().max(1e-3) as f64;
                n += 1;
            }
        }
    }
    // one opaque fragment per pixel makes the two equal; across panes they
    // differ by how each layer's own AO weights its own colour
    let mean = diff / n as f64;
    eprintln!("mean relative |inside − separate| {mean:.4}");
    assert!(mean > 0.0 && mean < 0.1, "mean relative difference {mean}");
    // with compression on, the inside variant still walks the lists (the nodes
    // hold no colour): the same images
    let mut c = aba(true, Some(6));
    c.ao.as_mut().unwrap().inside = true;
    let rc = render(&gpu, &scene, c);
    assert_eq!(rc.abuffer().unwrap().ao_uniforms().unwrap().compressed, 0);
    assert_eq!(rc.read_target(&gpu, "hdr-aba-inside").unwrap().data, inside.data);
}

// --- compute-shader multilayer HBAO (ABA §V-B)

fn hbao_compute(multilayer: bool, compress: u32) -> ABufferSettings {
    let mut a = aba(multilayer, Some(compress));
    a.ao.as_mut().unwrap().kernel = AoKernel::HbaoCompute;
    a
}

/// Pixel (x, y) lies on the border of its 8×8 workgroup tile.
fn tile_border(x: u32, y: u32) -> bool {
    let t = strata_render::passes::abuffer::ao::TILE;
    x.is_multiple_of(t) || x % t == t - 1 || y.is_multiple_of(t) || y % t == t - 1
}

/// Renders `a` and compares `ao-raw` with the CPU twin over the read-back
/// compressed nodes at every pixel; returns the image, the uniforms, the
/// worst difference overall and on tile borders, the border pixels below 0.98
/// and the pixels whose HBAO steps reach past the staged apron.
fn compute_vs_twin(gpu: &GpuContext, scene: &Scene, a: ABufferSettings) -> (ImageBuf, f32, f32, u32, u32) {
    compute_vs_twin_sized(gpu, scene, a, W, H)
}

fn compute_vs_twin_sized(
    gpu: &GpuContext,
    scene: &Scene,
    a: ABufferSettings,
    w: u32,
    h: u32,
) -> (ImageBuf, f32, f32, u32, u32) {
    let r = render_sized(gpu, scene, a, w, h);
    let ab = r.abuffer().unwrap();
    let lists = ab.read_lists(gpu).unwrap();
    assert_eq!(lists.overflow, 0);
    let nodes = ab.read_compressed(gpu).unwrap().expect("hbao-compute compresses");
    let normals = ab.read_compressed_normals(gpu).unwrap().unwrap();
    let occ = Occluders::Compressed {
        nodes: &nodes,
        normals: &normals,
        depth_scale: ab.depth_scale(),
    };
    let u = ab.ao_uniforms().unwrap();
    assert_eq!(u.kernel, AoKernel::HbaoCompute as u32);
    assert_eq!((u.directions, u.rotate), (4, 0), "compute HBAO: the axis directions");
    assert!(u.apron > 0);
    let frame = r.frame_uniforms();
    let got = raw(gpu, &r);
    let (mut worst, mut worst_border, mut border_dark, mut beyond) = (0.0f32, 0.0f32, 0, 0);
    assert_eq!((got.width, got.height), (w, h));
    let max_ulps = if common::cpu_adapter(gpu) { 0 } else { 4 };
    for y in 0..h {
        for x in 0..w {
            let want = ambient_visibility_cpu(&lists, &occ, &frame, &u, x, y);
            let have = got.pixel(x, y)[0];
            let d = (have - want).abs();
            // the same f32 operations in the same order: bit for bit on lavapipe; a GPU
            // driver may contract a*b+c into one fma or round a division differently
            // (NVIDIA 580: 1 ulp at a few pixels), so elsewhere a few ulps
            let ulps = (have.to_bits() as i64 - want.to_bits() as i64).unsigned_abs();
            assert!(
                ulps <= max_ulps,
                "({x}, {y}): GPU {have} vs CPU twin {want}: {ulps} ulps apart (at most {max_ulps} on this adapter)"
            );
            worst = worst.max(d);
            if tile_border(x, y) {
                worst_border = worst_border.max(d);
                border_dark += (want < 0.98) as u32;
            }
            // the farthest step r_p (S − ½)/S of the nearest receiver, against the apron
            if let Some(f) = lists.at(x, y).first() {
                let r_p = u.proj_scale * u.radius / f.depth;
                let reach = (r_p * (u.steps as f32 - 0.5) / u.steps as f32 + 0.5).floor() as u32;
                beyond += (reach > u.apron) as u32;
            }
        }
    }
    (got, worst, worst_border, border_dark, beyond)
}

#[test]
fn compute_hbao_equals_its_cpu_twin_also_on_tile_borders_and_past_the_apron() {
    let gpu = common::gpu();
    let mixed = mixed();
    let mut big = hidden_occluder();
    // r_p ≈ 3× the scene's: steps reach past the staged apron (global reads)
    big.settings.ao_radius = 3.0;
    for (name, scene, multilayer, m) in [
        ("mixed", &mixed, true, 6),
        ("mixed", &mixed, false, 6),
        ("mixed", &mixed, true, 3),
        ("hidden", &hidden_occluder(), true, 6),
        ("hidden r=3", &big, true, 6),
        ("hidden r=3", &big, false, 6),
    ] {
        let (img, worst, worst_border, border_dark, beyond) = compute_vs_twin(&gpu, scene, hbao_compute(multilayer, m));
        let dark = img.data.iter().filter(|&&a| a < 0.98).count();
        eprintln!(
            "{name} multilayer={multilayer} M={m}: |GPU − twin| max {worst:.2e} (tile borders {worst_border:.2e}), \
             {dark} pixels < 0.98 ({border_dark} tile-border pixels < 0.98), {beyond} receivers reach past the apron"
        );
        assert!(dark > 50, "{name}: the scene occludes ({dark} pixels below 0.98)");
        // border pixels take occluders from the neighbouring tiles' apron
        assert!(border_dark > 20, "{name}: {border_dark} occluded tile-border pixels");
        if name.ends_with("r=3") {
            assert!(
                beyond > 100,
                "{name}: only {beyond} receivers exercise the global fallback"
            );
        }
        if m == 3 {
            // every tap inside the staged tile + apron: workgroup memory alone
            assert_eq!(beyond, 0, "{name} M=3: the apron covers every step");
        }
    }
}

#[test]
fn compute_hbao_equals_its_twin_on_partial_tiles_of_an_odd_sized_image() {
    // 61×45: the last tile column and row are partial (5 of 8 pixels); their
    // invocations outside the image stage but write nothing, and the apron of
    // the edge tiles is cut by the image border
    let gpu = common::gpu();
    let mut scene = hidden_occluder();
    scene.settings.ao_radius = 3.0;
    for multilayer in [true, false] {
        let (img, worst, _, _, _) = compute_vs_twin_sized(&gpu, &scene, hbao_compute(multilayer, 6), 61, 45);
        // pixels of the partial tiles: x ≥ 56 or y ≥ 40
        let partial = (0..45u32)
            .flat_map(|y| (0..61u32).map(move |x| (x, y)))
            .filter(|&(x, y)| x >= 56 || y >= 40);
        let dark = partial.filter(|&(x, y)| img.pixel(x, y)[0] < 0.98).count();
        eprintln!(
            "61×45 multilayer={multilayer}: max |GPU − twin| {worst:.1e}, {dark} occluded pixels in the partial tiles"
        );
        assert!(dark > 5, "the partial tiles hold occluded pixels: {dark}");
    }
}

#[test]
fn compute_hbao_of_an_unoccluded_plane_is_one() {
    let gpu = common::gpu();
    let scene = quads(
        vec![Material::diffuse("plane", [0.6, 0.6, 0.6])],
        &[(0.0, [-20.0, 20.0], [-20.0, 20.0], 0)],
    );
    for multilayer in [true, false] {
        let av = raw(&gpu, &render(&gpu, &scene, hbao_compute(multilayer, 6)));
        assert!(
            av.data.iter().all(|&a| a == 1.0),
            "multilayer={multilayer}: min AV {}",
            av.data.iter().cloned().fold(1.0, f32::min)
        );
    }
}

#[test]
fn compute_hbao_with_one_layer_equals_single_layer_compute_hbao() {
    // M = 1 without the back-half search keeps each pixel's nearest node
    // (opaque: Eq. 5 evicts the farthest), so Algorithm 1 over one layer is
    // the single-layer kernel over M = 6 bit for bit; M = 6 differs (hidden occluder)
    let gpu = common::gpu();
    let mut scene = hidden_occluder();
    // r = 3 reaches from the plane to the visible pane's edge (single-layer occlusion)
    scene.settings.ao_radius = 3.0;
    let mut one = hbao_compute(true, 1);
    one.compress_back_half = false;
    let one = raw(&gpu, &render(&gpu, &scene, one));
    let single = raw(&gpu, &render(&gpu, &scene, hbao_compute(false, 6)));
    let multi = raw(&gpu, &render(&gpu, &scene, hbao_compute(true, 6)));
    assert_eq!(one.data, single.data, "one stored layer = single-layer compute HBAO");
    let occluded = single.data.iter().filter(|&&a| a < 0.99).count();
    assert!(
        occluded > 50,
        "{occluded} occluded pixels (the pane's edge over the plane)"
    );
    assert_ne!(multi.data, single.data, "six layers see the hidden occluder");
}

#[test]
fn compute_hbao_an_occluder_hidden_behind_the_first_layer_darkens_only_multilayer() {
    let gpu = common::gpu();
    let scene = hidden_occluder();
    let multi = raw(&gpu, &render(&gpu, &scene, hbao_compute(true, 6)));
    let single = raw(&gpu, &render(&gpu, &scene, hbao_compute(false, 6)));
    hidden_occluder_darkens(&multi, &single, AoKernel::HbaoCompute);
}

#[test]
fn compute_hbao_settings_are_range_checked_with_one_line_errors() {
    let t = strata_render::technique::find("aba-ao").unwrap();
    let mut s = t.settings(&RenderSettings::default(), None).unwrap();
    t.set(&mut s, "kernel", 2.0).unwrap();
    assert_eq!(
        s.abuffer.as_ref().unwrap().ao.as_ref().unwrap().kernel,
        AoKernel::HbaoCompute
    );
    s.validate().expect("hbao-compute with the default compress = 6");
    let e = t.set(&mut s, "kernel", 3.0).unwrap_err().to_string();
    assert!(e.contains("kernel") && !e.contains('\n'), "{e}");
    s.abuffer.as_mut().unwrap().compress = None;
    let e = s.validate().unwrap_err().to_string();
    assert!(
        e.contains("hbao-compute") && e.contains("compress") && !e.contains('\n'),
        "{e}"
    );
    s.abuffer.as_mut().unwrap().compress = Some(6);
    s.abuffer.as_mut().unwrap().ao.as_mut().unwrap().inside = true;
    let e = s.validate().unwrap_err().to_string();
    assert!(e.contains("hbao-compute") && !e.contains('\n'), "{e}");
}

/// `a` with the multi-resolution AO on `levels` levels (ABA Table II).
fn multires(a: ABufferSettings, levels: u32) -> ABufferSettings {
    let mut a = a;
    a.ao.as_mut().unwrap().levels = levels;
    a
}

/// Multi-resolution AO (4 levels): the GPU equals the CPU twin over the
/// read-back lists / compressed nodes, for list walks and compressed nodes,
/// Poisson (spiral) and HBAO kernels.
#[test]
fn gpu_multires_ao_equals_the_cpu_twin() {
    let gpu = common::gpu();
    let scene = mixed();
    let cases = [
        (aba_with(ABufferMethod::LinkedList, true, None), "linked-list"),
        (aba_with(ABufferMethod::FixedArray, true, None), "fixed-array"),
        (aba_with(ABufferMethod::Linear, true, Some(6)), "linear compress=6"),
        (
            hbao(aba_with(ABufferMethod::LinkedList, true, None)),
            "linked-list hbao",
        ),
    ];
    for (settings, name) in cases {
        let r = render(&gpu, &scene, multires(settings, 4));
        let ab = r.abuffer().unwrap();
        let lists = ab.read_lists(&gpu).unwrap();
        assert_eq!(lists.overflow, 0);
        let nodes = ab.read_compressed(&gpu).unwrap();
        let normals = ab.read_compressed_normals(&gpu).unwrap();
        let occ = match (&nodes, &normals) {
            (Some(n), Some(nf)) => Occluders::Compressed {
                nodes: n,
                normals: nf,
                depth_scale: ab.depth_scale(),
            },
            _ => Occluders::Lists,
        };
        let u = ab.ao_uniforms().expect("AO uniforms were set");
        assert_eq!(u.levels, 4, "{name}: the uniforms carry the levels");
        let frame = r.frame_uniforms();
        let gpu_av = raw(&gpu, &r);
        let (mut worst, mut sum, mut dark) = (0.0f32, 0.0f64, 0);
        for y in 0..H {
            for x in 0..W {
                let want = ambient_visibility_cpu(&lists, &occ, &frame, &u, x, y);
                let got = gpu_av.pixel(x, y)[0];
                let d = (got - want).abs();
                worst = worst.max(d);
                sum += d as f64;
                dark += (want < 0.9) as u32;
                assert!(d < 2e-3, "{name} multires=4: pixel ({x}, {y}) GPU {got} vs CPU {want}");
            }
        }
        let mean = sum / (W * H) as f64;
        eprintln!("{name} multires=4: |GPU − CPU| max {worst:.2e}, mean {mean:.2e}, {dark} pixels below 0.9");
        assert!(mean < 1e-4, "mean difference {mean}");
        assert!(dark > 50, "the scene occludes: {dark} pixels below 0.9");
    }
}

/// With 4 levels an unoccluded plane still has AV exactly 1 (every level's
/// taps read nodes on the plane itself: Eq. 2's bias keeps them at 0).
#[test]
fn multires_keeps_an_unoccluded_plane_at_one() {
    let gpu = common::gpu();
    let scene = quads(
        vec![Material::diffuse("plane", [0.6, 0.6, 0.6])],
        &[(0.0, [-20.0, 20.0], [-20.0, 20.0], 0)],
    );
    for a in [aba(true, None), aba(true, Some(6)), hbao(aba(true, None))] {
        let av = raw(&gpu, &render(&gpu, &scene, multires(a, 4)));
        assert!(
            av.data.iter().all(|&a| a == 1.0),
            "min AV {}",
            av.data.iter().cloned().fold(1.0, f32::min)
        );
    }
}

/// One level (level 0 only) is today's single-resolution AO bit for bit, and
/// 4 levels change the image (the coarse levels reach farther, the fine are capped).
#[test]
fn multires_level_zero_only_is_the_single_resolution_ao() {
    let gpu = common::gpu();
    let scene = mixed();
    for (a, compress) in [(aba(true, None), None), (aba(true, Some(6)), Some(6))] {
        assert_eq!(AbaAoSettings::default().levels, 1, "off by default");
        let today = raw(&gpu, &render(&gpu, &scene, a.clone()));
        let one = raw(&gpu, &render(&gpu, &scene, multires(a.clone(), 1)));
        assert_eq!(today.data, one.data, "compress={compress:?}: multires=1 is today's AO");
        let four = raw(&gpu, &render(&gpu, &scene, multires(a, 4)));
        let differ = today
            .data
            .iter()
            .zip(&four.data)
            .filter(|(a, b)| (*a - *b).abs() > 1e-3)
            .count();
        assert!(differ > 20, "compress={compress:?}: 4 levels change {differ} pixels");
    }
    assert_eq!(strata_render::passes::abuffer::ao::level_radius(37.5, 0, 1), 37.5);
    assert_eq!(strata_render::passes::abuffer::ao::level_radius(37.5, 0, 4), 5.0);
    assert_eq!(strata_render::passes::abuffer::ao::level_radius(37.5, 3, 4), 37.5 / 8.0);
}

/// `multires` is a registry setting with a one-line range error, and the
/// compute HBAO (one staged resolution) refuses it.
#[test]
fn multires_setting_range_and_kernel_errors() {
    let t = strata_render::technique::find("aba-ao").unwrap();
    let mut s = t.settings(&RenderSettings::default(), None).unwrap();
    t.set(&mut s, "multires", 4.0).unwrap();
    assert_eq!(s.abuffer.as_ref().unwrap().ao.as_ref().unwrap().levels, 4);
    for bad in [0.0, 5.0] {
        let e = t.set(&mut s, "multires", bad).unwrap_err().to_string();
        assert!(e.contains("multires") && !e.contains('\n'), "{e}");
    }
    let mut a = multires(aba(true, Some(4)), 4);
    a.ao.as_mut().unwrap().kernel = AoKernel::HbaoCompute;
    let e = a.validate().unwrap_err();
    assert!(e.contains("multires") && !e.contains('\n'), "{e}");
    let mut a = multires(aba(true, None), 5);
    let e = a.validate().unwrap_err();
    assert!(e.contains("multires") && !e.contains('\n'), "{e}");
    a.ao.as_mut().unwrap().levels = 2;
    a.validate().unwrap();
}
