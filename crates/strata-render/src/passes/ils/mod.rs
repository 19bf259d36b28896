//! Interleaved deferred shading of virtual point lights (Segovia, Iehl,
//! Mitanchey, Péroche 2006, "ILS"), §4's pipeline in the interactive mode of
//! §6.2 (one bounce, visibility of the VPLs ignored: SNSM):
//!
//! | pass | ILS | what |
//! |---|---|---|
//! | `ils-gbuffer` | §4.1 BC | layer 0's normal and csz packed into one RGBA32F buffer |
//! | `ils-bs` | §4.2 BS | split into n×m sub-buffers ([`Interleave`], any [`SplitMethod`]) |
//! | `ils-snsm` | §4.3 SNSM | sub-buffer (i, j) shaded with its own subset of the N VPLs |
//! | `ils-bg` | §4.4 BG | the tiled irradiance gathered back to the image |
//! | `ils-bg-glossy` | – | the same for the glossy receivers' GGX radiance (`ils-glossy`), in scenes with glossy materials |
//! | `ils-db` | §4.5 DB | discontinuity buffer (depth and normal vs the three positive neighbours) |
//! | `ils-blur-h`, `ils-blur-v` | §4.5 B | separable Gaussian blur stopping at discontinuities (Fig. 4 a or b) |
//! | `ils-blur-glossy-h`, `-v` | – | the same blur over `ils-glossy` (docs/ils.md, "Glossy receivers"); only in scenes with glossy materials |
//! | `ils-spike`, `ils-peak-h`, `ils-peak-v` | – | only with [`IlsSettings::refine_peak`]: each gathered texel's spike over its own VPL subset one pattern period away, and the largest within the blur's window (not in the paper) |
//! | `ils-refine` | – | only with [`IlsSettings::refine`], [`IlsSettings::refine_roughness`] or [`IlsSettings::refine_peak`]: pixels the blur averaged too few VPL subsets for, sharp glossy receivers, and pixels whose window holds a spike (a VPL close to the receivers), shaded with all N VPLs (not in the paper) |
//! | `compose` | Fig. 3 g | final = direct + ρ/π · blurred irradiance + blurred glossy radiance (the shared compose pass) |
//!
//! With [`IlsSettings::brute_force`] the three middle passes are replaced by
//! `ils-brute-force`: every pixel, all N VPLs (Table 4's "no IS"), with the
//! same shading code (`shaders/common/vpl.wgsl`); DB and B do not run then
//! (nothing is interleaved, so there is nothing to blur).
//!
//! **VPL assignment.** VPL k goes to sub-buffer s = k mod (n·m), s = j·n + i,
//! so the subsets partition the N VPLs; a pixel of sub-buffer s sums its
//! N_s = ⌈(N − s)/(n·m)⌉ VPLs and scales by N/N_s (= n·m when n·m divides N):
//! its estimate of the full sum is unbiased over the choice of subset.
//!
//! **Shading.** Irradiance E(x) = Σ_k Φ_k/π · cos θ_y cos θ_x / d² with the
//! geometry term clamped to 1/d_c² ([`IlsSettings::clamp_distance`]; default
//! [`DEFAULT_CLAMP_SHARE`] = 4 % of the scene's bounding-box diagonal); Lambertian receivers, ρ/π applied
//! in compose after the blur (§4.5: object colours are never filtered).
//! Receivers of `Material::glossy` materials (emission.a = 2 in the G-buffer)
//! get Σ_k f_GGX(v, l_k) Φ_k/π · (same clamped geometry term) instead, in a
//! second target `ils-glossy` (divided by `ggx_demodulation`, so the blur keeps
//! textures) that compose multiplies back and adds as radiance.
//!
//! **VPLs come from the caller.** strata-render does not trace light paths:
//! the caller generates the VPLs on the CPU (`strata_reference::Reference::vpls`,
//! instant radiosity) and passes them in [`IlsSettings::vpls`], as light probes
//! are passed. They are uploaded once when the renderer is built; static scenes
//! generate them once (the CLI does), a caller with moving lights regenerates
//! them and calls [`crate::Renderer::set_vpls`] per frame.

use std::sync::Arc;

use crate::frame::{Pass, PassInfo, TargetDesc, Targets};
use crate::gpu::GpuContext;
use crate::passes::builder::{FullscreenPass, PassBuilder};
use crate::passes::interleave::{Interleave, SplitMethod, PADDING_MARKER};
use crate::scene_gpu::GpuScene;
use crate::RenderError;

pub mod ssm;

/// Most VPLs one frame accepts.
pub const MAX_VPLS: u32 = 65536;

/// SSM's shadow-map pass (§4.3: one cube map per VPL, `ssm`).
pub const VPL_SHADOW_PASS: &str = "ils-vpl-shadows";

/// The brute-force baseline's pass (replaces BS, SNSM, BG).
pub const BRUTE_FORCE_PASS: &str = "ils-brute-force";

/// One VPL as the GPU reads it (`shaders/common/vpl.wgsl`; w components unused).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct GpuVpl {
    pub position: [f32; 4],
    /// Unit normal on the side the light arrived from.
    pub normal: [f32; 4],
    /// Reflected power Φ per channel.
    pub flux: [f32; 4],
}

impl GpuVpl {
    pub fn new(position: [f32; 3], normal: [f32; 3], flux: [f32; 3]) -> Self {
        let w = |v: [f32; 3]| [v[0], v[1], v[2], 0.0];
        Self {
            position: w(position),
            normal: w(normal),
            flux: w(flux),
        }
    }
}

/// VPL visibility in the shading (ILS §4.3).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum VplShadows {
    /// SNSM: visibility ignored (§6.2's interactive mode).
    #[default]
    None,
    /// SSM: one omnidirectional shadow map per VPL (six cube faces, `crate::lights`' face
    /// code), the hemisphere above the VPL looked up per receiver (§4.3, §6.3).
    ShadowMaps,
}

impl VplShadows {
    pub fn name(self) -> &'static str {
        match self {
            VplShadows::None => "none",
            VplShadows::ShadowMaps => "vpl",
        }
    }

    /// Whether the VPLs' visibility is part of the shading.
    pub fn traced(self) -> bool {
        self == VplShadows::ShadowMaps
    }
}

/// The default clamp distance d_c as a share of the scene's bounding-box diagonal. ILS
/// gives no value. Swept against the one-bounce path tracer on five scenes (docs/ils.md §
/// "The clamp distance"): against 2 % (the default until 2026-11-29), 4 % lowers the
/// indirect RMSE by 15–28 % on four scenes and keeps still-life's within 1 %, with and
/// without VPL shadows; ꟻLIP and outliers fall or hold; the frames lose 0.5–2.9 % of
/// their light.
pub const DEFAULT_CLAMP_SHARE: f32 = 0.04;

