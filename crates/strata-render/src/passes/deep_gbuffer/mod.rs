//! Deep G-buffer construction with minimum separation (DGB §2).
//!
//! Layer 0 is the ordinary G-buffer. Layer j ≥ 1 holds, per pixel, the nearest
//! surface whose camera-space depth exceeds layer j − 1's by more than the
//! minimum separation Δz. Knowing layer j − 1 *before* it is rendered needs an
//! oracle; [`Variant`] picks it:
//!
//! | variant | passes | oracle for layer j (Listing 1 line 13 / Listing 2 line 22) |
//! |---|---|---|
//! | [`Variant::Peel`] | k geometry passes | this frame's layer j − 1, same pixel — exact |
//! | [`Variant::Delay`] | 1 (k + 1 views) | layer 0 of frame t rendered with T_t during frame t − 1 — exact, one frame of latency |
//! | [`Variant::Previous`] | 1 (k views) | last frame's layer j − 1, same pixel |
//! | [`Variant::Predict`] | 1 (k + 1 views) | layer 0 rendered during frame t − 1 with T_t extrapolated from T_{t−2}, T_{t−1} |
//! | [`Variant::Reproject`] | 1 (k views) | last frame's layer j − 1 at the fragment's position at t − 1 (reverse reprojection) |
//!
//! "No oracle" — a single-pass variant's first frame, or a comparison texel off
//! screen or behind the old camera — accepts the fragment (the layer then holds
//! the nearest surface there rather than a hole). An oracle texel without a
//! surface counts as infinitely far and rejects it.
//!
//! **Submission.** Listing 2 renders all layers from one geometry submission;
//! here that is one multiview pass (view j = layer j, plus the predicted
//! layer). On Mesa lavapipe (22.3) multiview views ≥ 1 are not rasterised like
//! view 0: on `atrium` at 96×64, a first frame where every view must equal
//! layer 0 differs in 373 of 6144 view-1 pixels (nearer fragments lost). So
//! [`Submission::Auto`] uses [`Submission::PerLayer`] on CPU adapters: the
//! same oracles, one non-multiview submission per layer (and one for the
//! predicted layer). [`Submission::Multiview`] keeps the one-pass form, whose
//! cost `strata bench deep-gbuffer` still reports.
//!
//! DELAY and PREDICT are implemented for k = 2 (the paper's
//! 2k − 1-view generalisation of PREDICT is not).
//!
//! **Reduced layers** (DGB Fig. 11, [`DeepGBufferSettings::layer_scale`]): layers ≥ 1 drawn
//! at 1/s of the resolution into `reduced-*` targets, then written into the full-resolution
//! arrays by [`LayerUpsamplePass`], one submission per layer.
//!
//! Outputs: per-layer arrays (`csz`, `normal`, `albedo`, `emission`, `depth`;
//! Delay/Predict add the depth-only predicted layer at index k) and the packed
//! layout of DGB Table 1 (`zpack` = RG32F camera-space z of layers 0 and 1,
//! `npack` = RGBA8 Oct16 normals of layers 0 and 1, `zpack23`/`npack23` for
//! k > 2, `radiosity0…` R11G11B10 per-layer radiosity B, written by the
//! lighting pass).

use std::num::NonZeroU32;
use std::str::FromStr;

use wgpu::util::DeviceExt;

use crate::frame::{Pass, PassInfo, TargetDesc, Targets};
use crate::gpu::GpuContext;
use crate::scene_gpu::{GpuScene, NextTransforms, VERTEX_LAYOUT};
use crate::RenderError;

mod layer_upsample;
pub use layer_upsample::{texel_plane_depth, upsample_depth, upsample_pick, LayerUpsamplePass};

pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
/// Most layers a deep G-buffer can have (DGB §5 generalises to k layers).
pub const MAX_LAYERS: u32 = 4;
/// Format of the per-layer radiosity targets (DGB Table 1).
pub const RADIOSITY_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rg11b10Ufloat;

