//! DGB §3.1 deep-G-buffer ambient occlusion: Eq. 1–2 over k layers with §3.4's
//! spiral QMC taps on the `zmip` chain. Output `ao-raw`: ambient visibility
//! AV ∈ [0, 1] (1 = unoccluded) before temporal and bilateral reconstruction.

pub(crate) mod stage;

use crate::passes::builder::{Kernel, PassBuilder, ScreenPass};
use glam::Vec3;
use strata_scene::{ImageBuf, Scene};

use crate::frame::{FrameUniforms, TargetDesc, Targets};
use crate::gpu::GpuContext;
use crate::passes::bilateral::BilateralSettings;
use crate::passes::depth_mip::DepthMipSettings;
use crate::passes::temporal::TemporalSettings;
use crate::scene_gpu::GpuScene;
use crate::spiral::{self, SpiralTurns};

/// Largest accepted sample count N.
pub const MAX_SAMPLES: u32 = 256;
/// Largest side n, m of a deinterleaving pattern (4×4 already leaves about one
/// of the default 19 taps per sub-buffer).
pub const MAX_DEINTERLEAVE: u32 = 4;

/// The passes the deinterleaved AO adds or substitutes, in frame order (the
/// `ao` pass is replaced by `ao-deint`), and `filter_obscurance`'s last pass.
pub const DEINTERLEAVED_PASSES: &[&str] = &[
    "ao-deint-copy",
    "ao-deint-split-z",
    "ao-deint-split-n",
    "ao-deint",
    "ao-deint-gather",
    "ao-resolve",
];

/// AO settings. Defaults: N = 19 taps (SAO's and the DGB demo's default; the
/// paper does not state its AO N), τ from Listing 3, φ from a per-pixel hash, the
/// scene's radius r, β = 0.01·r and ε = 0.01·r² (those of the CPU reference),
/// intensity 1 (Eq. 1 exactly), q = 8 px (SAO's first MIP step), 5 MIP levels,
/// temporal α = 0.85 (§3.3), 4-tap-radius bilateral with step 2 (SAO).
#[derive(Clone, Debug, PartialEq)]
pub struct AoSettings {
    /// World-space radius r; `None` = the scene's `ao_radius`.
    pub radius: Option<f32>,
    /// Bias β (world units); `None` = 0.01·r.
    pub bias: Option<f32>,
    /// ε (world units²); `None` = 0.01·r².
    pub epsilon: Option<f32>,
    /// Multiplies the sum in Eq. 1 (1 = the equation as written).
    pub intensity: f32,
    /// Samples N per pixel.
    pub samples: u32,
    /// τ: Listing 3 or fixed.
    pub turns: SpiralTurns,
    /// Rotate each pixel's spiral by φ = hash(x, y) (false: φ = 0, Fig. 7 left).
    pub rotate: bool,
    /// Also hash the renderer's frame count into φ, so the temporal filter
    /// averages different patterns. On by default (issue 14): the paper's φ
    /// depends on (x, y) only, which leaves a static view's 19-tap noise as
    /// fixed blotches after the bilateral filter (docs/ao.md "Temporal rotation").
    pub temporal_noise: bool,
    /// q: the tap radius in pixels at which the MIP level first increments.
    pub q: f32,
    pub mips: DepthMipSettings,
    pub blur: BilateralSettings,
    /// `None` disables the temporal filter.
    pub temporal: Option<TemporalSettings>,
    /// Deinterleaved evaluation (issue 11 item 8, `docs/ao.md`): the n×m
    /// pattern of the ILS split/gather passes; sub-buffer s = i + n·j
    /// evaluates the spiral taps k ≡ s (mod n·m) on its quarter-resolution
    /// (for 2×2) depth layout. `None` = the single full-resolution pass.
    pub deinterleave: Option<[u32; 2]>,
    /// Not in the paper: `ao-raw` holds the obscurance mean S = π/N·Σ A_i
    /// (Eq. 1 before the square root); the temporal and bilateral filters
    /// average S and a last pass `ao-resolve` writes AV = max(0, 1 − √S).
    /// Averaging after the square root is lighter than before it (Jensen),
    /// which the deinterleaved AO's few taps per pixel make large
    /// (`docs/ao.md`), and so does the per-frame rotation's temporal
    /// accumulation. Default true since issue 14 (false = DGB's order).
    pub filter_obscurance: bool,
    /// Not in the paper: the bilateral reconstruction also weighs each tap by its
    /// surface's world distance from X, × max(0, 1 − |Y − X|²/r²) with r the AO radius
    /// ([`BilateralSettings::world_radius`]). The paper's plane and normal weights accept
    /// a neighbour anywhere on X's plane, so on a surface seen at a grazing angle (a floor
    /// far away, the ground through a window) pixels a metre apart, farther than r, are
    /// averaged and a concave corner's occlusion spreads along the plane (issue 14's
    /// "dark halos"; docs/ao.md). Default true (false = DGB's weights).
    pub distance_weight: bool,
    /// The AO pass (Eq. 1–2; not the deinterleaved one) as a fullscreen fragment pass
    /// or as a compute pass (8×8 pixels per workgroup, storage-texture output): the same
    /// shader code and values. Not in the paper (default [`Kernel::Auto`]: compute on
    /// GPUs, fragment on CPU adapters; docs/ao.md § "The AO pass as compute").
    pub kernel: Kernel,
    /// The AO pass's resolution divisor s, 1..=[`MAX_SCALE`](crate::passes::upsample::MAX_SCALE):
    /// at s > 1 it shades one pixel of each s×s block (a different one each frame with
    /// `temporal_noise`) and a joint bilateral upsampling fills the rest (as the radiosity
    /// gather's `gather_scale`, whose blur steps s times as far; AO's does not: docs/ao.md
    /// § "Reduced-resolution AO"). Not with `deinterleave`. Not in the paper (default 1).
    pub scale: u32,
}

