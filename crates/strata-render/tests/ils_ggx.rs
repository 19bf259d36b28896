//! Glossy receivers of interleaved deferred shading: the WGSL GGX twin
//! (`shaders/common/ggx.wgsl`, `vpl_glossy_radiance` in `common/vpl.wgsl`)
//! against its CPU twin `strata_reference::Vpl::glossy_radiance_at` (which is
//! `brdf::Ggx::eval`, the path tracer's BRDF) on many random configurations.
//! Fails on any wgpu validation error.

mod common;

use glam::Vec3;
use strata_reference::vpl::Vpl;

/// One configuration as the shader reads it (7 vec4).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Case {
    vpl_position: [f32; 4],
    vpl_normal: [f32; 4],
    vpl_flux: [f32; 4],
    x: [f32; 4],
    n: [f32; 4],
    view: [f32; 4],
    /// rgb = ρ, w = roughness
    rho: [f32; 4],
    /// x = metallic, y = max geometry
    params: [f32; 4],
}

const SHADER: &str = r#"
#import "common/vpl.wgsl"
struct Case {
    vpl_position: vec4f,
    vpl_normal: vec4f,
    vpl_flux: vec4f,
    x: vec4f,
    n: vec4f,
    view: vec4f,
    rho: vec4f,
    params: vec4f,
}
@group(0) @binding(0) var<storage, read> cases: array<Case>;
@group(0) @binding(1) var<storage, read_write> out: array<vec4f>;
@compute @workgroup_size(64)
fn cs_main(@builtin(global_invocation_id) id: vec3u) {
    let i = id.x;
    if (i >= arrayLength(&cases)) {
        return;
    }
    let c = cases[i];
    let v = Vpl(c.vpl_position, c.vpl_normal, c.vpl_flux);
    let l = vpl_glossy_radiance(v, c.x.xyz, c.n.xyz, c.view.xyz, c.rho.rgb, c.rho.w, c.params.x, c.params.y);
    out[i] = vec4f(l, 0.0);
}
"#;

/// xorshift in [0, 1)
struct Rng(u64);
impl Rng {
    fn f(&mut self) -> f32 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }
    fn unit(&mut self) -> Vec3 {
        loop {
            let v = Vec3::new(self.f(), self.f(), self.f()) * 2.0 - 1.0;
            if v.length_squared() > 0.01 && v.length_squared() <= 1.0 {
                return v.normalize();
            }
        }
    }
}

