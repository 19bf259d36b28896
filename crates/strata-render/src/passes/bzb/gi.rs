//! `bzb-gi`: one-bounce diffuse and glossy global illumination with the bounced
//! z-buffer (Nalbach, Ritschel, Seidel 2016, §3 with a radiance payload), the
//! GI half of issue 13. The splats are the AOV path's triangles (one instanced
//! draw, vertex pulling: wgpu has no geometry shaders), the payload is the
//! sender's outgoing radiance. Passes (profiler names), after the lighting pass:
//!
//! 1. `bzb-directions` (§3.1): per texel of the bounced z-buffer (S sub-images),
//!    x_p from layer 0 and ω importance-sampled by the receiver's BRDF × cos:
//!    cosine for Lambert receivers, the path tracer's GGX mixture (visible
//!    normals with probability P_s, else cosine) for glossy ones; the pdf α is
//!    stored ([`direction`], [`lobe_uniform`] are the CPU twins).
//! 2. `bzb-zminmax`, `bzb-splat` (§3.2): the AOV splat rectangles grown by
//!    d_max; each covered texel intersects its ray with the triangle and on a
//!    hit at t ∈ (t_min, d_max) writes depth t²/d_max² and the payload
//!    L(y → x_p): direct light at y (the analytic lights, shadow-mapped as the
//!    lighting pass does) × ρ/π (or f_GGX for glossy senders), + emission when
//!    no Rect light carries it. Nearest sender wins. Without visibility
//!    (baseline) every triangle within d_max adds π·F·L (form factor F,
//!    radiance at a hashed point of it) by additive blending.
//! 3. `bzb-reconstruct` (§3.3): mean over s of L · f · cos θ / α, with L the
//!    sky's radiance for a ray that hit nothing when d_max spans the scene; Lambert
//!    receivers into `bzb-gi-raw` as irradiance (compose applies ρ/π), glossy
//!    ones into `bzb-gi-glossy-raw` as radiance.
//! 4. `bzb-gi-blur-h/-v`, `bzb-gi-glossy-blur-h/-v`: the cross-bilateral filter
//!    of [`crate::passes::bilateral`] into `indirect` and `bzb-gi-glossy`.
//! 5. `compose`: hdr + ρ/π · indirect + glossy (the pass DGB radiosity and ILS use).

use bytemuck::Zeroable;
use glam::Vec3;
use strata_scene::Scene;

use super::{BzbUniforms, SplatPass, SplatSpec, ZMinMaxPass, DEPTH, DIRECTIONS, MAX_DIRECTIONS, ORIGINS};
use crate::frame::{Pass, TargetDesc, Targets};
use crate::gpu::GpuContext;
use crate::lights::GpuLight;
use crate::passes::bilateral::{BilateralPass, BilateralSettings};
use crate::passes::builder::{FullscreenPass, PassBuilder};
use crate::scene_gpu::GpuScene;
use crate::spiral::pcg_hash;

/// Ray–triangle tests a frame above which `bzb-gi`'s AOV splat gets a warning: about 80 s
/// on lavapipe (2 cores), which tests about 1.3·10⁸ a second (atrium, 160×90).
pub const SPLAT_TESTS_WARNING: u64 = 10_000_000_000;

/// Bounced-z-buffer GI settings. Defaults: S = 4, visibility on, d_max = the
/// scene's bounding-box diagonal, t_min = 0.01 × the scene's AO radius (the AO
/// bias convention), seed 0, bilateral filter 4 taps each side, 1 px apart.
#[derive(Clone, Debug, PartialEq)]
pub struct BzbGiSettings {
    /// S: directions per pixel (1..=16).
    pub directions: u32,
    /// true: bounced z-buffer (nearest sender per direction); false: the additive baseline.
    pub visibility: bool,
    /// Largest sender distance d_max (world units); `None` = the scene's diagonal. A ray
    /// that hits no sender within d_max brings the sky's radiance when d_max is at
    /// least the diagonal (it has left the scene), and nothing otherwise.
    pub d_max: Option<f32>,
    /// Ray t_min (world units); `None` = 0.01 × the scene's AO radius.
    pub bias: Option<f32>,
    pub seed: u32,
    pub filter: BilateralSettings,
    /// Depth-tile culling of splats, AOV triangles and DSS shells (BZB §4.3; the
    /// image is unchanged).
    pub culling: bool,
    /// AOV splats draw the box around each triangle's occlusion volume (as `bzb-ao`'s
    /// [`super::BzbSettings::box_splats`]); the image is unchanged.
    pub box_splats: bool,
    /// The AOV splats as fragment or compute work (as `bzb-ao`'s
    /// [`super::BzbSettings::splat_kernel`]; default `Auto`); the image is unchanged.
    pub splat_kernel: crate::passes::Kernel,
    /// Largest sender radiance a payload keeps (its RGB scaled down to this
    /// maximum component; biased, trades caustic fireflies for energy); `None` = off.
    pub clamp: Option<f32>,
    /// The splats: the scene's triangles (AOV-style, default) or DSS surfels
    /// shaded with direct light at surfelization (BZB §4.3).
    pub splat: super::Splat,
    /// DSS's levels, surfel size and frustum culling (`splat = dss`); the
    /// outermost shell reaches d_max.
    pub dss: super::dss::DssSettings,
    /// DGB §3.3's temporal filter (reverse reprojection, EWMA) on the reconstructed
    /// irradiance and glossy radiance before the bilateral filter, with the
    /// directions re-drawn every frame (seed + frame): a still camera averages S new
    /// directions per frame. `None` (the default, as the paper): every frame stands
    /// alone. Not in BZB.
    pub temporal: Option<crate::passes::temporal::TemporalSettings>,
}

impl Default for BzbGiSettings {
    fn default() -> Self {
        Self {
            directions: 4,
            visibility: true,
            d_max: None,
            bias: None,
            seed: 0,
            filter: BilateralSettings {
                radius: 4,
                step: 1,
                ..BilateralSettings::default()
            },
            culling: true,
            box_splats: false,
            splat_kernel: crate::passes::Kernel::Auto,
            clamp: None,
            splat: super::Splat::Aov,
            dss: super::dss::DssSettings::default(),
            temporal: None,
        }
    }
}

/// The passes `splat=dss` adds to bzb-gi's frame (profiler names; the registry's
/// `passes` list the AOV path's): surfelization, the surfels' direct light, DSS's
/// shuffle, splat, unshuffle and reduction.
pub const DSS_PASSES: [&str; 8] = [
    "dss-tessellate",
    "dss-fine",
    "dss-filter",
    "dss-gi-shade",
    "dss-shuffle",
    "dss-splat",
    "dss-unshuffle",
    "dss-reduce",
];

impl BzbGiSettings {
    /// The temporal filter `alpha` turns on ([`super::temporal_filter`]).
    pub fn temporal_filter() -> crate::passes::temporal::TemporalSettings {
        super::temporal_filter()
    }

