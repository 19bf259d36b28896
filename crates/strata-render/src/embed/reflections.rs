//! Deep-G-buffer mirror reflections (DGB §3.6) on an application's G-buffer: the pass of
//! `strata render --technique full`, a camera-space ray march tested against every
//! layer, without strata's composite; the environment is the application's cube map, if
//! it gives one.
//!
//! The application gives, per layer, depth and normals (as for [`super::EmbeddedAo`]) and
//! the outgoing radiance a reflection ray that hits the layer sees: layer 0's shaded image
//! and the second layer's lit radiance (linear HDR). Layer 0's roughness and metallic come
//! from its material texture: a pixel is a mirror where metallic ≥ ½ and roughness ≤
//! `settings.max_roughness`. It gets back [`EmbeddedReflections::output`]: the reflected
//! radiance (rgb) and what the ray found (a): 0 not a mirror, 1 no hit (the ray left the
//! buffer or went `max_distance`: the application's environment cube map along the ray,
//! [`EmbeddedReflectionsConfig::environment`], or the application's own), 2 a layer-0
//! surface, 3 a second-layer surface. The application weights it by its own Fresnel term
//! and adds it to its image.
//!
//! ```no_run
//! # fn frame(adapter: &wgpu::Adapter, device: &wgpu::Device, queue: &wgpu::Queue,
//! #          depth: &wgpu::Texture, normals: &wgpu::Texture, material: &wgpu::Texture,
//! #          hdr: &wgpu::Texture, view: glam::Mat4, proj: glam::Mat4)
//! #          -> Result<(), strata_render::RenderError> {
//! use strata_render::embed::{AoInputs, EmbeddedReflections, EmbeddedReflectionsConfig, ReflectionInputs};
//! let mut refl = EmbeddedReflections::new(adapter, device, queue, EmbeddedReflectionsConfig {
//!     width: 1280,
//!     height: 720,
//!     ..EmbeddedReflectionsConfig::default()
//! })?;
//! let mut encoder = device.create_command_encoder(&Default::default());
//! // ... the application's geometry and lighting passes write its G-buffer and `hdr` ...
//! refl.encode(&mut encoder, &ReflectionInputs {
//!     gbuffer: AoInputs::new(depth.into(), normals.into(), view, proj),
//!     material: material.into(),
//!     radiance: hdr.into(),
//!     second_radiance: None,
//! })?;
//! queue.submit([encoder.finish()]);
//! // add F · refl.output() to the image where its alpha is 2 or 3 (and 1 with an
//! // environment in the config; without one, F · the application's environment there)
//! # Ok(()) }
//! ```

use super::core::{Core, CoreConfig, Shading, ShadingImport};
use super::{AoInputs, NormalEncoding, NormalSpace, TextureLayer};
use crate::frame::Pass;
use crate::passes::reflections::{ReflectedLight, ReflectionPass, ReflectionSettings, OUTPUTS};
use crate::RenderError;

/// The channels of the application's material texture that hold roughness and metallic
/// (0 = r, 1 = g, 2 = b, 3 = a).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MaterialChannels {
    pub roughness: u32,
    pub metallic: u32,
}

impl Default for MaterialChannels {
    /// glTF 2.0's `metallicRoughnessTexture`: roughness in g, metallic in b.
    fn default() -> Self {
        Self {
            roughness: 1,
            metallic: 2,
        }
    }
}

/// What [`EmbeddedReflections::new`] builds.
#[derive(Clone, Debug)]
pub struct EmbeddedReflectionsConfig {
    /// The application's render size in pixels (the inputs' size).
    pub width: u32,
    pub height: u32,
    /// Deep G-buffer layers k: 1, or 2 with a second layer's inputs each frame.
    pub layers: u32,
    /// The settings of `strata render --technique full`. `max_distance` and
    /// `thickness` are in world units; `thickness: None` takes `min_separation`.
    pub settings: ReflectionSettings,
    /// Δz of the application's second layer, world units (DGB §2's minimum separation):
    /// the layers' surface thickness in the hit test (DGB §3.6). Default 0.5, the paper's.
    pub min_separation: f32,
    pub normals: NormalEncoding,
    pub normal_space: NormalSpace,
    pub material: MaterialChannels,
    /// The application's environment: a cube map (a 2D texture of 6 square layers in
    /// WebGPU's face order +x, −x, +y, −y, +z, −z, world-space directions, a filterable
    /// float format, `TEXTURE_BINDING` usage). A ray that finds no surface takes its
    /// radiance along the ray (mip 0, bilinear); `None`: rgb 0 there, for the
    /// application's own composite.
    pub environment: Option<wgpu::Texture>,
}