impl Default for AoSettings {
    fn default() -> Self {
        Self {
            radius: None,
            bias: None,
            epsilon: None,
            intensity: 1.0,
            samples: 19,
            turns: SpiralTurns::Optimal,
            rotate: true,
            temporal_noise: true,
            q: 8.0,
            mips: DepthMipSettings::default(),
            // 5 taps per direction, 1 px apart (σ = 1.5 px): measured against
            // converged references, SAO's 9 taps 2 px apart (σ = 6 px) blurred
            // contact shadows and, with taps of one pixel parity only, left a
            // 2×2 checker and row banding (`docs/ao.md`, issue 14).
            blur: BilateralSettings {
                radius: 2,
                step: 1,
                ..BilateralSettings::default()
            },
            temporal: Some(TemporalSettings::default()),
            deinterleave: None,
            filter_obscurance: true,
            distance_weight: true,
            kernel: Kernel::Auto,
            scale: 1,
        }
    }
}

impl AoSettings {
    pub fn validate(&self) -> Result<(), String> {
        let positive = |name: &str, v: Option<f32>| match v {
            Some(x) if !(x > 0.0 && x.is_finite()) => Err(format!("{name} {x} is out of range: must be > 0")),
            _ => Ok(()),
        };
        positive("AO radius", self.radius)?;
        positive("AO epsilon", self.epsilon)?;
        if let Some(b) = self.bias {
            if !(b >= 0.0 && b.is_finite()) {
                return Err(format!("AO bias {b} is out of range: must be >= 0"));
            }
        }
        if !(self.intensity >= 0.0 && self.intensity.is_finite()) {
            return Err(format!("AO intensity {} is out of range: must be >= 0", self.intensity));
        }
        if !(1..=MAX_SAMPLES).contains(&self.samples) {
            return Err(format!(
                "AO samples {} is out of range: must be in 1..={MAX_SAMPLES}",
                self.samples
            ));
        }
        if let SpiralTurns::Fixed(t) = self.turns {
            if !(t > 0.0 && t.is_finite()) {
                return Err(format!("spiral turns {t} is out of range: must be > 0"));
            }
        }
        if !(self.q >= 1.0 && self.q.is_finite()) {
            return Err(format!("MIP radius q {} is out of range: must be >= 1 pixel", self.q));
        }
        if let Some([n, m]) = self.deinterleave {
            if !(1..=MAX_DEINTERLEAVE).contains(&n) || !(1..=MAX_DEINTERLEAVE).contains(&m) || n * m > self.samples {
                return Err(format!(
                    "AO deinterleave pattern {n}x{m} is out of range: n and m must be in 1..={MAX_DEINTERLEAVE} and n·m <= samples ({})",
                    self.samples
                ));
            }
        }
        let max_scale = crate::passes::upsample::MAX_SCALE;
        if !(1..=max_scale).contains(&self.scale) {
            return Err(format!(
                "AO scale {} is out of range: must be in 1..={max_scale}",
                self.scale
            ));
        }
        if self.scale > 1 && self.deinterleave.is_some() {
            return Err(format!(
                "AO scale (ao-scale) {} needs deinterleave off: the deinterleaved AO shades every pixel",
                self.scale
            ));
        }
        self.mips.validate()?;
        self.blur.validate()?;
        if let Some(t) = &self.temporal {
            t.validate()?;
        }
        Ok(())
    }

