//! The bounced z-buffer (BZB, Nalbach, Ritschel, Seidel 2016) for ambient
//! occlusion with ambient occlusion volumes (AOV, McGuire 2010) as the
//! splatting algorithm: indirect visibility by rasterisation, no ray-tracing
//! hierarchy.
//!
//! Passes (profiler names), after the deep G-buffer's packing:
//!
//! 1. `bzb-directions` (§3.1): every texel of the bounced z-buffer — S
//!    interleaved sub-images of the frame's size, direction s of pixel p in
//!    sub-image s — gets the ray origin x_p (layer 0) and a direction ω on the
//!    hemisphere around n_p (cosine-weighted by default, or uniform as the
//!    paper's AO) from a hash of (p, s, seed), with its pdf α
//!    ([`sample_uniforms`], [`direction`] are the CPU twins).
//! 2. `bzb-splat` (§3.2): one instanced draw, one instance per (triangle, s),
//!    six vertices pulled from a storage buffer of world-space triangles (wgpu
//!    has no geometry or tessellation shaders, so no per-triangle volume is
//!    emitted): the screen rectangle of the triangle's AABB grown by r, a
//!    conservative bound of its occlusion volume {x : dist(x, T) < r}, in
//!    sub-image s. Each covered texel intersects its own ray with the triangle
//!    ([`ray_triangle`]); a hit at t ∈ (t_min, r) writes depth t²/r² and payload
//!    1 with the depth test on and blending off, so the nearest occluder along ω
//!    wins; a miss discards. With `visibility = false` (the baseline) the same
//!    splats add McGuire's analytic AOV occlusion ([`aov_occlusion`]) with
//!    additive blending and no depth test.
//! 3. `bzb-reconstruct` (§3.3, weighting): per pixel the mean over its S
//!    directions of occlusion · (cos θ/π)/α — an unbiased estimate of binary
//!    AO with the cosine-weighted measure, the quantity the CPU reference
//!    `ao_binary` integrates — and AV = 1 − AO into `bzb-raw`.
//! 4. `bzb-blur-h`, `bzb-blur-v` (§3.3, filtering): the cross-bilateral filter
//!    of [`crate::passes::bilateral`] (position and normal weights) into `ao`,
//!    the target DGB AO writes, so compose and `eval` treat both alike.

/// WGSL of a pass that shades bzb-gi senders: the shared bounced-z-buffer and GI
/// uniforms, the sender shading (`bzb_gi_sender.wgsl`) and the pass's own `$file`.
macro_rules! gi_sender_shader {
    ($file:literal) => {
        concat!(
            include_str!("bzb.wgsl"),
            "\n",
            include_str!("bzb_gi.wgsl"),
            "\n",
            include_str!("bzb_gi_sender.wgsl"),
            "\n",
            include_str!($file)
        )
    };
}

pub mod dss;
pub mod gi;

use bytemuck::Zeroable;
use glam::Vec3;
use strata_scene::Scene;

use crate::frame::{Pass, PassInfo, TargetDesc, Targets};
use crate::gpu::GpuContext;
use crate::passes::bilateral::{BilateralPass, BilateralSettings};
use crate::passes::builder::{FullscreenPass, PassBuilder};
use crate::scene_gpu::GpuScene;
use crate::spiral::pcg_hash;

/// Largest accepted directions per pixel S.
pub const MAX_DIRECTIONS: u32 = 16;

/// How §3.1 distributes the bounced directions on the hemisphere.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Hemisphere {
    /// pdf cos θ/π: the weight of §3.3 cancels (each sample is 0 or 1), the
    /// lowest-variance choice for cosine-weighted AO (default).
    #[default]
    Cosine,
    /// pdf 1/(2π): the paper's choice for AO (§3.1); §3.3 weights by 2 cos θ.
    Uniform,
}

/// The splatting algorithm whose splats the bounced z-buffer tests (BZB §3.2).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Splat {
    /// Ambient occlusion volumes: one splat per triangle (McGuire 2010; default).
    #[default]
    Aov,
    /// Deep screen space: surfels shell-splatted into an interleaved
    /// hierarchical framebuffer (BZB §4, [`dss`]).
    Dss,
}

/// Bounced-z-buffer AO settings. Defaults: S = 4 directions per pixel (the
/// paper's, §5), the bounced z-buffer on, cosine-weighted directions, the
/// scene's AO radius r as d_max, t_min = 0.01·r (DGB AO's bias convention),
/// seed 0, and a cross-bilateral filter of 4 taps each side, 1 px apart.
#[derive(Clone, Debug, PartialEq)]
pub struct BzbSettings {
    /// S: directions per pixel, one sub-image each (1..=16).
    pub directions: u32,
    /// true: the bounced z-buffer (§3.2, nearest occluder wins); false: the
    /// AOV baseline (additive blending of the analytic occlusion, no depth test).
    pub visibility: bool,
    /// World-space AO radius r = d_max; `None` = the scene's `ao_radius`.
    pub radius: Option<f32>,
    /// Ray t_min (world units): hits nearer than this do not occlude (the
    /// receiver's own surface); `None` = 0.01·r.
    pub bias: Option<f32>,
    pub hemisphere: Hemisphere,
    /// Seed of the direction hash (§3.1).
    pub seed: u32,
    /// The cross-bilateral reconstruction filter (§3.3).
    pub filter: BilateralSettings,
    /// Cull splats (AOV triangles, DSS shells) whose camera-depth range misses every
    /// receiver under them, from min/max depth tiles (issue 13 item 4, BZB §4.3's
    /// "Min/Max MIP-map for splat culling"); the image is the same either way.
    pub culling: bool,
    /// AOV splats draw the box around each triangle's occlusion volume, clipped to the
    /// screen rectangle of its grown AABB (true), or that rectangle alone (false, the
    /// default). Both bound the volume, so the image is the same. The box covers fewer
    /// texels but draws 36 vertices an instance against 6; on lavapipe it is slower
    /// (`docs/bzb.md` § "Box splats").
    pub box_splats: bool,
    /// How the AOV splats build the bounced z-buffer: the rasteriser's depth test (the
    /// paper) or a compute pass over the same rectangles with the same tests, keeping
    /// the nearest hit (ties to the first triangle, as the depth test's draw order)
    /// with 64-bit atomics (`SHADER_INT64_ATOMIC_MIN_MAX`); the same bits either way.
    /// `Auto` (default): compute on GPUs that have those atomics, for rectangle splats;
    /// fragment on CPU adapters. Visibility on only: the additive baseline blends in
    /// fragments. `docs/bzb.md` § "Compute splats".
    pub splat_kernel: crate::passes::Kernel,
    /// The splatting algorithm (AOV or DSS).
    pub splat: Splat,
    /// DSS's levels, surfel size and frustum culling (used with `Splat::Dss`).
    pub dss: dss::DssSettings,
    /// The "simple re-projection" BZB §6 applies for animated scenes: DGB §3.3's
    /// temporal filter (reverse reprojection, EWMA) on the reconstructed AV before the
    /// bilateral filter, with the directions re-drawn every frame (seed + frame), so a
    /// still camera averages S new directions per frame. `None` (the default, as the
    /// paper's figures): every frame stands alone.
    pub temporal: Option<crate::passes::temporal::TemporalSettings>,
}

