//! Declarative full-screen passes: a pass is its WGSL plus what it reads, writes
//! and which uniforms it takes; the builder makes the bind-group layout, the bind
//! group, the uniform buffer, the pipeline layout and the pipeline, and the built
//! pass reports its inputs/outputs and records itself.
//!
//! ```ignore
//! let pass = PassBuilder::new(gpu, targets, "temporal")
//!     .shader("temporal", include_str!("temporal.wgsl"))
//!     .frame(scene)                     // group 0: frame uniforms
//!     .uniforms(&u)                     // group 1 binding 0
//!     .read(input).read(history)        // bindings 1, 2, …
//!     .write(output)
//!     .build();
//! ```
//!
//! The same declarations make a compute pass: `.compute()` first, a compute `entry`,
//! outputs as `.write_storage(name)`, then `.build_compute()`. [`ScreenPass`] builds
//! either form of one shader function ([`Kernel`]).

use crate::frame::{PassInfo, Targets};
use crate::gpu::GpuContext;
use crate::scene_gpu::GpuScene;

/// How a screen pass that has both forms runs: as a fullscreen fragment pass or as its
/// compute twin (the same shader function over 8×8-pixel workgroups, storage-texture
/// outputs). Not in the papers: an implementation choice with the same values.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kernel {
    /// Compute on GPUs, fragment on CPU adapters: an H100's fragment path ran the
    /// radiosity gather 40× slower than compute, lavapipe's compute path 1.2× slower
    /// than fragment (docs/benchmarks.md, 2026-11-28).
    Auto,
    Fragment,
    Compute,
}

impl Kernel {
    /// `Auto` resolved for an adapter: `true` for compute.
    pub fn compute_on(self, gpu: &GpuContext) -> bool {
        match self {
            Kernel::Auto => gpu.adapter.get_info().device_type != wgpu::DeviceType::Cpu,
            Kernel::Fragment => false,
            Kernel::Compute => true,
        }
    }

    /// [`Kernel::compute_on`] for a pass writing `formats`: compute only where `gpu` can
    /// write each of them as a storage texture ([`storable`]); R16F and RG11B10 need the
    /// adapter's own format features. Elsewhere the pass stays a fragment pass.
    pub fn compute_for(self, gpu: &GpuContext, formats: &[wgpu::TextureFormat]) -> bool {
        self.compute_on(gpu) && formats.iter().all(|&f| storable(gpu, f))
    }
}

/// The formats of the screen passes' targets with a compute form (`strata info` lists
/// which of them this adapter can write as storage textures).
pub const SCREEN_FORMATS: &[wgpu::TextureFormat] = &[
    wgpu::TextureFormat::Rgba16Float,
    wgpu::TextureFormat::R32Float,
    wgpu::TextureFormat::R16Float,
    wgpu::TextureFormat::Rg11b10Ufloat,
    wgpu::TextureFormat::Rg32Float,
];

/// Whether a compute pass on `gpu` can write `format` as a write-only storage texture: the
/// adapter's own format features where the device has
/// `TEXTURE_ADAPTER_SPECIFIC_FORMAT_FEATURES` (lavapipe writes R16F and RG11B10; whether a
/// GPU's driver does, `strata info` tells), WebGPU's guaranteed ones elsewhere (RGBA16F, R32F
/// and RG32F among strata's).
pub fn storable(gpu: &GpuContext, format: wgpu::TextureFormat) -> bool {
    let features = gpu.device.features();
    let f = if features.contains(wgpu::Features::TEXTURE_ADAPTER_SPECIFIC_FORMAT_FEATURES) {
        gpu.adapter.get_texture_format_features(format)
    } else {
        format.guaranteed_format_features(features)
    };
    f.allowed_usages.contains(wgpu::TextureUsages::STORAGE_BINDING)
        && f.flags.contains(wgpu::TextureFormatFeatureFlags::STORAGE_WRITE_ONLY)
}

