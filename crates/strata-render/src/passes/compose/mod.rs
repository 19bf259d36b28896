//! Final composition (DGB Eq. 6, Fig. 9): `hdr` (direct light, emission, sky)
//! plus the Lambertian reflection ρ/π · E · boost(ρ) of the indirect irradiance,
//! where E blends the deep-G-buffer result with static irradiance probes by the
//! gather's confidence c = M/N (the probe term modulated by AO when it runs):
//! E = c · E_dgb + (1 − c) · G · E_probe, G = AV or its multi-bounce form
//! (`radiosity::ProbeAo`). Outputs `hdr-full`,
//! `indirect-blended` (E, c) and `probe-irradiance` (AO's factor · E_probe, AV).

use crate::passes::builder::{PassBuilder, ScreenPass};
use strata_scene::probes::IrradianceProbes;

use crate::frame::{TargetDesc, Targets};
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
        "light-probe irradiance × AO's factor (AV, or the multi-bounce G(AV, ρ)) (rgb), AV (a)",
    ),
];

/// Mirrors `ProbeGrid` in `common/probes.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct ProbeGridUniform {
    origin: [f32; 4],
    /// w: the visibility test's normal offset
    spacing: [f32; 4],
    /// w: 1 = distance maps (the visibility test)
    dims: [u32; 4],
}

/// The light probes on the GPU, as `common/probes.wgsl` reads them: the grid and the
/// storage buffers `probes` (9 SH coefficients, validity in the first one's w) and
/// `probe_depth` (distance moments). Without probes: a 1-probe dummy.
pub struct ProbeGpu {
    pub grid: ProbeGridUniform,
    pub probes: wgpu::Buffer,
    pub depth: wgpu::Buffer,
}

impl ProbeGpu {
    /// `ao_radius`: the AO's world-space radius r, for each probe's own openness within r
    /// (`IrradianceProbes::openness_sh`, `ProbeAo::Relative`); `None`: every probe open.
    pub fn new(gpu: &GpuContext, probes: Option<&IrradianceProbes>, ao_radius: Option<f32>) -> Self {
        let grid = ProbeGridUniform {
            origin: probes.map_or([0.0; 4], |p| p.origin.extend(p.view_bias()).to_array()),
            spacing: probes.map_or([1.0; 4], |p| p.spacing.extend(p.visibility_bias()).to_array()),
            dims: probes.map_or([1, 1, 1, 0], |p| {
                [p.dims[0], p.dims[1], p.dims[2], !p.depth.is_empty() as u32]
            }),
        };
        let data: Vec<[f32; 4]> = match probes {
            Some(p) => p
                .coeffs
                .iter()
                .zip(&p.valid)
                .enumerate()
                .flat_map(|(index, (c, &valid))| {
                    let offset = p.offsets.get(index).copied().unwrap_or([0.0; 3]);
                    let open = match ao_radius {
                        Some(r) => p.openness_sh(index, r),
                        None => strata_scene::probes::OPEN_EVERYWHERE,
                    };
                    // w: the validity (coefficient 0), the relocation offset (1–3), the
                    // openness within the AO radius as order-1 SH (4–7)
                    c.iter().enumerate().map(move |(i, rgb)| {
                        let w = match i {
                            0 => valid as u32 as f32,
                            1..=3 => offset[i - 1],
                            4..=7 => open[i - 4],
                            _ => 0.0,
                        };
                        [rgb[0], rgb[1], rgb[2], w]
                    })
                })
                .collect(),
            None => vec![[0.0; 4]; 9],
        };
        let storage = |label: &str, contents: &[u8]| {
            wgpu::util::DeviceExt::create_buffer_init(
                &gpu.device,
                &wgpu::util::BufferInitDescriptor {
                    label: Some(label),
                    contents,
                    usage: wgpu::BufferUsages::STORAGE,
                },
            )
        };
        let depth: Vec<[f32; 2]> = match probes {
            Some(p) if !p.depth.is_empty() => p.depth.iter().flatten().copied().collect(),
            _ => vec![[0.0; 2]],
        };
        Self {
            grid,
            probes: storage("light probes", bytemuck::cast_slice(&data)),
            depth: storage("light-probe distance maps", bytemuck::cast_slice(&depth)),
        }
    }
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct ComposeUniforms {
    boost: u32,
    use_probes: u32,
    use_ao: u32,
    use_glossy: u32,
    grid: ProbeGridUniform,
}

/// How the composition uses the light probes.
pub struct ComposeProbes<'a> {
    pub probes: &'a ProbeGpu,
    pub ao: crate::passes::radiosity::ProbeAo,
    /// The probes plus c × the gather's detail term (`RadiositySettings::probe_detail`),
    /// instead of DGB's blend by c.
    pub detail: bool,
    /// DGB's blend with a one-sided confidence
    /// (`RadiositySettings::one_sided_confidence`, `radiosity::probe_blend`).
    pub one_sided: bool,
}

