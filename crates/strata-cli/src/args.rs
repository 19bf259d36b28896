//! Command-line arguments.

use std::path::PathBuf;

use clap::{Args, Parser, Subcommand, ValueEnum};
use glam::Vec3;
use strata_render::passes::ao::AoSettings;
use strata_render::passes::bilateral::BilateralSettings;
use strata_render::passes::deep_gbuffer::{DeepGBufferSettings, Variant};
use strata_render::passes::depth_mip::DepthMipSettings;
use strata_render::passes::radiosity::{Preset, RadiositySettings};
use strata_render::passes::temporal::TemporalSettings;
use strata_render::renderer::GuardBand;
use strata_render::spiral::SpiralTurns;

#[derive(Parser)]
#[command(
    name = "strata",
    version,
    about = "Layered screen-space global illumination (deep G-buffers and friends), measured against a CPU ray-traced reference",
    after_help = "Scenes: a built-in name (cornell, atrium, warehouse, plane, column-wall, dense, mirror, mirror-sign, glasshouse, still-life, dominoes, interior) or a path to a .gltf, .glb, .obj or .toml file.\nExamples:\n  strata info\n  strata render --scene atrium --width 640 --height 360 --out atrium.png\n  strata reference --scene cornell --kind ao --spp 16 --width 64 --height 64 --out ao.exr\n  strata render --scene atrium --layers 2 --variant reproject --debug-view layer1-albedo --out l1.png\n  strata bench gbuffer --scene atrium --width 640 --height 360 --frames 5 --json\n  strata bench deep-gbuffer --scene atrium --width 640 --height 360 --frames 8 --json\n  strata render --scene atrium --technique ao --layers 2 --out ao.png\n  strata eval --scene atrium --technique ao --layers 2 --json --report report/\n  strata bench ao --scene atrium --width 640 --height 360 --layers 2 --frames 5 --json\n  strata render --scene atrium --technique full --preset balanced --layers 2 --warmup 8 --out full.png\n  strata eval --scene warehouse --technique gi --layers 2 --json\n  strata bench radiosity --scene atrium --preset balanced --json"
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Subcommand)]
pub enum Command {
    /// Adapter, backend, driver, and which features strata uses are present.
    Info(InfoArgs),
    /// Render a scene on the GPU and write a PNG (tonemapped) or EXR (linear).
    Render(RenderArgs),
    /// Render ground truth with the CPU ray tracer (AO, path-traced GI, exact deep layers).
    Reference(ReferenceArgs),
    /// GPU timestamp benchmarks (per-pass milliseconds).
    Bench(BenchArgs),
    /// The registered techniques with their outputs, presets and settings (defaults, ranges).
    Techniques(TechniquesArgs),
    /// Render many frames along the camera path and sample resident memory and wgpu's allocations (JSON).
    Soak(SoakArgs),
    /// Compare a GPU technique with the CPU ground truth for the same camera (FLIP, RMSE, MAE; JSON; HTML report).
    Eval(EvalArgs),
    /// Stitch the result JSON files, images and reports in a folder into one HTML page (tables, SVG plots).
    Report(crate::report_cmd::ReportArgs),
    /// Write the scene at one frame with the camera for an external renderer: scene.json (camera,
    /// materials, lights, settings) and one binary PLY of world-space triangles per material.
    ExportScene(crate::export::ExportArgs),
    /// Compare two images (EXR/PNG) with the metrics of `eval`: FLIP, RMSE, MAE and the mean difference.
    Compare(crate::compare::CompareArgs),
    /// Interactive viewer: fly through a scene, switch techniques, settings and debug views, watch
    /// per-pass GPU time, save a frame with the `strata render` command that reproduces it.
    View(ViewArgs),
}

/// `strata view`: the flags of `render` (scene, camera, technique, settings) plus the viewer's.
#[derive(Args)]
pub struct ViewArgs {
    #[command(flatten)]
    pub frame: FrameArgs,
    /// Debug view shown first (`strata render --list-passes` lists them; the panel too).
    #[arg(long)]
    pub debug_view: Option<String>,
    /// Non-interactive: render this many frames in the window, write --screenshot, exit. 1..=100000.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=100_000))]
    pub frames: Option<u32>,
    /// With --frames: the viewport PNG written at the end (and FILE.cmd.txt: the `strata render` command).
    #[arg(long, requires = "frames")]
    pub screenshot: Option<PathBuf>,
    /// With --frames: also a PNG of the whole window (panels included) at the end.
    #[arg(long, requires = "frames")]
    pub window_screenshot: Option<PathBuf>,
    /// Scripted input, one command a line (key W 10, mouse-drag 40 0, technique ao, debug-view normal, …;
    /// docs/viewer.md lists them).
    #[arg(long)]
    pub script: Option<PathBuf>,
    /// Internal-resolution scale while the camera moves, 0.1..=1 (1: always full resolution).
    #[arg(long, default_value_t = 0.5)]
    pub motion_scale: f32,
    /// Overwrite --screenshot / --window-screenshot if they exist.
    #[arg(long)]
    pub force: bool,
}

#[derive(Args, Clone)]
pub struct GpuArgs {
    /// Adapter to use: a case-insensitive substring of its name (default: the first real GPU, else any). Also STRATA_ADAPTER.
    #[arg(long)]
    pub adapter: Option<String>,
}

#[derive(Args)]
pub struct InfoArgs {
    #[command(flatten)]
    pub gpu: GpuArgs,
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
}

/// Scene, frame and camera selection shared by every command.
#[derive(Args, Clone)]
pub struct SceneArgs {
    /// Built-in scene name or path to a .gltf/.glb/.obj/.toml file.
    #[arg(long, default_value = "atrium")]
    pub scene: String,
    /// Frame index along the scene's camera path / animation.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub frame: f32,
    /// Image width in pixels.
    #[arg(long, default_value_t = 640)]
    pub width: u32,
    /// Image height in pixels.
    #[arg(long, default_value_t = 360)]
    pub height: u32,
    /// Camera position "x,y,z" (overrides the scene camera and its path).
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    pub eye: Option<Vec3>,
    /// Camera look-at point "x,y,z".
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    pub target: Option<Vec3>,
    /// Camera up vector "x,y,z".
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    pub up: Option<Vec3>,
    /// Vertical field of view in degrees, in (0, 180).
    #[arg(long, allow_negative_numbers = true)]
    pub fov: Option<f32>,
    /// Which of the scene file's cameras to use (glTF camera nodes in file order, from 0;
    /// default: the first). The --eye/--target/--up/--fov overrides apply on top.
    #[arg(long)]
    pub camera: Option<usize>,
}

