//! Deep-G-buffer ambient occlusion (DGB §3.1), screen-space radiosity (§3.2–3.3,
//! [`EmbeddedRadiosity`]) and mirror reflections (§3.6, [`EmbeddedReflections`]), the
//! bounced z-buffer's AO ([`EmbeddedBzbAo`]) and interleaved deferred shading of the
//! application's VPLs ([`EmbeddedIls`]) inside an application's own wgpu renderer
//! (`docs/embed.md`).
//!
//! The application draws its scene as usual, into a depth texture and a normal texture
//! (and, for DGB's second layer, a second pair). Each frame, [`EmbeddedAo::encode`] records
//! strata's AO passes into the application's command encoder. They are the passes
//! `strata render --technique ao` runs: Eq. 1–2 over the depth MIP chain, the temporal
//! filter (§3.3) and the bilateral reconstruction. The result is [`EmbeddedAo::output`], the
//! ambient visibility AV in [0, 1] (1 = unoccluded) at the application's resolution.
//!
//! ```no_run
//! # fn frame(adapter: &wgpu::Adapter, device: &wgpu::Device, queue: &wgpu::Queue,
//! #          depth: &wgpu::Texture, normals: &wgpu::Texture, view: glam::Mat4, proj: glam::Mat4)
//! #          -> Result<(), strata_render::RenderError> {
//! use strata_render::embed::{AoInputs, EmbeddedAo, EmbeddedAoConfig, NormalEncoding};
//! use strata_render::passes::ao::AoSettings;
//! let mut ao = EmbeddedAo::new(adapter, device, queue, EmbeddedAoConfig {
//!     width: 1280,
//!     height: 720,
//!     // the world-space radius r, in the application's units
//!     settings: AoSettings { radius: Some(0.5), ..AoSettings::default() },
//!     normals: NormalEncoding::Signed,
//!     ..EmbeddedAoConfig::default()
//! })?;
//! let mut encoder = device.create_command_encoder(&Default::default());
//! // ... the application's geometry pass writes `depth` and `normals` ...
//! ao.encode(&mut encoder, &AoInputs::new(depth.into(), normals.into(), view, proj))?;
//! queue.submit([encoder.finish()]);
//! // sample ao.output_view() in the lighting pass
//! # Ok(()) }
//! ```
//!
//! Conventions (the ones wgpu and glam use by default, checked where they can be):
//! - `proj` is a perspective projection with a symmetric frustum, or one jittered by up to
//!   [`MAX_JITTER_PIXELS`] (TAA: pass the jittered matrix the depth was drawn with),
//!   right- or left-handed, standard or reversed depth, finite or infinite far plane. No
//!   surface is where the depth buffer holds its clear value (1, or 0 when reversed).
//! - Pixel (x, y) is the texel whose centre is at (x + ½, y + ½), y down, as in wgpu.
//! - Without a normal buffer, [`NormalEncoding::FromDepth`] reconstructs each layer's
//!   normal from its depth ([`AoInputs::depth_only`]).
//! - `settings.radius` and the temporal filter's `max_distance` are in world units.
//! - The temporal filter reprojects with the camera of the previous call. Surfaces
//!   that move on their own follow the optional motion texture (world-space motion since
//!   the last frame, rgb); without it a moving object's history is rejected and restarts.
//!   Call [`EmbeddedAo::reset_history`] after a camera cut.

use glam::{Mat4, Vec3, Vec4};

mod bzb;
mod core;
mod ils;
mod radiosity;
mod reflections;

pub use bzb::{indexed_triangles, EmbeddedBzbAo, EmbeddedBzbAoConfig};
pub use ils::{EmbeddedIls, EmbeddedIlsConfig};
pub use radiosity::{EmbeddedRadiosity, EmbeddedRadiosityConfig, RadiosityInputs};
pub use reflections::{EmbeddedReflections, EmbeddedReflectionsConfig, MaterialChannels, ReflectionInputs};

use self::core::{Core, CoreConfig};
use crate::frame::{FrameUniforms, Pass};
use crate::passes::ao::stage::AoStage;
use crate::passes::ao::{AoSettings, AoUniforms};
use crate::passes::deep_gbuffer::{DeepGBufferSettings, Variant};
use crate::RenderError;

