//! Final composition (DGB Eq. 6, Fig. 9): `hdr` (direct light, emission, sky)
//! plus the Lambertian reflection ρ/π · E · boost(ρ) of the indirect irradiance,
//! where E blends the deep-G-buffer result with static irradiance probes by the
//! gather's confidence c = M/N (the probe term modulated by AO when it runs):
//! E = c · E_dgb + (1 − c) · AV · E_probe. Outputs `hdr-full`,
//! `indirect-blended` (E, c) and `probe-irradiance` (AV · E_probe, AV).

use strata_scene::probes::IrradianceProbes;

use crate::frame::{Pass, PassInfo, TargetDesc, Targets};
use crate::gpu::GpuContext;
use crate::scene_gpu::GpuScene;

pub const OUTPUTS: [TargetDesc; 3] = [
    TargetDesc::new(
        "hdr-full",
        wgpu::TextureFormat::Rgba16Float,
        1,
        "direct + indirect diffuse (linear HDR)",
    ),
    TargetDesc::new(
        "indirect-blended",
        wgpu::TextureFormat::Rgba16Float,
        1,
        "E blended from the deep G-buffer and the probes (rgb), confidence M/N (a)",
    ),
    TargetDesc::new(
        "probe-irradiance",
        wgpu::TextureFormat::Rgba16Float,
        1,
        "light-probe irradiance × AV (rgb), AV (a)",
    ),
];

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct ComposeUniforms {
    boost: u32,
    use_probes: u32,
    use_ao: u32,
    _pad: u32,
    origin: [f32; 4],
    spacing: [f32; 4],
    dims: [u32; 4],
}

pub struct ComposePass {
    pipeline: wgpu::RenderPipeline,
    group: wgpu::BindGroup,
    inputs: Vec<&'static str>,
}

impl ComposePass {
    /// `probes`: the static fallback (Fig. 9); AO modulates it when target `ao` exists.
    pub fn new(
        gpu: &GpuContext,
        scene: &GpuScene,
        targets: &Targets,
        boost: bool,
        probes: Option<&IrradianceProbes>,
    ) -> Self {
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
                texture_entry(5, d2, false),
                texture_entry(6, d2, false),
                wgpu::BindGroupLayoutEntry {
                    binding: 7,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Storage { read_only: true },
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                },
            ],
        });
        let use_ao = probes.is_some() && targets.try_get("ao").is_some();
        let u = ComposeUniforms {
            boost: boost as u32,
            use_probes: probes.is_some() as u32,
            use_ao: use_ao as u32,
            _pad: 0,
            origin: probes.map_or([0.0; 4], |p| p.origin.extend(0.0).to_array()),
            spacing: probes.map_or([1.0; 4], |p| p.spacing.extend(0.0).to_array()),
            dims: probes.map_or([1, 1, 1, 0], |p| [p.dims[0], p.dims[1], p.dims[2], 0]),
        };
        let buffer = crate::passes::uniform_buffer(device, "compose", &u);
        let data: Vec<[f32; 4]> = match probes {
            Some(p) => p
                .coeffs
                .iter()
                .zip(&p.valid)
                .flat_map(|(c, &valid)| {
                    c.iter()
                        .enumerate()
                        .map(move |(i, rgb)| [rgb[0], rgb[1], rgb[2], if i == 0 { valid as u32 as f32 } else { 0.0 }])
                })
                .collect(),
            None => vec![[0.0; 4]; 9],
        };
        let probe_buf = wgpu::util::DeviceExt::create_buffer_init(
            device,
            &wgpu::util::BufferInitDescriptor {
                label: Some("light probes"),
                contents: bytemuck::cast_slice(&data),
                usage: wgpu::BufferUsages::STORAGE,
            },
        );
        let layer0 = |n: &str| wgpu::BindingResource::TextureView(targets.get(n).layer(0));
        let ao = if use_ao { "ao" } else { "indirect" };
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
                layer0("csz"),
                layer0(ao),
                probe_buf.as_entire_binding(),
            ],
        );
        let pl = crate::passes::frame_pipeline_layout(device, "compose", scene, &[&layout]);
        let module = crate::shader::module(device, "compose", include_str!("compose.wgsl"));
        let formats = crate::passes::color_targets(&OUTPUTS);
        let pipeline = crate::passes::fullscreen_pipeline(device, "compose", &pl, &module, &formats);
        let mut inputs = vec!["hdr", "albedo", "normal", "indirect", "csz"];
        if use_ao {
            inputs.push("ao");
        }
        Self {
            pipeline,
            group,
            inputs,
        }
    }
}

impl Pass for ComposePass {
    fn info(&self) -> PassInfo {
        PassInfo {
            name: "compose",
            inputs: self.inputs.clone(),
            outputs: OUTPUTS.iter().map(|t| t.name).collect(),
        }
    }

    fn encode(&self, _gpu: &GpuContext, scene: &GpuScene, targets: &Targets, encoder: &mut wgpu::CommandEncoder) {
        let outputs = crate::passes::output_views(targets, &OUTPUTS);
        crate::passes::fullscreen_pass(
            encoder,
            "compose",
            &self.pipeline,
            &outputs,
            &[&scene.frame_bind_group, &self.group],
        );
    }
}