/// Deep G-buffer construction (DGB §2).
#[derive(Args, Clone)]
pub struct DeepArgs {
    /// Deep G-buffer layers k, 1..=4 (layer 0 is the visible surface).
    #[arg(long, default_value_t = 1)]
    pub layers: u32,
    /// How layers ≥ 1 are built: peel (k passes, exact), delay (1 pass, exact, one frame of latency),
    /// previous, predict, reproject (1 pass; the paper's choice).
    #[arg(long, default_value = "reproject", value_parser = parse_variant)]
    pub variant: Variant,
    /// Minimum separation Δz between layers in scene units, >= 0 (default: the scene's; the paper uses 0.5 m).
    #[arg(long, allow_negative_numbers = true)]
    pub min_separation: Option<f32>,
    /// Resolution divisor s of layers >= 1, 1..=4 (DGB Fig. 11): each is rasterised at 1/s of the
    /// size and upsampled keeping the minimum separation (1 = full resolution, as the paper's results).
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=4))]
    pub layer_scale: u32,
    /// Guard band rendered around the image and cropped: pixels per side (e.g. 32), percent of the height (e.g. 10%), or auto (the technique's default: 10% for ao and full, else 0).
    #[arg(long, default_value = "auto", value_parser = parse_guard_band)]
    pub guard_band: GuardBand,
}

impl DeepArgs {
    pub fn settings(&self) -> DeepGBufferSettings {
        DeepGBufferSettings {
            layers: self.layers,
            variant: self.variant,
            min_separation: self.min_separation,
            layer_scale: self.layer_scale,
            ..Default::default()
        }
    }
}

/// A technique `eval` can compare: one whose eval kind is not `none` (`gi` = `full`).
fn parse_eval_technique(s: &str) -> Result<&'static strata_render::technique::Technique, String> {
    let t = parse_technique(if s == "gi" { "full" } else { s })?;
    if t.eval == strata_render::technique::EvalKind::None {
        let names: Vec<_> = strata_render::technique::registry()
            .iter()
            .filter(|t| t.eval != strata_render::technique::EvalKind::None)
            .map(|t| t.name)
            .collect();
        return Err(format!(
            "technique '{s}' has no ground-truth comparison: eval takes {} (gi = full)",
            names.join(", ")
        ));
    }
    Ok(t)
}

/// `--set NAME=VALUE` (`render`, `soak`, `bench technique`).
#[derive(Args)]
pub struct SetArgs {
    /// Any registered setting of the technique, NAME=VALUE, range-checked and applied last
    /// (repeatable; `strata techniques` lists the names and ranges).
    #[arg(long = "set", value_name = "NAME=VALUE", allow_hyphen_values = true, value_parser = parse_set)]
    pub values: Vec<(String, f64)>,
}

/// `NAME=VALUE` of `--set`.
pub fn parse_set(kv: &str) -> Result<(String, f64), String> {
    let (name, value) = kv
        .split_once('=')
        .ok_or_else(|| format!("--set {kv}: expected NAME=VALUE (e.g. --set samples=32)"))?;
    let v: f64 = value
        .trim()
        .parse()
        .ok()
        .or_else(|| strata_render::technique::named_value(name.trim(), value))
        .ok_or_else(|| {
            let named = strata_render::technique::named_values(name.trim());
            if named.is_empty() {
                format!("--set {kv}: '{value}' is not a number")
            } else {
                format!(
                    "--set {kv}: '{value}' is not a number nor a value of '{}' ({})",
                    name.trim(),
                    named.join(", ")
                )
            }
        })?;
    Ok((name.trim().to_string(), v))
}

/// `--exposure`: a fixed multiplier or auto-exposure.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ExposureArg {
    Fixed(f32),
    Auto(strata_render::passes::exposure::AutoExposure),
}

impl ExposureArg {
    /// The fixed exposure, if that is what was asked for.
    pub fn fixed(this: Option<Self>) -> Option<f32> {
        match this {
            Some(Self::Fixed(e)) => Some(e),
            _ => None,
        }
    }

    /// The auto-exposure settings, if that is what was asked for.
    pub fn auto(this: Option<Self>) -> Option<strata_render::passes::exposure::AutoExposure> {
        match this {
            Some(Self::Auto(a)) => Some(a),
            _ => None,
        }
    }
}

/// `--exposure`: a number > 0, or `auto[:SPEC]`. SPEC is a comma list of `key=K`,
/// `adapt=A`, `low=L` and `high=H` ([`AutoExposure`]'s fields); a bare number first is
/// the key (`auto:0.09`).
///
/// [`AutoExposure`]: strata_render::passes::exposure::AutoExposure
pub fn parse_exposure(s: &str) -> Result<ExposureArg, String> {
    use strata_render::passes::exposure::AutoExposure;
    const USE: &str = "use auto or auto:KEY or auto:key=K,adapt=A,low=L,high=H";
    if let Some(rest) = s.strip_prefix("auto") {
        let mut a = AutoExposure::default();
        if let Some(spec) = rest.strip_prefix(':') {
            for (i, item) in spec.split(',').enumerate() {
                let (name, value) = match item.split_once('=') {
                    Some((n, v)) => (n.trim(), v.trim()),
                    None if i == 0 => ("key", item.trim()),
                    None => return Err(format!("'{item}' in '{s}' is not NAME=VALUE: {USE}")),
                };
                let v: f32 = value
                    .parse()
                    .map_err(|_| format!("'{value}' is not a number (auto-exposure {name}): {USE}"))?;
                match name {
                    "key" => a.key = v,
                    "adapt" => a.adaptation = v,
                    "low" => a.low = v,
                    "high" => a.high = v,
                    _ => {
                        return Err(format!(
                            "'{name}' in '{s}' is not an auto-exposure setting: valid are key, adapt, low and high"
                        ))
                    }
                }
            }
        } else if !rest.is_empty() {
            return Err(format!("'{s}': use a number > 0, auto or auto:KEY"));
        }
        a.validate()?;
        return Ok(ExposureArg::Auto(a));
    }
    let e: f32 = s
        .parse()
        .map_err(|_| format!("'{s}' is not a number: use a number > 0, auto or auto:KEY"))?;
    if !(e > 0.0 && e.is_finite()) {
        return Err(format!("exposure {e} is out of range: must be > 0 (or auto)"));
    }
    Ok(ExposureArg::Fixed(e))
}

fn parse_probe_grid(s: &str) -> Result<[u32; 3], String> {
    let bad = || {
        format!(
            "'{s}' is not NX,NY,NZ with each in 1..=64 and at most {} probes",
            MAX_PROBES
        )
    };
    let v: Vec<u32> = s
        .split(',')
        .map(|x| x.trim().parse::<u32>())
        .collect::<Result<_, _>>()
        .map_err(|_| bad())?;
    match v[..] {
        [x, y, z] if [x, y, z].iter().all(|d| (1..=64).contains(d)) && x * y * z <= MAX_PROBES => Ok([x, y, z]),
        _ => Err(bad()),
    }
}

/// The most probes `--probe-grid` takes (about 72 MB of probe buffers).
const MAX_PROBES: u32 = 32768;

fn parse_probe_rays(s: &str) -> Result<u32, String> {
    let range = strata_eval::cache::probes::RAYS_RANGE;
    s.trim()
        .parse::<u32>()
        .ok()
        .filter(|n| range.contains(n))
        .ok_or_else(|| format!("'{s}' is out of range: paths per probe must be in {range:?}"))
}

impl RadiosityArgs {
    /// How the light probes are baked: `--probe-grid` and `--probe-rays`, else the defaults.
    pub fn probe_bake(&self) -> strata_eval::cache::probes::ProbeBake {
        let d = strata_eval::cache::probes::ProbeBake::default();
        strata_eval::cache::probes::ProbeBake {
            grid: self.probe_grid.unwrap_or(d.grid),
            rays: self.probe_rays.unwrap_or(d.rays),
        }
    }
}