    /// The bilateral reconstruction's settings: [`AoSettings::blur`] with the world radius
    /// r of [`AoSettings::distance_weight`] (`radius` = the resolved r).
    pub fn reconstruction(&self, radius: f32) -> BilateralSettings {
        BilateralSettings {
            world_radius: self.blur.world_radius.or(self.distance_weight.then_some(radius)),
            ..self.blur
        }
    }

    /// r, β, ε for `scene`.
    pub fn resolve(&self, scene: &Scene) -> (f32, f32, f32) {
        let r = self.radius.unwrap_or(scene.settings.ao_radius);
        (r, self.bias.unwrap_or(0.01 * r), self.epsilon.unwrap_or(0.01 * r * r))
    }
}

/// Mirrors `Ao` in `ao.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct AoUniforms {
    pub radius: f32,
    pub bias: f32,
    pub epsilon: f32,
    pub intensity: f32,
    pub proj_scale: f32,
    pub q: f32,
    pub tau: f32,
    pub rotate: u32,
    pub samples: u32,
    pub max_mip: u32,
    pub seed: u32,
    /// 1: write the obscurance mean S = π·intensity/N·Σ instead of AV = max(0, 1 − √S)
    /// ([`AoSettings::filter_obscurance`]).
    pub output_obscurance: u32,
}

impl AoUniforms {
    /// The uniforms of one frame: `frame` is the (guard-banded) frame's uniforms.
    pub fn new(s: &AoSettings, scene: &Scene, frame: &FrameUniforms, max_mip: u32, frame_index: u32) -> Self {
        let (radius, bias, epsilon) = s.resolve(scene);
        Self {
            radius,
            bias,
            epsilon,
            intensity: s.intensity,
            proj_scale: proj_scale(frame),
            q: s.q,
            tau: s.turns.tau(s.samples),
            rotate: s.rotate as u32,
            samples: s.samples,
            max_mip,
            seed: if s.temporal_noise { frame_index } else { 0 },
            output_obscurance: s.filter_obscurance as u32,
        }
    }
}

/// Pixels spanned by an object of height 1 at camera-space depth 1 (the
/// demo's `projScale`): image height / (2 tan(fov_y / 2)).
pub fn proj_scale(frame: &FrameUniforms) -> f32 {
    let up = Vec3::from_slice(&frame.cam_up[..3]).length();
    frame.size[1] / (2.0 * up)
}

pub const OUTPUT: TargetDesc = TargetDesc::new(
    "ao-raw",
    wgpu::TextureFormat::R32Float,
    1,
    "DGB Eq. 1 ambient visibility before reconstruction (1 = unoccluded)",
);

/// The AO pass's output at [`AoSettings::scale`] > 1 (⌈w/s⌉ × ⌈h/s⌉), before its upsampling
/// into [`OUTPUT`].
pub const OUTPUT_LOW: TargetDesc = TargetDesc::new(
    "ao-raw-low",
    wgpu::TextureFormat::R32Float,
    1,
    "DGB Eq. 1 at 1/s resolution: one pixel per s×s block (AoSettings::scale)",
);

pub struct AoPass {
    pass: ScreenPass,
    last: std::cell::Cell<AoUniforms>,
    /// The split geometry of the deinterleaved pass (`ao-deint`); `None`: `ao`.
    ils: Option<crate::passes::interleave::IlsUniforms>,
}

