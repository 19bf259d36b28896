//! Single-layer G-buffer pass (one geometry submission, reversed-Z depth test).

use crate::frame::{Pass, PassInfo, TargetDesc, Targets};
use crate::gpu::GpuContext;
use crate::scene_gpu::{GpuScene, VERTEX_LAYOUT};

pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// Targets written by the G-buffer pass.
pub const OUTPUTS: &[TargetDesc] = &[
    TargetDesc {
        name: "depth",
        format: DEPTH_FORMAT,
        layers: 1,
        doc: "hardware depth (reversed-Z, near/z)",
    },
    TargetDesc {
        name: "csz",
        format: wgpu::TextureFormat::R32Float,
        layers: 1,
        doc: "camera-space depth z (0 = sky)",
    },
    TargetDesc {
        name: "normal",
        format: wgpu::TextureFormat::Rgba8Unorm,
        layers: 1,
        doc: "rg = Oct16 world normal, b = roughness, a = metallic",
    },
    TargetDesc {
        name: "albedo",
        format: wgpu::TextureFormat::Rgba8UnormSrgb,
        layers: 1,
        doc: "base colour, a = opacity",
    },
    TargetDesc {
        name: "emission",
        format: wgpu::TextureFormat::Rgba16Float,
        layers: 1,
        doc: "emitted radiance",
    },
];

pub struct GBufferPass {
    pipeline: wgpu::RenderPipeline,
}

impl GBufferPass {
    pub fn new(gpu: &GpuContext, scene: &GpuScene) -> Self {
        let device = &gpu.device;
        let module = crate::shader::module(device, "gbuffer", include_str!("gbuffer.wgsl"));
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("gbuffer"),
            bind_group_layouts: &[
                Some(&scene.frame_layout),
                Some(&scene.object_layout),
                Some(&scene.material_layout),
            ],
            immediate_size: 0,
        });
        let targets: Vec<Option<wgpu::ColorTargetState>> = OUTPUTS[1..]
            .iter()
            .map(|t| Some(wgpu::ColorTargetState::from(t.format)))
            .collect();
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("gbuffer"),
            layout: Some(&layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_main"),
                compilation_options: Default::default(),
                buffers: &[Some(VERTEX_LAYOUT)],
            },
            primitive: wgpu::PrimitiveState {
                cull_mode: None,
                ..Default::default()
            },
            depth_stencil: Some(wgpu::DepthStencilState {
                format: DEPTH_FORMAT,
                depth_write_enabled: Some(true),
                depth_compare: Some(wgpu::CompareFunction::Greater),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_main"),
                compilation_options: Default::default(),
                targets: &targets,
            }),
            multiview_mask: None,
            cache: None,
        });
        Self { pipeline }
    }
}

impl Pass for GBufferPass {
    fn info(&self) -> PassInfo {
        PassInfo {
            name: "gbuffer",
            inputs: vec!["scene"],
            outputs: OUTPUTS.iter().map(|t| t.name).collect(),
        }
    }

    fn encode(&self, _gpu: &GpuContext, scene: &GpuScene, targets: &Targets, encoder: &mut wgpu::CommandEncoder) {
        let color = |name: &str| {
            Some(wgpu::RenderPassColorAttachment {
                view: &targets.get(name).view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                    store: wgpu::StoreOp::Store,
                },
            })
        };
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("gbuffer"),
            color_attachments: &[color("csz"), color("normal"), color("albedo"), color("emission")],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &targets.get("depth").view,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(0.0),
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &scene.frame_bind_group, &[]);
        scene.draw_all(&mut pass, 1, Some(2));
    }
}