/// The temporal filter `alpha` turns on for `bzb-ao` and `bzb-gi`: DGB's defaults
/// without the history clamp. A few directions per pixel make the current 3×3
/// neighbourhood a skewed sample (most rays miss, a few hit), whose range often lies
/// away from the history's mean: clamping pulled the average towards the median (for
/// bzb-gi the atrium's shade came out 2.5 % dark).
pub fn temporal_filter() -> crate::passes::temporal::TemporalSettings {
    crate::passes::temporal::TemporalSettings {
        clamp_history: false,
        ..Default::default()
    }
}

/// The directions' seed of frame `frame_index` with the temporal filter on (0 keeps
/// the settings' seed): a new set of S directions per frame.
pub fn frame_seed(seed: u32, frame_index: u32) -> u32 {
    seed.wrapping_add(frame_index.wrapping_mul(0x9e37_79b9))
}

impl Default for BzbSettings {
    fn default() -> Self {
        Self {
            directions: 4,
            visibility: true,
            radius: None,
            bias: None,
            hemisphere: Hemisphere::Cosine,
            seed: 0,
            filter: BilateralSettings {
                radius: 4,
                step: 1,
                ..BilateralSettings::default()
            },
            culling: true,
            box_splats: false,
            splat_kernel: crate::passes::Kernel::Auto,
            splat: Splat::Aov,
            dss: dss::DssSettings::default(),
            temporal: None,
        }
    }
}

impl BzbSettings {
    pub fn validate(&self) -> Result<(), String> {
        if !(1..=MAX_DIRECTIONS).contains(&self.directions) {
            return Err(format!(
                "bzb directions {} is out of range: must be in 1..={MAX_DIRECTIONS}",
                self.directions
            ));
        }
        if let Some(r) = self.radius {
            if !(r > 0.0 && r.is_finite()) {
                return Err(format!("bzb AO radius {r} is out of range: must be > 0"));
            }
        }
        if let Some(b) = self.bias {
            if !(b >= 0.0 && b.is_finite()) {
                return Err(format!("bzb AO bias {b} is out of range: must be >= 0"));
            }
        }
        splat_kernel_valid("bzb", self.splat_kernel, self.box_splats, self.splat)?;
        self.dss.validate()?;
        if let Some(t) = &self.temporal {
            t.validate()?;
        }
        self.filter.validate()
    }

    /// Whether the AOV splats of a `w`×`h` frame run as a compute pass on `gpu`
    /// ([`Self::splat_kernel`] resolved: `Auto` by adapter, features, limits, visibility
    /// and splat bounds).
    pub fn compute_splat_on(&self, gpu: &GpuContext, w: u32, h: u32) -> bool {
        let (c, r) = self.grid();
        let texels = (w * c) as u64 * (h * r) as u64;
        let form = (self.visibility, self.box_splats);
        self.splat == Splat::Aov && splat_compute_on(gpu, "bzb", self.splat_kernel, form, texels).unwrap_or(false)
    }

    /// r and t_min for `scene`.
    pub fn resolve(&self, scene: &Scene) -> (f32, f32) {
        let r = self.radius.unwrap_or(scene.settings.ao_radius);
        (r, self.bias.unwrap_or(0.01 * r))
    }

    /// DSS uniforms for a `w`×`h` frame, AO radius `r`, bias `t_min`.
    pub fn dss_uniforms(&self, w: u32, h: u32, r: f32, t_min: f32, triangles: u32) -> dss::DssUniforms {
        let (cols, rows) = self.grid();
        let [tri_capacity, fine_capacity, surfel_capacity] = dss::capacities(triangles);
        dss::DssUniforms {
            levels: self.dss.levels,
            directions: self.directions,
            cols,
            rows,
            size: [w, h],
            plane: self.dss.plane(w, h),
            d_max: self.dss.d_max(r),
            t_min,
            surfel_px: self.dss.surfel_px,
            fine_ratio: dss::FINE_RATIO,
            max_fine: dss::MAX_FINE,
            tri_capacity,
            fine_capacity,
            surfel_capacity,
            seed: self.seed,
            visibility: self.visibility as u32,
            culling: self.dss.culling as u32,
            triangles,
            max_split: dss::MAX_SPLIT,
            gi: 0,
            depth_culling: self.culling as u32,
            redirect: self.dss.redirect as u32,
        }
    }

    /// The frame's BZB passes (profiler names) for this splatting algorithm, with the
    /// temporal filter when it is on.
    pub fn pass_names(&self) -> Vec<&'static str> {
        let splat: &[&str] = match self.splat {
            Splat::Aov => &["bzb-directions", "bzb-zminmax", "bzb-splat", "bzb-reconstruct"],
            Splat::Dss => &[
                "bzb-directions",
                "bzb-zminmax",
                "dss-tessellate",
                "dss-fine",
                "dss-filter",
                "dss-shuffle",
                "dss-splat",
                "dss-unshuffle",
                "dss-reduce",
                "bzb-reconstruct",
            ],
        };
        let temporal = self.temporal.is_some().then_some(TEMPORAL_PASS);
        splat
            .iter()
            .copied()
            .chain(temporal)
            .chain(["bzb-blur-h", "bzb-blur-v"])
            .collect()
    }

    /// Sub-image grid (cols, rows) holding S sub-images: cols = ⌈√S⌉.
    pub fn grid(&self) -> (u32, u32) {
        let cols = (self.directions as f32).sqrt().ceil() as u32;
        (cols, self.directions.div_ceil(cols))
    }

    /// GPU bytes for a `w`×`h` frame and `triangles` triangles: the bounced
    /// z-buffer (origins, directions, payload, depth) and the reconstruction targets.
    pub fn estimated_bytes(&self, w: u32, h: u32, triangles: u64) -> u64 {
        let (c, r) = self.grid();
        let px = w as u64 * h as u64;
        if self.splat == Splat::Dss {
            let m = dss::memory(&self.dss_uniforms(w, h, 0.0, 0.0, triangles as u32));
            return px * (c * r) as u64 * (16 + 16 + 2)
                + px * (4 + 2 + 2)
                + triangles * 48
                + m.shuffled_positions
                + m.shuffled_directions
                + m.layered_framebuffer
                + m.surfels;
        }
        // the compute splats' keys, where they may run
        let compute = self.splat_kernel != crate::passes::Kernel::Fragment && !self.box_splats;
        let keys = if compute && self.visibility { 8 } else { 0 };
        px * (c * r) as u64 * (16 + 16 + 2 + 4 + keys)
            + px * (4 + 2 + 2)
            + triangles * 48
            + zminmax_tile_count(w, h) as u64 * 8
    }
}

/// `splat-kernel=compute` tests the AOV splats' rectangles: not box splats, not DSS.
/// `technique` names it in the error.
pub(crate) fn splat_kernel_valid(
    technique: &str,
    kernel: crate::passes::Kernel,
    box_splats: bool,
    splat: Splat,
) -> Result<(), String> {
    if kernel == crate::passes::Kernel::Compute && box_splats {
        return Err(format!("{technique} splat-kernel=compute tests the splats' rectangles: use splat-bounds=rect (box splats need splat-kernel=fragment or auto)"));
    }
    if kernel == crate::passes::Kernel::Compute && splat == Splat::Dss {
        return Err(format!(
            "{technique} splat-kernel=compute applies to splat=aov (DSS splats its surfels in fragments)"
        ));
    }
    Ok(())
}