    pub fn validate(&self) -> Result<(), String> {
        if !(1..=MAX_DIRECTIONS).contains(&self.directions) {
            return Err(format!(
                "bzb-gi directions {} is out of range: must be in 1..={MAX_DIRECTIONS}",
                self.directions
            ));
        }
        if let Some(d) = self.d_max {
            if !(d > 0.0 && d.is_finite()) {
                return Err(format!("bzb-gi dmax {d} is out of range: must be > 0"));
            }
        }
        if let Some(b) = self.bias {
            if !(b >= 0.0 && b.is_finite()) {
                return Err(format!("bzb-gi bias {b} is out of range: must be >= 0"));
            }
        }
        if let Some(c) = self.clamp {
            if !(c > 0.0 && c.is_finite()) {
                return Err(format!("bzb-gi clamp {c} is out of range: must be > 0"));
            }
        }
        super::splat_kernel_valid("bzb-gi", self.splat_kernel, self.box_splats, self.splat)?;
        self.dss.validate()?;
        if let Some(t) = &self.temporal {
            t.validate()?;
        }
        self.filter.validate()
    }

    /// Whether the AOV splats run as a compute pass on `gpu` (as `bzb-ao`'s
    /// [`super::BzbSettings::compute_splat_on`]).
    pub fn compute_splat_on(&self, gpu: &GpuContext, w: u32, h: u32) -> bool {
        let (c, r) = self.grid();
        let texels = (w * c) as u64 * (h * r) as u64;
        let form = (self.visibility, self.box_splats);
        self.splat == super::Splat::Aov
            && super::splat_compute_on(gpu, "bzb-gi", self.splat_kernel, form, texels).unwrap_or(false)
    }

    /// DSS uniforms (`splat = dss`) for a `w`×`h` frame: the outermost shell
    /// d_max_dss·2^(l_max−1) reaches bzb-gi's d_max; without visibility one
    /// direction (the additive sum does not depend on ω, reconstruction reads
    /// sub-image 0).
    pub fn dss_uniforms(&self, scene: &Scene, w: u32, h: u32, triangles: u32) -> super::dss::DssUniforms {
        let (d_max, t_min) = self.resolve(scene);
        let (cols, rows) = if self.visibility { self.grid() } else { (1, 1) };
        let [tri_capacity, fine_capacity, surfel_capacity] = super::dss::capacities(triangles);
        super::dss::DssUniforms {
            levels: self.dss.levels,
            directions: if self.visibility { self.directions } else { 1 },
            cols,
            rows,
            size: [w, h],
            plane: self.dss.plane(w, h),
            d_max: self.dss.d_max(d_max),
            t_min,
            surfel_px: self.dss.surfel_px,
            fine_ratio: super::dss::FINE_RATIO,
            max_fine: super::dss::MAX_FINE,
            tri_capacity,
            fine_capacity,
            surfel_capacity,
            seed: self.seed,
            visibility: self.visibility as u32,
            culling: self.dss.culling as u32,
            triangles,
            max_split: super::dss::MAX_SPLIT,
            gi: 1,
            depth_culling: self.culling as u32,
            redirect: self.dss.redirect as u32,
        }
    }

    /// (d_max, t_min) for `scene`.
    pub fn resolve(&self, scene: &Scene) -> (f32, f32) {
        let d_max = self.d_max.unwrap_or_else(|| scene_diagonal(scene));
        (d_max, self.bias.unwrap_or(0.01 * scene.settings.ao_radius))
    }

    /// Ray–triangle tests of one frame's AOV splat when every splat covers its whole
    /// sub-image: T·S·W·H (T·W·H for the additive baseline, which splats sub-image 0
    /// only). That is the case with d_max at least the scene's diagonal, the default: each
    /// triangle's box grown by d_max then holds the camera. `None` for DSS surfels or a
    /// shorter d_max, whose splats their grown boxes bound.
    pub fn full_screen_splat_tests(&self, scene: &Scene, w: u32, h: u32) -> Option<u64> {
        let spans = self.d_max.is_none_or(|d| d >= scene_diagonal(scene));
        if self.splat != super::Splat::Aov || !spans {
            return None;
        }
        let s = if self.visibility { self.directions } else { 1 };
        Some(scene.triangle_count() as u64 * s as u64 * w as u64 * h as u64)
    }

    /// The one-line warning of a full-screen AOV splat above [`SPLAT_TESTS_WARNING`] tests.
    pub fn cost_warning(&self, scene: &Scene, w: u32, h: u32) -> Option<String> {
        let tests = self.full_screen_splat_tests(scene, w, h)?;
        (tests > SPLAT_TESTS_WARNING).then(|| {
            format!(
                "bzb-gi: every AOV splat covers its whole sub-image (d_max spans the scene): {} triangles × {} directions × {w}x{h} = {tests:.1e} ray–triangle tests a frame, minutes or more on a CPU adapter; --set splat=dss splats surfels instead",
                scene.triangle_count(),
                if self.visibility { self.directions } else { 1 },
            )
        })
    }

    /// Sub-image grid (cols, rows): cols = ⌈√S⌉.
    pub fn grid(&self) -> (u32, u32) {
        let cols = (self.directions as f32).sqrt().ceil() as u32;
        (cols, self.directions.div_ceil(cols))
    }

    /// GPU bytes for `scene` at `w`×`h`; with `splat = dss` the DSS buffers at capacity
    /// too ([`super::dss::memory`]).
    pub fn estimated_bytes(&self, scene: &Scene, w: u32, h: u32) -> u64 {
        let triangles = scene.triangle_count() as u64;
        let dss = if self.splat == super::Splat::Dss {
            super::dss::memory(&self.dss_uniforms(scene, w, h, triangles as u32)).total()
        } else {
            0
        };
        let (c, r) = self.grid();
        let px = w as u64 * h as u64;
        // the compute splats' keys, where they may run
        let compute = self.splat_kernel != crate::passes::Kernel::Fragment && !self.box_splats;
        let keys = if compute && self.visibility { 8 } else { 0 };
        dss + px * (c * r) as u64 * (16 + 16 + 8 + 4 + keys)
            + px * 8 * 7
            + self.temporal.map_or(0, |_| px * (4 * 8 + 4 * 2))
            + triangles * (48 + 80)
            + super::zminmax_tile_count(w, h) as u64 * 8
    }

    /// The AOV splat uniforms with r = d_max (the additive baseline splats
    /// into sub-image 0 only: its sum does not depend on ω).
    pub fn splat_uniforms(&self, scene: &Scene, triangles: u32) -> BzbUniforms {
        let mut u = self.uniforms(scene, triangles);
        if !self.visibility {
            u.directions = 1;
        }
        u
    }

    /// The direction and reconstruction uniforms with r = d_max.
    pub fn uniforms(&self, scene: &Scene, triangles: u32) -> BzbUniforms {
        let (d_max, t_min) = self.resolve(scene);
        let (cols, rows) = self.grid();
        BzbUniforms {
            radius: d_max,
            t_min,
            inv_r2: 1.0 / (d_max * d_max),
            escape_sky: (d_max >= scene_diagonal(scene)) as u32,
            directions: self.directions,
            cols,
            rows,
            seed: self.seed,
            // bzb-gi reuses `hemisphere` as "the additive payload is irradiance
            // for glossy receivers too" (DSS without visibility: bzb_gi_reconstruct.wgsl)
            hemisphere: (self.splat == super::Splat::Dss && !self.visibility) as u32,
            visibility: self.visibility as u32,
            triangles,
            culling: self.culling as u32,
            box_splats: self.box_splats as u32,
        }
    }
}