/// Settings of interleaved deferred shading. Defaults: ILS Table 4 / Fig. 9
/// (480 VPLs, 8×6 pattern), Fig. 4 b's bilinear blur with a kernel matched to
/// the pattern.
#[derive(Clone, Debug, PartialEq)]
pub struct IlsSettings {
    /// The VPLs (generated by the caller on the CPU; empty = no indirect light).
    pub vpls: Arc<[GpuVpl]>,
    /// N the caller generates (light paths of instant radiosity); 1..=[`MAX_VPLS`].
    pub vpl_count: u32,
    /// The interleaving pattern n×m, each 1..=16.
    pub pattern: [u32; 2],
    /// BS/BG method: `Naive` (one pass; the fastest on lavapipe, docs/ils-split.md)
    /// or `Blocks` (§3.3), or `Compute` (one compute pass; its destinations get storage usage).
    pub method: SplitMethod,
    /// d_c: the geometry term is clamped to 1/d_c² (scene units; `None`:
    /// [`DEFAULT_CLAMP_SHARE`] of the scene's bounding-box diagonal).
    pub clamp_distance: Option<f32>,
    /// Table 4's "no IS": every pixel shades all N VPLs (no BS, BG, and no DB, B
    /// whatever [`IlsSettings::blur`] says).
    pub brute_force: bool,
    /// Test hook: every sub-buffer shades all N VPLs (scale 1), so the gathered
    /// image must equal the brute force.
    pub all_vpls_per_sub_buffer: bool,
    /// Blur kernel scale s in 0..=4 (0 = no blur): radius ⌊s·n/2⌋ × ⌊s·m/2⌋
    /// taps per side, σ = the radius, so with s = 1 the 2⌊n/2⌋+1 ≥ n taps of a
    /// row cover every sub-buffer (ILS Table 3: 4×4 pattern, 5×5 kernel).
    pub blur: f32,
    /// Fig. 4 b: two texels per bilinear tap (false: Fig. 4 a, texel centres).
    pub bilinear: bool,
    /// Not in the paper: each tap's Gaussian weight is divided by the sum of the
    /// Gaussian over the window's taps of the same sub-buffer (offset mod n along x, mod
    /// m along y), so on a flat region every sub-buffer of a row (column) weighs the
    /// same and the blur removes the interleaved pattern exactly. §4.5's plain Gaussian
    /// weighs them unequally (n = 8, radius 4: 0.75 to 1.22), which leaves a faint n×m
    /// grid on flat walls (docs/ils.md § "Equal sub-buffer weights"). Default true.
    pub equal_subsets: bool,
    /// Not in the paper: the horizontal blur stops only at discontinuities
    /// towards (x+1, y), the vertical one towards (x, y+1), instead of at
    /// §4.5's flag over all three positive neighbours (which leaves pixels along
    /// an edge unblurred across it, visible as speckled outlines).
    pub per_axis_discontinuities: bool,
    /// Not in the paper: where the blur is cut on one side (an edge), the window slides
    /// away from the edge to keep min(2r + 1, n) contiguous texels along x (m along y)
    /// while its other side stays on the surface, so a pixel beside an edge still
    /// averages every VPL subset of its row (column) instead of keeping most of its own
    /// subset's noise: the dark wedges and bright speckles along edges (docs/ils.md §
    /// "Sliding the window at edges"). The slid window weighs its texels equally (equal
    /// sub-buffer weights) or by the Gaussian of their offset. Default false.
    pub slide_window: bool,
    /// DB: a neighbour is a discontinuity beyond this distance from the
    /// pixel's tangent plane, relative to its depth z (> 0).
    pub depth_threshold: f32,
    /// DB: … or when the normals differ by more than this (degrees, 0..=180).
    pub normal_threshold_deg: f32,
    /// VPL visibility: SNSM (none) or SSM (per-VPL shadow maps).
    pub shadows: VplShadows,
    /// SSM: texels per side of each of a VPL's six cube faces, 8..=512.
    pub vpl_shadow_resolution: u32,
    /// SSM: keep the VPL shadow maps from frame to frame while the VPLs (`set_vpls`)
    /// and the scene (no animated object) hold still; false redraws them every frame,
    /// as §6.3's fresh VPL sets must (what the bench's per-map cost measures). Not in
    /// the paper; default true.
    pub vpl_shadow_cache: bool,
    /// Not in the paper: after the blur, pixels that averaged less than this share
    /// of the n·m VPL subsets (edges, thin features: speckles) are shaded again with
    /// all N VPLs (`ils-refine`, docs/ils.md § "Refining the pixels the blur misses").
    /// 0..=1; 0 = off.
    pub refine: f32,
    /// Not in the paper: `ils-refine` also shades glossy receivers smoother than this
    /// roughness with all N VPLs. Neighbours see different reflections in a sharp lobe,
    /// so the blur cannot rebuild it from their subsets and it stays as n×m blocks.
    /// 0..=1; 0 = off.
    pub refine_roughness: f32,
    /// Not in the paper: `ils-refine` also shades the Lambert receivers whose blur window
    /// holds a gathered texel q that outshines its own VPL subset one pattern period away,
    /// in channel sums G(q) − min G(q ± (n, 0), q ± (0, m)) > `refine_peak` · n·m · B(p),
    /// B the pixel's blurred irradiance (ils_peak.wgsl). A texel holds one VPL subset
    /// ×n·m, so a VPL close to the receivers lights its subset's texel in one n×m block
    /// and not in the next, and the blur spreads that spike over the block: the bright
    /// squares where the brute force has a round VPL blob. A subset bright over several
    /// blocks (a far VPL) is left to the blur. 0..=1; 0 = off (docs/ils.md § "VPLs close
    /// to the receivers").
    pub refine_peak: f32,
}

impl Default for IlsSettings {
    fn default() -> Self {
        Self {
            vpls: Arc::from(Vec::new()),
            vpl_count: 480,
            pattern: [8, 6],
            method: SplitMethod::Naive,
            clamp_distance: None,
            brute_force: false,
            all_vpls_per_sub_buffer: false,
            blur: 1.0,
            bilinear: true,
            equal_subsets: true,
            per_axis_discontinuities: false,
            slide_window: false,
            depth_threshold: 0.02,
            normal_threshold_deg: 25.0,
            shadows: VplShadows::None,
            vpl_shadow_resolution: 64,
            vpl_shadow_cache: true,
            refine: 0.0,
            refine_roughness: 0.0,
            refine_peak: 0.0,
        }
    }
}

/// The `ils` technique's presets (`--preset`), the first the default. Each names what it
/// changes from [`IlsSettings::default`]; every one keeps the VPLs, pattern and shading:
/// - `standard`: §4.5's filter as the defaults have it (nothing changed);
/// - `clean-edges`: the blur stops per axis and slides its cut windows
///   ([`IlsSettings::per_axis_discontinuities`], [`IlsSettings::slide_window`]; not in the
///   paper): most of the speckles and dark wedges along edges go, for about 25 % more
///   blur time (docs/ils.md § "Sliding the window at edges");
/// - `refined`: `clean-edges` and [`IlsSettings::refine`] = 0.5: the pixels that still
///   average fewer than half the VPL subsets are shaded with all N VPLs.
pub const PRESETS: [&str; 3] = ["standard", "clean-edges", "refined"];

impl IlsSettings {
    /// These settings with preset `name` ([`PRESETS`]) applied on top.
    pub fn with_preset(mut self, name: &str) -> Result<Self, String> {
        match name {
            "standard" => {}
            "clean-edges" | "refined" => {
                self.per_axis_discontinuities = true;
                self.slide_window = true;
                if name == "refined" {
                    self.refine = 0.5;
                }
            }
            _ => {
                return Err(format!(
                    "unknown preset '{name}': valid presets are {}",
                    PRESETS.join(", ")
                ))
            }
        }
        Ok(self)
    }

    /// One-line errors naming the parameter and its range.
    pub fn validate(&self) -> Result<(), String> {
        if !(1..=MAX_VPLS).contains(&self.vpl_count) {
            return Err(format!(
                "vpls {} is out of range: must be in 1..={MAX_VPLS}",
                self.vpl_count
            ));
        }
        if self.vpls.len() > MAX_VPLS as usize {
            return Err(format!(
                "{} VPLs were passed: at most {MAX_VPLS} are accepted",
                self.vpls.len()
            ));
        }
        let [n, m] = self.pattern;
        crate::passes::interleave::InterleaveGeometry::new(64, 64, n, m, self.method)?;
        if let Some(d) = self.clamp_distance {
            if !(d > 0.0 && d.is_finite()) {
                return Err(format!("clamp-distance {d} is out of range: must be > 0"));
            }
        }
        if !(0.0..=1.0).contains(&self.refine) {
            return Err(format!("refine {} is out of range: must be in 0..=1", self.refine));
        }
        if !(0.0..=1.0).contains(&self.refine_peak) {
            return Err(format!(
                "refine-peak {} is out of range: must be in 0..=1",
                self.refine_peak
            ));
        }
        if !(0.0..=1.0).contains(&self.refine_roughness) {
            return Err(format!(
                "refine-roughness {} is out of range: must be in 0..=1",
                self.refine_roughness
            ));
        }
        if !(0.0..=4.0).contains(&self.blur) {
            return Err(format!("blur {} is out of range: must be in 0..=4", self.blur));
        }
        if !(self.depth_threshold > 0.0 && self.depth_threshold.is_finite()) {
            return Err(format!(
                "depth-threshold {} is out of range: must be > 0",
                self.depth_threshold
            ));
        }
        if !(0.0..=180.0).contains(&self.normal_threshold_deg) {
            return Err(format!(
                "normal-threshold {} is out of range: must be in 0..=180",
                self.normal_threshold_deg
            ));
        }
        if !(8..=512).contains(&self.vpl_shadow_resolution) {
            return Err(format!(
                "vpl-shadow-resolution {} is out of range: must be in 8..=512",
                self.vpl_shadow_resolution
            ));
        }
        check_vpls(&self.vpls)?;
        Ok(())
    }

    /// d_c in scene units for `scene`.
    pub fn clamp_distance_for(&self, scene: &strata_scene::Scene) -> f32 {
        self.clamp_distance.unwrap_or_else(|| {
            let (lo, hi) = scene.bounds(0.0);
            (DEFAULT_CLAMP_SHARE * (hi - lo).length()).max(1e-6)
        })
    }

    /// The bound of cos θ_y cos θ_x / d² the shading uses for `scene`: 1/d_c².
    pub fn max_geometry(&self, scene: &strata_scene::Scene) -> f32 {
        let d = self.clamp_distance_for(scene);
        1.0 / (d * d)
    }

    /// Blur radii (taps per side) along x and y: ⌊s·n/2⌋, ⌊s·m/2⌋.
    pub fn blur_radius(&self) -> [u32; 2] {
        self.pattern.map(|p| (self.blur * p as f32 * 0.5).floor() as u32)
    }

    /// Whether the DB and blur passes run: `blur` > 0 on the interleaved frame.
    /// The brute force is Table 4's "standard deferred shading": every pixel already
    /// has all N VPLs, so it is never blurred, whatever `blur` says.
    pub fn blurs(&self) -> bool {
        self.blur > 0.0 && !self.brute_force
    }