fn parse_technique(s: &str) -> Result<&'static strata_render::technique::Technique, String> {
    strata_render::technique::find(s).map_err(|e| e.to_string())
}

fn parse_variant(s: &str) -> Result<Variant, String> {
    s.parse()
}

fn parse_guard_band(s: &str) -> Result<GuardBand, String> {
    s.parse()
}

/// Deep-G-buffer radiosity settings (DGB §3.2–3.5): a Table 2 preset, then overrides.
#[derive(Args, Clone)]
pub struct RadiosityArgs {
    /// The technique's preset (`strata techniques` lists them): full's DGB Table 2 parameter
    /// sets (presets/*.toml) high-performance, balanced (default), high-quality; ils's
    /// standard (default), clean-edges, refined.
    #[arg(long)]
    pub preset: Option<String>,
    /// Indirect samples N per pixel, 1..=256 (default: the preset's).
    #[arg(long)]
    pub indirect_samples: Option<u32>,
    /// World-space gather radius, > 0 (scene units; default: the scene's `radiosity_radius`).
    #[arg(long)]
    pub radiosity_radius: Option<f32>,
    /// Omit Eq. 5's n_Y test (cheaper, biased; default: the preset's choice).
    #[arg(long)]
    pub no_normal_test: bool,
    /// Minimum MIP level of the gather taps, below the MIP levels (default: the preset's).
    #[arg(long)]
    pub min_mip: Option<u32>,
    /// Apply Eq. 7's boost to the reflected indirect light (off: energy-conserving).
    #[arg(long)]
    pub boost: bool,
    /// Bilateral taps on each side for the indirect light, 0..=32 (default: the preset's taps / 2).
    #[arg(long)]
    pub indirect_blur_radius: Option<u32>,
    /// Temporal filter weight α of the indirect light, in [0, 1) (0 disables).
    #[arg(long, default_value_t = 0.85)]
    pub indirect_alpha: f32,
    /// Progressive multi-bounce damping δ in [0, 1] (DGB §3.3; 0 = single bounce).
    #[arg(long, default_value_t = 0.9)]
    pub delta: f32,
    /// on (default): hash the frame index into the gather's spiral rotation too, so the temporal
    /// filter averages different tap patterns; off: the paper's per-pixel hash only.
    #[arg(long, num_args = 0..=1, default_missing_value = "on")]
    pub indirect_temporal_noise: Option<String>,
    /// Tap weights of the gather: "solid-angle" (default: each tap weighs the solid angle its
    /// screen area covers at the receiver, self-normalised) or "paper" (DGB Eq. 4, equal weights;
    /// docs/radiosity.md).
    #[arg(long)]
    pub indirect_weights: Option<String>,
    /// Light-probe grid "NX,NY,NZ": probes per axis over the scene's bounds, each 1..=64, at
    /// most 32768 in all (default 16,8,16). The bake's time grows with the count; each grid
    /// is cached apart (docs/radiosity.md § "Probe grid").
    #[arg(long, value_name = "NX,NY,NZ", value_parser = parse_probe_grid)]
    pub probe_grid: Option<[u32; 3]>,
    /// Paths per light probe in its bake, 64..=1048576 (default 16384). The bake's noise falls
    /// as 1/√N and its time grows with N; each count is cached apart (docs/radiosity.md §
    /// "Rays per probe").
    #[arg(long, value_name = "N", value_parser = parse_probe_rays)]
    pub probe_rays: Option<u32>,
}

impl RadiosityArgs {
    /// The DGB Table 2 preset's name: `--preset`, or balanced.
    pub fn radiosity_preset(&self) -> &str {
        self.preset.as_deref().unwrap_or("balanced")
    }

    pub fn settings(&self) -> Result<RadiositySettings, String> {
        let preset = Preset::named(self.radiosity_preset()).map_err(|e| format!("--preset: {e}"))?;
        let mut s = preset.apply(RadiositySettings::default());
        if let Some(n) = self.indirect_samples {
            s.samples = n;
        }
        s.radius = self.radiosity_radius;
        if self.no_normal_test {
            s.normal_test = false;
        }
        if let Some(m) = self.min_mip {
            s.min_mip = m;
        }
        s.boost = self.boost;
        if let Some(r) = self.indirect_blur_radius {
            s.blur.radius = r;
        }
        s.temporal = (self.indirect_alpha != 0.0).then_some(TemporalSettings {
            alpha: self.indirect_alpha,
            ..s.temporal
                .unwrap_or_else(strata_render::passes::radiosity::indirect_temporal)
        });
        s.delta = self.delta;
        match self.indirect_temporal_noise.as_deref() {
            None => {}
            Some("on") => s.temporal_noise = true,
            Some("off") => s.temporal_noise = false,
            Some(v) => {
                return Err(format!(
                    "--indirect-temporal-noise '{v}' is out of range: must be on or off"
                ))
            }
        }
        match self.indirect_weights.as_deref() {
            None => {}
            Some("paper") => s.solid_angle = false,
            Some("solid-angle") => s.solid_angle = true,
            Some(w) => {
                return Err(format!(
                    "--indirect-weights '{w}' is out of range: must be paper or solid-angle"
                ))
            }
        }
        Ok(s)
    }
}

/// Deep-G-buffer AO settings (DGB §3.1, §3.3, §3.4).
#[derive(Args, Clone)]
pub struct AoArgs {
    /// AO world-space radius r, > 0 (default: the scene's).
    #[arg(long)]
    pub ao_radius: Option<f32>,
    /// AO samples N per pixel, 1..=256 (spiral turns τ from DGB Listing 3 for N <= 98).
    #[arg(long, default_value_t = 19)]
    pub samples: u32,
    /// Bias β in scene units, >= 0 (default: 0.01·r).
    #[arg(long)]
    pub ao_bias: Option<f32>,
    /// Multiplies the sum in DGB Eq. 1, >= 0 (1 = the equation as written).
    #[arg(long, default_value_t = 1.0)]
    pub ao_intensity: f32,
    /// Spiral turns: "optimal" (DGB Listing 3) or a fixed number (SAO used 7; DGB Fig. 7 left).
    #[arg(long, default_value = "optimal", value_parser = parse_turns)]
    pub spiral_turns: SpiralTurns,
    /// Do not rotate each pixel's spiral (φ = 0; DGB Fig. 7 left).
    #[arg(long)]
    pub no_rotate: bool,
    /// Hash the frame index into the spiral rotation (temporal accumulation of different
    /// patterns). The default since issue 14; the flag is kept for scripts.
    #[arg(long, conflicts_with = "fixed_rotation")]
    pub temporal_noise: bool,
    /// The paper's rotation: φ = hash(x, y) only, the same tap pattern every frame (off by
    /// default: the frame index is hashed in too, docs/ao.md "Temporal rotation").
    #[arg(long)]
    pub fixed_rotation: bool,
    /// Temporal filter weight α in [0, 1) of the reprojected history (DGB §3.3; 0 disables the filter).
    #[arg(long, default_value_t = 0.85)]
    pub alpha: f32,
    /// Temporal filter: reprojection accepted within this camera-space distance of either layer, > 0 (scene units; paper: 1 cm).
    #[arg(long, default_value_t = 0.01)]
    pub temporal_distance: f32,
    /// Bilateral filter taps on each side, 0..=32 (0 = no spatial reconstruction).
    #[arg(long, default_value_t = 2)]
    pub blur_radius: u32,
    /// Pixels between bilateral taps, 1..=8 (SAO used 4 taps 2 px apart; see docs/ao.md).
    #[arg(long, default_value_t = 1)]
    pub blur_step: u32,
    /// Depth MIP levels, 1..=12.
    #[arg(long, default_value_t = 5)]
    pub mip_levels: u32,
    /// Tap radius q in pixels at which the MIP level first increments, >= 1 (m = floor(log2(h/q))).
    #[arg(long, default_value_t = 8.0)]
    pub mip_q: f32,
    /// Deinterleaved AO: "off" or an NxM pattern, N, M in 1..=4 (e.g. 2x2, 4x4; docs/ao.md).
    #[arg(long, default_value = "off", value_parser = parse_pattern)]
    pub deinterleave: Deinterleave,
    /// on (default): the temporal and bilateral filters average Eq. 1's obscurance mean S, then
    /// AV = 1 − √S (not in the paper; docs/ao.md); off: DGB's order (filter AV).
    #[arg(long, num_args = 0..=1, default_missing_value = "on", value_parser = ["on", "off"])]
    pub filter_obscurance: Option<String>,
}

