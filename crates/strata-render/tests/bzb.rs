//! Bounced z-buffer AO (BZB §3 with AOV splats): the GPU's directions against
//! their CPU twin and the pdf, the splat pass's bounced z-buffer against a CPU
//! nearest-hit search over the same rays, draw-order independence, the
//! unoccluded plane, and visibility against the ray-traced binary AO.

mod common;

use glam::{Mat4, Vec3};
use strata_reference::ao::AoBinarySettings;
use strata_reference::Reference;
use strata_render::frame::FrameCameras;
use strata_render::passes::bzb::{self, BzbSettings, Hemisphere};
use strata_render::{GpuContext, RenderSettings, Renderer};
use strata_scene::model::Object;
use strata_scene::{procedural, Camera, ImageBuf, Scene};

const W: u32 = 64;
const H: u32 = 48;

/// A scene of quads (corner, edge u, edge v; front face = u × v), one grey material.
fn quads_scene(name: &str, quads: &[(Vec3, Vec3, Vec3)], camera: Camera, ao_radius: f32) -> Scene {
    let corners: Vec<[Vec3; 4]> = quads.iter().map(|&(c, u, v)| [c, c + u, c + u + v, c + v]).collect();
    let polygons: Vec<&[Vec3]> = corners.iter().map(|p| p.as_slice()).collect();
    common::polygons_scene(name, &polygons, camera, ao_radius)
}