/// How the second and later layers find the oracle depth (DGB §2.1–2.2).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Variant {
    /// Listing 1: one geometry pass per layer, each tested against the layer
    /// before it in the same frame. Exact; Δz = 0 is classic depth peeling.
    Peel,
    /// Listing 2 with the next frame's transforms known (one frame of latency). Exact.
    Delay,
    /// Listing 2 against last frame's layer at the same pixel.
    Previous,
    /// Listing 2 with T_{t+1} extrapolated from T_{t−1} and T_t (camera and objects).
    Predict,
    /// Listing 2 with reverse reprojection: the test point is the fragment's
    /// position at t − 1, compared with last frame's layer. The paper's principal solution.
    Reproject,
}

impl Variant {
    pub const ALL: [Variant; 5] = [
        Variant::Peel,
        Variant::Delay,
        Variant::Previous,
        Variant::Predict,
        Variant::Reproject,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Variant::Peel => "peel",
            Variant::Delay => "delay",
            Variant::Previous => "previous",
            Variant::Predict => "predict",
            Variant::Reproject => "reproject",
        }
    }

    /// The shader's oracle code (`ORACLE_*` in `deep_gbuffer.wgsl`).
    fn oracle(self) -> u32 {
        match self {
            Variant::Peel => 1,
            Variant::Delay => 2,
            Variant::Previous => 3,
            Variant::Predict => 4,
            Variant::Reproject => 5,
        }
    }

    /// All layers in one geometry submission (Listing 2)?
    pub fn is_single_pass(self) -> bool {
        self != Variant::Peel
    }

    /// Renders the depth-only layer 0 of frame t + 1 as an extra view.
    pub fn has_predicted_view(self) -> bool {
        matches!(self, Variant::Delay | Variant::Predict)
    }

    /// Where the frame-(t + 1) transforms come from.
    pub fn next_transforms(self) -> NextTransforms {
        if self == Variant::Predict {
            NextTransforms::Extrapolated
        } else {
            NextTransforms::Exact
        }
    }
}

impl FromStr for Variant {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        Variant::ALL.into_iter().find(|v| v.name() == s).ok_or_else(|| {
            format!(
                "unknown deep G-buffer variant '{s}': valid variants are {}",
                Variant::ALL.map(|v| v.name()).join(", ")
            )
        })
    }
}

impl std::fmt::Display for Variant {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Deep G-buffer settings. `Default` is the paper's configuration: two layers
/// built in one pass by REPROJECT, Δz from the scene (the paper uses 0.5 m for
/// every result, DGB §4.2; [`strata_scene::SceneSettings`] defaults to that).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DeepGBufferSettings {
    /// Number of layers k, 1..=[`MAX_LAYERS`]. 1 = an ordinary G-buffer.
    pub layers: u32,
    pub variant: Variant,
    /// Minimum separation Δz in scene units (≥ 0); `None` = the scene's setting.
    pub min_separation: Option<f32>,
    /// How the single-pass variants submit their layers (default [`Submission::Auto`]).
    pub submission: Submission,
    /// Resolution divisor s of layers ≥ 1, 1..=[`MAX_LAYER_SCALE`] (DGB Fig. 11: the second
    /// layer at a lower resolution than the first). 1 = every layer at full resolution, as in
    /// the paper's results. At s > 1 each layer j ≥ 1 is rasterised at ⌈w/s⌉ × ⌈h/s⌉ and a
    /// depth-aware upsampling ([`LayerUpsamplePass`]) writes it into the full-resolution
    /// arrays, so every later pass reads the same targets; it needs per-layer submission.
    pub layer_scale: u32,
}

/// Largest [`DeepGBufferSettings::layer_scale`].
pub const MAX_LAYER_SCALE: u32 = 4;

/// Geometry submissions of the single-pass variants (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Submission {
    /// Multiview, except on CPU adapters (lavapipe), where it is unreliable.
    Auto,
    /// One multiview pass for every layer (Listing 2).
    Multiview,
    /// One submission per layer with the same last-frame oracles.
    PerLayer,
}

impl Submission {
    /// `Auto` resolved for an adapter.
    pub fn resolve(self, gpu: &GpuContext) -> Submission {
        match self {
            Submission::Auto if gpu.adapter.get_info().device_type == wgpu::DeviceType::Cpu => Submission::PerLayer,
            Submission::Auto => Submission::Multiview,
            s => s,
        }
    }
}

