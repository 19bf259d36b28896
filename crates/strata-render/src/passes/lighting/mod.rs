//! Deferred direct lighting over the G-buffer: Lambert + GGX specular, shadow
//! maps with PCF (PCSS penumbrae for area lights), emission, constant ambient, sky.

use crate::frame::{Pass, PassInfo, TargetDesc, Targets};
use crate::gpu::GpuContext;
use crate::lights::GpuLight;
use crate::passes::builder::{storage_texture_entry, ScreenPipeline};
use crate::passes::shadow::ShadowPass;
use crate::passes::Kernel;
use crate::scene_gpu::GpuScene;

/// Lighting settings.
#[derive(Clone, Debug, PartialEq)]
pub struct LightingSettings {
    /// Add the GGX specular lobe to the HDR output (default true).
    pub specular: bool,
    /// PCF kernel radius in shadow texels (default 1 → 3×3 bilinear comparisons).
    pub pcf_radius: i32,
    /// Soft shadows of `Rect` (area) lights: percentage-closer soft shadows
    /// (PCSS) whose kernel is the light's image through the blockers, so the
    /// penumbra widens with the blocker-to-receiver distance as the path
    /// tracer's does (default true). False: hard shadows from the light's centre.
    pub area_penumbrae: bool,
    /// The pass as a fullscreen fragment pass or its compute twin (the same values;
    /// default [`Kernel::Auto`]: compute on GPUs whose storage textures take R16F and
    /// RG11B10). An H200 ran the fragment form at 1080p in 3.9 ms.
    pub kernel: Kernel,
}

impl Default for LightingSettings {
    fn default() -> Self {
        Self {
            specular: true,
            pcf_radius: 1,
            area_penumbrae: true,
            kernel: Kernel::Auto,
        }
    }
}

pub const OUTPUTS: &[TargetDesc] = &[
    TargetDesc::new(
        "hdr",
        wgpu::TextureFormat::Rgba16Float,
        1,
        "direct + emission + ambient (linear)",
    ),
    TargetDesc::new(
        "direct-diffuse",
        wgpu::TextureFormat::Rgba16Float,
        1,
        "Lambertian direct outgoing radiance",
    ),
    TargetDesc::new("shadow", wgpu::TextureFormat::R16Float, 1, "visibility of light 0"),
    TargetDesc::new(
        "radiosity0",
        crate::passes::deep_gbuffer::RADIOSITY_FORMAT,
        1,
        "DGB Table 1: layer 0 radiosity B, initialised with Lambertian direct light + emission",
    ),
];

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Params {
    light_count: u32,
    specular: u32,
    pcf_radius: i32,
    shadow_size: f32,
    emission_in_radiosity: u32,
    area_penumbrae: u32,
    _pad: [u32; 2],
}

pub struct LightingPass {
    pipeline: ScreenPipeline,
    group: wgpu::BindGroup,
    lights: wgpu::Buffer,
    /// Layers 1.. of the deep G-buffer: their initial radiosity B (DGB §3.2).
    layer_pipeline: ScreenPipeline,
    layer_groups: Vec<(&'static str, wgpu::BindGroup)>,
}

/// Per-layer radiosity targets (DGB Table 1: layer j's previous-bounce B).
pub const RADIOSITY: [&str; 4] = ["radiosity0", "radiosity1", "radiosity2", "radiosity3"];

impl LightingPass {
    /// Whether the pass runs as compute on `gpu` ([`LightingSettings::kernel`], where the
    /// storage textures take every output's format).
    pub fn compute_on(gpu: &GpuContext, settings: &LightingSettings) -> bool {
        let formats: Vec<wgpu::TextureFormat> = OUTPUTS.iter().map(|t| t.format).collect();
        settings.kernel.compute_for(gpu, &formats)
    }

