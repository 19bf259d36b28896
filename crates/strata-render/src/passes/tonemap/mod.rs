//! Exposure and ACES filmic tonemapping of `hdr` into the sRGB `ldr` target.

use crate::frame::{Pass, PassInfo, TargetDesc, Targets};
use crate::gpu::GpuContext;
use crate::scene_gpu::GpuScene;

pub const OUTPUTS: &[TargetDesc] = &[TargetDesc::new(
    "ldr",
    wgpu::TextureFormat::Rgba8UnormSrgb,
    1,
    "tonemapped display image (sRGB)",
)];

pub struct TonemapPass {
    pipeline: wgpu::RenderPipeline,
    group: wgpu::BindGroup,
    input: &'static str,
}

impl TonemapPass {
    /// Tonemaps target `input` (normally "hdr").
    pub fn new(gpu: &GpuContext, scene: &GpuScene, targets: &Targets, input: &'static str) -> Self {
        let device = &gpu.device;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("tonemap"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::FRAGMENT,
                ty: wgpu::BindingType::Texture {
                    sample_type: wgpu::TextureSampleType::Float { filterable: false },
                    view_dimension: wgpu::TextureViewDimension::D2,
                    multisampled: false,
                },
                count: None,
            }],
        });
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("tonemap"),
            layout: &layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::TextureView(&targets.get(input).view),
            }],
        });
        let module = crate::shader::module(device, "tonemap", include_str!("tonemap.wgsl"));
        let pl = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("tonemap"),
            bind_group_layouts: &[Some(&scene.frame_layout), Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = crate::passes::fullscreen_pipeline(
            device,
            "tonemap",
            &pl,
            &module,
            &[Some(wgpu::ColorTargetState::from(OUTPUTS[0].format))],
        );
        Self { pipeline, group, input }
    }
}

impl Pass for TonemapPass {
    fn info(&self) -> PassInfo {
        PassInfo {
            name: "tonemap",
            inputs: vec![self.input],
            outputs: vec!["ldr"],
        }
    }

    fn encode(&self, _gpu: &GpuContext, scene: &GpuScene, targets: &Targets, encoder: &mut wgpu::CommandEncoder) {
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("tonemap"),
            color_attachments: &[crate::passes::clear_attachment(&targets.get("ldr").view)],
            depth_stencil_attachment: None,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &scene.frame_bind_group, &[]);
        pass.set_bind_group(1, &self.group, &[]);
        pass.draw(0..3, 0..1);
    }
}