/// WGSL's name of a storage texture format, for the `STORAGE_FORMAT_i` placeholders
/// ([`PassBuilder`]); `None` for a format no storage texture takes.
fn wgsl_storage_format(format: wgpu::TextureFormat) -> Option<&'static str> {
    use wgpu::TextureFormat as F;
    Some(match format {
        F::Rgba16Float => "rgba16float",
        F::R32Float => "r32float",
        F::R16Float => "r16float",
        F::Rg11b10Ufloat => "rg11b10ufloat",
        F::Rgba32Float => "rgba32float",
        F::Rg32Float => "rg32float",
        F::Rgba8Unorm => "rgba8unorm",
        F::R32Uint => "r32uint",
        _ => return None,
    })
}

/// The shader module of a screen pass whose outputs have `formats`: `STORAGE_FORMAT_i` in
/// its WGSL becomes the WGSL name of `formats[i]`, so one compute entry writes whatever
/// format its target has. In the fragment form the storage textures are declared but
/// unused, so any format does for one that no storage texture takes.
pub(crate) fn module_writing(
    device: &wgpu::Device,
    label: &str,
    source: &str,
    formats: &[wgpu::TextureFormat],
) -> wgpu::ShaderModule {
    let mut text = crate::shader::compose(source);
    for (i, &f) in formats.iter().enumerate().rev() {
        text = text.replace(
            &format!("STORAGE_FORMAT_{i}"),
            wgsl_storage_format(f).unwrap_or("rgba16float"),
        );
    }
    crate::shader::module(device, label, &text)
}

/// A hand-built screen pass's pipeline in either form ([`Kernel`]), for passes whose
/// bindings the [`PassBuilder`] does not make (the lighting, the depth MIP chain).
pub(crate) enum ScreenPipeline {
    Fragment(wgpu::RenderPipeline),
    Compute(wgpu::ComputePipeline),
}

impl ScreenPipeline {
    /// Records the pass: a fullscreen pass into `outputs`, or the compute form over `size`
    /// texels, 8×8 per workgroup (its outputs are storage textures in `groups`).
    pub fn record(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        label: &str,
        outputs: &[&wgpu::TextureView],
        groups: &[&wgpu::BindGroup],
        size: [u32; 2],
    ) {
        match self {
            ScreenPipeline::Fragment(p) => super::fullscreen_pass(encoder, label, p, outputs, groups),
            ScreenPipeline::Compute(p) => {
                let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some(label),
                    timestamp_writes: None,
                });
                pass.set_pipeline(p);
                for (i, g) in groups.iter().enumerate() {
                    pass.set_bind_group(i as u32, *g, &[]);
                }
                pass.dispatch_workgroups(size[0].div_ceil(8), size[1].div_ceil(8), 1);
            }
        }
    }
}

/// A write-only storage texture of `format` at `binding`, for compute passes.
pub(crate) fn storage_texture_entry(binding: u32, format: wgpu::TextureFormat) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::StorageTexture {
            access: wgpu::StorageTextureAccess::WriteOnly,
            format,
            view_dimension: wgpu::TextureViewDimension::D2,
        },
        count: None,
    }
}

/// What a built pass holds besides its pipeline, in either form.
struct Bound {
    name: &'static str,
    group: wgpu::BindGroup,
    uniforms: Option<wgpu::Buffer>,
    frame: bool,
    inputs: Vec<&'static str>,
    outputs: Vec<&'static str>,
}

impl Bound {
    fn set_uniforms<T: bytemuck::Pod>(&self, gpu: &GpuContext, value: &T) {
        let buf = self.uniforms.as_ref().expect("the pass declared uniforms");
        gpu.queue.write_buffer(buf, 0, bytemuck::bytes_of(value));
    }

    fn info(&self) -> PassInfo {
        PassInfo {
            name: self.name,
            inputs: self.inputs.clone(),
            outputs: self.outputs.clone(),
        }
    }
}

