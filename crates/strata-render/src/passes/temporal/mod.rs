//! DGB §3.3 temporal filtering, reusable by any per-pixel estimate: an
//! exponentially weighted moving average with reverse reprojection and
//! rejection of failed reprojections. The pass's output is kept as
//! `<output>-history` by a [`HistoryPass`](crate::passes::HistoryPass).

use crate::frame::{FrameUniforms, Targets};
use crate::gpu::GpuContext;
use crate::passes::builder::{PassBuilder, ScreenPass};
use crate::scene_gpu::GpuScene;
use glam::{Mat4, Vec3};
use strata_scene::ImageBuf;

/// Defaults: α = 0.85 (the paper's recommendation); reprojection accepted when
/// the point lies within 0.01 scene units of either layer (the paper's 1 cm, with
/// scenes in metres); the history clamp on (not in the paper: issue 14, measured
/// in docs/ao.md "History clamp"); the start-up ramp on (not in the paper: issue 14,
/// docs/radiosity.md § "Start-up ramp").
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TemporalSettings {
    /// Weight of the reprojected history, in [0, 1).
    pub alpha: f32,
    /// Camera-space distance (scene units) within which the reprojected point
    /// must lie of a layer of last frame's deep G-buffer.
    pub max_distance: f32,
    /// Clamp the reprojected history to the range of the current input's 3×3
    /// neighbourhood before blending (per channel; not in the paper): history that no
    /// nearby current value supports — an occluder that moved away or arrived, light
    /// that changed — is pulled to what this frame sees instead of fading over
    /// 1/(1 − α) frames.
    pub clamp_history: bool,
    /// Average the first frames of a pixel's history with equal weights: where the
    /// history has been accepted n frames in a row (counted per pixel, so a cut or a
    /// disocclusion restarts it) it blends with α_n = min(α, n/(n + 1)), the running
    /// mean, until n/(n + 1) reaches α (n = 6 for α = 0.85) and the paper's EWMA takes
    /// over. Off: α from the first frame, so the oldest frame keeps weight α^n (not in
    /// the paper).
    pub ramp: bool,
    /// Reproject with per-object velocities: the surface point moves back by the deep
    /// G-buffer's `motion` (x_t − x_{t−1} of its object) before the camera's reverse
    /// reprojection, so a moving object finds its own history (DGB §3.3 reprojects "to
    /// account for motion" and reads a failed test as "an incorrect velocity estimate").
    /// Off: the camera's motion only, and a moving object's pixels fail the test (or,
    /// moving within their own plane, read another point's history).
    pub object_motion: bool,
}

impl Default for TemporalSettings {
    fn default() -> Self {
        Self {
            alpha: 0.85,
            max_distance: 0.01,
            clamp_history: true,
            ramp: true,
            object_motion: true,
        }
    }
}

impl TemporalSettings {
    /// The history's weight where it has been accepted `history_frames` frames in a row
    /// (0 = no history): α, or with [`ramp`](Self::ramp) min(α, n/(n + 1)). The CPU twin
    /// of `temporal.wgsl`'s.
    pub fn history_weight(&self, history_frames: u32) -> f32 {
        if history_frames == 0 {
            0.0
        } else if self.ramp {
            let n = history_frames as f32;
            self.alpha.min(n / (n + 1.0))
        } else {
            self.alpha
        }
    }

    pub fn validate(&self) -> Result<(), String> {
        if !(0.0..1.0).contains(&self.alpha) {
            return Err(format!(
                "temporal alpha {} is out of range: must be in [0, 1)",
                self.alpha
            ));
        }
        if !(self.max_distance > 0.0 && self.max_distance.is_finite()) {
            return Err(format!(
                "temporal distance threshold {} is out of range: must be > 0",
                self.max_distance
            ));
        }
        Ok(())
    }
}