pub struct ComposePass {
    pass: ScreenPass,
}

impl ComposePass {
    /// `probes`: the static fallback (Fig. 9); AO modulates it when target `ao` exists.
    /// `indirect`: the target holding E (rgb) and the confidence (a), e.g. `indirect`.
    /// `glossy`: a target of outgoing radiance added as is (ILS's `ils-glossy`).
    /// `compute`: the compute form ([`crate::passes::Kernel`]; the outputs must then allow
    /// storage binding).
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        gpu: &GpuContext,
        scene: &GpuScene,
        targets: &Targets,
        boost: bool,
        probes: Option<ComposeProbes>,
        indirect: &'static str,
        glossy: Option<&'static str>,
        compute: bool,
    ) -> Self {
        let probe_ao = probes.as_ref().map_or(crate::passes::radiosity::ProbeAo::Off, |p| p.ao);
        let use_ao =
            probes.is_some() && targets.try_get("ao").is_some() && probe_ao != crate::passes::radiosity::ProbeAo::Off;
        let dummy;
        let gpu_probes = match &probes {
            Some(p) => p.probes,
            None => {
                dummy = ProbeGpu::new(gpu, None, None);
                &dummy
            }
        };
        let u = ComposeUniforms {
            boost: boost as u32,
            // 0: none, 1: DGB's blend, 2: probes + detail, 3: DGB's blend, one-sided c
            use_probes: probes.as_ref().map_or(0, |p| match (p.detail, p.one_sided) {
                (true, _) => 2,
                (false, true) => 3,
                (false, false) => 1,
            }),
            // 0: no AO, 1: × AV, 2: × GTAO's multi-bounce G(AV, ρ) (`ProbeAo`)
            use_ao: if use_ao { probe_ao as u32 } else { 0 },
            use_glossy: glossy.is_some() as u32,
            grid: gpu_probes.grid,
        };
        let mut b = PassBuilder::new(gpu, targets, "compose");
        if compute {
            b = b.compute().entry("cs_main");
        }
        let b = b
            .shader("compose", include_str!("compose.wgsl"))
            .frame(scene)
            .uniforms(&u)
            .read_layer("hdr", 0)
            .read_layer("albedo", 0)
            .read_layer("normal", 0)
            .read_layer(indirect, 0)
            .read_layer("csz", 0)
            // without AO the binding is filled by a target that is read anyway
            .read_layer(if use_ao { "ao" } else { indirect }, 0)
            .storage(&gpu_probes.probes)
            // without glossy receivers the binding is filled by a target that is read anyway
            .read_layer(glossy.unwrap_or(indirect), 0)
            .storage(&gpu_probes.depth);
        Self {
            pass: ScreenPass::build(b, &OUTPUTS.map(|t| t.name), compute),
        }
    }
}

crate::passes::builder::delegate_pass!(ComposePass);