/// `--deinterleave`: `None` = off.
#[derive(Clone, Copy, Debug)]
pub struct Deinterleave(pub Option<[u32; 2]>);

impl AoArgs {
    pub fn settings(&self) -> AoSettings {
        let d = AoSettings::default();
        AoSettings {
            radius: self.ao_radius,
            bias: self.ao_bias,
            intensity: self.ao_intensity,
            samples: self.samples,
            turns: self.spiral_turns,
            rotate: !self.no_rotate,
            temporal_noise: !self.fixed_rotation,
            q: self.mip_q,
            mips: DepthMipSettings {
                levels: self.mip_levels,
            },
            blur: BilateralSettings {
                radius: self.blur_radius,
                step: self.blur_step,
                ..d.blur
            },
            temporal: (self.alpha != 0.0).then_some(TemporalSettings {
                alpha: self.alpha,
                max_distance: self.temporal_distance,
                ..Default::default()
            }),
            deinterleave: self.deinterleave.0,
            filter_obscurance: self.filter_obscurance.as_deref() != Some("off"),
            ..d
        }
    }
}

fn parse_pattern(s: &str) -> Result<Deinterleave, String> {
    if s.eq_ignore_ascii_case("off") {
        return Ok(Deinterleave(None));
    }
    let bad = || format!("'{s}' is not a deinterleave pattern: use \"off\" or NxM, e.g. 2x2");
    let (n, m) = s.split_once(['x', 'X']).ok_or_else(bad)?;
    Ok(Deinterleave(Some([
        n.trim().parse().map_err(|_| bad())?,
        m.trim().parse().map_err(|_| bad())?,
    ])))
}

fn parse_turns(s: &str) -> Result<SpiralTurns, String> {
    if s.eq_ignore_ascii_case("optimal") {
        return Ok(SpiralTurns::Optimal);
    }
    match s.parse::<f32>() {
        Ok(t) if t > 0.0 && t.is_finite() => Ok(SpiralTurns::Fixed(t)),
        _ => Err(format!(
            "'{s}' is not a spiral turn count: use \"optimal\" or a number > 0"
        )),
    }
}

/// What `strata eval` compares.

#[derive(Args)]
pub struct EvalArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    #[command(flatten)]
    pub gpu: GpuArgs,
    /// Registered technique to compare (`strata techniques`): its eval kind picks the reference —
    /// `ao` against ray-traced obscurance and binary AO, `full` (alias `gi`) against the path tracer,
    /// `ils` against the brute force of the same VPLs and the one-bounce path tracer (`--bounces` is read by `--progressive` only).
    #[arg(long, default_value = "ao", value_parser = parse_eval_technique)]
    pub technique: &'static strata_render::technique::Technique,
    #[command(flatten)]
    pub deep: DeepArgs,
    #[command(flatten)]
    pub ao: AoArgs,
    #[command(flatten)]
    pub radiosity: RadiosityArgs,
    /// Cap on the CPU reference's samples per pixel, 2..=65536 (default 32768). The reference
    /// integrates until --ref-noise is met or this cap is reached.
    #[arg(long, value_parser = clap::value_parser!(u32).range(2..=65536))]
    pub ref_spp: Option<u32>,
    /// Noise target of the CPU reference, in [0, 1): ꟻLIP between its two independent halves
    /// (0: integrate to the --ref-spp cap). Converged references are cached.
    #[arg(long, default_value_t = 0.02)]
    pub ref_noise: f64,
    /// Indirect bounces of the path-traced reference (gi; ils --progressive: also the VPL bounces), 1..=64.
    #[arg(long, default_value_t = 4)]
    pub bounces: u32,
    /// ils: also run §6.3's physically-based mode — up to K frames with fresh VPL sets of
    /// --bounces bounces and VPL shadow maps, accumulated until within 1 % RMS of the mean of
    /// K independent sets, for 1x1 and 2x2 (Table 5), and that mean against the path tracer; 2..=16384.
    #[arg(long)]
    pub progressive: Option<u32>,
    /// gi: also run DGB Fig. 10's error-source study — single-bounce GPU radiosity with and
    /// without the n_Y test against single-bounce references with and without visibility.
    #[arg(long)]
    pub fig10: bool,
    /// gi: also evaluate DGB's blend with a *perfect* gather over 1 and k ≤ 2 layers: the path
    /// tracer's light from the surfaces the layers hold, c the share of paths they hold, and
    /// the GPU's probes for the rest (`docs/radiosity.md` § "A perfect gather"). Its
    /// paths are traced and cached like the reference's.
    #[arg(long)]
    pub oracle: bool,
    /// gi: evaluate the deep G-buffer's screen-space radiosity alone. By default it is blended
    /// with light probes baked from the evaluated (sky-off) scene by its confidence, as
    /// `render --technique full` shows it (DGB §3.2: "all our results use static radiance and
    /// irradiance probes for the coarse-scale fallback").
    #[arg(long)]
    pub no_probes: bool,
    /// gi and full --views: bake the light probes from this scene (built-in name or file) instead of the
    /// evaluated one: stale probes, as after a change the static bake has not seen (a moved
    /// object, a recoloured surface), which only the screen-space radiosity can follow.
    #[arg(long, value_name = "SCENE", conflicts_with = "no_probes")]
    pub probes_from: Option<String>,
    /// gi, full, ao, bzb-ao, bzb-gi: the warm-up frames follow the scene's camera path and animation up to the
    /// evaluated --frame (frames f − warmup … f) instead of holding its camera still: the error
    /// of a moving camera and moving objects, with the temporal filter (and the progressive
    /// bounces) reprojecting every frame.
    #[arg(long)]
    pub moving: bool,
    /// full: instead of the sky-off GI comparison, measure what `render --technique full`
    /// shows (probes on): pixels clipped in the final image and the probe-only / blended /
    /// gbuffer-only views, |blended − probe-only|, and the chroma of fixed regions against the
    /// path-traced frame with sky (docs/image-quality.md). The frame compared with the
    /// (Lambertian) path tracer has the GGX specular lobe off; `final-specular` is the frame
    /// with it, as `render` shows it.
    #[arg(long)]
    pub views: bool,
    /// Static frames rendered before the evaluated one (gi: the progressive bounces and the
    /// temporal filter build up; 8 is a short history, a camera held still reaches its
    /// steady state by about 32: docs/radiosity.md § "Cosine normalisation"), 0..=1000.
    #[arg(long, default_value_t = strata_render::ACCUMULATION_WARMUP, value_parser = clap::value_parser!(u32).range(0..=1000))]
    pub warmup: u32,
    /// Folder of cached reference images (default: $STRATA_CACHE, else $XDG_CACHE_HOME/strata/reference, else ~/.cache/strata/reference).
    #[arg(long)]
    pub cache: Option<PathBuf>,
    /// Recompute the reference even when cached.
    #[arg(long)]
    pub no_cache: bool,
    /// Also measure temporal instability over this many frames along the camera path, 2..=1000 ("flicker" in the output).
    #[arg(long)]
    pub frames: Option<u32>,
    /// Write an HTML report with images (GPU, reference, FLIP maps, 1 layer vs k layers) into this folder.
    #[arg(long)]
    pub report: Option<PathBuf>,
    /// Overwrite an existing report.
    #[arg(long)]
    pub force: bool,
    /// Print one JSON object on stdout.
    #[arg(long)]
    pub json: bool,
    /// Hide progress bars.
    #[arg(long)]
    pub quiet: bool,
    /// --technique ils: its settings (e.g. --set vpls=480 --set shadows=vpl).
    #[command(flatten)]
    pub set: SetArgs,
    /// The ids of the flags given on the command line (not defaulted), filled after parsing:
    /// `eval` warns of those its comparison does not read ([`EvalArgs::unread_flags`]).
    #[arg(skip)]
    pub given: Vec<String>,
}