impl Default for DeepGBufferSettings {
    fn default() -> Self {
        Self {
            layers: 2,
            variant: Variant::Reproject,
            min_separation: None,
            submission: Submission::Auto,
            layer_scale: 1,
        }
    }
}

impl DeepGBufferSettings {
    /// An ordinary one-layer G-buffer.
    pub fn single_layer() -> Self {
        Self {
            layers: 1,
            ..Self::default()
        }
    }

    pub fn validate(&self) -> Result<(), RenderError> {
        if !(1..=MAX_LAYERS).contains(&self.layers) {
            return Err(RenderError::Parameter(format!(
                "layers {} is out of range: must be in 1..={MAX_LAYERS}",
                self.layers
            )));
        }
        if self.variant.has_predicted_view() && self.layers > 2 {
            return Err(RenderError::Parameter(format!(
                "variant {} supports 1 or 2 layers (got {}); use peel, previous or reproject for more",
                self.variant, self.layers
            )));
        }
        if !(1..=MAX_LAYER_SCALE).contains(&self.layer_scale) {
            return Err(RenderError::Parameter(format!(
                "layer-scale {} is out of range: must be in 1..={MAX_LAYER_SCALE}",
                self.layer_scale
            )));
        }
        if self.is_reduced() && self.submission == Submission::Multiview {
            return Err(RenderError::Parameter(format!(
                "layer-scale {} needs one submission per layer: a multiview pass renders every layer at one size",
                self.layer_scale
            )));
        }
        if let Some(dz) = self.min_separation {
            if !(dz >= 0.0 && dz.is_finite()) {
                return Err(RenderError::Parameter(format!(
                    "min-separation {dz} is out of range: must be a finite number >= 0 (scene units)"
                )));
            }
        }
        Ok(())
    }

    /// Are layers ≥ 1 built at a reduced resolution (k ≥ 2 and `layer_scale` > 1)?
    pub fn is_reduced(&self) -> bool {
        self.layers >= 2 && self.layer_scale > 1
    }

    /// How the layers are submitted on `gpu`: [`Submission::Auto`] resolved, and one
    /// submission per layer where there is nothing to share a pass (one layer, the peel) or
    /// the layers are built at a reduced resolution.
    pub fn submission_on(&self, gpu: &GpuContext) -> Submission {
        if !multiview_needed(self) || self.is_reduced() {
            Submission::PerLayer
        } else {
            self.submission.resolve(gpu)
        }
    }

    /// Size of the reduced layers' targets for a `width` × `height` G-buffer.
    pub fn reduced_size(&self, width: u32, height: u32) -> [u32; 2] {
        let s = self.layer_scale.max(1);
        [width.div_ceil(s), height.div_ceil(s)]
    }

    /// The reduced-resolution targets that layers ≥ 1 are rasterised into before their
    /// upsampling (one layer each, reused by every layer ≥ 1; empty unless [`Self::is_reduced`]).
    /// `motion` adds its reduced twin.
    pub fn reduced_outputs(&self, motion: bool) -> Vec<TargetDesc> {
        if !self.is_reduced() {
            return Vec::new();
        }
        let full = self.outputs();
        let mut v: Vec<TargetDesc> = REDUCED
            .iter()
            .take(5)
            .map(|&(name, of)| {
                let d = full.iter().find(|d| d.name == of).expect("a G-buffer target");
                TargetDesc::new(
                    name,
                    d.format,
                    1,
                    "a layer >= 1 at the reduced resolution (layer-scale)",
                )
            })
            .collect();
        if motion {
            let (name, _) = REDUCED[5];
            v.push(TargetDesc::new(
                name,
                self.motion_target().format,
                1,
                "a layer >= 1's motion at the reduced resolution (layer-scale)",
            ));
        }
        v
    }

    /// Layers of the per-layer arrays: k, plus the predicted layer for DELAY/PREDICT.
    pub fn array_layers(&self) -> u32 {
        self.layers + (self.layers >= 2 && self.variant.has_predicted_view()) as u32
    }

    /// Does the frame keep last frame's depths (single-pass variants with k ≥ 2)?
    pub fn uses_history(&self) -> bool {
        self.layers >= 2 && self.variant.is_single_pass()
    }

