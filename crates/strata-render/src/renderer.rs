//! The frame: shadow → deep G-buffer (one or more geometry passes) → Table-1
//! packing → lighting → tonemap → history, with every intermediate target
//! readable as a debug view and every pass timed.

use strata_scene::{ImageBuf, Scene};

use crate::frame::{validate_pass_order, FrameCameras, FrameUniforms, Pass, PassInfo, Targets};
use crate::gpu::GpuContext;
use crate::lights::{gpu_lights_for, GpuLight};
use crate::passes::ao::stage::AoStage;
use crate::passes::ao::{AoSettings, AoUniforms};
use crate::passes::deep_gbuffer::{self, DeepGBufferSettings, Variant};
use crate::passes::depth_mip::DepthMipPass;
use crate::passes::depth_mip::DepthMipSettings;
use crate::passes::radiosity::stage::RadiosityStage;
use crate::passes::radiosity::{RadiositySettings, RadiosityUniforms};
use crate::passes::{lighting, shadow, tonemap, HistoryPass};
use crate::profiler::{PassTimings, Profiler};
use crate::scene_gpu::GpuScene;
use crate::RenderError;

/// GPU memory strata may allocate for one renderer unless `STRATA_MEMORY_BUDGET_MB`
/// says otherwise: 8 GiB (the estimate is checked before anything is allocated).
pub const DEFAULT_MEMORY_BUDGET: u64 = 8 << 30;

/// The memory budget in bytes: `STRATA_MEMORY_BUDGET_MB` (MiB, ≥ 1) or [`DEFAULT_MEMORY_BUDGET`].
pub fn memory_budget() -> Result<u64, RenderError> {
    match std::env::var("STRATA_MEMORY_BUDGET_MB") {
        Err(_) => Ok(DEFAULT_MEMORY_BUDGET),
        Ok(v) => match v.trim().parse::<u64>() {
            Ok(mb) if mb >= 1 => Ok(mb << 20),
            _ => Err(RenderError::Parameter(format!(
                "STRATA_MEMORY_BUDGET_MB '{v}' is invalid: must be a whole number of MiB >= 1"
            ))),
        },
    }
}

fn texel_bytes(f: wgpu::TextureFormat) -> u64 {
    f.block_copy_size(None)
        .or_else(|| f.block_copy_size(Some(wgpu::TextureAspect::DepthOnly)))
        .unwrap_or(16) as u64
}

fn desc_bytes(d: &crate::frame::TargetDesc, w: u32, h: u32) -> u64 {
    let base = w as u64 * h as u64 * d.layers as u64 * texel_bytes(d.format);
    // a full MIP chain adds at most a third
    if d.mips > 1 {
        base * 4 / 3
    } else {
        base
    }
}

/// The size a driver may allocate for a `w`×`h` texture stored in tiles: width
/// padded to 64 texels, height to 128 rows. NVIDIA's block-linear layout
/// (580 driver, 2026-11-25) allocated every 256×144 target as 256×256
/// (+78 %); lavapipe allocates the unpadded size.
pub fn tiled_size((w, h): (u32, u32)) -> (u32, u32) {
    (w.next_multiple_of(64), h.next_multiple_of(128))
}

/// What the estimate adds for what it does not itemise: uniform and counter
/// buffers and the driver's rounding of each allocation to its alignment
/// (lavapipe allocates exactly the itemised bytes; NVIDIA 580 allocated 10 KiB
/// more for `cornell direct` at 160×120, 2026-11-25).
pub const ALLOCATION_SLACK: u64 = 1 << 20;

/// Smallest and largest accepted image sizes.
pub const MIN_SIZE: u32 = 8;
pub const MAX_SIZE: u32 = 8192;

/// A band of extra pixels rendered around the image and cropped at output, so
/// screen-space passes see surfaces just outside the frame (DGB §3.5).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum GuardBand {
    /// `g` pixels on every side.
    Pixels(u32),
    /// A fraction of the image height on every side (0.1 = 10 %).
    Fraction(f32),
    /// The technique's own default ([`crate::technique::Technique::settings`]
    /// resolves it: AO techniques [`AO_GUARD_BAND`], the rest none); 0 if unresolved.
    Auto,
}

/// The guard band AO techniques default to: 10 % of the height per side. The AO
/// taps of pixels near the border find the occluders just outside the image
/// (DGB §3: "the Deep G-buffer input fills a guard band"); measured against
/// converged references it lowers the atrium's AO ꟻLIP from 0.070 to 0.053
/// (`docs/ao.md`).
pub const AO_GUARD_BAND: GuardBand = GuardBand::Fraction(0.1);

impl Default for GuardBand {
    fn default() -> Self {
        GuardBand::Pixels(0)
    }
}

impl GuardBand {
    /// Guard pixels per side for an image `height` rows tall.
    pub fn pixels(&self, height: u32) -> u32 {
        match *self {
            GuardBand::Pixels(g) => g,
            GuardBand::Fraction(f) => (f * height as f32).round() as u32,
            GuardBand::Auto => 0,
        }
    }

    /// `default` where this is [`GuardBand::Auto`].
    pub fn or_default(self, default: GuardBand) -> GuardBand {
        if self == GuardBand::Auto {
            default
        } else {
            self
        }
    }
}

impl std::str::FromStr for GuardBand {
    type Err = String;
    /// `N` (pixels), `F%` (percent of the image height) or `auto` (the technique's default).
    fn from_str(s: &str) -> Result<Self, String> {
        if s.trim() == "auto" {
            return Ok(GuardBand::Auto);
        }
        let bad = || {
            format!("guard band '{s}' is invalid: use pixels (e.g. 32), a percentage of the height (e.g. 10%) or auto")
        };
        if let Some(p) = s.strip_suffix('%') {
            let f: f32 = p.trim().parse().map_err(|_| bad())?;
            if !(0.0..=100.0).contains(&f) {
                return Err(format!("guard band {s} is out of range: must be in 0%..=100%"));
            }
            Ok(GuardBand::Fraction(f / 100.0))
        } else {
            s.trim().parse().map(GuardBand::Pixels).map_err(|_| bad())
        }
    }
}

/// Frames `strata render` draws before its output frame when `--warmup` is not given and
/// the frame [accumulates](Renderer::accumulates), and `strata eval`'s default warm-up:
/// by then the temporal filters' start-up ramp has reached the paper's α (it averages the
/// first frames' sampling patterns equally) and the progressive bounces have propagated 8 times.
pub const ACCUMULATION_WARMUP: u32 = 8;

/// What to render and how.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderSettings {
    pub width: u32,
    pub height: u32,
    /// Deep G-buffer layers and construction variant (default: one layer).
    pub deep: DeepGBufferSettings,
    pub guard_band: GuardBand,
    /// Run shadow, lighting and tonemap after the G-buffer (false: geometry only,
    /// for G-buffer benchmarks and tests).
    pub shade: bool,
    pub shadow: shadow::ShadowSettings,
    pub lighting: lighting::LightingSettings,
    /// Overrides the scene's exposure.
    pub exposure: Option<f32>,
    /// Meters the exposure from the image instead (`passes::exposure`; not in the
    /// papers); `None`: the scene's or `exposure`.
    pub auto_exposure: Option<crate::passes::exposure::AutoExposure>,
    /// Deep-G-buffer ambient occlusion (DGB §3.1) into target `ao`; `None` = off.
    pub ao: Option<AoSettings>,
    /// Deep-G-buffer radiosity (DGB §3.2) into target `indirect`; `None` = off.
    /// Needs `shade` (the lighting pass writes the radiosity buffers B).
    pub radiosity: Option<RadiositySettings>,
    /// Deep-G-buffer mirror reflections (DGB §3.6) into `hdr-reflected`; needs `shade`.
    pub reflections: Option<crate::passes::reflections::ReflectionSettings>,
    /// The radiance environment map the reflection rays that find nothing take (DGB
    /// §3.6's "environment map lookups"); `None`: the scene's sky colour.
    pub environment: Option<strata_scene::environment::EnvironmentMap>,
    /// Static irradiance probes blended with the radiosity by confidence
    /// (Fig. 9); they replace the scene's constant ambient term.
    pub probes: Option<strata_scene::probes::IrradianceProbes>,
    /// Interleaved deferred shading of VPLs (ILS §4, §6.2) into target
    /// `indirect`; `None` = off. Needs `shade`; excludes `radiosity`. The VPLs
    /// inside are generated by the caller (see `passes::ils`).
    pub ils: Option<crate::passes::ils::IlsSettings>,
    /// A-buffer (ABA): every fragment stored per pixel, composited front to back
    /// into `hdr-oit` (OIT) and compressed (Eq. 5); `None` = off. Needs `shade`
    /// off (it replaces the deferred lighting; `tonemap` shows `hdr-oit`).
    pub abuffer: Option<crate::passes::abuffer::ABufferSettings>,
    /// Bounced-z-buffer AO (BZB §3, AOV splats) into target `ao`; `None` = off.
    /// Excludes `ao` (both write the `ao` target).
    pub bzb: Option<crate::passes::bzb::BzbSettings>,
    /// Bounced-z-buffer GI (BZB §3 with a radiance payload, AOV triangle
    /// splats) into `indirect` and `bzb-gi-glossy`, composed into `hdr-full`;
    /// `None` = off. Needs `shade`; excludes `radiosity`, `ils` and `bzb`.
    pub bzb_gi: Option<crate::passes::bzb::gi::BzbGiSettings>,
}