impl EvalArgs {
    /// One line per flag given on the command line that this comparison does not read:
    /// - `oit` (one static frame's composite against the exact CPU compositing): the AO
    ///   and radiosity flags, the deep-G-buffer construction besides `--layers`,
    ///   `--warmup`, and the reference's flags;
    /// - `ils` (one static frame of layer 0): the AO and radiosity flags (`--preset` is
    ///   read), the construction besides `--layers`, `--warmup`, and `--bounces` without
    ///   `--progressive`;
    /// - `ao`, `bzb-ao`, `aba-ao`: the radiosity flags and `--bounces`;
    /// - `gi`/`full` without `--views` and `bzb-gi`: the AO flags (no AO in the
    ///   comparison), and for `bzb-gi` `--bounces` (its reference has one bounce).
    ///
    /// Flags a comparison refuses outright are left to its one-line error.
    pub fn unread_flags(&self) -> Vec<String> {
        use strata_render::technique::EvalKind;
        let kind = self.technique.eval;
        let ids = |c: clap::Command| -> Vec<String> { c.get_arguments().map(|a| a.get_id().to_string()).collect() };
        let ao = ids(<AoArgs as Args>::augment_args(clap::Command::new("ao")));
        // --preset is checked against the technique's presets (`eval::run`)
        let radiosity: Vec<String> = ids(<RadiosityArgs as Args>::augment_args(clap::Command::new("radiosity")))
            .into_iter()
            .filter(|id| id != "preset")
            .collect();
        let strings = |v: &[&str]| v.iter().map(|x| x.to_string()).collect::<Vec<_>>();
        let bzb_gi = self.technique.name == "bzb-gi";
        let (unread, why): (Vec<String>, &str) = match kind {
            EvalKind::Composite => (
                [
                    ao,
                    radiosity,
                    strings(&[
                        "variant",
                        "min_separation",
                        "warmup",
                        "ref_spp",
                        "ref_noise",
                        "cache",
                        "no_cache",
                        "bounces",
                    ]),
                ]
                .concat(),
                "it compares one static frame's A-buffer composite with the exact CPU compositing",
            ),
            EvalKind::VplRadiance => {
                let mut v = [ao, radiosity, strings(&["variant", "min_separation", "warmup"])].concat();
                if self.progressive.is_none() {
                    v.push("bounces".into());
                }
                (
                    v,
                    "it compares one static frame of layer 0 with the brute force and the one-bounce path tracer",
                )
            }
            EvalKind::AmbientVisibility => (
                [radiosity, strings(&["bounces"])].concat(),
                "it measures ambient occlusion against the ray-traced AO, with no radiosity",
            ),
            EvalKind::Radiance if self.views => (Vec::new(), ""),
            EvalKind::Radiance if bzb_gi => (
                [ao, strings(&["bounces"])].concat(),
                "it compares the indirect light without AO against the one-bounce path tracer",
            ),
            EvalKind::Radiance => (
                ao,
                "it compares the radiosity and probes without AO (--views measures the frame with AO)",
            ),
            EvalKind::None => (Vec::new(), ""),
        };
        given_among::<EvalArgs>(&self.given, &unread)
            .into_iter()
            .map(|(id, long)| {
                let why = if kind == EvalKind::VplRadiance && id == "bounces" {
                    "--bounces is read only with --progressive (the reference has one bounce)"
                } else {
                    why
                };
                format!(
                    "--{long} is not read by eval --technique {}: {why}",
                    self.technique.name
                )
            })
            .collect()
    }
}

#[derive(Args)]
pub struct RenderArgs {
    #[command(flatten)]
    pub frame: FrameArgs,
    /// Write an intermediate target instead of the final image (e.g. csz, normal, albedo, emission, direct-diffuse, shadow, hdr). `--list-passes` shows them.
    #[arg(long)]
    pub debug_view: Option<String>,
    /// Output file: .png (tonemapped, sRGB) or .exr (linear HDR).
    #[arg(long, required_unless_present_any = ["list_passes", "list_lights"])]
    pub out: Option<PathBuf>,
    /// Overwrite the output file if it exists.
    #[arg(long)]
    pub force: bool,
    /// Print the frame's passes with their inputs and outputs, and the debug views, then exit.
    #[arg(long)]
    pub list_passes: bool,
    /// Print the scene's lights (type, position or direction, colour, intensity in strata's
    /// units) and cameras, then exit.
    #[arg(long)]
    pub list_lights: bool,
    /// Print per-pass GPU times after rendering.
    #[arg(long)]
    pub timings: bool,
    /// Frames rendered before the output frame (along the camera path), 0..=1000, so temporal
    /// filters and progressive bounces (DGB §3.3) have history. Default: 8 where the frame
    /// builds up over frames (AO's and the radiosity's temporal filters, the progressive
    /// bounces), else 0; `--warmup 0` shows the first frame after a cut.
    #[arg(long, value_parser = clap::value_parser!(u32).range(0..=1000))]
    pub warmup: Option<u32>,
}

