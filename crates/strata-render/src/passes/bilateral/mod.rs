//! Separable bilateral reconstruction with normal and plane weights (DGB §3.1,
//! [SGNS07]), reusable by every noisy screen-space estimate: a horizontal and a
//! vertical [`BilateralPass`].

use glam::Vec3;
use strata_scene::ImageBuf;

use crate::frame::{FrameUniforms, Targets};
use crate::gpu::GpuContext;
use crate::passes::ao::world_from_csz;
use crate::passes::builder::{PassBuilder, ScreenPass};
use crate::scene_gpu::GpuScene;

/// Defaults: radius 4 taps with step 2 pixels (SAO's AO blur: 9 taps spanning
/// ±8 px per direction), Gaussian σ = 0.75·radius taps (SAO's radius-4 kernel has
/// σ ≈ 3), plane weight max(0, 1 − 100·d/z) (zero once the tap's surface is 1 % of
/// X's depth off X's tangent plane), normal weight (n_X·n_Y)^8, no distance weight.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BilateralSettings {
    /// Taps on each side (0 disables the filter).
    pub radius: u32,
    /// Pixels between taps.
    pub step: u32,
    pub plane_sharpness: f32,
    /// Exponent of the normal weight (n_X·n_Y)^p, 0..=32.
    pub normal_power: u32,
    /// World distance R beyond which a tap's surface gets no weight: × max(0, 1 − |Y − X|²/R²)
    /// ([`distance_weight`]). Not in the paper (its weights see only X's tangent plane and
    /// normal, so on a surface seen at a grazing angle neighbouring pixels metres apart
    /// are averaged). `None`: off. AO sets it to its radius (`ao::AoSettings::distance_weight`).
    pub world_radius: Option<f32>,
    /// History-aware radius after a temporal filter (not in the papers): a pixel whose
    /// history holds n accepted frames (the temporal filter's count) filters with radius
    /// max(`radius`, round(R_fresh / √(n + 1))) taps, so a disoccluded pixel (n = 0) gets
    /// R_fresh and the extra taps fall away as its history builds up (2-D taps ∝ r²,
    /// history variance ∝ 1/(n + 1)). `None`: off; only passes given the count use it.
    pub fresh_radius: Option<u32>,
}

/// The bilateral filter's distance weight of a tap whose surface lies `d2` = |Y − X|² from
/// X, for world radius `r` (CPU twin of bilateral.wgsl's): 1 at X, 0 from R on.
pub fn distance_weight(d2: f32, r: f32) -> f32 {
    (1.0 - d2 / (r * r)).max(0.0)
}

impl Default for BilateralSettings {
    fn default() -> Self {
        Self {
            radius: 4,
            step: 2,
            plane_sharpness: 100.0,
            normal_power: 8,
            world_radius: None,
            fresh_radius: None,
        }
    }
}

impl BilateralSettings {
    pub fn validate(&self) -> Result<(), String> {
        if self.radius > 32 {
            return Err(format!(
                "blur radius {} is out of range: must be in 0..=32",
                self.radius
            ));
        }
        if !(1..=8).contains(&self.step) {
            return Err(format!("blur step {} is out of range: must be in 1..=8", self.step));
        }
        if !(self.plane_sharpness >= 0.0 && self.plane_sharpness.is_finite()) {
            return Err(format!(
                "blur plane sharpness {} is out of range: must be >= 0",
                self.plane_sharpness
            ));
        }
        if self.normal_power > 32 {
            return Err(format!(
                "blur normal power {} is out of range: must be in 0..=32",
                self.normal_power
            ));
        }
        if let Some(r) = self.world_radius {
            if !(r > 0.0 && r.is_finite()) {
                return Err(format!("blur world radius {r} is out of range: must be > 0"));
            }
        }
        if let Some(r) = self.fresh_radius {
            if !(1..=32).contains(&r) {
                return Err(format!("blur fresh radius {r} is out of range: must be in 1..=32"));
            }
        }
        Ok(())
    }

    /// Total taps per direction (the paper's "reconstruction filter taps").
    pub fn taps(&self) -> u32 {
        2 * self.radius + 1
    }
}

/// The Gaussian weight of tap k for a filter of `radius` taps (σ = 0.75·radius, at least
/// ½), as `BilateralUniforms::gauss` holds it and bilateral.wgsl computes it for the
/// history-aware radii.
pub fn gauss_weight(k: u32, radius: u32) -> f32 {
    let sigma = (0.75 * radius as f32).max(0.5);
    (-((k * k) as f32) / (2.0 * sigma * sigma)).exp()
}

/// [`BilateralSettings::fresh_radius`]: the radius of a pixel whose temporal history holds
/// `n` accepted frames (WGSL twin `history_radius`).
pub fn history_radius(radius: u32, fresh_radius: u32, n: f32) -> u32 {
    radius.max((fresh_radius as f32 / (n.max(0.0) + 1.0).sqrt() + 0.5).floor() as u32)
}