    /// The target holding the frame's indirect irradiance E for these settings: refined,
    /// blurred, or as gathered.
    pub fn output(&self) -> TargetDesc {
        if self.refines() {
            REFINED
        } else if self.blurs() {
            INDIRECT
        } else {
            IRRADIANCE
        }
    }

    /// Whether `ils-refine` runs (after a blur of the interleaved frame).
    pub fn refines(&self) -> bool {
        (self.refine > 0.0 || self.refine_roughness > 0.0 || self.refine_peak > 0.0) && self.blurs()
    }

    /// The frame's passes for these settings in `scene`, in order. A scene without
    /// glossy materials has no glossy receivers, so its glossy radiance is 0 and is
    /// neither gathered nor blurred.
    pub fn passes(&self, scene: &strata_scene::Scene) -> Vec<&'static str> {
        let glossy = has_glossy_receivers(scene);
        let mut v = vec!["ils-gbuffer"];
        if self.shadows.traced() {
            v.push(VPL_SHADOW_PASS);
        }
        if self.brute_force {
            v.push(BRUTE_FORCE_PASS);
        } else {
            v.extend(["ils-bs", self.shading_pass(), "ils-bg"]);
            if glossy {
                v.push("ils-bg-glossy");
            }
        }
        if self.blurs() {
            v.extend(["ils-db", "ils-blur-h", "ils-blur-v"]);
            if glossy {
                v.extend(["ils-blur-glossy-h", "ils-blur-glossy-v"]);
            }
            if self.refines() {
                if self.refine_peak > 0.0 {
                    v.extend(PEAK_PASSES);
                }
                v.push(REFINE_PASS);
            }
        }
        v.push("compose");
        v
    }

    /// The interleaved shading pass: `ils-snsm`, or `ils-ssm` with VPL shadows (§4.3).
    pub fn shading_pass(&self) -> &'static str {
        if self.shadows.traced() {
            "ils-ssm"
        } else {
            "ils-snsm"
        }
    }

    /// Whether the VPL shadow maps of the first frame serve the next ones (SSM with
    /// `vpl_shadow_cache` in a scene with no animated object, whose motion would change
    /// every VPL's view) until `set_vpls`.
    pub fn vpl_shadow_maps_cached(&self, scene: &strata_scene::Scene) -> bool {
        self.shadows.traced() && self.vpl_shadow_cache && !scene.animated()
    }

    /// How many VPLs the renderer holds room for: those passed, and in a scene with
    /// animated objects as many as `vpl_count` one-bounce paths can make (one per path),
    /// so that the callers' per-frame VPLs (`Renderer::set_vpls`) fit.
    pub fn vpl_capacity(&self, scene: &strata_scene::Scene) -> usize {
        let regenerated = if scene.animated() { self.vpl_count as usize } else { 0 };
        self.vpls.len().max(regenerated).max(1)
    }

    /// Bytes of the VPL shadow maps (SSM): N layers of six R² Depth32Float faces, plus the
    /// face matrices (256-byte uniform stride + packed storage copy); N at most
    /// `vpl_capacity` of an animated scene.
    pub fn shadow_map_bytes(&self) -> u64 {
        if !self.shadows.traced() {
            return 0;
        }
        let r = self.vpl_shadow_resolution as u64;
        self.vpls.len().max(self.vpl_count as usize).max(1) as u64 * 6 * (r * r * 4 + 256 + 64)
    }

    /// Upper bound of the stage's target bytes at `w`×`h` (tiled buffers included).
    pub fn estimated_bytes(&self, w: u32, h: u32) -> u64 {
        let [n, m] = self.pattern;
        let tiled = (w.div_ceil(n.max(1)) * n.max(1)) as u64 * (h.div_ceil(m.max(1)) * m.max(1)) as u64;
        let px = w as u64 * h as u64;
        // gbuffer 16 + irradiance 8 + glossy 8 + DB 8 + blur-h 8 + indirect 8 + compose 24
        // (+ refined 8 + 8 + the refine list's 4; + refine-peak's spike, peak-h and peak
        // 4 + 4 + 4); tiled: 16 + 8 + 8; the Blocks intermediates ≤ 2 more tiled-size buffers
        let refined = if self.refines() { 20 } else { 0 };
        let peak = if self.refines() && self.refine_peak > 0.0 {
            12
        } else {
            0
        };
        px * (80 + refined + peak)
            + tiled * (32 + 24)
            + self.vpls.len().max(self.vpl_count as usize) as u64 * 48
            + self.shadow_map_bytes()
    }
}

/// Targets of the stage.
pub const GBUFFER: TargetDesc = TargetDesc::new(
    "ils-gbuffer",
    wgpu::TextureFormat::Rgba32Float,
    1,
    "ILS §4.1: layer 0's world normal (xyz) and csz (w), the buffer that is split",
);
pub const GBUFFER_SPLIT: TargetDesc = TargetDesc::new(
    "ils-gbuffer-split",
    wgpu::TextureFormat::Rgba32Float,
    1,
    "ILS §4.2 (Fig. 3 b): the packed G-buffer split into n×m tiled sub-buffers",
);
pub const IRRADIANCE_TILED: TargetDesc = TargetDesc::new(
    "ils-irradiance-tiled",
    wgpu::TextureFormat::Rgba16Float,
    1,
    "ILS §4.3 (Fig. 3 c): irradiance of each sub-buffer from its VPL subset, tiled",
);
pub const IRRADIANCE: TargetDesc = TargetDesc::new(
    "ils-irradiance",
    wgpu::TextureFormat::Rgba16Float,
    1,
    "ILS §4.4 (Fig. 3 d): gathered interleaved irradiance (or the brute force's)",
);
pub const GLOSSY_TILED: TargetDesc = TargetDesc::new(
    "ils-glossy-tiled",
    wgpu::TextureFormat::Rgba16Float,
    1,
    "outgoing radiance of glossy (GGX) receivers from each sub-buffer's VPL subset, tiled (0 on Lambert ones)",
);
pub const GLOSSY: TargetDesc = TargetDesc::new(
    "ils-glossy",
    wgpu::TextureFormat::Rgba16Float,
    1,
    "outgoing radiance of glossy (GGX) receivers, gathered; compose adds it as is (0 on Lambert receivers)",
);
pub const GLOSSY_BLURRED: TargetDesc = TargetDesc::new(
    "ils-glossy-blurred",
    wgpu::TextureFormat::Rgba16Float,
    1,
    "ils-glossy after the same discontinuity-aware blur as the irradiance",
);
pub const DISCONTINUITY: TargetDesc = TargetDesc::new(
    "ils-discontinuity",
    wgpu::TextureFormat::Rgba16Float,
    1,
    "ILS §4.5 (Fig. 3 e): a = 1 where a pixel differs from a positive neighbour; r, g: from (x+1, y), (x, y+1)",
);
pub const BLUR_H: TargetDesc = TargetDesc::new(
    "ils-blur-h",
    wgpu::TextureFormat::Rgba16Float,
    1,
    "ILS §4.5: irradiance after the horizontal blur",
);
pub const INDIRECT: TargetDesc = TargetDesc::new(
    "indirect",
    wgpu::TextureFormat::Rgba16Float,
    1,
    "indirect irradiance E of layer 0 (rgb), ILS's blurred result; a = the share of the n·m VPL subsets the blur averaged",
);
pub const REFINED: TargetDesc = TargetDesc::new(
    "ils-refined",
    wgpu::TextureFormat::Rgba16Float,
    1,
    "indirect after ils-refine: pixels the blur averaged too few VPL subsets for shaded with all VPLs",
);
pub const GLOSSY_REFINED: TargetDesc = TargetDesc::new(
    "ils-glossy-refined",
    wgpu::TextureFormat::Rgba16Float,
    1,
    "ils-glossy-blurred after ils-refine",
);
/// `refine-peak` (ils_peak.wgsl): each gathered texel's spike over its own VPL subset one
/// pattern period away, then the largest within the blur's radius along x and along y.
pub const SPIKE: TargetDesc = TargetDesc::new(
    "ils-spike",
    wgpu::TextureFormat::R32Float,
    1,
    "refine-peak: a gathered texel's channel sum over the least of its VPL subset's one pattern period away",
);
pub const PEAK_H: TargetDesc = TargetDesc::new(
    "ils-peak-h",
    wgpu::TextureFormat::R32Float,
    1,
    "refine-peak: the largest ils-spike within the blur's radius along x",
);
pub const PEAK: TargetDesc = TargetDesc::new(
    "ils-peak",
    wgpu::TextureFormat::R32Float,
    1,
    "refine-peak: the largest ils-spike within the blur's window, which ils-refine compares with the blurred irradiance",
);
/// The passes of `refine-peak`, in order.
pub const PEAK_PASSES: [&str; 3] = ["ils-spike", "ils-peak-h", "ils-peak-v"];

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct PeakUniforms {
    pattern: [i32; 2],
    dir: [i32; 2],
    radius: i32,
    _pad: [u32; 3],
}

