//! DGB §3.6 mirror reflections through the deep G-buffer: a camera-space ray
//! march that tests every step against all layers (hit within [z, z + Δz]),
//! reading the hit layer's outgoing radiance; the environment (sky) after a
//! maximum distance or once the ray leaves the guard-banded buffer.
//!
//! Outputs `reflection` (rgb = reflected radiance, a = 0 not a mirror,
//! 1 environment, 2 layer-0 hit, 3 layer-1 hit) and `hdr-reflected` (the input
//! image plus F0 · reflected radiance on mirrors).

use crate::frame::{Pass, PassInfo, TargetDesc, Targets};
use crate::gpu::GpuContext;
use crate::scene_gpu::GpuScene;

/// Defaults: 64 steps over 16 scene units, surface thickness Δz = the deep
/// G-buffer's minimum separation (as the paper), mirrors = metallic ≥ 0.5 and
/// roughness ≤ 0.1.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReflectionSettings {
    pub max_distance: f32,
    pub steps: u32,
    /// Thickness of a layer's surface for the hit test; `None` = the scene's Δz.
    pub thickness: Option<f32>,
    pub max_roughness: f32,
}

impl Default for ReflectionSettings {
    fn default() -> Self {
        Self {
            max_distance: 16.0,
            steps: 64,
            thickness: None,
            max_roughness: 0.1,
        }
    }
}

impl ReflectionSettings {
    pub fn validate(&self) -> Result<(), String> {
        if !(self.max_distance > 0.0 && self.max_distance.is_finite()) {
            return Err(format!(
                "reflection distance {} is out of range: must be > 0",
                self.max_distance
            ));
        }
        if !(1..=1024).contains(&self.steps) {
            return Err(format!(
                "reflection steps {} is out of range: must be in 1..=1024",
                self.steps
            ));
        }
        if let Some(t) = self.thickness {
            if !(t > 0.0 && t.is_finite()) {
                return Err(format!("reflection thickness {t} is out of range: must be > 0"));
            }
        }
        Ok(())
    }
}

/// Mirrors `Reflections` in `reflections.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct ReflectionUniforms {
    pub max_distance: f32,
    pub steps: u32,
    pub thickness: f32,
    pub max_roughness: f32,
}

pub const OUTPUTS: [TargetDesc; 2] = [
    TargetDesc::new(
        "reflection",
        wgpu::TextureFormat::Rgba16Float,
        1,
        "reflected radiance (rgb); a = 0 no mirror, 1 environment, 2 layer-0 hit, 3 layer-1 hit",
    ),
    TargetDesc::new(
        "hdr-reflected",
        wgpu::TextureFormat::Rgba16Float,
        1,
        "the shaded image plus F0 · reflected radiance on mirrors (linear HDR)",
    ),
];

pub struct ReflectionPass {
    inputs: Vec<&'static str>,
    pipeline: wgpu::RenderPipeline,
    group: wgpu::BindGroup,
    uniforms: wgpu::Buffer,
    settings: ReflectionSettings,
}

impl ReflectionPass {
    /// Reflects `input` (the shaded layer 0) and layer 1's radiosity.
    pub fn new(
        gpu: &GpuContext,
        scene: &GpuScene,
        targets: &Targets,
        layers: u32,
        input: &'static str,
        settings: &ReflectionSettings,
    ) -> Self {
        use crate::passes::{texture_entry, uniform_entry};
        let device = &gpu.device;
        let (d2, arr) = (wgpu::TextureViewDimension::D2, wgpu::TextureViewDimension::D2Array);
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("reflections"),
            entries: &[
                uniform_entry(0),
                texture_entry(1, arr, false),
                texture_entry(2, arr, false),
                texture_entry(3, arr, false),
                texture_entry(4, d2, false),
                texture_entry(5, d2, false),
            ],
        });
        let uniforms = crate::passes::uniform_buffer(
            device,
            "reflections",
            &<ReflectionUniforms as bytemuck::Zeroable>::zeroed(),
        );
        let layer1 = if layers > 1 { "radiosity1" } else { "radiosity0" };
        let view = |n: &str| wgpu::BindingResource::TextureView(&targets.get(n).view);
        let array = |n: &str| wgpu::BindingResource::TextureView(&targets.get(n).array_view);
        let group = crate::passes::bind_group(
            device,
            "reflections",
            &layout,
            &[
                uniforms.as_entire_binding(),
                array("csz"),
                array("normal"),
                array("albedo"),
                view(input),
                view(layer1),
            ],
        );
        let pl = crate::passes::frame_pipeline_layout(device, "reflections", scene, &[&layout]);
        let module = crate::shader::module(device, "reflections", include_str!("reflections.wgsl"));
        let formats = crate::passes::color_targets(&OUTPUTS);
        let pipeline = crate::passes::fullscreen_pipeline_with(
            device,
            "reflections",
            &pl,
            &module,
            "fs_main",
            &[("LAYERS", layers as f64)],
            &formats,
        );
        let mut inputs = vec!["csz", "normal", "albedo", input];
        if layers > 1 {
            inputs.push("radiosity1");
        }
        Self {
            inputs,
            pipeline,
            group,
            uniforms,
            settings: *settings,
        }
    }

    pub fn set_frame(&self, gpu: &GpuContext, min_separation: f32) {
        let s = &self.settings;
        let u = ReflectionUniforms {
            max_distance: s.max_distance,
            steps: s.steps,
            thickness: s.thickness.unwrap_or(min_separation),
            max_roughness: s.max_roughness,
        };
        gpu.queue.write_buffer(&self.uniforms, 0, bytemuck::bytes_of(&u));
    }
}

impl Pass for ReflectionPass {
    fn info(&self) -> PassInfo {
        PassInfo {
            name: "reflections",
            inputs: self.inputs.clone(),
            outputs: OUTPUTS.iter().map(|t| t.name).collect(),
        }
    }

    fn encode(&self, _gpu: &GpuContext, scene: &GpuScene, targets: &Targets, encoder: &mut wgpu::CommandEncoder) {
        let outputs = crate::passes::output_views(targets, &OUTPUTS);
        crate::passes::fullscreen_pass(
            encoder,
            "reflections",
            &self.pipeline,
            &outputs,
            &[&scene.frame_bind_group, &self.group],
        );
    }
}