/// Whether the AOV splats run as a compute pass on `gpu` ([`BzbSettings::splat_kernel`])
/// over a bounced z-buffer of `texels` texels: `Compute` where the adapter has 64-bit
/// atomic max on storage buffers and a storage buffer can hold the keys (8 bytes a texel;
/// a one-line error naming the setting otherwise), `Auto` on GPUs where both hold, with
/// visibility and rectangle splats; never without visibility (the baseline blends).
pub(crate) fn splat_compute_on(
    gpu: &GpuContext,
    technique: &str,
    kernel: crate::passes::Kernel,
    (visibility, box_splats): (bool, bool),
    texels: u64,
) -> Result<bool, crate::RenderError> {
    let atomics = gpu.has(wgpu::Features::SHADER_INT64 | wgpu::Features::SHADER_INT64_ATOMIC_MIN_MAX);
    let limits = gpu.device.limits();
    let largest = limits.max_storage_buffer_binding_size.min(limits.max_buffer_size);
    let keys = texels.saturating_mul(8);
    if kernel == crate::passes::Kernel::Compute && visibility {
        if !atomics {
            return Err(crate::RenderError::Parameter(format!(
                "{technique} splat-kernel=compute needs 64-bit atomics (SHADER_INT64_ATOMIC_MIN_MAX), which this adapter lacks: use splat-kernel=fragment or auto"
            )));
        }
        if keys > largest {
            return Err(crate::RenderError::Parameter(format!(
                "{technique} splat-kernel=compute: the keys of {texels} bounced-z-buffer texels ({keys} bytes) exceed the adapter's largest storage buffer ({largest} bytes): lower the directions or the size, or use splat-kernel=fragment or auto"
            )));
        }
    }
    Ok(visibility && atomics && keys <= largest && !box_splats && kernel.compute_on(gpu))
}

/// Mirrors `Bzb` in `bzb.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct BzbUniforms {
    pub radius: f32,
    pub t_min: f32,
    pub inv_r2: f32,
    /// bzb-gi: 1 = rays that hit nothing within d_max see the sky (d_max ≥ the scene's
    /// diagonal); always 0 for AO.
    pub escape_sky: u32,
    pub directions: u32,
    pub cols: u32,
    pub rows: u32,
    pub seed: u32,
    pub hemisphere: u32,
    pub visibility: u32,
    pub triangles: u32,
    pub culling: u32,
    pub box_splats: u32,
}

impl BzbUniforms {
    pub fn new(s: &BzbSettings, scene: &Scene, triangles: u32) -> Self {
        let (radius, t_min) = s.resolve(scene);
        let (cols, rows) = s.grid();
        Self {
            radius,
            t_min,
            inv_r2: 1.0 / (radius * radius),
            escape_sky: 0,
            directions: s.directions,
            cols,
            rows,
            seed: s.seed,
            hemisphere: s.hemisphere as u32,
            visibility: s.visibility as u32,
            triangles,
            culling: s.culling as u32,
            box_splats: s.box_splats as u32,
        }
    }
}

// ---- CPU twins of bzb.wgsl ----

/// `bzb_sample_uniforms`: two uniforms in [0, 1) from a hash of pixel `p`, direction `s`, `seed`.
pub fn sample_uniforms(p: [u32; 2], s: u32, seed: u32) -> [f32; 2] {
    let h1 = pcg_hash(p[0].wrapping_add(pcg_hash(p[1].wrapping_add(pcg_hash(s.wrapping_add(pcg_hash(seed)))))));
    let h2 = pcg_hash(h1 ^ 0x9e37_79b9);
    [(h1 >> 8) as f32 / 16_777_216.0, (h2 >> 8) as f32 / 16_777_216.0]
}

/// `bzb_direction` (§3.1): ω on the hemisphere around unit `n` from uniforms `u`, and its pdf α.
pub fn direction(n: Vec3, u: [f32; 2], hemisphere: Hemisphere) -> (Vec3, f32) {
    use std::f32::consts::PI;
    let phi = 2.0 * PI * u[1];
    let (l, pdf) = match hemisphere {
        Hemisphere::Cosine => {
            let r = u[0].sqrt();
            let z = (1.0 - u[0]).max(0.0).sqrt();
            (Vec3::new(r * phi.cos(), r * phi.sin(), z), z / PI)
        }
        Hemisphere::Uniform => {
            let r = (1.0 - u[0] * u[0]).max(0.0).sqrt();
            (Vec3::new(r * phi.cos(), r * phi.sin(), u[0]), 0.5 / PI)
        }
    };
    let sgn = if n.z >= 0.0 { 1.0 } else { -1.0 };
    let a = -1.0 / (sgn + n.z);
    let b = n.x * n.y * a;
    let t = Vec3::new(1.0 + sgn * n.x * n.x * a, sgn * b, -sgn * n.x);
    let bt = Vec3::new(b, sgn + n.y * n.y * a, -n.y);
    (t * l.x + bt * l.y + n * l.z, pdf)
}

/// The pdf α(ω | n) of [`direction`] (0 below the horizon).
pub fn pdf(n: Vec3, w: Vec3, hemisphere: Hemisphere) -> f32 {
    let c = n.dot(w);
    if c <= 0.0 {
        return 0.0;
    }
    match hemisphere {
        Hemisphere::Cosine => c / std::f32::consts::PI,
        Hemisphere::Uniform => 0.5 / std::f32::consts::PI,
    }
}

/// `bzb_ray_triangle` (§3.2): t of o + t·d on triangle `v` (both faces), `None` on a miss.
pub fn ray_triangle(o: Vec3, d: Vec3, v: [Vec3; 3]) -> Option<f32> {
    let (e1, e2) = (v[1] - v[0], v[2] - v[0]);
    let pv = d.cross(e2);
    let det = e1.dot(pv);
    if det == 0.0 {
        return None;
    }
    let inv = 1.0 / det;
    let tv = o - v[0];
    let u = tv.dot(pv) * inv;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let qv = tv.cross(e1);
    let w = d.dot(qv) * inv;
    if w < 0.0 || u + w > 1.0 {
        return None;
    }
    Some(e2.dot(qv) * inv)
}

/// The bounced z-buffer's content for one ray: the nearest hit t ∈ (t_min, r)
/// over `triangles`, as the depth t²/r² the splat pass keeps (1 = no hit).
pub fn bounced_depth(o: Vec3, d: Vec3, triangles: &[[Vec3; 3]], r: f32, t_min: f32) -> f32 {
    triangles
        .iter()
        .filter_map(|v| ray_triangle(o, d, *v))
        .filter(|t| *t > t_min && *t < r)
        .fold(1.0f32, |z, t| z.min(t * t / (r * r)))
}

