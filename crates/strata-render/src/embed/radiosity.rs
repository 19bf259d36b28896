//! Deep-G-buffer screen-space radiosity (DGB §3.2–3.3) on an application's G-buffer: the
//! passes of `strata render --technique full` from the gather to the bilateral
//! reconstruction, without strata's lighting, light probes or composite.
//!
//! The application gives, per layer, what DGB's radiosity reads: depth and normals (as
//! for [`super::EmbeddedAo`]), the diffuse albedo ρ, and the outgoing diffuse radiance B
//! its own lighting computed (Lambertian direct light + emission, linear HDR). It gets
//! back [`EmbeddedRadiosity::output`]: layer 0's indirect irradiance E (rgb) and the
//! gather's confidence (a). The application composes `direct + ρ/π · E` itself, where
//! confidence is low blending in its own coarse-scale fallback (DGB §3.2 uses static
//! light probes there).

use super::core::{Core, CoreConfig, Shading};
use super::{AoInputs, NormalEncoding, NormalSpace, TextureLayer};
use crate::frame::{FrameUniforms, Pass, TargetDesc};
use crate::passes::deep_gbuffer::{DeepGBufferSettings, Variant};
use crate::passes::radiosity::stage::RadiosityStage;
use crate::passes::radiosity::{RadiositySettings, RadiosityUniforms};
use crate::RenderError;

/// What [`EmbeddedRadiosity::new`] builds.
#[derive(Clone, Debug)]
pub struct EmbeddedRadiosityConfig {
    /// The application's render size in pixels (the inputs' size).
    pub width: u32,
    pub height: u32,
    /// Deep G-buffer layers k: 1, or 2 with a second layer's inputs each frame.
    pub layers: u32,
    /// The radiosity settings of `strata render --technique full`; `radius` (the
    /// world-space gather radius) is required. Probe settings are not read, nor is
    /// `boost`: Eq. 7 acts in the composite, which is the application's.
    pub settings: RadiositySettings,
    /// Δz of the application's second layer, world units (DGB §2's minimum separation;
    /// the gather's `tap-visibility` test takes it as the layers' thickness). Default 0.5,
    /// the paper's.
    pub min_separation: f32,
    pub normals: NormalEncoding,
    pub normal_space: NormalSpace,
}

impl Default for EmbeddedRadiosityConfig {
    /// 1×1 (set the size), one layer, [`RadiositySettings::default`] (no radius: set it),
    /// Δz = 0.5, signed world-space normals.
    fn default() -> Self {
        Self {
            width: 1,
            height: 1,
            layers: 1,
            settings: RadiositySettings::default(),
            min_separation: 0.5,
            normals: NormalEncoding::Signed,
            normal_space: NormalSpace::World,
        }
    }
}

/// One frame's inputs to [`EmbeddedRadiosity::encode`].
#[derive(Clone, Copy, Debug)]
pub struct RadiosityInputs<'a> {
    /// Depth, normals, the second layer's pair, motion, view and projection.
    pub gbuffer: AoInputs<'a>,
    /// Diffuse albedo ρ of the visible surface (rgb; an sRGB format is decoded).
    pub albedo: TextureLayer<'a>,
    /// Its outgoing diffuse radiance B: Lambertian direct light + emission (linear rgb).
    pub radiance: TextureLayer<'a>,
    /// The second layer's albedo and radiance; required with 2 layers.
    pub second: Option<(TextureLayer<'a>, TextureLayer<'a>)>,
}

/// The radiosity passes of `strata render --technique full` on an application's G-buffer.
pub struct EmbeddedRadiosity {
    core: Core,
    config: EmbeddedRadiosityConfig,
    stage: RadiosityStage,
}

super::embedded_common!(EmbeddedRadiosity, EmbeddedRadiosityConfig, resize);