/// The scene's bounding-box diagonal: the default d_max, and the distance past which
/// a ray from any surface has left the scene (misses then bring the sky's light).
fn scene_diagonal(scene: &Scene) -> f32 {
    let (lo, hi) = scene.bounds(0.0);
    (hi - lo).length().max(1e-3)
}

/// Mirrors `BzbGi` in `bzb_gi.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct GiUniforms {
    pub light_count: u32,
    pub pcf_radius: i32,
    pub shadow_size: f32,
    pub emission_in: u32,
    pub d_max: f32,
    pub t_min: f32,
    pub visibility: u32,
    pub seed: u32,
    /// Payload clamp (largest RGB component; 0 = off).
    pub clamp: f32,
    /// 1: Rect lights' shadows are the lighting pass's PCSS penumbrae (`LightingSettings::area_penumbrae`).
    pub area_penumbrae: u32,
    pub _pad: [u32; 2],
}

// ---- CPU twins of bzb_gi.wgsl ----

/// `bzb_gi_lobe_uniform`: the lobe-choice uniform of sample (p, s) (the third
/// hash after [`super::sample_uniforms`]' two).
pub fn lobe_uniform(p: [u32; 2], s: u32, seed: u32) -> f32 {
    let h1 = pcg_hash(p[0].wrapping_add(pcg_hash(p[1].wrapping_add(pcg_hash(s.wrapping_add(pcg_hash(seed)))))));
    let h2 = pcg_hash(h1 ^ 0x9e37_79b9);
    let h3 = pcg_hash(h2 ^ 0x85eb_ca6b);
    (h3 >> 8) as f32 / 16_777_216.0
}

fn luminance(c: Vec3) -> f32 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}

fn schlick_dielectric(c: f32) -> f32 {
    0.04 + 0.96 * (1.0 - c.clamp(0.0, 1.0)).powi(5)
}

/// The GGX α of `roughness` (clamped as the BRDF clamps it).
pub fn alpha(roughness: f32) -> f32 {
    let r = roughness.clamp(0.0, 1.0);
    (r * r).max(0.002)
}

/// `bzb_gi_p_spec`: probability of the specular lobe (as `strata_reference::brdf::Ggx`).
pub fn p_spec(nv: f32, rho: Vec3, metallic: f32) -> f32 {
    if nv <= 1e-4 {
        return 0.0;
    }
    let m = metallic.clamp(0.0, 1.0);
    let f0 = Vec3::splat(0.04).lerp(rho, m);
    let k = (1.0 - nv.clamp(0.0, 1.0)).powi(5);
    let ws = luminance(f0 + (Vec3::ONE - f0) * k);
    let wd = luminance(rho * (1.0 - m)) * (1.0 - schlick_dielectric(nv));
    let sum = ws + wd;
    if sum.is_nan() || sum <= 0.0 {
        return 0.5;
    }
    (ws / sum).clamp(0.0, 1.0)
}

fn ggx_d(cos_h: f32, alpha: f32) -> f32 {
    if cos_h <= 0.0 {
        return 0.0;
    }
    let a2 = alpha * alpha;
    let k = (1.0 - cos_h) * (1.0 + cos_h) + a2 * cos_h * cos_h;
    a2 / (std::f32::consts::PI * k * k)
}

fn smith_lambda(c: f32, alpha: f32) -> f32 {
    let c2 = (c * c).max(1e-12);
    let tan2 = (1.0 - c2).max(0.0) / c2;
    0.5 * ((1.0 + alpha * alpha * tan2).sqrt() - 1.0)
}

/// `bzb_gi_ggx_pdf`: solid-angle pdf of [`direction`] for a glossy receiver.
pub fn ggx_pdf(n: Vec3, v: Vec3, l: Vec3, rho: Vec3, roughness: f32, metallic: f32) -> f32 {
    let nv = n.dot(v);
    let ps = p_spec(nv, rho, metallic);
    let mut p = 0.0;
    if ps < 1.0 {
        p += (1.0 - ps) * n.dot(l).max(0.0) / std::f32::consts::PI;
    }
    if ps > 0.0 {
        let hv = v + l;
        let hl = hv.length();
        if hl > 0.0 {
            let h = hv / hl;
            if v.dot(h) > 0.0 {
                let a = alpha(roughness);
                let g1 = 1.0 / (1.0 + smith_lambda(nv, a));
                p += ps * g1 * ggx_d(n.dot(h), a) / (4.0 * nv);
            }
        }
    }
    p
}

fn vndf(v: Vec3, alpha: f32, u: [f32; 2]) -> Vec3 {
    let vs = Vec3::new(v.x * alpha, v.y * alpha, v.z).normalize();
    let phi = 2.0 * std::f32::consts::PI * u[0];
    let z = (1.0 - u[1]) * (1.0 + vs.z) - vs.z;
    let s = (1.0 - z * z).max(0.0).sqrt();
    let hs = Vec3::new(s * phi.cos(), s * phi.sin(), z) + vs;
    let h = Vec3::new(hs.x * alpha, hs.y * alpha, hs.z.max(0.0));
    let len = h.length();
    if len.is_nan() || len <= 0.0 {
        return Vec3::Z;
    }
    h / len
}

/// A glossy receiver's material for [`direction`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Glossy {
    pub rho: Vec3,
    pub roughness: f32,
    pub metallic: f32,
}

/// `bzb_gi_direction` (§3.1 for GI): ω and its pdf α for a receiver with unit
/// normal `n`, unit view direction `v`; `glossy` = `None` for Lambert
/// (cosine-weighted), else the GGX mixture of the path tracer.
pub fn direction(n: Vec3, v: Vec3, glossy: Option<Glossy>, u_lobe: f32, u: [f32; 2]) -> (Vec3, f32) {
    use std::f32::consts::PI;
    let sgn = if n.z >= 0.0 { 1.0 } else { -1.0 };
    let a = -1.0 / (sgn + n.z);
    let b = n.x * n.y * a;
    let t = Vec3::new(1.0 + sgn * n.x * n.x * a, sgn * b, -sgn * n.x);
    let bt = Vec3::new(b, sgn + n.y * n.y * a, -n.y);
    let nv = n.dot(v);
    let l = match glossy {
        Some(g) if u_lobe < p_spec(nv, g.rho, g.metallic) => {
            let hl = vndf(Vec3::new(v.dot(t), v.dot(bt), nv), alpha(g.roughness), u);
            let h = t * hl.x + bt * hl.y + n * hl.z;
            let rl = 2.0 * v.dot(h) * h - v;
            let len = rl.length();
            if len > 0.0 {
                rl / len
            } else {
                n
            }
        }
        _ => {
            let r = u[0].sqrt();
            let phi = 2.0 * PI * u[1];
            (t * (r * phi.cos()) + bt * (r * phi.sin()) + n * (1.0 - u[0]).max(0.0).sqrt()).normalize()
        }
    };
    match glossy {
        Some(g) => (l, ggx_pdf(n, v, l, g.rho, g.roughness, g.metallic)),
        None => (l, n.dot(l).max(0.0) / PI),
    }
}