/// `bzb_aov_occlusion`: the no-visibility baseline's analytic occlusion of
/// triangle `v` at `x` (unit normal `n`): 0 when dist(x, T) ≥ r; else the form
/// factor of T clipped to n·(y − x) ≥ β, times 1 − (h/r)² (h: x's distance to
/// T's plane; exact binary AO within r for an infinite plane).
pub fn aov_occlusion(x: Vec3, n: Vec3, v: [Vec3; 3], r: f32, beta: f32) -> f32 {
    if triangle_dist2(x, v).partial_cmp(&(r * r)) != Some(std::cmp::Ordering::Less) {
        return 0.0;
    }
    let rel = v.map(|p| p - x);
    let mut poly = Vec::with_capacity(4);
    for i in 0..3 {
        let (p, q) = (rel[i], rel[(i + 1) % 3]);
        let (hp, hq) = (n.dot(p) - beta, n.dot(q) - beta);
        if hp >= 0.0 {
            poly.push(p);
        }
        if (hp >= 0.0) != (hq >= 0.0) {
            poly.push(p + (q - p) * (hp / (hp - hq)));
        }
    }
    if poly.len() < 3 {
        return 0.0;
    }
    let mut sum = 0.0;
    for i in 0..poly.len() {
        let (u0, u1) = (poly[i].normalize(), poly[(i + 1) % poly.len()].normalize());
        let c = u0.cross(u1);
        let len = c.length();
        if len > 1e-12 {
            sum += len.atan2(u0.dot(u1)) * n.dot(c) / len;
        }
    }
    let nor = (v[1] - v[0]).cross(v[2] - v[0]).normalize();
    let h = nor.dot(x - v[0]).abs();
    (sum.abs() / (2.0 * std::f32::consts::PI)).min(1.0) * (1.0 - h * h / (r * r)).max(0.0)
}

/// Squared distance from `p` to triangle `v`.
pub fn triangle_dist2(p: Vec3, v: [Vec3; 3]) -> f32 {
    let [a, b, c] = v;
    let (ba, pa, cb, pb, ac, pc) = (b - a, p - a, c - b, p - b, a - c, p - c);
    let nor = ba.cross(ac);
    let sign = |x: f32| {
        if x > 0.0 {
            1.0
        } else if x < 0.0 {
            -1.0
        } else {
            0.0
        }
    };
    let outside = sign(ba.cross(nor).dot(pa)) + sign(cb.cross(nor).dot(pb)) + sign(ac.cross(nor).dot(pc)) < 2.0;
    if outside {
        let e = |e: Vec3, p: Vec3| (e * (e.dot(p) / e.dot(e)).clamp(0.0, 1.0) - p).length_squared();
        e(ba, pa).min(e(cb, pb)).min(e(ac, pc))
    } else {
        let h = nor.dot(pa);
        h * h / nor.dot(nor)
    }
}

/// World-space triangles of `scene` at `frame` as the splat pass pulls them
/// (3 × vec4 per triangle).
pub fn triangle_data(scene: &Scene, frame: f32) -> Vec<[f32; 4]> {
    scene
        .world_triangles(frame)
        .iter()
        .flat_map(|t| t.p.map(|p| p.extend(0.0).to_array()))
        .collect()
}

// ---- passes ----

pub const ORIGINS: TargetDesc = TargetDesc::new(
    "bzb-origins",
    wgpu::TextureFormat::Rgba32Float,
    1,
    "BZB §3.1 ray origin x_p per sub-image texel (w = 1: has a sample)",
);
pub const DIRECTIONS: TargetDesc = TargetDesc::new(
    "bzb-directions",
    wgpu::TextureFormat::Rgba32Float,
    1,
    "BZB §3.1 direction ω (xyz) and its pdf α (w; 0 = no sample), sub-image s = direction s",
);
pub const PAYLOAD: TargetDesc = TargetDesc::new(
    "bzb-payload",
    wgpu::TextureFormat::R16Float,
    1,
    "BZB §3.2 payload per sub-image texel: occlusion of the nearest hit (or the AOV sum without visibility)",
);
pub const DEPTH: TargetDesc = TargetDesc::new(
    "bzb-depth",
    wgpu::TextureFormat::Depth32Float,
    1,
    "the bounced z-buffer: |x_p - y|² / r² of the nearest hit (1 = none)",
);
pub const RAW: TargetDesc = TargetDesc::new(
    "bzb-raw",
    wgpu::TextureFormat::R32Float,
    1,
    "BZB §3.3 AV = 1 - mean weighted occlusion over the S directions, before filtering",
);
/// The temporal filter's output (`BzbSettings::temporal`) and last frame's copy.
pub const TEMPORAL: [TargetDesc; 2] = [
    TargetDesc::new(
        "bzb-temporal",
        wgpu::TextureFormat::R32Float,
        1,
        "BZB AV after the temporal filter (DGB §3.3; BZB §6's re-projection)",
    ),
    TargetDesc::new(
        "bzb-temporal-history",
        wgpu::TextureFormat::R32Float,
        1,
        "last frame's bzb-temporal",
    ),
];
/// The temporal filter's per-pixel count of accepted histories and its copy.
pub const TEMPORAL_FRAMES: [&str; 2] = ["bzb-temporal-frames", "bzb-temporal-frames-history"];
/// The pass the temporal filter adds (`alpha` > 0; the registry lists the default frame's).
pub const TEMPORAL_PASS: &str = "bzb-temporal";

/// Square tile sizes of the min/max depth tiles (`zminmax_tile` in common/zminmax.wgsl);
/// the last level is one tile over the whole image.
pub const ZMINMAX_TILES: [u32; 3] = [8, 32, 128];

/// Tiles of every level at `w`×`h` (the `bzb-zminmax` buffer holds one vec2 each).
pub fn zminmax_tile_count(w: u32, h: u32) -> u32 {
    ZMINMAX_TILES
        .iter()
        .map(|t| w.div_ceil(*t) * h.div_ceil(*t))
        .sum::<u32>()
        + 1
}

/// Min/max receiver depth per tile (compute), for the splat pass's culling.
pub struct ZMinMaxPass {
    /// One pipeline per level (override LEVEL) and that level's tile count.
    levels: Vec<(wgpu::ComputePipeline, u32)>,
    group: wgpu::BindGroup,
    buffer: wgpu::Buffer,
}

impl ZMinMaxPass {
    /// The last frame's (min, max) receiver depth per tile, levels in
    /// [`ZMINMAX_TILES`] order then the whole image, row-major tiles.
    pub fn read_tiles(&self, gpu: &GpuContext) -> Result<Vec<[f32; 2]>, crate::RenderError> {
        let bytes = gpu.read_storage(&self.buffer)?;
        Ok(bytemuck::cast_slice::<u8, [f32; 2]>(&bytes).to_vec())
    }
}

/// The CPU twin of `bzb-zminmax`: (min, max) camera depth `z(x, y)` of the
/// receivers (`Some`) over every tile, in the GPU buffer's order.
pub fn zminmax_tiles(w: u32, h: u32, z: impl Fn(u32, u32) -> Option<f32>) -> Vec<[f32; 2]> {
    let mut out = Vec::new();
    let sizes = ZMINMAX_TILES.iter().copied().chain([w.max(h)]);
    for t in sizes {
        for ty in 0..h.div_ceil(t) {
            for tx in 0..w.div_ceil(t) {
                let mut r = [3.0e38f32, -3.0e38];
                for y in ty * t..((ty + 1) * t).min(h) {
                    for x in tx * t..((tx + 1) * t).min(w) {
                        if let Some(v) = z(x, y) {
                            r = [r[0].min(v), r[1].max(v)];
                        }
                    }
                }
                out.push(r);
            }
        }
    }
    out
}

impl Pass for ZMinMaxPass {
    fn info(&self) -> PassInfo {
        PassInfo {
            name: "bzb-zminmax",
            inputs: vec![ORIGINS.name],
            outputs: vec!["bzb-zminmax"],
        }
    }

