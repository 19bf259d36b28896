//! The frame: shadow → G-buffer → lighting → tonemap, with every intermediate
//! target readable as a debug view and every pass timed.

use strata_scene::{Camera, ImageBuf, Scene};

use crate::frame::{validate_pass_order, FrameUniforms, Pass, PassInfo, Targets};
use crate::gpu::GpuContext;
use crate::lights::{gpu_lights, GpuLight};
use crate::passes::{gbuffer, lighting, shadow, tonemap};
use crate::profiler::{PassTimings, Profiler};
use crate::scene_gpu::GpuScene;
use crate::RenderError;

/// Smallest and largest accepted image sizes.
pub const MIN_SIZE: u32 = 8;
pub const MAX_SIZE: u32 = 8192;

/// What to render and how.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderSettings {
    pub width: u32,
    pub height: u32,
    pub shadow: shadow::ShadowSettings,
    pub lighting: lighting::LightingSettings,
    /// Overrides the scene's exposure.
    pub exposure: Option<f32>,
}

impl Default for RenderSettings {
    fn default() -> Self {
        Self {
            width: 640,
            height: 360,
            shadow: Default::default(),
            lighting: Default::default(),
            exposure: None,
        }
    }
}

impl RenderSettings {
    pub fn validate(&self) -> Result<(), RenderError> {
        for (name, v) in [("width", self.width), ("height", self.height)] {
            if !(MIN_SIZE..=MAX_SIZE).contains(&v) {
                return Err(RenderError::Parameter(format!(
                    "{name} {v} is out of range: must be in {MIN_SIZE}..={MAX_SIZE}"
                )));
            }
        }
        if !(64..=8192).contains(&self.shadow.resolution) {
            return Err(RenderError::Parameter(format!(
                "shadow resolution {} is out of range: must be in 64..=8192",
                self.shadow.resolution
            )));
        }
        if let Some(e) = self.exposure {
            if !(e > 0.0 && e.is_finite()) {
                return Err(RenderError::Parameter(format!(
                    "exposure {e} is out of range: must be > 0"
                )));
            }
        }
        Ok(())
    }
}

pub struct Renderer {
    pub settings: RenderSettings,
    pub scene_gpu: GpuScene,
    pub targets: Targets,
    shadow: shadow::ShadowPass,
    gbuffer: gbuffer::GBufferPass,
    lighting: lighting::LightingPass,
    tonemap: tonemap::TonemapPass,
    profiler: Profiler,
    lights: Vec<GpuLight>,
    animated: bool,
}

impl Renderer {
    pub fn new(gpu: &GpuContext, scene: &Scene, settings: RenderSettings) -> Result<Self, RenderError> {
        settings.validate()?;
        if scene.objects.is_empty() {
            return Err(RenderError::Parameter(format!(
                "scene '{}' has no geometry",
                scene.name
            )));
        }
        let scene_gpu = GpuScene::new(gpu, scene);
        let mut targets = Targets::new(settings.width, settings.height);
        for d in gbuffer::OUTPUTS.iter().chain(lighting::OUTPUTS).chain(tonemap::OUTPUTS) {
            targets.create(gpu, *d);
        }
        let lights = gpu_lights(scene, 0.0, settings.shadow.resolution);
        let shadow = shadow::ShadowPass::new(gpu, &scene_gpu, &lights, &settings.shadow);
        let gbuffer = gbuffer::GBufferPass::new(gpu, &scene_gpu);
        let lighting = lighting::LightingPass::new(
            gpu,
            &scene_gpu,
            &targets,
            &shadow,
            &lights,
            settings.shadow.resolution,
            &settings.lighting,
        );
        let tonemap = tonemap::TonemapPass::new(gpu, &scene_gpu, &targets, "hdr");
        let profiler = Profiler::new(gpu, 16);
        let animated = scene.objects.iter().any(|o| o.animation.is_some());
        let r = Self {
            settings,
            scene_gpu,
            targets,
            shadow,
            gbuffer,
            lighting,
            tonemap,
            profiler,
            lights,
            animated,
        };
        validate_pass_order(&r.pass_infos()).map_err(RenderError::Other)?;
        gpu.check_errors()?;
        Ok(r)
    }

