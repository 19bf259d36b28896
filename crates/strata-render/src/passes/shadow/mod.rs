//! Shadow maps: one depth layer per shadowed light (sun: orthographic; spot and
//! rect: perspective) and six per shadowed point light (cube faces, see
//! `crate::lights`), standard depth (0 near, 1 far), slope-scaled bias. The
//! layers' view-projections are also kept in a storage buffer
//! ([`ShadowPass::matrices`]) that the lighting pass indexes by layer.

use crate::frame::{Pass, PassInfo, Targets};
use crate::gpu::GpuContext;

use crate::scene_gpu::{GpuScene, VERTEX_LAYOUT};

/// Settings for shadow mapping.
#[derive(Clone, Debug, PartialEq)]
pub struct ShadowSettings {
    /// Shadow map resolution per light (texels per side). Default 2048.
    pub resolution: u32,
    /// How many point lights (the most intense) get omnidirectional shadow maps;
    /// the others are unshadowed. Default [`crate::lights::POINT_SHADOW_BUDGET`] (2).
    pub point_lights: usize,
    /// Lights (indices into the scene's list, as `strata render --list-lights`
    /// numbers them) that cast no shadow: per-light shadows off. Default none.
    pub unshadowed: Vec<usize>,
}

impl Default for ShadowSettings {
    fn default() -> Self {
        Self {
            resolution: 2048,
            point_lights: crate::lights::POINT_SHADOW_BUDGET,
            unshadowed: Vec::new(),
        }
    }
}

const STRIDE: u64 = 256;

pub struct ShadowPass {
    pipeline: wgpu::RenderPipeline,
    views_buffer: wgpu::Buffer,
    views_group: wgpu::BindGroup,
    /// Depth array: the layers of [`crate::lights::shadow_matrices`] (at least one).
    pub maps: wgpu::Texture,
    pub array_view: wgpu::TextureView,
    /// Every layer's view-projection, tightly packed (`array<mat4x4f>`).
    pub matrices: wgpu::Buffer,
    layer_views: Vec<wgpu::TextureView>,
    /// Whether a frame draws the maps (kept in a static scene: [`Self::set_cached`];
    /// [`Self::update`] redraws).
    draw: crate::passes::DrawOnce,
}

/// The depth-only pipeline that renders a shadow map's face (`shadow.wgsl`, two-sided,
/// slope-scaled bias) and the bind group of its view matrix, read from `views` at a
/// dynamic offset (one 64-byte matrix per face, in slots of `STRIDE`). The scene's
/// shadow maps and ILS's VPL shadow maps share it.
pub(crate) fn depth_only_pipeline(
    device: &wgpu::Device,
    object_layout: &wgpu::BindGroupLayout,
    views: &wgpu::Buffer,
    label: &str,
) -> (wgpu::BindGroup, wgpu::RenderPipeline) {
    let views_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some(&format!("{label} view")),
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
        label: Some(&format!("{label} views")),
        layout: &views_layout,
        entries: &[wgpu::BindGroupEntry {
            binding: 0,
            resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                buffer: views,
                offset: 0,
                size: wgpu::BufferSize::new(64),
            }),
        }],
    });
    let module = crate::shader::module(device, "shadow", include_str!("shadow.wgsl"));
    let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(label),
        bind_group_layouts: &[Some(&views_layout), Some(object_layout)],
        immediate_size: 0,
    });
    let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(label),
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
    (views_group, pipeline)
}

impl ShadowPass {
    /// `matrices`: one view-projection per shadow-map layer
    /// ([`crate::lights::shadow_matrices`]); none renders no map.
    pub fn new(gpu: &GpuContext, scene: &GpuScene, matrices: &[[[f32; 4]; 4]], settings: &ShadowSettings) -> Self {
        let device = &gpu.device;
        let layers = (matrices.len() as u32).max(1);
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
        let mut bytes = vec![0u8; (STRIDE * layers as u64) as usize];
        let mut layer_views = Vec::new();
        for (i, m) in matrices.iter().enumerate() {
            let s = i * STRIDE as usize;
            bytes[s..s + 64].copy_from_slice(bytemuck::bytes_of(m));
            layer_views.push(maps.create_view(&wgpu::TextureViewDescriptor {
                dimension: Some(wgpu::TextureViewDimension::D2),
                base_array_layer: i as u32,
                array_layer_count: Some(1),
                ..Default::default()
            }));
        }
        let mut packed: Vec<[[f32; 4]; 4]> = matrices.to_vec();
        if packed.is_empty() {
            packed.push([[0.0; 4]; 4]);
        }
        let matrices_buffer = wgpu::util::DeviceExt::create_buffer_init(
            device,
            &wgpu::util::BufferInitDescriptor {
                label: Some("shadow matrices"),
                contents: bytemuck::cast_slice(&packed),
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            },
        );
        let views_buffer = wgpu::util::DeviceExt::create_buffer_init(
            device,
            &wgpu::util::BufferInitDescriptor {
                label: Some("shadow views"),
                contents: &bytes,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            },
        );
        let (views_group, pipeline) = depth_only_pipeline(device, &scene.object_layout, &views_buffer, "shadow");
        Self {
            pipeline,
            views_buffer,
            views_group,
            maps,
            array_view,
            matrices: matrices_buffer,
            layer_views,
            draw: Default::default(),
        }
    }

    /// Whether the maps are kept from frame to frame ([`Self::set_cached`]).
    pub fn cached(&self) -> bool {
        self.draw.cached()
    }

    /// Keep the maps from frame to frame instead of re-rendering them: for a scene whose
    /// geometry and lights do not move (the renderer sets it when no object is
    /// animated). [`Self::update`] still re-renders them.
    pub fn set_cached(&mut self, cached: bool) {
        self.draw.set_cached(cached);
    }

    /// Re-uploads the layers' matrices (animated scenes move the fitted bounds
    /// and the lights); the layer count is fixed at creation.
    pub fn update(&self, gpu: &GpuContext, matrices: &[[[f32; 4]; 4]]) {
        self.draw.invalidate();
        for (i, m) in matrices.iter().enumerate().take(self.layer_views.len()) {
            gpu.queue
                .write_buffer(&self.views_buffer, i as u64 * STRIDE, bytemuck::bytes_of(m));
            gpu.queue
                .write_buffer(&self.matrices, i as u64 * 64, bytemuck::bytes_of(m));
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
        if !self.draw.must_draw() {
            return;
        }
        for (slot, view) in self.layer_views.iter().enumerate() {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("shadow"),
                color_attachments: &[],
                depth_stencil_attachment: Some(crate::passes::clear_depth_attachment(view)),
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