    /// Shades layer 0 into `OUTPUTS` and layers 1..`layers` into `radiosityJ`; `compute`
    /// ([`LightingPass::compute_on`]): as compute passes, whose outputs must have storage
    /// binding.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        gpu: &GpuContext,
        scene: &GpuScene,
        targets: &Targets,
        shadow: &ShadowPass,
        lights: &[GpuLight],
        shadow_resolution: u32,
        settings: &LightingSettings,
        layers: u32,
        compute: bool,
    ) -> Self {
        let device = &gpu.device;
        let tex =
            |b: u32, filterable: bool| crate::passes::texture_entry(b, wgpu::TextureViewDimension::D2, filterable);
        let [shadow_texture, shadow_sampler] = crate::passes::shadow_map_entries(5, wgpu::ShaderStages::FRAGMENT);
        let mut entries = vec![
            tex(0, false),
            tex(1, false),
            tex(2, false),
            tex(3, false),
            crate::passes::storage_entry(4),
            shadow_texture,
            shadow_sampler,
            crate::passes::uniform_entry(7),
            crate::passes::storage_entry(8),
        ];
        // the compute form's layer 0 writes bindings 9..=12 (OUTPUTS), a deeper layer 13
        let mut layer_entries = entries.clone();
        if compute {
            for e in entries.iter_mut().chain(layer_entries.iter_mut()) {
                e.visibility = wgpu::ShaderStages::COMPUTE;
            }
            entries.extend(
                OUTPUTS
                    .iter()
                    .enumerate()
                    .map(|(i, t)| storage_texture_entry(9 + i as u32, t.format)),
            );
            layer_entries.push(storage_texture_entry(13, crate::passes::deep_gbuffer::RADIOSITY_FORMAT));
        }
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("lighting"),
            entries: &entries,
        });
        let layer_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("lighting layer radiosity"),
            entries: &layer_entries,
        });
        let mut light_data = lights.to_vec();
        if light_data.is_empty() {
            light_data.push(bytemuck::Zeroable::zeroed());
        }
        let lights_buf = wgpu::util::DeviceExt::create_buffer_init(
            device,
            &wgpu::util::BufferInitDescriptor {
                label: Some("lights"),
                contents: bytemuck::cast_slice(&light_data),
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            },
        );
        let params = Params {
            light_count: lights.len() as u32,
            specular: settings.specular as u32,
            pcf_radius: settings.pcf_radius.clamp(0, 4),
            shadow_size: shadow_resolution as f32,
            // Emitters light the scene through the radiosity buffers, unless
            // they are also analytic `Rect` lights: then the direct term
            // already carries their light (no double counting).
            emission_in_radiosity: !lights.iter().any(|l| l.kind[0] == crate::lights::KIND_RECT) as u32,
            area_penumbrae: settings.area_penumbrae as u32,
            _pad: [0; 2],
        };
        let params_buf = wgpu::util::DeviceExt::create_buffer_init(
            device,
            &wgpu::util::BufferInitDescriptor {
                label: Some("lighting params"),
                contents: bytemuck::bytes_of(&params),
                usage: wgpu::BufferUsages::UNIFORM,
            },
        );
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("shadow"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            compare: Some(wgpu::CompareFunction::LessEqual),
            ..Default::default()
        });
        let group_for = |j: u32| {
            let view = |n: &str| wgpu::BindingResource::TextureView(targets.get(n).layer(j));
            let mut resources = vec![
                view("csz"),
                view("normal"),
                view("albedo"),
                view("emission"),
                lights_buf.as_entire_binding(),
                wgpu::BindingResource::TextureView(&shadow.array_view),
                wgpu::BindingResource::Sampler(&sampler),
                params_buf.as_entire_binding(),
                shadow.matrices.as_entire_binding(),
            ];
            let (label, layout) = match (compute, j) {
                (false, _) => ("lighting", &layout),
                (true, 0) => {
                    resources.extend(OUTPUTS.iter().map(|t| view(t.name)));
                    ("lighting", &layout)
                }
                (true, _) => {
                    // the deeper layer's radiosity at binding 13 (bindings 9..=12 unused)
                    let out = wgpu::BindingResource::TextureView(targets.get(RADIOSITY[j as usize]).layer(0));
                    let entries: Vec<wgpu::BindGroupEntry> = resources
                        .into_iter()
                        .enumerate()
                        .map(|(i, resource)| wgpu::BindGroupEntry {
                            binding: i as u32,
                            resource,
                        })
                        .chain(std::iter::once(wgpu::BindGroupEntry {
                            binding: 13,
                            resource: out,
                        }))
                        .collect();
                    return device.create_bind_group(&wgpu::BindGroupDescriptor {
                        label: Some("lighting layer radiosity"),
                        layout: &layer_layout,
                        entries: &entries,
                    });
                }
            };
            crate::passes::bind_group(device, label, layout, &resources)
        };
        let group = group_for(0);
        let layer_groups = (1..layers.min(4))
            .map(|j| (RADIOSITY[j as usize], group_for(j)))
            .collect();
        let formats: Vec<wgpu::TextureFormat> = OUTPUTS.iter().map(|t| t.format).collect();
        let module =
            crate::passes::builder::module_writing(device, "lighting", include_str!("lighting.wgsl"), &formats);
        let pipeline_layout = |layout: &wgpu::BindGroupLayout| {
            device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("lighting"),
                bind_group_layouts: &[Some(&scene.frame_layout), Some(layout)],
                immediate_size: 0,
            })
        };
        let pl = pipeline_layout(&layout);
        let compute_pipeline = |label: &str, layout: &wgpu::PipelineLayout, entry: &str| {
            ScreenPipeline::Compute(device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(label),
                layout: Some(layout),
                module: &module,
                entry_point: Some(entry),
                compilation_options: Default::default(),
                cache: None,
            }))
        };
        let (pipeline, layer_pipeline) = if compute {
            (
                compute_pipeline("lighting", &pl, "cs_main"),
                compute_pipeline(
                    "lighting layer radiosity",
                    &pipeline_layout(&layer_layout),
                    "cs_layer_radiosity",
                ),
            )
        } else {
            let targets_fmt = crate::passes::color_targets(OUTPUTS);
            (
                ScreenPipeline::Fragment(crate::passes::fullscreen_pipeline(
                    device,
                    "lighting",
                    &pl,
                    &module,
                    &targets_fmt,
                )),
                ScreenPipeline::Fragment(crate::passes::fullscreen_pipeline_with(
                    device,
                    "lighting layer radiosity",
                    &pl,
                    &module,
                    "fs_layer_radiosity",
                    &[],
                    &[Some(wgpu::ColorTargetState::from(
                        crate::passes::deep_gbuffer::RADIOSITY_FORMAT,
                    ))],
                )),
            )
        };
        Self {
            pipeline,
            group,
            lights: lights_buf,
            layer_pipeline,
            layer_groups,
        }
    }

    pub fn update_lights(&self, gpu: &GpuContext, lights: &[GpuLight]) {
        if !lights.is_empty() {
            gpu.queue.write_buffer(&self.lights, 0, bytemuck::cast_slice(lights));
        }
    }
}

impl Pass for LightingPass {
    fn info(&self) -> PassInfo {
        PassInfo {
            name: "lighting",
            inputs: vec!["csz", "normal", "albedo", "emission", "shadow-maps"],
            outputs: OUTPUTS
                .iter()
                .map(|t| t.name)
                .chain(self.layer_groups.iter().map(|(n, _)| *n))
                .collect(),
        }
    }

    fn encode(&self, _gpu: &GpuContext, scene: &GpuScene, targets: &Targets, encoder: &mut wgpu::CommandEncoder) {
        let size = [targets.width, targets.height];
        let outputs = crate::passes::output_views(targets, OUTPUTS);
        let groups = [&scene.frame_bind_group, &self.group];
        self.pipeline.record(encoder, "lighting", &outputs, &groups, size);
        for (name, group) in &self.layer_groups {
            let groups = [&scene.frame_bind_group, group];
            let outputs = [&targets.get(name).view];
            self.layer_pipeline
                .record(encoder, "lighting layer radiosity", &outputs, &groups, size);
        }
    }
}