    fn passes(&self) -> [&dyn Pass; 4] {
        [&self.shadow, &self.gbuffer, &self.lighting, &self.tonemap]
    }

    /// The frame's passes in order, with declared inputs and outputs.
    pub fn pass_infos(&self) -> Vec<PassInfo> {
        self.passes().iter().map(|p| p.info()).collect()
    }

    /// Renders one frame with `camera` at (fractional) frame index `frame`.
    pub fn render(
        &mut self,
        gpu: &GpuContext,
        scene: &Scene,
        camera: &Camera,
        prev_camera: &Camera,
        frame: f32,
    ) -> Result<PassTimings, RenderError> {
        camera.validate().map_err(RenderError::Parameter)?;
        let exposure = self.settings.exposure.unwrap_or(scene.settings.exposure);
        let u = FrameUniforms::new(
            scene,
            camera,
            prev_camera,
            self.settings.width,
            self.settings.height,
            frame,
            exposure,
        );
        self.scene_gpu.update_frame(gpu, &u);
        self.scene_gpu.update_objects(gpu, frame);
        if self.animated {
            self.lights = gpu_lights(scene, frame, self.settings.shadow.resolution);
            self.shadow.update(gpu, &self.lights);
            self.lighting.update_lights(gpu, &self.lights);
        }
        let mut encoder = gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("frame") });
        self.profiler.reset();
        let passes = [&self.shadow as &dyn Pass, &self.gbuffer, &self.lighting, &self.tonemap];
        for p in passes {
            let slot = self.profiler.begin(&mut encoder, p.info().name);
            p.encode(gpu, &self.scene_gpu, &self.targets, &mut encoder);
            self.profiler.end(&mut encoder, slot);
        }
        self.profiler.resolve(&mut encoder);
        gpu.queue.submit([encoder.finish()]);
        gpu.check_errors()?;
        self.profiler.read(gpu)
    }

    /// Names of every readable target (each can be a debug view).
    pub fn target_names(&self) -> Vec<&'static str> {
        self.targets.names().copied().collect()
    }

    /// Reads target `name` back as floats (sRGB targets decoded to linear).
    pub fn read_target(&self, gpu: &GpuContext, name: &str) -> Result<ImageBuf, RenderError> {
        let t = self.targets.try_get(name).ok_or_else(|| {
            RenderError::Parameter(format!(
                "unknown target '{name}': valid names are {}",
                self.target_names().join(", ")
            ))
        })?;
        let bytes = gpu.read_texture(&t.texture, 0)?;
        decode_texels(&bytes, t.desc.format, self.settings.width, self.settings.height)
    }

    /// Display-ready debug views: every target plus derived channels.
    pub fn debug_view_names(&self) -> Vec<String> {
        let mut v: Vec<String> = self.target_names().iter().map(|s| s.to_string()).collect();
        v.extend(["roughness", "metallic"].iter().map(|s| s.to_string()));
        v.sort();
        v
    }

    /// A debug view as an image: normals mapped to 0.5 + 0.5·n, depths normalised
    /// to [0, 1] by their maximum (`exr_raw` keeps raw values for EXR output).
    pub fn debug_view(&self, gpu: &GpuContext, name: &str, exr_raw: bool) -> Result<ImageBuf, RenderError> {
        match name {
            "normal" => {
                let n = self.read_normals(gpu)?;
                let mut img = ImageBuf::new(n.width, n.height, 3);
                for (o, p) in img.data.chunks_exact_mut(3).zip(n.data.chunks_exact(3)) {
                    for c in 0..3 {
                        o[c] = if exr_raw { p[c] } else { 0.5 + 0.5 * p[c] };
                    }
                }
                Ok(img)
            }
            "roughness" | "metallic" => {
                let t = self.read_target(gpu, "normal")?;
                Ok(t.channel(if name == "roughness" { 2 } else { 3 }))
            }
            "csz" | "depth" => {
                let mut img = self.read_target(gpu, name)?.channel(0);
                if !exr_raw {
                    let max = img.data.iter().cloned().fold(0.0f32, f32::max).max(1e-9);
                    img.data.iter_mut().for_each(|v| *v /= max);
                }
                Ok(img)
            }
            _ => {
                if !self.debug_view_names().iter().any(|n| n == name) {
                    return Err(RenderError::Parameter(format!(
                        "unknown debug view '{name}': valid views are {}",
                        self.debug_view_names().join(", ")
                    )));
                }
                self.read_target(gpu, name)
            }
        }
    }

    /// World-space G-buffer normals (decoded Oct16), 3 channels; zero where no surface.
    pub fn read_normals(&self, gpu: &GpuContext) -> Result<ImageBuf, RenderError> {
        let t = self.targets.get("normal");
        let bytes = gpu.read_texture(&t.texture, 0)?;
        let csz = self.read_target(gpu, "csz")?;
        let mut img = ImageBuf::new(self.settings.width, self.settings.height, 3);
        for (i, px) in bytes.chunks_exact(4).enumerate() {
            if csz.data[i] > 0.0 {
                let n = crate::packing::oct16_unpack([px[0], px[1]]);
                img.data[i * 3..i * 3 + 3].copy_from_slice(&n.to_array());
            }
        }
        Ok(img)
    }
}