    /// The world-space motion of each layer's surface since the frame last drawn, which the
    /// geometry passes also write where the renderer creates it (a temporal filter or the
    /// multi-bounce propagation reprojects: `RenderSettings::needs_motion`).
    pub fn motion_target(&self) -> TargetDesc {
        TargetDesc::new(
            "motion",
            wgpu::TextureFormat::Rgba16Float,
            self.array_layers(),
            "world-space motion of the surface since last frame (rgb; 0 = static): the temporal filters' per-object velocities",
        )
    }

    /// The colour targets of a pass that writes a layer (`csz`, `normal`, `albedo`, `emission`
    /// at locations 0–3; location 4, `motion`, only where the target exists).
    pub(crate) fn layer_color_targets(&self, motion: bool) -> Vec<Option<wgpu::ColorTargetState>> {
        let mut v = crate::passes::color_targets(&self.outputs()[1..5]);
        v.push(motion.then(|| wgpu::ColorTargetState::from(self.motion_target().format)));
        v
    }

    /// The targets the deep G-buffer passes write (and [`Self::motion_target`] where it exists).
    pub fn outputs(&self) -> Vec<TargetDesc> {
        let l = self.array_layers();
        let desc = TargetDesc::new;
        use wgpu::TextureFormat as F;
        let mut v = vec![
            desc(
                "depth",
                DEPTH_FORMAT,
                l,
                "hardware depth per layer (reversed-Z, near/z)",
            ),
            desc("csz", F::R32Float, l, "camera-space depth z per layer (0 = no surface)"),
            desc(
                "normal",
                F::Rgba8Unorm,
                l,
                "rg = Oct16 world normal, b = roughness, a = metallic",
            ),
            desc("albedo", F::Rgba8UnormSrgb, l, "base colour, a = opacity"),
            desc("emission", F::Rgba16Float, l, "emitted radiance"),
            desc(
                "zpack",
                F::Rg32Float,
                1,
                "DGB Table 1: camera-space z of layers 0 (r) and 1 (g)",
            ),
            desc(
                "npack",
                F::Rgba8Unorm,
                1,
                "DGB Table 1: Oct16 normals of layers 0 (rg) and 1 (ba)",
            ),
        ];
        if self.layers > 2 {
            v.push(desc(
                "zpack23",
                F::Rg32Float,
                1,
                "camera-space z of layers 2 (r) and 3 (g)",
            ));
            v.push(desc(
                "npack23",
                F::Rgba8Unorm,
                1,
                "Oct16 normals of layers 2 (rg) and 3 (ba)",
            ));
        }
        if self.uses_history() {
            v.push(desc(
                "csz-history",
                F::R32Float,
                l,
                "last frame's csz (the single-pass oracle)",
            ));
        }
        for name in crate::passes::lighting::RADIOSITY
            .iter()
            .take(self.layers as usize)
            .skip(1)
        {
            v.push(desc(
                name,
                RADIOSITY_FORMAT,
                1,
                "DGB Table 1 radiosity B of this layer: Lambertian direct + emission",
            ));
        }
        v
    }
}

/// The reduced-resolution targets and the full-resolution arrays they are upsampled into.
const REDUCED: [(&str, &str); 6] = [
    ("reduced-depth", "depth"),
    ("reduced-csz", "csz"),
    ("reduced-normal", "normal"),
    ("reduced-albedo", "albedo"),
    ("reduced-emission", "emission"),
    ("reduced-motion", "motion"),
];

/// Per-frame constants of a geometry pass (`DeepParams` in WGSL).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct DeepParams {
    min_separation: f32,
    has_history: u32,
    /// Full-resolution pixels per pixel of this pass's targets (the peel's oracle lookup).
    scale: f32,
    _pad: u32,
}