#[test]
fn gpu_glossy_vpl_radiance_equals_the_cpu_twin() {
    let gpu = common::gpu();
    let mut rng = Rng(0x9e3779b97f4a7c15);
    let mut cases = Vec::new();
    let mut cpu = Vec::new();
    let mut alphas = Vec::new();
    let w4 = |v: Vec3, w: f32| [v.x, v.y, v.z, w];
    for i in 0..4096 {
        let n = rng.unit();
        // views in the receiver's upper hemisphere, some grazing
        let mut view = rng.unit();
        if view.dot(n) < 0.0 {
            view = -view;
        }
        // VPLs above the receiver: many near the mirror direction (the highlight)
        let x = Vec3::new(rng.f(), rng.f(), rng.f()) * 4.0 - 2.0;
        let mirror = 2.0 * view.dot(n) * n - view;
        let dir = if i % 2 == 0 {
            (mirror + rng.unit() * 0.1).normalize()
        } else {
            rng.unit()
        };
        let position = x + dir * (0.05 + 2.0 * rng.f());
        let vpl = Vpl {
            position,
            normal: (-dir + rng.unit() * 0.5).normalize(),
            flux: Vec3::new(rng.f(), rng.f(), rng.f()) * 10.0,
            albedo: Vec3::ONE,
            bounce: 1,
        };
        let rho = Vec3::new(rng.f(), rng.f(), rng.f());
        // roughness down to 0 (α clamped to 0.002: the sharpest lobe), metallic 0, 1 or between
        let roughness = [0.0, 0.05, 0.15, 0.4, 1.0, rng.f()][i % 6];
        let metallic = [0.0, 1.0, rng.f()][i % 3];
        let max_g = if i % 4 == 0 { 4.0 } else { f32::INFINITY };
        let alpha = (roughness * roughness).max(strata_reference::brdf::ALPHA_MIN);
        alphas.push(alpha);
        cpu.push(vpl.glossy_radiance_at(x, n, view, rho, roughness, metallic, max_g));
        cases.push(Case {
            vpl_position: w4(vpl.position, 0.0),
            vpl_normal: w4(vpl.normal, 0.0),
            vpl_flux: w4(vpl.flux, 0.0),
            x: w4(x, 0.0),
            n: w4(n, 0.0),
            view: w4(view, 0.0),
            rho: w4(rho, roughness),
            params: [metallic, max_g, 0.0, 0.0],
        });
    }
    let size = (cases.len() * 16) as u64;
    let bytes = common::run_compute(
        &gpu,
        "ggx-twin",
        SHADER,
        "cs_main",
        bytemuck::cast_slice(&cases),
        size,
        cases.len() as u32,
    );
    let got: &[[f32; 4]] = bytemuck::cast_slice(&bytes);
    // per value: |GPU − CPU| ≤ (1e-3 + 1e-6/α²) relative + 1e-6 of the case's largest
    // channel. f32 on both sides, but sqrt, division and the pow5 product round
    // differently, and D's denominator (1 − n·h)(1 + n·h) + α²(n·h)² turns an
    // f32 rounding of n·h (~6e-8) into a relative error of ~2·6e-8/α² near the
    // peak of a narrow lobe, more with the few-ulp error of h (seen: 8 % at
    // α = 0.002, roughness 0; the bound allows 25 % there, 0.3 % at roughness 0.15).
    let mut lit = 0;
    let mut worst = 0.0f32;
    for (i, (g, c)) in got.iter().zip(&cpu).enumerate() {
        if c.max_element() > 0.0 {
            lit += 1;
        }
        for k in 0..3 {
            let tol = (1e-3 + 1e-6 / (alphas[i] * alphas[i])) * c[k].abs() + 1e-6 * c.max_element();
            let err = (g[k] - c[k]).abs();
            worst = worst.max(err / tol.max(f32::MIN_POSITIVE));
            assert!(
                err <= tol || err == 0.0,
                "case {i} channel {k}: GPU {} vs CPU {} ({:?})",
                g[k],
                c[k],
                bytemuck::cast_slice::<Case, f32>(&cases[i..i + 1])
            );
        }
    }
    assert!(lit > cases.len() / 4, "only {lit} cases are lit");
    eprintln!(
        "{lit} of {} cases lit; worst error {worst:.3} of the tolerance",
        cases.len()
    );
}

/// One ILS frame of `scene` (in the first test `still-life`: gold metal sphere,
/// blue glossy vase, Lambert cloth and boxes), its `ils-glossy` multiplied back by
/// the CPU twin of its demodulation, and, per pixel, the CPU twin of what it must hold: from the
/// frame's own csz, decoded normal, roughness, metallic, albedo and glossy flag
/// (emission.a = 2), Σ_k `glossy_radiance_at` (glossy pixels) or Σ_k
/// `irradiance_at` (Lambert pixels) over the pixel's VPL subset (8×6, or all
/// for the brute force) scaled by N/N_s; a term counts only where `visible`
/// (the VPL seen from the surface point) says so.
struct GlossyFrame {
    irradiance: strata_scene::ImageBuf,
    glossy: strata_scene::ImageBuf,
    /// compose's output minus the direct light (`hdr-full` − `hdr`) and the direct light
    composed: Vec<Vec3>,
    direct: Vec<Vec3>,
    cpu: Vec<Vec3>,
    is_glossy: Vec<bool>,
}

const W: u32 = 64;
const H: u32 = 48;

