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
/// blue glossy vase, Lambert cloth and boxes) and, per pixel, the CPU twin of what it must hold: from the
/// frame's own csz, decoded normal, roughness, metallic, albedo and glossy flag
/// (emission.a = 2), Σ_k `glossy_radiance_at` (glossy pixels) or Σ_k
/// `irradiance_at` (Lambert pixels) over the pixel's VPL subset (8×6, or all
/// for the brute force) scaled by N/N_s; a term counts only where `visible`
/// (the VPL seen from the surface point) says so.
struct GlossyFrame {
    irradiance: strata_scene::ImageBuf,
    glossy: strata_scene::ImageBuf,
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
    use strata_render::frame::FrameCameras;
    use strata_render::{RenderSettings, Renderer};
    let max_g = ils.max_geometry(scene);
    let brute_force = ils.brute_force;
    let t = strata_render::technique::find("ils").unwrap();
    let mut s = t
        .settings(
            &RenderSettings {
                width: W,
                height: H,
                ..Default::default()
            },
            None,
        )
        .unwrap();
    s.ils = Some(ils);
    let mut r = Renderer::new(gpu, scene, s).expect("renderer builds without validation errors");
    r.render(gpu, scene, &FrameCameras::fixed(scene.camera), 0.0)
        .expect("frame renders without validation errors");
    let read = |name: &str| {
        let img = r.read_target(gpu, name).unwrap();
        gpu.check_errors().unwrap();
        img
    };
    let (irradiance, glossy) = (read("ils-irradiance"), read("ils-glossy"));
    let (nrm, albedo, emission) = (read("normal"), read("albedo"), read("emission"));
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
/// CPU sum in `ils-glossy` and 0 in `ils-irradiance`; Lambert pixels carry
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