/// One geometry submission of the deep G-buffer: the single-layer pass, one
/// peel pass, or the single-pass multiview construction of all layers.
pub struct GeometryPass {
    name: &'static str,
    pipeline: wgpu::RenderPipeline,
    /// Layer written by view 0.
    first_layer: u32,
    /// Views rendered (1 = no multiview).
    views: u32,
    group: wgpu::BindGroup,
    params: wgpu::Buffer,
    inputs: Vec<&'static str>,
    /// The `motion` target exists and this pass writes it.
    motion: bool,
    /// Renders into the reduced-resolution targets (`layer_scale` > 1, a layer ≥ 1).
    reduced: bool,
    /// Full-resolution pixels per pixel of this pass's targets.
    scale: f32,
}

const PEEL_NAMES: [&str; 4] = ["gbuffer", "peel1", "peel2", "peel3"];
/// Per-layer submissions of the single-pass variants ([`Submission::PerLayer`]).
const LAYER_NAMES: [&str; 4] = ["gbuffer", "layer1", "layer2", "layer3"];

/// One step of the deep G-buffer's construction: a geometry submission, or the
/// upsampling of a reduced-resolution layer into the full-resolution arrays.
pub enum GeometryStep {
    Geometry(GeometryPass),
    Upsample(LayerUpsamplePass),
}

impl GeometryStep {
    /// Sets Δz, whether last frame's oracle exists and the camera's near plane, before
    /// encoding a frame.
    pub fn set_frame(&self, gpu: &GpuContext, min_separation: f32, has_history: bool, near: f32) {
        match self {
            GeometryStep::Geometry(g) => g.set_frame(gpu, min_separation, has_history),
            GeometryStep::Upsample(u) => u.set_frame(gpu, min_separation, near),
        }
    }
}

impl Pass for GeometryStep {
    fn info(&self) -> PassInfo {
        match self {
            GeometryStep::Geometry(g) => g.info(),
            GeometryStep::Upsample(u) => u.info(),
        }
    }

    fn encode(&self, gpu: &GpuContext, scene: &GpuScene, targets: &Targets, encoder: &mut wgpu::CommandEncoder) {
        match self {
            GeometryStep::Geometry(g) => g.encode(gpu, scene, targets, encoder),
            GeometryStep::Upsample(u) => u.encode(gpu, scene, targets, encoder),
        }
    }
}