/// The splat's triangles (`super::triangle_data`, 3 vec4 of positions each) with each
/// vertex's w = 1 where the edge from it to the next vertex is open
/// ([`super::dss::open_edges`]; with none given, as for AOV splats, w stays 0): DSS's
/// GI disks stop there.
pub fn gi_triangle_data(scene: &Scene, frame: f32, open_edges: &[[bool; 3]]) -> Vec<[f32; 4]> {
    let mut data = super::triangle_data(scene, frame);
    for (v, open) in data.chunks_exact_mut(3).zip(open_edges) {
        for k in 0..3 {
            v[k][3] = open[k] as u32 as f32;
        }
    }
    data
}

/// vec4s per triangle in the sender data ([`sender_data`], `gi_tris` in WGSL).
pub const SENDER_VEC4S: usize = 7;

/// Words of the sRGB decode table at the start of [`SenderTexels::words`].
pub const SENDER_TEXEL_LUT: usize = 256;

/// The most bytes of sender texels strata uploads by default: larger texture sets are
/// halved, largest first, until they fit ([`sender_texels`]).
pub const SENDER_TEXEL_BUDGET: u64 = 64 << 20;

/// The senders' base-colour textures as `bzb_gi_sender.wgsl` reads them: BZB §3.2's
/// payload is the sender's radiance at the hit y, so ρ(y) takes the texel under y's UV.
/// One `u32` storage buffer (no bindless):
/// - words 0–255: the reference's sRGB decode of each byte, as f32 bits (so the GPU
///   decodes exactly as `Texture::sample_linear`);
/// - then 4 words per uploaded texture (slot): offset of its first texel, width, height, 0;
/// - then the texels, RGBA8 packed little-endian (r in the low byte).
#[derive(Clone, Debug)]
pub struct SenderTexels {
    pub words: Vec<u32>,
    /// Per scene texture: its slot + 1, 0 where it is missing or malformed (the
    /// reference skips those too).
    pub slots: Vec<u32>,
    /// How many times a texture was halved to fit the budget (0: all at full size).
    pub halvings: u32,
}

/// Packs the scene's textures into [`SenderTexels`], at most `budget` bytes: while they
/// do not fit, the texture with the most texels is halved (triangle filter on the sRGB
/// bytes). Only the halved ones then differ from what the reference reads.
pub fn sender_texels(scene: &Scene, budget: u64) -> SenderTexels {
    let mut images: Vec<Option<image::RgbaImage>> = scene
        .textures
        .iter()
        .map(|t| {
            let bytes = t.width as u64 * t.height as u64 * 4;
            (t.width > 0 && t.height > 0 && t.rgba8.len() as u64 >= bytes)
                .then(|| image::RgbaImage::from_raw(t.width, t.height, t.rgba8[..bytes as usize].to_vec()))
                .flatten()
        })
        .collect();
    let bytes = |images: &[Option<image::RgbaImage>]| -> u64 {
        let words: u64 = images
            .iter()
            .flatten()
            .map(|i| 4 + i.width() as u64 * i.height() as u64)
            .sum();
        (SENDER_TEXEL_LUT as u64 + words) * 4
    };
    let mut halvings = 0;
    while bytes(&images) > budget {
        let Some(big) = images
            .iter_mut()
            .flatten()
            .filter(|i| i.width() * i.height() > 1)
            .max_by_key(|i| i.width() as u64 * i.height() as u64)
        else {
            break;
        };
        let (w, h) = ((big.width() / 2).max(1), (big.height() / 2).max(1));
        *big = image::imageops::resize(big, w, h, image::imageops::FilterType::Triangle);
        halvings += 1;
    }
    let mut words: Vec<u32> = (0..=255u8)
        .map(|b| strata_scene::model::srgb_to_linear(b).to_bits())
        .collect();
    let uploaded = images.iter().flatten().count();
    let mut offset = (SENDER_TEXEL_LUT + 4 * uploaded) as u32;
    let mut slots = Vec::with_capacity(images.len());
    for image in &images {
        match image {
            Some(i) => {
                slots.push(1 + (words.len() - SENDER_TEXEL_LUT) as u32 / 4);
                words.extend([offset, i.width(), i.height(), 0]);
                offset += i.width() * i.height();
            }
            None => slots.push(0),
        }
    }
    for i in images.iter().flatten() {
        words.extend(i.pixels().map(|p| u32::from_le_bytes(p.0)));
    }
    SenderTexels { words, slots, halvings }
}

/// CPU twin of `gi_sender_texture` (`bzb_gi_sender.wgsl`): the linear base-colour
/// texture of slot `slot` (1-based; 0: none, white) under `uv`: nearest texel, wrap.
pub fn sender_texel_cpu(words: &[u32], slot: u32, uv: [f32; 2]) -> [f32; 3] {
    if slot == 0 {
        return [1.0; 3];
    }
    let e = SENDER_TEXEL_LUT + 4 * (slot as usize - 1);
    let (offset, w, h) = (words[e], words[e + 1], words[e + 2]);
    let x = ((uv[0] - uv[0].floor()) * w as f32) as u32;
    let y = ((uv[1] - uv[1].floor()) * h as f32) as u32;
    let p = words[(offset + y.min(h - 1) * w + x.min(w - 1)) as usize];
    [0, 8, 16].map(|s| f32::from_bits(words[((p >> s) & 0xff) as usize]))
}

/// Per-triangle sender data as `bzb_gi_sender.wgsl` pulls it: [`SENDER_VEC4S`] vec4
/// per triangle, (n0, ρ.r), (n1, ρ.g), (n2, ρ.b), (emission, glossy), (roughness,
/// metallic, texture slot, 0), (uv0, uv1), (uv2, 0, 0). ρ is the material's base
/// colour; the shader multiplies it by the texture (slot from `slots`,
/// [`SenderTexels::slots`]; 0 = none) at the point it shades.
pub fn sender_data(scene: &Scene, frame: f32, slots: &[u32]) -> Vec<[f32; 4]> {
    let mut out = Vec::new();
    for t in scene.world_triangles(frame).iter() {
        let m = &scene.materials[t.material as usize];
        for (n, r) in t.n.iter().zip(m.base_color) {
            out.push(n.extend(r).to_array());
        }
        let e = m.emission;
        out.push([e[0], e[1], e[2], m.glossy as u32 as f32]);
        let slot = m.base_color_texture.and_then(|i| slots.get(i)).copied().unwrap_or(0);
        out.push([m.roughness, m.metallic, slot as f32, 0.0]);
        out.push([t.uv[0][0], t.uv[0][1], t.uv[1][0], t.uv[1][1]]);
        out.push([t.uv[2][0], t.uv[2][1], 0.0, 0.0]);
    }
    out
}

