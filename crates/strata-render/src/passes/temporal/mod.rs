//! DGB §3.3 temporal filtering, reusable by any per-pixel estimate: an
//! exponentially weighted moving average with reverse reprojection and
//! rejection of failed reprojections. The pass's output is kept as
//! `<output>-history` by a [`HistoryPass`](crate::passes::HistoryPass).

use crate::frame::{Pass, PassInfo, Targets};
use crate::gpu::GpuContext;
use crate::scene_gpu::GpuScene;

/// Defaults: α = 0.85 (the paper's recommendation); reprojection accepted when
/// the point lies within 0.01 scene units of either layer (the paper's 1 cm, with
/// scenes in metres).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TemporalSettings {
    /// Weight of the reprojected history, in [0, 1).
    pub alpha: f32,
    /// Camera-space distance (scene units) within which the reprojected point
    /// must lie of a layer of last frame's deep G-buffer.
    pub max_distance: f32,
}

impl Default for TemporalSettings {
    fn default() -> Self {
        Self {
            alpha: 0.85,
            max_distance: 0.01,
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
}

/// Filters target `input` with `history` (last frame's `output`) into `output`.
pub struct TemporalPass {
    name: &'static str,
    input: &'static str,
    history: &'static str,
    output: &'static str,
    settings: TemporalSettings,
    layers: u32,
    pipeline: wgpu::RenderPipeline,
    group: wgpu::BindGroup,
    uniforms: wgpu::Buffer,
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
        use crate::passes::{texture_entry, uniform_entry};
        let device = &gpu.device;
        let d2 = wgpu::TextureViewDimension::D2;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some(name),
            entries: &[
                uniform_entry(0),
                texture_entry(1, d2, false),
                texture_entry(2, d2, false),
                texture_entry(3, d2, false),
                texture_entry(4, wgpu::TextureViewDimension::D2Array, false),
            ],
        });
        let u = TemporalUniforms {
            alpha: settings.alpha,
            max_distance: settings.max_distance,
            has_history: 0,
            layers,
        };
        let uniforms = crate::passes::uniform_buffer(device, name, &u);
        let group = crate::passes::bind_group(
            device,
            name,
            &layout,
            &[
                uniforms.as_entire_binding(),
                wgpu::BindingResource::TextureView(&targets.get(input).view),
                wgpu::BindingResource::TextureView(&targets.get(history).view),
                wgpu::BindingResource::TextureView(&targets.get("zpack").view),
                wgpu::BindingResource::TextureView(&targets.get("csz-history").array_view),
            ],
        );
        let pl = crate::passes::frame_pipeline_layout(device, name, scene, &[&layout]);
        let module = crate::shader::module(device, "temporal", include_str!("temporal.wgsl"));
        let pipeline = crate::passes::fullscreen_pipeline(
            device,
            name,
            &pl,
            &module,
            &[Some(wgpu::ColorTargetState::from(targets.get(output).desc.format))],
        );
        Self {
            name,
            input,
            history,
            output,
            settings: *settings,
            layers,
            pipeline,
            group,
            uniforms,
        }
    }

    /// Whether `history` holds last frame's output.
    pub fn set_frame(&self, gpu: &GpuContext, has_history: bool) {
        let u = TemporalUniforms {
            alpha: self.settings.alpha,
            max_distance: self.settings.max_distance,
            has_history: has_history as u32,
            layers: self.layers,
        };
        gpu.queue.write_buffer(&self.uniforms, 0, bytemuck::bytes_of(&u));
    }
}

impl Pass for TemporalPass {
    fn info(&self) -> PassInfo {
        PassInfo {
            name: self.name,
            inputs: vec![self.input, self.history, "zpack", "csz-history"],
            outputs: vec![self.output],
        }
    }

    fn encode(&self, _gpu: &GpuContext, scene: &GpuScene, targets: &Targets, encoder: &mut wgpu::CommandEncoder) {
        crate::passes::fullscreen_pass(
            encoder,
            self.name,
            &self.pipeline,
            &[&targets.get(self.output).view],
            &[&scene.frame_bind_group, &self.group],
        );
    }
}