/// `refine-peak`'s passes (ils_peak.wgsl): `IRRADIANCE` → `SPIKE` → `PEAK_H` → `PEAK`.
fn peak_passes(gpu: &GpuContext, targets: &mut Targets, s: &IlsSettings) -> [FullscreenPass; 3] {
    for t in [SPIKE, PEAK_H, PEAK] {
        targets.create(gpu, t);
    }
    let [n, m] = s.pattern.map(|p| p as i32);
    let [rx, ry] = s.blur_radius().map(|r| r as i32);
    let uniforms = |dir: [i32; 2], radius: i32| PeakUniforms {
        pattern: [n, m],
        dir,
        radius,
        _pad: [0; 3],
    };
    let targets = &*targets;
    let pass = |name: &'static str, entry: &'static str, u: PeakUniforms, src: &'static str, dst: &'static str| {
        PassBuilder::new(gpu, targets, name)
            .shader("ils-peak", include_str!("ils_peak.wgsl"))
            .entry(entry)
            .uniforms(&u)
            .read(src)
            .write(dst)
            .build()
    };
    [
        pass(
            PEAK_PASSES[0],
            "fs_spike",
            uniforms([0, 0], 0),
            IRRADIANCE.name,
            SPIKE.name,
        ),
        pass(
            PEAK_PASSES[1],
            "fs_spread",
            uniforms([1, 0], rx),
            SPIKE.name,
            PEAK_H.name,
        ),
        pass(
            PEAK_PASSES[2],
            "fs_spread",
            uniforms([0, 1], ry),
            PEAK_H.name,
            PEAK.name,
        ),
    ]
}

/// The refinement pass (`IlsSettings::refine`, `IlsSettings::refine_roughness`,
/// `IlsSettings::refine_peak`).
pub const REFINE_PASS: &str = "ils-refine";

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct ShadeUniforms {
    geo: crate::passes::interleave::IlsUniforms,
    vpl_count: u32,
    sub_buffers: u32,
    all_vpls: u32,
    /// `IlsSettings::refine` (ils_refine.wgsl)
    refine: f32,
    max_geometry: f32,
    /// SSM: eye offset, texel size at distance 1, half a texel in face uv.
    ssm: [f32; 3],
    /// `IlsSettings::refine_roughness`
    refine_roughness: f32,
    /// `IlsSettings::refine_peak`
    refine_peak: f32,
    _pad: [u32; 2],
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct FilterUniforms {
    depth_threshold: f32,
    normal_cos: f32,
    radius: u32,
    sigma: f32,
    dir: [i32; 2],
    bilinear: u32,
    channel: u32,
    /// The interleave period along `dir` with [`IlsSettings::equal_subsets`], else 0.
    period: u32,
    /// The interleave pattern's size along `dir` (the blur's coverage; 0 for the DB).
    pattern: u32,
    /// [`IlsSettings::slide_window`] (0 for the DB).
    slide: u32,
    _pad: u32,
    /// [`blur_weights`], four per vec4.
    weights: [[f32; 4]; 9],
}

/// Taps per side the blur's weight table holds: ⌊4 · 16 / 2⌋ (blur ≤ 4, pattern ≤ 16).
const MAX_BLUR_RADIUS: usize = 32;

/// The blur's tap weights at offsets 0..=`radius` (the same at −k): the Gaussian of σ =
/// `sigma`, and with `period` > 1 ([`IlsSettings::equal_subsets`]) each divided by the
/// Gaussian's sum over the window's taps of the same sub-buffer (offsets ≡ k mod
/// `period` in [−radius, radius]), so that on a flat region every sub-buffer weighs 1.
/// The CPU side of `weight` in `ils_filter.wgsl`.
pub fn blur_weights(radius: u32, sigma: f32, period: u32) -> Vec<f32> {
    let gauss = |k: i32| (-0.5 * (k * k) as f32 / (sigma * sigma)).exp();
    let r = radius as i32;
    (0..=r)
        .map(|k| {
            if period <= 1 {
                return gauss(k);
            }
            let p = period as i32;
            let class: f32 = (-r..=r).filter(|j| (j - k).rem_euclid(p) == 0).map(gauss).sum();
            gauss(k) / class
        })
        .collect()
}

/// A one-line error for the first VPL with a non-finite component or a negative flux.
pub fn check_vpls(vpls: &[GpuVpl]) -> Result<(), String> {
    for (k, v) in vpls.iter().enumerate() {
        let finite = v.position.iter().chain(&v.normal).chain(&v.flux).all(|c| c.is_finite());
        if !finite || v.flux.iter().any(|&c| c < 0.0) {
            return Err(format!(
                "vpls[{k}] is invalid: position, normal and flux must be finite and the flux >= 0"
            ));
        }
    }
    Ok(())
}

/// Whether any material of `scene` is glossy (GGX): only then does the frame blur the
/// glossy receivers' radiance (`ils-glossy` is 0 otherwise, and compose reads it as is).
fn has_glossy_receivers(scene: &strata_scene::Scene) -> bool {
    scene.materials.iter().any(|m| m.glossy)
}

/// BS or BG of one target into another, as a frame pass (also used by the
/// deinterleaved AO, `passes::ao::stage`).
pub(crate) struct InterleavePass {
    pub(crate) name: &'static str,
    pub(crate) interleave: Interleave,
    pub(crate) src: &'static str,
    pub(crate) dst: &'static str,
    pub(crate) split: bool,
}

impl Pass for InterleavePass {
    fn info(&self) -> PassInfo {
        PassInfo {
            name: self.name,
            inputs: vec![self.src],
            outputs: vec![self.dst],
        }
    }

    fn encode(&self, _gpu: &GpuContext, _scene: &GpuScene, targets: &Targets, encoder: &mut wgpu::CommandEncoder) {
        let (src, dst) = (&targets.get(self.src).view, &targets.get(self.dst).view);
        let r = if self.split {
            self.interleave.split(encoder, src, dst)
        } else {
            self.interleave.gather(encoder, src, dst)
        };
        // the stage created both targets with the interleave's sizes and format
        r.expect("interleave targets match their interleave geometry");
    }
}

/// §4.5's filter uniforms for a blur of `radius` texels along `dir` (the DB pass: 0,
/// [0, 0]).
fn filter_uniforms(s: &IlsSettings, radius: u32, dir: [i32; 2]) -> FilterUniforms {
    let period = match (s.equal_subsets, dir) {
        (true, [0, 0]) | (false, _) => 0,
        (true, [_, 0]) => s.pattern[0],
        (true, _) => s.pattern[1],
    };
    let sigma = radius.max(1) as f32;
    let mut weights = [[0.0f32; 4]; 9];
    for (k, w) in blur_weights(radius.min(MAX_BLUR_RADIUS as u32), sigma, period)
        .into_iter()
        .enumerate()
    {
        weights[k / 4][k % 4] = w;
    }
    FilterUniforms {
        depth_threshold: s.depth_threshold,
        normal_cos: s.normal_threshold_deg.to_radians().cos(),
        radius,
        sigma,
        dir,
        bilinear: s.bilinear as u32,
        // §4.5's three-neighbour flag (a), or the flag of the blur's own axis (r, g)
        channel: if s.per_axis_discontinuities {
            (dir[1] != 0) as u32
        } else {
            3
        },
        period,
        pattern: match dir {
            [0, 0] => 0,
            [_, 0] => s.pattern[0],
            _ => s.pattern[1],
        },
        slide: (s.slide_window && dir != [0, 0]) as u32,
        _pad: 0,
        weights,
    }
}

/// §4.5's DB pass (from `ils-gbuffer`) and the two blur passes `src` →
/// `ils-blur-h` → `dst` (creates `ils-discontinuity` and `ils-blur-h`).
fn filter_passes(
    gpu: &GpuContext,
    scene_gpu: &GpuScene,
    targets: &mut Targets,
    s: &IlsSettings,
    src: &'static str,
    dst: &'static str,
) -> (FullscreenPass, FullscreenPass, FullscreenPass) {
    targets.create(gpu, DISCONTINUITY);
    targets.create(gpu, BLUR_H);
    let discontinuity = PassBuilder::new(gpu, targets, "ils-db")
        .shader("ils-filter", include_str!("ils_filter.wgsl"))
        .entry("fs_discontinuity")
        .frame(scene_gpu)
        .uniforms(&filter_uniforms(s, 0, [0, 0]))
        .read(GBUFFER.name)
        .write(DISCONTINUITY.name)
        .build();
    let (h, v) = blur_passes(gpu, scene_gpu, targets, s, ["ils-blur-h", "ils-blur-v"], src, dst);
    (discontinuity, h, v)
}

/// The separable discontinuity-aware blur (§4.5) `src` → `ils-blur-h` → `dst`, passes
/// named `names` (horizontal, vertical); the DB and `ils-blur-h` must exist.
fn blur_passes(
    gpu: &GpuContext,
    scene_gpu: &GpuScene,
    targets: &mut Targets,
    s: &IlsSettings,
    names: [&'static str; 2],
    src: &'static str,
    dst: &'static str,
) -> (FullscreenPass, FullscreenPass) {
    let [rx, ry] = s.blur_radius();
    let sampler = gpu.device.create_sampler(&wgpu::SamplerDescriptor {
        label: Some(names[0]),
        mag_filter: wgpu::FilterMode::Linear,
        min_filter: wgpu::FilterMode::Linear,
        ..Default::default()
    });
    let blur = |name: &'static str, src: &'static str, dst: &'static str, u: FilterUniforms| {
        let src_t = targets.get(src);
        let db = targets.get(DISCONTINUITY.name);
        PassBuilder::new(gpu, targets, name)
            .shader("ils-filter", include_str!("ils_filter.wgsl"))
            .entry("fs_blur")
            .frame(scene_gpu)
            .uniforms(&u)
            .view(src, &src_t.view, wgpu::TextureViewDimension::D2, true)
            .view(DISCONTINUITY.name, &db.view, wgpu::TextureViewDimension::D2, true)
            .sampler(&sampler, wgpu::SamplerBindingType::Filtering)
            .write(dst)
            .build()
    };
    let h = blur(names[0], src, BLUR_H.name, filter_uniforms(s, rx, [1, 0]));
    let v = blur(names[1], BLUR_H.name, dst, filter_uniforms(s, ry, [0, 1]));
    (h, v)
}

/// The same blur (kernel, DB) over the glossy receivers' radiance, `GLOSSY` →
/// `GLOSSY_BLURRED` through `BLUR_H` (free again after `ils-blur-v`).
fn glossy_blur_passes(
    gpu: &GpuContext,
    scene_gpu: &GpuScene,
    targets: &mut Targets,
    s: &IlsSettings,
) -> (FullscreenPass, FullscreenPass) {
    targets.create(gpu, GLOSSY_BLURRED);
    let names = ["ils-blur-glossy-h", "ils-blur-glossy-v"];
    blur_passes(gpu, scene_gpu, targets, s, names, GLOSSY.name, GLOSSY_BLURRED.name)
}

/// The ILS passes of a frame (see the module docs).
pub(crate) struct IlsStage {
    gbuffer: FullscreenPass,
    split: Option<InterleavePass>,
    shade: FullscreenPass,
    gather: Option<InterleavePass>,
    /// BG of the glossy receivers' radiance (`ils-glossy`; blurred like the irradiance: docs/ils.md)
    gather_glossy: Option<InterleavePass>,
    discontinuity: Option<FullscreenPass>,
    blur_h: Option<FullscreenPass>,
    blur_v: Option<FullscreenPass>,
    glossy_h: Option<FullscreenPass>,
    glossy_v: Option<FullscreenPass>,
    /// `IlsSettings::refine_peak`: the spikes `refine` compares (ils_peak.wgsl)
    peak: Option<[FullscreenPass; 3]>,
    /// `IlsSettings::refine`, `refine_roughness`, `refine_peak`: the pixels the blur
    /// averaged too few VPL subsets for, sharp glossy receivers and VPLs close to the
    /// receivers
    refine: Option<RefinePass>,
    /// The renderer's composite (`None` in an application's renderer, `embed::EmbeddedIls`).
    compose: Option<crate::passes::compose::ComposePass>,
    vpl_buffer: wgpu::Buffer,
    vpl_capacity: usize,
    shade_uniforms: ShadeUniforms,
    /// SSM's shadow maps (`shadows = vpl`).
    vpl_shadows: Option<ssm::VplShadowPass>,
}

/// A shading pass's WGSL: the shared VPL shading (`ils_vpl_shading.wgsl`) and the
/// file with its bindings and entry points.
macro_rules! shading_shader {
    ($file:literal) => {
        concat!(include_str!("ils_vpl_shading.wgsl"), "\n", include_str!($file))
    };
}

/// SSM's bindings after a shading pass's others: the VPLs' shadow maps, their
/// comparison sampler and face matrices (none without VPL shadows).
fn with_vpl_shadows<'a>(b: PassBuilder<'a>, shadows: &'a Option<ssm::VplShadowPass>) -> PassBuilder<'a> {
    match shadows {
        Some(p) => b
            .depth_view(
                "ils-vpl-shadow-maps",
                &p.array_view,
                wgpu::TextureViewDimension::D2Array,
            )
            .sampler(&p.sampler, wgpu::SamplerBindingType::Comparison)
            .storage(&p.matrices),
        None => b,
    }
}

/// The VPL buffer: `vpls`, then zeros up to `capacity` (at least one VPL).
fn vpl_buffer(gpu: &GpuContext, vpls: &[GpuVpl], capacity: usize) -> wgpu::Buffer {
    use wgpu::util::DeviceExt;
    let mut data = vpls.to_vec();
    data.resize(
        capacity.max(vpls.len()).max(1),
        GpuVpl::new([0.0; 3], [0.0; 3], [0.0; 3]),
    );
    gpu.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("ils vpls"),
        contents: bytemuck::cast_slice(&data),
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
    })
}