// ---- targets ----

pub const PAYLOAD: TargetDesc = TargetDesc::new(
    "bzb-gi-payload",
    wgpu::TextureFormat::Rgba16Float,
    1,
    "bzb-gi §3.2 payload per sub-image texel: the nearest sender's radiance L(y → x) (without visibility: the summed irradiance or glossy radiance of every splat)",
);
pub const HIT: TargetDesc = TargetDesc::new(
    "bzb-gi-hit",
    wgpu::TextureFormat::R32Float,
    1,
    "bzb-gi §3.2 the nearest sender per sub-image texel: triangle index + 1 (0 = no hit)",
);
pub const RAW: TargetDesc = TargetDesc::new(
    "bzb-gi-raw",
    wgpu::TextureFormat::Rgba16Float,
    1,
    "bzb-gi §3.3 Lambert receivers' indirect irradiance E before filtering",
);
pub const GLOSSY_RAW: TargetDesc = TargetDesc::new(
    "bzb-gi-glossy-raw",
    wgpu::TextureFormat::Rgba16Float,
    1,
    "bzb-gi §3.3 glossy receivers' indirect radiance before filtering",
);
pub const BLUR_H: TargetDesc = TargetDesc::new(
    "bzb-gi-blur-h",
    wgpu::TextureFormat::Rgba16Float,
    1,
    "bzb-gi irradiance after the horizontal bilateral pass",
);
pub const GLOSSY_BLUR_H: TargetDesc = TargetDesc::new(
    "bzb-gi-glossy-blur-h",
    wgpu::TextureFormat::Rgba16Float,
    1,
    "bzb-gi glossy radiance after the horizontal bilateral pass",
);
/// The temporal filter's outputs (`BzbGiSettings::temporal`) and last frame's copies.
pub const TEMPORAL: [TargetDesc; 4] = [
    TargetDesc::new(
        "bzb-gi-temporal",
        wgpu::TextureFormat::Rgba16Float,
        1,
        "bzb-gi irradiance after the temporal filter (DGB §3.3)",
    ),
    TargetDesc::new(
        "bzb-gi-temporal-history",
        wgpu::TextureFormat::Rgba16Float,
        1,
        "last frame's bzb-gi-temporal",
    ),
    TargetDesc::new(
        "bzb-gi-glossy-temporal",
        wgpu::TextureFormat::Rgba16Float,
        1,
        "bzb-gi glossy radiance after the temporal filter",
    ),
    TargetDesc::new(
        "bzb-gi-glossy-temporal-history",
        wgpu::TextureFormat::Rgba16Float,
        1,
        "last frame's bzb-gi-glossy-temporal",
    ),
];
/// The passes the temporal filter adds (`alpha` > 0; the registry lists the default frame's).
pub const TEMPORAL_PASSES: [&str; 2] = ["bzb-gi-temporal", "bzb-gi-glossy-temporal"];

/// The temporal filters' per-pixel counts and their copies (irradiance, glossy).
pub const TEMPORAL_FRAMES: [[&str; 2]; 2] = [
    ["bzb-gi-temporal-frames", "bzb-gi-temporal-frames-history"],
    ["bzb-gi-glossy-temporal-frames", "bzb-gi-glossy-temporal-frames-history"],
];

pub const GLOSSY: TargetDesc = TargetDesc::new(
    "bzb-gi-glossy",
    wgpu::TextureFormat::Rgba16Float,
    1,
    "bzb-gi glossy receivers' indirect radiance (filtered), added by compose",
);

/// The frame's bzb-gi passes (profiler names).
pub const PASSES: &[&str] = &[
    "bzb-directions",
    "bzb-zminmax",
    "bzb-gi-senders",
    "bzb-splat",
    "bzb-gi-shade",
    "bzb-reconstruct",
    "bzb-gi-blur-h",
    "bzb-gi-blur-v",
    "bzb-gi-glossy-blur-h",
    "bzb-gi-glossy-blur-v",
    "compose",
];

macro_rules! gi_shader {
    ($file:literal) => {
        concat!(
            include_str!("bzb.wgsl"),
            "\n",
            include_str!("bzb_gi.wgsl"),
            "\n",
            include_str!($file)
        )
    };
}

/// What the GI stage needs of the lighting: the shadow maps and lights it was built with.
pub struct LightInputs<'a> {
    pub shadow: &'a crate::passes::shadow::ShadowPass,
    pub lights: &'a [GpuLight],
    pub shadow_resolution: u32,
    pub pcf_radius: i32,
    pub area_penumbrae: bool,
}

pub(crate) struct BzbGiStage {
    directions: FullscreenPass,
    /// AOV-style triangle splats (`splat = aov`).
    zminmax: Option<ZMinMaxPass>,
    splat: Option<SplatPass>,
    /// DSS surfels (`splat = dss`).
    dss: Option<super::dss::DssStage>,
    /// Without visibility: the triangles' mean radiance L̄_T.
    senders_pass: Option<SenderPass>,
    /// With visibility: the winners' radiance (deferred shading of the hits).
    shade: Option<FullscreenPass>,
    reconstruct: FullscreenPass,
    /// `BzbGiSettings::temporal`: irradiance, glossy radiance.
    temporal: Option<[crate::passes::temporal::TemporalPass; 2]>,
    blur: [BilateralPass; 4],
    compose: crate::passes::compose::ComposePass,
    splat_uniforms: wgpu::Buffer,
    gi_uniforms: wgpu::Buffer,
    lights: wgpu::Buffer,
    triangles: wgpu::Buffer,
    senders: wgpu::Buffer,
    /// Each scene texture's slot in the senders' texels ([`sender_texels`]).
    texture_slots: Vec<u32>,
    /// [`super::dss::open_edges`] of every triangle (DSS only; empty for AOV splats).
    open_edges: Vec<[bool; 3]>,
    count: u32,
    settings: BzbGiSettings,
    base: GiUniforms,
}

