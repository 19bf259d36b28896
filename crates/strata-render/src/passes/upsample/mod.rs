//! Joint bilateral upsampling (Kopf et al. 2007) of a screen pass run at reduced
//! resolution; not in DGB. At scale s a pass shades one pixel of each s×s block
//! ([`crate::spiral::block_pixel`]: every pixel of the block in turn over s² frames) into
//! a ⌈w/s⌉ × ⌈h/s⌉ target, and [`UpsamplePass`] writes the full-resolution target from it
//! (`upsample.wgsl`: 2×2 texels per pixel). Used by the radiosity gather
//! ([`RadiositySettings::gather_scale`](crate::passes::radiosity::RadiositySettings::gather_scale),
//! both receivers) and by AO ([`AoSettings::scale`](crate::passes::ao::AoSettings::scale),
//! layer 0).

use glam::Vec3;
use strata_scene::ImageBuf;

use crate::frame::{FrameUniforms, Targets};
use crate::gpu::GpuContext;
use crate::passes::ao::world_from_csz;
use crate::passes::bilateral::BilateralSettings;
use crate::passes::builder::{PassBuilder, ScreenPass};
use crate::scene_gpu::GpuScene;

/// The most a pass's resolution may be divided by, per axis.
pub const MAX_SCALE: u32 = 4;

/// The low-resolution size of a `w` × `h` image gathered at scale `s`: ⌈w/s⌉ × ⌈h/s⌉.
pub fn low_size(w: u32, h: u32, s: u32) -> [u32; 2] {
    [w.div_ceil(s), h.div_ceil(s)]
}

/// A full-resolution rectangle [x, y, w, h] in low-resolution texels at scale `s`: every
/// texel whose block meets it.
pub fn low_rect([x, y, w, h]: [u32; 4], s: u32) -> [u32; 4] {
    let (x0, y0) = (x / s, y / s);
    [x0, y0, (x + w).div_ceil(s) - x0, (y + h).div_ceil(s) - y0]
}

/// Mirrors `Upsample` in `upsample.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct UpsampleUniforms {
    pub scale: u32,
    /// The reduced pass's seed this frame (which pixel of its block each texel shaded).
    pub seed: u32,
    pub plane_sharpness: f32,
    pub normal_power: u32,
    /// Layer 0's value where it has no surface, in every channel (what the low-resolution
    /// pass writes there: 0 for E, 1 for AV).
    pub empty: f32,
    pub _pad: [u32; 3],
}

impl UpsampleUniforms {
    /// Scale `s`, with the plane and normal weights of the bilateral filter `blur` that
    /// follows the upsampling; 0 where layer 0 is empty.
    pub fn new(s: u32, blur: &BilateralSettings) -> Self {
        Self {
            scale: s,
            seed: 0,
            plane_sharpness: blur.plane_sharpness,
            normal_power: blur.normal_power,
            empty: 0.0,
            _pad: [0; 3],
        }
    }
}

/// Below this share of the spatial weights the joint weights count as none (`MIN_WEIGHT`
/// in upsample.wgsl).
const MIN_WEIGHT: f32 = 1e-3;

/// CPU twin of `upsample.wgsl` for layer `j`: `low` = the reduced pass's output
/// of that layer (any channel count), `csz` = `zmip` level 0 (channel j = layer j's
/// depth; ≤ 0: none), `normals` = layer j's unit normals (3 channels). Returns the
/// full-resolution image (as many channels; where layer j is empty, `u.empty` for layer 0
/// and zero for layer 1).
pub fn upsample_cpu(
    low: &ImageBuf,
    csz: &ImageBuf,
    normals: &ImageBuf,
    frame: &FrameUniforms,
    u: &UpsampleUniforms,
    j: usize,
) -> ImageBuf {
    let (w, h) = (csz.width, csz.height);
    let s = u.scale as i32;
    let z_of = |x: i32, y: i32| csz.pixel(x as u32, y as u32)[j];
    let n_of = |x: i32, y: i32| Vec3::from_slice(&normals.pixel(x as u32, y as u32)[..3]);
    let at = |x: i32, y: i32, z: f32| world_from_csz(frame, [x as f32 + 0.5, y as f32 + 0.5], z);
    let ch = low.channels as usize;
    let mut out = ImageBuf::new(w, h, low.channels);
    for py in 0..h as i32 {
        for px in 0..w as i32 {
            let zp = z_of(px, py);
            if zp <= 0.0 {
                if j == 0 {
                    out.pixel_mut(px as u32, py as u32).fill(u.empty);
                }
                continue;
            }
            let (x, n) = (at(px, py, zp), n_of(px, py));
            let (mut sum, mut weight, mut spatial) = (vec![0.0f32; ch], 0.0f32, 0.0f32);
            let (mut nearest, mut nearest_dz) = (vec![0.0f32; ch], f32::INFINITY);
            // the texel whose block centre is the last at or before the pixel, per axis
            let home = |q: i32| (2 * q + s + 1) / (2 * s) - 1;
            for dy in 0..=1 {
                for dx in 0..=1 {
                    let (tx, ty) = (home(px) + dx, home(py) + dy);
                    if tx < 0 || ty < 0 || tx >= low.width as i32 || ty >= low.height as i32 {
                        continue;
                    }
                    let r = crate::spiral::block_pixel([tx as u32, ty as u32], u.scale, u.seed, [w, h]);
                    let (rx, ry) = (r[0] as i32, r[1] as i32);
                    let zr = z_of(rx, ry);
                    if zr <= 0.0 {
                        continue;
                    }
                    let v = low.pixel(tx as u32, ty as u32);
                    let (ddx, ddy) = ((rx - px) as f32, (ry - py) as f32);
                    let ws = (1.0 - (ddx * ddx + ddy * ddy) / (5 * s * s) as f32).max(0.0);
                    let y = at(rx, ry, zr);
                    let plane = (1.0 - u.plane_sharpness * n.dot(y - x).abs() / zp).max(0.0);
                    let c = n.dot(n_of(rx, ry)).max(0.0);
                    let wt = ws * plane * c.powi(u.normal_power as i32);
                    for (a, b) in sum.iter_mut().zip(v) {
                        *a += wt * b;
                    }
                    weight += wt;
                    spatial += ws;
                    if (zr - zp).abs() < nearest_dz {
                        nearest_dz = (zr - zp).abs();
                        nearest.copy_from_slice(v);
                    }
                }
            }
            let o = out.pixel_mut(px as u32, py as u32);
            if weight > MIN_WEIGHT * spatial && weight > 0.0 {
                for (a, b) in o.iter_mut().zip(&sum) {
                    *a = b / weight;
                }
            } else {
                o.copy_from_slice(&nearest);
            }
        }
    }
    out
}

