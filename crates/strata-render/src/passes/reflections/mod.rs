//! DGB §3.6 mirror reflections through the deep G-buffer: a camera-space ray
//! march that tests every step against all layers (hit within [z, z + Δz]),
//! reading the hit layer's outgoing radiance; the environment (sky) after a
//! maximum distance or once the ray leaves the guard-banded buffer.
//!
//! Outputs `reflection` (rgb = reflected radiance, a = 0 not a mirror,
//! 1 environment, 2 layer-0 hit, 3 layer-1 hit) and `hdr-reflected` (the input
//! image plus F0 · reflected radiance on mirrors).

use crate::frame::{TargetDesc, Targets};
use crate::gpu::GpuContext;
use crate::passes::builder::{PassBuilder, ScreenPass};
use crate::passes::Kernel;
use crate::scene_gpu::GpuScene;

/// Defaults: 64 steps over 16 scene units, surface thickness Δz = the deep
/// G-buffer's minimum separation (as the paper), mirrors = metallic ≥ 0.5 and
/// roughness ≤ 0.1, the march as compute on GPUs ([`Kernel::Auto`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReflectionSettings {
    pub max_distance: f32,
    pub steps: u32,
    /// Thickness of a layer's surface for the hit test; `None` = the scene's Δz.
    pub thickness: Option<f32>,
    pub max_roughness: f32,
    /// The march as a fullscreen fragment pass or its compute twin (the same values). Not
    /// in the paper: an H200 ran the fragment form of this pass at 1080p in 9.9 ms
    /// (docs/benchmarks.md, 2026-11-29).
    pub kernel: Kernel,
}

impl Default for ReflectionSettings {
    fn default() -> Self {
        Self {
            max_distance: 16.0,
            steps: 64,
            thickness: None,
            max_roughness: 0.1,
            kernel: Kernel::Auto,
        }
    }
}

impl ReflectionSettings {
    pub fn validate(&self) -> Result<(), String> {
        if !(self.max_distance > 0.0 && self.max_distance.is_finite()) {
            return Err(format!(
                "reflection distance {} is out of range: must be > 0",
                self.max_distance
            ));
        }
        if !(1..=1024).contains(&self.steps) {
            return Err(format!(
                "reflection steps {} is out of range: must be in 1..=1024",
                self.steps
            ));
        }
        if !(0.0..=1.0).contains(&self.max_roughness) {
            return Err(format!(
                "reflection max_roughness {} is out of range: must be in 0..=1",
                self.max_roughness
            ));
        }
        if let Some(t) = self.thickness {
            if !(t > 0.0 && t.is_finite()) {
                return Err(format!("reflection thickness {t} is out of range: must be > 0"));
            }
        }
        Ok(())
    }
}

/// Mirrors `Reflections` in `reflections.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct ReflectionUniforms {
    pub max_distance: f32,
    pub steps: u32,
    pub thickness: f32,
    pub max_roughness: f32,
    /// The light probes' grid, for second-layer hits ([`Layer1Radiance::indirect`]).
    pub grid: crate::passes::compose::ProbeGridUniform,
}

pub const OUTPUTS: [TargetDesc; 2] = [
    TargetDesc::new(
        "reflection",
        wgpu::TextureFormat::Rgba16Float,
        1,
        "reflected radiance (rgb); a = 0 no mirror, 1 environment, 2 layer-0 hit, 3 layer-1 hit",
    ),
    TargetDesc::new(
        "hdr-reflected",
        wgpu::TextureFormat::Rgba16Float,
        1,
        "the shaded image plus F0 · reflected radiance on mirrors (linear HDR)",
    ),
];

/// What the rays reflect besides layer 0's shaded image: a layer-1 hit's terms and, for a
/// ray that finds nothing, the environment.
#[derive(Clone, Copy, Default)]
pub struct ReflectedLight<'a> {
    pub layer1: Layer1Radiance<'a>,
    /// A cube map view (world-space directions, filterable) read along rays that find
    /// nothing; `None`: the scene's sky colour.
    pub environment: Option<&'a wgpu::TextureView>,
}