fn glossy_frame(
    gpu: &strata_render::GpuContext,
    scene: &strata_scene::Scene,
    v: &[Vpl],
    ils: strata_render::passes::ils::IlsSettings,
    visible: &dyn Fn(Vec3, Vec3, &Vpl) -> bool,
) -> GlossyFrame {
    let max_g = ils.max_geometry(scene);
    let brute_force = ils.brute_force;
    let r = common::ils_renderer(gpu, scene, ils, (W, H));
    let read = |name: &str| {
        let img = r.read_target(gpu, name).unwrap();
        gpu.check_errors().unwrap();
        img
    };
    let (irradiance, mut glossy) = (read("ils-irradiance"), read("ils-glossy"));
    let (nrm, albedo, emission) = (read("normal"), read("albedo"), read("emission"));
    let (full, hdr) = (read("hdr-full"), read("hdr"));
    let px = |img: &strata_scene::ImageBuf, i: usize| Vec3::from_slice(&img.data[i * 4..i * 4 + 3]);
    let direct: Vec<Vec3> = (0..(W * H) as usize).map(|i| px(&hdr, i)).collect();
    let composed = (0..(W * H) as usize).map(|i| px(&full, i) - direct[i]).collect();
    let u = r.frame_uniforms();
    let eye = Vec3::new(u.eye[0], u.eye[1], u.eye[2]);
    let mut cpu = vec![Vec3::ZERO; (W * H) as usize];
    let mut is_glossy = vec![false; (W * H) as usize];
    for q in common::surface_points(gpu, &r) {
        let (i, p, n) = (q.i, q.p, q.n);
        let g = emission.data[i * 4 + 3] > 1.5;
        is_glossy[i] = g;
        let rho = Vec3::from_slice(&albedo.data[i * 4..i * 4 + 3]);
        let (rough, metal) = (nrm.data[i * 4 + 2], nrm.data[i * 4 + 3]);
        let view = (eye - p).normalize();
        if g {
            // `ils-glossy` holds L_o / A; compose multiplies A back (its CPU twin here)
            let a = strata_reference::brdf::demodulation_albedo(n.dot(view), rho, rough, metal);
            for c in 0..3 {
                glossy.data[i * 4 + c] *= a[c];
            }
        }
        cpu[i] = common::ils_vpl_sum([8, 6], v.len(), brute_force, (q.x, q.y), |k| {
            let vpl = &v[k];
            let term = if g {
                vpl.glossy_radiance_at(p, n, view, rho, rough, metal, max_g)
            } else {
                vpl.irradiance_at(p, n, max_g)
            };
            if term != Vec3::ZERO && visible(p, n, vpl) {
                term
            } else {
                Vec3::ZERO
            }
        });
    }
    GlossyFrame {
        irradiance,
        glossy,
        composed,
        direct,
        cpu,
        is_glossy,
    }
}

fn frame_vpls(scene: &strata_scene::Scene, paths: u32) -> (Vec<Vpl>, strata_render::passes::ils::IlsSettings) {
    use strata_reference::vpl::VplSettings;
    use strata_reference::Reference;
    use strata_render::passes::ils::{GpuVpl, IlsSettings};
    let v = Reference::new(scene, 0.0).vpls(&VplSettings {
        paths,
        ..Default::default()
    });
    assert!(!v.is_empty());
    let ils = IlsSettings {
        vpls: v
            .iter()
            .map(|v| GpuVpl::new(v.position.into(), v.normal.into(), v.flux.into()))
            .collect(),
        blur: 0.0,
        ..Default::default()
    };
    (v, ils)
}

/// The largest channel of the CPU values over glossy (`glossy`) or Lambert pixels.
fn scale(f: &GlossyFrame, glossy: bool) -> f32 {
    (0..f.cpu.len())
        .filter(|&i| f.is_glossy[i] == glossy)
        .map(|i| f.cpu[i].max_element())
        .fold(0.0f32, f32::max)
}