/// Decodes tightly packed texels of the formats strata renders into floats.
pub fn decode_texels(bytes: &[u8], format: wgpu::TextureFormat, w: u32, h: u32) -> Result<ImageBuf, RenderError> {
    use wgpu::TextureFormat as F;
    let n = (w * h) as usize;
    let (channels, data): (u32, Vec<f32>) = match format {
        F::R32Float | F::Depth32Float => (1, bytemuck::cast_slice::<u8, f32>(bytes).to_vec()),
        F::R16Float => (
            1,
            bytemuck::cast_slice::<u8, u16>(bytes)
                .iter()
                .map(|&h| f16_to_f32(h))
                .collect(),
        ),
        F::Rgba16Float => (
            4,
            bytemuck::cast_slice::<u8, u16>(bytes)
                .iter()
                .map(|&h| f16_to_f32(h))
                .collect(),
        ),
        F::Rgba32Float => (4, bytemuck::cast_slice::<u8, f32>(bytes).to_vec()),
        F::Rgba8Unorm => (4, bytes.iter().map(|&b| b as f32 / 255.0).collect()),
        F::Rgba8UnormSrgb => (
            4,
            bytes
                .iter()
                .enumerate()
                .map(|(i, &b)| {
                    if i % 4 == 3 {
                        b as f32 / 255.0
                    } else {
                        strata_scene::model::srgb_to_linear(b)
                    }
                })
                .collect(),
        ),
        f => return Err(RenderError::Other(format!("no read-back decoder for {f:?}"))),
    };
    debug_assert_eq!(data.len(), n * channels as usize);
    Ok(ImageBuf {
        width: w,
        height: h,
        channels,
        data,
    })
}

/// IEEE half → f32.
pub fn f16_to_f32(h: u16) -> f32 {
    let s = ((h >> 15) & 1) as u32;
    let e = ((h >> 10) & 0x1f) as u32;
    let m = (h & 0x3ff) as u32;
    let bits = if e == 0 {
        if m == 0 {
            s << 31
        } else {
            // subnormal: renormalise
            let mut e2 = 127 - 15 + 1;
            let mut m2 = m;
            while m2 & 0x400 == 0 {
                m2 <<= 1;
                e2 -= 1;
            }
            (s << 31) | ((e2 as u32) << 23) | ((m2 & 0x3ff) << 13)
        }
    } else if e == 31 {
        (s << 31) | (0xff << 23) | (m << 13)
    } else {
        (s << 31) | ((e + 127 - 15) << 23) | (m << 13)
    };
    f32::from_bits(bits)
}