/// A full-screen pass made by [`PassBuilder`].
pub(crate) struct FullscreenPass {
    pipeline: wgpu::RenderPipeline,
    bound: Bound,
}

impl FullscreenPass {
    /// Replaces the pass's uniforms (declared with [`PassBuilder::uniforms`]).
    pub fn set_uniforms<T: bytemuck::Pod>(&self, gpu: &GpuContext, value: &T) {
        self.bound.set_uniforms(gpu, value)
    }

    pub fn info(&self) -> PassInfo {
        self.bound.info()
    }

    /// Records the pass (clearing its outputs), shading only inside `scissor` when given.
    pub fn encode_in(
        &self,
        scene: &GpuScene,
        targets: &Targets,
        encoder: &mut wgpu::CommandEncoder,
        scissor: Option<[u32; 4]>,
    ) {
        let b = &self.bound;
        let views: Vec<&wgpu::TextureView> = b.outputs.iter().map(|n| &targets.get(n).view).collect();
        let groups: Vec<&wgpu::BindGroup> = if b.frame {
            vec![&scene.frame_bind_group, &b.group]
        } else {
            vec![&b.group]
        };
        super::fullscreen_pass_in(encoder, b.name, &self.pipeline, &views, &groups, scissor);
    }

    pub fn encode(&self, scene: &GpuScene, targets: &Targets, encoder: &mut wgpu::CommandEncoder) {
        self.encode_in(scene, targets, encoder, None)
    }
}

impl crate::frame::Pass for FullscreenPass {
    fn info(&self) -> PassInfo {
        FullscreenPass::info(self)
    }

    fn encode(&self, _gpu: &GpuContext, scene: &GpuScene, targets: &Targets, encoder: &mut wgpu::CommandEncoder) {
        FullscreenPass::encode(self, scene, targets, encoder)
    }
}

/// `impl Pass` for a struct whose field `pass` is its [`FullscreenPass`].
macro_rules! delegate_pass {
    ($t:ty) => {
        impl crate::frame::Pass for $t {
            fn info(&self) -> crate::frame::PassInfo {
                self.pass.info()
            }

            fn encode(
                &self,
                _gpu: &crate::gpu::GpuContext,
                scene: &crate::scene_gpu::GpuScene,
                targets: &crate::frame::Targets,
                encoder: &mut wgpu::CommandEncoder,
            ) {
                self.pass.encode(scene, targets, encoder);
            }
        }
    };
}
pub(crate) use delegate_pass;

/// Declares a [`FullscreenPass`]; bindings are numbered in declaration order.
pub(crate) struct PassBuilder<'a> {
    gpu: &'a GpuContext,
    targets: &'a Targets,
    name: &'static str,
    shader: Option<(&'static str, &'static str)>,
    entry: &'static str,
    constants: Vec<(&'static str, f64)>,
    frame_layout: Option<&'a wgpu::BindGroupLayout>,
    /// Initial contents of the uniform buffer, created by `build`.
    uniforms: Option<Vec<u8>>,
    layout_entries: Vec<wgpu::BindGroupLayoutEntry>,
    /// `None` marks the uniform buffer's binding.
    resources: Vec<Option<wgpu::BindingResource<'a>>>,
    inputs: Vec<&'static str>,
    outputs: Vec<&'static str>,
    /// The stage the bindings are visible to: FRAGMENT, or COMPUTE after [`PassBuilder::compute`].
    stage: wgpu::ShaderStages,
}

impl<'a> PassBuilder<'a> {
    pub fn new(gpu: &'a GpuContext, targets: &'a Targets, name: &'static str) -> Self {
        Self {
            gpu,
            targets,
            name,
            shader: None,
            entry: "fs_main",
            constants: Vec::new(),
            frame_layout: None,
            uniforms: None,
            layout_entries: Vec::new(),
            resources: Vec::new(),
            inputs: Vec::new(),
            outputs: Vec::new(),
            stage: wgpu::ShaderStages::FRAGMENT,
        }
    }

