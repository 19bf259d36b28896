//! One module per technique, each with its WGSL beside it.

pub mod abuffer;
pub mod ao;
pub mod bilateral;
pub(crate) mod builder;
pub use builder::{storable, Kernel, SCREEN_FORMATS};
pub mod bzb;
pub mod compose;
pub mod deep_gbuffer;
pub mod depth_mip;
pub mod exposure;
pub mod ils;
pub mod interleave;
pub mod lighting;
pub mod radiosity;
pub mod reflections;
pub mod shadow;
pub mod temporal;
pub mod tonemap;
pub mod upsample;

/// A full-screen-triangle pipeline (vertex entry `vs_fullscreen` from
/// `common/fullscreen.wgsl`, fragment entry `fs_main`).
pub(crate) fn fullscreen_pipeline(
    device: &wgpu::Device,
    label: &str,
    layout: &wgpu::PipelineLayout,
    module: &wgpu::ShaderModule,
    targets: &[Option<wgpu::ColorTargetState>],
) -> wgpu::RenderPipeline {
    fullscreen_pipeline_with(device, label, layout, module, "fs_main", &[], targets)
}

/// As [`fullscreen_pipeline`] with a named fragment entry and override constants.
pub(crate) fn fullscreen_pipeline_with(
    device: &wgpu::Device,
    label: &str,
    layout: &wgpu::PipelineLayout,
    module: &wgpu::ShaderModule,
    fragment_entry: &str,
    constants: &[(&str, f64)],
    targets: &[Option<wgpu::ColorTargetState>],
) -> wgpu::RenderPipeline {
    fullscreen_pipeline_writing_depth(device, label, layout, module, fragment_entry, constants, targets, None)
}

/// [`fullscreen_pipeline_with`] that also writes its fragments' `frag_depth` into a
/// depth attachment of `depth` format (test Always), where `depth` is given.
#[allow(clippy::too_many_arguments)]
pub(crate) fn fullscreen_pipeline_writing_depth(
    device: &wgpu::Device,
    label: &str,
    layout: &wgpu::PipelineLayout,
    module: &wgpu::ShaderModule,
    fragment_entry: &str,
    constants: &[(&str, f64)],
    targets: &[Option<wgpu::ColorTargetState>],
    depth: Option<wgpu::TextureFormat>,
) -> wgpu::RenderPipeline {
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(label),
        layout: Some(layout),
        vertex: wgpu::VertexState {
            module,
            entry_point: Some("vs_fullscreen"),
            compilation_options: Default::default(),
            buffers: &[],
        },
        primitive: Default::default(),
        depth_stencil: depth.map(|format| wgpu::DepthStencilState {
            format,
            depth_write_enabled: Some(true),
            depth_compare: Some(wgpu::CompareFunction::Always),
            stencil: Default::default(),
            bias: Default::default(),
        }),
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module,
            entry_point: Some(fragment_entry),
            compilation_options: wgpu::PipelineCompilationOptions {
                constants,
                ..Default::default()
            },
            targets,
        }),
        multiview_mask: None,
        cache: None,
    })
}

pub(crate) fn clear_attachment(view: &wgpu::TextureView) -> Option<wgpu::RenderPassColorAttachment<'_>> {
    Some(wgpu::RenderPassColorAttachment {
        view,
        depth_slice: None,
        resolve_target: None,
        ops: wgpu::Operations {
            load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
            store: wgpu::StoreOp::Store,
        },
    })
}

/// Whether a pass whose output can outlive the frame (shadow maps of a static scene)
/// must draw: with `cached` off every frame draws; on, the first frame after
/// [`Self::invalidate`] (or creation) does and the next ones keep its output.
#[derive(Debug, Default)]
pub(crate) struct DrawOnce {
    cached: bool,
    /// The output is current (cleared by `invalidate`).
    drawn: std::sync::atomic::AtomicBool,
}

impl DrawOnce {
    /// Keep the output from frame to frame (`true`) or draw every frame; the next frame draws.
    pub fn set_cached(&mut self, cached: bool) {
        self.cached = cached;
        self.invalidate();
    }

    pub fn cached(&self) -> bool {
        self.cached
    }

    /// The next frame draws (its inputs changed).
    pub fn invalidate(&self) {
        self.drawn.store(false, std::sync::atomic::Ordering::Relaxed);
    }

    /// Whether this frame draws; marks the output current.
    pub fn must_draw(&self) -> bool {
        !(self.cached && self.drawn.swap(true, std::sync::atomic::Ordering::Relaxed))
    }
}

/// A depth attachment cleared to 1 (the far plane) and stored.
pub(crate) fn clear_depth_attachment(view: &wgpu::TextureView) -> wgpu::RenderPassDepthStencilAttachment<'_> {
    wgpu::RenderPassDepthStencilAttachment {
        view,
        depth_ops: Some(wgpu::Operations {
            load: wgpu::LoadOp::Clear(1.0),
            store: wgpu::StoreOp::Store,
        }),
        stencil_ops: None,
    }
}