/// Mirrors `Temporal` in `temporal.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct TemporalUniforms {
    pub alpha: f32,
    pub max_distance: f32,
    pub layers: u32,
    /// 1 = [`TemporalSettings::clamp_history`].
    pub clamp: u32,
    pub has_history: u32,
    /// 1 = [`TemporalSettings::ramp`].
    pub ramp: u32,
    /// 1 = [`TemporalSettings::object_motion`].
    pub motion: u32,
    pub _pad: u32,
}

/// Filters target `input` with `history` (last frame's `output`) into `output`.
pub struct TemporalPass {
    settings: TemporalSettings,
    layers: u32,
    pass: ScreenPass,
}

impl TemporalPass {
    /// `frames`: the per-pixel count of accepted histories and its copy from last frame
    /// (`<output>-frames`, `<output>-frames-history`; [`frames_targets`]). `compute`: the
    /// compute form ([`crate::passes::Kernel`]), for `output` and `frames[0]` with storage
    /// binding.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        gpu: &GpuContext,
        scene: &GpuScene,
        targets: &Targets,
        settings: &TemporalSettings,
        name: &'static str,
        input: &'static str,
        history: &'static str,
        output: &'static str,
        frames: [&'static str; 2],
        layers: u32,
        compute: bool,
    ) -> Self {
        let settings = *settings;
        let builder = PassBuilder::new(gpu, targets, name).kernel(compute);
        let builder = builder
            .shader("temporal", include_str!("temporal.wgsl"))
            .frame(scene)
            .uniforms(&Self::uniforms(&settings, layers, false))
            .read(input)
            .read(history)
            .read("zpack")
            .read_array("csz-history")
            .read(frames[1])
            .read_layer("motion", 0);
        let pass = ScreenPass::build(builder, &[output, frames[0]], compute);
        Self { settings, layers, pass }
    }

    fn uniforms(s: &TemporalSettings, layers: u32, has_history: bool) -> TemporalUniforms {
        TemporalUniforms {
            alpha: s.alpha,
            max_distance: s.max_distance,
            layers,
            clamp: s.clamp_history as u32,
            has_history: has_history as u32,
            ramp: s.ramp as u32,
            motion: s.object_motion as u32,
            _pad: 0,
        }
    }

    /// Whether `history` holds last frame's output.
    pub fn set_frame(&self, gpu: &GpuContext, has_history: bool) {
        self.pass
            .set_uniforms(gpu, &Self::uniforms(&self.settings, self.layers, has_history));
    }
}