/// `ils-refine` (ils_refine.wgsl): `fs_refine_select` keeps every pixel's blurred
/// value and lists the pixels to refine; `cs_refine` shades the listed ones with
/// all N VPLs, dispatched indirectly by the list's count. One pass to the frame.
pub(crate) struct RefinePass {
    /// `RefineList`: the indirect dispatch (3 × u32), the count, one u32 per pixel
    list: wgpu::Buffer,
    /// the list's first 12 bytes, copied: a buffer bound read-write cannot also be
    /// the dispatch's indirect buffer
    args: wgpu::Buffer,
    select: FullscreenPass,
    shade: crate::passes::builder::ComputePass,
}

impl RefinePass {
    /// `blurred`: the irradiance and glossy radiance the kept pixels show.
    fn new(
        gpu: &GpuContext,
        scene_gpu: &GpuScene,
        targets: &mut Targets,
        uniforms: &ShadeUniforms,
        vpl_buffer: &wgpu::Buffer,
        vpl_shadows: &Option<ssm::VplShadowPass>,
        blurred: [&'static str; 2],
    ) -> Self {
        let (w, h) = (targets.width, targets.height);
        for t in [REFINED, GLOSSY_REFINED] {
            targets.create_with_usage(gpu, t, [w, h], wgpu::TextureUsages::STORAGE_BINDING);
        }
        let list = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("ils-refine list"),
            size: 16 + 4 * (w as u64 * h as u64),
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let args = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("ils-refine dispatch"),
            size: 12,
            usage: wgpu::BufferUsages::INDIRECT | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        // bindings 0–8 alike in both steps (ils_refine.wgsl), so one WGSL serves both
        fn common<'a>(
            b: PassBuilder<'a>,
            scene_gpu: &'a GpuScene,
            uniforms: &ShadeUniforms,
            vpl_buffer: &'a wgpu::Buffer,
            blurred: [&'static str; 2],
            list: &'a wgpu::Buffer,
        ) -> PassBuilder<'a> {
            let peak = uniforms.refine_peak > 0.0;
            b.shader("ils-refine", shading_shader!("ils_refine.wgsl"))
                .frame(scene_gpu)
                .uniforms(uniforms)
                .read(GBUFFER.name)
                .storage(vpl_buffer)
                .read_layer("normal", 0)
                .read_layer("albedo", 0)
                .read_layer("emission", 0)
                .read(blurred[0])
                .read(blurred[1])
                .storage_rw(list)
                // refine-peak's window maxima; without it any texture stands in (unread)
                .read(if peak { PEAK.name } else { IRRADIANCE.name })
        }
        let targets = &*targets;
        let select = common(
            PassBuilder::new(gpu, targets, REFINE_PASS),
            scene_gpu,
            uniforms,
            vpl_buffer,
            blurred,
            &list,
        )
        .entry("fs_refine_select")
        .write(REFINED.name)
        .write(GLOSSY_REFINED.name)
        .build();
        let entry = if vpl_shadows.is_some() {
            "cs_refine_ssm"
        } else {
            "cs_refine"
        };
        let b = common(
            PassBuilder::new(gpu, targets, REFINE_PASS).compute(),
            scene_gpu,
            uniforms,
            vpl_buffer,
            blurred,
            &list,
        )
        .entry(entry)
        .write_storage(REFINED.name)
        .write_storage(GLOSSY_REFINED.name);
        let shade = with_vpl_shadows(b, vpl_shadows).build_compute();
        Self {
            list,
            args,
            select,
            shade,
        }
    }

    fn set_uniforms(&self, gpu: &GpuContext, u: &ShadeUniforms) {
        self.select.set_uniforms(gpu, u);
        self.shade.set_uniforms(gpu, u);
    }
}