/// CPU twin of one direction of `bilateral.wgsl` on channel 0 of `src`: along x, or
/// along y when `vertical`; `csz` = camera-space depth per pixel (channel 0; ≤ 0 = no
/// surface), `normals` = unit normals (3 channels), `frame` = the frame's uniforms;
/// `frames`: a temporal filter's per-pixel count (channel 0), for
/// [`BilateralSettings::fresh_radius`].
pub fn bilateral_cpu(
    src: &ImageBuf,
    csz: &ImageBuf,
    normals: &ImageBuf,
    frame: &FrameUniforms,
    s: &BilateralSettings,
    vertical: bool,
    frames: Option<&ImageBuf>,
) -> ImageBuf {
    let u = BilateralUniforms::new(s, frames.is_some());
    let (w, h) = (src.width as i32, src.height as i32);
    let normal = |x: i32, y: i32| {
        let p = normals.pixel(x as u32, y as u32);
        Vec3::new(p[0], p[1], p[2])
    };
    let at = |x: i32, y: i32, z: f32| world_from_csz(frame, [x as f32 + 0.5, y as f32 + 0.5], z);
    let mut out = ImageBuf::new(src.width, src.height, 1);
    for py in 0..h {
        for px in 0..w {
            let centre = src.pixel(px as u32, py as u32)[0];
            let z = csz.pixel(px as u32, py as u32)[0];
            let o = (py * w + px) as usize;
            let radius = match frames {
                Some(f) if u.fresh_radius > 0 => {
                    history_radius(u.radius as u32, u.fresh_radius as u32, f.pixel(px as u32, py as u32)[0]) as i32
                }
                _ => u.radius,
            };
            if z <= 0.0 || radius == 0 {
                out.data[o] = centre;
                continue;
            }
            let gauss = |k: i32| {
                if radius == u.radius {
                    u.gauss[k.unsigned_abs() as usize]
                } else {
                    gauss_weight(k.unsigned_abs(), radius as u32)
                }
            };
            let (x, n) = (at(px, py, z), normal(px, py));
            let (mut sum, mut weight) = (centre, 1.0f32);
            for k in -radius..=radius {
                let (qx, qy) = if vertical {
                    (px, py + k * u.step)
                } else {
                    (px + k * u.step, py)
                };
                if k == 0 || qx < 0 || qy < 0 || qx >= w || qy >= h {
                    continue;
                }
                let zq = csz.pixel(qx as u32, qy as u32)[0];
                if zq <= 0.0 {
                    continue;
                }
                let y = at(qx, qy, zq);
                let plane = (1.0 - u.plane_sharpness * n.dot(y - x).abs() / z).max(0.0);
                let c = n.dot(normal(qx, qy)).max(0.0);
                let mut wt = gauss(k) * plane * c.powi(u.normal_power as i32);
                if let Some(r) = s.world_radius {
                    wt *= distance_weight((y - x).length_squared(), r);
                }
                sum += wt * src.pixel(qx as u32, qy as u32)[0];
                weight += wt;
            }
            out.data[o] = sum / weight;
        }
    }
    out
}

/// Mirrors `Bilateral` in `bilateral.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct BilateralUniforms {
    radius: i32,
    step: i32,
    plane_sharpness: f32,
    normal_power: u32,
    /// Gaussian weight of tap |k| (k ≤ 32, index k).
    gauss: [f32; 36],
    /// 1/R² of [`BilateralSettings::world_radius`] (0: no distance weight).
    inv_radius2: f32,
    /// [`BilateralSettings::fresh_radius`] where the pass reads a history count, else 0.
    fresh_radius: i32,
    _pad: [f32; 2],
}

impl BilateralUniforms {
    /// `history`: the pass reads the temporal filter's count (`fresh_radius` applies).
    pub fn new(s: &BilateralSettings, history: bool) -> Self {
        Self {
            radius: s.radius as i32,
            step: s.step as i32,
            plane_sharpness: s.plane_sharpness,
            normal_power: s.normal_power,
            gauss: std::array::from_fn(|k| gauss_weight(k as u32, s.radius)),
            inv_radius2: s.world_radius.map_or(0.0, |r| 1.0 / (r * r)),
            fresh_radius: s.fresh_radius.filter(|_| history).unwrap_or(0) as i32,
            _pad: [0.0; 2],
        }
    }
}

/// One direction of the separable filter, from target `input` into `output`.
pub struct BilateralPass {
    pass: ScreenPass,
}

impl BilateralPass {
    /// `vertical` picks the direction; `output` must already exist in `targets`; `compute`:
    /// the compute form ([`crate::passes::Kernel`]), for an `output` with storage binding;
    /// `frames`: after a temporal filter, its per-pixel count of accepted history frames,
    /// which [`BilateralSettings::fresh_radius`] reads.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        gpu: &GpuContext,
        scene: &GpuScene,
        targets: &Targets,
        settings: &BilateralSettings,
        name: &'static str,
        input: &'static str,
        output: &'static str,
        vertical: bool,
        compute: bool,
        frames: Option<&'static str>,
    ) -> Self {
        let builder = PassBuilder::new(gpu, targets, name)
            .kernel(compute)
            .shader("bilateral", include_str!("bilateral.wgsl"))
            .constant("DIRECTION", vertical as u32 as f64)
            .frame(scene)
            .uniforms(&BilateralUniforms::new(settings, frames.is_some()))
            .read(input)
            .read("zpack")
            .read("npack")
            // without a count the binding holds the depth, which the shader then never reads
            .read(frames.unwrap_or("zpack"));
        let pass = ScreenPass::build(builder, &[output], compute);
        Self { pass }
    }
}

crate::passes::builder::delegate_pass!(BilateralPass);