/// Mirrors `DeintAo` in `ao_deint.wgsl`: Eq. 1–2's uniforms and the split's geometry.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct DeintUniforms {
    ao: AoUniforms,
    ils: crate::passes::interleave::IlsUniforms,
}

/// The tiled targets of the deinterleaved AO (sub-buffer (i, j) at
/// `InterleaveGeometry::tile_origin(i, j)`).
pub const DEINT_Z: TargetDesc = TargetDesc::new(
    "ao-deint-z",
    wgpu::TextureFormat::Rg32Float,
    1,
    "zmip level 0 copied to a single-level texture (the split's source)",
);
pub const DEINT_Z_SPLIT: TargetDesc = TargetDesc::new(
    "ao-deint-z-split",
    wgpu::TextureFormat::Rg32Float,
    1,
    "ILS §3.2 split of zmip level 0: n×m tiled sub-buffers of camera-space z (channel j = layer j)",
);
pub const DEINT_N_SPLIT: TargetDesc = TargetDesc::new(
    "ao-deint-n-split",
    wgpu::TextureFormat::Rgba8Unorm,
    1,
    "ILS §3.2 split of npack (Oct16 normals) into n×m tiled sub-buffers",
);
pub const DEINT_RAW_TILED: TargetDesc = TargetDesc::new(
    "ao-raw-tiled",
    wgpu::TextureFormat::R32Float,
    1,
    "deinterleaved DGB Eq. 1: each sub-buffer's AV from its subset of the spiral taps, tiled",
);

impl AoPass {
    /// `compute`: [`AoSettings::kernel`] resolved (the output must then allow storage
    /// binding); `scale`: [`AoSettings::scale`] (> 1: into [`OUTPUT_LOW`]).
    pub fn new(gpu: &GpuContext, scene: &GpuScene, targets: &Targets, layers: u32, compute: bool, scale: u32) -> Self {
        let zeroed = AoUniforms::zeroed();
        let mut builder = PassBuilder::new(gpu, targets, "ao");
        if compute {
            builder = builder.compute().entry("cs_main");
        }
        let builder = builder
            .shader("ao", include_str!("ao.wgsl"))
            .constant("LAYERS", layers as f64)
            .constant("SCALE", scale as f64)
            .frame(scene)
            .uniforms(&zeroed)
            .read("zmip")
            .read("npack");
        let output = if scale > 1 { OUTPUT_LOW } else { OUTPUT };
        let pass = ScreenPass::build(builder, &[output.name], compute);
        Self {
            pass,
            last: std::cell::Cell::new(zeroed),
            ils: None,
        }
    }

    /// The deinterleaved pass `ao-deint`: one full-screen pass over the tiled
    /// buffer (every sub-buffer in its tile), reading the split depth and
    /// normals, writing [`DEINT_RAW_TILED`].
    pub(crate) fn new_deinterleaved(
        gpu: &GpuContext,
        scene: &GpuScene,
        targets: &Targets,
        layers: u32,
        geometry: &crate::passes::interleave::InterleaveGeometry,
    ) -> Self {
        let zeroed = AoUniforms::zeroed();
        let ils = geometry.uniforms(crate::passes::interleave::PADDING_MARKER);
        let pass = PassBuilder::new(gpu, targets, "ao-deint")
            .shader("ao-deint", include_str!("ao_deint.wgsl"))
            .constant("LAYERS", layers as f64)
            .frame(scene)
            .uniforms(&DeintUniforms { ao: zeroed, ils })
            .read(DEINT_Z_SPLIT.name)
            .read(DEINT_N_SPLIT.name)
            .read("zmip")
            .write(DEINT_RAW_TILED.name)
            .build();
        Self {
            pass: ScreenPass::Fragment(pass, None),
            last: std::cell::Cell::new(zeroed),
            ils: Some(ils),
        }
    }

    pub fn set_frame(&self, gpu: &GpuContext, u: AoUniforms) {
        match self.ils {
            Some(ils) => self.pass.set_uniforms(gpu, &DeintUniforms { ao: u, ils }),
            None => self.pass.set_uniforms(gpu, &u),
        }
        self.last.set(u);
    }

    /// The uniforms of the last frame (for CPU re-evaluation).
    pub fn uniforms(&self) -> AoUniforms {
        self.last.get()
    }
}