impl BzbGiStage {
    pub fn new(
        gpu: &GpuContext,
        scene_gpu: &GpuScene,
        targets: &mut Targets,
        s: &BzbGiSettings,
        scene: &Scene,
        light: &LightInputs,
        layers: u32,
    ) -> Result<Self, crate::RenderError> {
        use wgpu::util::DeviceExt;
        let device = &gpu.device;
        let (w, h) = (targets.width, targets.height);
        let (cols, rows) = s.grid();
        let max = device.limits().max_texture_dimension_2d;
        if w * cols > max || h * rows > max {
            return Err(crate::RenderError::Parameter(format!(
                "bzb-gi directions {}: the bounced z-buffer of {cols}x{rows} sub-images is {}x{}, over the adapter's largest texture {max}x{max} (lower the directions or the size)",
                s.directions,
                w * cols,
                h * rows
            )));
        }
        let big = [w * cols, h * rows];
        for d in [ORIGINS, DIRECTIONS, PAYLOAD] {
            targets.create_sized(gpu, d, big);
        }
        let aov = s.splat == super::Splat::Aov;
        if s.visibility && aov {
            targets.create_sized(gpu, DEPTH, big);
            targets.create_sized(gpu, HIT, big);
        }
        for d in [
            RAW,
            GLOSSY_RAW,
            BLUR_H,
            GLOSSY_BLUR_H,
            GLOSSY,
            crate::passes::ils::INDIRECT,
        ] {
            if targets.try_get(d.name).is_none() {
                targets.create(gpu, d);
            }
        }
        for t in crate::passes::compose::OUTPUTS {
            if targets.try_get(t.name).is_none() {
                targets.create(gpu, t);
            }
        }
        // only DSS's disks need them (AOV splats test the triangle itself)
        let open_edges = match s.splat {
            super::Splat::Dss => super::dss::open_edges(scene),
            super::Splat::Aov => Vec::new(),
        };
        let data = gi_triangle_data(scene, 0.0, &open_edges);
        let count = (data.len() / 3) as u32;
        let limit = device.limits().max_storage_buffer_binding_size;
        let packed = sender_texels(scene, SENDER_TEXEL_BUDGET.min(limit));
        if packed.halvings > 0 {
            tracing::warn!(
                "scene '{}': bzb-gi halved its senders' textures {} times to fit {} bytes (the reference reads them at full size)",
                scene.name,
                packed.halvings,
                SENDER_TEXEL_BUDGET.min(limit)
            );
        }
        let senders_data = sender_data(scene, 0.0, &packed.slots);
        let sender_bytes = (senders_data.len() * 16).max(16 * SENDER_VEC4S) as u64;
        if sender_bytes > limit {
            return Err(crate::RenderError::Parameter(format!(
                "scene '{}' has {count} triangles: {sender_bytes} bytes of bzb-gi sender data exceed the adapter's storage buffer binding size {limit}",
                scene.name
            )));
        }
        let buffer = |label: &str, mut bytes: Vec<u8>, min: usize, usage: wgpu::BufferUsages| {
            bytes.resize(bytes.len().max(min), 0);
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents: &bytes,
                usage,
            })
        };
        let storage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST;
        let triangles = buffer("bzb-triangles", bytemuck::cast_slice(&data).to_vec(), 48, storage);
        let senders = buffer(
            "bzb-gi-senders",
            bytemuck::cast_slice(&senders_data).to_vec(),
            16 * SENDER_VEC4S,
            storage,
        );
        let texels = buffer(
            "bzb-gi-sender-texels",
            bytemuck::cast_slice(&packed.words).to_vec(),
            0,
            storage,
        );
        let mut light_data = light.lights.to_vec();
        if light_data.is_empty() {
            light_data.push(Zeroable::zeroed());
        }
        let lights = buffer("bzb-gi-lights", bytemuck::cast_slice(&light_data).to_vec(), 0, storage);
        let u = s.uniforms(scene, count);
        let splat_u = s.splat_uniforms(scene, count);
        let base = GiUniforms {
            light_count: light.lights.len() as u32,
            pcf_radius: light.pcf_radius.clamp(0, 4),
            shadow_size: light.shadow_resolution as f32,
            // the lighting pass's convention: Rect lights carry their emitters' light
            emission_in: !light.lights.iter().any(|l| l.kind[0] == crate::lights::KIND_RECT) as u32,
            d_max: u.radius,
            t_min: u.t_min,
            visibility: s.visibility as u32,
            seed: s.seed,
            clamp: s.clamp.unwrap_or(0.0),
            area_penumbrae: light.area_penumbrae as u32,
            _pad: [0; 2],
        };
        let uniform = wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST;
        let splat_uniforms = buffer("bzb-splat", bytemuck::bytes_of(&splat_u).to_vec(), 0, uniform);
        let mean = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("bzb-gi-mean-radiance"),
            size: (count.max(1) as u64) * 16,
            usage: wgpu::BufferUsages::STORAGE,
            mapped_at_creation: false,
        });
        let gi_uniforms = buffer("bzb-gi", bytemuck::bytes_of(&base).to_vec(), 0, uniform);

        let directions = PassBuilder::new(gpu, targets, "bzb-directions")
            .shader("bzb-gi-directions", gi_shader!("bzb_gi_directions.wgsl"))
            .frame(scene_gpu)
            .uniforms(&u)
            .read("zpack")
            .read("npack")
            .read_layer("normal", 0)
            .read_layer("albedo", 0)
            .read_layer("emission", 0)
            .write(ORIGINS.name)
            .write(DIRECTIONS.name)
            .build();
        let reconstruct = PassBuilder::new(gpu, targets, "bzb-reconstruct")
            .shader("bzb-gi-reconstruct", gi_shader!("bzb_gi_reconstruct.wgsl"))
            .frame(scene_gpu)
            .uniforms(&u)
            .read(PAYLOAD.name)
            .read(DIRECTIONS.name)
            .read("zpack")
            .read("npack")
            .read_layer("normal", 0)
            .read_layer("albedo", 0)
            .read_layer("emission", 0)
            .write(RAW.name)
            .write(GLOSSY_RAW.name)
            .build();
        let tile_count = super::zminmax_tile_count(w, h);
        let tiles = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("bzb-zminmax"),
            size: tile_count as u64 * 8,
            usage: wgpu::BufferUsages::STORAGE,
            mapped_at_creation: false,
        });
        // the AOV splats and DSS's shells cull against the same tiles
        let zminmax = Some(super::BzbStage::zminmax_pass(
            gpu, scene_gpu, targets, &tiles, tile_count,
        ));

        // group 2 of the splat: sender data, lights, shadow maps, receiver material
        let frag = wgpu::ShaderStages::FRAGMENT;
        let tex = |binding| crate::passes::texture_entry(binding, wgpu::TextureViewDimension::D2, false);
        let storage_ro = |binding| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: frag,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Storage { read_only: true },
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        };
        let [shadow_texture, shadow_sampler] = crate::passes::shadow_map_entries(3, frag);
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("bzb-gi-senders"),
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: frag,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                },
                storage_ro(1),
                storage_ro(2),
                shadow_texture,
                shadow_sampler,
                storage_ro(5),
                tex(6),
                tex(7),
                tex(8),
                storage_ro(9),
                storage_ro(10),
            ],
        });
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("bzb-gi shadow"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            compare: Some(wgpu::CompareFunction::LessEqual),
            ..Default::default()
        });
        let view = |n: &str| wgpu::BindingResource::TextureView(targets.get(n).layer(0));
        let group = crate::passes::bind_group(
            device,
            "bzb-gi-senders",
            &layout,
            &[
                gi_uniforms.as_entire_binding(),
                senders.as_entire_binding(),
                lights.as_entire_binding(),
                wgpu::BindingResource::TextureView(&light.shadow.array_view),
                wgpu::BindingResource::Sampler(&sampler),
                light.shadow.matrices.as_entire_binding(),
                view("normal"),
                view("albedo"),
                view("emission"),
                mean.as_entire_binding(),
                texels.as_entire_binding(),
            ],
        );
        let senders_pass = (!s.visibility && aov).then(|| {
            SenderPass::new(
                gpu,
                [
                    gi_uniforms.as_entire_binding(),
                    triangles.as_entire_binding(),
                    senders.as_entire_binding(),
                    lights.as_entire_binding(),
                    wgpu::BindingResource::TextureView(&light.shadow.array_view),
                    wgpu::BindingResource::Sampler(&sampler),
                    light.shadow.matrices.as_entire_binding(),
                    mean.as_entire_binding(),
                    texels.as_entire_binding(),
                ],
                count,
            )
        });
        let shade = (s.visibility && aov).then(|| {
            PassBuilder::new(gpu, targets, "bzb-gi-shade")
                .shader("bzb-gi-shade", gi_sender_shader!("bzb_gi_shade.wgsl"))
                .frame(scene_gpu)
                .uniforms(&base)
                .read(ORIGINS.name)
                .read(DIRECTIONS.name)
                .read(HIT.name)
                .storage(&triangles)
                .storage(&senders)
                .storage(&lights)
                .depth_view(
                    "shadow-maps",
                    &light.shadow.array_view,
                    wgpu::TextureViewDimension::D2Array,
                )
                .sampler(&sampler, wgpu::SamplerBindingType::Comparison)
                .storage(&light.shadow.matrices)
                .storage(&texels)
                .write(PAYLOAD.name)
                .build()
        });
        let big_texels = big[0] as u64 * big[1] as u64;
        let form = (s.visibility, s.box_splats);
        let compute_splat = aov && super::splat_compute_on(gpu, "bzb-gi", s.splat_kernel, form, big_texels)?;
        let splat = aov.then(|| {
            super::splat_pass_with(
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
                        include_str!("bzb_gi.wgsl"),
                        "\n",
                        include_str!("bzb_splat.wgsl"),
                        "\n",
                        include_str!("bzb_gi_sender.wgsl"),
                        "\n",
                        include_str!("bzb_gi_splat.wgsl")
                    ),
                    entries: ("fs_visibility", "fs_gi_additive"),
                    payload: if s.visibility { HIT } else { PAYLOAD },
                    extra: Some((&layout, group)),
                    hit: super::HitPayload::HitIndex,
                    compute: compute_splat,
                },
                &splat_uniforms,
                &triangles,
                &tiles,
            )
        });
        let dss = match s.splat {
            super::Splat::Aov => None,
            super::Splat::Dss => Some(super::dss::DssStage::new(
                gpu,
                scene_gpu,
                targets,
                &s.dss_uniforms(scene, w, h, count),
                (&triangles, &tiles),
                PAYLOAD.name,
                Some(super::dss::DssGiInputs {
                    gi_uniforms: &gi_uniforms,
                    senders: &senders,
                    lights: &lights,
                    shadow_view: &light.shadow.array_view,
                    sampler: &sampler,
                    shadow_mats: &light.shadow.matrices,
                    texels: &texels,
                }),
            )?),
        };
        // the temporal filter between the reconstruction and the bilateral filter
        let (mut filtered, mut glossy_filtered) = (RAW.name, GLOSSY_RAW.name);
        let temporal = s.temporal.as_ref().map(|t| {
            for d in TEMPORAL.into_iter().chain(
                TEMPORAL_FRAMES
                    .into_iter()
                    .flat_map(crate::passes::temporal::frames_targets),
            ) {
                targets.create(gpu, d);
            }
            (filtered, glossy_filtered) = (TEMPORAL[0].name, TEMPORAL[2].name);
            let pass = |name, input, k: usize| {
                crate::passes::temporal::TemporalPass::new(
                    gpu,
                    scene_gpu,
                    targets,
                    t,
                    name,
                    input,
                    TEMPORAL[2 * k + 1].name,
                    TEMPORAL[2 * k].name,
                    TEMPORAL_FRAMES[k],
                    layers,
                    false,
                )
            };
            [
                pass(TEMPORAL_PASSES[0], RAW.name, 0),
                pass(TEMPORAL_PASSES[1], GLOSSY_RAW.name, 1),
            ]
        });
        // after the temporal filters the blur may widen where the history is short
        let has_temporal = temporal.is_some();
        let blur = |name, input, output, vertical, k: usize| {
            let frames = has_temporal.then_some(TEMPORAL_FRAMES[k][0]);
            BilateralPass::new(
                gpu, scene_gpu, targets, &s.filter, name, input, output, vertical, false, frames,
            )
        };
        let blur = [
            blur("bzb-gi-blur-h", filtered, BLUR_H.name, false, 0),
            blur("bzb-gi-blur-v", BLUR_H.name, crate::passes::ils::INDIRECT.name, true, 0),
            blur("bzb-gi-glossy-blur-h", glossy_filtered, GLOSSY_BLUR_H.name, false, 1),
            blur("bzb-gi-glossy-blur-v", GLOSSY_BLUR_H.name, GLOSSY.name, true, 1),
        ];
        let compose = crate::passes::compose::ComposePass::new(
            gpu,
            scene_gpu,
            targets,
            false,
            None,
            crate::passes::ils::INDIRECT.name,
            Some(GLOSSY.name),
            false,
        );
        Ok(Self {
            directions,
            zminmax,
            splat,
            dss,
            senders_pass,
            shade,
            reconstruct,
            temporal,
            blur,
            compose,
            splat_uniforms,
            gi_uniforms,
            lights,
            triangles,
            senders,
            texture_slots: packed.slots,
            open_edges,
            count,
            settings: s.clone(),
            base,
        })
    }

    /// This frame's uniforms; animated scenes also get their triangles and lights at `frame`.
    /// With the temporal filter the directions' seed moves on with `frame_index` (frames
    /// rendered so far; 0 keeps the settings' seed) and `has_history` says whether last
    /// frame's filtered output may be reprojected.
    #[allow(clippy::too_many_arguments)]
    pub fn set_frame(
        &self,
        gpu: &GpuContext,
        scene: &Scene,
        frame: f32,
        animated: bool,
        lights: &[GpuLight],
        frame_index: u32,
        has_history: bool,
    ) {
        let mut u = self.settings.uniforms(scene, self.count);
        if let Some(t) = &self.temporal {
            u.seed = super::frame_seed(self.settings.seed, frame_index);
            for p in t {
                p.set_frame(gpu, has_history);
            }
        }
        self.directions.set_uniforms(gpu, &u);
        self.reconstruct.set_uniforms(gpu, &u);
        let u = self.settings.splat_uniforms(scene, self.count);
        if let Some(p) = &self.shade {
            p.set_uniforms(gpu, &self.base);
        }
        gpu.queue.write_buffer(&self.splat_uniforms, 0, bytemuck::bytes_of(&u));
        if let Some(d) = &self.dss {
            let [w, h] = d.size;
            d.set_uniforms(gpu, &self.settings.dss_uniforms(scene, w, h, self.count));
        }
        gpu.queue
            .write_buffer(&self.gi_uniforms, 0, bytemuck::bytes_of(&self.base));
        if animated && self.count > 0 {
            let data = gi_triangle_data(scene, frame, &self.open_edges);
            gpu.queue.write_buffer(&self.triangles, 0, bytemuck::cast_slice(&data));
            let senders = sender_data(scene, frame, &self.texture_slots);
            gpu.queue.write_buffer(&self.senders, 0, bytemuck::cast_slice(&senders));
            if !lights.is_empty() {
                gpu.queue.write_buffer(&self.lights, 0, bytemuck::cast_slice(lights));
            }
        }
    }

    pub fn passes(&self) -> Vec<&dyn Pass> {
        let mut v: Vec<&dyn Pass> = vec![&self.directions];
        if let Some(p) = &self.zminmax {
            v.push(p);
        }
        if let Some(p) = &self.senders_pass {
            v.push(p);
        }
        if let Some(p) = &self.splat {
            v.push(p);
        }
        if let Some(d) = &self.dss {
            v.extend(d.passes());
        }
        if let Some(p) = &self.shade {
            v.push(p);
        }
        v.push(&self.reconstruct);
        if let Some(t) = &self.temporal {
            v.extend(t.iter().map(|p| p as &dyn Pass));
        }
        v.extend(self.blur.iter().map(|b| b as &dyn Pass));
        v.push(&self.compose);
        v
    }

    /// The DSS stage (`splat = dss`).
    pub fn dss(&self) -> Option<&super::dss::DssStage> {
        self.dss.as_ref()
    }

    /// Scene triangles (splat buffer).
    pub fn triangle_count(&self) -> u32 {
        self.count
    }

    /// The splat uniforms of the last frame (d_max in `radius`).
    pub fn uniforms(&self) -> GiUniforms {
        self.base
    }
}