impl Default for EmbeddedReflectionsConfig {
    /// 1×1 (set the size), one layer, [`ReflectionSettings::default`], Δz = 0.5, signed
    /// world-space normals, glTF's material channels, no environment.
    fn default() -> Self {
        Self {
            width: 1,
            height: 1,
            layers: 1,
            settings: ReflectionSettings::default(),
            min_separation: 0.5,
            normals: NormalEncoding::Signed,
            normal_space: NormalSpace::World,
            material: MaterialChannels::default(),
            environment: None,
        }
    }
}

/// The cube view of an application's environment ([`EmbeddedReflectionsConfig::environment`]),
/// or a one-line error naming what is wrong.
fn environment_view(device: &wgpu::Device, t: &wgpu::Texture) -> Result<wgpu::TextureView, RenderError> {
    let what = "embedded reflections: environment";
    let (w, h, n) = (t.width(), t.height(), t.depth_or_array_layers());
    if t.dimension() != wgpu::TextureDimension::D2 || n != 6 || w != h {
        return Err(RenderError::Parameter(format!(
            "{what} is a {:?} texture of {w}x{h}x{n}: must be a cube map, a 2D texture of 6 square layers",
            t.dimension()
        )));
    }
    let f = t.format();
    if !matches!(
        f.sample_type(None, Some(device.features())),
        Some(wgpu::TextureSampleType::Float { filterable: true })
    ) {
        return Err(RenderError::Parameter(format!(
            "{what} format {f:?} is not a filterable float format on this device (e.g. Rgba16Float, Rgba8Unorm)"
        )));
    }
    if !t.usage().contains(wgpu::TextureUsages::TEXTURE_BINDING) {
        return Err(RenderError::Parameter(format!("{what} lacks TEXTURE_BINDING usage")));
    }
    Ok(t.create_view(&wgpu::TextureViewDescriptor {
        label: Some("embedded reflections environment"),
        dimension: Some(wgpu::TextureViewDimension::Cube),
        ..Default::default()
    }))
}

/// One frame's inputs to [`EmbeddedReflections::encode`].
#[derive(Clone, Copy, Debug)]
pub struct ReflectionInputs<'a> {
    /// Depth, normals, the second layer's pair and the camera (motion is not read).
    pub gbuffer: AoInputs<'a>,
    /// Layer 0's roughness and metallic ([`EmbeddedReflectionsConfig::material`]'s
    /// channels, linear: not an sRGB format).
    pub material: TextureLayer<'a>,
    /// Layer 0's outgoing radiance: the application's shaded image (linear rgb).
    pub radiance: TextureLayer<'a>,
    /// The second layer's outgoing radiance; required with 2 layers.
    pub second_radiance: Option<TextureLayer<'a>>,
}

/// The reflection pass of `strata render --technique full` on an application's
/// G-buffer.
pub struct EmbeddedReflections {
    core: Core,
    config: EmbeddedReflectionsConfig,
    stage: ReflectionPass,
}

/// Lets [`super::embedded_common`] list the one pass like a stage's.
impl ReflectionPass {
    fn passes(&self) -> Vec<&dyn Pass> {
        vec![self]
    }
}

super::embedded_common!(EmbeddedReflections, EmbeddedReflectionsConfig, resize);