/// What a hit on layer 1 reflects besides that layer's radiance target (`radiosity1`, or an
/// application's): the terms layer 0's shaded image holds and B does not.
#[derive(Clone, Copy, Default)]
pub struct Layer1Radiance<'a> {
    /// Add ambient × diffuse albedo (the renderer's B has no ambient term).
    pub ambient: bool,
    /// Add ρ/π · k · E as compose adds layer 0's: E is the gather's layer-1 irradiance
    /// (`indirect1-raw`), blended with the light probes at the hit where there are probes;
    /// k = boost(ρ) when `boost`.
    pub indirect: Option<Layer1Indirect<'a>>,
}

/// The radiosity stage's light for second-layer hits ([`Layer1Radiance::indirect`]).
#[derive(Clone, Copy)]
pub struct Layer1Indirect<'a> {
    /// The probes and compose's blend mode (1 DGB's blend, 2 probes + detail, 3 one-sided);
    /// `None`: the gather alone.
    pub probes: Option<(&'a crate::passes::compose::ProbeGpu, u32)>,
    pub boost: bool,
}

pub struct ReflectionPass {
    pass: ScreenPass,
    settings: ReflectionSettings,
    grid: crate::passes::compose::ProbeGridUniform,
}

impl ReflectionPass {
    /// Reflects `input` (the shaded layer 0), layer 1's radiosity with what
    /// `light.layer1` adds, and `light.environment`; creates [`OUTPUTS`].
    pub fn new(
        gpu: &GpuContext,
        scene: &GpuScene,
        targets: &mut Targets,
        layers: u32,
        input: &'static str,
        settings: &ReflectionSettings,
        light: ReflectedLight<'_>,
    ) -> Self {
        let ReflectedLight { layer1, environment } = light;
        let compute = settings.kernel.compute_for(gpu, &OUTPUTS.map(|t| t.format));
        for t in OUTPUTS {
            targets.create_storable(gpu, t, compute);
        }
        let targets = &*targets;
        // one layer: the binding holds the input, never read
        let dummy = crate::passes::compose::ProbeGpu::new(gpu, None, None);
        let (layer1_name, declared) = if layers > 1 {
            ("radiosity1", "radiosity1")
        } else {
            (input, "")
        };
        let b = PassBuilder::new(gpu, targets, "reflections")
            .kernel(compute)
            .shader("reflections", include_str!("reflections.wgsl"))
            .constant("LAYERS", layers as f64)
            .constant("LAYER1_AMBIENT", layer1.ambient as u32 as f64)
            .constant(
                "LAYER1_INDIRECT",
                layer1.indirect.map_or(0, |i| i.probes.map_or(4, |(_, mode)| mode)) as f64,
            )
            .constant("LAYER1_BOOST", layer1.indirect.is_some_and(|i| i.boost) as u32 as f64)
            .frame(scene)
            .uniforms(&<ReflectionUniforms as bytemuck::Zeroable>::zeroed())
            .read_array("csz")
            .read_array("normal")
            .read_array("albedo")
            .read(input)
            .view(
                declared,
                &targets.get(layer1_name).view,
                wgpu::TextureViewDimension::D2,
                false,
            );
        // without the radiosity stage the bindings hold the input and empty probes, unread
        let (e1, declared) = match layer1.indirect {
            Some(_) if layers > 1 => ("indirect1-raw", "indirect1-raw"),
            _ => (input, ""),
        };
        let b = b.view(declared, &targets.get(e1).view, wgpu::TextureViewDimension::D2, false);
        let probes = layer1.indirect.and_then(|i| i.probes).map_or(&dummy, |(p, _)| p);
        let b = b.storage(&probes.probes).storage(&probes.depth);
        // without an environment cube map the binding holds a 1-texel stand-in, unread
        let stand_in = environment.is_none().then(|| environment_stand_in(gpu));
        let environment_view = environment.or(stand_in.as_ref()).expect("one of the two");
        let sampler = gpu.device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("reflections environment"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            ..Default::default()
        });
        let b = b
            .constant("ENVIRONMENT", environment.is_some() as u32 as f64)
            .view("", environment_view, wgpu::TextureViewDimension::Cube, true)
            .sampler(&sampler, wgpu::SamplerBindingType::Filtering);
        Self {
            pass: ScreenPass::build(b, &OUTPUTS.map(|t| t.name), compute),
            settings: *settings,
            grid: probes.grid,
        }
    }

    pub fn set_frame(&self, gpu: &GpuContext, min_separation: f32) {
        let s = &self.settings;
        let u = ReflectionUniforms {
            max_distance: s.max_distance,
            steps: s.steps,
            thickness: s.thickness.unwrap_or(min_separation),
            max_roughness: s.max_roughness,
            grid: self.grid,
        };
        self.pass.set_uniforms(gpu, &u);
    }
}

