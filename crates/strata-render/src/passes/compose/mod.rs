//! Final composition: `hdr` (direct light, emission, ambient, sky) plus the
//! Lambertian reflection ρ/π · E · boost(ρ) of the deep-G-buffer indirect
//! irradiance (DGB Eq. 6) into `hdr-full`, which the tonemapper then reads.

use crate::frame::{Pass, PassInfo, TargetDesc, Targets};
use crate::gpu::GpuContext;
use crate::scene_gpu::GpuScene;

pub const OUTPUT: TargetDesc = TargetDesc::new(
    "hdr-full",
    wgpu::TextureFormat::Rgba16Float,
    1,
    "direct + indirect diffuse (linear HDR)",
);

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct ComposeUniforms {
    boost: u32,
    _pad: [u32; 3],
}

pub struct ComposePass {
    pipeline: wgpu::RenderPipeline,
    group: wgpu::BindGroup,
}

impl ComposePass {
    pub fn new(gpu: &GpuContext, targets: &Targets, boost: bool) -> Self {
        use crate::passes::{texture_entry, uniform_entry};
        let device = &gpu.device;
        let d2 = wgpu::TextureViewDimension::D2;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("compose"),
            entries: &[
                uniform_entry(0),
                texture_entry(1, d2, false),
                texture_entry(2, d2, false),
                texture_entry(3, d2, false),
                texture_entry(4, d2, false),
            ],
        });
        let u = ComposeUniforms {
            boost: boost as u32,
            _pad: [0; 3],
        };
        let buffer = crate::passes::uniform_buffer(device, "compose", &u);
        let layer0 = |n: &str| wgpu::BindingResource::TextureView(targets.get(n).layer(0));
        let group = crate::passes::bind_group(
            device,
            "compose",
            &layout,
            &[
                buffer.as_entire_binding(),
                layer0("hdr"),
                layer0("albedo"),
                layer0("normal"),
                layer0("indirect"),
            ],
        );
        let pl = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("compose"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let module = crate::shader::module(device, "compose", include_str!("compose.wgsl"));
        let pipeline = crate::passes::fullscreen_pipeline(
            device,
            "compose",
            &pl,
            &module,
            &[Some(wgpu::ColorTargetState::from(OUTPUT.format))],
        );
        Self { pipeline, group }
    }
}

impl Pass for ComposePass {
    fn info(&self) -> PassInfo {
        PassInfo {
            name: "compose",
            inputs: vec!["hdr", "albedo", "normal", "indirect"],
            outputs: vec![OUTPUT.name],
        }
    }

    fn encode(&self, _gpu: &GpuContext, _scene: &GpuScene, targets: &Targets, encoder: &mut wgpu::CommandEncoder) {
        crate::passes::fullscreen_pass(
            encoder,
            "compose",
            &self.pipeline,
            &[&targets.get(OUTPUT.name).view],
            &[&self.group],
        );
    }
}