/// What a frame renders: scene, camera, technique and its settings (shared by
/// `render` and `soak`).
#[derive(Args)]
pub struct FrameArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    #[command(flatten)]
    pub gpu: GpuArgs,
    /// Shading technique (`strata techniques` lists them with their settings).
    #[arg(long, default_value = "direct", value_parser = parse_technique)]
    pub technique: &'static strata_render::technique::Technique,
    #[command(flatten)]
    pub deep: DeepArgs,
    #[command(flatten)]
    pub ao: AoArgs,
    #[command(flatten)]
    pub radiosity: RadiosityArgs,
    /// Exposure multiplier before tonemapping (default: the scene's), or `auto[:KEY]`: the
    /// exposure that maps the image's typical luminance (the log mean of its non-black
    /// pixels from the 50th to the 95th percentile) to KEY (default 0.18, in (0, 10]),
    /// metered every frame. `auto:key=K,adapt=A,low=L,high=H` also sets the weight of each
    /// frame's metering in log space (A in (0, 1], default 1: at once; A < 1 adapts over
    /// about 1/A frames, and the frame is warmed up like a temporal filter's) and the
    /// percentile window (0 <= L < H <= 1).
    #[arg(long, allow_negative_numbers = true, value_parser = parse_exposure)]
    pub exposure: Option<ExposureArg>,
    /// Shadow map resolution per light, 64..=8192.
    #[arg(long, default_value_t = 2048)]
    pub shadow_resolution: u32,
    /// How many point lights (the most intense) cast shadows through cube shadow maps
    /// (six maps each); the rest are unshadowed. 0..=16.
    #[arg(long, default_value_t = strata_render::lights::POINT_SHADOW_BUDGET, value_parser = clap::builder::RangedU64ValueParser::<usize>::new().range(0..=16))]
    pub point_shadows: usize,
    /// Lights that cast no shadow, by the index `--list-lights` prints (comma-separated, e.g. 0,2).
    #[arg(long, value_delimiter = ',')]
    pub no_shadow: Vec<usize>,
    /// --technique full: no light-probe fallback and no environment map for the reflections
    /// (the sky colour instead); both are baked once per scene by the CPU path tracer and
    /// cached in $STRATA_CACHE.
    #[arg(long)]
    pub no_probes: bool,
    #[command(flatten)]
    pub set: SetArgs,
    /// The ids of the flags given on the command line (not defaulted), filled after parsing:
    /// `render` warns of those its technique does not read ([`FrameArgs::unread_flags`]).
    #[arg(skip)]
    pub given: Vec<String>,
}

impl FrameArgs {
    /// One line per flag given on the command line that `settings` (the technique's,
    /// resolved) does not read: the AO flags without the deep-G-buffer AO (the
    /// radius, bias and intensity carry over to `aba-ao` and the radius and bias to `bzb-ao`),
    /// the radiosity flags and `--no-probes` without the radiosity, `--variant` and
    /// `--layer-scale` without a second layer, and `--layers` above 1 where no pass reads a
    /// second layer (ILS, the A-buffer techniques, `bzb-ao`, `direct`) and no debug view
    /// (`debug_view`) may show one. `render` prints them as warnings and renders: the command
    /// `strata view` prints for a frame keeps the flags given to it across technique switches. (`eval`
    /// refuses some flags of its own that a comparison does not read and warns of the rest:
    /// [`EvalArgs::unread_flags`].)
    pub fn unread_flags(&self, settings: &strata_render::RenderSettings, debug_view: bool) -> Vec<String> {
        let longs = |c: clap::Command| -> Vec<(String, String)> {
            c.get_arguments()
                .filter_map(|a| Some((a.get_id().to_string(), a.get_long()?.to_string())))
                .collect()
        };
        let aba_ao = settings.abuffer.as_ref().is_some_and(|a| a.ao.is_some());
        let dgb_ao = settings.ao.is_some();
        let radiosity = settings.radiosity.is_some();
        // (flag id, its long name, whether the technique reads it, what it belongs to)
        let mut flags: Vec<(String, String, bool, &str)> = Vec::new();
        for (id, long) in longs(<AoArgs as Args>::augment_args(clap::Command::new("ao"))) {
            let read = match id.as_str() {
                "ao_radius" | "ao_bias" => dgb_ao || aba_ao || settings.bzb.is_some(),
                "ao_intensity" => dgb_ao || aba_ao,
                _ => dgb_ao,
            };
            flags.push((id, long, read, "the deep-G-buffer AO"));
        }
        for (id, long) in longs(<RadiosityArgs as Args>::augment_args(clap::Command::new("radiosity"))) {
            // --preset is checked against the technique's presets (`Technique::settings`)
            if id != "preset" {
                flags.push((id, long, radiosity, "the deep-G-buffer radiosity"));
            }
        }
        flags.push((
            "no_probes".into(),
            "no-probes".into(),
            radiosity,
            "the deep-G-buffer radiosity",
        ));
        // the stages that read layers >= 1 (the deep-G-buffer AO, radiosity, mirror reflections
        // and bzb-gi's visibility)
        let reads_layers =
            dgb_ao || radiosity || settings.reflections.is_some() || settings.bzb_gi.is_some() || debug_view;
        flags.push((
            "layers".into(),
            "layers".into(),
            reads_layers || settings.deep.layers < 2,
            "a pass that reads a second deep-G-buffer layer",
        ));
        for (id, long) in [("variant", "variant"), ("layer_scale", "layer-scale")] {
            flags.push((
                id.into(),
                long.into(),
                settings.deep.layers >= 2,
                "a second deep-G-buffer layer (--layers 2 or more)",
            ));
        }
        let given = |id: &str| self.given.iter().any(|g| g == id);
        flags
            .iter()
            .filter(|f| !f.2 && given(&f.0))
            .map(|(_, long, _, what)| {
                format!(
                    "--{long} is not read by --technique {}: it runs without {what}",
                    self.technique.name
                )
            })
            .collect()
    }
}

#[derive(Args)]
pub struct TechniquesArgs {
    /// Only this technique (default: every registered one).
    #[arg(value_parser = parse_technique)]
    pub technique: Option<&'static strata_render::technique::Technique>,
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
}

/// `strata soak`: a long run along the camera path that samples memory.
#[derive(Args)]
pub struct SoakArgs {
    #[command(flatten)]
    pub frame: FrameArgs,
    /// Frames to render along the camera path (scene animation included), 1..=10000000.
    #[arg(long, default_value_t = 10_000, value_parser = clap::value_parser!(u32).range(1..=10_000_000))]
    pub frames: u32,
    /// Sample memory every N frames, 1..=1000000.
    #[arg(long, default_value_t = 500, value_parser = clap::value_parser!(u32).range(1..=1_000_000))]
    pub sample_every: u32,
    /// Fail (exit 1) when resident memory grows by more than this percentage between the
    /// first sample and the last, 0..=1000.
    #[arg(long, allow_negative_numbers = true)]
    pub max_growth_percent: Option<f64>,
    /// Print JSON.
    #[arg(long)]
    pub json: bool,
}