/// `bzb-gi-senders` (compute, baseline only): every triangle's mean radiance L̄_T.
struct SenderPass {
    pipeline: wgpu::ComputePipeline,
    group: wgpu::BindGroup,
    count: u32,
}

impl SenderPass {
    fn new(gpu: &GpuContext, resources: [wgpu::BindingResource; 9], count: u32) -> Self {
        let device = &gpu.device;
        let comp = wgpu::ShaderStages::COMPUTE;
        let buf = |binding, read_only| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: comp,
            ty: wgpu::BindingType::Buffer {
                ty: if binding == 0 {
                    wgpu::BufferBindingType::Uniform
                } else {
                    wgpu::BufferBindingType::Storage { read_only }
                },
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        };
        let [shadow_texture, shadow_sampler] = crate::passes::shadow_map_entries(4, comp);
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("bzb-gi-senders"),
            entries: &[
                buf(0, true),
                buf(1, true),
                buf(2, true),
                buf(3, true),
                shadow_texture,
                shadow_sampler,
                buf(6, true),
                buf(7, false),
                buf(8, true),
            ],
        });
        let group = crate::passes::bind_group(device, "bzb-gi-senders", &layout, &resources);
        let pl = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("bzb-gi-senders"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let module = crate::shader::module(device, "bzb-gi-senders", gi_sender_shader!("bzb_gi_senders.wgsl"));
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("bzb-gi-senders"),
            layout: Some(&pl),
            module: &module,
            entry_point: Some("cs_main"),
            compilation_options: Default::default(),
            cache: None,
        });
        Self { pipeline, group, count }
    }
}

