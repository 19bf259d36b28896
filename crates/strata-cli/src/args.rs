//! Command-line arguments.

use std::path::PathBuf;

use clap::{Args, Parser, Subcommand, ValueEnum};
use glam::Vec3;
use strata_render::passes::deep_gbuffer::{DeepGBufferSettings, Variant};
use strata_render::renderer::GuardBand;

#[derive(Parser)]
#[command(
    name = "strata",
    version,
    about = "Layered screen-space global illumination (deep G-buffers and friends), measured against a CPU ray-traced reference",
    after_help = "Scenes: a built-in name (cornell, atrium, warehouse, plane, column-wall) or a path to a .gltf, .glb, .obj or .toml file.\nExamples:\n  strata info\n  strata render --scene atrium --width 640 --height 360 --out atrium.png\n  strata reference --scene cornell --kind ao --spp 16 --width 64 --height 64 --out ao.exr\n  strata render --scene atrium --layers 2 --variant reproject --debug-view layer1-albedo --out l1.png\n  strata bench gbuffer --scene atrium --width 640 --height 360 --frames 5 --json\n  strata bench deep-gbuffer --scene atrium --width 640 --height 360 --frames 8 --json"
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
    #[arg(long, default_value_t = 0.0)]
    pub frame: f32,
    /// Image width in pixels.
    #[arg(long, default_value_t = 640)]
    pub width: u32,
    /// Image height in pixels.
    #[arg(long, default_value_t = 360)]
    pub height: u32,
    /// Camera position "x,y,z" (overrides the scene camera and its path).
    #[arg(long, value_parser = parse_vec3)]
    pub eye: Option<Vec3>,
    /// Camera look-at point "x,y,z".
    #[arg(long, value_parser = parse_vec3)]
    pub target: Option<Vec3>,
    /// Camera up vector "x,y,z".
    #[arg(long, value_parser = parse_vec3)]
    pub up: Option<Vec3>,
    /// Vertical field of view in degrees, in (0, 180).
    #[arg(long)]
    pub fov: Option<f32>,
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
    #[arg(long)]
    pub min_separation: Option<f32>,
    /// Guard band rendered around the image and cropped: pixels per side (e.g. 32) or percent of the height (e.g. 10%).
    #[arg(long, default_value = "0", value_parser = parse_guard_band)]
    pub guard_band: GuardBand,
}

impl DeepArgs {
    pub fn settings(&self) -> DeepGBufferSettings {
        DeepGBufferSettings {
            layers: self.layers,
            variant: self.variant,
            min_separation: self.min_separation,
            ..Default::default()
        }
    }
}

fn parse_variant(s: &str) -> Result<Variant, String> {
    s.parse()
}

fn parse_guard_band(s: &str) -> Result<GuardBand, String> {
    s.parse()
}

#[derive(Copy, Clone, PartialEq, Eq, ValueEnum, Debug)]
pub enum Technique {
    /// Direct light (sun/point/spot/area, shadows) + emission + ambient.
    Direct,
}

#[derive(Args)]
pub struct RenderArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    #[command(flatten)]
    pub gpu: GpuArgs,
    /// Shading technique.
    #[arg(long, value_enum, default_value_t = Technique::Direct)]
    pub technique: Technique,
    #[command(flatten)]
    pub deep: DeepArgs,
    /// Write an intermediate target instead of the final image (e.g. csz, normal, albedo, emission, direct-diffuse, shadow, hdr). `--list-passes` shows them.
    #[arg(long)]
    pub debug_view: Option<String>,
    /// Exposure multiplier before tonemapping (default: the scene's).
    #[arg(long)]
    pub exposure: Option<f32>,
    /// Shadow map resolution per light, 64..=8192.
    #[arg(long, default_value_t = 2048)]
    pub shadow_resolution: u32,
    /// Output file: .png (tonemapped, sRGB) or .exr (linear HDR).
    #[arg(long, required_unless_present = "list_passes")]
    pub out: Option<PathBuf>,
    /// Overwrite the output file if it exists.
    #[arg(long)]
    pub force: bool,
    /// Print the frame's passes with their inputs and outputs, and the debug views, then exit.
    #[arg(long)]
    pub list_passes: bool,
    /// Print per-pass GPU times after rendering.
    #[arg(long)]
    pub timings: bool,
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
    #[arg(long, default_value_t = 64)]
    pub spp: u32,
    /// Indirect bounces for gi/indirect, 0..=64.
    #[arg(long, default_value_t = 3)]
    pub bounces: u32,
    /// Number of layers for --kind layers, 1..=8.
    #[arg(long, default_value_t = 2)]
    pub layers: u32,
    /// Minimum separation Δz for --kind layers (default: the scene's).
    #[arg(long)]
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
    #[arg(long)]
    pub min_separation: Option<f32>,
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