impl Default for RenderSettings {
    fn default() -> Self {
        Self {
            width: 640,
            height: 360,
            deep: DeepGBufferSettings::single_layer(),
            guard_band: GuardBand::default(),
            shade: true,
            shadow: Default::default(),
            lighting: Default::default(),
            exposure: None,
            auto_exposure: None,
            ao: None,
            radiosity: None,
            reflections: None,
            environment: None,
            probes: None,
            ils: None,
            abuffer: None,
            bzb: None,
            bzb_gi: None,
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
        if let Some(a) = &self.auto_exposure {
            a.validate().map_err(RenderError::Parameter)?;
            if let Some(e) = self.exposure {
                return Err(RenderError::Parameter(format!(
                    "exposure {e} and auto-exposure are both set: give one (a fixed exposure, or auto)"
                )));
            }
        }
        if let GuardBand::Fraction(f) = self.guard_band {
            if !(0.0..=1.0).contains(&f) {
                return Err(RenderError::Parameter(format!(
                    "guard band fraction {f} is out of range: must be in 0..=1"
                )));
            }
        }
        let (w, h) = self.internal_size();
        if w > MAX_SIZE || h > MAX_SIZE {
            let g = self.guard_pixels();
            let fits = MAX_SIZE.saturating_sub(2 * g);
            return Err(RenderError::Parameter(if fits < 8 {
                format!(
                    "guard band {g} px is out of range: must be at most {} px",
                    (MAX_SIZE - 8) / 2
                )
            } else if let GuardBand::Fraction(f) = self.guard_band {
                // the band grows with the height: the tallest image whose band still fits
                let h_max = (8..=MAX_SIZE)
                    .rev()
                    .find(|&h| h + 2 * self.guard_band.pixels(h) <= MAX_SIZE)
                    .unwrap_or(8);
                format!(
                    "guard band {g} px ({}% of the height) makes the rendered size {w}x{h}: must stay within {MAX_SIZE} (with this guard band the height must be in 8..={h_max} and, at height {}, the width in 8..={fits}; or set the guard band to 0)",
                    f * 100.0,
                    self.height
                )
            } else {
                format!(
                    "guard band {g} px makes the rendered size {w}x{h}: must stay within {MAX_SIZE} (with this guard band width and height must be in 8..={fits}, or set the guard band to 0)"
                )
            }));
        }
        if let Some(ao) = &self.ao {
            ao.validate().map_err(RenderError::Parameter)?;
        }
        if let Some(b) = &self.bzb {
            b.validate().map_err(RenderError::Parameter)?;
            if self.ao.is_some() {
                return Err(RenderError::Parameter(
                    "bzb and ao both write the ao target: turn one off".into(),
                ));
            }
        }
        if let Some(g) = &self.bzb_gi {
            g.validate().map_err(RenderError::Parameter)?;
            if !self.shade {
                return Err(RenderError::Parameter(
                    "bzb-gi needs shading on: its senders are lit by the lighting pass's lights and shadow maps".into(),
                ));
            }
            if self.radiosity.is_some() || self.ils.is_some() || self.bzb.is_some() {
                return Err(RenderError::Parameter(
                    "bzb-gi and radiosity/ils/bzb-ao are exclusive (the same indirect and bounced z-buffer targets): turn the others off".into(),
                ));
            }
        }
        if let Some(r) = &self.reflections {
            r.validate().map_err(RenderError::Parameter)?;
            if !self.shade {
                return Err(RenderError::Parameter(
                    "reflections need shading on: they reflect the shaded image".into(),
                ));
            }
        }
        if let Some(r) = &self.radiosity {
            r.validate().map_err(RenderError::Parameter)?;
            if !self.shade {
                return Err(RenderError::Parameter(
                    "radiosity needs shading on: the lighting pass writes its radiosity buffers".into(),
                ));
            }
        }
        if let Some(i) = &self.ils {
            i.validate().map_err(RenderError::Parameter)?;
            if !self.shade {
                return Err(RenderError::Parameter(
                    "ils needs shading on: it adds indirect light to the shaded image".into(),
                ));
            }
            if self.radiosity.is_some() {
                return Err(RenderError::Parameter(
                    "ils and radiosity both write the indirect light: turn one off".into(),
                ));
            }
        }
        if let Some(a) = &self.abuffer {
            a.validate().map_err(RenderError::Parameter)?;
            if self.shade {
                return Err(RenderError::Parameter(
                    "abuffer needs shading off: the A-buffer shades its own fragments (technique oit)".into(),
                ));
            }
            if a.ao.is_some() && (self.ao.is_some() || self.bzb.is_some()) {
                return Err(RenderError::Parameter(
                    "abuffer AO and ao/bzb all write the ao target: turn one off".into(),
                ));
            }
        }
        self.deep.validate()
    }

    /// A one-line warning when a frame is far more expensive than its size suggests, for
    /// `render`, `soak` and `view` alike: `bzb-gi` with AOV splats that each cover the whole
    /// sub-image (T·S·W·H ray–triangle tests, [`crate::passes::bzb::gi::SPLAT_TESTS_WARNING`]).
    pub fn cost_warning(&self, scene: &Scene) -> Option<String> {
        self.bzb_gi.as_ref()?.cost_warning(scene, self.width, self.height)
    }

    /// Upper bound of the GPU memory a renderer with these settings allocates for
    /// `scene`, in bytes: every screen target (exactly where the pass declares its
    /// list, a documented bound for targets a stage creates internally: AO ≤ 24,
    /// radiosity ≤ 48 bytes per pixel, plus their temporal filters' per-pixel counts),
    /// the shadow maps, and the scene's vertex,
    /// index and texture data.
    pub fn estimated_bytes(&self, scene: &Scene) -> u64 {
        use crate::frame::TargetDesc;
        let (w, h) = tiled_size(self.internal_size());
        let px = w as u64 * h as u64;
        let sum = |ds: &[TargetDesc]| ds.iter().map(|d| desc_bytes(d, w, h)).sum::<u64>();
        let mut bytes = sum(&self.deep.outputs());
        if self.needs_motion() {
            bytes += sum(&[self.deep.motion_target()]);
        }
        let [rw, rh] = self.deep.reduced_size(w, h);
        bytes += self
            .deep
            .reduced_outputs(self.needs_motion())
            .iter()
            .map(|d| desc_bytes(d, rw, rh))
            .sum::<u64>();
        if !self.deep.uses_history() {
            // csz-history, when only a temporal filter keeps it
            bytes += px * self.deep.array_layers() as u64 * 4;
        }
        if self.shade {
            bytes += sum(crate::passes::lighting::OUTPUTS) + sum(crate::passes::tonemap::OUTPUTS);
            let lights = gpu_lights_for(scene, 0.0, &self.shadow);
            let maps = crate::lights::shadow_layer_count(&lights).max(1) as u64;
            bytes += maps * (self.shadow.resolution as u64).pow(2) * 4;
        }
        let levels = [
            self.ao.as_ref().map(|a| a.mips.levels),
            self.radiosity.as_ref().map(|r| r.mips.levels),
        ]
        .into_iter()
        .flatten()
        .max();
        if let Some(levels) = levels {
            bytes += desc_bytes(&DepthMipSettings { levels }.output(self.deep.layers, w, h), w, h);
        }
        // the temporal filters' per-pixel counts (the start-up ramp)
        let frames = |names| sum(&crate::passes::temporal::frames_targets(names));
        if let Some(a) = &self.ao {
            bytes += px * 24;
            if a.temporal.is_some() {
                bytes += frames(crate::passes::ao::stage::AO_FRAMES);
            }
        }
        if let Some(r) = &self.radiosity {
            bytes += sum(&crate::passes::radiosity::OUTPUTS)
                + sum(&crate::passes::radiosity::BOUNCE_OUTPUTS)
                + sum(&crate::passes::compose::OUTPUTS)
                + px * 48;
            if r.temporal.is_some() {
                bytes += frames(crate::passes::radiosity::stage::INDIRECT_FRAMES);
            }
            // the probe buffers, shared by the composition and the gather (without probes,
            // each pass binds two 1-probe dummies): 64 KiB bounds a small buffer
            bytes += self.probes.as_ref().map_or(4 * 65536, |p| {
                (p.count() * (9 * 16 + strata_scene::probes::DEPTH_TEXELS * 8)) as u64
            });
        }
        if self.reflections.is_some() {
            bytes += sum(&crate::passes::reflections::OUTPUTS);
        }
        if let Some(i) = &self.ils {
            bytes += i.estimated_bytes(w, h);
        }
        if let Some(a) = &self.abuffer {
            bytes += a.estimated_bytes(w, h) + sum(crate::passes::tonemap::OUTPUTS);
        }
        if let Some(b) = &self.bzb {
            bytes += b.estimated_bytes(w, h, scene.triangle_count() as u64);
        }
        if let Some(g) = &self.bzb_gi {
            bytes += g.estimated_bytes(scene, w, h) + sum(&crate::passes::compose::OUTPUTS);
        }
        let geometry: u64 = scene
            .meshes
            .iter()
            .map(|m| m.positions.len() as u64 * 32 + m.indices.len() as u64 * 4)
            .sum();
        let textures: u64 = scene
            .textures
            .iter()
            .map(|t| t.width as u64 * t.height as u64 * 4 * 4 / 3)
            .sum();
        bytes + geometry + textures + ALLOCATION_SLACK
    }

    /// Checks the settings against the adapter's limits and the memory budget,
    /// before anything is allocated; errors name the parameters and the limit.
    pub fn check_resources(&self, gpu: &GpuContext, scene: &Scene) -> Result<(), RenderError> {
        let limits = gpu.device.limits();
        let (w, h) = self.internal_size();
        let max = limits.max_texture_dimension_2d;
        if w > max || h > max {
            return Err(RenderError::Parameter(format!(
                "rendered size {w}x{h} (width, height and guard band) exceeds the adapter's largest texture, {max}x{max}"
            )));
        }
        if self.deep.array_layers() > limits.max_texture_array_layers {
            return Err(RenderError::Parameter(format!(
                "layers {} exceed the adapter's {} texture array layers",
                self.deep.array_layers(),
                limits.max_texture_array_layers
            )));
        }
        if let Some(&i) = self.shadow.unshadowed.iter().find(|&&i| i >= scene.lights.len()) {
            return Err(RenderError::Parameter(format!(
                "no-shadow light {i} is out of range: scene '{}' has {} lights (0..{})",
                scene.name,
                scene.lights.len(),
                scene.lights.len()
            )));
        }
        if self.shade {
            let lights = gpu_lights_for(scene, 0.0, &self.shadow);
            let maps = crate::lights::shadow_layer_count(&lights);
            if maps > limits.max_texture_array_layers {
                return Err(RenderError::Parameter(format!(
                    "scene '{}' needs {maps} shadow maps: more than the adapter's {} texture array layers",
                    scene.name, limits.max_texture_array_layers
                )));
            }
        }
        let budget = memory_budget()?;
        let need = self.estimated_bytes(scene);
        if need > budget {
            return Err(RenderError::Parameter(format!(
                "width {} x height {} x layers {} needs about {} MiB of GPU memory for scene '{}', over the budget of {} MiB \
                 (lower the size or layers, or raise STRATA_MEMORY_BUDGET_MB)",
                self.width,
                self.height,
                self.deep.layers,
                need >> 20,
                scene.name,
                budget >> 20
            )));
        }
        Ok(())
    }

    /// Whether a pass reprojects last frame's values (a temporal filter, the multi-bounce
    /// propagation), so the deep G-buffer writes its `motion` target.
    pub fn needs_motion(&self) -> bool {
        self.ao.as_ref().is_some_and(|a| a.temporal.is_some())
            || self
                .radiosity
                .as_ref()
                .is_some_and(|r| r.temporal.is_some() || r.delta > 0.0)
            || self.bzb.as_ref().is_some_and(|b| b.temporal.is_some())
            || self.bzb_gi.as_ref().is_some_and(|b| b.temporal.is_some())
    }

    /// Guard-band pixels per side.
    pub fn guard_pixels(&self) -> u32 {
        self.guard_band.pixels(self.height)
    }

    /// Size of every render target: the image plus the guard band.
    pub fn internal_size(&self) -> (u32, u32) {
        let g = self.guard_pixels();
        (self.width + 2 * g, self.height + 2 * g)
    }
}

pub struct Renderer {
    pub settings: RenderSettings,
    pub scene_gpu: GpuScene,
    pub targets: Targets,
    shadow: Option<shadow::ShadowPass>,
    geometry: Vec<deep_gbuffer::GeometryStep>,
    pack: deep_gbuffer::PackPass,
    lighting: Option<lighting::LightingPass>,
    tonemap: Option<tonemap::TonemapPass>,
    /// Auto-exposure's metering, before `tonemap` (`RenderSettings::auto_exposure`).
    exposure: Option<crate::passes::exposure::ExposurePass>,
    /// Whether a frame has left a metered exposure to adapt from.
    exposure_history: bool,
    mip: Option<DepthMipPass>,
    ao: Option<AoStage>,
    radiosity: Option<RadiosityStage>,
    ils: Option<crate::passes::ils::IlsStage>,
    bzb: Option<crate::passes::bzb::BzbStage>,
    bzb_gi: Option<crate::passes::bzb::gi::BzbGiStage>,
    reflections: Option<crate::passes::reflections::ReflectionPass>,
    abuffer: Option<crate::passes::abuffer::ABufferStage>,
    history: Option<HistoryPass>,
    last_frame: FrameUniforms,
    /// Last frame's depths are in `csz-history` (false before the first frame).
    has_history: bool,
    /// Last frame's layers ≥ 1 had their oracle (false on a single-pass
    /// variant's first frame), so its temporally filtered outputs are usable.
    history_layers_valid: bool,
    /// Frames rendered so far: the seed of per-frame rotated sampling patterns
    /// (independent of the animation frame, so a static view also varies).
    frames_rendered: u32,
    /// The animation frame the objects were last drawn at (`None` before the first frame
    /// and after a cut): their "previous" transforms, so re-rendering a frame (a still
    /// image's warm-up) gives zero motion.
    last_object_frame: Option<f32>,
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
        settings.check_resources(gpu, scene)?;
        let scene_gpu = GpuScene::new(gpu, scene);
        let (w, h) = settings.internal_size();
        let mut targets = Targets::new(w, h);
        // the lighting pass's compute form writes layer 0's outputs and the deeper layers'
        // radiosity as storage textures
        let lighting_compute = settings.shade && lighting::LightingPass::compute_on(gpu, &settings.lighting);
        for d in settings.deep.outputs() {
            let storage = lighting_compute && lighting::RADIOSITY.contains(&d.name);
            targets.create_storable(gpu, d, storage);
        }
        if settings.needs_motion() {
            targets.create(gpu, settings.deep.motion_target());
        }
        let reduced = settings.deep.reduced_size(w, h);
        for d in settings.deep.reduced_outputs(settings.needs_motion()) {
            targets.create_sized(gpu, d, reduced);
        }
        if settings.shade {
            for d in lighting::OUTPUTS {
                targets.create_storable(gpu, *d, lighting_compute);
            }
            for d in tonemap::OUTPUTS {
                targets.create(gpu, *d);
            }
        }
        let lights = gpu_lights_for(scene, 0.0, &settings.shadow);
        let geometry = deep_gbuffer::geometry_passes(gpu, &scene_gpu, &targets, &settings.deep)?;
        let pack = deep_gbuffer::PackPass::new(gpu, &targets, &settings.deep);
        let (mut shadow, lighting) = if settings.shade {
            let matrices = crate::lights::shadow_matrices(scene, 0.0, &lights);
            let shadow = shadow::ShadowPass::new(gpu, &scene_gpu, &matrices, &settings.shadow);
            let lighting = lighting::LightingPass::new(
                gpu,
                &scene_gpu,
                &targets,
                &shadow,
                &lights,
                settings.shadow.resolution,
                &settings.lighting,
                settings.deep.layers,
                lighting_compute,
            );
            (Some(shadow), Some(lighting))
        } else {
            (None, None)
        };
        // one depth MIP chain for every screen-space technique
        let mip_levels = [
            settings.ao.as_ref().map(|a| a.mips.levels),
            settings.radiosity.as_ref().map(|r| r.mips.levels),
        ]
        .into_iter()
        .flatten()
        .max();
        let mip = mip_levels.map(|levels| {
            let zmip = DepthMipSettings { levels }.output(settings.deep.layers, w, h);
            // compute when a technique that reads the chain runs its passes as compute
            let compute = [
                settings.ao.as_ref().map(|a| a.kernel),
                settings.radiosity.as_ref().map(|r| r.kernel),
            ]
            .into_iter()
            .flatten()
            .any(|k| DepthMipPass::compute_on(gpu, k, zmip.format));
            targets.create_storable(gpu, zmip, compute);
            DepthMipPass::new(gpu, &targets, settings.deep.layers, compute)
        });
        if settings.needs_motion() && targets.try_get("csz-history").is_none() {
            let l = settings.deep.array_layers();
            targets.create(
                gpu,
                crate::frame::TargetDesc::new("csz-history", wgpu::TextureFormat::R32Float, l, "last frame's csz"),
            );
        }
        let ao = match &settings.ao {
            Some(a) => Some(AoStage::new(
                gpu,
                &scene_gpu,
                &mut targets,
                &settings.deep,
                a,
                a.resolve(scene).0,
            )?),
            None => None,
        };
        let bzb = match &settings.bzb {
            Some(b) => Some(crate::passes::bzb::BzbStage::new(
                gpu,
                &scene_gpu,
                &mut targets,
                b,
                scene,
                settings.deep.layers,
            )?),
            None => None,
        };
        let radiosity = match &settings.radiosity {
            Some(r) => Some(RadiosityStage::new(
                gpu,
                &scene_gpu,
                &mut targets,
                &settings.deep,
                r,
                settings.guard_pixels(),
                settings.probes.as_ref(),
                settings
                    .ao
                    .as_ref()
                    .and_then(|a| a.radius)
                    .unwrap_or(scene.settings.ao_radius),
                true,
            )),
            None => None,
        };
        let ils = match &settings.ils {
            Some(i) => Some(crate::passes::ils::IlsStage::new(
                gpu,
                &scene_gpu,
                &mut targets,
                i,
                scene,
                true,
            )?),
            None => None,
        };
        let bzb_gi = match (&settings.bzb_gi, &shadow) {
            (Some(g), Some(sh)) => Some(crate::passes::bzb::gi::BzbGiStage::new(
                gpu,
                &scene_gpu,
                &mut targets,
                g,
                scene,
                &crate::passes::bzb::gi::LightInputs {
                    shadow: sh,
                    lights: &lights,
                    shadow_resolution: settings.shadow.resolution,
                    pcf_radius: settings.lighting.pcf_radius,
                    area_penumbrae: settings.lighting.area_penumbrae,
                },
                settings.deep.layers,
            )?),
            _ => None,
        };
        let shaded = if radiosity.is_some() || ils.is_some() || bzb_gi.is_some() {
            "hdr-full"
        } else {
            "hdr"
        };
        let environment = settings
            .environment
            .as_ref()
            .map(|e| crate::passes::reflections::environment_cube(gpu, e));
        let reflections = settings.reflections.as_ref().map(|rs| {
            crate::passes::reflections::ReflectionPass::new(
                gpu,
                &scene_gpu,
                &mut targets,
                settings.deep.layers,
                shaded,
                rs,
                crate::passes::reflections::ReflectedLight {
                    layer1: crate::passes::reflections::Layer1Radiance {
                        ambient: true,
                        indirect: radiosity.as_ref().zip(settings.radiosity.as_ref()).map(|(stage, r)| {
                            crate::passes::reflections::Layer1Indirect {
                                probes: stage.probes.as_ref().map(|(p, mode)| (p, *mode)),
                                boost: r.boost,
                            }
                        }),
                    },
                    // the baked environment, else the scene's sky colour
                    environment: environment.as_ref(),
                },
            )
        });
        let shown = if reflections.is_some() { "hdr-reflected" } else { shaded };
        let abuffer = match &settings.abuffer {
            Some(a) => Some(crate::passes::abuffer::ABufferStage::new(
                gpu,
                &scene_gpu,
                &mut targets,
                a,
                &lights,
            )?),
            None => None,
        };
        // the tonemapper shows direct + indirect + reflections, or the A-buffer's composite
        let tonemap_input = if settings.shade {
            Some(shown)
        } else if abuffer.is_some() {
            for d in tonemap::OUTPUTS {
                targets.create(gpu, *d);
            }
            Some(crate::passes::abuffer::OUTPUT.name)
        } else {
            None
        };
        let exposure = tonemap_input.zip(settings.auto_exposure).map(|(input, a)| {
            crate::passes::exposure::ExposurePass::new(gpu, &targets, input, settings.guard_pixels(), a)
        });
        let tonemap = tonemap_input.map(|input| {
            tonemap::TonemapPass::new(gpu, &scene_gpu, &targets, input, exposure.as_ref().map(|e| e.buffer()))
        });
        let mut copies = Vec::new();
        if settings.deep.uses_history() || settings.needs_motion() {
            copies.push(("csz", "csz-history"));
        }
        if ao.as_ref().is_some_and(|a| a.temporal.is_some()) {
            copies.push(("ao-temporal", "ao-temporal-history"));
            let [n, h] = crate::passes::ao::stage::AO_FRAMES;
            copies.push((n, h));
        }
        if radiosity.as_ref().is_some_and(|r| r.temporal.is_some()) {
            copies.push(("indirect-temporal", "indirect-temporal-history"));
            let [n, h] = crate::passes::radiosity::stage::INDIRECT_FRAMES;
            copies.push((n, h));
        }
        if settings.bzb.as_ref().is_some_and(|b| b.temporal.is_some()) {
            copies.push((
                crate::passes::bzb::TEMPORAL[0].name,
                crate::passes::bzb::TEMPORAL[1].name,
            ));
            let [n, h] = crate::passes::bzb::TEMPORAL_FRAMES;
            copies.push((n, h));
        }
        if settings.bzb_gi.as_ref().is_some_and(|g| g.temporal.is_some()) {
            for k in 0..2 {
                copies.push((
                    crate::passes::bzb::gi::TEMPORAL[2 * k].name,
                    crate::passes::bzb::gi::TEMPORAL[2 * k + 1].name,
                ));
                let [n, h] = crate::passes::bzb::gi::TEMPORAL_FRAMES[k];
                copies.push((n, h));
            }
        }
        if radiosity.as_ref().is_some_and(|r| r.propagate.is_some()) {
            // the next bounce reflects the best estimate of E there is: with probes, the blend
            copies.push((
                if settings.probes.is_some() {
                    "indirect-blended"
                } else {
                    "indirect"
                },
                "indirect-history",
            ));
            if settings.deep.layers > 1 {
                copies.push(("indirect1-raw", "indirect1-history"));
            }
        }
        let history = (!copies.is_empty()).then_some(HistoryPass { copies });
        // (a technique's passes, up to 4 geometry passes and 3 reduced layers' upsampling)
        let profiler = Profiler::new(gpu, 48);
        let animated = scene.animated();
        // nothing moves: the shadow maps of frame 0 serve every frame (an animated
        // scene's `update` re-renders them each frame)
        if let Some(s) = &mut shadow {
            s.set_cached(!animated);
        }
        let r = Self {
            settings,
            scene_gpu,
            targets,
            shadow,
            geometry,
            pack,
            lighting,
            tonemap,
            exposure,
            exposure_history: false,
            mip,
            ao,
            radiosity,
            ils,
            bzb,
            bzb_gi,
            reflections,
            abuffer,
            history,
            last_frame: bytemuck::Zeroable::zeroed(),
            has_history: false,
            history_layers_valid: false,
            frames_rendered: 0,
            last_object_frame: None,
            profiler,
            lights,
            animated,
        };
        validate_pass_order(&r.pass_infos()).map_err(RenderError::Other)?;
        gpu.check_errors()?;
        Ok(r)
    }