impl crate::frame::Pass for RefinePass {
    fn info(&self) -> PassInfo {
        let mut info = self.select.info();
        for i in self.shade.info().inputs {
            if !info.inputs.contains(&i) {
                info.inputs.push(i);
            }
        }
        info
    }

    fn encode(&self, _gpu: &GpuContext, scene: &GpuScene, targets: &Targets, encoder: &mut wgpu::CommandEncoder) {
        encoder.clear_buffer(&self.list, 0, Some(16));
        self.select.encode(scene, targets, encoder);
        encoder.copy_buffer_to_buffer(&self.list, 0, &self.args, 0, Some(12));
        self.shade.encode_indirect(scene, encoder, &self.args, 0);
    }
}

impl IlsStage {
    pub(crate) fn new(
        gpu: &GpuContext,
        scene_gpu: &GpuScene,
        targets: &mut Targets,
        s: &IlsSettings,
        scene: &strata_scene::Scene,
        compose: bool,
    ) -> Result<Self, RenderError> {
        s.validate().map_err(RenderError::Parameter)?;
        let (w, h) = (targets.width, targets.height);
        let [n, m] = s.pattern;
        let capacity = s.vpl_capacity(scene);
        let vpl_buffer = vpl_buffer(gpu, &s.vpls, capacity);
        // the compute BS/BG writes its destinations as storage textures: the split
        // G-buffer, and the gathered irradiance and glossy radiance
        let storage = match s.method {
            SplitMethod::Compute if !s.brute_force => wgpu::TextureUsages::STORAGE_BINDING,
            _ => wgpu::TextureUsages::empty(),
        };
        for t in [GBUFFER, INDIRECT] {
            targets.create(gpu, t);
        }
        for t in [IRRADIANCE, GLOSSY] {
            targets.create_with_usage(gpu, t, [w, h], storage);
        }
        let gbuffer = PassBuilder::new(gpu, targets, "ils-gbuffer")
            .shader("ils-gbuffer", include_str!("ils_gbuffer.wgsl"))
            .read_layer("csz", 0)
            .read_layer("normal", 0)
            .write(GBUFFER.name)
            .build();

        let glossy_receivers = has_glossy_receivers(scene);
        let (split, gather, gather_glossy, geo) = if s.brute_force {
            (None, None, None, None)
        } else {
            let bs = Interleave::new(gpu, GBUFFER.format, w, h, n, m, s.method)?;
            let bg = Interleave::new(gpu, IRRADIANCE.format, w, h, n, m, s.method)?;
            let tiled = bs.tiled_size();
            targets.create_with_usage(gpu, GBUFFER_SPLIT, tiled, storage);
            targets.create_sized(gpu, IRRADIANCE_TILED, tiled);
            targets.create_sized(gpu, GLOSSY_TILED, tiled);
            let geo = *bs.geometry();
            let split = InterleavePass {
                name: "ils-bs",
                interleave: bs,
                src: GBUFFER.name,
                dst: GBUFFER_SPLIT.name,
                split: true,
            };
            let gather = InterleavePass {
                name: "ils-bg",
                interleave: bg,
                src: IRRADIANCE_TILED.name,
                dst: IRRADIANCE.name,
                split: false,
            };
            // without glossy receivers the glossy radiance is 0: `ils-glossy` stays as
            // created (zeros) and is not gathered
            let gather_glossy = if glossy_receivers {
                Some(InterleavePass {
                    name: "ils-bg-glossy",
                    interleave: Interleave::new(gpu, GLOSSY.format, w, h, n, m, s.method)?,
                    src: GLOSSY_TILED.name,
                    dst: GLOSSY.name,
                    split: false,
                })
            } else {
                None
            };
            (Some(split), Some(gather), gather_glossy, Some(geo))
        };
        let vpl_shadows = match s.shadows {
            VplShadows::None => None,
            VplShadows::ShadowMaps => {
                let mut p = ssm::VplShadowPass::new(gpu, scene_gpu, scene, &s.vpls, capacity, s.vpl_shadow_resolution)?;
                p.set_cached(s.vpl_shadow_maps_cached(scene));
                Some(p)
            }
        };
        let ssm_uniforms = vpl_shadows.as_ref().map_or([0.0; 3], |p| {
            [
                p.eye_offset(),
                ssm::texel_at_unit_distance(p.resolution()),
                0.5 / p.resolution() as f32,
            ]
        });
        let shade_uniforms = ShadeUniforms {
            geo: geo.map_or(bytemuck::Zeroable::zeroed(), |g| g.uniforms(PADDING_MARKER)),
            vpl_count: s.vpls.len() as u32,
            sub_buffers: if s.brute_force { 1 } else { n * m },
            all_vpls: s.all_vpls_per_sub_buffer as u32,
            refine: s.refine,
            max_geometry: s.max_geometry(scene),
            ssm: ssm_uniforms,
            refine_roughness: s.refine_roughness,
            refine_peak: s.refine_peak,
            _pad: [0; 2],
        };
        let shade = {
            let traced = vpl_shadows.is_some();
            let (name, entry, input, output, output_glossy) = match (s.brute_force, traced) {
                (true, false) => (
                    BRUTE_FORCE_PASS,
                    "fs_brute_force",
                    GBUFFER.name,
                    IRRADIANCE.name,
                    GLOSSY.name,
                ),
                (true, true) => (
                    BRUTE_FORCE_PASS,
                    "fs_brute_force_ssm",
                    GBUFFER.name,
                    IRRADIANCE.name,
                    GLOSSY.name,
                ),
                (false, false) => (
                    "ils-snsm",
                    "fs_snsm",
                    GBUFFER_SPLIT.name,
                    IRRADIANCE_TILED.name,
                    GLOSSY_TILED.name,
                ),
                (false, true) => (
                    "ils-ssm",
                    "fs_ssm",
                    GBUFFER_SPLIT.name,
                    IRRADIANCE_TILED.name,
                    GLOSSY_TILED.name,
                ),
            };
            let b = PassBuilder::new(gpu, targets, name)
                .shader("ils-snsm", shading_shader!("ils_snsm.wgsl"))
                .entry(entry)
                .frame(scene_gpu)
                .uniforms(&shade_uniforms)
                .read(input)
                .storage(&vpl_buffer)
                .read_layer("normal", 0)
                .read_layer("albedo", 0)
                .read_layer("emission", 0);
            with_vpl_shadows(b, &vpl_shadows)
                .write(output)
                .write(output_glossy)
                .build()
        };

        let (mut discontinuity, mut blur_h, mut blur_v) = (None, None, None);
        let (mut glossy_h, mut glossy_v) = (None, None);
        // Without glossy receivers the interleaved frame gathers no glossy radiance:
        // `ils-glossy` stays 0 as created. Compose then reads none, and refine keeps that of
        // the tiled target, which the shading wrote as 0 everywhere.
        let glossy_gathered = glossy_receivers || s.brute_force;
        let unblurred_glossy = if glossy_gathered {
            GLOSSY.name
        } else {
            GLOSSY_TILED.name
        };
        let (shown, glossy_shown) = if s.blurs() {
            let (db, h, v) = filter_passes(gpu, scene_gpu, targets, s, IRRADIANCE.name, INDIRECT.name);
            (discontinuity, blur_h, blur_v) = (Some(db), Some(h), Some(v));
            if glossy_receivers {
                let (gh, gv) = glossy_blur_passes(gpu, scene_gpu, targets, s);
                (glossy_h, glossy_v) = (Some(gh), Some(gv));
                (INDIRECT.name, GLOSSY_BLURRED.name)
            } else {
                (INDIRECT.name, unblurred_glossy)
            }
        } else {
            (IRRADIANCE.name, unblurred_glossy)
        };
        let (mut refine, mut peak) = (None, None);
        let (shown, glossy_shown) = if s.refines() {
            if s.refine_peak > 0.0 {
                peak = Some(peak_passes(gpu, targets, s));
            }
            refine = Some(RefinePass::new(
                gpu,
                scene_gpu,
                targets,
                &shade_uniforms,
                &vpl_buffer,
                &vpl_shadows,
                [shown, glossy_shown],
            ));
            (REFINED.name, GLOSSY_REFINED.name)
        } else {
            (shown, glossy_shown)
        };
        debug_assert_eq!(shown, s.output().name);
        let compose = compose.then(|| {
            for t in crate::passes::compose::OUTPUTS {
                targets.create(gpu, t);
            }
            crate::passes::compose::ComposePass::new(
                gpu,
                scene_gpu,
                targets,
                false,
                None,
                shown,
                glossy_gathered.then_some(glossy_shown),
                false,
            )
        });
        Ok(Self {
            gbuffer,
            split,
            shade,
            gather,
            gather_glossy,
            discontinuity,
            blur_h,
            blur_v,
            glossy_h,
            glossy_v,
            peak,
            refine,
            compose,
            vpl_capacity: capacity,
            vpl_buffer,
            shade_uniforms,
            vpl_shadows,
        })
    }