/// How the application's normal texture stores a unit normal.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum NormalEncoding {
    /// xyz as signed values (e.g. `Rgba16Float`, `Rgba8Snorm`).
    #[default]
    Signed,
    /// xyz · ½ + ½ (e.g. `Rgba8Unorm`).
    Unsigned,
    /// rg = the octahedral map in [0, 1] (Cigolle et al. 2014; strata's own G-buffer).
    Octahedral,
    /// No normal texture (a forward renderer with only a depth prepass): each layer's
    /// normal is reconstructed from its depth, as the cross product of the screen-space
    /// tangents towards the neighbours nearer in depth. The normal textures of the inputs
    /// are not read ([`AoInputs::depth_only`]).
    FromDepth,
}

/// The space the application's normals are in.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum NormalSpace {
    #[default]
    World,
    /// View space of the `view` matrix passed each frame.
    View,
}

/// What [`EmbeddedAo::new`] builds.
#[derive(Clone, Debug)]
pub struct EmbeddedAoConfig {
    /// The application's render size in pixels (the inputs' size).
    pub width: u32,
    pub height: u32,
    /// Deep G-buffer layers k: 1, or 2 with a second depth and normal layer each frame.
    pub layers: u32,
    /// The AO settings of `strata render --technique ao`; `radius` is required (world units).
    pub settings: AoSettings,
    pub normals: NormalEncoding,
    pub normal_space: NormalSpace,
}

impl Default for EmbeddedAoConfig {
    /// 1×1 (set the size), one layer, [`AoSettings::default`] (no radius: set it), signed
    /// world-space normals.
    fn default() -> Self {
        Self {
            width: 1,
            height: 1,
            layers: 1,
            settings: AoSettings::default(),
            normals: NormalEncoding::Signed,
            normal_space: NormalSpace::World,
        }
    }
}

/// Most layers [`EmbeddedAoConfig::layers`] takes.
pub const MAX_LAYERS: u32 = 2;

/// One array layer of an application texture (layer 0 of a plain 2D texture).
#[derive(Clone, Copy, Debug)]
pub struct TextureLayer<'a> {
    pub texture: &'a wgpu::Texture,
    pub layer: u32,
}

impl<'a> From<&'a wgpu::Texture> for TextureLayer<'a> {
    fn from(texture: &'a wgpu::Texture) -> Self {
        Self { texture, layer: 0 }
    }
}

/// One frame's inputs to [`EmbeddedAo::encode`].
#[derive(Clone, Copy, Debug)]
pub struct AoInputs<'a> {
    /// Hardware depth of the visible surface (a depth format, single-sampled,
    /// `TEXTURE_BINDING`).
    pub depth: TextureLayer<'a>,
    /// Its normals (a float, unorm or snorm format; [`EmbeddedAoConfig::normals`]).
    pub normals: TextureLayer<'a>,
    /// The second layer's depth and normals (DGB §2: the nearest surface at least Δz
    /// behind the first); required with 2 layers.
    pub second: Option<(TextureLayer<'a>, TextureLayer<'a>)>,
    /// World-space motion of the visible surface since the last frame (rgb); `None`: static.
    pub motion: Option<TextureLayer<'a>>,
    /// World → view transform (rigid: no scale) and projection the depth was drawn with.
    pub view: Mat4,
    pub proj: Mat4,
}

impl<'a> AoInputs<'a> {
    /// One layer, no motion.
    pub fn new(depth: TextureLayer<'a>, normals: TextureLayer<'a>, view: Mat4, proj: Mat4) -> Self {
        Self {
            depth,
            normals,
            second: None,
            motion: None,
            view,
            proj,
        }
    }

    /// One layer of depth alone, for [`NormalEncoding::FromDepth`]: `normals` holds the
    /// depth texture too, and is not read. (A second layer is `Some((depth1, depth1))`.)
    pub fn depth_only(depth: TextureLayer<'a>, view: Mat4, proj: Mat4) -> Self {
        Self::new(depth, depth, view, proj)
    }
}

/// Largest sub-pixel jitter (TAA) [`CameraModel::of`] takes in an off-centre projection, in
/// pixels per axis; a larger offset is an asymmetric frustum, which it refuses.
pub const MAX_JITTER_PIXELS: f32 = 2.0;