#[derive(Copy, Clone, PartialEq, Eq, ValueEnum, Debug)]
pub enum ReferenceKind {
    /// Ambient visibility: cosine-weighted binary visibility within --ao-radius (1 = unoccluded).
    Ao,
    /// Ambient visibility from the deep G-buffer obscurance estimator (DGB Eq. 1–2) over the true geometry, all layers.
    Obscurance,
    /// Path-traced diffuse GI: direct + --bounces indirect bounces.
    Gi,
    /// Indirect light only (GI minus direct and emission).
    Indirect,
    /// The exact deep G-buffer: first surface beyond z0 + Δz, for --layers layers.
    Layers,
    /// Order-independent transparency: every surface crossing of the pixel-centre ray
    /// composited front to back (ABA's ground truth; unshadowed fragment shading).
    Composite,
    /// Ambient visibility with opacity (ABA Eq. 3–4): every crossing's binary AO within
    /// --ao-radius, occluders weighted by α (strongest occluder), transparent receivers
    /// exterior + interior, blended front to back like the colour (the ground truth of aba-ao).
    AoOpacity,
}

#[derive(Args)]
pub struct ReferenceArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    /// What to compute.
    #[arg(long, value_enum)]
    pub kind: ReferenceKind,
    /// AO world-space radius (default: the scene's).
    #[arg(long)]
    pub ao_radius: Option<f32>,
    /// Samples per pixel, 1..=65536.
    #[arg(long, default_value_t = 64, value_parser = clap::value_parser!(u32).range(1..=65536))]
    pub spp: u32,
    /// Indirect bounces for gi/indirect, 0..=64.
    #[arg(long, default_value_t = 3)]
    pub bounces: u32,
    /// Seed of the sample sequences (ao, obscurance, gi, indirect): different seeds give
    /// independent noise at the same settings.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Number of layers for --kind layers, 1..=8.
    #[arg(long, default_value_t = 2)]
    pub layers: u32,
    /// Minimum separation Δz for --kind layers (default: the scene's).
    #[arg(long, allow_negative_numbers = true)]
    pub min_separation: Option<f32>,
    /// Output file (.exr linear or .png). For layers: one file per layer and attachment, named from this stem.
    #[arg(long)]
    pub out: PathBuf,
    /// Overwrite existing output files.
    #[arg(long)]
    pub force: bool,
    /// Hide the progress bar.
    #[arg(long)]
    pub quiet: bool,
    /// The ids of the flags given on the command line (not defaulted), filled after parsing:
    /// `reference` warns of those its kind does not read ([`ReferenceArgs::unread_flags`]).
    #[arg(skip)]
    pub given: Vec<String>,
}

/// (id, long name) of each flag of `A` that was `given` on the command line and is among
/// `ids` (the unread-flag warnings of `eval` and `reference`).
fn given_among<A: Args>(given: &[String], ids: &[String]) -> Vec<(String, String)> {
    A::augment_args(clap::Command::new("args"))
        .get_arguments()
        .filter_map(|a| Some((a.get_id().to_string(), a.get_long()?.to_string())))
        .filter(|(id, _)| ids.contains(id) && given.contains(id))
        .collect()
}

impl ReferenceArgs {
    /// One warning per given flag that `--kind` does not read (it is still range-checked).
    pub fn unread_flags(&self) -> Vec<String> {
        use ReferenceKind::*;
        let reads: &[&str] = match self.kind {
            Ao | Obscurance | AoOpacity => &["ao_radius", "spp", "seed"],
            Gi | Indirect => &["spp", "bounces", "seed"],
            Layers => &["layers", "min_separation"],
            Composite => &[],
        };
        let kind = self
            .kind
            .to_possible_value()
            .map_or(String::new(), |v| v.get_name().to_string());
        let unread: Vec<String> = ["ao_radius", "spp", "bounces", "seed", "layers", "min_separation"]
            .into_iter()
            .filter(|id| !reads.contains(id))
            .map(String::from)
            .collect();
        given_among::<ReferenceArgs>(&self.given, &unread)
            .into_iter()
            .map(|(_, long)| {
                let read: Vec<String> = reads.iter().map(|r| format!("--{}", r.replace('_', "-"))).collect();
                let what = if read.is_empty() {
                    "it takes none of the sampling flags".to_string()
                } else {
                    format!("it reads {}", read.join(", "))
                };
                format!("--{long} is not read by reference --kind {kind}: {what}")
            })
            .collect()
    }
}

#[derive(Args)]
pub struct BenchArgs {
    #[command(subcommand)]
    pub what: BenchWhat,
}

#[derive(Subcommand)]
pub enum BenchWhat {
    /// Per-pass GPU time of the single-layer frame (shadow, gbuffer, lighting, tonemap).
    Gbuffer(BenchGbufferArgs),
    /// Deep G-buffer construction, DGB Table 5 and Fig. 3: layer times per method and
    /// second-layer mismatches against the exact peel along the camera path.
    DeepGbuffer(BenchDeepArgs),
    /// CPU reference throughput (million rays per second).
    Reference(BenchReferenceArgs),
    /// Deep-G-buffer AO passes (DGB Table 4, AO column): per-pass GPU ms and the
    /// 1st layer + 2nd layer increment split.
    Ao(BenchAoArgs),
    /// Deep-G-buffer radiosity passes (DGB Table 4, indirect columns): per-pass GPU ms and
    /// the 1st layer + 2nd layer increment split, for a Table 2 preset.
    Radiosity(BenchRadiosityArgs),
    /// Deep-G-buffer mirror reflections (DGB §3.6; Table 4's ray-tracing footnote): GPU ms of
    /// the ray march, 1st layer + 2nd layer.
    Reflections(BenchReflectionsArgs),
    /// GPU time of any registered technique's passes (`strata techniques`), k = 1 and k layers.
    Technique(BenchTechniqueArgs),
    /// Interleaved deferred shading (ILS Table 4): per-pass GPU ms of the interleaved frame and
    /// of the brute force of the same frame (all N VPLs per pixel), and the speed-up.
    Ils(BenchIlsArgs),
    /// A-buffer constructions (ABA Table I): per-stage GPU ms (AO included) of linked-list, linear,
    /// fixed-array, dual-peel and the compressed path, memory and overflow per method, and the
    /// compressed-vs-brute-force AO speed-up.
    Abuffer(BenchAbufferArgs),
    /// Bounced z-buffer AO (BZB Table 1): per-pass GPU ms with the bounced z-buffer and
    /// with the additive AOV baseline (no visibility), the visibility step's cost, memory.
    Bzb(BenchBzbArgs),
    /// A frame onto a window (`strata view`): read back and encoded to 8-bit sRGB on the
    /// CPU, against the GPU encoder of the same bytes; wall-clock ms until the texture is ready.
    Display(BenchDisplayArgs),
}

#[derive(Args)]
pub struct BenchDisplayArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    #[command(flatten)]
    pub gpu: GpuArgs,
    /// Frames to time (after one warm-up frame), 1..=10000.
    #[arg(long, default_value_t = 10)]
    pub frames: u32,
    /// Registered technique whose display target is shown (`strata techniques`).
    #[arg(long, default_value = "direct", value_parser = parse_technique)]
    pub technique: &'static strata_render::technique::Technique,
    /// Print one JSON object on stdout.
    #[arg(long)]
    pub json: bool,
}