    /// Makes a compute pass instead ([`PassBuilder::build_compute`]): the bindings are
    /// visible to the compute stage and `entry` names a compute entry point. Call it
    /// before declaring any binding.
    pub fn compute(mut self) -> Self {
        self.stage = wgpu::ShaderStages::COMPUTE;
        self
    }

    /// The form `compute` asks for of a screen pass: the compute form's entry is `cs_main`.
    /// Call it before declaring any binding.
    pub fn kernel(self, compute: bool) -> Self {
        if compute {
            self.compute().entry("cs_main")
        } else {
            self
        }
    }

    /// The form `compute` asks for of a screen pass limited to `scissor` ([x, y, w, h] in
    /// output texels; `None`: everywhere). The fragment form takes the scissor when it is
    /// built ([`ScreenPass::build_in`]); the compute form (entry `cs_main`) gets it as the
    /// override constants of `common/scissor.wgsl`, whose `in_scissor` its shader tests.
    /// Call it before declaring any binding.
    pub fn kernel_in(self, compute: bool, scissor: Option<[u32; 4]>) -> Self {
        if !compute {
            return self;
        }
        let [x0, y0, x1, y1] = scissor.map_or([0, 0, u32::MAX, u32::MAX], |[x, y, w, h]| [x, y, x + w, y + h]);
        self.compute()
            .entry("cs_main")
            .constant("SCISSOR_X0", x0 as f64)
            .constant("SCISSOR_Y0", y0 as f64)
            .constant("SCISSOR_X1", x1 as f64)
            .constant("SCISSOR_Y1", y1 as f64)
    }

    /// The WGSL (with `#import`s) and its label.
    pub fn shader(mut self, label: &'static str, source: &'static str) -> Self {
        self.shader = Some((label, source));
        self
    }

    /// The fragment entry point (default `fs_main`).
    pub fn entry(mut self, entry: &'static str) -> Self {
        self.entry = entry;
        self
    }

    /// A pipeline-overridable constant.
    pub fn constant(mut self, name: &'static str, value: f64) -> Self {
        self.constants.push((name, value));
        self
    }

    /// Binds the frame uniforms as group 0 (the pass's own group becomes 1).
    pub fn frame(mut self, scene: &'a GpuScene) -> Self {
        self.frame_layout = Some(&scene.frame_layout);
        self
    }

    fn push(mut self, ty: wgpu::BindingType, resource: Option<wgpu::BindingResource<'a>>) -> Self {
        self.layout_entries.push(wgpu::BindGroupLayoutEntry {
            binding: self.layout_entries.len() as u32,
            visibility: self.stage,
            ty,
            count: None,
        });
        self.resources.push(resource);
        self
    }

    /// A uniform buffer holding `value` (update it with [`FullscreenPass::set_uniforms`]).
    pub fn uniforms<T: bytemuck::Pod>(mut self, value: &T) -> Self {
        assert!(self.uniforms.is_none(), "one uniform buffer per pass");
        self.uniforms = Some(bytemuck::bytes_of(value).to_vec());
        self.push(
            wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Uniform,
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            None,
        )
    }

    /// Any texture view (`input` names it in the pass's declared inputs; "" for none).
    pub fn view(
        mut self,
        input: &'static str,
        view: &'a wgpu::TextureView,
        dimension: wgpu::TextureViewDimension,
        filterable: bool,
    ) -> Self {
        if !input.is_empty() && !self.inputs.contains(&input) {
            self.inputs.push(input);
        }
        self.push(
            wgpu::BindingType::Texture {
                sample_type: wgpu::TextureSampleType::Float { filterable },
                view_dimension: dimension,
                multisampled: false,
            },
            Some(wgpu::BindingResource::TextureView(view)),
        )
    }