impl EmbeddedRadiosity {
    /// Builds the passes for `config` on the application's device. Errors name the
    /// parameter and its valid range.
    pub fn new(
        adapter: &wgpu::Adapter,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        config: EmbeddedRadiosityConfig,
    ) -> Result<Self, RenderError> {
        let what = "embedded radiosity";
        let s = &config.settings;
        let radius = super::required_radius(what, s.radius, "the world-space gather radius", s.validate())?;
        let needed = wgpu::Features::RG11B10UFLOAT_RENDERABLE;
        if !device.features().contains(needed) {
            return Err(RenderError::Parameter(format!(
                "{what}: the device lacks {needed:?}, which DGB Table 1's radiosity buffers need: request it when opening the device"
            )));
        }
        let dz = config.min_separation;
        if !(dz >= 0.0 && dz.is_finite()) {
            return Err(RenderError::Parameter(format!(
                "{what}: min_separation {dz} is out of range: must be >= 0 (world units)"
            )));
        }
        let mut scene = strata_scene::Scene::default();
        scene.settings.radiosity_radius = radius;
        scene.settings.min_separation = dz;
        let core = CoreConfig {
            what,
            width: config.width,
            height: config.height,
            layers: config.layers,
            normals: config.normals,
            normal_space: config.normal_space,
            mip_levels: Some(s.mips.levels),
            kernel: s.kernel,
            shading: super::core::ShadingImport::Radiosity,
        };
        Core::scoped(device, || {
            let mut core = Core::new(adapter, device, queue, core, scene)?;
            let layers = config.layers;
            let deep = DeepGBufferSettings {
                layers,
                variant: Variant::Peel,
                min_separation: Some(dz),
                ..DeepGBufferSettings::default()
            };
            let history = s.temporal.is_some() || s.delta > 0.0;
            if history {
                core.targets.create(
                    &core.gpu,
                    TargetDesc::new("csz-history", wgpu::TextureFormat::R32Float, layers, "last frame's csz"),
                );
            }
            let stage = RadiosityStage::new(
                &core.gpu,
                &core.scene_gpu,
                &mut core.targets,
                &deep,
                s,
                0,
                None,
                0.0,
                false,
            );
            let mut copies = Vec::new();
            if history {
                copies.push(("csz", "csz-history"));
            }
            if stage.temporal.is_some() {
                let [n, h] = crate::passes::radiosity::stage::INDIRECT_FRAMES;
                copies.extend([("indirect-temporal", "indirect-temporal-history"), (n, h)]);
            }
            if stage.propagate.is_some() {
                // the next bounce reflects this frame's E (DGB §3.3)
                copies.push(("indirect", "indirect-history"));
                if layers > 1 {
                    copies.push(("indirect1-raw", "indirect1-history"));
                }
            }
            core.history.copies = copies;
            Ok(Self {
                core,
                config: config.clone(),
                stage,
            })
        })
    }

    /// Layer 0's indirect irradiance E (rgb) and the gather's confidence (a), `Rgba16Float`,
    /// written by the last [`EmbeddedRadiosity::encode`] once its encoder is submitted.
    pub fn output(&self) -> &wgpu::Texture {
        &self.core.targets.get("indirect").texture
    }

    /// A view of [`EmbeddedRadiosity::output`] to bind in the application's composite.
    pub fn output_view(&self) -> &wgpu::TextureView {
        &self.core.targets.get("indirect").view
    }

    /// Records this frame's radiosity into `encoder` and writes its uniforms with the
    /// queue: submit `encoder` before the next call. Inputs are checked first; a bad one is
    /// a one-line error and nothing is recorded.
    pub fn encode(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        inputs: &RadiosityInputs<'_>,
    ) -> Result<(), RenderError> {
        let mut shading: Vec<Shading<'_>> = vec![(Some(inputs.albedo), inputs.radiance)];
        match (self.config.layers, inputs.second) {
            (2, Some((albedo, radiance))) => shading.push((Some(albedo), radiance)),
            (2, None) => return Err(RenderError::Parameter(
                "embedded radiosity: 2 layers need RadiosityInputs::second (the second layer's albedo and radiance)"
                    .into(),
            )),
            (_, Some(_)) => {
                return Err(RenderError::Parameter(
                    "embedded radiosity: RadiosityInputs::second is given but the config has 1 layer".into(),
                ))
            }
            _ => {}
        }
        let cam = self.core.check_inputs(&inputs.gbuffer, &shading, None)?;
        let (frame, has_history): (FrameUniforms, bool) = self.core.begin(&inputs.gbuffer, &cam);
        let gpu = &self.core.gpu;
        let u = RadiosityUniforms::new(
            &self.config.settings,
            &self.core.scene,
            &frame,
            self.core.max_mip(),
            self.core.frames,
            self.config.min_separation,
        );
        self.stage.set_frame(gpu, u);
        if let Some(p) = &self.stage.propagate {
            p.set_frame(gpu, has_history);
        }
        if let Some(t) = &self.stage.temporal {
            t.set_frame(gpu, has_history);
        }
        let passes: Vec<&dyn Pass> = self.stage.passes();
        self.core.record(encoder, &inputs.gbuffer, &shading, None, passes);
        Ok(())
    }
}