/// A fragment-stage float texture binding (`filterable` for sampled reads).
pub(crate) fn texture_entry(
    binding: u32,
    dimension: wgpu::TextureViewDimension,
    filterable: bool,
) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Float { filterable },
            view_dimension: dimension,
            multisampled: false,
        },
        count: None,
    }
}

/// A fragment-stage read-only storage buffer binding.
/// The shadow maps' bindings: the depth array at `binding` and its comparison sampler at
/// `binding + 1`, visible to `visibility`.
pub(crate) fn shadow_map_entries(binding: u32, visibility: wgpu::ShaderStages) -> [wgpu::BindGroupLayoutEntry; 2] {
    [
        wgpu::BindGroupLayoutEntry {
            binding,
            visibility,
            ty: wgpu::BindingType::Texture {
                sample_type: wgpu::TextureSampleType::Depth,
                view_dimension: wgpu::TextureViewDimension::D2Array,
                multisampled: false,
            },
            count: None,
        },
        wgpu::BindGroupLayoutEntry {
            binding: binding + 1,
            visibility,
            ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Comparison),
            count: None,
        },
    ]
}

pub(crate) fn storage_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only: true },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

/// A fragment-stage uniform buffer binding.
pub(crate) fn uniform_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

/// Records a full-screen-triangle pass that clears and writes `outputs`, with
/// `groups` bound at 0, 1, ….
pub(crate) fn fullscreen_pass(
    encoder: &mut wgpu::CommandEncoder,
    label: &str,
    pipeline: &wgpu::RenderPipeline,
    outputs: &[&wgpu::TextureView],
    groups: &[&wgpu::BindGroup],
) {
    fullscreen_pass_in(encoder, label, pipeline, outputs, groups, None)
}

/// As [`fullscreen_pass`], shading only inside `scissor` = [x, y, w, h] (the
/// rest of the outputs is cleared to zero).
pub(crate) fn fullscreen_pass_in(
    encoder: &mut wgpu::CommandEncoder,
    label: &str,
    pipeline: &wgpu::RenderPipeline,
    outputs: &[&wgpu::TextureView],
    groups: &[&wgpu::BindGroup],
    scissor: Option<[u32; 4]>,
) {
    let att: Vec<_> = outputs.iter().map(|v| clear_attachment(v)).collect();
    let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some(label),
        color_attachments: &att,
        depth_stencil_attachment: None,
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    });
    pass.set_pipeline(pipeline);
    for (i, g) in groups.iter().enumerate() {
        pass.set_bind_group(i as u32, *g, &[]);
    }
    if let Some([x, y, w, h]) = scissor {
        pass.set_scissor_rect(x, y, w, h);
    }
    pass.draw(0..3, 0..1);
}

/// A bind group binding `resources` at 0, 1, ….
pub(crate) fn bind_group(
    device: &wgpu::Device,
    label: &str,
    layout: &wgpu::BindGroupLayout,
    resources: &[wgpu::BindingResource],
) -> wgpu::BindGroup {
    let entries: Vec<_> = resources
        .iter()
        .enumerate()
        .map(|(i, r)| wgpu::BindGroupEntry {
            binding: i as u32,
            resource: r.clone(),
        })
        .collect();
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some(label),
        layout,
        entries: &entries,
    })
}

/// Keeps targets for the next frame at the end of this one: `csz` →
/// `csz-history` (the single-pass deep G-buffer's oracle and the temporal
/// filter's reprojection test) and each temporal filter's output →
/// `<output>-history`.
pub struct HistoryPass {
    /// (source, destination) pairs of same-shaped targets.
    pub copies: Vec<(&'static str, &'static str)>,
}

impl crate::frame::Pass for HistoryPass {
    fn info(&self) -> crate::frame::PassInfo {
        crate::frame::PassInfo {
            name: "history",
            inputs: self.copies.iter().map(|c| c.0).collect(),
            outputs: self.copies.iter().map(|c| c.1).collect(),
        }
    }

    fn encode(
        &self,
        _gpu: &crate::gpu::GpuContext,
        _scene: &crate::scene_gpu::GpuScene,
        targets: &crate::frame::Targets,
        encoder: &mut wgpu::CommandEncoder,
    ) {
        for (src, dst) in &self.copies {
            let (src, dst) = (targets.get(src), targets.get(dst));
            encoder.copy_texture_to_texture(
                src.texture.as_image_copy(),
                dst.texture.as_image_copy(),
                src.texture.size(),
            );
        }
    }
}

/// Colour-target states for writing the targets `descs` (in order).
pub(crate) fn color_targets(descs: &[crate::frame::TargetDesc]) -> Vec<Option<wgpu::ColorTargetState>> {
    descs
        .iter()
        .map(|t| Some(wgpu::ColorTargetState::from(t.format)))
        .collect()
}

/// The views of the targets `descs` (in order), as a pass's attachments.
pub(crate) fn output_views<'a>(
    targets: &'a crate::frame::Targets,
    descs: &[crate::frame::TargetDesc],
) -> Vec<&'a wgpu::TextureView> {
    descs.iter().map(|t| &targets.get(t.name).view).collect()
}