/// A floor (y = 0) with a stack of `plates` parallel vertical plates standing on
/// it, 0.15 apart behind z = 0, seen from the front and above: floor pixels in
/// front of the stack look at occluders behind each other.
fn plate_stack(plates: usize) -> Scene {
    let mut quads = vec![(
        Vec3::new(-3.0, 0.0, 3.0),
        Vec3::new(6.0, 0.0, 0.0),
        Vec3::new(0.0, 0.0, -6.0),
    )];
    for k in 0..plates {
        let z = -0.15 * k as f32;
        quads.push((
            Vec3::new(-1.5, 0.0, z),
            Vec3::new(3.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        ));
    }
    let camera = Camera::new(Vec3::new(0.0, 2.0, 2.6), Vec3::new(0.0, 0.1, -0.2), Vec3::Y, 50.0, 0.05);
    quads_scene("plate-stack", &quads, camera, 1.0)
}

/// Large tilted quads seen at a grazing angle, one crossing the near plane (the box
/// splats' rectangle fallback).
fn tilted_quads() -> Scene {
    let camera = Camera::new(Vec3::new(0.0, 0.6, 2.0), Vec3::new(0.0, 0.0, -1.0), Vec3::Y, 60.0, 0.05);
    let quads = [
        // the floor, seen at a grazing angle
        (
            Vec3::new(-4.0, 0.0, 3.0),
            Vec3::new(8.0, 0.0, 0.0),
            Vec3::new(0.0, 0.0, -9.0),
        ),
        // a plate rotated about two axes, standing on it
        (
            Vec3::new(-1.2, 0.0, -0.5),
            Vec3::new(1.6, 0.3, -0.9),
            Vec3::new(0.2, 1.1, 0.3),
        ),
        // a long thin sliver across the view
        (
            Vec3::new(-3.0, 0.05, -1.0),
            Vec3::new(6.0, 0.4, 0.5),
            Vec3::new(0.0, 0.02, 0.06),
        ),
        // a panel passing beside the camera, through its near plane
        (
            Vec3::new(0.4, 0.1, 2.5),
            Vec3::new(0.0, 0.0, -2.0),
            Vec3::new(0.3, 0.8, 0.0),
        ),
    ];
    quads_scene("tilted", &quads, camera, 0.6)
}

fn settings(b: BzbSettings) -> RenderSettings {
    RenderSettings {
        width: W,
        height: H,
        shade: false,
        bzb: Some(b),
        ..Default::default()
    }
}

fn render(gpu: &GpuContext, scene: &Scene, b: BzbSettings) -> Renderer {
    let mut r = Renderer::new(gpu, scene, settings(b)).unwrap_or_else(|e| panic!("{}: {e}", scene.name));
    r.render(gpu, scene, &FrameCameras::fixed(scene.camera), 0.0)
        .expect("frame renders without validation errors");
    r
}

fn world_triangles(scene: &Scene) -> Vec<[Vec3; 3]> {
    scene.world_triangles(0.0).iter().map(|t| t.p).collect()
}

fn texel(img: &ImageBuf, x: u32, y: u32) -> &[f32] {
    img.pixel(x, y)
}

/// Every texel of the bounced z-buffer that has a sample: (tile s, pixel p, big-texel x, y).
fn sample_texels(b: &BzbSettings) -> Vec<(u32, [u32; 2], u32, u32)> {
    let (cols, _) = b.grid();
    let mut v = Vec::new();
    for s in 0..b.directions {
        let (ox, oy) = ((s % cols) * W, (s / cols) * H);
        for y in 0..H {
            for x in 0..W {
                v.push((s, [x, y], ox + x, oy + y));
            }
        }
    }
    v
}

#[test]
fn gpu_directions_equal_the_cpu_twin() {
    let gpu = common::gpu();
    let scene = plate_stack(2);
    for (hemisphere, directions, seed) in [(Hemisphere::Cosine, 4, 0), (Hemisphere::Uniform, 3, 7)] {
        let b = BzbSettings {
            hemisphere,
            directions,
            seed,
            ..Default::default()
        };
        let r = render(&gpu, &scene, b.clone());
        let dirs = r.read_target(&gpu, "bzb-directions").unwrap();
        let origins = r.read_target(&gpu, "bzb-origins").unwrap();
        let (cols, rows) = b.grid();
        assert_eq!((dirs.width, dirs.height), (W * cols, H * rows));
        let normals = common::npack_normals(&r.read_target(&gpu, "npack").unwrap(), 0);
        let csz = r.read_target(&gpu, "csz").unwrap();
        let mut checked = 0;
        for (s, p, x, y) in sample_texels(&b) {
            let d = texel(&dirs, x, y);
            if csz.pixel(p[0], p[1])[0] <= 0.0 {
                assert_eq!(d[3], 0.0, "no surface, no sample at {p:?}");
                continue;
            }
            let n = Vec3::from_slice(normals.pixel(p[0], p[1]));
            let (w, pdf) = bzb::direction(n, bzb::sample_uniforms(p, s, seed), hemisphere);
            let g = Vec3::new(d[0], d[1], d[2]);
            assert!(
                (g - w).length() < 1e-3 && (d[3] - pdf).abs() < 1e-3 * pdf.max(1.0),
                "{hemisphere:?} s={s} p={p:?}: GPU {g:?} α {} vs CPU {w:?} α {pdf}",
                d[3]
            );
            assert_eq!(texel(&origins, x, y)[3], 1.0);
            checked += 1;
        }
        assert!(checked as u32 > W * H * directions / 2, "{checked} samples checked");
        // sub-images beyond S hold no samples
        for s in directions..cols * rows {
            let (ox, oy) = ((s % cols) * W, (s / cols) * H);
            assert_eq!(texel(&dirs, ox + 5, oy + 5)[3], 0.0, "unused sub-image {s}");
        }
    }
}

/// A sphere direction from two uniforms (for Monte Carlo over the sphere).
fn sphere_dir(u: [f32; 2]) -> Vec3 {
    let z = 1.0 - 2.0 * u[0];
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = std::f32::consts::TAU * u[1];
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

#[test]
fn direction_pdfs_integrate_to_one_and_samples_follow_them() {
    let normals = [
        Vec3::Z,
        -Vec3::Z,
        Vec3::new(0.3, -0.8, 0.2).normalize(),
        Vec3::new(-0.6, 0.1, -0.75).normalize(),
    ];
    let n_samples = 200_000u32;
    for hemisphere in [Hemisphere::Cosine, Hemisphere::Uniform] {
        for n in normals {
            // ∫ α dω = 1: Monte Carlo with uniform sphere directions (pdf 1/4π)
            let mut integral = 0.0f64;
            for i in 0..n_samples {
                let w = sphere_dir(bzb::sample_uniforms([i, 1], 0, 99));
                integral += (bzb::pdf(n, w, hemisphere) * 4.0 * std::f32::consts::PI) as f64;
            }
            integral /= n_samples as f64;
            assert!((integral - 1.0).abs() < 0.01, "{hemisphere:?} n={n}: ∫α = {integral}");
            // moments of cos θ and of the tangent component, stored α = α(ω)
            let (mut c1, mut c2, mut tx) = (0.0f64, 0.0f64, 0.0f64);
            let t = n.any_orthonormal_vector();
            for i in 0..n_samples {
                let (w, a) = bzb::direction(n, bzb::sample_uniforms([i % 509, i / 509], i % 4, 3), hemisphere);
                assert!((w.length() - 1.0).abs() < 1e-4);
                let c = n.dot(w);
                assert!(c >= 0.0, "below the horizon: {c}");
                assert!((a - bzb::pdf(n, w, hemisphere)).abs() < 1e-4, "stored α");
                c1 += c as f64;
                c2 += (c * c) as f64;
                tx += t.dot(w) as f64;
            }
            let (c1, c2, tx) = (c1 / n_samples as f64, c2 / n_samples as f64, tx / n_samples as f64);
            // E[cos θ], E[cos² θ]: cosine 2/3, 1/2; uniform 1/2, 1/3
            let (e1, e2) = match hemisphere {
                Hemisphere::Cosine => (2.0 / 3.0, 0.5),
                Hemisphere::Uniform => (0.5, 1.0 / 3.0),
            };
            assert!((c1 - e1).abs() < 0.005, "{hemisphere:?} n={n}: E[cos] {c1} vs {e1}");
            assert!((c2 - e2).abs() < 0.005, "{hemisphere:?} n={n}: E[cos²] {c2} vs {e2}");
            assert!(tx.abs() < 0.005, "{hemisphere:?} n={n}: E[ω·t] {tx}");
        }
    }
}

#[test]
fn cpu_ray_triangle_mirror_hits_what_it_should() {
    let v = [Vec3::ZERO, Vec3::X, Vec3::Y];
    let t = bzb::ray_triangle(Vec3::new(0.2, 0.2, 1.0), -Vec3::Z, v).unwrap();
    assert!((t - 1.0).abs() < 1e-6);
    // both faces
    let t = bzb::ray_triangle(Vec3::new(0.2, 0.2, -2.0), Vec3::Z, v).unwrap();
    assert!((t - 2.0).abs() < 1e-6);
    assert!(bzb::ray_triangle(Vec3::new(0.8, 0.8, 1.0), -Vec3::Z, v).is_none());
    assert!(bzb::ray_triangle(Vec3::new(0.2, 0.2, 1.0), Vec3::X, v).is_none());
}

/// The bounced z-buffer after the splat pass equals, texel by texel, the CPU's
/// nearest hit in (t_min, r) over all triangles along the same ray (which also
/// checks that the conservative splat rectangles cover every hit).
#[test]
fn bounced_zbuffer_equals_cpu_nearest_hits() {
    let gpu = common::gpu();
    let mut scene = plate_stack(3);
    // plus a tilted triangle and a small plate hovering over the floor
    scene = {
        let mut quads = vec![(
            Vec3::new(0.5, 0.3, 0.9),
            Vec3::new(0.6, 0.2, 0.0),
            Vec3::new(0.0, 0.3, 0.5),
        )];
        quads.push((
            Vec3::new(-1.0, 0.35, 0.3),
            Vec3::new(0.0, 0.0, 0.5),
            Vec3::new(0.6, 0.0, 0.0),
        ));
        let mut extra = quads_scene("extra", &quads, scene.camera, 1.0);
        let base = scene.meshes.len();
        for (i, m) in extra.meshes.drain(..).enumerate() {
            scene.meshes.push(m);
            scene.objects.push(Object {
                name: format!("extra-{i}"),
                mesh: base + i,
                transform: Mat4::IDENTITY,
                animation: None,
            });
        }
        scene
    };
    let b = BzbSettings::default();
    let r = render(&gpu, &scene, b.clone());
    let u = r.bzb_uniforms().unwrap();
    let depth = r.read_target(&gpu, "bzb-depth").unwrap();
    let payload = r.read_target(&gpu, "bzb-payload").unwrap();
    let origins = r.read_target(&gpu, "bzb-origins").unwrap();
    let dirs = r.read_target(&gpu, "bzb-directions").unwrap();
    let tris = world_triangles(&scene);
    let (mut hits, mut samples, mut wrong) = (0, 0, Vec::new());
    for (_, _, x, y) in sample_texels(&b) {
        let d = texel(&dirs, x, y);
        if d[3] <= 0.0 {
            continue;
        }
        samples += 1;
        let o = Vec3::from_slice(&texel(&origins, x, y)[..3]);
        let cpu = bzb::bounced_depth(o, Vec3::new(d[0], d[1], d[2]), &tris, u.radius, u.t_min);
        let gpu_z = texel(&depth, x, y)[0];
        if cpu < 1.0 {
            hits += 1;
        }
        if (gpu_z - cpu).abs() > 1e-4 {
            wrong.push((x, y, gpu_z, cpu));
        }
        let expected_payload = if gpu_z < 1.0 { 1.0 } else { 0.0 };
        assert_eq!(texel(&payload, x, y)[0], expected_payload, "payload at ({x}, {y})");
    }
    // rays grazing a triangle edge may round differently on the GPU: at most 0.1 %
    assert!(
        wrong.len() * 1000 <= samples,
        "{} of {samples} texels differ from the CPU nearest hit, e.g. {:?}",
        wrong.len(),
        &wrong[..wrong.len().min(5)]
    );
    assert!(
        hits * 10 > samples,
        "only {hits} of {samples} rays hit: the scene tests too little"
    );
    eprintln!("{hits} of {samples} rays hit, {} differ from the CPU", wrong.len());
}

/// For one pixel and two occluders along the same direction the nearer one wins,
/// whichever is drawn first.
#[test]
fn nearer_occluder_wins_regardless_of_draw_order() {
    let gpu = common::gpu();
    // a floor seen from straight above, and two horizontal plates beside the view
    // (x < -1.6) at heights 0.3 (near) and 0.6 (far): grazing floor rays towards -x
    // pass through both
    let camera = Camera::new(Vec3::new(0.0, 3.0, 0.01), Vec3::ZERO, Vec3::Y, 40.0, 0.05);
    let floor = (
        Vec3::new(-2.0, 0.0, 2.0),
        Vec3::new(4.0, 0.0, 0.0),
        Vec3::new(0.0, 0.0, -4.0),
    );
    let near = (
        Vec3::new(-5.0, 0.3, -2.0),
        Vec3::new(3.4, 0.0, 0.0),
        Vec3::new(0.0, 0.0, 4.0),
    );
    let far = (
        Vec3::new(-5.0, 0.6, -2.0),
        Vec3::new(3.4, 0.0, 0.0),
        Vec3::new(0.0, 0.0, 4.0),
    );
    let b = BzbSettings {
        radius: Some(10.0),
        ..Default::default()
    };
    let mut depths = Vec::new();
    for order in [[floor, near, far], [floor, far, near]] {
        let scene = quads_scene("two-plates", &order, camera, 10.0);
        let r = render(&gpu, &scene, b.clone());
        let u = r.bzb_uniforms().unwrap();
        let depth = r.read_target(&gpu, "bzb-depth").unwrap();
        let origins = r.read_target(&gpu, "bzb-origins").unwrap();
        let dirs = r.read_target(&gpu, "bzb-directions").unwrap();
        let plate = |q: (Vec3, Vec3, Vec3)| {
            let p = [q.0, q.0 + q.1, q.0 + q.1 + q.2, q.0 + q.2];
            [[p[0], p[1], p[2]], [p[0], p[2], p[3]]]
        };
        let (near_tris, far_tris) = (plate(near), plate(far));
        let mut both = 0;
        for (_, _, x, y) in sample_texels(&b) {
            let d = texel(&dirs, x, y);
            if d[3] <= 0.0 {
                continue;
            }
            let o = Vec3::from_slice(&texel(&origins, x, y)[..3]);
            let w = Vec3::new(d[0], d[1], d[2]);
            let zn = bzb::bounced_depth(o, w, &near_tris, u.radius, u.t_min);
            let zf = bzb::bounced_depth(o, w, &far_tris, u.radius, u.t_min);
            if zn < 1.0 && zf < 1.0 && o.y < 0.1 {
                // a floor ray through both plates keeps the nearer one's depth
                both += 1;
                let g = texel(&depth, x, y)[0];
                assert!((g - zn).abs() < 1e-4, "({x}, {y}): depth {g}, near {zn}, far {zf}");
                assert!(zn < zf);
            }
        }
        assert!(both > 100, "only {both} rays pass through both plates");
        depths.push(depth);
    }
    assert_eq!(
        depths[0].data, depths[1].data,
        "the bounced z-buffer depends on the draw order"
    );
}

#[test]
fn unoccluded_plane_is_one_in_both_modes() {
    let gpu = common::gpu();
    let mut scene = procedural::builtin("plane").unwrap();
    scene.camera_path = None;
    for visibility in [true, false] {
        let b = BzbSettings {
            visibility,
            ..Default::default()
        };
        let r = render(&gpu, &scene, b);
        for target in ["bzb-raw", "ao"] {
            let av = r.read_target(&gpu, target).unwrap();
            let min = av.data.iter().cloned().fold(f32::INFINITY, f32::min);
            assert!(min >= 1.0 - 1e-3, "visibility={visibility} {target}: min AV {min}");
        }
    }
}

fn mean_abs(a: &ImageBuf, b: &ImageBuf, mask: &[bool]) -> f32 {
    let (mut s, mut n) = (0.0f32, 0u32);
    for (i, m) in mask.iter().enumerate() {
        if *m {
            s += (a.data[i] - b.data[i]).abs();
            n += 1;
        }
    }
    s / n.max(1) as f32
}

/// The ray-traced binary AO within r = 1 (1024 spp) the plate-stack tests compare with.
fn binary_ao(scene: &Scene, camera: &Camera) -> ImageBuf {
    Reference::new(scene, 0.0).ao_binary(
        camera,
        W,
        H,
        &AoBinarySettings {
            radius: 1.0,
            spp: 1024,
            seed: 1,
        },
    )
}

/// `bzb-ao` without the bilateral filter, so a test sees the temporal filter alone.
fn unblurred(temporal: Option<strata_render::passes::temporal::TemporalSettings>) -> BzbSettings {
    BzbSettings {
        filter: strata_render::passes::bilateral::BilateralSettings {
            radius: 0,
            ..Default::default()
        },
        temporal,
        ..Default::default()
    }
}

fn mean_of(a: &ImageBuf, mask: &[bool]) -> f32 {
    let v: Vec<f32> = a.data.iter().zip(mask).filter(|(_, m)| **m).map(|(v, _)| *v).collect();
    v.iter().sum::<f32>() / v.len().max(1) as f32
}

/// In front of a stack of parallel plates, AOV without visibility sums the
/// occluders behind each other and over-occludes; the bounced z-buffer keeps the
/// nearest along each direction and stays within a tolerance of the ray-traced
/// binary AO with the same radius.
#[test]
fn visibility_removes_the_over_occlusion_of_stacked_occluders() {
    let gpu = common::gpu();
    let scene = plate_stack(3);
    let reference = binary_ao(&scene, &scene.camera);
    let run = |visibility: bool, directions: u32| {
        let r = render(
            &gpu,
            &scene,
            BzbSettings {
                visibility,
                directions,
                ..Default::default()
            },
        );
        r.read_target(&gpu, "ao").unwrap()
    };
    // occluded region: pixels the reference darkens by at least 0.1
    let occluded: Vec<bool> = reference.data.iter().map(|v| *v < 0.9).collect();
    let all = vec![true; reference.data.len()];
    let n_occluded = occluded.iter().filter(|m| **m).count();
    assert!(n_occluded > 200, "only {n_occluded} occluded pixels");
    let with = run(true, 16);
    let with4 = run(true, 4);
    let without = run(false, 4);
    if let Ok(dir) = std::env::var("STRATA_TEST_IMAGES") {
        for (img, n) in [
            (&reference, "ref"),
            (&with, "vis16"),
            (&with4, "vis4"),
            (&without, "novis"),
        ] {
            img.save(&std::path::Path::new(&dir).join(format!("bzb-stack-{n}.png")), true)
                .unwrap();
        }
    }
    let (e_with, e_with4, e_without) = (
        mean_abs(&with, &reference, &all),
        mean_abs(&with4, &reference, &all),
        mean_abs(&without, &reference, &all),
    );
    let (m_ref, m_with, m_without) = (
        mean_of(&reference, &occluded),
        mean_of(&with, &occluded),
        mean_of(&without, &occluded),
    );
    eprintln!(
        "plate stack: MAE vs ray-traced binary AO: visibility S=16 {e_with:.4}, S=4 {e_with4:.4}, no visibility {e_without:.4}; \
         mean AV over {n_occluded} occluded pixels: reference {m_ref:.4}, visibility {m_with:.4}, no visibility {m_without:.4}"
    );
    // without visibility the stack over-occludes
    assert!(
        m_without < m_ref - 0.05,
        "no over-occlusion without visibility: {m_without} vs {m_ref}"
    );
    // with visibility: within 0.03 of the reference on average over the occluded region, and
    // per-pixel MAE within 0.04 (S = 16) / 0.06 (S = 4, the paper's)
    assert!(
        (m_with - m_ref).abs() < 0.03,
        "visibility: mean AV {m_with} vs reference {m_ref}"
    );
    assert!(e_with < 0.04, "visibility S=16: MAE {e_with}");
    assert!(e_with4 < 0.06, "visibility S=4: MAE {e_with4}");
    assert!(
        e_with4 < e_without,
        "S=4 with visibility {e_with4} not closer than without {e_without}"
    );
}

#[test]
fn settings_errors_name_the_parameter_and_range() {
    let gpu = common::gpu();
    let scene = plate_stack(1);
    for (b, needle) in [
        (
            BzbSettings {
                directions: 0,
                ..Default::default()
            },
            "directions 0 is out of range: must be in 1..=16",
        ),
        (
            BzbSettings {
                radius: Some(-1.0),
                ..Default::default()
            },
            "radius -1 is out of range",
        ),
        (
            BzbSettings {
                temporal: Some(strata_render::passes::temporal::TemporalSettings {
                    alpha: 1.0,
                    ..bzb::temporal_filter()
                }),
                ..Default::default()
            },
            "temporal alpha 1 is out of range: must be in [0, 1)",
        ),
        (
            BzbSettings {
                splat_kernel: strata_render::passes::Kernel::Compute,
                box_splats: true,
                ..Default::default()
            },
            "splat-kernel=compute tests the splats' rectangles: use splat-bounds=rect",
        ),
        (
            BzbSettings {
                splat_kernel: strata_render::passes::Kernel::Compute,
                splat: bzb::Splat::Dss,
                ..Default::default()
            },
            "splat-kernel=compute applies to splat=aov",
        ),
    ] {
        let e = Renderer::new(&gpu, &scene, settings(b))
            .err()
            .expect("rejected")
            .to_string();
        assert!(e.contains(needle), "{e}");
        assert_eq!(e.lines().count(), 1, "{e}");
    }
    // bzb and DGB AO both write `ao`
    let mut s = settings(BzbSettings::default());
    s.ao = Some(Default::default());
    assert!(s.validate().unwrap_err().to_string().contains("ao target"));
}

#[test]
fn depth_tile_culling_leaves_the_image_unchanged() {
    // issue 13 item 4 / BZB §4.3: splats (AOV triangles, DSS shells) are culled only
    // where no receiver under them is within their depth range, so the bounced
    // z-buffer, the payload and the AO are the same bits with and without culling,
    // in both modes and with both splatting algorithms
    let gpu = common::gpu();
    for scene in [
        strata_scene::procedural::builtin("atrium").unwrap(),
        strata_scene::procedural::builtin("cornell").unwrap(),
    ] {
        for (visibility, splat) in [true, false]
            .into_iter()
            .flat_map(|v| [(v, bzb::Splat::Aov), (v, bzb::Splat::Dss)])
        {
            let b = |culling: bool| BzbSettings {
                visibility,
                culling,
                splat,
                ..Default::default()
            };
            let (on, off) = (render(&gpu, &scene, b(true)), render(&gpu, &scene, b(false)));
            for t in ["bzb-payload", "bzb-raw", "ao"] {
                let differ = common::target_bits_differing(&gpu, &on, &off, t);
                assert_eq!(
                    differ, 0,
                    "{} visibility={visibility} {splat:?} {t}: {differ} values differ",
                    scene.name
                );
            }
            // the splats hit something: culling had work to leave alone
            let payload = on.read_target(&gpu, "bzb-payload").unwrap();
            let hits = payload.data.iter().filter(|&&v| v > 0.0).count();
            eprintln!("{} visibility={visibility} {splat:?}: {hits} texels hit", scene.name);
            assert!(hits > 40, "{}: the scene occludes ({hits})", scene.name);
        }
    }
}

/// AOV splats drawn as the box around each occlusion volume cover every texel the AABB's
/// screen rectangle covered that a triangle can occlude: the bounced z-buffer, the
/// payload and the AO are the same bits either way, in both modes. Scenes: atrium and
/// Cornell, the plate stack, and large tilted triangles seen at a grazing angle, one
/// of them crossing the near plane (the rectangle fallback).
#[test]
fn box_splats_equal_rectangle_splats() {
    let gpu = common::gpu();
    for scene in [
        procedural::builtin("atrium").unwrap(),
        procedural::builtin("cornell").unwrap(),
        plate_stack(3),
        tilted_quads(),
    ] {
        for visibility in [true, false] {
            let b = |box_splats: bool| BzbSettings {
                visibility,
                box_splats,
                ..Default::default()
            };
            let (boxed, rect) = (render(&gpu, &scene, b(true)), render(&gpu, &scene, b(false)));
            let mut targets = vec!["bzb-payload", "bzb-raw", "ao"];
            if visibility {
                targets.push("bzb-depth");
            }
            for t in targets {
                let differ = common::target_bits_differing(&gpu, &boxed, &rect, t);
                assert_eq!(
                    differ, 0,
                    "{} visibility={visibility} {t}: {differ} values differ",
                    scene.name
                );
            }
            let payload = boxed.read_target(&gpu, "bzb-payload").unwrap();
            let hits = payload.data.iter().filter(|&&v| v > 0.0).count();
            assert!(hits > 40, "{}: the scene occludes ({hits})", scene.name);
        }
    }
}

/// The compute form of the splats (`splat-kernel=compute`: the same rectangles, the
/// nearest hit kept with 64-bit atomics, then resolved into the same targets) builds
/// the rasteriser's bounced z-buffer bit for bit: depth, payload, the reconstructed and
/// the filtered AO, with and without the depth-tile culling. Scenes: atrium, Cornell,
/// the plate stack (occluders behind each other) and the tilted quads.
#[test]
fn compute_splats_equal_fragment_splats() {
    let gpu = common::gpu();
    // atrium with S = 16: 125,856 instances, four rows of the compute dispatch
    // (`compute_splat_groups`); the others fit one row
    for (scene, culling, directions) in [
        (procedural::builtin("atrium").unwrap(), true, 4),
        (procedural::builtin("atrium").unwrap(), false, 16),
        (procedural::builtin("cornell").unwrap(), true, 4),
        (plate_stack(3), true, 4),
        (tilted_quads(), true, 4),
    ] {
        let instances = world_triangles(&scene).len() as u32 * directions;
        assert!(directions != 16 || bzb::compute_splat_groups(instances).1 > 1);
        let b = |compute: bool| BzbSettings {
            splat_kernel: common::kernel(compute),
            culling,
            directions,
            ..Default::default()
        };
        let (compute, fragment) = (render(&gpu, &scene, b(true)), render(&gpu, &scene, b(false)));
        for t in ["bzb-depth", "bzb-payload", "bzb-raw", "ao"] {
            let differ = common::target_bits_differing(&gpu, &compute, &fragment, t);
            assert_eq!(
                differ, 0,
                "{} culling={culling} {t}: {differ} values differ",
                scene.name
            );
        }
        let payload = compute.read_target(&gpu, "bzb-payload").unwrap();
        let hits = payload.data.iter().filter(|&&v| v > 0.0).count();
        assert!(hits > 40, "{}: the scene occludes ({hits})", scene.name);
    }
    // without visibility the additive baseline blends in fragments either way
    let scene = plate_stack(3);
    let b = |compute: bool| BzbSettings {
        splat_kernel: common::kernel(compute),
        visibility: false,
        ..Default::default()
    };
    let (compute, fragment) = (render(&gpu, &scene, b(true)), render(&gpu, &scene, b(false)));
    assert_eq!(common::target_bits_differing(&gpu, &compute, &fragment, "ao"), 0);
}

/// `bzb-zminmax` (one workgroup per tile, a workgroup reduction) equals its CPU
/// twin over `bzb-origins`: every level, partial tiles at the borders (odd size).
#[test]
fn depth_tiles_equal_their_cpu_twin() {
    let gpu = common::gpu();
    let scene = procedural::builtin("atrium").unwrap();
    let (w, h) = (147, 83);
    let mut r = Renderer::new(
        &gpu,
        &scene,
        RenderSettings {
            width: w,
            height: h,
            ..settings(BzbSettings::default())
        },
    )
    .unwrap();
    r.render(&gpu, &scene, &FrameCameras::fixed(scene.camera), 0.0).unwrap();
    let got = r.bzb_zminmax(&gpu).expect("AOV splats have depth tiles").unwrap();
    let origins = r.read_target(&gpu, "bzb-origins").unwrap();
    let f = r.frame_uniforms();
    let (eye, fwd) = (Vec3::from_slice(&f.eye[..3]), Vec3::from_slice(&f.cam_forward[..3]));
    let want = bzb::zminmax_tiles(w, h, |x, y| {
        let o = origins.pixel(x, y);
        (o[3] > 0.0).then(|| (Vec3::new(o[0], o[1], o[2]) - eye).dot(fwd))
    });
    assert_eq!(got.len(), want.len());
    assert_eq!(got.len() as u32, bzb::zminmax_tile_count(w, h));
    let mut filled = 0;
    for (i, (g, c)) in got.iter().zip(&want).enumerate() {
        for k in 0..2 {
            assert!(
                (g[k] - c[k]).abs() <= 1e-5 * c[k].abs().max(1.0),
                "tile {i}: GPU {g:?} vs CPU {c:?}"
            );
        }
        filled += (c[0] <= c[1]) as u32;
    }
    assert!(
        filled > got.len() as u32 / 2,
        "{filled} of {} tiles hold receivers",
        got.len()
    );
}

/// `--set alpha` (BZB §6's re-projection, DGB §3.3's filter): plate stack, S = 4, no
/// bilateral filter. The first frame equals the unfiltered one (same seed, no history);
/// after 8 still frames, each with new directions, the MAE against the ray-traced binary
/// AO is at most 0.6× the single frame's, and the mean AV over the occluded region stays
/// within 0.02 of the reference's (the filter averages, it does not bias).
#[test]
fn temporal_filter_averages_new_directions_on_a_still_camera() {
    let gpu = common::gpu();
    let scene = plate_stack(3);
    let reference = binary_ao(&scene, &scene.camera);
    let (single, filtered) = (unblurred(None), unblurred(Some(bzb::temporal_filter())));
    let all = vec![true; reference.data.len()];
    let occluded: Vec<bool> = reference.data.iter().map(|v| *v < 0.9).collect();
    let one = render(&gpu, &scene, single).read_target(&gpu, "ao").unwrap();
    let mut acc = render(&gpu, &scene, filtered);
    let first = acc.read_target(&gpu, "ao").unwrap();
    assert_eq!(first.data, one.data, "frame 0 with the filter is the unfiltered frame");
    for _ in 0..7 {
        acc.render(&gpu, &scene, &FrameCameras::fixed(scene.camera), 0.0)
            .unwrap();
    }
    let eight = acc.read_target(&gpu, "ao").unwrap();
    let (e1, e8) = (mean_abs(&one, &reference, &all), mean_abs(&eight, &reference, &all));
    let (m_ref, m8) = (mean_of(&reference, &occluded), mean_of(&eight, &occluded));
    eprintln!("bzb-ao temporal: MAE {e1:.4} (one frame) -> {e8:.4} after 8 frames; occluded mean AV {m8:.4} (reference {m_ref:.4})");
    assert!(e8 <= 0.6 * e1, "MAE {e8} vs one frame's {e1}");
    assert!((m8 - m_ref).abs() < 0.02, "mean AV {m8} vs reference {m_ref}");
}

/// The filter reprojects with the camera: a camera sliding sideways by 0.02 per frame.
/// After 8 frames, the AV at the last camera is closer to the ray-traced binary AO than a
/// single frame's, and closer than the same frames told that the camera stood still
/// (`previous = current`), whose history lands beside the plates' edges.
#[test]
fn temporal_filter_follows_a_moving_camera() {
    let gpu = common::gpu();
    let scene = plate_stack(3);
    let cam = |k: u32| {
        let mut c = scene.camera;
        let d = Vec3::new(0.02 * k as f32, 0.0, 0.0);
        c.eye += d;
        c.target += d;
        c
    };
    let last = cam(7);
    let reference = binary_ao(&scene, &last);
    let s = unblurred(Some(bzb::temporal_filter()));
    let run = |told_still: bool| {
        let mut r = Renderer::new(&gpu, &scene, settings(s.clone())).unwrap();
        for k in 0..8 {
            let cams = FrameCameras {
                previous: if told_still || k == 0 { cam(k) } else { cam(k - 1) },
                current: cam(k),
                next_view: cam(k).view(),
            };
            r.render(&gpu, &scene, &cams, 0.0).unwrap();
        }
        r.read_target(&gpu, "ao").unwrap()
    };
    let mut one = Renderer::new(&gpu, &scene, settings(unblurred(None))).unwrap();
    one.render(&gpu, &scene, &FrameCameras::fixed(last), 0.0).unwrap();
    let one = one.read_target(&gpu, "ao").unwrap();
    let all = vec![true; reference.data.len()];
    let (moving, still) = (run(false), run(true));
    let (e1, e_moving, e_still) = (
        mean_abs(&one, &reference, &all),
        mean_abs(&moving, &reference, &all),
        mean_abs(&still, &reference, &all),
    );
    eprintln!(
        "bzb-ao temporal, moving camera: MAE one frame {e1:.4}, reprojected {e_moving:.4}, told still {e_still:.4}"
    );
    assert!(e_moving <= 0.75 * e1, "reprojected MAE {e_moving} vs one frame's {e1}");
    assert!(
        e_moving < 0.85 * e_still,
        "reprojected MAE {e_moving} vs told-still {e_still}"
    );
}

/// `filter-fresh-radius` (not in the paper): after the temporal filter, a pixel whose
/// history holds n frames is filtered with max(radius, round(R / √(n + 1))) taps. Both
/// GPU passes equal `bilateral_cpu` on the same buffers; pixels with a long
/// history keep the plain radius-1 filter, and the ones the moving camera uncovered get a
/// wider one.
#[test]
fn fresh_radius_widens_the_filter_where_the_history_is_short() {
    use strata_render::passes::bilateral::{bilateral_cpu, history_radius, BilateralSettings};
    let gpu = common::gpu();
    let scene = plate_stack(3);
    // still for 8 frames, then two steps sideways that uncover the plates' sides
    let cam = |k: u32| {
        let mut c = scene.camera;
        let d = Vec3::new(0.15 * k.saturating_sub(7) as f32, 0.0, 0.0);
        c.eye += d;
        c.target += d;
        c
    };
    let filter = BilateralSettings {
        radius: 1,
        fresh_radius: Some(4),
        ..Default::default()
    };
    let s = BzbSettings {
        filter,
        temporal: Some(bzb::temporal_filter()),
        ..Default::default()
    };
    let mut r = Renderer::new(&gpu, &scene, settings(s)).unwrap();
    for k in 0..10 {
        let cams = FrameCameras {
            previous: cam(k.max(1) - 1),
            current: cam(k),
            next_view: cam(k).view(),
        };
        r.render(&gpu, &scene, &cams, 0.0).unwrap();
    }
    let read = |n: &str| r.read_target(&gpu, n).unwrap();
    let (temporal, frames, blur_h, out) = (
        read("bzb-temporal"),
        read("bzb-temporal-frames"),
        read("bzb-blur-h"),
        read("ao"),
    );
    let zpack = read("zpack");
    let normals = common::npack_normals(&read("npack"), 0);
    let f = r.frame_uniforms();
    let n = (W * H) as usize;
    let ch = |img: &ImageBuf, i: usize| img.data[i * img.channels as usize];
    let near = |g: &ImageBuf, c: &ImageBuf| {
        (0..n)
            .filter(|&i| (ch(g, i) - ch(c, i)).abs() <= 2e-3 + 2e-3 * ch(c, i).abs())
            .count()
    };
    let twin = |src: &ImageBuf, vertical| bilateral_cpu(src, &zpack, &normals, &f, &filter, vertical, Some(&frames));
    let (twin_h, twin_v) = (twin(&temporal, false), twin(&blur_h, true));
    let (close_h, close_v) = (near(&blur_h, &twin_h), near(&out, &twin_v));
    // the plain radius-1 filter of the same input
    let plain = bilateral_cpu(
        &temporal,
        &zpack,
        &normals,
        &f,
        &BilateralSettings {
            fresh_radius: None,
            ..filter
        },
        false,
        None,
    );
    let surface = |i: usize| ch(&zpack, i) > 0.0;
    let radius_of = |i: usize| history_radius(1, 4, ch(&frames, i));
    let long: Vec<usize> = (0..n).filter(|&i| surface(i) && radius_of(i) == 1).collect();
    let short: Vec<usize> = (0..n).filter(|&i| surface(i) && radius_of(i) >= 3).collect();
    let widened = short
        .iter()
        .filter(|&&i| (ch(&twin_h, i) - ch(&plain, i)).abs() > 1e-4)
        .count();
    eprintln!(
        "fresh radius: GPU = twin {close_h}/{n} (h), {close_v}/{n} (v); {} pixels with a long history, {} uncovered ({widened} changed by the wider filter)",
        long.len(),
        short.len()
    );
    assert!(close_h as f32 >= 0.995 * n as f32, "h: {close_h}/{n} GPU = CPU twin");
    assert!(close_v as f32 >= 0.995 * n as f32, "v: {close_v}/{n} GPU = CPU twin");
    assert!(
        long.len() > n / 4 && short.len() >= 20,
        "the test needs both kinds: {} / {}",
        long.len(),
        short.len()
    );
    assert!(
        long.iter().all(|&i| ch(&twin_h, i) == ch(&plain, i)),
        "a long history keeps radius 1"
    );
    // (where every neighbour holds the same AV, e.g. unoccluded floor, widening changes nothing)
    assert!(
        widened >= 20 && widened * 4 >= short.len(),
        "the wider filter changes the uncovered pixels: {widened} of {}",
        short.len()
    );
}