    fn encode(&self, _gpu: &GpuContext, scene: &GpuScene, _targets: &Targets, encoder: &mut wgpu::CommandEncoder) {
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("bzb-zminmax"),
            timestamp_writes: None,
        });
        pass.set_bind_group(0, &scene.frame_bind_group, &[]);
        pass.set_bind_group(1, &self.group, &[]);
        // finest level first: each coarser level reads the one below
        for (pipeline, tiles) in &self.levels {
            pass.set_pipeline(pipeline);
            pass.dispatch_workgroups(tiles.div_ceil(64), 1, 1);
        }
    }
}

/// The triangles of the scene in a storage buffer (vertex pulling).
struct TriangleBuffer {
    buffer: wgpu::Buffer,
    count: u32,
}

/// §3.2's splat pass: instanced draw of T × S screen rectangles.
pub struct SplatPass {
    /// The rasteriser's form (`None` when `compute` replaces it).
    pipeline: Option<wgpu::RenderPipeline>,
    group: wgpu::BindGroup,
    visibility: bool,
    instances: u32,
    /// Vertices per instance: 36 for box splats (`SPLAT_VERTICES`), 6 for rectangles.
    vertices: u32,
    /// The payload target (`bzb-payload`, or `bzb-gi-payload` for GI).
    payload: &'static str,
    /// bzb-gi's sender data (group 2: materials, lights, shadow maps).
    extra: Option<wgpu::BindGroup>,
    /// `splat-kernel=compute`: the same splats tested in a compute pass.
    compute: Option<ComputeSplat>,
}

/// §3.2's splats in a compute pass (`splat-kernel=compute`, bzb_splat_compute.wgsl):
/// one workgroup per instance walks its rectangle's texels and keeps the nearest hit
/// with a 64-bit `atomicMax` on (depth, triangle) keys; a full-screen pass
/// (bzb_splat_resolve.wgsl) then writes the keys into the fragment form's payload and
/// depth targets, so every later pass and debug view reads the same targets.
struct ComputeSplat {
    pipeline: wgpu::ComputePipeline,
    group: wgpu::BindGroup,
    resolve: wgpu::RenderPipeline,
    resolve_group: wgpu::BindGroup,
    keys: wgpu::Buffer,
}

/// Workgroups (x, y) for `instances` compute-splat instances: x·y ≥ instances with
/// both within the 65,535 a dispatch dimension allows (`cs_splat` skips ids past the end).
pub fn compute_splat_groups(instances: u32) -> (u32, u32) {
    const X: u32 = 32_768;
    let x = instances.clamp(1, X);
    (x, instances.div_ceil(x))
}

impl Pass for SplatPass {
    fn info(&self) -> PassInfo {
        let mut outputs = vec![self.payload];
        if self.visibility {
            outputs.push(DEPTH.name);
        }
        PassInfo {
            name: "bzb-splat",
            inputs: vec!["scene", ORIGINS.name, DIRECTIONS.name, "npack", "bzb-zminmax"],
            outputs,
        }
    }

    fn encode(&self, _gpu: &GpuContext, scene: &GpuScene, targets: &Targets, encoder: &mut wgpu::CommandEncoder) {
        if let Some(c) = &self.compute {
            encoder.clear_buffer(&c.keys, 0, None);
            if self.instances > 0 {
                let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some("bzb-splat"),
                    timestamp_writes: None,
                });
                pass.set_pipeline(&c.pipeline);
                pass.set_bind_group(0, &scene.frame_bind_group, &[]);
                pass.set_bind_group(1, &c.group, &[]);
                let (x, y) = compute_splat_groups(self.instances);
                pass.dispatch_workgroups(x, y, 1);
            }
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("bzb-splat-resolve"),
                color_attachments: &[crate::passes::clear_attachment(&targets.get(self.payload).view)],
                depth_stencil_attachment: Some(crate::passes::clear_depth_attachment(&targets.get(DEPTH.name).view)),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&c.resolve);
            pass.set_bind_group(0, &c.resolve_group, &[]);
            pass.draw(0..3, 0..1);
            return;
        }
        let depth = self
            .visibility
            .then(|| crate::passes::clear_depth_attachment(&targets.get(DEPTH.name).view));
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("bzb-splat"),
            color_attachments: &[crate::passes::clear_attachment(&targets.get(self.payload).view)],
            depth_stencil_attachment: depth,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        let Some(pipeline) = self.pipeline.as_ref().filter(|_| self.instances > 0) else {
            return;
        };
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, &scene.frame_bind_group, &[]);
        pass.set_bind_group(1, &self.group, &[]);
        if let Some(g) = &self.extra {
            pass.set_bind_group(2, g, &[]);
        }
        pass.draw(0..self.vertices, 0..self.instances);
    }
}

/// The WGSL of a BZB pass with the shared functions prepended.
macro_rules! bzb_shader {
    ($file:literal) => {
        concat!(include_str!("bzb.wgsl"), "\n", include_str!($file))
    };
}

/// The BZB AO passes of a frame, into target `ao`.
pub(crate) struct BzbStage {
    pub(crate) directions: FullscreenPass,
    /// AOV splatting (with its depth tiles), or DSS.
    pub(crate) zminmax: Option<ZMinMaxPass>,
    pub(crate) splat: Option<SplatPass>,
    pub(crate) dss: Option<dss::DssStage>,
    pub(crate) reconstruct: FullscreenPass,
    /// `BzbSettings::temporal`.
    pub(crate) temporal: Option<crate::passes::temporal::TemporalPass>,
    pub(crate) blur_h: BilateralPass,
    pub(crate) blur_v: BilateralPass,
    uniforms: wgpu::Buffer,
    triangles: TriangleBuffer,
    settings: BzbSettings,
    last: std::cell::Cell<BzbUniforms>,
}

impl BzbStage {
    pub fn new(
        gpu: &GpuContext,
        scene_gpu: &GpuScene,
        targets: &mut Targets,
        s: &BzbSettings,
        scene: &Scene,
        layers: u32,
    ) -> Result<Self, crate::RenderError> {
        Self::with_triangles(gpu, scene_gpu, targets, s, scene, layers, &triangle_data(scene, 0.0))
    }