/// Joint bilateral upsampling of a reduced-resolution pass (`upsample.wgsl`).
pub struct UpsamplePass {
    pass: ScreenPass,
    uniforms: std::cell::Cell<UpsampleUniforms>,
}

impl UpsamplePass {
    /// Both layers' upsampling (pass `name`), `low` (layer 0, layer 1) into `outputs`
    /// (RGBA16F). `scissor`: the shaded full-resolution rectangle (zero outside it);
    /// `compute`: the compute form (outputs with storage binding).
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        gpu: &GpuContext,
        scene: &GpuScene,
        targets: &Targets,
        name: &'static str,
        layers: u32,
        u: UpsampleUniforms,
        low: [&'static str; 2],
        outputs: [&'static str; 2],
        scissor: Option<[u32; 4]>,
        compute: bool,
    ) -> Self {
        let builder = Self::builder(gpu, scene, targets, name, layers, &u, compute, scissor)
            .read(low[0])
            .read(low[1])
            .read("zmip")
            .read("npack");
        let pass = ScreenPass::build_in(builder, &outputs, compute, scissor);
        Self {
            pass,
            uniforms: std::cell::Cell::new(u),
        }
    }

    /// Layer 0's upsampling of `low` into `output` (one channel used), as a fragment pass
    /// named `name` (AO at [`AoSettings::scale`](crate::passes::ao::AoSettings::scale)).
    pub fn layer0(
        gpu: &GpuContext,
        scene: &GpuScene,
        targets: &Targets,
        name: &'static str,
        u: UpsampleUniforms,
        low: &'static str,
        output: &'static str,
    ) -> Self {
        let builder = Self::builder(gpu, scene, targets, name, 1, &u, false, None)
            .entry("fs_layer0")
            .read(low)
            .read(low)
            .read("zmip")
            .read("npack");
        let pass = ScreenPass::build(builder, &[output], false);
        Self {
            pass,
            uniforms: std::cell::Cell::new(u),
        }
    }

    #[allow(clippy::too_many_arguments)]
    fn builder<'a>(
        gpu: &'a GpuContext,
        scene: &'a GpuScene,
        targets: &'a Targets,
        name: &'static str,
        layers: u32,
        u: &UpsampleUniforms,
        compute: bool,
        scissor: Option<[u32; 4]>,
    ) -> PassBuilder<'a> {
        PassBuilder::new(gpu, targets, name)
            .kernel_in(compute, scissor)
            .shader("upsample", include_str!("upsample.wgsl"))
            .constant("LAYERS", layers as f64)
            .frame(scene)
            .uniforms(u)
    }

    /// This frame's seed of the reduced pass (which pixel of its block each texel shaded).
    pub fn set_frame(&self, gpu: &GpuContext, seed: u32) {
        let u = UpsampleUniforms {
            seed,
            ..self.uniforms.get()
        };
        self.pass.set_uniforms(gpu, &u);
        self.uniforms.set(u);
    }

    pub fn uniforms(&self) -> UpsampleUniforms {
        self.uniforms.get()
    }
}

crate::passes::builder::delegate_pass!(UpsamplePass);

#[cfg(test)]
mod tests {
    use super::*;