#[derive(Args)]
pub struct BenchBzbArgs {
    #[command(flatten)]
    pub stage: BenchStageArgs,
    /// Which bounced z-buffer technique: bzb-ao (BZB Table 1's AO column) or bzb-gi (its
    /// indirect-light columns: still-life, dominoes).
    #[arg(long, default_value = "bzb-ao", value_parser = parse_bzb_technique)]
    pub technique: String,
    /// Settings of the technique (e.g. --set directions=4 --set ao-radius=1, --set splat=dss); visibility is the bench's.
    #[command(flatten)]
    pub set: SetArgs,
}

fn parse_bzb_technique(s: &str) -> Result<String, String> {
    match s {
        "bzb-ao" | "bzb-gi" => Ok(s.to_string()),
        _ => Err(format!("'{s}': bench bzb times bzb-ao or bzb-gi")),
    }
}

#[derive(Args)]
pub struct BenchAbufferArgs {
    #[command(flatten)]
    pub stage: BenchStageArgs,
    /// Settings of technique `aba-ao` (e.g. --set pool=8000000 --set max-layers=16 --set compress=6
    /// --set kernel=hbao); `abuffer` and `compress` are the bench's own per column. With
    /// --set kernel=hbao-compute: ABA Table III (list columns walk lists with the compute
    /// kernel's axis taps; adds `compressed-fragment` and `single-layer`).
    #[command(flatten)]
    pub set: SetArgs,
}

#[derive(Args)]
pub struct BenchIlsArgs {
    #[command(flatten)]
    pub stage: BenchStageArgs,
    /// One of technique `ils`'s presets: standard (default), clean-edges, refined.
    #[arg(long)]
    pub preset: Option<String>,
    /// Settings of technique `ils` (e.g. --set vpls=480 --set interleave-n=8 --set interleave-m=6).
    #[command(flatten)]
    pub set: SetArgs,
}

#[derive(Args)]
pub struct BenchReflectionsArgs {
    #[command(flatten)]
    pub stage: BenchStageArgs,
    /// Ray-march steps, 1..=1024.
    #[arg(long, default_value_t = 64)]
    pub steps: u32,
    /// Maximum ray distance in scene units, > 0.
    #[arg(long, default_value_t = 16.0)]
    pub max_distance: f32,
}

#[derive(Args)]
pub struct BenchRadiosityArgs {
    #[command(flatten)]
    pub stage: BenchStageArgs,
    #[command(flatten)]
    pub radiosity: RadiosityArgs,
}

/// What every `bench` of a deep-G-buffer technique takes: scene, frames, layers.
#[derive(Args)]
pub struct BenchStageArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    #[command(flatten)]
    pub gpu: GpuArgs,
    /// Frames along the camera path to time (after one warm-up frame), 1..=10000.
    #[arg(long, default_value_t = 5)]
    pub frames: u32,
    /// Deep G-buffer layers k, 1..=4 (compared with k = 1 for the increment).
    #[arg(long, default_value_t = 2)]
    pub layers: u32,
    /// Deep G-buffer construction variant.
    #[arg(long, default_value = "reproject", value_parser = parse_variant)]
    pub variant: Variant,
    /// Print one JSON object on stdout.
    #[arg(long)]
    pub json: bool,
    /// The ids of the flags given on the command line (not defaulted), filled after parsing:
    /// the benches that time no second layer warn of `--layers` and `--variant`.
    #[arg(skip)]
    pub given: Vec<String>,
}

impl BenchWhat {
    /// The shared stage flags of the benches that have them.
    pub fn stage_mut(&mut self) -> Option<&mut BenchStageArgs> {
        match self {
            BenchWhat::Ao(b) => Some(&mut b.stage),
            BenchWhat::Radiosity(b) => Some(&mut b.stage),
            BenchWhat::Technique(b) => Some(&mut b.stage),
            BenchWhat::Ils(b) => Some(&mut b.stage),
            BenchWhat::Abuffer(b) => Some(&mut b.stage),
            BenchWhat::Bzb(b) => Some(&mut b.stage),
            BenchWhat::Reflections(b) => Some(&mut b.stage),
            BenchWhat::Gbuffer(_) | BenchWhat::DeepGbuffer(_) | BenchWhat::Reference(_) | BenchWhat::Display(_) => None,
        }
    }
}

#[derive(Args)]
pub struct BenchTechniqueArgs {
    #[command(flatten)]
    pub stage: BenchStageArgs,
    /// Registered technique (`strata techniques` lists them).
    #[arg(long, value_parser = parse_technique)]
    pub technique: &'static strata_render::technique::Technique,
    /// One of the technique's presets (default: its first).
    #[arg(long)]
    pub preset: Option<String>,
    #[command(flatten)]
    pub set: SetArgs,
}

#[derive(Args)]
pub struct BenchAoArgs {
    #[command(flatten)]
    pub stage: BenchStageArgs,
    #[command(flatten)]
    pub ao: AoArgs,
}

#[derive(Args)]
pub struct BenchGbufferArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    #[command(flatten)]
    pub gpu: GpuArgs,
    /// Frames to time (after one warm-up frame), 1..=10000.
    #[arg(long, default_value_t = 10)]
    pub frames: u32,
    /// Print one JSON object on stdout.
    #[arg(long)]
    pub json: bool,
}

#[derive(Args)]
pub struct BenchDeepArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    #[command(flatten)]
    pub gpu: GpuArgs,
    /// Frames along the camera path to time and compare (after one warm-up frame), 1..=10000.
    #[arg(long, default_value_t = 8)]
    pub frames: u32,
    /// Deep G-buffer layers k, 2..=4 (delay and predict run only for k = 2).
    #[arg(long, default_value_t = 2)]
    pub layers: u32,
    /// Minimum separation Δz in scene units (default: the scene's).
    #[arg(long, allow_negative_numbers = true)]
    pub min_separation: Option<f32>,
    /// Resolution divisor s of the second and later layers for every method, 1..=4 (DGB Fig. 11:
    /// layer j >= 1 rasterised at 1/s of the size, then upsampled; 1 = full resolution).
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=4))]
    pub layer_scale: u32,
    /// Write Fig. 3-style images (each method's layer 1 and its differences from the peel) into this folder.
    #[arg(long)]
    pub images: Option<PathBuf>,
    /// Overwrite existing images in --images.
    #[arg(long)]
    pub force: bool,
    /// Print one JSON object on stdout.
    #[arg(long)]
    pub json: bool,
}

#[derive(Args)]
pub struct BenchReferenceArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    /// Rays per measurement, in millions.
    #[arg(long, default_value_t = 4.0)]
    pub mrays: f64,
    #[arg(long)]
    pub json: bool,
}

pub fn parse_vec3(s: &str) -> Result<Vec3, String> {
    let v: Vec<f32> = s
        .split(',')
        .map(|p| p.trim().parse::<f32>())
        .collect::<Result<_, _>>()
        .map_err(|_| format!("'{s}' is not a vector: expected three numbers \"x,y,z\""))?;
    if v.len() != 3 || v.iter().any(|x| !x.is_finite()) {
        return Err(format!(
            "'{s}' is not a vector: expected three finite numbers \"x,y,z\""
        ));
    }
    Ok(Vec3::new(v[0], v[1], v[2]))
}