/// The geometry passes for `settings`, in order (with [`DeepGBufferSettings::layer_scale`]
/// > 1, each reduced layer's pass is followed by its upsampling).
pub fn geometry_passes(
    gpu: &GpuContext,
    scene: &GpuScene,
    targets: &Targets,
    settings: &DeepGBufferSettings,
) -> Result<Vec<GeometryStep>, RenderError> {
    settings.validate()?;
    let k = settings.layers;
    let device = &gpu.device;
    let module = crate::shader::module(device, "deep_gbuffer", include_str!("deep_gbuffer.wgsl"));
    let group_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("deep_gbuffer oracle"),
        entries: &[
            crate::passes::uniform_entry(0),
            crate::passes::texture_entry(1, wgpu::TextureViewDimension::D2Array, false),
        ],
    });
    let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some("deep_gbuffer"),
        bind_group_layouts: &[
            Some(&scene.frame_layout),
            Some(&scene.object_layout),
            Some(&scene.material_layout),
            Some(&group_layout),
        ],
        immediate_size: 0,
    });
    // Bound where a pipeline has no oracle (never read).
    let no_oracle = device
        .create_texture(&wgpu::TextureDescriptor {
            label: Some("no oracle"),
            size: wgpu::Extent3d {
                width: 1,
                height: 1,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::R32Float,
            usage: wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        })
        .create_view(&wgpu::TextureViewDescriptor {
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            ..Default::default()
        });
    let csz = targets.get("csz");
    let motion = targets.try_get("motion").is_some();
    let make = |name: &'static str,
                oracle: u32,
                first_layer: u32,
                views: u32,
                oracle_view: &wgpu::TextureView,
                entry: Entry,
                reduced: bool| {
        let scale = if reduced { settings.layer_scale as f32 } else { 1.0 };
        let params = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some(name),
            contents: bytemuck::bytes_of(&DeepParams {
                min_separation: 0.0,
                has_history: 0,
                scale,
                _pad: 0,
            }),
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        });
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some(name),
            layout: &group_layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: params.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(oracle_view),
                },
            ],
        });
        let constants = [
            ("ORACLE", oracle as f64),
            ("LAYER_BASE", first_layer as f64),
            ("LAYERS", settings.layers as f64),
        ];
        let multiview = views > 1;
        // The separate oracle pass writes array layer k.
        let first_layer = if entry == Entry::Oracle {
            settings.layers
        } else {
            first_layer
        };
        let (vs, fs) = match entry {
            Entry::Single => ("vs_single", "fs_single"),
            Entry::Multiview => ("vs_multiview", "fs_multiview"),
            Entry::Oracle => ("vs_oracle", "fs_oracle"),
        };
        let options = wgpu::PipelineCompilationOptions {
            constants: &constants,
            ..Default::default()
        };
        let color_targets = settings.layer_color_targets(motion);
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some(name),
            layout: Some(&layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some(vs),
                compilation_options: options.clone(),
                buffers: &[Some(VERTEX_LAYOUT)],
            },
            primitive: wgpu::PrimitiveState {
                cull_mode: None,
                ..Default::default()
            },
            depth_stencil: Some(wgpu::DepthStencilState {
                format: DEPTH_FORMAT,
                depth_write_enabled: Some(true),
                depth_compare: Some(wgpu::CompareFunction::Greater),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some(fs),
                compilation_options: options,
                targets: &color_targets,
            }),
            multiview_mask: multiview.then(|| NonZeroU32::new((1u32 << views) - 1).expect("views > 0")),
            cache: None,
        });
        let inputs = match (oracle, entry) {
            (0, _) | (_, Entry::Oracle) => vec!["scene"],
            (1, _) => vec!["scene", "csz"],
            _ => vec!["scene", "csz-history"],
        };
        GeometryStep::Geometry(GeometryPass {
            name,
            pipeline,
            first_layer,
            views,
            group,
            params,
            inputs,
            motion,
            reduced,
            scale,
        })
    };
    let reduced = settings.is_reduced();
    // A reduced layer j's pass and then its upsampling (before layer j + 1's peel reads it).
    let layer = |v: &mut Vec<GeometryStep>, pass: GeometryStep, j: u32| {
        v.push(pass);
        if reduced {
            v.push(GeometryStep::Upsample(LayerUpsamplePass::new(
                gpu, scene, targets, settings, j,
            )));
        }
    };

    if multiview_needed(settings)
        && settings.submission_on(gpu) == Submission::Multiview
        && !gpu.features.contains(wgpu::Features::MULTIVIEW)
    {
        return Err(RenderError::MissingFeature {
            feature: "MULTIVIEW".into(),
            pass: format!("deep_gbuffer ({})", settings.variant),
        });
    }
    let passes = if k == 1 {
        vec![make("gbuffer", 0, 0, 1, &no_oracle, Entry::Single, false)]
    } else if settings.variant == Variant::Peel {
        let mut v = vec![make("gbuffer", 0, 0, 1, &no_oracle, Entry::Single, false)];
        for j in 1..k {
            // This frame's layer j − 1 only: rendering into layer j while reading it.
            let prev_layer = csz.texture.create_view(&wgpu::TextureViewDescriptor {
                dimension: Some(wgpu::TextureViewDimension::D2Array),
                base_array_layer: j - 1,
                array_layer_count: Some(1),
                ..Default::default()
            });
            let pass = make(
                PEEL_NAMES[j as usize],
                settings.variant.oracle(),
                j,
                1,
                &prev_layer,
                Entry::Single,
                reduced,
            );
            layer(&mut v, pass, j);
        }
        v
    } else {
        let history = &targets.get("csz-history").array_view;
        let oracle = settings.variant.oracle();
        match settings.submission_on(gpu) {
            Submission::PerLayer => {
                let mut v = vec![make("gbuffer", 0, 0, 1, &no_oracle, Entry::Single, false)];
                for j in 1..k {
                    let pass = make(LAYER_NAMES[j as usize], oracle, j, 1, history, Entry::Single, reduced);
                    layer(&mut v, pass, j);
                }
                if settings.variant.has_predicted_view() {
                    v.push(make("oracle", oracle, 0, 1, &no_oracle, Entry::Oracle, false));
                }
                v
            }
            _ => vec![make(
                "deep_gbuffer",
                oracle,
                0,
                settings.array_layers(),
                history,
                Entry::Multiview,
                false,
            )],
        }
    };
    Ok(passes)
}