/// The camera a perspective `proj` and `view` describe, in strata's model: the frame's
/// uniforms (eye, the basis scaled to the frustum) and the import's constants.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraModel {
    /// w_clip = w_sign · z_view: −1 right-handed (wgpu, glam `_rh`), +1 left-handed.
    pub w_sign: f32,
    /// Reversed depth: the far plane (or infinity) at 0, the near plane at 1.
    pub reversed: bool,
    /// Camera-space z of the near plane.
    pub near: f32,
    /// `proj` without its sub-pixel jitter (TAA): the symmetric frustum strata's camera
    /// model describes. The import inverts the jittered `proj`, at whose pixel centres the
    /// depth was drawn; the AO reconstructs positions at the unjittered centres, less than
    /// [`MAX_JITTER_PIXELS`] away.
    pub unjittered: Mat4,
}

impl CameraModel {
    /// Checks that `proj` is a perspective projection, symmetric up to a sub-pixel jitter at
    /// `width`×`height`, and reads its conventions.
    pub fn of(proj: Mat4, width: u32, height: u32) -> Result<Self, RenderError> {
        let bad = |why: &str| RenderError::Parameter(format!("proj {why}"));
        let p = proj.to_cols_array_2d();
        if !p.iter().flatten().all(|v| v.is_finite()) {
            return Err(bad("has a non-finite entry"));
        }
        let w_sign = p[2][3];
        // w_clip = ±z_view and nothing else: a perspective projection
        let translated = p[3][0] != 0.0 || p[3][1] != 0.0;
        if (w_sign.abs() - 1.0).abs() > 1e-6 || p[0][3] != 0.0 || p[1][3] != 0.0 || p[3][3] != 0.0 || translated {
            return Err(bad(
                "is not a perspective projection (its w row must be (0, 0, ±1, 0) and x, y must not depend on w; an orthographic projection is not supported)",
            ));
        }
        if p[0][1] != 0.0 || p[1][0] != 0.0 {
            return Err(bad(
                "has a skewed frustum (x and y mixed): strata's camera model is not skewed",
            ));
        }
        // an off-centre frustum shifts NDC by proj[2][0..2] · w_sign: 2/size per pixel
        let jitter = [p[2][0].abs() * width as f32 / 2.0, p[2][1].abs() * height as f32 / 2.0];
        if jitter.iter().any(|j| *j > MAX_JITTER_PIXELS) {
            return Err(bad(&format!(
                "is off-centre by ({:.2}, {:.2}) pixels: a sub-pixel (TAA) jitter up to {MAX_JITTER_PIXELS} pixels is taken, an asymmetric frustum is not",
                jitter[0], jitter[1]
            )));
        }
        let mut unjittered = proj;
        unjittered.z_axis.x = 0.0;
        unjittered.z_axis.y = 0.0;
        if !(p[0][0] > 0.0 && p[1][1] > 0.0) {
            return Err(bad("has a non-positive x or y scale: x must map right and y up"));
        }
        // the NDC depth of a point infinitely far away: ≥ 1 standard, ≤ 0 reversed
        let far = p[2][2] * w_sign;
        let reversed = far < 0.5;
        let inv = proj.inverse();
        let near_ndc = if reversed { 1.0 } else { 0.0 };
        let v = inv * Vec4::new(0.0, 0.0, near_ndc, 1.0);
        let near = w_sign * v.z / v.w;
        if !(near > 0.0 && near.is_finite()) {
            return Err(bad("puts its near plane at or behind the eye"));
        }
        Ok(Self {
            w_sign,
            reversed,
            near,
            unjittered,
        })
    }

    /// The frame's uniforms of strata's camera model for `view` and the unjittered
    /// projection at `width`×`height`; `prev_view_proj` (unjittered too) reprojects.
    pub fn frame_uniforms(&self, view: Mat4, prev_view_proj: Mat4, width: u32, height: u32) -> FrameUniforms {
        let proj = self.unjittered;
        let inv_view = view.inverse();
        let eye = inv_view.transform_point3(Vec3::ZERO);
        let right = inv_view.transform_vector3(Vec3::X).normalize();
        let up = inv_view.transform_vector3(Vec3::Y).normalize();
        let forward = inv_view.transform_vector3(Vec3::Z * self.w_sign).normalize();
        let vp = proj * view;
        let p = proj.to_cols_array_2d();
        FrameUniforms {
            view: view.to_cols_array_2d(),
            proj: p,
            view_proj: vp.to_cols_array_2d(),
            inv_view_proj: vp.inverse().to_cols_array_2d(),
            prev_view_proj: prev_view_proj.to_cols_array_2d(),
            next_view_proj: vp.to_cols_array_2d(),
            eye: eye.extend(self.near).to_array(),
            // pixel_dir = forward + right·ndc_x + up·ndc_y has forward component 1
            cam_right: (right / p[0][0]).extend(0.0).to_array(),
            cam_up: (up / p[1][1]).extend(0.0).to_array(),
            cam_forward: forward.extend(0.0).to_array(),
            size: [width as f32, height as f32, 1.0 / width as f32, 1.0 / height as f32],
            sky: [0.0; 4],
            ambient: [0.0; 4],
        }
    }
}