use bytemuck::Zeroable;

crate::passes::builder::delegate_pass!(AoPass);

/// CPU evaluation of exactly what `ao.wgsl` computes at pixel (x, y), from
/// read-back buffers: `zmip[m]` is MIP level m (channel j = layer j), `normals`
/// the decoded layer-0 world normals (3 channels). Eq. 1–2 with the same
/// spiral taps, texel rounding and MIP levels.
pub fn ambient_visibility_cpu(
    zmip: &[ImageBuf],
    normals: &ImageBuf,
    frame: &FrameUniforms,
    u: &AoUniforms,
    layers: u32,
    x: u32,
    y: u32,
) -> f32 {
    deinterleaved_visibility_cpu(zmip, normals, frame, u, layers, [1, 1], x, y)
}

/// The taps of sub-buffer (i, j) of an n×m pattern: k ≡ s (mod n·m) with
/// s = i + n·j, and how many there are, N_s = ⌈(N − s)/(n·m)⌉ (≥ 1 when
/// n·m ≤ N). Striding through the spiral gives every sub-buffer taps over the
/// whole radius range κ ∈ (0, 1) (a contiguous block of k would give one
/// sub-buffer only the nearest taps), and the n·m pixels of a pattern cell
/// together evaluate each of the N taps exactly once.
pub fn sub_buffer_taps(
    samples: u32,
    [n, m]: [u32; 2],
    i: u32,
    j: u32,
) -> (std::iter::StepBy<std::ops::Range<u32>>, u32) {
    let count = n * m;
    let s = i + n * j;
    ((s..samples).step_by(count as usize), (samples - s).div_ceil(count))
}

/// A full-resolution tap offset d (px) snapped to the lattice of pixels of the
/// same sub-buffer, in sub-buffer texels: ⌊(d + n/2)/n⌋ = ⌊d/n + ½⌋ per axis
/// (integer maths, as in `ao_deint.wgsl`). The tap then lies at full-res pixel
/// p + n·that, i.e. at most n/2 px from where the spiral put it.
pub fn snap_tap(d: [i32; 2], [n, m]: [u32; 2]) -> [i32; 2] {
    let f = |d: i32, n: u32| (2 * d + n as i32).div_euclid(2 * n as i32);
    [f(d[0], n), f(d[1], m)]
}

/// CPU twin of the deinterleaved AO (`ao_deint.wgsl`) at full-resolution
/// pixel (x, y) for the n×m `pattern`: Eq. 1–2 over the taps of the pixel's
/// sub-buffer ([`sub_buffer_taps`]), each snapped to the sub-buffer's lattice
/// ([`snap_tap`]) and normalised by N_s. Level-0 taps read the split depth,
/// which holds exactly the full-resolution texel at the snapped pixel, so this
/// reads `zmip[0]` there; taps at MIP level ≥ 1 (DGB §3.4) read the MIP chain
/// at the snapped pixel as the single-pass AO does. 1×1 is the single-pass AO.
#[allow(clippy::too_many_arguments)]
pub fn deinterleaved_visibility_cpu(
    zmip: &[ImageBuf],
    normals: &ImageBuf,
    frame: &FrameUniforms,
    u: &AoUniforms,
    layers: u32,
    pattern: [u32; 2],
    x: u32,
    y: u32,
) -> f32 {
    visibility_from_obscurance(deinterleaved_obscurance_cpu(
        zmip, normals, frame, u, layers, pattern, x, y,
    ))
}

/// Eq. 1's AV = max(0, 1 − √S) of an obscurance mean S (`ao-resolve`).
pub fn visibility_from_obscurance(s: f32) -> f32 {
    (1.0 - s.sqrt()).max(0.0)
}

