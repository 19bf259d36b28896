//! Shadow maps: one depth layer per shadowed light (sun: orthographic; spot and
//! rect: perspective), standard depth (0 near, 1 far), slope-scaled bias.

use crate::frame::{Pass, PassInfo, Targets};
use crate::gpu::GpuContext;
use crate::lights::{GpuLight, NO_SHADOW};
use crate::scene_gpu::{GpuScene, VERTEX_LAYOUT};

/// Settings for shadow mapping.
#[derive(Clone, Debug, PartialEq)]
pub struct ShadowSettings {
    /// Shadow map resolution per light (texels per side). Default 2048.
    pub resolution: u32,
}

impl Default for ShadowSettings {
    fn default() -> Self {
        Self { resolution: 2048 }
    }
}

const STRIDE: u64 = 256;

pub struct ShadowPass {
    pipeline: wgpu::RenderPipeline,
    views_buffer: wgpu::Buffer,
    views_group: wgpu::BindGroup,
    /// Depth array, one layer per shadowed light (at least one layer).
    pub maps: wgpu::Texture,
    pub array_view: wgpu::TextureView,
    layer_views: Vec<wgpu::TextureView>,
    layer_slots: Vec<u32>,
}

impl ShadowPass {
    pub fn new(gpu: &GpuContext, scene: &GpuScene, lights: &[GpuLight], settings: &ShadowSettings) -> Self {
        let device = &gpu.device;
        let layers = crate::lights::shadow_layer_count(lights).max(1);
        let maps = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("shadow maps"),
            size: wgpu::Extent3d {
                width: settings.resolution,
                height: settings.resolution,
                depth_or_array_layers: layers,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Depth32Float,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT
                | wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        let array_view = maps.create_view(&wgpu::TextureViewDescriptor {
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            ..Default::default()
        });
        let mut bytes = vec![0u8; (STRIDE * lights.len().max(1) as u64) as usize];
        let mut layer_views = Vec::new();
        let mut layer_slots = Vec::new();
        for (i, l) in lights.iter().enumerate() {
            let s = i * STRIDE as usize;
            bytes[s..s + 64].copy_from_slice(bytemuck::bytes_of(&l.shadow_view_proj));
            if l.kind[1] != NO_SHADOW {
                layer_views.push(maps.create_view(&wgpu::TextureViewDescriptor {
                    dimension: Some(wgpu::TextureViewDimension::D2),
                    base_array_layer: l.kind[1],
                    array_layer_count: Some(1),
                    ..Default::default()
                }));
                layer_slots.push(i as u32);
            }
        }
        let views_buffer = wgpu::util::DeviceExt::create_buffer_init(
            device,
            &wgpu::util::BufferInitDescriptor {
                label: Some("shadow views"),
                contents: &bytes,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            },
        );
        let views_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("shadow view"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::VERTEX,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: true,
                    min_binding_size: wgpu::BufferSize::new(64),
                },
                count: None,
            }],
        });
        let views_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("shadow views"),
            layout: &views_layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                    buffer: &views_buffer,
                    offset: 0,
                    size: wgpu::BufferSize::new(64),
                }),
            }],
        });
        let module = crate::shader::module(device, "shadow", include_str!("shadow.wgsl"));
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("shadow"),
            bind_group_layouts: &[Some(&views_layout), Some(&scene.object_layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("shadow"),
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
                format: wgpu::TextureFormat::Depth32Float,
                depth_write_enabled: Some(true),
                depth_compare: Some(wgpu::CompareFunction::LessEqual),
                stencil: Default::default(),
                bias: wgpu::DepthBiasState {
                    constant: 2,
                    slope_scale: 2.0,
                    clamp: 0.0,
                },
            }),
            multisample: Default::default(),
            fragment: None,
            multiview_mask: None,
            cache: None,
        });
        Self {
            pipeline,
            views_buffer,
            views_group,
            maps,
            array_view,
            layer_views,
            layer_slots,
        }
    }

    /// Re-uploads light matrices (animated scenes move the fitted bounds).
    pub fn update(&self, gpu: &GpuContext, lights: &[GpuLight]) {
        for (i, l) in lights.iter().enumerate() {
            gpu.queue.write_buffer(
                &self.views_buffer,
                i as u64 * STRIDE,
                bytemuck::bytes_of(&l.shadow_view_proj),
            );
        }
    }
}

impl Pass for ShadowPass {
    fn info(&self) -> PassInfo {
        PassInfo {
            name: "shadow",
            inputs: vec!["scene"],
            outputs: vec!["shadow-maps"],
        }
    }

    fn encode(&self, _gpu: &GpuContext, scene: &GpuScene, _targets: &Targets, encoder: &mut wgpu::CommandEncoder) {
        for (view, &slot) in self.layer_views.iter().zip(&self.layer_slots) {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("shadow"),
                color_attachments: &[],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(1.0),
                        store: wgpu::StoreOp::Store,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &self.views_group, &[(slot as u64 * STRIDE) as u32]);
            scene.draw_all(&mut pass, 1, None);
        }
    }
}