/// A cube map's texture: 6 square layers of `size` texels, one mip.
pub fn cube_texture(
    gpu: &GpuContext,
    size: u32,
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
) -> wgpu::Texture {
    gpu.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("cube map"),
        size: wgpu::Extent3d {
            width: size,
            height: size,
            depth_or_array_layers: 6,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage,
        view_formats: &[],
    })
}

/// Environment map `e` as a cube map view (Rgba16Float, one mip).
pub fn environment_cube(gpu: &GpuContext, e: &strata_scene::environment::EnvironmentMap) -> wgpu::TextureView {
    let t = cube_texture(
        gpu,
        e.size,
        wgpu::TextureFormat::Rgba16Float,
        wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
    );
    let bytes: Vec<u8> = e
        .texels
        .iter()
        .flat_map(|c| [c[0], c[1], c[2], 1.0])
        .flat_map(|v| half_bits(v).to_le_bytes())
        .collect();
    gpu.queue.write_texture(
        t.as_image_copy(),
        &bytes,
        wgpu::TexelCopyBufferLayout {
            offset: 0,
            bytes_per_row: Some(8 * e.size),
            rows_per_image: Some(e.size),
        },
        t.size(),
    );
    t.create_view(&wgpu::TextureViewDescriptor {
        dimension: Some(wgpu::TextureViewDimension::Cube),
        ..Default::default()
    })
}

/// IEEE half of a non-negative radiance `v` (round to nearest; NaN and negatives 0, above
/// the largest half the largest half).
pub fn half_bits(v: f32) -> u16 {
    if v.is_nan() || v <= 0.0 {
        return 0;
    }
    let b = v.to_bits();
    let e = ((b >> 23) & 0xff) as i32 - 127 + 15;
    let m = (b & 0x7f_ffff) | 0x80_0000;
    let h = if e >= 31 {
        0x7bff
    } else if e <= 0 {
        // subnormal: the significand shifted down by 1 - e more places
        let shift = (14 - e) as u32;
        if shift > 24 {
            return 0;
        }
        (m >> shift) + ((m >> (shift - 1)) & 1)
    } else {
        (((e as u32) << 10) | ((m & 0x7f_ffff) >> 13)) + ((m >> 12) & 1)
    };
    h.min(0x7bff) as u16
}

/// A 1×1 cube map for the environment binding when there is none.
fn environment_stand_in(gpu: &GpuContext) -> wgpu::TextureView {
    let t = cube_texture(
        gpu,
        1,
        wgpu::TextureFormat::Rgba8Unorm,
        wgpu::TextureUsages::TEXTURE_BINDING,
    );
    t.create_view(&wgpu::TextureViewDescriptor {
        dimension: Some(wgpu::TextureViewDimension::Cube),
        ..Default::default()
    })
}

crate::passes::builder::delegate_pass!(ReflectionPass);

#[cfg(test)]
mod tests {
    /// Against IEEE half values: normals, rounding, the subnormals, the clamps.
    #[test]
    fn half_bits_are_ieee_halves() {
        use super::half_bits;
        for (v, h) in [
            (1.0f32, 0x3c00u16),
            (0.5, 0x3800),
            (2.0, 0x4000),
            (0.1, 0x2e66),
            (1.0 + 1.5 / 1024.0, 0x3c02),
            (65504.0, 0x7bff),
            (1e9, 0x7bff),
            (f32::INFINITY, 0x7bff),
            (2f32.powi(-14), 0x0400),
            (2f32.powi(-24), 0x0001),
            (3.0 * 2f32.powi(-16), 0x0300),
            (2f32.powi(-26), 0),
            (0.0, 0),
            (-1.0, 0),
            (f32::NAN, 0),
        ] {
            assert_eq!(half_bits(v), h, "{v}");
        }
    }
}