    /// A depth texture view (`texture_depth_*`, read with a comparison sampler or `textureLoad`).
    pub fn depth_view(
        mut self,
        input: &'static str,
        view: &'a wgpu::TextureView,
        dimension: wgpu::TextureViewDimension,
    ) -> Self {
        if !input.is_empty() && !self.inputs.contains(&input) {
            self.inputs.push(input);
        }
        self.push(
            wgpu::BindingType::Texture {
                sample_type: wgpu::TextureSampleType::Depth,
                view_dimension: dimension,
                multisampled: false,
            },
            Some(wgpu::BindingResource::TextureView(view)),
        )
    }

    /// Target `name` as a whole (`D2Array` when it has several layers).
    pub fn read(self, name: &'static str) -> Self {
        let t = self.targets.get(name);
        let dim = if t.desc.layers > 1 {
            wgpu::TextureViewDimension::D2Array
        } else {
            wgpu::TextureViewDimension::D2
        };
        self.view(name, &t.view, dim, false)
    }

    /// Target `name` as a `D2Array` (also when it has one layer).
    pub fn read_array(self, name: &'static str) -> Self {
        let t = self.targets.get(name);
        self.view(name, &t.array_view, wgpu::TextureViewDimension::D2Array, false)
    }

    /// Array layer `j` of target `name`.
    pub fn read_layer(self, name: &'static str, j: u32) -> Self {
        let t = self.targets.get(name);
        self.view(name, t.layer(j), wgpu::TextureViewDimension::D2, false)
    }

    /// Declares input `name` without a binding (a buffer an earlier pass writes).
    pub fn input(mut self, name: &'static str) -> Self {
        if !self.inputs.contains(&name) {
            self.inputs.push(name);
        }
        self
    }

    /// A read-only storage buffer.
    pub fn storage(self, buffer: &'a wgpu::Buffer) -> Self {
        self.storage_buffer(buffer, true)
    }

    /// A read-write storage buffer (atomics, appended lists).
    pub fn storage_rw(self, buffer: &'a wgpu::Buffer) -> Self {
        self.storage_buffer(buffer, false)
    }

    fn storage_buffer(self, buffer: &'a wgpu::Buffer, read_only: bool) -> Self {
        self.push(
            wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Storage { read_only },
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            Some(buffer.as_entire_binding()),
        )
    }

    /// A sampler of binding type `ty`.
    pub fn sampler(self, sampler: &'a wgpu::Sampler, ty: wgpu::SamplerBindingType) -> Self {
        self.push(
            wgpu::BindingType::Sampler(ty),
            Some(wgpu::BindingResource::Sampler(sampler)),
        )
    }

    /// Renders into target `name` (whole, cleared); colour targets follow declaration order.
    pub fn write(mut self, name: &'static str) -> Self {
        self.outputs.push(name);
        self
    }

    /// Target `name` as a write-only storage texture (compute passes; declared as an output).
    pub fn write_storage(mut self, name: &'static str) -> Self {
        let t = self.targets.get(name);
        self.outputs.push(name);
        let ty = storage_texture_entry(0, t.desc.format).ty;
        self.push(ty, Some(wgpu::BindingResource::TextureView(t.layer(0))))
    }

