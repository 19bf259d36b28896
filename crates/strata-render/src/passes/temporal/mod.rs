//! DGB §3.3 temporal filtering, reusable by any per-pixel estimate: an
//! exponentially weighted moving average with reverse reprojection and
//! rejection of failed reprojections. The pass's output is kept as
//! `<output>-history` by a [`HistoryPass`](crate::passes::HistoryPass).

use crate::frame::Targets;
use crate::gpu::GpuContext;
use crate::passes::builder::{FullscreenPass, PassBuilder};
use crate::scene_gpu::GpuScene;

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
}

impl Default for TemporalSettings {
    fn default() -> Self {
        Self {
            alpha: 0.85,
            max_distance: 0.01,
            clamp_history: true,
            ramp: true,
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
}

/// Filters target `input` with `history` (last frame's `output`) into `output`.
pub struct TemporalPass {
    settings: TemporalSettings,
    layers: u32,
    pass: FullscreenPass,
}

impl TemporalPass {
    /// `frames`: the per-pixel count of accepted histories and its copy from last frame
    /// (`<output>-frames`, `<output>-frames-history`; [`frames_targets`]).
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
    ) -> Self {
        let settings = *settings;
        let pass = PassBuilder::new(gpu, targets, name)
            .shader("temporal", include_str!("temporal.wgsl"))
            .frame(scene)
            .uniforms(&Self::uniforms(&settings, layers, false))
            .read(input)
            .read(history)
            .read("zpack")
            .read_array("csz-history")
            .read(frames[1])
            .write(output)
            .write(frames[0])
            .build();
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