/// The per-pixel count of accepted histories of the temporal filter writing `output`
/// and last frame's copy (R16Float: whole numbers up to the cap 1024 are exact).
pub fn frames_targets(names: [&'static str; 2]) -> [crate::frame::TargetDesc; 2] {
    [
        crate::frame::TargetDesc::new(
            names[0],
            wgpu::TextureFormat::R16Float,
            1,
            "frames in a row the temporal filter accepted this pixel's history (the start-up ramp)",
        ),
        crate::frame::TargetDesc::new(names[1], wgpu::TextureFormat::R16Float, 1, "last frame's count"),
    ]
}

crate::passes::builder::delegate_pass!(TemporalPass);

/// `reproject` in common/reproject.wgsl on the CPU: where world point `x` was seen in
/// frame t − 1, as (pixel position, camera-space depth); `None` behind the old camera or
/// outside its image.
pub fn reproject(f: &FrameUniforms, x: Vec3) -> Option<([f32; 2], f32)> {
    let clip = Mat4::from_cols_array_2d(&f.prev_view_proj) * x.extend(1.0);
    if clip.w <= 0.0 {
        return None;
    }
    let ndc = [clip.x / clip.w, clip.y / clip.w];
    let c = [(ndc[0] * 0.5 + 0.5) * f.size[0], (0.5 - 0.5 * ndc[1]) * f.size[1]];
    (c[0] >= 0.0 && c[1] >= 0.0 && c[0] < f.size[0] && c[1] < f.size[1]).then_some((c, clip.w))
}

/// The four texels around sub-pixel position `c` (clamped to `img`) and the bilinear
/// weights' fractions, as reproject.wgsl's `depth_at` and `bilinear_at` take them.
fn bilinear_taps(img: &ImageBuf, c: [f32; 2]) -> ([[u32; 2]; 4], [f32; 2]) {
    let f = [c[0] - 0.5, c[1] - 0.5];
    let i0 = [f[0].floor() as i64, f[1].floor() as i64];
    let at = |dx: i64, dy: i64| {
        [
            (i0[0] + dx).clamp(0, img.width as i64 - 1) as u32,
            (i0[1] + dy).clamp(0, img.height as i64 - 1) as u32,
        ]
    };
    (
        [at(0, 0), at(1, 0), at(0, 1), at(1, 1)],
        [f[0] - f[0].floor(), f[1] - f[1].floor()],
    )
}

/// `bilinear_at` in common/reproject.wgsl on the CPU: channel `ch` of `img` at sub-pixel
/// position `c`, bilinear between texel centres.
pub fn bilinear_at(img: &ImageBuf, c: [f32; 2], ch: usize) -> f32 {
    let (q, t) = bilinear_taps(img, c);
    let v = |i: usize| img.pixel(q[i][0], q[i][1])[ch];
    let lerp = |a: f32, b: f32, s: f32| a + (b - a) * s;
    lerp(lerp(v(0), v(1), t[0]), lerp(v(2), v(3), t[0]), t[1])
}

/// `matching_layer` in common/reproject.wgsl on the CPU: which of last frame's layer
/// depths `csz` (one image per layer) holds the reprojected point `r` within
/// `max_distance` (1/z bilinear, the nearest texel where one of the four is empty).
pub fn matching_layer(csz: &[ImageBuf], r: Option<([f32; 2], f32)>, max_distance: f32) -> Option<usize> {
    let (c, z) = r?;
    csz.iter().take(2).position(|img| {
        let (q, t) = bilinear_taps(img, c);
        let d = |i: usize| img.pixel(q[i][0], q[i][1])[0];
        let zj = if (0..4).any(|i| d(i) <= 0.0) {
            img.pixel(c[0].floor() as u32, c[1].floor() as u32)[0]
        } else {
            let lerp = |a: f32, b: f32, s: f32| a + (b - a) * s;
            1.0 / lerp(
                lerp(1.0 / d(0), 1.0 / d(1), t[0]),
                lerp(1.0 / d(2), 1.0 / d(3), t[0]),
                t[1],
            )
        };
        zj > 0.0 && (zj - z).abs() < max_distance
    })
}

#[cfg(test)]
mod tests {
    use super::TemporalSettings;

    /// With the ramp the filter is the running mean of the frames since the cut until
    /// n/(n + 1) reaches α; then (and without the ramp throughout) the weight is α.
    #[test]
    fn ramp_averages_the_first_frames_equally_then_hands_over_to_alpha() {
        let on = TemporalSettings::default();
        let off = TemporalSettings { ramp: false, ..on };
        let frames = [3.0f32, -1.0, 4.0, 1.0, -5.0, 9.0, 2.0, 6.0];
        let (mut e_on, mut e_off) = (0.0f32, 0.0f32);
        for (n, &x) in frames.iter().enumerate() {
            let (a_on, a_off) = (on.history_weight(n as u32), off.history_weight(n as u32));
            e_on = (1.0 - a_on) * x + a_on * e_on;
            e_off = (1.0 - a_off) * x + a_off * e_off;
            let mean = frames[..=n].iter().sum::<f32>() / (n + 1) as f32;
            if (n as f32) / (n as f32 + 1.0) <= on.alpha {
                assert!((e_on - mean).abs() < 1e-5, "frame {n}: {e_on} vs the mean {mean}");
            } else {
                assert_eq!(a_on, on.alpha, "frame {n}");
            }
            assert_eq!(a_off, if n == 0 { 0.0 } else { off.alpha }, "frame {n}");
        }
        // without the ramp the first frame keeps weight α^7 after 7 more frames
        assert!(
            (e_off - e_on).abs() > 0.1,
            "the ramp changed nothing ({e_on} vs {e_off})"
        );
    }
}
