//! Deep-G-buffer ambient occlusion (DGB §3.1) inside an application's own wgpu renderer.
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
//! - `settings.radius` and the temporal filter's `max_distance` are in world units.
//! - The temporal filter reprojects with the camera of the previous call. Surfaces
//!   that move on their own follow the optional motion texture (world-space motion since
//!   the last frame, rgb); without it a moving object's history is rejected and restarts.
//!   Call [`EmbeddedAo::reset_history`] after a camera cut.

use glam::{Mat4, Vec3, Vec4};

use crate::frame::{FrameUniforms, Pass, TargetDesc, Targets};
use crate::gpu::GpuContext;
use crate::passes::ao::stage::AoStage;
use crate::passes::ao::{AoSettings, AoUniforms};
use crate::passes::deep_gbuffer::{DeepGBufferSettings, Variant};
use crate::passes::depth_mip::{DepthMipPass, DepthMipSettings};
use crate::passes::HistoryPass;
use crate::scene_gpu::GpuScene;
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
}

/// Mirrors `Import` in `import.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct ImportUniforms {
    inv_proj: [[f32; 4]; 4],
    inv_view: [[f32; 4]; 4],
    size: [f32; 4],
    w_sign: f32,
    reversed: u32,
    _pad: [u32; 2],
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
        let bad = |why: &str| RenderError::Parameter(format!("embedded AO: proj {why}"));
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

/// The AO passes of `strata render --technique ao` on an application's G-buffer.
pub struct EmbeddedAo {
    gpu: GpuContext,
    /// A scene without geometry: the AO's radius, and the frame uniforms' buffer.
    scene: strata_scene::Scene,
    scene_gpu: GpuScene,
    targets: Targets,
    config: EmbeddedAoConfig,
    import_pipeline: wgpu::RenderPipeline,
    import_layout: wgpu::BindGroupLayout,
    import_uniforms: wgpu::Buffer,
    /// Zeros, bound where the application gives no motion texture.
    no_motion: wgpu::TextureView,
    mip: DepthMipPass,
    stage: AoStage,
    history: HistoryPass,
    /// Per-pass GPU time where the application's device has timestamp queries inside
    /// encoders (`TIMESTAMP_QUERY | TIMESTAMP_QUERY_INSIDE_ENCODERS`).
    profiler: crate::profiler::Profiler,
    frames: u32,
    prev_view_proj: Option<Mat4>,
}