    /// [`BzbStage::new`] splatting `data` (3 × vec4 per world-space triangle, as
    /// [`triangle_data`] lays them out) instead of `scene`'s triangles; `scene` gives
    /// the radius where the settings have none. The embedded AO passes the
    /// application's geometry this way (`embed::EmbeddedBzbAo`).
    #[allow(clippy::too_many_arguments)]
    pub fn with_triangles(
        gpu: &GpuContext,
        scene_gpu: &GpuScene,
        targets: &mut Targets,
        s: &BzbSettings,
        scene: &Scene,
        layers: u32,
        data: &[[f32; 4]],
    ) -> Result<Self, crate::RenderError> {
        use wgpu::util::DeviceExt;
        let (w, h) = (targets.width, targets.height);
        let (cols, rows) = s.grid();
        let max = gpu.device.limits().max_texture_dimension_2d;
        if w * cols > max || h * rows > max {
            return Err(crate::RenderError::Parameter(format!(
                "bzb directions {}: the bounced z-buffer of {cols}x{rows} sub-images is {}x{}, over the adapter's largest texture {max}x{max} (lower the directions or the size)",
                s.directions,
                w * cols,
                h * rows
            )));
        }
        let big = [w * cols, h * rows];
        for d in [ORIGINS, DIRECTIONS, PAYLOAD] {
            targets.create_sized(gpu, d, big);
        }
        if s.visibility && s.splat == Splat::Aov {
            targets.create_sized(gpu, DEPTH, big);
        }
        for d in [
            RAW,
            TargetDesc::new(
                "bzb-blur-h",
                wgpu::TextureFormat::R16Float,
                1,
                "BZB AV after the horizontal bilateral pass",
            ),
        ] {
            targets.create(gpu, d);
        }
        if targets.try_get("ao").is_none() {
            targets.create(
                gpu,
                TargetDesc::new(
                    "ao",
                    wgpu::TextureFormat::R16Float,
                    1,
                    "ambient visibility AV (1 = unoccluded)",
                ),
            );
        }
        let count = (data.len() / 3) as u32;
        let bytes = (data.len() * 16).max(48) as u64;
        let limit = gpu.device.limits().max_storage_buffer_binding_size;
        if bytes > limit {
            return Err(crate::RenderError::Parameter(format!(
                "scene '{}' has {count} triangles: {bytes} bytes of splat triangles exceed the adapter's storage buffer binding size {limit}",
                scene.name
            )));
        }
        let mut contents = bytemuck::cast_slice::<[f32; 4], u8>(data).to_vec();
        contents.resize(bytes as usize, 0);
        let buffer = gpu.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("bzb-triangles"),
            contents: &contents,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
        });
        let u = BzbUniforms::new(s, scene, count);
        let directions = PassBuilder::new(gpu, targets, "bzb-directions")
            .shader("bzb-directions", bzb_shader!("bzb_directions.wgsl"))
            .frame(scene_gpu)
            .uniforms(&u)
            .read("zpack")
            .read("npack")
            .write(ORIGINS.name)
            .write(DIRECTIONS.name)
            .build();
        let reconstruct = PassBuilder::new(gpu, targets, "bzb-reconstruct")
            .shader("bzb-reconstruct", bzb_shader!("bzb_reconstruct.wgsl"))
            .frame(scene_gpu)
            .uniforms(&u)
            .read(PAYLOAD.name)
            .read(DIRECTIONS.name)
            .read("zpack")
            .read("npack")
            .write(RAW.name)
            .build();
        let uniforms = gpu.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("bzb-splat"),
            contents: bytemuck::bytes_of(&u),
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        });
        let tile_count = zminmax_tile_count(w, h);
        let tiles = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("bzb-zminmax"),
            size: tile_count as u64 * 8,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let big_texels = big[0] as u64 * big[1] as u64;
        let form = (s.visibility, s.box_splats);
        let compute_splat = s.splat == Splat::Aov && splat_compute_on(gpu, "bzb", s.splat_kernel, form, big_texels)?;
        let (zminmax, splat, dss) = match s.splat {
            Splat::Aov => (
                Some(Self::zminmax_pass(gpu, scene_gpu, targets, &tiles, tile_count)),
                Some(Self::splat_pass(
                    gpu,
                    scene_gpu,
                    targets,
                    s,
                    compute_splat,
                    &uniforms,
                    &buffer,
                    &tiles,
                    count,
                )),
                None,
            ),
            Splat::Dss => {
                let du = s.dss_uniforms(w, h, u.radius, u.t_min, count);
                (
                    Some(Self::zminmax_pass(gpu, scene_gpu, targets, &tiles, tile_count)),
                    None,
                    Some(dss::DssStage::new(
                        gpu,
                        scene_gpu,
                        targets,
                        &du,
                        (&buffer, &tiles),
                        PAYLOAD.name,
                        None,
                    )?),
                )
            }
        };
        // the temporal filter between the reconstruction and the bilateral filter
        let mut filtered = RAW.name;
        let temporal = s.temporal.as_ref().map(|t| {
            for d in TEMPORAL
                .into_iter()
                .chain(crate::passes::temporal::frames_targets(TEMPORAL_FRAMES))
            {
                targets.create(gpu, d);
            }
            filtered = TEMPORAL[0].name;
            crate::passes::temporal::TemporalPass::new(
                gpu,
                scene_gpu,
                targets,
                t,
                TEMPORAL_PASS,
                RAW.name,
                TEMPORAL[1].name,
                TEMPORAL[0].name,
                TEMPORAL_FRAMES,
                layers,
                false,
            )
        });
        // after the temporal filter the blur may widen where the history is short
        let frames = temporal.is_some().then_some(TEMPORAL_FRAMES[0]);
        let blur_h = BilateralPass::new(
            gpu,
            scene_gpu,
            targets,
            &s.filter,
            "bzb-blur-h",
            filtered,
            "bzb-blur-h",
            false,
            false,
            frames,
        );
        let blur_v = BilateralPass::new(
            gpu,
            scene_gpu,
            targets,
            &s.filter,
            "bzb-blur-v",
            "bzb-blur-h",
            "ao",
            true,
            false,
            frames,
        );
        Ok(Self {
            directions,
            zminmax,
            splat,
            dss,
            reconstruct,
            temporal,
            blur_h,
            blur_v,
            uniforms,
            triangles: TriangleBuffer { buffer, count },
            settings: s.clone(),
            last: std::cell::Cell::new(u),
        })
    }

    pub(crate) fn zminmax_pass(
        gpu: &GpuContext,
        scene_gpu: &GpuScene,
        targets: &Targets,
        tiles: &wgpu::Buffer,
        tile_count: u32,
    ) -> ZMinMaxPass {
        let device = &gpu.device;
        let comp = wgpu::ShaderStages::COMPUTE;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("bzb-zminmax"),
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: comp,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Float { filterable: false },
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 1,
                    visibility: comp,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Storage { read_only: false },
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                },
            ],
        });
        let group = crate::passes::bind_group(
            device,
            "bzb-zminmax",
            &layout,
            &[
                wgpu::BindingResource::TextureView(&targets.get(ORIGINS.name).view),
                tiles.as_entire_binding(),
            ],
        );
        let pl = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("bzb-zminmax"),
            bind_group_layouts: &[Some(&scene_gpu.frame_layout), Some(&layout)],
            immediate_size: 0,
        });
        let module = crate::shader::module(device, "bzb-zminmax", bzb_shader!("bzb_zminmax.wgsl"));
        let (w, h) = (targets.width, targets.height);
        let sizes = ZMINMAX_TILES.iter().copied().chain([w.max(h)]);
        let levels: Vec<_> = sizes
            .enumerate()
            .map(|(level, t)| {
                let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                    label: Some("bzb-zminmax"),
                    layout: Some(&pl),
                    module: &module,
                    entry_point: Some("cs_main"),
                    compilation_options: wgpu::PipelineCompilationOptions {
                        constants: &[("LEVEL", level as f64)],
                        ..Default::default()
                    },
                    cache: None,
                });
                (pipeline, w.div_ceil(t) * h.div_ceil(t))
            })
            .collect();
        debug_assert_eq!(levels.iter().map(|l| l.1).sum::<u32>(), tile_count);
        ZMinMaxPass {
            levels,
            group,
            buffer: tiles.clone(),
        }
    }

    #[allow(clippy::too_many_arguments)]
    fn splat_pass(
        gpu: &GpuContext,
        scene_gpu: &GpuScene,
        targets: &Targets,
        s: &BzbSettings,
        compute: bool,
        uniforms: &wgpu::Buffer,
        triangles: &wgpu::Buffer,
        tiles: &wgpu::Buffer,
        count: u32,
    ) -> SplatPass {
        splat_pass_with(
            gpu,
            scene_gpu,
            targets,
            SplatSpec {
                visibility: s.visibility,
                instances: count.saturating_mul(s.directions),
                box_splats: s.box_splats,
                source: concat!(
                    include_str!("bzb.wgsl"),
                    "\n",
                    include_str!("bzb_splat.wgsl"),
                    "\n",
                    include_str!("bzb_splat_ao.wgsl")
                ),
                entries: ("fs_visibility", "fs_additive"),
                payload: PAYLOAD,
                extra: None,
                hit: HitPayload::Occlusion,
                compute,
            },
            uniforms,
            triangles,
            tiles,
        )
    }

    /// Uploads this frame's uniforms (and, for animated scenes, the triangles at `frame`).
    /// With the temporal filter the directions' seed moves on with `frame_index` (frames
    /// rendered so far) and `has_history` says whether last frame's filtered AV may be
    /// reprojected.
    #[allow(clippy::too_many_arguments)]
    pub fn set_frame(
        &self,
        gpu: &GpuContext,
        scene: &Scene,
        frame: f32,
        animated: bool,
        frame_index: u32,
        has_history: bool,
    ) {
        let mut u = BzbUniforms::new(&self.settings, scene, self.triangles.count);
        if let Some(t) = &self.temporal {
            u.seed = frame_seed(self.settings.seed, frame_index);
            t.set_frame(gpu, has_history);
        }
        self.directions.set_uniforms(gpu, &u);
        self.reconstruct.set_uniforms(gpu, &u);
        gpu.queue.write_buffer(&self.uniforms, 0, bytemuck::bytes_of(&u));
        if let Some(d) = &self.dss {
            let [w, h] = d.size;
            d.set_uniforms(
                gpu,
                &self
                    .settings
                    .dss_uniforms(w, h, u.radius, u.t_min, self.triangles.count),
            );
        }
        if animated && self.triangles.count > 0 {
            let data = triangle_data(scene, frame);
            gpu.queue
                .write_buffer(&self.triangles.buffer, 0, bytemuck::cast_slice(&data));
        }
        self.last.set(u);
    }

    /// Overwrites splat triangles `first..` with `data` (as [`triangle_data`] lays them
    /// out, 3 entries per triangle), which must end within the count the stage was built
    /// with; for geometry that moves between frames.
    pub fn write_triangles(&self, gpu: &GpuContext, first: u32, data: &[[f32; 4]]) {
        debug_assert!(data.len().is_multiple_of(3) && first as usize + data.len() / 3 <= self.triangles.count as usize);
        if !data.is_empty() {
            let offset = first as u64 * 3 * std::mem::size_of::<[f32; 4]>() as u64;
            gpu.queue
                .write_buffer(&self.triangles.buffer, offset, bytemuck::cast_slice(data));
        }
    }

    /// The uniforms of the last frame.
    pub fn uniforms(&self) -> BzbUniforms {
        self.last.get()
    }

    pub fn passes(&self) -> Vec<&dyn Pass> {
        let mut v: Vec<&dyn Pass> = vec![&self.directions];
        if let Some(z) = &self.zminmax {
            v.push(z);
        }
        if let Some(s) = &self.splat {
            v.push(s);
        }
        if let Some(d) = &self.dss {
            v.extend(d.passes());
        }
        v.push(&self.reconstruct);
        if let Some(t) = &self.temporal {
            v.push(t);
        }
        v.extend([&self.blur_h as &dyn Pass, &self.blur_v]);
        v
    }

    /// The AOV splats' depth tiles (`splat = aov`).
    pub fn zminmax(&self) -> Option<&ZMinMaxPass> {
        self.zminmax.as_ref()
    }

    /// The DSS stage (`splat = dss`).
    pub fn dss(&self) -> Option<&dss::DssStage> {
        self.dss.as_ref()
    }

    /// Scene triangles in the splat buffer.
    pub fn triangle_count(&self) -> u32 {
        self.triangles.count
    }
}