/// The obscurance mean S = π·intensity/N_s·Σ of [`deinterleaved_visibility_cpu`]
/// (what `ao-raw` holds with [`AoSettings::filter_obscurance`]; 0 = no surface).
#[allow(clippy::too_many_arguments)]
pub fn deinterleaved_obscurance_cpu(
    zmip: &[ImageBuf],
    normals: &ImageBuf,
    frame: &FrameUniforms,
    u: &AoUniforms,
    layers: u32,
    pattern: [u32; 2],
    x: u32,
    y: u32,
) -> f32 {
    let z = zmip[0].pixel(x, y)[0];
    if z <= 0.0 {
        return 0.0;
    }
    let px = normals.pixel(x, y);
    let n = Vec3::new(px[0], px[1], px[2]);
    let pos = world_from_csz(frame, [x as f32 + 0.5, y as f32 + 0.5], z);
    let r_p = u.proj_scale * u.radius / z;
    let phi = if u.rotate != 0 {
        spiral::pixel_angle(x, y, u.seed)
    } else {
        0.0
    };
    let (w, h) = (zmip[0].width as i32, zmip[0].height as i32);
    let (taps, taps_here) = sub_buffer_taps(u.samples, pattern, x % pattern[0], y % pattern[1]);
    let mut sum = 0.0f32;
    for i in taps {
        let tap = spiral::spiral_tap(i, u.samples, u.tau, r_p, phi);
        let dl = snap_tap(spiral::tap_texel(tap.offset), pattern);
        let (qx, qy) = (
            x as i32 + dl[0] * pattern[0] as i32,
            y as i32 + dl[1] * pattern[1] as i32,
        );
        if qx < 0 || qy < 0 || qx >= w || qy >= h {
            continue;
        }
        let m = spiral::mip_level(tap.radius, u.q, u.max_mip);
        let (tx, ty) = crate::passes::depth_mip::mip_texel(qx as u32, qy as u32, m, w as u32, h as u32);
        let zs = zmip[m as usize].pixel(tx, ty);
        let (sx, sy) = crate::passes::depth_mip::source_pixel(tx, ty, m, w as u32, h as u32);
        let mut a = 0.0f32;
        for &zj in zs.iter().take(layers as usize) {
            if zj > 0.0 {
                let yv = world_from_csz(frame, [sx as f32 + 0.5, sy as f32 + 0.5], zj);
                a = a.max(obscurance(u, yv - pos, n));
            }
        }
        sum += a;
    }
    u.intensity * std::f32::consts::PI / taps_here as f32 * sum
}

/// DGB Eq. 2.
pub fn obscurance(u: &AoUniforms, v: Vec3, n: Vec3) -> f32 {
    let vv = v.dot(v);
    let r2 = u.radius * u.radius;
    if vv.partial_cmp(&r2) != Some(std::cmp::Ordering::Less) {
        return 0.0;
    }
    (1.0 - vv / r2) * ((v.dot(n) - u.bias) / (vv + u.epsilon).sqrt()).max(0.0)
}

/// Pixel position of world point `q`, `None` at or before the near plane: the inverse of
/// [`world_from_csz`] (`pixel_of_world` in common/camera.wgsl).
pub fn pixel_of_world(f: &FrameUniforms, q: Vec3) -> Option<[f32; 2]> {
    let v3 = |a: [f32; 4]| Vec3::new(a[0], a[1], a[2]);
    let v = q - v3(f.eye);
    let z = v.dot(v3(f.cam_forward));
    if z <= f.eye[3] {
        return None;
    }
    let (right, up) = (v3(f.cam_right), v3(f.cam_up));
    let ndc = [v.dot(right) / right.dot(right) / z, v.dot(up) / up.dot(up) / z];
    Some([(ndc[0] * 0.5 + 0.5) * f.size[0], (0.5 - ndc[1] * 0.5) * f.size[1]])
}

/// `camera.wgsl`'s `pixel_dir` on the CPU: the world direction through a pixel position,
/// scaled so its forward component is 1.
pub fn pixel_dir(f: &FrameUniforms, pix: [f32; 2]) -> Vec3 {
    let v = |a: [f32; 4]| Vec3::new(a[0], a[1], a[2]);
    let ndc = [pix[0] * f.size[2] * 2.0 - 1.0, 1.0 - pix[1] * f.size[3] * 2.0];
    v(f.cam_forward) + v(f.cam_right) * ndc[0] + v(f.cam_up) * ndc[1]
}

/// `camera.wgsl`'s `world_from_csz` on the CPU.
pub fn world_from_csz(f: &FrameUniforms, pix: [f32; 2], z: f32) -> Vec3 {
    Vec3::new(f.eye[0], f.eye[1], f.eye[2]) + pixel_dir(f, pix) * z
}