/// Which shader entry points a geometry pass uses.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Entry {
    /// One layer (`LAYER_BASE`), no multiview.
    Single,
    /// Layers 0..views in one multiview pass.
    Multiview,
    /// The depth-only frame-(t + 1) layer k on its own.
    Oracle,
}

fn multiview_needed(settings: &DeepGBufferSettings) -> bool {
    settings.layers >= 2 && settings.variant.is_single_pass()
}

impl GeometryPass {
    /// Sets Δz and whether last frame's oracle exists, before encoding a frame.
    pub fn set_frame(&self, gpu: &GpuContext, min_separation: f32, has_history: bool) {
        let p = DeepParams {
            min_separation,
            has_history: has_history as u32,
            scale: self.scale,
            _pad: 0,
        };
        gpu.queue.write_buffer(&self.params, 0, bytemuck::bytes_of(&p));
    }
}

impl Pass for GeometryPass {
    fn info(&self) -> PassInfo {
        PassInfo {
            name: self.name,
            inputs: self.inputs.clone(),
            outputs: match (self.reduced, self.motion) {
                (false, true) => vec!["depth", "csz", "normal", "albedo", "emission", "motion"],
                (false, false) => vec!["depth", "csz", "normal", "albedo", "emission"],
                (true, m) => REDUCED.iter().take(5 + m as usize).map(|r| r.0).collect(),
            },
        }
    }

    fn encode(&self, _gpu: &GpuContext, scene: &GpuScene, targets: &Targets, encoder: &mut wgpu::CommandEncoder) {
        // Multiview: exactly layers first..first + views (a mask narrower than the
        // attachment would need SELECTIVE_MULTIVIEW).
        let names: &[&str] = if self.motion {
            &["csz", "normal", "albedo", "emission", "motion", "depth"]
        } else {
            &["csz", "normal", "albedo", "emission", "depth"]
        };
        let owned: Vec<Option<wgpu::TextureView>> = names
            .iter()
            .map(|n| {
                let t = targets.get(n);
                (self.views > 1 && t.desc.layers != self.views).then(|| {
                    t.texture.create_view(&wgpu::TextureViewDescriptor {
                        dimension: Some(wgpu::TextureViewDimension::D2Array),
                        base_array_layer: self.first_layer,
                        array_layer_count: Some(self.views),
                        ..Default::default()
                    })
                })
            })
            .collect();
        let view = |name: &str| {
            let i = names.iter().position(|n| *n == name).expect("a G-buffer attachment");
            if self.reduced {
                let (reduced, _) = REDUCED.iter().find(|r| r.1 == name).expect("a reduced twin");
                return &targets.get(reduced).view;
            }
            let t = targets.get(name);
            match (&owned[i], self.views > 1) {
                (Some(v), _) => v,
                (None, true) => &t.array_view,
                (None, false) => t.layer(self.first_layer),
            }
        };
        let mask = (self.views > 1).then(|| NonZeroU32::new((1u32 << self.views) - 1).expect("views > 0"));
        let mut pass = begin_layer_pass(encoder, self.name, view, self.motion, mask);
        if self.reduced {
            // exactly 1/s of the full image, so that reduced pixel i's centre is full-resolution
            // (i + 1/2)·s for any size; a last partial column or row, whose centre lies on or
            // past the viewport's edge, is scissored off so that it stays empty on every
            // rasteriser (the upsampling takes its neighbours)
            let (w, h) = (targets.width as f32 / self.scale, targets.height as f32 / self.scale);
            pass.set_viewport(0.0, 0.0, w, h, 0.0, 1.0);
            pass.set_scissor_rect(0, 0, (w.floor() as u32).max(1), (h.floor() as u32).max(1));
        }
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &scene.frame_bind_group, &[]);
        pass.set_bind_group(3, &self.group, &[]);
        scene.draw_all(&mut pass, 1, Some(2));
    }
}