    /// Replaces the VPLs (at most as many as the renderer was built with).
    pub(crate) fn set_vpls(&mut self, gpu: &GpuContext, vpls: &[GpuVpl]) -> Result<(), RenderError> {
        if vpls.len() > self.vpl_capacity {
            return Err(RenderError::Parameter(format!(
                "{} VPLs passed to set_vpls: the renderer was built for at most {}",
                vpls.len(),
                self.vpl_capacity
            )));
        }
        gpu.queue.write_buffer(&self.vpl_buffer, 0, bytemuck::cast_slice(vpls));
        if let Some(p) = &mut self.vpl_shadows {
            p.set_vpls(gpu, vpls);
        }
        self.shade_uniforms.vpl_count = vpls.len() as u32;
        self.shade.set_uniforms(gpu, &self.shade_uniforms);
        if let Some(p) = &self.refine {
            p.set_uniforms(gpu, &self.shade_uniforms);
        }
        Ok(())
    }

    /// Draws the VPL shadow maps again next frame (SSM; the occluders moved).
    pub(crate) fn invalidate_vpl_shadows(&self) {
        if let Some(p) = &self.vpl_shadows {
            p.invalidate();
        }
    }

    /// Whether the VPL shadow maps are kept from frame to frame (SSM only).
    pub(crate) fn vpl_shadow_maps_cached(&self) -> bool {
        self.vpl_shadows.as_ref().is_some_and(|p| p.cached())
    }

    pub(crate) fn passes(&self) -> Vec<&dyn Pass> {
        let mut v: Vec<&dyn Pass> = vec![&self.gbuffer];
        if let Some(p) = &self.vpl_shadows {
            v.push(p);
        }
        if let Some(p) = &self.split {
            v.push(p);
        }
        v.push(&self.shade);
        if let Some(p) = &self.gather {
            v.push(p);
        }
        if let Some(p) = &self.gather_glossy {
            v.push(p);
        }
        for p in [
            &self.discontinuity,
            &self.blur_h,
            &self.blur_v,
            &self.glossy_h,
            &self.glossy_v,
        ]
        .into_iter()
        .flatten()
        {
            v.push(p);
        }
        for p in self.peak.iter().flatten() {
            v.push(p);
        }
        if let Some(p) = &self.refine {
            v.push(p);
        }
        if let Some(c) = &self.compose {
            v.push(c);
        }
        v
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::{FrameCameras, FrameUniforms};

    fn upload(gpu: &GpuContext, t: &wgpu::Texture, texels: &[[f32; 4]]) {
        let bytes: Vec<u8> = match t.format() {
            wgpu::TextureFormat::Rgba32Float => bytemuck::cast_slice(texels).to_vec(),
            wgpu::TextureFormat::Rgba16Float => texels
                .iter()
                .flatten()
                .flat_map(|&v| f32_to_f16(v).to_le_bytes())
                .collect(),
            f => panic!("{f:?}"),
        };
        let bpp = t.format().block_copy_size(None).unwrap();
        gpu.queue.write_texture(
            t.as_image_copy(),
            &bytes,
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(t.width() * bpp),
                rows_per_image: None,
            },
            t.size(),
        );
    }

    /// f32 → IEEE half (round to nearest; test values are exact halves).
    fn f32_to_f16(v: f32) -> u16 {
        let b = v.to_bits();
        let s = ((b >> 16) & 0x8000) as u16;
        let e = ((b >> 23) & 0xff) as i32 - 127 + 15;
        let m = b & 0x7f_ffff;
        if v == 0.0 {
            return s;
        }
        assert!((1..31).contains(&e), "{v} is not a normal half");
        s | ((e as u16) << 10) | ((m + 0x1000) >> 13) as u16
    }

    /// Runs DB + blur over a synthetic `w`×`h` frame whose pixel (x, y) lies on
    /// plane `plane(x, y)` (facing the camera at depth 1 + plane) with
    /// irradiance `value(plane)`; returns the blurred irradiance (r) and the DB.
    /// One context per test, shared by its filter runs: creating and dropping a
    /// Vulkan device per run (8 in a test) crashed the NVIDIA 580 driver twice
    /// (SIGSEGV) when four test binaries ran at once.
    fn gpu() -> GpuContext {
        GpuContext::new(&crate::GpuOptions::default()).expect("a Vulkan adapter")
    }

    fn filter(
        gpu: &GpuContext,
        s: &IlsSettings,
        w: u32,
        h: u32,
        plane: impl Fn(u32, u32) -> u32,
        value: impl Fn(u32, u32, u32) -> f32,
    ) -> (Vec<f32>, Vec<f32>) {
        let scene = strata_scene::procedural::plane();
        let scene_gpu = GpuScene::new(gpu, &scene);
        let cam = scene.camera;
        let u = FrameUniforms::new(&scene, &FrameCameras::fixed(cam), w, h, 0.0, 1.0);
        scene_gpu.update_frame(gpu, &u);
        let mut targets = Targets::new(w, h);
        for t in [GBUFFER, IRRADIANCE, INDIRECT] {
            targets.create(gpu, t);
        }
        let (db, bh, bv) = filter_passes(gpu, &scene_gpu, &mut targets, s, IRRADIANCE.name, INDIRECT.name);
        let n = [-u.cam_forward[0], -u.cam_forward[1], -u.cam_forward[2]];
        let mut g = Vec::new();
        let mut e = Vec::new();
        for y in 0..h {
            for x in 0..w {
                let p = plane(x, y);
                g.push([n[0], n[1], n[2], 1.0 + p as f32]);
                let v = value(x, y, p);
                e.push([v, v, v, 1.0]);
            }
        }
        upload(gpu, &targets.get(GBUFFER.name).texture, &g);
        upload(gpu, &targets.get(IRRADIANCE.name).texture, &e);
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        for p in [&db, &bh, &bv] {
            Pass::encode(p, gpu, &scene_gpu, &targets, &mut enc);
        }
        gpu.queue.submit([enc.finish()]);
        gpu.check_errors().expect("no wgpu validation error");
        let read = |name: &str| {
            let t = &targets.get(name).texture;
            let bytes = gpu.read_texture(t, 0).unwrap();
            crate::renderer::decode_texels(&bytes, t.format(), w, h).unwrap()
        };
        (
            read(INDIRECT.name).channel(0).data,
            read(DISCONTINUITY.name).channel(3).data,
        )
    }

    fn settings(bilinear: bool) -> IlsSettings {
        IlsSettings {
            bilinear,
            ..Default::default()
        }
    }

    #[test]
    fn blur_keeps_a_constant_image_constant() {
        let gpu = gpu();
        for bilinear in [false, true] {
            let (out, db) = filter(&gpu, &settings(bilinear), 37, 29, |_, _| 0, |_, _, _| 0.75);
            assert!(db.iter().all(|&d| d == 0.0), "one plane has no discontinuity");
            for (i, v) in out.iter().enumerate() {
                assert!((v - 0.75).abs() <= 1e-3, "bilinear {bilinear}: texel {i} = {v}");
            }
        }
    }

    /// `blur_weights`: with a period, the taps of each sub-buffer in the window sum to 1
    /// (every pattern size and kernel scale); without, the plain Gaussian (1 at the centre).
    #[test]
    fn blur_weights_give_every_sub_buffer_the_same_total() {
        for period in 1..=16u32 {
            for blur in [0.5f32, 1.0, 2.0, 4.0] {
                let r = (blur * period as f32 * 0.5).floor() as i32;
                let w = blur_weights(r as u32, r.max(1) as f32, period);
                let plain = blur_weights(r as u32, r.max(1) as f32, 0);
                assert_eq!(plain[0], 1.0);
                if period == 1 || r == 0 {
                    continue;
                }
                let p = period as i32;
                // the sub-buffers the window reaches
                for class in (-r..=r).map(|k| k.rem_euclid(p)) {
                    let total: f32 = (-r..=r)
                        .filter(|k| (k - class).rem_euclid(p) == 0)
                        .map(|k| w[k.unsigned_abs() as usize])
                        .sum();
                    assert!(
                        (total - 1.0).abs() < 1e-5,
                        "period {period}, blur {blur}, class {class}: {total}"
                    );
                }
            }
        }
    }