    fn frame(w: u32, h: u32) -> FrameUniforms {
        let mut f: FrameUniforms = bytemuck::Zeroable::zeroed();
        f.size = [w as f32, h as f32, 1.0 / w as f32, 1.0 / h as f32];
        f.eye = [0.0, 0.0, 0.0, 1.0];
        f.cam_forward = [0.0, 0.0, -1.0, 0.0];
        f.cam_right = [0.5, 0.0, 0.0, 0.0];
        f.cam_up = [0.0, 0.5 * h as f32 / w as f32, 0.0, 0.0];
        f
    }

    /// Two fronto-parallel planes, the left half of the image at depth 2 and the right
    /// at 5, each gathered as a constant (1 and 7, confidence ½ and 1): at scales 2 and 3
    /// and any seed, every pixel upsamples to its own plane's value, beside the step too
    /// (the plane weight or, where no texel of its plane is near, the nearest depth), and
    /// pixels without a surface stay zero.
    #[test]
    fn upsampling_keeps_each_plane_its_own_value() {
        let (w, h) = (23u32, 11u32);
        let edge = 9;
        let f = frame(w, h);
        let mut csz = ImageBuf::new(w, h, 2);
        let mut normals = ImageBuf::new(w, h, 3);
        for y in 0..h {
            for x in 0..w {
                let z = if y == 0 {
                    0.0
                } else if x < edge {
                    2.0
                } else {
                    5.0
                };
                csz.pixel_mut(x, y)[0] = z;
                normals.pixel_mut(x, y).copy_from_slice(&[0.0, 0.0, 1.0]);
            }
        }
        let value = |z: f32| {
            if z < 3.0 {
                [1.0, 1.0, 1.0, 0.5]
            } else {
                [7.0, 7.0, 7.0, 1.0]
            }
        };
        for s in [2u32, 3] {
            for seed in 0..s * s {
                let u = UpsampleUniforms {
                    seed,
                    ..UpsampleUniforms::new(s, &BilateralSettings::default())
                };
                let [lw, lh] = low_size(w, h, s);
                let mut low = ImageBuf::new(lw, lh, 4);
                for ty in 0..lh {
                    for tx in 0..lw {
                        let r = crate::spiral::block_pixel([tx, ty], s, seed, [w, h]);
                        let z = csz.pixel(r[0], r[1])[0];
                        if z > 0.0 {
                            low.pixel_mut(tx, ty).copy_from_slice(&value(z));
                        }
                    }
                }
                let out = upsample_cpu(&low, &csz, &normals, &f, &u, 0);
                for y in 0..h {
                    for x in 0..w {
                        let z = csz.pixel(x, y)[0];
                        let want = if z > 0.0 { value(z) } else { [0.0; 4] };
                        let got = out.pixel(x, y);
                        for c in 0..4 {
                            assert!(
                                (got[c] - want[c]).abs() < 1e-5,
                                "s={s} seed={seed} ({x}, {y}): {got:?} != {want:?}"
                            );
                        }
                    }
                }
            }
        }
    }

    /// On one plane a linear ramp of E upsamples to within the ramp's change over the
    /// weights' reach (a normalised average of samples less than 2s pixels away).
    #[test]
    fn upsampling_a_ramp_stays_within_a_block_of_it() {
        let (w, h) = (24u32, 16u32);
        let f = frame(w, h);
        let mut csz = ImageBuf::new(w, h, 2);
        let mut normals = ImageBuf::new(w, h, 3);
        for y in 0..h {
            for x in 0..w {
                csz.pixel_mut(x, y)[0] = 3.0;
                normals.pixel_mut(x, y).copy_from_slice(&[0.0, 0.0, 1.0]);
            }
        }
        let ramp = |x: u32| 1.0 + 0.25 * x as f32;
        for s in [2u32, 4] {
            let u = UpsampleUniforms {
                seed: 5,
                ..UpsampleUniforms::new(s, &BilateralSettings::default())
            };
            let [lw, lh] = low_size(w, h, s);
            let mut low = ImageBuf::new(lw, lh, 4);
            for ty in 0..lh {
                for tx in 0..lw {
                    let r = crate::spiral::block_pixel([tx, ty], s, u.seed, [w, h]);
                    low.pixel_mut(tx, ty).copy_from_slice(&[ramp(r[0]); 4]);
                }
            }
            let out = upsample_cpu(&low, &csz, &normals, &f, &u, 0);
            for y in 0..h {
                for x in 0..w {
                    let (got, want) = (out.pixel(x, y)[0], ramp(x));
                    let tol = 0.25 * (2 * s - 1) as f32;
                    assert!((got - want).abs() <= tol, "s={s} ({x}, {y}): {got} vs {want}");
                }
            }
        }
    }

    #[test]
    fn low_rect_covers_the_full_resolution_rect() {
        assert_eq!(low_rect([5, 5, 90, 70], 2), [2, 2, 46, 36]);
        assert_eq!(low_rect([0, 0, 7, 5], 2), [0, 0, 4, 3]);
        assert_eq!(low_size(7, 5, 2), [4, 3]);
        assert_eq!(low_size(8, 6, 4), [2, 2]);
    }
}