/// What distinguishes the AO and GI splat passes: the shader, its two fragment
/// entries (visibility, additive), the payload target and GI's group 2.
pub(crate) struct SplatSpec<'a> {
    pub visibility: bool,
    pub instances: u32,
    /// Box splats (36 vertices an instance) or rectangles (6).
    pub box_splats: bool,
    pub source: &'static str,
    pub entries: (&'static str, &'static str),
    pub payload: TargetDesc,
    pub extra: Option<(&'a wgpu::BindGroupLayout, wgpu::BindGroup)>,
    /// What a hit writes besides its depth (with visibility).
    pub hit: HitPayload,
    /// The compute form (`splat-kernel`; visibility only).
    pub compute: bool,
}

/// What a hit writes besides its depth, in either form (`HIT_INDEX` in bzb_splat.wgsl
/// and bzb_splat_resolve.wgsl).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum HitPayload {
    /// 1: bzb-ao's binary occlusion.
    Occlusion,
    /// The hit triangle + 1: bzb-gi's `bzb-gi-hit`.
    HitIndex,
}

impl HitPayload {
    /// The shaders' `HIT_INDEX` override.
    fn constants(self) -> [(&'static str, f64); 1] {
        [("HIT_INDEX", (self == HitPayload::HitIndex) as u32 as f64)]
    }
}

/// §3.2's splat pass over the triangles in `triangles` (group 1: uniforms,
/// triangles, origins, directions, npack, depth tiles).
pub(crate) fn splat_pass_with(
    gpu: &GpuContext,
    scene_gpu: &GpuScene,
    targets: &Targets,
    spec: SplatSpec,
    uniforms: &wgpu::Buffer,
    triangles: &wgpu::Buffer,
    tiles: &wgpu::Buffer,
) -> SplatPass {
    let device = &gpu.device;
    let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("bzb-splat"),
        entries: &splat_layout_entries(false),
    });
    let resources = [
        uniforms.as_entire_binding(),
        triangles.as_entire_binding(),
        wgpu::BindingResource::TextureView(&targets.get(ORIGINS.name).view),
        wgpu::BindingResource::TextureView(&targets.get(DIRECTIONS.name).view),
        wgpu::BindingResource::TextureView(&targets.get("npack").view),
        tiles.as_entire_binding(),
    ];
    let group = crate::passes::bind_group(device, "bzb-splat", &layout, &resources);
    let (extra_layout, extra) = match spec.extra {
        Some((l, g)) => (Some(l), Some(g)),
        None => (None, None),
    };
    let mut layouts = vec![Some(&scene_gpu.frame_layout), Some(&layout)];
    if let Some(l) = extra_layout {
        layouts.push(Some(l));
    }
    let compute = (spec.compute && spec.visibility).then(|| {
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("bzb-splat compute"),
            entries: &splat_layout_entries(true),
        });
        let size = targets.get(ORIGINS.name).texture.size();
        let (w, h) = (size.width, size.height);
        let keys = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("bzb-splat keys"),
            size: (w as u64 * h as u64 * 8).max(8),
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut entries = resources.to_vec();
        entries.push(keys.as_entire_binding());
        let group = crate::passes::bind_group(device, "bzb-splat compute", &layout, &entries);
        // the test reads group 1 alone (bzb-gi's group 2 serves its fragment entries)
        let pl = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("bzb-splat compute"),
            bind_group_layouts: &[Some(&scene_gpu.frame_layout), Some(&layout)],
            immediate_size: 0,
        });
        let source = format!("{}\n{}", spec.source, include_str!("bzb_splat_compute.wgsl"));
        let module = crate::shader::module(device, "bzb-splat compute", &source);
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("bzb-splat compute"),
            layout: Some(&pl),
            module: &module,
            entry_point: Some("cs_splat"),
            compilation_options: Default::default(),
            cache: None,
        });
        let (resolve, resolve_group) = resolve_pipeline(device, targets, &keys, spec.payload.format, spec.hit);
        ComputeSplat {
            pipeline,
            group,
            resolve,
            resolve_group,
            keys,
        }
    });
    let constants = spec.hit.constants();
    // the rasteriser's form, unless the compute form replaces it
    let pipeline = compute.is_none().then(|| {
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("bzb-splat"),
            bind_group_layouts: &layouts,
            immediate_size: 0,
        });
        let module = crate::shader::module(device, "bzb-splat", spec.source);
        splat_pipeline_with(
            device,
            "bzb-splat",
            &pipeline_layout,
            &module,
            spec.visibility,
            spec.payload.format,
            spec.entries,
            if spec.visibility { &constants[..] } else { &[] },
        )
    });
    SplatPass {
        pipeline,
        group,
        compute,
        visibility: spec.visibility,
        instances: spec.instances,
        // bzb_splat.wgsl's `SPLAT_VERTICES`, or its fallback rectangle alone
        vertices: if spec.box_splats { 36 } else { 6 },
        payload: spec.payload.name,
        extra,
    }
}

