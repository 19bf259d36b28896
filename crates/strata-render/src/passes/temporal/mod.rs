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
/// in docs/ao.md "History clamp").
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
}

impl Default for TemporalSettings {
    fn default() -> Self {
        Self {
            alpha: 0.85,
            max_distance: 0.01,
            clamp_history: true,
        }
    }
}

impl TemporalSettings {
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
    pub has_history: u32,
    pub layers: u32,
    /// 1 = [`TemporalSettings::clamp_history`].
    pub clamp: u32,
}

/// Filters target `input` with `history` (last frame's `output`) into `output`.
pub struct TemporalPass {
    settings: TemporalSettings,
    layers: u32,
    pass: FullscreenPass,
}

impl TemporalPass {
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
        layers: u32,
    ) -> Self {
        let u = TemporalUniforms {
            alpha: settings.alpha,
            max_distance: settings.max_distance,
            has_history: 0,
            layers,
            clamp: settings.clamp_history as u32,
        };
        let pass = PassBuilder::new(gpu, targets, name)
            .shader("temporal", include_str!("temporal.wgsl"))
            .frame(scene)
            .uniforms(&u)
            .read(input)
            .read(history)
            .read("zpack")
            .read_array("csz-history")
            .write(output)
            .build();
        Self {
            settings: *settings,
            layers,
            pass,
        }
    }

    /// Whether `history` holds last frame's output.
    pub fn set_frame(&self, gpu: &GpuContext, has_history: bool) {
        let u = TemporalUniforms {
            alpha: self.settings.alpha,
            max_distance: self.settings.max_distance,
            has_history: has_history as u32,
            layers: self.layers,
            clamp: self.settings.clamp_history as u32,
        };
        self.pass.set_uniforms(gpu, &u);
    }
}

crate::passes::builder::delegate_pass!(TemporalPass);