    /// The bind group, its uniform buffer, the pipeline layout and the shader module.
    fn build_common(
        &self,
    ) -> (
        wgpu::BindGroup,
        Option<wgpu::Buffer>,
        wgpu::PipelineLayout,
        wgpu::ShaderModule,
    ) {
        let device = &self.gpu.device;
        let (label, source) = self.shader.expect("a pass needs its WGSL");
        let group_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some(self.name),
            entries: &self.layout_entries,
        });
        let uniforms = self.uniforms.as_ref().map(|bytes| {
            use wgpu::util::DeviceExt;
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(self.name),
                contents: bytes,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            })
        });
        let entries: Vec<wgpu::BindGroupEntry> = self
            .resources
            .iter()
            .enumerate()
            .map(|(i, r)| wgpu::BindGroupEntry {
                binding: i as u32,
                resource: match r {
                    Some(r) => r.clone(),
                    None => uniforms.as_ref().expect("declared uniforms").as_entire_binding(),
                },
            })
            .collect();
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some(self.name),
            layout: &group_layout,
            entries: &entries,
        });
        let mut layouts = Vec::new();
        if let Some(f) = self.frame_layout {
            layouts.push(Some(f));
        }
        layouts.push(Some(&group_layout));
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some(self.name),
            bind_group_layouts: &layouts,
            immediate_size: 0,
        });
        let formats: Vec<wgpu::TextureFormat> = self.outputs.iter().map(|n| self.targets.get(n).desc.format).collect();
        let module = module_writing(device, label, source, &formats);
        (group, uniforms, pipeline_layout, module)
    }

    fn bound(self, group: wgpu::BindGroup, uniforms: Option<wgpu::Buffer>) -> Bound {
        Bound {
            name: self.name,
            group,
            uniforms,
            frame: self.frame_layout.is_some(),
            inputs: self.inputs,
            outputs: self.outputs,
        }
    }

    pub fn build(self) -> FullscreenPass {
        assert_eq!(
            self.stage,
            wgpu::ShaderStages::FRAGMENT,
            "a compute pass is made by build_compute"
        );
        let (group, uniforms, pipeline_layout, module) = self.build_common();
        let device = &self.gpu.device;
        let formats: Vec<Option<wgpu::ColorTargetState>> = self
            .outputs
            .iter()
            .map(|n| Some(wgpu::ColorTargetState::from(self.targets.get(n).desc.format)))
            .collect();
        let pipeline = super::fullscreen_pipeline_with(
            device,
            self.name,
            &pipeline_layout,
            &module,
            self.entry,
            &self.constants,
            &formats,
        );
        FullscreenPass {
            pipeline,
            bound: self.bound(group, uniforms),
        }
    }

    /// The compute pass (after [`PassBuilder::compute`]); its outputs are the targets
    /// declared with [`PassBuilder::write_storage`].
    pub fn build_compute(self) -> ComputePass {
        assert_eq!(self.stage, wgpu::ShaderStages::COMPUTE, "declare .compute() first");
        let (group, uniforms, pipeline_layout, module) = self.build_common();
        let constants: Vec<(&str, f64)> = self.constants.clone();
        let pipeline = self
            .gpu
            .device
            .create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(self.name),
                layout: Some(&pipeline_layout),
                module: &module,
                entry_point: Some(self.entry),
                compilation_options: wgpu::PipelineCompilationOptions {
                    constants: &constants,
                    ..Default::default()
                },
                cache: None,
            });
        ComputePass {
            pipeline,
            bound: self.bound(group, uniforms),
        }
    }
}

/// A compute pass made by [`PassBuilder::build_compute`].
pub(crate) struct ComputePass {
    pipeline: wgpu::ComputePipeline,
    bound: Bound,
}

impl ComputePass {
    /// Replaces the pass's uniforms (declared with [`PassBuilder::uniforms`]).
    pub fn set_uniforms<T: bytemuck::Pod>(&self, gpu: &GpuContext, value: &T) {
        self.bound.set_uniforms(gpu, value)
    }

    pub fn info(&self) -> PassInfo {
        self.bound.info()
    }

    /// Records the pass with its workgroup counts read from `args` at `offset`
    /// (`dispatch_workgroups_indirect`).
    pub fn encode_indirect(
        &self,
        scene: &GpuScene,
        encoder: &mut wgpu::CommandEncoder,
        args: &wgpu::Buffer,
        offset: wgpu::BufferAddress,
    ) {
        self.record(scene, encoder, |pass| pass.dispatch_workgroups_indirect(args, offset));
    }