    /// Whether the shadow maps of the first frame serve every frame (a scene with no
    /// animated object); false without shadow maps.
    pub fn shadow_maps_cached(&self) -> bool {
        self.shadow.as_ref().is_some_and(|s| s.cached())
    }

    /// Whether ILS's VPL shadow maps of the first frame serve the next ones until
    /// `set_vpls` (`IlsSettings::vpl_shadow_maps_cached`); false without them.
    pub fn vpl_shadow_maps_cached(&self) -> bool {
        self.ils.as_ref().is_some_and(|i| i.vpl_shadow_maps_cached())
    }

    /// The frame's passes in execution order.
    fn passes(&self) -> Vec<&dyn Pass> {
        let mut v: Vec<&dyn Pass> = Vec::new();
        if let Some(s) = &self.shadow {
            v.push(s);
        }
        v.extend(self.geometry.iter().map(|p| p as &dyn Pass));
        v.push(&self.pack);
        if let Some(m) = &self.mip {
            v.push(m);
        }
        if let Some(a) = &self.ao {
            v.extend(a.passes());
        }
        if let Some(b) = &self.bzb {
            v.extend(b.passes());
        }
        if let (Some(l), Some(t)) = (&self.lighting, &self.tonemap) {
            v.push(l);
            if let Some(r) = &self.radiosity {
                v.extend(r.passes());
            }
            if let Some(i) = &self.ils {
                v.extend(i.passes());
            }
            if let Some(g) = &self.bzb_gi {
                v.extend(g.passes());
            }
            if let Some(r) = &self.reflections {
                v.push(r);
            }
            if let Some(e) = &self.exposure {
                v.push(e);
            }
            v.push(t);
        }
        if let Some(a) = &self.abuffer {
            v.extend(a.passes());
            if let (None, Some(t)) = (&self.lighting, &self.tonemap) {
                if let Some(e) = &self.exposure {
                    v.push(e);
                }
                v.push(t);
            }
        }
        if let Some(h) = &self.history {
            v.push(h);
        }
        v
    }