/// The frame, brute force and 8×6 SNSM without blur: glossy pixels carry the
/// CPU sum in `ils-glossy` (divided by its demodulation) and 0 in `ils-irradiance`,
/// and compose adds exactly that sum to the direct light; Lambert pixels carry
/// theirs in `ils-irradiance` as before and 0 in `ils-glossy`.
#[test]
fn ils_frame_shades_glossy_receivers_with_the_cpu_twin() {
    use strata_render::passes::ils::IlsSettings;
    let gpu = common::gpu();
    let scene = strata_scene::procedural::builtin("still-life").unwrap();
    let (v, ils) = frame_vpls(&scene, 96);
    for brute_force in [true, false] {
        let f = glossy_frame(
            &gpu,
            &scene,
            &v,
            IlsSettings {
                brute_force,
                ..ils.clone()
            },
            &|_, _, _| true,
        );
        let n_glossy = f.is_glossy.iter().filter(|g| **g).count();
        let n_lambert = f.cpu.len() - n_glossy;
        assert!(
            n_glossy > 50 && n_lambert > 50,
            "{n_glossy} glossy, {n_lambert} Lambert pixels"
        );
        let (scale_g, scale_l) = (scale(&f, true), scale(&f, false));
        assert!(scale_g > 0.0 && scale_l > 0.0, "the VPLs light both kinds");
        let mut worst = 0.0f32;
        for i in 0..f.cpu.len() {
            let (own, other, scale, rel) = if f.is_glossy[i] {
                // glossy: f32 camera reconstruction and sRGB decode differ; narrow lobes amplify
                (&f.glossy, &f.irradiance, scale_g, 0.01)
            } else {
                // Lambert: the bound of tests/ils.rs (0.2 % + 0.02 % of the max; f16 storage)
                (&f.irradiance, &f.glossy, scale_l, 0.002)
            };
            let abs = if f.is_glossy[i] { 2e-3 } else { 2e-4 };
            for c in 0..3 {
                let (a, b) = (own.data[i * 4 + c], f.cpu[i][c]);
                let err = (a - b).abs() / (rel * b.abs() + abs * scale);
                worst = worst.max(err);
                assert!(
                    err <= 1.0,
                    "brute force {brute_force}: pixel {i} (glossy {}) channel {c}: GPU {a} vs CPU {b} (scale {scale})",
                    f.is_glossy[i]
                );
                assert_eq!(other.data[i * 4 + c], 0.0, "pixel {i}: the other target is 0");
                if f.is_glossy[i] {
                    // compose multiplies the demodulation back: its output minus the
                    // direct light is L_o (f16 targets: 0.2 % of the direct light more)
                    let (a, b) = (f.composed[i][c], f.cpu[i][c]);
                    let tol = rel * b.abs() + abs * scale + 2e-3 * f.direct[i][c].abs();
                    assert!(
                        (a - b).abs() <= tol,
                        "brute force {brute_force}: glossy pixel {i} channel {c}: composed {a} vs CPU {b}"
                    );
                }
            }
        }
        eprintln!(
            "brute force {brute_force}: {n_glossy} glossy, {n_lambert} Lambert pixels; worst {worst:.3} of the tolerance"
        );
    }
}