/// Group 1 of the splat passes: uniforms, triangles, origins, directions, npack, depth
/// tiles; for the compute form (`compute`) every entry is visible to the compute stage
/// and binding 6 holds the keys (bzb_splat_compute.wgsl).
fn splat_layout_entries(compute: bool) -> Vec<wgpu::BindGroupLayoutEntry> {
    use wgpu::ShaderStages as S;
    let (buffers, textures, tiles) = if compute {
        (S::COMPUTE, S::COMPUTE, S::COMPUTE)
    } else {
        (S::VERTEX | S::FRAGMENT, S::FRAGMENT, S::VERTEX)
    };
    let buffer = |binding, visibility, ty| wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Buffer {
            ty,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    };
    let read_only = wgpu::BufferBindingType::Storage { read_only: true };
    let mut entries = vec![
        buffer(0, buffers, wgpu::BufferBindingType::Uniform),
        buffer(1, buffers, read_only),
    ];
    entries.extend((2..5).map(|b| wgpu::BindGroupLayoutEntry {
        visibility: textures,
        ..crate::passes::texture_entry(b, wgpu::TextureViewDimension::D2, false)
    }));
    entries.push(buffer(5, tiles, read_only));
    if compute {
        entries.push(buffer(
            6,
            S::COMPUTE,
            wgpu::BufferBindingType::Storage { read_only: false },
        ));
    }
    entries
}

/// The compute form's resolve (bzb_splat_resolve.wgsl): a full-screen pass over the
/// bounced z-buffer writing each key's depth (test Always) and payload.
fn resolve_pipeline(
    device: &wgpu::Device,
    targets: &Targets,
    keys: &wgpu::Buffer,
    format: wgpu::TextureFormat,
    hit: HitPayload,
) -> (wgpu::RenderPipeline, wgpu::BindGroup) {
    let frag = wgpu::ShaderStages::FRAGMENT;
    let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("bzb-splat-resolve"),
        entries: &[
            wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: frag,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Storage { read_only: true },
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                count: None,
            },
            crate::passes::texture_entry(1, wgpu::TextureViewDimension::D2, false),
        ],
    });
    let group = crate::passes::bind_group(
        device,
        "bzb-splat-resolve",
        &layout,
        &[
            keys.as_entire_binding(),
            wgpu::BindingResource::TextureView(&targets.get(ORIGINS.name).view),
        ],
    );
    let pl = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some("bzb-splat-resolve"),
        bind_group_layouts: &[Some(&layout)],
        immediate_size: 0,
    });
    let module = crate::shader::module(device, "bzb-splat-resolve", include_str!("bzb_splat_resolve.wgsl"));
    let pipeline = crate::passes::fullscreen_pipeline_writing_depth(
        device,
        "bzb-splat-resolve",
        &pl,
        &module,
        "fs_resolve",
        &hit.constants(),
        &[Some(wgpu::ColorTargetState::from(format))],
        Some(DEPTH.format),
    );
    (pipeline, group)
}

impl Default for BzbUniforms {
    fn default() -> Self {
        Self::zeroed()
    }
}

/// The splat pipeline of §3.2, shared by the AOV and DSS splats. With
/// visibility: depth test `Less` with depth writes and no blending, so the
/// bounced z-buffer keeps the nearest hit per texel (`fs_visibility`);
/// without: additive blending and no depth test, the baseline that sums every
/// splat (`fs_additive`). Vertex pulling: no vertex buffers (`vs_splat`).
pub(crate) fn splat_pipeline(
    device: &wgpu::Device,
    label: &str,
    layout: &wgpu::PipelineLayout,
    module: &wgpu::ShaderModule,
    visibility: bool,
) -> wgpu::RenderPipeline {
    splat_pipeline_with(
        device,
        label,
        layout,
        module,
        visibility,
        PAYLOAD.format,
        ("fs_visibility", "fs_additive"),
        &[],
    )
}

/// [`splat_pipeline`] with the payload format, fragment entries (visibility, additive)
/// and the fragment stage's override constants given.
#[allow(clippy::too_many_arguments)]
pub(crate) fn splat_pipeline_with(
    device: &wgpu::Device,
    label: &str,
    layout: &wgpu::PipelineLayout,
    module: &wgpu::ShaderModule,
    visibility: bool,
    format: wgpu::TextureFormat,
    entries: (&'static str, &'static str),
    constants: &[(&str, f64)],
) -> wgpu::RenderPipeline {
    let (entry, blend, depth_stencil) = if visibility {
        (
            entries.0,
            None,
            Some(wgpu::DepthStencilState {
                format: DEPTH.format,
                depth_write_enabled: Some(true),
                depth_compare: Some(wgpu::CompareFunction::Less),
                stencil: Default::default(),
                bias: Default::default(),
            }),
        )
    } else {
        let add = wgpu::BlendComponent {
            src_factor: wgpu::BlendFactor::One,
            dst_factor: wgpu::BlendFactor::One,
            operation: wgpu::BlendOperation::Add,
        };
        (entries.1, Some(wgpu::BlendState { color: add, alpha: add }), None)
    };
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(label),
        layout: Some(layout),
        vertex: wgpu::VertexState {
            module,
            entry_point: Some("vs_splat"),
            compilation_options: Default::default(),
            buffers: &[],
        },
        primitive: wgpu::PrimitiveState {
            cull_mode: None,
            ..Default::default()
        },
        depth_stencil,
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module,
            entry_point: Some(entry),
            compilation_options: wgpu::PipelineCompilationOptions {
                constants,
                ..Default::default()
            },
            targets: &[Some(wgpu::ColorTargetState {
                format,
                blend,
                write_mask: wgpu::ColorWrites::ALL,
            })],
        }),
        multiview_mask: None,
        cache: None,
    })
}