    /// The frame's passes in order, with declared inputs and outputs.
    pub fn pass_infos(&self) -> Vec<PassInfo> {
        self.passes().iter().map(|p| p.info()).collect()
    }

    /// Forgets last frame's depths (a camera cut): the next frame's single-pass
    /// layers have no oracle.
    pub fn reset_history(&mut self) {
        self.has_history = false;
        self.exposure_history = false;
        self.last_object_frame = None;
    }

    /// Renders one frame at (fractional) frame index `frame`, seen by
    /// `cams.current`; `cams.previous` drives reverse reprojection and
    /// `cams.next_view` the DELAY oracle (PREDICT extrapolates its own).
    pub fn render(
        &mut self,
        gpu: &GpuContext,
        scene: &Scene,
        cams: &FrameCameras,
        frame: f32,
    ) -> Result<PassTimings, RenderError> {
        cams.current.validate().map_err(RenderError::Parameter)?;
        let variant = self.settings.deep.variant;
        let cams = if variant == Variant::Predict {
            FrameCameras::predicted(cams.previous, cams.current)
        } else {
            *cams
        };
        let cams = cams.with_guard_band(self.settings.height, self.settings.guard_pixels());
        let exposure = self.settings.exposure.unwrap_or(scene.settings.exposure);
        let (w, h) = self.settings.internal_size();
        let mut u = FrameUniforms::new(scene, &cams, w, h, frame, exposure);
        if self.settings.probes.is_some() && self.settings.radiosity.is_some() {
            // the probes carry the ambient light
            u.ambient[..3].copy_from_slice(&[0.0; 3]);
        }
        self.scene_gpu.update_frame(gpu, &u);
        self.last_frame = u;
        // history computed from oracle-less layers would linger for many
        // frames (α^n): temporal filters start the average afresh instead
        let temporal_history = self.has_history && self.history_layers_valid;
        let max_mip = self.targets.try_get("zmip").map_or(0, |t| t.desc.mips - 1);
        if let (Some(stage), Some(s)) = (&self.ao, &self.settings.ao) {
            let au = AoUniforms::new(s, scene, &u, max_mip, self.frames_rendered);
            stage.set_frame(gpu, au);
            if let Some(t) = &stage.temporal {
                t.set_frame(gpu, temporal_history);
            }
        }
        if let Some(b) = &self.bzb {
            b.set_frame(gpu, scene, frame, self.animated, self.frames_rendered, temporal_history);
        }
        // the deep G-buffer's minimum separation Δz (its override, else the scene's)
        let dz = self
            .settings
            .deep
            .min_separation
            .unwrap_or(scene.settings.min_separation);
        if let (Some(stage), Some(s)) = (&self.radiosity, &self.settings.radiosity) {
            let ru = RadiosityUniforms::new(s, scene, &u, max_mip, self.frames_rendered, dz);
            stage.set_frame(gpu, ru);
            if let Some(p) = &stage.propagate {
                p.set_frame(gpu, temporal_history);
            }
            if let Some(t) = &stage.temporal {
                t.set_frame(gpu, temporal_history);
            }
        }
        // the frame before on the first frame (PREDICT's extrapolation; no history reads it)
        let previous = self.last_object_frame.unwrap_or(frame - 1.0);
        self.scene_gpu
            .update_objects(gpu, frame, previous, variant.next_transforms());
        for g in &self.geometry {
            g.set_frame(gpu, dz, self.has_history, cams.current.near);
        }
        if let Some(r) = &self.reflections {
            r.set_frame(gpu, dz);
        }
        if let Some(a) = &self.abuffer {
            a.set_frame(gpu, crate::passes::abuffer::far_depth(scene, &cams.current, frame));
            if let Some(s) = &a.settings().ao {
                let m = a.settings().compress;
                a.set_ao_frame(
                    gpu,
                    crate::passes::abuffer::ao::AbaAoUniforms::with_nodes(s, scene, &u, m.is_some(), m.unwrap_or(0)),
                );
            }
        }
        if self.animated {
            if let (Some(s), Some(l)) = (&self.shadow, &self.lighting) {
                self.lights = gpu_lights_for(scene, frame, &self.settings.shadow);
                s.update(gpu, &crate::lights::shadow_matrices(scene, frame, &self.lights));
                l.update_lights(gpu, &self.lights);
            }
        }
        if let Some(g) = &self.bzb_gi {
            g.set_frame(
                gpu,
                scene,
                frame,
                self.animated,
                &self.lights,
                self.frames_rendered,
                temporal_history,
            );
        }
        if let Some(e) = &self.exposure {
            e.set_frame(gpu, self.exposure_history);
        }
        let mut encoder = gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("frame") });
        self.profiler.reset();
        let passes = self.passes();
        for p in passes {
            let slot = self.profiler.begin(&mut encoder, p.info().name);
            p.encode(gpu, &self.scene_gpu, &self.targets, &mut encoder);
            self.profiler.end(&mut encoder, slot);
        }
        self.profiler.resolve(&mut encoder);
        gpu.queue.submit([encoder.finish()]);
        gpu.check_errors()?;
        self.history_layers_valid = !self.settings.deep.uses_history() || self.has_history;
        self.frames_rendered = self.frames_rendered.wrapping_add(1);
        self.last_object_frame = Some(frame);
        self.has_history = self.history.is_some();
        self.exposure_history = true;
        self.profiler.read(gpu)
    }

    /// The last frame's auto-exposure histogram (pixels per bin of
    /// [`crate::passes::exposure::bin_of`]); `None` without auto-exposure.
    pub fn exposure_histogram(&self, gpu: &GpuContext) -> Result<Option<Vec<u32>>, RenderError> {
        self.exposure.as_ref().map(|e| e.read_histogram(gpu)).transpose()
    }

    /// The exposure the last frame was tonemapped with: the metered one with
    /// [`RenderSettings::auto_exposure`] (read back), else the frame's.
    pub fn displayed_exposure(&self, gpu: &GpuContext) -> Result<f32, RenderError> {
        match (&self.exposure, self.exposure_history) {
            (Some(e), true) => Ok(e.read(gpu)?.0),
            _ => Ok(self.last_frame.sky[3]),
        }
    }

    /// [`Renderer::displayed_exposure`] without waiting for the GPU: exact for a fixed
    /// exposure; under auto-exposure the latest metered value that has arrived (an earlier
    /// frame's, [`ExposurePass::read_latest`](crate::passes::exposure::ExposurePass::read_latest)),
    /// `None` until one has.
    pub fn latest_exposure(&self, gpu: &GpuContext) -> Option<f32> {
        match (&self.exposure, self.exposure_history) {
            (Some(e), true) => e.read_latest(gpu).map(|v| v.0),
            _ => Some(self.last_frame.sky[3]),
        }
    }

    /// Replaces the ILS VPLs for the next frames (moving lights: regenerate per
    /// frame); at most as many as the renderer was built with.
    pub fn set_vpls(&mut self, gpu: &GpuContext, vpls: &[crate::passes::ils::GpuVpl]) -> Result<(), RenderError> {
        match &mut self.ils {
            Some(i) => i.set_vpls(gpu, vpls),
            None => Err(RenderError::Parameter("set_vpls: the renderer has no ils stage".into())),
        }
    }

    /// Whether this frame's output builds up over frames: a temporal filter (DGB §3.3)
    /// or the radiosity's progressive bounces, the passes that reproject
    /// ([`RenderSettings::needs_motion`]), or an auto-exposure that adapts over frames
    /// ([`AutoExposure::adapts`](crate::passes::exposure::AutoExposure::adapts)). The
    /// first frame after a cut then shows one frame's sampling pattern and a single
    /// bounce; `strata render` warms such frames up by [`ACCUMULATION_WARMUP`] unless told
    /// otherwise, and the viewer keeps drawing still frames as long as for a temporal
    /// filter.
    pub fn accumulates(&self) -> bool {
        self.settings.needs_motion() || self.settings.auto_exposure.is_some_and(|a| a.adapts())
    }

    /// The A-buffer stage (read-back of its lists and compressed nodes), if on.
    pub fn abuffer(&self) -> Option<&crate::passes::abuffer::ABufferStage> {
        self.abuffer.as_ref()
    }

    /// The frame uniforms of the last rendered frame (guard-banded camera).
    pub fn frame_uniforms(&self) -> FrameUniforms {
        self.last_frame
    }

    /// The radiosity pass's uniforms of the last rendered frame.
    pub fn radiosity_uniforms(&self) -> Option<RadiosityUniforms> {
        self.radiosity.as_ref().map(|r| r.gather.uniforms())
    }

    /// The reduced-resolution gather's upsampling uniforms this frame
    /// (`RadiositySettings::gather_scale` > 1), for its CPU twin.
    pub fn upsample_uniforms(&self) -> Option<crate::passes::upsample::UpsampleUniforms> {
        self.radiosity.as_ref()?.upsample.as_ref().map(|u| u.uniforms())
    }

    /// The reduced-resolution AO's upsampling uniforms this frame (`AoSettings::scale` >
    /// 1), for its CPU twin.
    pub fn ao_upsample_uniforms(&self) -> Option<crate::passes::upsample::UpsampleUniforms> {
        self.ao.as_ref()?.upsample.as_ref().map(|u| u.uniforms())
    }

    /// The AO pass's uniforms of the last rendered frame.
    pub fn ao_uniforms(&self) -> Option<AoUniforms> {
        self.ao.as_ref().map(|a| a.ao.uniforms())
    }

    /// The bounced-z-buffer pass's uniforms of the last rendered frame.
    pub fn bzb_gi_uniforms(&self) -> Option<crate::passes::bzb::gi::GiUniforms> {
        self.bzb_gi.as_ref().map(|g| g.uniforms())
    }

    /// The BZB AO stage's uniforms of the last rendered frame.
    pub fn bzb_uniforms(&self) -> Option<crate::passes::bzb::BzbUniforms> {
        self.bzb.as_ref().map(|b| b.uniforms())
    }

    /// With BZB AOV splatting: the last frame's depth tiles (`bzb-zminmax`).
    pub fn bzb_zminmax(&self, gpu: &GpuContext) -> Option<Result<Vec<[f32; 2]>, RenderError>> {
        Some(self.bzb.as_ref()?.zminmax()?.read_tiles(gpu))
    }

    /// BZB §4.3 / Table 2: the DSS surfel counts of the last frame (`bzb-ao` or `bzb-gi`
    /// with `splat = dss`).
    pub fn dss_counts(&self, gpu: &GpuContext) -> Option<Result<crate::passes::bzb::dss::SurfelCounts, RenderError>> {
        if let Some(g) = &self.bzb_gi {
            return Some(g.dss()?.read_counts(gpu, g.triangle_count()));
        }
        let b = self.bzb.as_ref()?;
        Some(b.dss()?.read_counts(gpu, b.triangle_count()))
    }

    /// With DSS splatting: a one-line message when the last frame's
    /// surfelization overflowed a buffer ([`crate::passes::bzb::dss::SurfelCounts::overflow`]).
    pub fn dss_overflow(&self, gpu: &GpuContext) -> Option<Result<Option<String>, RenderError>> {
        let (d, triangles) = match (&self.bzb_gi, &self.bzb) {
            (Some(g), _) => (g.dss()?, g.triangle_count()),
            (None, Some(b)) => (b.dss()?, b.triangle_count()),
            (None, None) => return None,
        };
        Some(d.read_counts(gpu, triangles).map(|c| c.overflow(d.capacity())))
    }

    /// The DSS surfels of the last frame (GPU append order).
    pub fn dss_surfels(&self, gpu: &GpuContext) -> Option<Result<Vec<crate::passes::bzb::dss::Surfel>, RenderError>> {
        let b = self.bzb.as_ref()?;
        let d = b.dss()?;
        Some(d.read_counts(gpu, b.triangle_count()).and_then(|c| {
            d.read_surfels(
                gpu,
                c.surfels
                    .min(crate::passes::bzb::dss::capacities(b.triangle_count())[2]),
            )
        }))
    }

    /// `bzb-gi` with `splat = dss`: the last frame's surfels (GPU append order)
    /// with their shaded radiance towards +n (emission included) and −n.
    #[allow(clippy::type_complexity)]
    pub fn dss_gi_surfels(
        &self,
        gpu: &GpuContext,
    ) -> Option<Result<Vec<(crate::passes::bzb::dss::Surfel, glam::Vec3, glam::Vec3)>, RenderError>> {
        let g = self.bzb_gi.as_ref()?;
        let d = g.dss()?;
        Some((|| {
            let c = d.read_counts(gpu, g.triangle_count())?;
            let n = c.surfels.min(d.capacity()[2]);
            let sf = d.read_surfels(gpu, n)?;
            let l = d.read_radiance(gpu, n)?;
            Ok(sf.into_iter().zip(l).map(|(s, (a, b))| (s, a, b)).collect())
        })())
    }

    /// MIP level `mip` of target `name` (layer 0, whole texture incl. guard band).
    pub fn read_target_mip(&self, gpu: &GpuContext, name: &str, mip: u32) -> Result<ImageBuf, RenderError> {
        let t = self
            .targets
            .try_get(name)
            .ok_or_else(|| RenderError::Parameter(format!("unknown target '{name}'")))?;
        if mip >= t.desc.mips {
            return Err(RenderError::Parameter(format!(
                "target '{name}' has {} MIP level(s): level {mip} is out of range",
                t.desc.mips
            )));
        }
        let bytes = gpu.read_texture_level(&t.texture, 0, mip)?;
        let (w, h) = ((t.texture.width() >> mip).max(1), (t.texture.height() >> mip).max(1));
        decode_texels(&bytes, t.desc.format, w, h)
    }

    /// Target `name`'s texture (whole, guard band included), if the frame has it: e.g. the
    /// deep G-buffer's `depth` and `normal` as an application's G-buffer
    /// (`strata_render::embed`'s tests).
    pub fn target_texture(&self, name: &str) -> Option<&wgpu::Texture> {
        self.targets.try_get(name).map(|t| &t.texture)
    }

    /// The declaration of target `name` (format, layers, MIP levels), if the frame has it.
    pub fn target_desc(&self, name: &str) -> Option<crate::frame::TargetDesc> {
        self.targets.try_get(name).map(|t| t.desc)
    }

    /// Names of every readable target (each can be a debug view).
    pub fn target_names(&self) -> Vec<&'static str> {
        self.targets.names().copied().collect()
    }

    /// Reads layer 0 of target `name`, cropped to the image (guard band removed),
    /// as floats (sRGB targets decoded to linear).
    pub fn read_target(&self, gpu: &GpuContext, name: &str) -> Result<ImageBuf, RenderError> {
        self.read_target_layer(gpu, name, 0)
    }

    /// Reads array layer `layer` of target `name`, cropped to the image.
    pub fn read_target_layer(&self, gpu: &GpuContext, name: &str, layer: u32) -> Result<ImageBuf, RenderError> {
        let full = self.read_target_full(gpu, name, layer)?;
        let (origin, size) = self.image_region(full.width, full.height);
        Ok(if origin == [0, 0] && size == [full.width, full.height] {
            full
        } else {
            crop(&full, origin[0], origin[1], size[0], size[1])
        })
    }

    /// The region of target `name` (layer 0) that [`Renderer::read_target`] reads: what a
    /// window shows without reading it back ([`crate::display`]).
    pub fn display_region(&self, name: &str) -> Option<crate::display::Region<'_>> {
        let texture = &self.targets.try_get(name)?.texture;
        let (origin, size) = self.image_region(texture.width(), texture.height());
        Some(crate::display::Region {
            texture,
            layer: 0,
            origin,
            size,
        })
    }

    /// The image inside the guard band of a `w`×`h` target; a target of its own size (the
    /// ILS tiled buffers) is the image whole.
    fn image_region(&self, w: u32, h: u32) -> ([u32; 2], [u32; 2]) {
        if (w, h) != (self.targets.width, self.targets.height) {
            return ([0, 0], [w, h]);
        }
        let g = self.settings.guard_pixels();
        ([g, g], [self.settings.width, self.settings.height])
    }

    /// Reads array layer `layer` of target `name` including the guard band.
    pub fn read_target_full(&self, gpu: &GpuContext, name: &str, layer: u32) -> Result<ImageBuf, RenderError> {
        let t = self.targets.try_get(name).ok_or_else(|| {
            RenderError::Parameter(format!(
                "unknown target '{name}': valid names are {}",
                self.target_names().join(", ")
            ))
        })?;
        if layer >= t.desc.layers {
            return Err(RenderError::Parameter(format!(
                "target '{name}' has {} layer(s): layer {layer} is out of range",
                t.desc.layers
            )));
        }
        let bytes = gpu.read_texture(&t.texture, layer)?;
        decode_texels(&bytes, t.desc.format, t.texture.width(), t.texture.height())
    }

    /// Display-ready debug views: every target (layer 0), every layer of the
    /// per-layer G-buffer arrays as `layerJ-NAME` (J counts from 0 as in the
    /// paper's Z[0], Z[1]), derived channels (roughness, metallic) and, for
    /// DELAY/PREDICT, `predicted-csz` (the oracle for the next frame).
    pub fn debug_view_names(&self) -> Vec<String> {
        let mut v: Vec<String> = self.target_names().iter().map(|s| s.to_string()).collect();
        v.extend(["roughness", "metallic"].iter().map(|s| s.to_string()));
        for j in 0..self.settings.deep.layers {
            for n in PER_LAYER_VIEWS {
                if n != "motion" || self.targets.try_get("motion").is_some() {
                    v.push(format!("layer{j}-{n}"));
                }
            }
        }
        if self.settings.deep.array_layers() > self.settings.deep.layers {
            v.push("predicted-csz".into());
        }
        if self.ils.is_some() && self.targets.try_get("ils-gbuffer-split").is_some() {
            // the split G-buffer's normals and depths (Fig. 3 b)
            v.extend(["ils-split-normal", "ils-split-csz"].map(String::from));
        }
        if self.ils.is_some() && self.targets.try_get("ils-discontinuity").is_some() {
            // the share of the VPL subsets each blurred pixel averaged (what `refine` reads)
            v.push("ils-coverage".into());
        }
        if self.radiosity.is_some() {
            // Fig. 9's views: confidence, G-buffer-only, probe-only, blended
            v.extend(["confidence", "gbuffer-only", "probe-only", "blended"].map(String::from));
        }
        if let Some(a) = &self.abuffer {
            // the k-th nearest fragment of every list, and the compressed nodes
            for k in 0..ABUFFER_LAYER_VIEWS {
                v.push(format!("abuffer-layer{k}"));
            }
            for j in 0..a.settings().compress.unwrap_or(0).min(ABUFFER_LAYER_VIEWS) {
                v.push(format!("abuffer-node{j}-depth"));
                v.push(format!("abuffer-node{j}-alpha"));
            }
        }
        v.sort();
        v
    }

    /// A debug view as an image: normals mapped to 0.5 + 0.5·n, depths normalised
    /// to [0, 1] by their maximum (`exr_raw` keeps raw values for EXR output).
    pub fn debug_view(&self, gpu: &GpuContext, name: &str, exr_raw: bool) -> Result<ImageBuf, RenderError> {
        if !self.debug_view_names().iter().any(|n| n == name) {
            return Err(RenderError::Parameter(format!(
                "unknown debug view '{name}': valid views are {}",
                self.debug_view_names().join(", ")
            )));
        }
        let (layer, base) = match name.strip_prefix("layer").and_then(|r| r.split_once('-')) {
            Some((j, n)) => (j.parse::<u32>().unwrap_or(0), n),
            None if name == "predicted-csz" => (self.settings.deep.layers, "csz"),
            None => (0, name),
        };
        let normalise = |mut img: ImageBuf| {
            if !exr_raw {
                let max = img.data.iter().cloned().fold(0.0f32, f32::max).max(1e-9);
                img.data.iter_mut().for_each(|v| *v /= max);
            }
            img
        };
        if let (Some(a), Some(rest)) = (&self.abuffer, name.strip_prefix("abuffer-")) {
            if let Some(img) = self.abuffer_view(gpu, a, rest, exr_raw)? {
                return Ok(img);
            }
        }
        match base {
            "confidence" => Ok(self.read_target(gpu, "indirect")?.channel(3)),
            "ils-split-normal" => {
                let t = self.read_target(gpu, "ils-gbuffer-split")?;
                let mut img = ImageBuf::new(t.width, t.height, 3);
                for (o, p) in img.data.chunks_exact_mut(3).zip(t.data.chunks_exact(4)) {
                    for c in 0..3 {
                        o[c] = if exr_raw || p[3] <= 0.0 { p[c] } else { 0.5 + 0.5 * p[c] };
                    }
                }
                Ok(img)
            }
            "ils-split-csz" => Ok(normalise(self.read_target(gpu, "ils-gbuffer-split")?.channel(3))),
            // §4.5's flag as grey
            "ils-discontinuity" => Ok(self.read_target(gpu, base)?.channel(3)),
            // the blur's coverage (the blurred irradiance's alpha) as grey
            "ils-coverage" if self.targets.try_get("ils-discontinuity").is_some() => {
                Ok(self.read_target(gpu, "indirect")?.channel(3))
            }
            "ils-irradiance" | "ils-irradiance-tiled" | "ils-blur-h" | "indirect" if self.ils.is_some() => {
                Ok(pad_channels(&self.read_target(gpu, base)?, 3))
            }
            // Fig. 9's irradiance views: raw E in EXR; in PNG the light each E adds to the frame,
            // shown through the frame's exposure and tone curve (`indirect_display`)
            "gbuffer-only" | "probe-only" | "blended" => {
                let target = match base {
                    "gbuffer-only" => "indirect",
                    "probe-only" => "probe-irradiance",
                    _ => "indirect-blended",
                };
                let e = pad_channels(&self.read_target(gpu, target)?, 3);
                if exr_raw {
                    return Ok(e);
                }
                self.indirect_display(gpu, &e)
            }
            "normal" => {
                let n = self.read_normals_layer(gpu, layer)?;
                let mut img = ImageBuf::new(n.width, n.height, 3);
                for (o, p) in img.data.chunks_exact_mut(3).zip(n.data.chunks_exact(3)) {
                    for c in 0..3 {
                        o[c] = if exr_raw { p[c] } else { 0.5 + 0.5 * p[c] };
                    }
                }
                Ok(img)
            }
            "roughness" | "metallic" => {
                let t = self.read_target_layer(gpu, "normal", layer)?;
                Ok(t.channel(if base == "roughness" { 2 } else { 3 }))
            }
            // fragments per pixel: raw counts in EXR, a heat map (0 black … max white) in PNG
            "abuffer-count" => {
                let c = self.read_target(gpu, base)?;
                if exr_raw {
                    return Ok(c);
                }
                let c = normalise(c);
                let mut img = ImageBuf::new(c.width, c.height, 3);
                for (o, v) in img.data.chunks_exact_mut(3).zip(&c.data) {
                    o.copy_from_slice(&heat(*v));
                }
                Ok(img)
            }
            "csz" | "depth" | "csz-history" => Ok(normalise(self.read_target_layer(gpu, base, layer)?.channel(0))),
            "zpack" | "zpack23" => {
                let z = normalise(self.read_target(gpu, base)?);
                Ok(pad_channels(&z, 3))
            }
            // Colours without their alpha: an empty pixel shows black, not transparent.
            "albedo" | "emission" | "motion" => Ok(pad_channels(&self.read_target_layer(gpu, base, layer)?, 3)),
            _ => self.read_target_layer(gpu, base, layer),
        }
    }

    /// Irradiance `e` (RGB, layer 0's receivers) as the final image shows the light it adds:
    /// ρ/π · boost(ρ) · E with ρ = albedo · (1 − metallic) as `compose.wgsl` reflects it, then the
    /// last frame's exposure and the ACES curve of `tonemap.wgsl` (display values in [0, 1],
    /// linear; PNG output encodes sRGB as for the final image). Background pixels are black.
    pub fn indirect_display(&self, gpu: &GpuContext, e: &ImageBuf) -> Result<ImageBuf, RenderError> {
        let albedo = self.read_target_layer(gpu, "albedo", 0)?;
        let normal = self.read_target_layer(gpu, "normal", 0)?;
        let csz = self.read_target(gpu, "csz")?;
        let boost = self.settings.radiosity.as_ref().is_some_and(|r| r.boost);
        let exposure = self.displayed_exposure(gpu)?;
        let mut out = ImageBuf::new(e.width, e.height, 3);
        let (ca, cn, ce, cz) = (
            albedo.channels as usize,
            normal.channels as usize,
            e.channels as usize,
            csz.channels as usize,
        );
        for (i, o) in out.data.chunks_exact_mut(3).enumerate() {
            if csz.data[i * cz] <= 0.0 {
                continue;
            }
            let m = 1.0 - normal.data[i * cn + 3];
            let rho = glam::Vec3::from_slice(&albedo.data[i * ca..i * ca + 3]) * m;
            let k = if boost {
                crate::passes::radiosity::boost(rho)
            } else {
                1.0
            };
            for c in 0..3 {
                let l = rho[c] / std::f32::consts::PI * e.data[i * ce + c] * k;
                o[c] = crate::passes::tonemap::tonemap(l, exposure);
            }
        }
        Ok(out)
    }

    /// The A-buffer views read back on the CPU (`rest` = the name after
    /// `abuffer-`): `layer{k}` = the k-th nearest fragment's radiance × α (black
    /// where the list is shorter), `node{j}-depth` / `node{j}-alpha` = compressed
    /// node j's normalised depth (empty: black) and opacity. `None`: not one of them.
    fn abuffer_view(
        &self,
        gpu: &GpuContext,
        a: &crate::passes::abuffer::ABufferStage,
        rest: &str,
        exr_raw: bool,
    ) -> Result<Option<ImageBuf>, RenderError> {
        let (w, h) = (self.targets.width, self.targets.height);
        let mut img;
        if let Some(k) = rest.strip_prefix("layer").and_then(|k| k.parse::<usize>().ok()) {
            let lists = a.read_lists(gpu)?;
            img = ImageBuf::new(w, h, 3);
            for (o, l) in img.data.chunks_exact_mut(3).zip(&lists.lists) {
                if let Some(f) = l.get(k) {
                    for (o, r) in o.iter_mut().zip(f.radiance) {
                        *o = r * f.alpha;
                    }
                }
            }
            if !exr_raw {
                // the PNG shows it tonemapped like the frame: the last frame's exposure (the
                // scene's unless overridden; was the override or 1) and the final ACES curve
                // (was Reinhard)
                let e = self.displayed_exposure(gpu)?;
                img.data
                    .iter_mut()
                    .for_each(|v| *v = crate::passes::tonemap::tonemap(*v, e));
            }
        } else if let Some((j, what)) = rest
            .strip_prefix("node")
            .and_then(|r| r.split_once('-'))
            .and_then(|(j, w)| Some((j.parse::<usize>().ok()?, w)))
        {
            let Some(nodes) = a.read_compressed(gpu)? else {
                return Ok(None);
            };
            img = ImageBuf::new(w, h, 1);
            for (o, n) in img.data.iter_mut().zip(&nodes) {
                let word = n.get(j).copied().unwrap_or(0xffff_0000);
                let alpha = (word & 0xffff) as f32 / 65535.0;
                *o = match what {
                    "alpha" => alpha,
                    // normalised depth z/65535; an empty node (α = 0) is black
                    _ if alpha > 0.0 => (word >> 16) as f32 / 65535.0,
                    _ => 0.0,
                };
            }
        } else {
            return Ok(None);
        }
        let g = self.settings.guard_pixels();
        Ok(Some(crop(&img, g, g, self.settings.width, self.settings.height)))
    }

    /// World-space normals of layer 0 (decoded Oct16), 3 channels; zero where no surface.
    pub fn read_normals(&self, gpu: &GpuContext) -> Result<ImageBuf, RenderError> {
        self.read_normals_layer(gpu, 0)
    }

    /// World-space normals of layer `layer`, cropped; zero where no surface.
    pub fn read_normals_layer(&self, gpu: &GpuContext, layer: u32) -> Result<ImageBuf, RenderError> {
        let t = self.read_target_layer(gpu, "normal", layer)?;
        let csz = self.read_target_layer(gpu, "csz", layer)?;
        let mut img = ImageBuf::new(t.width, t.height, 3);
        for (i, px) in t.data.chunks_exact(4).enumerate() {
            if csz.data[i] > 0.0 {
                let q = |v: f32| (v * 255.0).round() as u8;
                let n = crate::packing::oct16_unpack([q(px[0]), q(px[1])]);
                img.data[i * 3..i * 3 + 3].copy_from_slice(&n.to_array());
            }
        }
        Ok(img)
    }
}