/// §4.3 SSM on glossy receivers: the frame's `ils-glossy` with each VPL's
/// visibility from its cube shadow map against the CPU GGX sum with visibility
/// traced through the reference's BVH (tests/ils.rs does the same for Lambert
/// receivers). The scene is cornell with every material made glossy
/// (roughness 0.35, dielectric), so the blocks shadow glossy floor and walls
/// from VPLs (on still-life the glossy objects see almost every VPL: SNSM and
/// the traced sum differ on 0.5 % of its glossy pixels). Shadow maps are approximate at shadow boundaries (normal offset,
/// PCF, texel size), so ≥ 95 % of the glossy pixels must agree within 5 % of
/// their value + 0.5 % of the glossy maximum, and the same frame without VPL
/// visibility (SNSM) must miss the traced sum on a clear share of them.
#[test]
fn ssm_glossy_receivers_match_traced_visibility() {
    use strata_reference::Reference;
    use strata_render::passes::ils::{IlsSettings, VplShadows};
    let gpu = common::gpu();
    let mut scene = strata_scene::procedural::builtin("cornell").unwrap();
    for m in scene.materials.iter_mut().filter(|m| m.emission == [0.0; 3]) {
        m.glossy = true;
        m.roughness = 0.35;
        m.metallic = 0.0;
    }
    let reference = Reference::new(&scene, 0.0);
    let (lo, hi) = scene.bounds(0.0);
    let eps = 1e-4 * (hi - lo).length();
    let traced = |p: Vec3, n: Vec3, vpl: &Vpl| {
        let origin = p + n * eps;
        let to = vpl.position - origin;
        let d = to.length();
        !reference.bvh().occluded(origin, to / d, 0.0, d - eps)
    };
    let (v, ils) = frame_vpls(&scene, 240);
    for brute_force in [true, false] {
        let settings = |shadows| IlsSettings {
            brute_force,
            shadows,
            vpl_shadow_resolution: 64,
            ..ils.clone()
        };
        let ssm = glossy_frame(&gpu, &scene, &v, settings(VplShadows::ShadowMaps), &traced);
        let snsm = glossy_frame(&gpu, &scene, &v, settings(VplShadows::None), &|_, _, _| true);
        let scale_g = scale(&ssm, true);
        assert!(scale_g > 0.0, "the VPLs light the glossy pixels");
        let glossy: Vec<usize> = (0..ssm.cpu.len()).filter(|&i| ssm.is_glossy[i]).collect();
        assert!(glossy.len() > 50, "{} glossy pixels", glossy.len());
        let off = |img: &strata_scene::ImageBuf| {
            let bad = glossy
                .iter()
                .filter(|&&i| {
                    (0..3).any(|c| {
                        (img.data[i * 4 + c] - ssm.cpu[i][c]).abs() > 0.05 * ssm.cpu[i][c].abs() + 5e-3 * scale_g
                    })
                })
                .count();
            bad as f64 / glossy.len() as f64
        };
        let (ssm_off, snsm_off) = (off(&ssm.glossy), off(&snsm.glossy));
        eprintln!(
            "brute force {brute_force}: {} glossy pixels; SSM off the traced sum on {:.2} %, SNSM on {:.2} %",
            glossy.len(),
            100.0 * ssm_off,
            100.0 * snsm_off
        );
        assert!(
            ssm_off <= 0.05,
            "brute force {brute_force}: SSM off on {:.2} %",
            100.0 * ssm_off
        );
        assert!(
            snsm_off >= 2.0 * ssm_off.max(0.01),
            "brute force {brute_force}: SNSM ({:.2} %) not clearly further from the traced sum than SSM",
            100.0 * snsm_off
        );
    }
}

/// One ILS frame's composed radiance (`hdr-full`) and its direct light (`hdr`), with
/// the G-buffer's albedo and emission (a = 2: glossy).
fn composed(
    gpu: &strata_render::GpuContext,
    scene: &strata_scene::Scene,
    ils: strata_render::passes::ils::IlsSettings,
) -> [strata_scene::ImageBuf; 4] {
    let r = common::ils_renderer(gpu, scene, ils, (W, H));
    ["hdr-full", "hdr", "albedo", "emission"].map(|name| {
        let img = r.read_target(gpu, name).unwrap();
        gpu.check_errors().unwrap();
        img
    })
}