impl EmbeddedAo {
    /// Builds the passes for `config` on the application's device. Errors name the
    /// parameter and its valid range.
    pub fn new(
        adapter: &wgpu::Adapter,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        config: EmbeddedAoConfig,
    ) -> Result<Self, RenderError> {
        let s = &config.settings;
        let radius = s.radius.ok_or_else(|| {
            RenderError::Parameter(
                "embedded AO: settings.radius is required: the world-space AO radius r (> 0, in the application's units)".into(),
            )
        })?;
        s.validate().map_err(RenderError::Parameter)?;
        if !(1..=MAX_LAYERS).contains(&config.layers) {
            return Err(RenderError::Parameter(format!(
                "embedded AO: layers {} is out of range: must be in 1..={MAX_LAYERS}",
                config.layers
            )));
        }
        let max = device.limits().max_texture_dimension_2d;
        if !(1..=max).contains(&config.width) || !(1..=max).contains(&config.height) {
            return Err(RenderError::Parameter(format!(
                "embedded AO: size {}x{} is out of range: width and height must be in 1..={max}",
                config.width, config.height
            )));
        }
        let gpu = GpuContext::from_device(adapter, device, queue);
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let built = Self::build(gpu, config, radius);
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(RenderError::Validation(e.to_string()));
        }
        built
    }

    fn build(gpu: GpuContext, config: EmbeddedAoConfig, radius: f32) -> Result<Self, RenderError> {
        use wgpu::TextureFormat as F;
        let (w, h, layers) = (config.width, config.height, config.layers);
        let mut scene = strata_scene::Scene::default();
        scene.settings.ao_radius = radius;
        let scene_gpu = GpuScene::new(&gpu, &scene);
        let mut targets = Targets::new(w, h);
        let imported = [
            TargetDesc::new(
                "zpack",
                F::Rg32Float,
                1,
                "DGB Table 1: camera-space z of layers 0 (r) and 1 (g)",
            ),
            TargetDesc::new(
                "npack",
                F::Rgba8Unorm,
                1,
                "DGB Table 1: Oct16 normals of layers 0 (rg) and 1 (ba)",
            ),
            TargetDesc::new(
                "csz",
                F::R32Float,
                layers,
                "camera-space depth z per layer (0 = no surface)",
            ),
            TargetDesc::new(
                "motion",
                F::Rgba16Float,
                1,
                "world-space motion of layer 0 since last frame",
            ),
        ];
        for d in imported {
            targets.create(&gpu, d);
        }
        let deep = DeepGBufferSettings {
            layers,
            variant: Variant::Peel,
            ..DeepGBufferSettings::default()
        };
        let s = &config.settings;
        targets.create(&gpu, DepthMipSettings { levels: s.mips.levels }.output(layers, w, h));
        let mip = DepthMipPass::new(&gpu, &targets, layers);
        if s.temporal.is_some() {
            targets.create(
                &gpu,
                TargetDesc::new("csz-history", F::R32Float, layers, "last frame's csz"),
            );
        }
        let stage = AoStage::new(&gpu, &scene_gpu, &mut targets, &deep, s, radius)?;
        let mut copies = Vec::new();
        if stage.temporal.is_some() {
            copies.push(("csz", "csz-history"));
            copies.push(("ao-temporal", "ao-temporal-history"));
            let [n, h] = crate::passes::ao::stage::AO_FRAMES;
            copies.push((n, h));
        }
        let history = HistoryPass { copies };
        let profiler = crate::profiler::Profiler::new(&gpu, 16);

        let device = &gpu.device;
        let depth_entry = |binding| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::FRAGMENT,
            ty: wgpu::BindingType::Texture {
                sample_type: wgpu::TextureSampleType::Depth,
                view_dimension: wgpu::TextureViewDimension::D2,
                multisampled: false,
            },
            count: None,
        };
        let colour = |b| crate::passes::texture_entry(b, wgpu::TextureViewDimension::D2, false);
        let import_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("embed-import"),
            entries: &[
                crate::passes::uniform_entry(0),
                depth_entry(1),
                colour(2),
                depth_entry(3),
                colour(4),
                colour(5),
            ],
        });
        let pl = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("embed-import"),
            bind_group_layouts: &[Some(&import_layout)],
            immediate_size: 0,
        });
        let module = crate::shader::module(device, "embed-import", include_str!("import.wgsl"));
        let mut formats = vec![F::Rg32Float, F::Rgba8Unorm, F::R32Float, F::Rgba16Float];
        if layers == 2 {
            formats.push(F::R32Float);
        }
        let color: Vec<_> = formats.iter().map(|f| Some(wgpu::ColorTargetState::from(*f))).collect();
        let normals = match config.normals {
            NormalEncoding::Signed => 0.0,
            NormalEncoding::Unsigned => 1.0,
            NormalEncoding::Octahedral => 2.0,
        };
        let constants = [
            ("NORMALS", normals),
            ("VIEW_SPACE", (config.normal_space == NormalSpace::View) as u32 as f64),
        ];
        let entry = if layers == 2 { "fs_import2" } else { "fs_import1" };
        let import_pipeline =
            crate::passes::fullscreen_pipeline_with(device, "embed-import", &pl, &module, entry, &constants, &color);
        let import_uniforms = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("embed-import"),
            size: std::mem::size_of::<ImportUniforms>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        // zero-initialised by wgpu
        let no_motion = device
            .create_texture(&wgpu::TextureDescriptor {
                label: Some("embed-no-motion"),
                size: wgpu::Extent3d {
                    width: w,
                    height: h,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: F::Rgba16Float,
                usage: wgpu::TextureUsages::TEXTURE_BINDING,
                view_formats: &[],
            })
            .create_view(&Default::default());
        Ok(Self {
            gpu,
            scene,
            scene_gpu,
            targets,
            config,
            import_pipeline,
            import_layout,
            import_uniforms,
            no_motion,
            mip,
            stage,
            history,
            profiler,
            frames: 0,
            prev_view_proj: None,
        })
    }

    /// The ambient visibility AV (`R16Float`, 1 = unoccluded), written by the last
    /// [`EmbeddedAo::encode`] once its encoder is submitted.
    pub fn output(&self) -> &wgpu::Texture {
        &self.targets.get("ao").texture
    }

    /// A view of [`EmbeddedAo::output`] to bind in the application's lighting pass.
    pub fn output_view(&self) -> &wgpu::TextureView {
        &self.targets.get("ao").view
    }

    /// Any intermediate target by its `strata render --list-passes` name (`zpack`,
    /// `npack`, `zmip`, `ao-raw`, …), for debugging.
    pub fn target(&self, name: &str) -> Option<&wgpu::Texture> {
        self.targets.try_get(name).map(|t| &t.texture)
    }

    /// Reads layer 0 of target `name` back as floats (after the submitted frames), for
    /// tests and debugging: `ao`, `zpack`, `npack`, `ao-raw`, ….
    pub fn read_target(&self, name: &str) -> Result<strata_scene::ImageBuf, RenderError> {
        let t = self
            .targets
            .try_get(name)
            .ok_or_else(|| RenderError::Parameter(format!("embedded AO: unknown target '{name}'")))?;
        let bytes = self.gpu.read_texture(&t.texture, 0)?;
        crate::renderer::decode_texels(&bytes, t.desc.format, t.texture.width(), t.texture.height())
    }

    /// GPU milliseconds per pass of the last submitted frame (waits for it). Empty unless
    /// the application's device has `TIMESTAMP_QUERY | TIMESTAMP_QUERY_INSIDE_ENCODERS`.
    pub fn timings(&self) -> Result<crate::PassTimings, RenderError> {
        self.profiler.read(&self.gpu)
    }

    /// The pass names [`EmbeddedAo::encode`] records, in order.
    pub fn pass_names(&self) -> Vec<&'static str> {
        let mut v = vec!["embed-import", self.mip.info().name];
        v.extend(self.stage.passes().iter().map(|p| p.info().name));
        v.push(self.history.info().name);
        v
    }

    /// Rebuilds the passes for a new render size (a resized window), keeping the rest of
    /// the config; the temporal history starts afresh. On error the old size stays.
    pub fn resize(&mut self, width: u32, height: u32) -> Result<(), RenderError> {
        let config = EmbeddedAoConfig {
            width,
            height,
            ..self.config.clone()
        };
        let gpu = &self.gpu;
        *self = Self::new(&gpu.adapter, &gpu.device, &gpu.queue, config)?;
        Ok(())
    }

    /// Forget the temporal history (a camera cut, a new scene): the next frame starts afresh.
    pub fn reset_history(&mut self) {
        self.prev_view_proj = None;
    }

    /// The application's config.
    pub fn config(&self) -> &EmbeddedAoConfig {
        &self.config
    }

    /// Checks one input texture: size, usage, sampling, format kind and layer.
    fn check(&self, what: &str, t: TextureLayer<'_>, depth: bool) -> Result<(), RenderError> {
        let bad = |why: String| Err(RenderError::Parameter(format!("embedded AO: {what} {why}")));
        let tex = t.texture;
        let (w, h) = (self.config.width, self.config.height);
        if tex.width() != w || tex.height() != h {
            return bad(format!(
                "is {}x{}: it must be the configured {w}x{h} (EmbeddedAoConfig::width/height)",
                tex.width(),
                tex.height()
            ));
        }
        if tex.dimension() != wgpu::TextureDimension::D2 {
            return bad("must be a 2D texture".into());
        }
        if t.layer >= tex.depth_or_array_layers() {
            return bad(format!(
                "layer {} is out of range: must be in 0..{}",
                t.layer,
                tex.depth_or_array_layers()
            ));
        }
        if !tex.usage().contains(wgpu::TextureUsages::TEXTURE_BINDING) {
            return bad("lacks TextureUsages::TEXTURE_BINDING".into());
        }
        if tex.sample_count() != 1 {
            return bad(format!(
                "has {} samples: resolve it to a single-sampled texture first",
                tex.sample_count()
            ));
        }
        let f = tex.format();
        if depth && !is_depth(f) {
            return bad(format!(
                "has format {f:?}: it must be a depth format (Depth16Unorm, Depth24Plus[Stencil8], Depth32Float[Stencil8])"
            ));
        }
        if !depth {
            let float = matches!(
                f.sample_type(None, Some(self.gpu.features)),
                Some(wgpu::TextureSampleType::Float { .. })
            );
            if !float || f.is_depth_stencil_format() {
                return bad(format!(
                    "has format {f:?}: it must be a float, unorm or snorm colour format"
                ));
            }
            if f.is_srgb() {
                return bad(format!(
                    "has format {f:?}: an sRGB format would decode the values; use its linear twin"
                ));
            }
        }
        Ok(())
    }

    fn layer_view(t: TextureLayer<'_>, depth: bool) -> wgpu::TextureView {
        t.texture.create_view(&wgpu::TextureViewDescriptor {
            label: Some("embed-input"),
            dimension: Some(wgpu::TextureViewDimension::D2),
            aspect: if depth {
                wgpu::TextureAspect::DepthOnly
            } else {
                wgpu::TextureAspect::All
            },
            base_array_layer: t.layer,
            array_layer_count: Some(1),
            mip_level_count: Some(1),
            ..Default::default()
        })
    }

    /// Records this frame's AO into `encoder` and writes its uniforms with the queue: submit
    /// `encoder` before the next call. Inputs are checked first; a bad one is a one-line
    /// error and nothing is recorded.
    pub fn encode(&mut self, encoder: &mut wgpu::CommandEncoder, inputs: &AoInputs<'_>) -> Result<(), RenderError> {
        self.check("depth", inputs.depth, true)?;
        self.check("normals", inputs.normals, false)?;
        match (self.config.layers, &inputs.second) {
            (2, Some((d, n))) => {
                self.check("second depth", *d, true)?;
                self.check("second normals", *n, false)?;
            }
            (2, None) => {
                return Err(RenderError::Parameter(
                    "embedded AO: 2 layers need AoInputs::second (the second layer's depth and normals)".into(),
                ))
            }
            (_, Some(_)) => {
                return Err(RenderError::Parameter(
                    "embedded AO: AoInputs::second is given but the config has 1 layer (EmbeddedAoConfig::layers = 2 uses it)"
                        .into(),
                ))
            }
            _ => {}
        }
        if let Some(m) = inputs.motion {
            self.check("motion", m, false)?;
        }
        if !is_rigid(inputs.view) {
            return Err(RenderError::Parameter(
                "embedded AO: view is not a rigid transform (a rotation and a translation, without scale)".into(),
            ));
        }
        let (w, h) = (self.config.width, self.config.height);
        let cam = CameraModel::of(inputs.proj, w, h)?;
        let vp = cam.unjittered * inputs.view;
        let has_history = self.prev_view_proj.is_some();
        let frame = cam.frame_uniforms(inputs.view, self.prev_view_proj.unwrap_or(vp), w, h);
        let gpu = &self.gpu;
        self.scene_gpu.update_frame(gpu, &frame);
        let max_mip = self.targets.get("zmip").desc.mips - 1;
        self.stage.set_frame(
            gpu,
            AoUniforms::new(&self.config.settings, &self.scene, &frame, max_mip, self.frames),
        );
        if let Some(t) = &self.stage.temporal {
            t.set_frame(gpu, has_history);
        }
        let u = ImportUniforms {
            inv_proj: inputs.proj.inverse().to_cols_array_2d(),
            inv_view: inputs.view.inverse().to_cols_array_2d(),
            size: frame.size,
            w_sign: cam.w_sign,
            reversed: cam.reversed as u32,
            _pad: [0; 2],
        };
        gpu.queue.write_buffer(&self.import_uniforms, 0, bytemuck::bytes_of(&u));

        let depth0 = Self::layer_view(inputs.depth, true);
        let normal0 = Self::layer_view(inputs.normals, false);
        let (depth1, normal1) = match inputs.second {
            Some((d, n)) => (Self::layer_view(d, true), Self::layer_view(n, false)),
            None => (depth0.clone(), normal0.clone()),
        };
        let motion = inputs.motion.map(|m| Self::layer_view(m, false));
        use wgpu::BindingResource as R;
        let group = crate::passes::bind_group(
            &gpu.device,
            "embed-import",
            &self.import_layout,
            &[
                self.import_uniforms.as_entire_binding(),
                R::TextureView(&depth0),
                R::TextureView(&normal0),
                R::TextureView(&depth1),
                R::TextureView(&normal1),
                R::TextureView(motion.as_ref().unwrap_or(&self.no_motion)),
            ],
        );
        let t = &self.targets;
        let mut outputs = vec![
            &t.get("zpack").view,
            &t.get("npack").view,
            &t.get("csz").layer_views[0],
            &t.get("motion").view,
        ];
        if self.config.layers == 2 {
            outputs.push(&t.get("csz").layer_views[1]);
        }
        let prof = &self.profiler;
        prof.reset();
        let slot = prof.begin(encoder, "embed-import");
        crate::passes::fullscreen_pass(encoder, "embed-import", &self.import_pipeline, &outputs, &[&group]);
        prof.end(encoder, slot);
        let mut passes: Vec<&dyn Pass> = vec![&self.mip];
        passes.extend(self.stage.passes());
        passes.push(&self.history);
        for p in passes {
            let slot = prof.begin(encoder, p.info().name);
            p.encode(gpu, &self.scene_gpu, t, encoder);
            prof.end(encoder, slot);
        }
        prof.resolve(encoder);
        self.frames = self.frames.wrapping_add(1);
        self.prev_view_proj = Some(vp);
        Ok(())
    }
}