/// A render pass that clears and writes a layer's G-buffer attachments (`csz`, `normal`,
/// `albedo`, `emission`, `motion` where it exists, and `depth`), each named view from `view`:
/// the geometry passes and the reduced layers' upsampling.
pub(crate) fn begin_layer_pass<'a, 'v>(
    encoder: &'a mut wgpu::CommandEncoder,
    label: &str,
    view: impl Fn(&str) -> &'v wgpu::TextureView,
    motion: bool,
    multiview_mask: Option<NonZeroU32>,
) -> wgpu::RenderPass<'a> {
    let color = |name: &str| crate::passes::clear_attachment(view(name));
    encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some(label),
        color_attachments: &[
            color("csz"),
            color("normal"),
            color("albedo"),
            color("emission"),
            motion.then(|| color("motion")).flatten(),
        ],
        depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
            view: view("depth"),
            depth_ops: Some(wgpu::Operations {
                load: wgpu::LoadOp::Clear(0.0),
                store: wgpu::StoreOp::Store,
            }),
            stencil_ops: None,
        }),
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask,
    })
}

/// Packs the per-layer arrays into DGB Table 1's layout (`zpack`, `npack`, and
/// `zpack23`, `npack23` for k > 2).
pub struct PackPass {
    pass: crate::passes::builder::FullscreenPass,
}

impl PackPass {
    pub fn new(gpu: &GpuContext, targets: &Targets, settings: &DeepGBufferSettings) -> Self {
        let four = settings.layers > 2;
        let mut b = crate::passes::builder::PassBuilder::new(gpu, targets, "pack")
            .shader("pack", include_str!("pack.wgsl"))
            .entry(if four { "fs_pack4" } else { "fs_pack2" })
            .constant("LAYERS", settings.layers as f64)
            .read_array("csz")
            .read_array("normal")
            .write("zpack")
            .write("npack");
        if four {
            b = b.write("zpack23").write("npack23");
        }
        Self { pass: b.build() }
    }
}

crate::passes::builder::delegate_pass!(PackPass);

/// Relative depth difference above which two layers hold different surfaces.
/// The construction passes use it too (WGSL twin `SURFACE_TOLERANCE`): a
/// layer-≥1 fragment within it of the oracle's depth is the oracle's own
/// surface and is rejected (`z > z_C + Δz + δ·z_C`), so that Δz = 0 is classic
/// depth peeling on every driver. Interpolated camera-space depth of one
/// surface differs between passes by a few ulps on lavapipe and by up to
/// 4·10⁻⁵ (relative) on NVIDIA 580 (Cornell's floor, 2026-11-25).
pub const SURFACE_TOLERANCE: f32 = 1e-4;

/// Per-pixel agreement of two camera-space depth images of the same layer (the
/// DGB Fig. 3 measure): a pixel counts when either image has a surface there
/// (z > 0); it mismatches when only one has a surface or the depths differ by
/// more than [`SURFACE_TOLERANCE`] relative.
#[derive(Clone, Debug, PartialEq)]
pub struct LayerComparison {
    /// Pixels with a surface in either image.
    pub counted: u64,
    /// Counted pixels whose surfaces differ.
    pub mismatched: u64,
    /// Per pixel: true where the surfaces differ.
    pub mask: Vec<bool>,
}

impl LayerComparison {
    pub fn new(a: &[f32], b: &[f32]) -> Self {
        assert_eq!(a.len(), b.len(), "layer images differ in size");
        let mut counted = 0;
        let mut mismatched = 0;
        let mask = a
            .iter()
            .zip(b)
            .map(|(&za, &zb)| {
                let (ha, hb) = (za > 0.0, zb > 0.0);
                if !ha && !hb {
                    return false;
                }
                counted += 1;
                let differ = ha != hb || (za - zb).abs() > SURFACE_TOLERANCE * za.max(zb);
                mismatched += differ as u64;
                differ
            })
            .collect();
        Self {
            counted,
            mismatched,
            mask,
        }
    }

    /// Mismatched share of counted pixels, in percent (0 when nothing is counted).
    pub fn percent(&self) -> f64 {
        if self.counted == 0 {
            0.0
        } else {
            100.0 * self.mismatched as f64 / self.counted as f64
        }
    }
}