impl Pass for SenderPass {
    fn info(&self) -> crate::frame::PassInfo {
        crate::frame::PassInfo {
            name: "bzb-gi-senders",
            inputs: vec!["shadow-maps"],
            outputs: vec!["bzb-gi-mean-radiance"],
        }
    }

    fn encode(&self, _gpu: &GpuContext, _scene: &GpuScene, _targets: &Targets, encoder: &mut wgpu::CommandEncoder) {
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("bzb-gi-senders"),
            timestamp_writes: None,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &self.group, &[]);
        pass.dispatch_workgroups(self.count.div_ceil(64), 1, 1);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use strata_scene::model::{Material, Texture};

    fn texture(name: &str, width: u32, height: u32, seed: u32) -> Texture {
        let rgba8 = (0..width * height * 4)
            .map(|i| (i.wrapping_mul(2_654_435_761).wrapping_add(seed) >> 13) as u8)
            .collect();
        Texture {
            name: name.into(),
            width,
            height,
            rgba8,
        }
    }

    fn scene_with(textures: Vec<Texture>) -> Scene {
        let mut scene = Scene::default();
        for (i, t) in textures.into_iter().enumerate() {
            let mut m = Material::diffuse(&t.name, [1.0; 3]);
            m.base_color_texture = Some(i);
            scene.materials.push(m);
            scene.textures.push(t);
        }
        scene
    }

    /// The packed texels read back exactly what the reference reads
    /// (`Texture::sample_linear`), at random UVs, negative and beyond 1 too; a
    /// malformed texture gets no slot (white), as the reference skips it.
    #[test]
    fn sender_texels_read_as_the_reference_reads_its_textures() {
        let mut bad = texture("short", 4, 4, 1);
        bad.rgba8.truncate(10);
        let scene = scene_with(vec![texture("a", 7, 3, 5), bad, texture("b", 16, 9, 11)]);
        let packed = sender_texels(&scene, SENDER_TEXEL_BUDGET);
        assert_eq!(packed.slots, vec![1, 0, 2]);
        assert_eq!(packed.halvings, 0);
        assert_eq!(packed.words.len(), SENDER_TEXEL_LUT + 8 + 7 * 3 + 16 * 9);
        assert_eq!(sender_texel_cpu(&packed.words, 0, [0.3, 0.4]), [1.0; 3]);
        let mut state = 12345u32;
        let mut next = || {
            state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (state >> 8) as f32 / (1 << 24) as f32 * 6.0 - 3.0
        };
        for _ in 0..2000 {
            let uv = [next(), next()];
            for (t, slot) in [(0usize, 1u32), (2, 2)] {
                let want = scene.textures[t].sample_linear(uv);
                assert_eq!(
                    sender_texel_cpu(&packed.words, slot, uv),
                    [want[0], want[1], want[2]],
                    "{uv:?}"
                );
            }
        }
    }

    /// Over the budget the largest texture is halved first, until the words fit.
    #[test]
    fn sender_texels_halve_the_largest_texture_to_fit_the_budget() {
        let scene = scene_with(vec![texture("big", 64, 32, 3), texture("small", 8, 8, 7)]);
        let full = sender_texels(&scene, SENDER_TEXEL_BUDGET);
        let budget = (full.words.len() as u64 * 4) / 2;
        let packed = sender_texels(&scene, budget);
        assert!(packed.words.len() as u64 * 4 <= budget);
        assert_eq!(packed.halvings, 1);
        let dims = |slot: u32| {
            let e = SENDER_TEXEL_LUT + 4 * (slot as usize - 1);
            (packed.words[e + 1], packed.words[e + 2])
        };
        assert_eq!((dims(1), dims(2)), ((32, 16), (8, 8)));
    }
}