    /// Records the pass over `size` invocations in x and y, `group` per workgroup (the
    /// shader's `@workgroup_size`; it skips the invocations past `size`).
    pub fn encode_grid(&self, scene: &GpuScene, encoder: &mut wgpu::CommandEncoder, size: [u32; 2], group: [u32; 2]) {
        self.record(scene, encoder, |pass| {
            pass.dispatch_workgroups(size[0].div_ceil(group[0]), size[1].div_ceil(group[1]), 1)
        });
    }

    fn record(
        &self,
        scene: &GpuScene,
        encoder: &mut wgpu::CommandEncoder,
        dispatch: impl FnOnce(&mut wgpu::ComputePass),
    ) {
        let b = &self.bound;
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some(b.name),
            timestamp_writes: None,
        });
        pass.set_pipeline(&self.pipeline);
        let mut i = 0;
        if b.frame {
            pass.set_bind_group(0, &scene.frame_bind_group, &[]);
            i = 1;
        }
        pass.set_bind_group(i, &b.group, &[]);
        dispatch(&mut pass);
    }
}

/// A screen pass built in either form ([`Kernel`]): a fullscreen fragment pass or its
/// compute twin, 8×8 pixels per workgroup over its first output.
pub(crate) enum ScreenPass {
    /// The fragment form, and the scissor rectangle it draws in (`None`: everywhere).
    Fragment(FullscreenPass, Option<[u32; 4]>),
    Compute(ComputePass),
}

impl ScreenPass {
    /// Declares the outputs (colour attachments or storage textures) and builds the
    /// form `compute` asks for; a compute builder must have been made with
    /// [`PassBuilder::compute`] and a compute `entry`.
    pub fn build(builder: PassBuilder<'_>, outputs: &[&'static str], compute: bool) -> Self {
        Self::build_in(builder, outputs, compute, None)
    }

    /// [`ScreenPass::build`] limited to `scissor` ([x, y, w, h] in output texels): the
    /// fragment form draws only there; the compute form, whose builder must come from
    /// [`PassBuilder::kernel_in`] with the same scissor, stores zero outside it.
    pub fn build_in(
        mut builder: PassBuilder<'_>,
        outputs: &[&'static str],
        compute: bool,
        scissor: Option<[u32; 4]>,
    ) -> Self {
        for &t in outputs {
            builder = if compute {
                builder.write_storage(t)
            } else {
                builder.write(t)
            };
        }
        if compute {
            ScreenPass::Compute(builder.build_compute())
        } else {
            ScreenPass::Fragment(builder.build(), scissor)
        }
    }

    pub fn set_uniforms<T: bytemuck::Pod>(&self, gpu: &GpuContext, value: &T) {
        match self {
            ScreenPass::Fragment(p, _) => p.set_uniforms(gpu, value),
            ScreenPass::Compute(p) => p.set_uniforms(gpu, value),
        }
    }

    pub fn info(&self) -> PassInfo {
        match self {
            ScreenPass::Fragment(p, _) => p.info(),
            ScreenPass::Compute(p) => p.info(),
        }
    }

    /// Records the pass (the compute form over its whole first output).
    pub fn encode(&self, scene: &GpuScene, targets: &Targets, encoder: &mut wgpu::CommandEncoder) {
        match self {
            ScreenPass::Fragment(p, scissor) => p.encode_in(scene, targets, encoder, *scissor),
            ScreenPass::Compute(p) => {
                let t = &targets.get(p.bound.outputs[0]).texture;
                p.encode_grid(scene, encoder, [t.width(), t.height()], [8, 8]);
            }
        }
    }
}

impl crate::frame::Pass for ScreenPass {
    fn info(&self) -> PassInfo {
        ScreenPass::info(self)
    }

    fn encode(&self, _gpu: &GpuContext, scene: &GpuScene, targets: &Targets, encoder: &mut wgpu::CommandEncoder) {
        ScreenPass::encode(self, scene, targets, encoder)
    }
}