/// Per-layer debug views (`layerJ-NAME`).
const PER_LAYER_VIEWS: [&str; 8] = [
    "csz",
    "depth",
    "normal",
    "albedo",
    "emission",
    "motion",
    "roughness",
    "metallic",
];

/// The `w`×`h` window of `img` starting at (`x0`, `y0`).
/// The `abuffer-layer{k}` debug views (and at most this many `abuffer-node{j}-*`).
pub const ABUFFER_LAYER_VIEWS: u32 = 4;

pub fn crop(img: &ImageBuf, x0: u32, y0: u32, w: u32, h: u32) -> ImageBuf {
    if x0 == 0 && y0 == 0 && w == img.width && h == img.height {
        return img.clone();
    }
    let c = img.channels as usize;
    let mut out = ImageBuf::new(w, h, img.channels);
    for y in 0..h {
        let src = ((y + y0) * img.width + x0) as usize * c;
        let dst = (y * w) as usize * c;
        out.data[dst..dst + w as usize * c].copy_from_slice(&img.data[src..src + w as usize * c]);
    }
    out
}

/// `img` with `channels` channels (extra ones zero).
fn pad_channels(img: &ImageBuf, channels: u32) -> ImageBuf {
    let mut out = ImageBuf::new(img.width, img.height, channels);
    let (a, b) = (img.channels as usize, channels as usize);
    for (o, p) in out.data.chunks_exact_mut(b).zip(img.data.chunks_exact(a)) {
        let n = a.min(b);
        o[..n].copy_from_slice(&p[..n]);
    }
    out
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
        F::Rg32Float => (2, bytemuck::cast_slice::<u8, f32>(bytes).to_vec()),
        F::Rg11b10Ufloat => (
            3,
            bytemuck::cast_slice::<u8, u32>(bytes)
                .iter()
                .flat_map(|&p| rg11b10_to_f32(p))
                .collect(),
        ),
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

/// Unpacks an `Rg11b10Ufloat` texel (r: bits 0–10, g: 11–21, b: 22–31; unsigned
/// floats with a 5-bit exponent, bias 15, and 6/6/5 mantissa bits).
pub fn rg11b10_to_f32(p: u32) -> [f32; 3] {
    fn small_float(bits: u32, mantissa_bits: u32) -> f32 {
        let m = bits & ((1 << mantissa_bits) - 1);
        let e = bits >> mantissa_bits;
        let scale = (1u32 << mantissa_bits) as f32;
        match e {
            0 => (m as f32 / scale) * 2f32.powi(-14),
            31 => {
                if m == 0 {
                    f32::INFINITY
                } else {
                    f32::NAN
                }
            }
            _ => 2f32.powi(e as i32 - 15) * (1.0 + m as f32 / scale),
        }
    }
    [
        small_float(p & 0x7ff, 6),
        small_float((p >> 11) & 0x7ff, 6),
        small_float(p >> 22, 5),
    ]
}

/// A heat-map colour of `v` in [0, 1]: black → blue → red → yellow → white.
fn heat(v: f32) -> [f32; 3] {
    const STOPS: [[f32; 3]; 5] = [
        [0.0, 0.0, 0.0],
        [0.0, 0.0, 1.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [1.0, 1.0, 1.0],
    ];
    let x = v.clamp(0.0, 1.0) * 4.0;
    let i = (x.floor() as usize).min(3);
    let f = x - i as f32;
    std::array::from_fn(|c| STOPS[i][c] + f * (STOPS[i + 1][c] - STOPS[i][c]))
}