/// A one-line error for the first triangle with a non-finite vertex; `first` is the index
/// of `triangles[0]` in the whole list (`what` names the technique).
fn check_triangles(what: &str, triangles: &[[glam::Vec3; 3]], first: usize) -> Result<(), RenderError> {
    match triangles.iter().position(|t| !t.iter().all(|p| p.is_finite())) {
        Some(i) => Err(RenderError::Parameter(format!(
            "{what}: triangles[{}] has a non-finite vertex ({:?})",
            first + i,
            triangles[i]
        ))),
        None => Ok(()),
    }
}

/// The settings' world-space radius, required (`meaning` names it in the error), once the
/// settings validate: the one-line errors every embedded technique's `new` gives first.
fn required_radius(
    what: &str,
    radius: Option<f32>,
    meaning: &str,
    valid: Result<(), String>,
) -> Result<f32, RenderError> {
    let r = radius.ok_or_else(|| {
        RenderError::Parameter(format!(
            "{what}: settings.radius is required: {meaning} (> 0, in the application's units)"
        ))
    })?;
    valid.map_err(|e| RenderError::Parameter(format!("{what}: {e}")))?;
    Ok(r)
}

/// A rotation (or a reflection, for left-handed views) and a translation: camera-space z
/// is then in world units, as the AO radius is.
fn is_rigid(m: Mat4) -> bool {
    let a = glam::Mat3::from_mat4(m);
    let cols = [a.x_axis, a.y_axis, a.z_axis];
    m.is_finite()
        && m.row(3) == Vec4::W
        && cols.iter().all(|c| (c.length() - 1.0).abs() < 1e-3)
        && (0..3).all(|i| cols[i].dot(cols[(i + 1) % 3]).abs() < 1e-3)
}

/// Depth formats the import reads (their depth aspect).
fn is_depth(format: wgpu::TextureFormat) -> bool {
    use wgpu::TextureFormat as F;
    matches!(
        format,
        F::Depth16Unorm | F::Depth24Plus | F::Depth24PlusStencil8 | F::Depth32Float | F::Depth32FloatStencil8
    )
}

/// The methods every embedded technique has, over its `core`, `stage` and `config`.
macro_rules! embedded_common {
    ($t:ty, $config:ty) => {
        impl $t {
            /// Any intermediate target by its `strata render --list-passes` name (`zpack`,
            /// `npack`, `zmip`, `ao-raw`, `indirect-raw`, …), for debugging.
            pub fn target(&self, name: &str) -> Option<&wgpu::Texture> {
                self.core.targets.try_get(name).map(|t| &t.texture)
            }

            /// Reads layer 0 of target `name` back as floats (after the submitted frames),
            /// for tests and debugging: the output, `zpack`, `npack`, `zmip`, ….
            pub fn read_target(&self, name: &str) -> Result<strata_scene::ImageBuf, RenderError> {
                self.core.read_target(name)
            }

            /// GPU milliseconds per pass of the last submitted frame (waits for it). Empty
            /// unless the application's device has `TIMESTAMP_QUERY |
            /// TIMESTAMP_QUERY_INSIDE_ENCODERS`.
            pub fn timings(&self) -> Result<crate::PassTimings, RenderError> {
                self.core.timings()
            }

            /// The pass names `encode` records, in order.
            pub fn pass_names(&self) -> Vec<&'static str> {
                self.core.pass_names(self.stage.passes())
            }

            /// Forget the temporal history (a camera cut, a new scene): the next frame
            /// starts afresh, and so do the radiosity's progressive bounces.
            pub fn reset_history(&mut self) {
                self.core.reset_history();
            }

            /// The application's config.
            pub fn config(&self) -> &$config {
                &self.config
            }
        }
    };
    ($t:ty, $config:ty, resize) => {
        $crate::embed::embedded_common!($t, $config);

        impl $t {
            /// Rebuilds the passes for a new render size (a resized window), keeping the
            /// rest of the config; the temporal history starts afresh. On error the old
            /// size stays.
            pub fn resize(&mut self, width: u32, height: u32) -> Result<(), RenderError> {
                let mut config = self.config.clone();
                config.width = width;
                config.height = height;
                let gpu = &self.core.gpu;
                *self = Self::new(&gpu.adapter, &gpu.device, &gpu.queue, config)?;
                Ok(())
            }
        }
    };
}
pub(crate) use embedded_common;