/// The discontinuity-aware blur must not blur a glossy receiver's texture: it sees
/// no edge inside a flat, textured floor, so a blur of L_o (ρ inside) averages the
/// texture over its 9×7 kernel. The blur runs on L_o / A (A = `ggx_demodulation`,
/// ρ inside) and compose multiplies A back. Scene: cornell with its white
/// surfaces glossy (roughness 0.5, dielectric) under a grey checker of cells about
/// 5 pixels wide. Against the brute force without blur (every VPL at every pixel),
/// on the pixels inside a cell: the 8×6 frame with its default blur must keep the
/// checker's contrast of glossy radiance between light and dark cells (ratio of
/// ratios within 0.9–1.25; it was 0.16 before the demodulation), and its glossy
/// radiance's mean relative error must be at most 1.2 × that of the same frames
/// without the texture (0.22 against 0.20 measured; 0.75 before).
#[test]
fn glossy_blur_keeps_the_receivers_texture() {
    use strata_render::passes::ils::IlsSettings;
    use strata_scene::model::Texture;
    let gpu = common::gpu();
    let mut scene = strata_scene::procedural::builtin("cornell").unwrap();
    let white = scene.materials.iter().position(|m| m.name == "white").unwrap();
    let m = &mut scene.materials[white];
    (m.glossy, m.roughness, m.metallic, m.base_color) = (true, 0.5, 0.0, [1.0; 3]);
    m.base_color_texture = Some(scene.textures.len());
    let (light, dark) = (230u8, 60u8);
    // 8 × 8 cells of 4 × 4 texels (bilinear magnification blends only their edges)
    let size = 32u32;
    scene.textures.push(Texture {
        name: "checker".into(),
        width: size,
        height: size,
        rgba8: (0..size * size)
            .flat_map(|i| {
                let c = if ((i % size) / 4 + i / size / 4).is_multiple_of(2) {
                    light
                } else {
                    dark
                };
                [c, c, c, 255]
            })
            .collect(),
    });
    // planar UVs that work on the axis-aligned floor, ceiling and back wall
    for mesh in scene.meshes.iter_mut().filter(|mesh| mesh.material == white) {
        mesh.uvs = mesh
            .positions
            .iter()
            .map(|p| [(p[0] + p[1]) * 2.0, (p[2] + p[1]) * 2.0])
            .collect();
    }
    let mut plain = scene.clone();
    plain.materials[white].base_color_texture = None;
    plain.materials[white].base_color = [strata_scene::model::srgb_to_linear(light); 3];
    let (_, ils) = frame_vpls(&scene, 480);
    let frames = |scene: &strata_scene::Scene| {
        let brute = composed(
            &gpu,
            scene,
            IlsSettings {
                brute_force: true,
                ..ils.clone()
            },
        );
        let blurred = composed(
            &gpu,
            scene,
            IlsSettings {
                blur: IlsSettings::default().blur,
                ..ils.clone()
            },
        );
        (brute, blurred)
    };
    let ((brute, blurred), (plain_brute, plain_blurred)) = (frames(&scene), frames(&plain));
    let (albedo, emission) = (&brute[2], &brute[3]);
    // pixels inside a cell (texture filtering blends the cells' edges): 0 dark, 1 light
    let lin = [dark, light].map(strata_scene::model::srgb_to_linear);
    let cells: Vec<(usize, usize)> = (0..(W * H) as usize)
        .filter(|&i| emission.data[i * 4 + 3] > 1.5)
        .filter_map(|i| {
            let a = albedo.data[i * 4 + 1];
            (0..2).find(|&k| (a - lin[k]).abs() < 0.1 * lin[1]).map(|k| (i, k))
        })
        .collect();
    // glossy radiance: the composed frame minus its direct light (luminance)
    let glossy = |f: &[strata_scene::ImageBuf; 4], i: usize| {
        let lum = |img: &strata_scene::ImageBuf| {
            0.2126 * img.data[i * 4] + 0.7152 * img.data[i * 4 + 1] + 0.0722 * img.data[i * 4 + 2]
        };
        (lum(&f[0]) - lum(&f[1])) as f64
    };
    // per class: Σ glossy radiance of the brute force, of the blurred frame; count
    let mut sums = [[0.0f64; 3]; 2];
    for &(i, k) in &cells {
        sums[k][0] += glossy(&brute, i);
        sums[k][1] += glossy(&blurred, i);
        sums[k][2] += 1.0;
    }
    assert!(
        sums[0][2] > 100.0 && sums[1][2] > 100.0,
        "pixels inside cells: {sums:?}"
    );
    let contrast = |k: usize| sums[1][k] / sums[1][2] / (sums[0][k] / sums[0][2]);
    let (want, got) = (contrast(0), contrast(1));
    let error = |brute: &[strata_scene::ImageBuf; 4], blurred: &[strata_scene::ImageBuf; 4]| {
        let d: f64 = cells
            .iter()
            .map(|&(i, _)| (glossy(blurred, i) - glossy(brute, i)).abs())
            .sum();
        d / cells.iter().map(|&(i, _)| glossy(brute, i)).sum::<f64>()
    };
    let (textured, untextured) = (error(&brute, &blurred), error(&plain_brute, &plain_blurred));
    eprintln!(
        "{} pixels inside cells; light/dark glossy radiance: brute force {want:.3}, 8×6 blurred {got:.3}; \
         mean relative error {textured:.4} (without the texture {untextured:.4})",
        cells.len()
    );
    assert!(want > 3.0, "the checker shows in the brute force ({want})");
    assert!(
        (0.9..=1.25).contains(&(got / want)),
        "the blur changed the texture's contrast: {got} vs {want}"
    );
    assert!(
        textured <= 1.2 * untextured,
        "mean relative error {textured} with the texture, {untextured} without"
    );
}