    /// The gathered image of one flat plane is the 8×6 interleaved pattern of its
    /// sub-buffers' values. With equal sub-buffer weights (the default) every pixel at
    /// least a kernel radius from the border blurs to the mean of the 48 values (texel
    /// taps: exactly; bilinear taps: within 0.4 %); §4.5's plain Gaussian leaves the grid
    /// (the control, ~1 %).
    #[test]
    fn equal_subset_weights_remove_the_interleaved_pattern() {
        let (w, h) = (48u32, 36u32);
        // 48 distinct values k/64, exact in f16
        let v = |x: u32, y: u32| (8 + ((x % 8) * 6 + y % 6) * 7 % 48) as f32 / 64.0;
        let mean = (0..8).flat_map(|i| (0..6).map(move |j| v(i, j))).sum::<f32>() / 48.0;
        let gpu = gpu();
        for (bilinear, equal) in [(false, true), (true, true), (false, false), (true, false)] {
            let s = IlsSettings {
                equal_subsets: equal,
                ..settings(bilinear)
            };
            let [rx, ry] = s.blur_radius();
            let (out, _) = filter(&gpu, &s, w, h, |_, _| 0, |x, y, _| v(x, y));
            let worst = (ry..h - ry)
                .flat_map(|y| (rx..w - rx).map(move |x| (x, y)))
                .map(|(x, y)| (out[(y * w + x) as usize] - mean).abs() / mean)
                .fold(0.0f32, f32::max);
            eprintln!("bilinear {bilinear}, equal sub-buffers {equal}: worst relative deviation {worst}");
            if equal {
                // texel taps: exact; bilinear taps: the sampler's sub-texel precision
                let bound = if bilinear { 4e-3 } else { 1e-4 };
                assert!(worst < bound, "bilinear {bilinear}: the pattern remains ({worst})");
            } else {
                assert!(worst > 5e-3, "control: the Gaussian removed the pattern ({worst})");
            }
        }
    }

    /// `slide_window`: two planes side by side (an edge at x = 20) and the image border
    /// cut the blur, and each plane's gathered image is the 8×6 interleaved pattern (the
    /// right one twice the left). Both planes are wider than 8 and taller than 6 texels,
    /// so with the sliding window every pixel, beside the edge and the border included,
    /// averages all 48 sub-buffers of its own plane: its plane's mean (texel taps and
    /// slid windows exactly; unslid bilinear taps within 0.4 %). With §4.5's flag the
    /// column x = 19 is flagged (it differs from its +x neighbour), which stops the
    /// vertical blur there, slid or not; with `per_axis_discontinuities` it is exact too.
    /// Without the slide the pixels within a radius of the edge keep part of the
    /// pattern (the control).
    #[test]
    fn sliding_windows_average_every_sub_buffer_beside_an_edge() {
        let (w, h) = (48u32, 36u32);
        let v = |x: u32, y: u32| (8 + ((x % 8) * 6 + y % 6) * 7 % 48) as f32 / 64.0;
        let mean = (0..8).flat_map(|i| (0..6).map(move |j| v(i, j))).sum::<f32>() / 48.0;
        let plane = |x: u32, _: u32| (x >= 20) as u32;
        let gpu = gpu();
        for (bilinear, per_axis, slide) in [
            (false, false, true),
            (true, false, true),
            (false, true, true),
            (true, true, true),
            (false, true, false),
            (true, false, false),
        ] {
            let s = IlsSettings {
                slide_window: slide,
                per_axis_discontinuities: per_axis,
                ..settings(bilinear)
            };
            let (out, _) = filter(&gpu, &s, w, h, plane, |x, y, p| v(x, y) * (1 + p) as f32);
            let deviation = |(x, y): (u32, u32)| {
                let want = mean * (1 + plane(x, y)) as f32;
                (out[(y * w + x) as usize] - want).abs() / want
            };
            let all = (0..h).flat_map(|y| (0..w).map(move |x| (x, y)));
            let worst = all
                .filter(|&(x, _)| per_axis || x != 19)
                .map(deviation)
                .fold(0.0f32, f32::max);
            let beside = (8..h - 8).flat_map(|y| (12..28).map(move |x| (x, y)));
            let worst_beside = beside.filter(|&(x, _)| x != 19).map(deviation).fold(0.0f32, f32::max);
            eprintln!("bilinear {bilinear}, per-axis {per_axis}, slide {slide}: worst {worst}, beside the edge {worst_beside}");
            if slide {
                let bound = if bilinear { 4e-3 } else { 1e-4 };
                assert!(
                    worst < bound,
                    "bilinear {bilinear}, per-axis {per_axis}: the pattern remains ({worst})"
                );
            } else {
                assert!(
                    worst_beside > 2e-2,
                    "control: no pattern beside the edge ({worst_beside})"
                );
            }
        }
    }

    #[test]
    fn no_value_crosses_a_discontinuity() {
        // four quadrants at depths 1..4, each with its own irradiance; 8x6 kernel
        // (radius 4 x 3), so every pixel within 4 of a boundary would mix if leaking
        let (w, h) = (40u32, 30u32);
        let quadrant = |x: u32, y: u32| (x >= 17) as u32 + 2 * (y >= 13) as u32;
        let values = [1.0f32, 4.0, 0.25, 2.0];
        let gpu = gpu();
        for (bilinear, per_axis, slide) in [
            (false, false, false),
            (true, false, false),
            (false, true, false),
            (true, true, false),
            (false, false, true),
            (true, true, true),
        ] {
            let s = IlsSettings {
                per_axis_discontinuities: per_axis,
                slide_window: slide,
                ..settings(bilinear)
            };
            let (out, db) = filter(&gpu, &s, w, h, quadrant, |_, _, p| values[p as usize]);
            // DB: exactly the pixels before a boundary (x = 16 or y = 12)
            for y in 0..h {
                for x in 0..w {
                    let expect = x == 16 || y == 12;
                    assert_eq!(db[(y * w + x) as usize] > 0.0, expect, "DB at ({x}, {y})");
                    let v = out[(y * w + x) as usize];
                    let want = values[quadrant(x, y) as usize];
                    assert!(
                        (v - want).abs() <= 1e-3 * want,
                        "bilinear {bilinear} per-axis {per_axis} slide {slide}: ({x}, {y}) = {v}, its plane's {want}"
                    );
                }
            }
            // control: without discontinuities the same blur does mix the planes
            let blind = IlsSettings {
                depth_threshold: 1e9,
                normal_threshold_deg: 180.0,
                ..s
            };
            let (out, db) = filter(&gpu, &blind, w, h, quadrant, |_, _, p| values[p as usize]);
            assert!(db.iter().all(|&d| d == 0.0));
            let v = out[(5 * w + 16) as usize];
            assert!(
                (v - values[0]).abs() > 0.1,
                "bilinear {bilinear}: the control blur did not mix ({v})"
            );
        }
    }

    /// `--preset`: standard is the defaults; clean-edges turns on the per-axis DB and the
    /// sliding window; refined adds refine = 0.5; every preset validates and keeps the
    /// caller's VPL count; an unknown name is a one-line error listing the valid ones.
    #[test]
    fn presets_change_only_the_filter() {
        let base = IlsSettings {
            vpl_count: 96,
            ..Default::default()
        };
        let p = |name: &str| base.clone().with_preset(name).unwrap();
        let standard = p("standard");
        assert!(!standard.per_axis_discontinuities && !standard.slide_window && standard.refine == 0.0);
        let edges = p("clean-edges");
        assert!(edges.per_axis_discontinuities && edges.slide_window && edges.refine == 0.0);
        let refined = p("refined");
        assert!(refined.per_axis_discontinuities && refined.slide_window && refined.refine == 0.5);
        for name in PRESETS {
            let s = p(name);
            s.validate().unwrap();
            assert_eq!(s.vpl_count, 96, "{name}");
            assert_eq!(s.pattern, base.pattern, "{name}");
        }
        let e = base.with_preset("balanced").unwrap_err();
        assert!(
            e.contains("balanced") && e.contains("standard, clean-edges, refined") && !e.contains('\n'),
            "{e}"
        );
    }

    #[test]
    fn settings_are_validated_with_one_line_errors() {
        let ok = IlsSettings::default();
        ok.validate().unwrap();
        assert_eq!(ok.blur_radius(), [4, 3]);
        let bad = [
            (
                IlsSettings {
                    vpl_count: 0,
                    ..ok.clone()
                },
                "vpls",
            ),
            (
                IlsSettings {
                    pattern: [17, 1],
                    ..ok.clone()
                },
                "pattern n",
            ),
            (
                IlsSettings {
                    method: SplitMethod::Blocks { block: 12 },
                    ..ok.clone()
                },
                "block size",
            ),
            (
                IlsSettings {
                    blur: 5.0,
                    ..ok.clone()
                },
                "blur",
            ),
            (
                IlsSettings {
                    clamp_distance: Some(0.0),
                    ..ok.clone()
                },
                "clamp-distance",
            ),
            (
                IlsSettings {
                    depth_threshold: -1.0,
                    ..ok.clone()
                },
                "depth-threshold",
            ),
            (
                IlsSettings {
                    normal_threshold_deg: 200.0,
                    ..ok.clone()
                },
                "normal-threshold",
            ),
            (
                IlsSettings {
                    vpl_shadow_resolution: 4,
                    ..ok.clone()
                },
                "vpl-shadow-resolution",
            ),
            (
                IlsSettings {
                    vpls: Arc::from(vec![GpuVpl::new([0.0; 3], [0.0, 1.0, 0.0], [f32::NAN, 0.0, 0.0])]),
                    ..ok.clone()
                },
                "vpls[0]",
            ),
        ];
        for (s, name) in bad {
            let e = s.validate().unwrap_err();
            assert!(e.contains(name) && !e.contains('\n'), "{name}: {e}");
        }
    }
}