impl EmbeddedReflections {
    /// Builds the pass for `config` on the application's device. Errors name the
    /// parameter and its valid range.
    pub fn new(
        adapter: &wgpu::Adapter,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        config: EmbeddedReflectionsConfig,
    ) -> Result<Self, RenderError> {
        let what = "embedded reflections";
        let s = &config.settings;
        s.validate()
            .map_err(|e| RenderError::Parameter(format!("{what}: {e}")))?;
        let dz = config.min_separation;
        if !(dz > 0.0 && dz.is_finite()) {
            return Err(RenderError::Parameter(format!(
                "{what}: min_separation {dz} is out of range: must be > 0 (world units)"
            )));
        }
        let m = config.material;
        for (name, c) in [("roughness", m.roughness), ("metallic", m.metallic)] {
            if c > 3 {
                return Err(RenderError::Parameter(format!(
                    "{what}: material.{name} channel {c} is out of range: must be in 0..=3 (r, g, b, a)"
                )));
            }
        }
        let core = CoreConfig {
            what,
            width: config.width,
            height: config.height,
            layers: config.layers,
            normals: config.normals,
            normal_space: config.normal_space,
            mip_levels: None,
            kernel: s.kernel,
            shading: ShadingImport::Reflections {
                roughness: m.roughness,
                metallic: m.metallic,
            },
        };
        let environment = config
            .environment
            .as_ref()
            .map(|t| environment_view(device, t))
            .transpose()?;
        let mut scene = strata_scene::Scene::default();
        scene.settings.min_separation = dz;
        Core::scoped(device, || {
            let mut core = Core::new(adapter, device, queue, core, scene)?;
            let stage = ReflectionPass::new(
                &core.gpu,
                &core.scene_gpu,
                &mut core.targets,
                config.layers,
                "hdr",
                s,
                ReflectedLight {
                    environment: environment.as_ref(),
                    ..Default::default()
                },
            );
            Ok(Self {
                core,
                config: config.clone(),
                stage,
            })
        })
    }

    /// The reflected radiance (rgb) and what each ray found (a: 0 not a mirror, 1 no hit,
    /// 2 layer 0, 3 the second layer), `Rgba16Float`, written by the last
    /// [`EmbeddedReflections::encode`] once its encoder is submitted. Where a = 1, rgb is
    /// the environment's radiance along the ray
    /// ([`EmbeddedReflectionsConfig::environment`]), or 0 without one: the application's
    /// environment belongs there.
    pub fn output(&self) -> &wgpu::Texture {
        &self.core.targets.get(OUTPUTS[0].name).texture
    }

    /// A view of [`EmbeddedReflections::output`] to bind in the application's composite.
    pub fn output_view(&self) -> &wgpu::TextureView {
        &self.core.targets.get(OUTPUTS[0].name).view
    }

    /// Records this frame's reflections into `encoder` and writes their uniforms with the
    /// queue: submit `encoder` before the next call. Inputs are checked first; a bad one is
    /// a one-line error and nothing is recorded.
    pub fn encode(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        inputs: &ReflectionInputs<'_>,
    ) -> Result<(), RenderError> {
        let mut shading: Vec<Shading<'_>> = vec![(None, inputs.radiance)];
        match (self.config.layers, inputs.second_radiance) {
            (2, Some(radiance)) => shading.push((None, radiance)),
            (2, None) => {
                return Err(RenderError::Parameter(
                    "embedded reflections: 2 layers need ReflectionInputs::second_radiance (the second layer's outgoing radiance)"
                        .into(),
                ))
            }
            (_, Some(_)) => {
                return Err(RenderError::Parameter(
                    "embedded reflections: ReflectionInputs::second_radiance is given but the config has 1 layer".into(),
                ))
            }
            _ => {}
        }
        let cam = self
            .core
            .check_inputs(&inputs.gbuffer, &shading, Some(inputs.material))?;
        self.core.begin(&inputs.gbuffer, &cam);
        self.stage.set_frame(&self.core.gpu, self.config.min_separation);
        let passes: Vec<&dyn Pass> = self.stage.passes();
        self.core
            .record(encoder, &inputs.gbuffer, &shading, Some(inputs.material), passes);
        Ok(())
    }
}