/// The AO passes of `strata render --technique ao` on an application's G-buffer.
pub struct EmbeddedAo {
    core: Core,
    config: EmbeddedAoConfig,
    stage: AoStage,
}

embedded_common!(EmbeddedAo, EmbeddedAoConfig, resize);

impl EmbeddedAo {
    /// Builds the passes for `config` on the application's device. Errors name the
    /// parameter and its valid range.
    pub fn new(
        adapter: &wgpu::Adapter,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        config: EmbeddedAoConfig,
    ) -> Result<Self, RenderError> {
        let what = "embedded AO";
        let s = &config.settings;
        let radius = required_radius(what, s.radius, "the world-space AO radius r", s.validate())?;
        let mut scene = strata_scene::Scene::default();
        scene.settings.ao_radius = radius;
        let core = CoreConfig {
            what,
            width: config.width,
            height: config.height,
            layers: config.layers,
            normals: config.normals,
            normal_space: config.normal_space,
            mip_levels: Some(s.mips.levels),
            kernel: s.kernel,
            shading: self::core::ShadingImport::None,
        };
        Core::scoped(device, || {
            let mut core = Core::new(adapter, device, queue, core, scene)?;
            let deep = DeepGBufferSettings {
                layers: config.layers,
                variant: Variant::Peel,
                ..DeepGBufferSettings::default()
            };
            if s.temporal.is_some() {
                core.targets.create(
                    &core.gpu,
                    crate::frame::TargetDesc::new(
                        "csz-history",
                        wgpu::TextureFormat::R32Float,
                        config.layers,
                        "last frame's csz",
                    ),
                );
            }
            let stage = AoStage::new(&core.gpu, &core.scene_gpu, &mut core.targets, &deep, s, radius)?;
            if stage.temporal.is_some() {
                let [n, h] = crate::passes::ao::stage::AO_FRAMES;
                core.history.copies = vec![("csz", "csz-history"), ("ao-temporal", "ao-temporal-history"), (n, h)];
            }
            Ok(Self {
                core,
                config: config.clone(),
                stage,
            })
        })
    }

    /// The ambient visibility AV (`R16Float`, 1 = unoccluded), written by the last
    /// [`EmbeddedAo::encode`] once its encoder is submitted.
    pub fn output(&self) -> &wgpu::Texture {
        &self.core.targets.get("ao").texture
    }

    /// A view of [`EmbeddedAo::output`] to bind in the application's lighting pass.
    pub fn output_view(&self) -> &wgpu::TextureView {
        &self.core.targets.get("ao").view
    }

    /// Records this frame's AO into `encoder` and writes its uniforms with the queue: submit
    /// `encoder` before the next call. Inputs are checked first; a bad one is a one-line
    /// error and nothing is recorded.
    pub fn encode(&mut self, encoder: &mut wgpu::CommandEncoder, inputs: &AoInputs<'_>) -> Result<(), RenderError> {
        let cam = self.core.check_inputs(inputs, &[], None)?;
        let (frame, has_history): (FrameUniforms, bool) = self.core.begin(inputs, &cam);
        let gpu = &self.core.gpu;
        let u = AoUniforms::new(
            &self.config.settings,
            &self.core.scene,
            &frame,
            self.core.max_mip(),
            self.core.frames,
        );
        self.stage.set_frame(gpu, u);
        if let Some(t) = &self.stage.temporal {
            t.set_frame(gpu, has_history);
        }
        let passes: Vec<&dyn Pass> = self.stage.passes();
        self.core.record(encoder, inputs, &[], None, passes);
        Ok(())
    }
}
