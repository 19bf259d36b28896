//! What the benchmarks and evaluations return: plain data, serialised as the JSON objects
//! `strata bench … --json` and `strata eval … --json` print, and read back by
//! [`crate::report::stitch`]. Keys are the ones those commands have always printed; fields added
//! since (`increment_spread`, `increment_within_noise`, `flicker_per_frame`, `by_layers`,
//! `bench: "deep-gbuffer"`) are extra keys.

use serde::{Deserialize, Serialize};

use crate::metrics::{ErrorStats, RefNoise};
use crate::stats::Spread;

/// The JSON text of a result as the CLI prints it: through `serde_json::Value`, so keys are
/// sorted and floats print as before the move into this crate.
pub fn to_json_string<T: Serialize>(v: &T) -> serde_json::Result<String> {
    serde_json::to_string(&serde_json::to_value(v)?)
}

/// Median and minimum GPU time of one pass over the timed frames.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PassTime {
    pub name: String,
    pub median_ms: f64,
    pub min_ms: f64,
}

/// What every GPU benchmark ran on.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BenchRun {
    pub scene: String,
    pub width: u32,
    pub height: u32,
    pub frames: u32,
    pub triangles: usize,
    pub device: String,
    /// No object moves, so the renderer draws the shadow maps in the warm-up frame only
    /// and the timed frames' `shadow` pass is ≈ 0 ms (false in results written before
    /// 2026-11-27, when every frame redrew them).
    #[serde(default)]
    pub shadow_maps_cached: bool,
}

/// `strata bench gbuffer`: per-pass times of the single-layer frame.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GbufferBench {
    #[serde(flatten)]
    pub run: BenchRun,
    pub passes: Vec<PassTime>,
    pub total_median_ms: f64,
    pub total_min_ms: f64,
}

/// `strata bench ao | radiosity | reflections`: the technique's passes with k layers, and the
/// "1st layer + increment" split against k = 1.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StageBench {
    #[serde(flatten)]
    pub run: BenchRun,
    pub layers: u32,
    pub passes: Vec<PassTime>,
    /// Median over frames of the per-frame sum of the technique's passes (k layers).
    pub total_median_ms: f64,
    pub total_min_ms: f64,
    /// `total_median_ms` of the k = 1 run (of this run when k = 1).
    pub layer1_ms: f64,
    /// `total_median_ms − layer1_ms` (a difference of medians: they add up).
    pub increment_ms: f64,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub passes_layers_1: Option<Vec<PassTime>>,
    /// The per-frame differences (k layers − 1 layer, same frame); k > 1 only.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub increment_spread: Option<Spread>,
    /// Whether `increment_spread`'s interquartile range includes zero; k > 1 only.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub increment_within_noise: Option<bool>,
    /// The technique's settings (preset, samples, variant, ...).
    #[serde(flatten)]
    pub settings: serde_json::Map<String, serde_json::Value>,
}

impl StageBench {
    /// "total T ms = F (1st layer) + I (layers 2..k)", and with k > 1 the per-frame increments'
    /// median, interquartile range and range, and whether the increment is within the
    /// frame-to-frame noise (its interquartile range includes zero).
    pub fn split_line(&self, name: &str) -> String {
        let mut line = format!(
            "{name} total {:.3} ms = {:.3} (1st layer) + {:.3} (layers 2..{})",
            self.total_median_ms, self.layer1_ms, self.increment_ms, self.layers
        );
        if let Some(s) = &self.increment_spread {
            line.push_str(&format!(
                "; per-frame increment median {:.3} ms, IQR [{:.3}, {:.3}], range [{:.3}, {:.3}] over {} frames",
                s.median_ms, s.q1_ms, s.q3_ms, s.min_ms, s.max_ms, s.frames
            ));
            if s.includes_zero() {
                line.push_str(": within the frame-to-frame noise (the IQR includes 0)");
            }
        }
        line
    }
}

/// One construction method of `strata bench deep-gbuffer` (DGB Table 5, Fig. 3).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DeepRow {
    pub method: String,
    pub layer1_ms: f64,
    pub layer2_ms: f64,
    pub total_ms: f64,
    /// Second-layer pixels that differ from the exact peel, percent.
    pub mismatch_pct: f64,
    /// "per-layer" or "multiview".
    pub submission: String,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub multiview_total_ms: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub multiview_layer2_ms: Option<f64>,
    /// With `layer_scale` > 1: the part of `layer2_ms` that upsamples the reduced layers
    /// into the full-resolution arrays (the rest rasterises them).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub upsample_ms: Option<f64>,
}

/// `strata bench deep-gbuffer`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DeepBench {
    #[serde(flatten)]
    pub run: BenchRun,
    pub layers: u32,
    /// Resolution divisor of layers ≥ 1 (DGB Fig. 11; 1 = full resolution).
    #[serde(default = "one")]
    pub layer_scale: u32,
    pub rows: Vec<DeepRow>,
}

fn one() -> u32 {
    1
}

fn is_one(v: &u32) -> bool {
    *v == 1
}

/// `strata bench reference`: CPU ray throughput.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ReferenceBench {
    pub scene: String,
    pub triangles: usize,
    pub width: u32,
    pub height: u32,
    pub threads: usize,
    pub bvh_build_s: f64,
    pub rays: u64,
    pub seconds: f64,
    pub mrays_per_s: f64,
    /// Throughput per tracer backend and kind of ray (empty in results written
    /// before these were measured). The fields above are the default backend's
    /// mixed primary + bounce measurement.
    #[serde(default)]
    pub kinds: Vec<RayKindBench>,
}

/// One tracer backend on one kind of ray (`strata bench reference`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RayKindBench {
    /// `"wide"` (the default) or `"binary"`.
    pub tracer: String,
    /// `"primary"` (camera rays, closest hit), `"ao"` (occlusion rays of length
    /// `ao_radius`, any hit) or `"diffuse"` (cosine bounce rays, closest hit).
    pub kind: String,
    pub build_s: f64,
    pub rays: u64,
    pub seconds: f64,
    pub mrays_per_s: f64,
    /// AO ray length (only for `"ao"`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ao_radius: Option<f32>,
}

/// Any benchmark's result, tagged by `"bench"`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "bench", rename_all = "kebab-case")]
pub enum BenchResult {
    Gbuffer(GbufferBench),
    DeepGbuffer(DeepBench),
    Ao(StageBench),
    Radiosity(StageBench),
    Reflections(StageBench),
    Reference(ReferenceBench),
    /// Any registered technique (`strata bench technique`).
    Technique(StageBench),
    /// Interleaved deferred shading vs its brute force (`strata bench ils`, ILS Table 4).
    Ils(Box<IlsBench>),
    /// A-buffer constructions and the compressed path (`strata bench abuffer`, ABA Table I).
    Abuffer(Box<AbufferBench>),
    /// Bounced z-buffer AO with and without visibility (`strata bench bzb`, BZB Table 1/3).
    Bzb(Box<BzbBench>),
    /// A frame onto a window: read back and encoded on the CPU, or encoded on the GPU
    /// (`strata bench display`).
    Display(DisplayBench),
}

/// `strata bench display`: wall-clock ms from an idle GPU until a window's 8-bit texture
/// of the frame is ready, by read-back (read the target, `to_rgba8`, upload) and by the GPU
/// encoder (`strata_render::display`); the two give the same bytes.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DisplayBench {
    #[serde(flatten)]
    pub run: BenchRun,
    pub technique: String,
    /// The display target (`ldr`, or `ao` for the AO techniques).
    pub target: String,
    pub readback_median_ms: f64,
    pub readback_min_ms: f64,
    pub gpu_median_ms: f64,
    pub gpu_min_ms: f64,
    /// `readback_median_ms / gpu_median_ms`.
    pub speedup: f64,
}

fn bzb_ao_name() -> String {
    "bzb-ao".into()
}

/// `strata bench bzb`: the `bzb-ao` or `bzb-gi` frame with the bounced z-buffer (depth
/// test, nearest sender) and without (the additive baseline), same splats.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BzbBench {
    /// `bzb-ao` or `bzb-gi` (results written before `bench bzb --technique` are AO).
    #[serde(default = "bzb_ao_name")]
    pub technique: String,
    pub triangles: u64,
    /// S directions per pixel.
    pub directions: u32,
    /// `bzb-splat` with visibility / without: what the visibility step costs.
    pub splat_ratio: f64,
    /// The whole technique's ratio.
    pub total_ratio: f64,
    /// Bytes of the bounced z-buffer, its payload and the splat inputs at the bench size.
    pub memory_bytes: u64,
    pub visibility: StageBench,
    pub no_visibility: StageBench,
    /// `splat = dss`: BZB Tables 1–3 (stage groups, surfel counts, memory).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dss: Option<DssBench>,
}

/// BZB Table 1's DSS stages (median ms, sums of the passes' medians), Table
/// 2's surfel counts and Table 3's memory.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DssBench {
    /// Table 1 with the bounced z-buffer.
    pub stages: DssStages,
    /// Table 1 for the additive shell splatting (no visibility).
    pub stages_no_visibility: DssStages,
    /// Table 2: triangles in, after frustum culling, sub-triangles, fine surfels, surfels.
    pub counts: strata_render::passes::bzb::dss::SurfelCounts,
    /// Table 3 (bytes).
    pub memory: strata_render::passes::bzb::dss::DssMemory,
    pub levels: u32,
    pub surfel_px: f32,
    pub d_max: f32,
}

#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct DssStages {
    /// dss-tessellate + dss-fine + dss-filter (Table 1's "tessellation"), and for bzb-gi
    /// dss-gi-shade (the surfels' direct light, shaded at surfelization, BZB §4.3).
    pub surfelization_ms: f64,
    pub tessellate_ms: f64,
    pub fine_ms: f64,
    pub filter_ms: f64,
    /// dss-gi-shade (bzb-gi only; 0 for AO and in results from before it was timed).
    #[serde(default)]
    pub shade_ms: f64,
    /// bzb-directions + dss-shuffle (direction setup and shuffling).
    pub shuffling_ms: f64,
    pub splatting_ms: f64,
    pub unshuffling_ms: f64,
    /// dss-reduce + bzb-reconstruct (levels combined, weighting).
    pub reduction_ms: f64,
    pub blurring_ms: f64,
    pub total_ms: f64,
}

/// `strata bench abuffer`: ABA Table I's stages per construction, keyed `dual-peel`,
/// `linked-list`, `linear`, `fixed-array`, `compressed`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct AbufferBench {
    pub methods: std::collections::BTreeMap<String, AbufferMethodBench>,
    /// The multilayer AO pass alone (ABA §III-B, heavy workload): brute force
    /// (linked lists walked per tap) over compressed (M nodes per tap).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ao_speedup: Option<f64>,
    /// ꟻLIP between the compressed and the brute-force AO images (`ao`, after the blur).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ao_flip_compressed_vs_brute: Option<f32>,
}

/// One column of ABA Table I: median GPU ms per stage (absent: the method has no such
/// pass), the A-buffer's memory and the fragments it stored and dropped.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct AbufferMethodBench {
    pub clear_ms: Option<f64>,
    pub count_ms: Option<f64>,
    pub prefix_sum_ms: Option<f64>,
    pub draw_ms: Option<f64>,
    pub resolve_ms: Option<f64>,
    /// Table I "AO": the multilayer AO pass (`aba-ao`) and its bilateral blur.
    #[serde(default)]
    pub ao_ms: Option<f64>,
    #[serde(default)]
    pub ao_blur_ms: Option<f64>,
    pub total_ms: f64,
    /// Bytes of the structure (nodes, heads/counters) and of the compressed nodes.
    pub memory_bytes: u64,
    /// Fragments rasterised, and those dropped for lack of room (overflow).
    pub fragments: u32,
    pub dropped: u32,
    /// The full per-pass timing.
    pub stage: StageBench,
}

/// `strata bench ils`: ILS Table 4's "IS" and "no IS" columns as GPU times of
/// the same frame with the same VPLs.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct IlsBench {
    /// VPL paths requested (N; the VPLs that hit a surface are shaded).
    pub vpls_generated: u32,
    /// Interleaved passes (ils-gbuffer, ils-bs, ils-snsm, ils-bg, ils-db, ils-blur-h/v, compose).
    pub interleaved: StageBench,
    /// Brute force (ils-gbuffer, ils-brute-force, compose).
    pub brute_force: StageBench,
    /// Brute force's total / the interleaved total (the indirect part of the frame).
    pub speedup: f64,
    /// ils-brute-force / ils-snsm: the shading alone.
    pub shading_speedup: f64,
}

impl BenchResult {
    /// The `"bench"` tag.
    pub fn name(&self) -> &'static str {
        match self {
            BenchResult::Gbuffer(_) => "gbuffer",
            BenchResult::DeepGbuffer(_) => "deep-gbuffer",
            BenchResult::Ao(_) => "ao",
            BenchResult::Radiosity(_) => "radiosity",
            BenchResult::Reflections(_) => "reflections",
            BenchResult::Reference(_) => "reference",
            BenchResult::Technique(_) => "technique",
            BenchResult::Ils(_) => "ils",
            BenchResult::Abuffer(_) => "abuffer",
            BenchResult::Bzb(_) => "bzb",
            BenchResult::Display(_) => "display",
        }
    }
}

/// Temporal instability along the camera path: mean |v_t(p) − v_{t−1}(p′)| over pixels whose
/// surface reprojects onto the same surface, averaged over consecutive frame pairs.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Flicker {
    #[serde(rename = "flicker")]
    pub mean: f64,
    #[serde(rename = "flicker_frames")]
    pub frames: u32,
    #[serde(rename = "flicker_valid_fraction")]
    pub valid_fraction: f64,
    /// `[frame t, mean |Δ| between t − 1 and t]` for each pair with valid pixels.
    #[serde(rename = "flicker_per_frame", default)]
    pub per_frame: Vec<[f64; 2]>,
}

/// What every evaluation reports besides its errors.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct EvalRun {
    pub scene: String,
    pub layers: u32,
    pub variant: String,
    /// Resolution divisor of layers ≥ 1 (`--layer-scale`, DGB Fig. 11); absent = 1.
    #[serde(default = "one", skip_serializing_if = "is_one")]
    pub layer_scale: u32,
    pub width: u32,
    pub height: u32,
    pub frame: f32,
    pub ref_spp: u32,
    /// What the reference computes, in words.
    pub reference: String,
    pub device: String,
    /// The warm-up followed the camera path, objects moving (`--moving`: gi, ao).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub moving: bool,
    /// `--set exposure`: the exposure the radiance comparisons displayed both images at for
    /// ꟻLIP; absent: the scene's.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub display_exposure: Option<f32>,
    #[serde(flatten)]
    pub flicker: Option<Flicker>,
    /// Things the reader of the numbers must know (a reference that did not converge, an error
    /// within 2× of the reference's noise); also printed on stderr.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub warnings: Vec<String>,
}

/// Errors of one configuration of `k` layers (the report's error-vs-layers rows).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ByLayers<E> {
    pub layers: u32,
    #[serde(flatten)]
    pub errors: E,
}

/// Deep-G-buffer AO errors: against the obscurance reference (top level) and binary AO.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct AoErrors {
    #[serde(flatten)]
    pub obscurance: ErrorStats,
    pub binary: ErrorStats,
}

/// `strata eval --technique ao`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct AoEval {
    #[serde(flatten)]
    pub run: EvalRun,
    pub samples: u32,
    pub radius: f32,
    pub bias: f32,
    pub epsilon: f32,
    #[serde(flatten)]
    pub errors: AoErrors,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub layers_1: Option<AoErrors>,
    /// With a report: every k from 1 to `layers`.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub by_layers: Vec<ByLayers<AoErrors>>,
    /// `bzb-ao`: directions S per pixel and whether the bounced z-buffer was on.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub directions: Option<u32>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub visibility: Option<bool>,
    /// `bzb-ao`: the AOV baseline (same splats, additive, no depth test) for the same camera.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub no_visibility: Option<AoErrors>,
    /// `bzb-ao`: DGB AO with 2 layers (its `--ao-*` flags) for the same camera.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dgb_2_layers: Option<AoErrors>,
    /// `bzb-ao`: the temporal filter's α (`--set alpha`; absent: off, every frame stands
    /// alone) and the frames rendered on the still camera before the evaluated one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub temporal_alpha: Option<f32>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub warmup_frames: Option<u32>,
}

/// Deep-G-buffer radiosity errors: the indirect light (top level) and direct + indirect.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct GiErrors {
    #[serde(flatten)]
    pub indirect: ErrorStats,
    pub full: ErrorStats,
}

/// One GPU configuration of DGB Fig. 10 against both single-bounce references.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Fig10Row {
    pub vs_visibility: ErrorStats,
    pub vs_mutual_visibility: ErrorStats,
}

/// DGB Fig. 10's error sources (single-bounce GPU radiosity with and without the n_Y test).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Fig10 {
    pub normal_test: Fig10Row,
    pub no_normal_test: Fig10Row,
}

/// `strata eval --technique gi`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GiEval {
    #[serde(flatten)]
    pub run: EvalRun,
    pub samples: u32,
    pub radius: f32,
    pub normal_test: bool,
    pub min_mip: u32,
    pub delta: f32,
    pub boost: bool,
    pub warmup: u32,
    pub ref_bounces: u32,
    /// Blended with light probes baked from the evaluated scene (`--probes`).
    #[serde(default)]
    pub probes: bool,
    /// The scene the probes were baked from when not the evaluated one (`--probes-from`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub probes_from: Option<String>,
    /// The probes' grid, probes per axis (`--probe-grid`), when blended with probes.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub probe_grid: Option<[u32; 3]>,
    /// Paths per probe of the bake (`--probe-rays`), when blended with probes.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub probe_rays: Option<u32>,
    #[serde(flatten)]
    pub errors: GiErrors,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub layers_1: Option<GiErrors>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fig10: Option<Fig10>,
    /// With a report: every k from 1 to `layers`.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub by_layers: Vec<ByLayers<GiErrors>>,
    /// `--oracle`: DGB's blend with a perfect gather beside the GPU's, for k = 1 and k.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub oracle: Option<GiOracle>,
}

/// `eval --technique gi --oracle`: what a perfect screen-space gather over k layers gives
/// (`strata_reference::oracle`), path-traced along paths independent of the reference's.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GiOracle {
    /// The oracle's own noise: its two halves' images compared, for k = `layers` within the
    /// radius: the renderer's blend (without probes, the seen light). Its convergence rule
    /// also waits for the control variate's image.
    pub noise: RefNoise,
    /// The gather's world-space radius of the bounded rows.
    pub radius: f32,
    /// Mean |E_cpu − E_gpu| / mean E_gpu of the probes' irradiance at the evaluated pixels:
    /// how closely the CPU twin the `detail` rows read follows the GPU's probe field.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub probe_twin_error: Option<f64>,
    /// One row per evaluated layer count (1, then `layers`).
    pub by_layers: Vec<GiOracleRow>,
}

/// The oracle's errors for one layer count, indirect light against the reference.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GiOracleRow {
    pub layers: u32,
    /// Mean confidence c (the share of paths whose first bounce the layers hold) over the
    /// pixels with a surface: anywhere in the image, and within the radius.
    pub confidence: f64,
    pub confidence_within_radius: f64,
    /// The GPU image's RMSE for this k with the reference's Monte Carlo noise taken out,
    /// beside the entries' `rmse_denoised`.
    pub gpu_rmse_denoised: f32,
    /// The GPU's gather against the perfect one over the same receivers (with DGB's blend:
    /// with `probe-detail` the gathered term is not an irradiance).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gather: Option<GiGatherAgreement>,
    pub entries: Vec<GiOracleEntry>,
}

/// How the GPU's gathered irradiance E_dgb and confidence compare with the perfect gather's
/// Ê and c (k layers, within the radius).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GiGatherAgreement {
    /// The GPU's mean confidence over the pixels with a surface (beside the row's
    /// `confidence_within_radius`).
    pub confidence: f64,
    /// Σ E_dgb / Σ Ê per RGB channel over the pixels where the perfect gather's c ≥
    /// `min_confidence` and the GPU's gather found something.
    pub irradiance_ratio: [f64; 3],
    pub min_confidence: f32,
    pub pixels: u32,
}

/// One blend of the perfect gather.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GiOracleEntry {
    /// `paper`: c·Ê + (1 − c)·E_probe (DGB §3.2); `renderer`: the rule the GPU ran, with
    /// the one-sided confidence (listed when it is on); `detail`: E_probe + E_seen − the
    /// probes' own light over the seen directions (the control variate of `--set
    /// probe-detail=on`, with the CPU twin of the probe field); `alone`: Ê, screen space
    /// alone; `probes`: E_probe alone (c = 0), the same for every k; `gpu`: the rule compose
    /// ran (DGB's blend, or with `probe-detail` the control variate) on the GPU's own
    /// gathered term and c (its image, recomposed with the path tracer's albedo);
    /// `gpu-gather-oracle-c` and `oracle-gather-gpu-c`: that rule with one half of the pair
    /// the oracle's.
    pub blend: String,
    /// Only paths whose first bounce lies within the gather's radius count as seen.
    pub within_radius: bool,
    pub errors: ErrorStats,
    /// RMSE with both images' Monte Carlo noise taken out (each image's variance from its
    /// two halves).
    pub rmse_denoised: f32,
}

/// `strata eval --technique bzb-gi`: bounced-z-buffer GI against the one-bounce path tracer,
/// with the additive baseline and 2-layer DGB radiosity of the same camera beside it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BzbGiEval {
    #[serde(flatten)]
    pub run: EvalRun,
    pub directions: u32,
    pub visibility: bool,
    pub d_max: f32,
    pub t_min: f32,
    /// The indirect light (top level: flip, rmse, mae) and the full image (`full`).
    #[serde(flatten)]
    pub errors: GiErrors,
    /// The same splats summed additively (form factor × radiance, no depth test).
    pub no_visibility: GiErrors,
    /// DGB radiosity with 2 layers, single bounce (δ = 0), for the same camera.
    pub dgb_2_layers: GiErrors,
    /// GPU milliseconds of `bzb-splat` in the evaluated frame, with and without visibility.
    pub splat_ms: f64,
    pub splat_ms_no_visibility: f64,
    /// GPU milliseconds of the whole frame (bzb-gi with visibility).
    pub frame_ms: f64,
    /// The temporal filter's α (`--set alpha`; absent: off, every frame stands alone).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub temporal_alpha: Option<f32>,
    /// Frames rendered on the still camera before the evaluated one, for both bzb-gi
    /// configurations: `--warmup` with the temporal filter, else 0. Absent in results
    /// written before 2026-11-29, which rendered one frame even with the filter on.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub warmup_frames: Option<u32>,
}

/// A-buffer OIT (ABA §IV) against the CPU compositing of every crossing.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct OitEval {
    #[serde(flatten)]
    pub run: EvalRun,
    /// The A-buffer construction (`linked-list`, `linear`, `fixed-array`, `dual-peel`).
    pub method: String,
    /// Fragments rasterised, and those dropped for lack of room (overflow).
    pub fragments: u32,
    pub dropped: u32,
    pub max_fragments_per_pixel: u32,
    /// Bytes of the A-buffer structure at the evaluated size.
    pub memory_bytes: u64,
    /// Linear radiance vs the CPU compositing: HDR ꟻLIP through the eval tonemap, RMSE, MAE.
    #[serde(flatten)]
    pub errors: ErrorStats,
}

/// Interleaved deferred shading (ILS §4, §6.2) against the brute force of the same VPLs and
/// against the one-bounce path tracer.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct IlsEval {
    #[serde(flatten)]
    pub run: EvalRun,
    /// VPL light paths requested (N) and VPLs shaded (the paths that hit a surface).
    pub vpl_paths: u32,
    pub vpls: u32,
    /// n×m.
    pub pattern: String,
    pub split: String,
    pub blur: f32,
    pub bilinear: bool,
    /// `ils-refine`'s coverage threshold (0 = off; `IlsSettings::refine`).
    #[serde(default)]
    pub refine: f32,
    /// d_c, the distance below which the geometry term is clamped (scene units; the
    /// default is `passes::ils::DEFAULT_CLAMP_SHARE` of the scene's diagonal); absent in
    /// results written before 2026-11-29.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub clamp_distance: Option<f32>,
    /// `ils-refine`'s roughness below which glossy receivers are refined (0 = off;
    /// `IlsSettings::refine_roughness`).
    #[serde(default)]
    pub refine_roughness: f32,
    /// `ils-refine`'s spike share for VPLs close to the receivers (0 = off;
    /// `IlsSettings::refine_peak`).
    #[serde(default)]
    pub refine_peak: f32,
    /// Whether windows an edge cuts slide and are re-weighted (`IlsSettings::slide_window`).
    #[serde(default)]
    pub blur_slide: bool,
    /// Whether each blur pass stops at its own axis's discontinuities only
    /// (`IlsSettings::per_axis_discontinuities`).
    #[serde(default)]
    pub per_axis_db: bool,
    /// The technique's preset (`--preset`; `standard` unless set), before `--set`.
    #[serde(default)]
    pub preset: String,
    /// With `refine`, `refine-roughness` or `refine-peak`: the share of the pixels
    /// `ils-refine` shaded again with all VPLs (their refined value differs from the
    /// blurred one).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub refined_share: Option<f32>,
    /// `none` (SNSM: VPL visibility ignored) or `vpl` (SSM: per-VPL shadow maps, §4.3).
    pub shadows: String,
    /// Full image vs the brute force (every pixel, all N VPLs, same shadows): ꟻLIP and RMSE of
    /// the tonemapped sRGB display values.
    pub flip_vs_brute: f32,
    pub rmse_vs_brute: f32,
    /// The indirect part (composed − direct) alone vs the brute force's, tonemapped.
    pub indirect_flip_vs_brute: f32,
    pub indirect_rmse_vs_brute: f32,
    /// Against the path tracer with one indirect bounce: `flip`, `rmse`, `mae` of the indirect
    /// light (top level) and of the full image (`full`).
    #[serde(flatten)]
    pub errors: GiErrors,
    /// The brute force against the same path tracer (what the interleaving itself adds is the
    /// difference).
    pub brute_force: GiErrors,
    /// §6.3's physically-based mode (`--progressive K`), when run.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub progressive: Option<IlsProgressive>,
}

/// ILS §6.3 / Table 5: frames with fresh VPL sets accumulated until the running mean is
/// within `target_rms` (relative RMS) of the converged image of the same estimator.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct IlsProgressive {
    /// K: VPL sets of the converged image, and the most frames accumulated.
    pub sets: u32,
    /// B: VPL bounces (instant radiosity) and indirect bounces of the path tracer.
    pub bounces: u32,
    pub vpl_paths: u32,
    pub target_rms: f64,
    /// n×m = 1×1 and 2×2.
    pub patterns: Vec<IlsProgressivePattern>,
    /// The 1×1 converged image against the path tracer with B bounces (full image,
    /// HDR ꟻLIP / RMSE / MAE): the bias of the geometry-term clamp and VPL singularities.
    pub converged_vs_path_tracer: ErrorStats,
    pub ref_spp: u32,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct IlsProgressivePattern {
    pub pattern: String,
    /// Frames until the relative RMS fell below the target (`None`: not within K).
    pub frames_to_target: Option<u32>,
    /// GPU milliseconds of those frames, and the CPU milliseconds that generated their VPLs.
    pub gpu_ms_to_target: Option<f64>,
    pub vpl_ms_to_target: Option<f64>,
    pub gpu_ms_per_frame: f64,
    /// σ₁: relative RMS of one VPL set about the estimator's expectation, from the
    /// sample variance of every set the pattern rendered (the converged image's K and
    /// the accumulated frames).
    pub per_set_rel_rms: f64,
    /// ⌈(σ₁ / target)²⌉: frames until the running mean is within the target of the
    /// expectation, and their GPU / VPL-generation milliseconds at the measured per-frame
    /// cost — Table 5's time where K frames do not reach it (a prediction, not a run).
    pub predicted_frames_to_target: u64,
    pub predicted_gpu_ms_to_target: f64,
    pub predicted_vpl_ms_to_target: f64,
    /// GPU ms per frame of the passes that depend on the VPL set (VPL shadow maps,
    /// SSM/SNSM or brute-force shading).
    pub vpl_dependent_ms_per_frame: f64,
    /// §6.3's accounting for a static view: one frame's fixed passes (G-buffer,
    /// direct light, BS, DB; BG and the blur are linear with fixed weights, so once on
    /// the accumulated sub-buffers) + the predicted frames × the VPL-dependent passes.
    pub predicted_static_view_gpu_ms_to_target: f64,
    /// (frames accumulated, relative RMS against the converged image).
    pub rms_curve: Vec<(u32, f64)>,
    /// (frames accumulated = 1, 2, 4, …, relative RMS of the running mean against the path
    /// tracer's full image): falls with the frames down to the clamp/singularity bias.
    pub rms_vs_path_tracer: Vec<(u32, f64)>,
}

/// Any evaluation's result, tagged by `"technique"`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "technique", rename_all = "lowercase")]
pub enum EvalResult {
    Ao(AoEval),
    /// A-buffer OIT (`oit`) against the CPU compositing.
    Oit(OitEval),
    /// Bounced-z-buffer AO (`bzb-ao`), with its baseline and DGB AO beside it.
    #[serde(rename = "bzb-ao")]
    Bzb(AoEval),
    /// A-buffer multilayer AO (`aba-ao`), with its single-layer variant (`layers_1`) and DGB AO beside it.
    #[serde(rename = "aba-ao")]
    AbaAo(AoEval),
    Gi(GiEval),
    Ils(IlsEval),
    /// Bounced-z-buffer GI (`bzb-gi`), with its baseline and DGB radiosity beside it.
    #[serde(rename = "bzb-gi")]
    BzbGi(BzbGiEval),
}

impl EvalResult {
    pub fn run(&self) -> &EvalRun {
        match self {
            EvalResult::Ao(e) | EvalResult::Bzb(e) | EvalResult::AbaAo(e) => &e.run,
            EvalResult::Gi(e) => &e.run,
            EvalResult::Ils(e) => &e.run,
            EvalResult::BzbGi(e) => &e.run,
            EvalResult::Oit(e) => &e.run,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn stats(x: f32) -> ErrorStats {
        ErrorStats {
            flip: x,
            rmse: 2.0 * x,
            mae: x,
            ..Default::default()
        }
    }

    fn run() -> EvalRun {
        EvalRun {
            scene: "atrium".into(),
            layers: 2,
            variant: "reproject".into(),
            layer_scale: 1,
            width: 32,
            height: 16,
            frame: 0.0,
            ref_spp: 16,
            reference: "obscurance".into(),
            device: "lavapipe".into(),
            moving: false,
            display_exposure: None,
            flicker: None,
            warnings: vec![],
        }
    }

    #[test]
    fn ao_eval_keeps_the_cli_keys_and_round_trips() {
        let errors = AoErrors {
            obscurance: stats(0.25),
            binary: stats(0.5),
        };
        let mut e = AoEval {
            run: run(),
            samples: 19,
            radius: 1.0,
            bias: 0.01,
            epsilon: 0.001,
            errors,
            layers_1: Some(errors),
            by_layers: vec![],
            directions: None,
            visibility: None,
            no_visibility: None,
            dgb_2_layers: None,
            temporal_alpha: None,
            warmup_frames: None,
        };
        let v = serde_json::to_value(EvalResult::Ao(e.clone())).unwrap();
        for key in [
            "technique",
            "scene",
            "layers",
            "flip",
            "rmse",
            "mae",
            "binary",
            "ref_spp",
            "device",
        ] {
            assert!(v.get(key).is_some(), "{key}: {v}");
        }
        assert_eq!(v["technique"], "ao");
        assert_eq!(v["binary"]["flip"], 0.5);
        assert_eq!(v["layers_1"]["binary"]["mae"], 0.5);
        assert!(v.get("flicker").is_none() && v.get("by_layers").is_none());
        e.run.flicker = Some(Flicker {
            mean: 0.01,
            frames: 3,
            valid_fraction: 0.9,
            per_frame: vec![[1.0, 0.01], [2.0, 0.02]],
        });
        let r = EvalResult::Ao(e);
        let v = serde_json::to_value(&r).unwrap();
        assert_eq!(v["flicker"], 0.01);
        assert_eq!(v["flicker_frames"], 3);
        let back: EvalResult = serde_json::from_value(v).unwrap();
        assert_eq!(back, r);
    }

    #[test]
    fn stage_bench_flattens_its_settings_and_round_trips() {
        let mut settings = serde_json::Map::new();
        settings.insert("preset".into(), "balanced".into());
        settings.insert("samples".into(), 13.into());
        let b = BenchResult::Radiosity(StageBench {
            run: BenchRun {
                scene: "cornell".into(),
                width: 48,
                height: 48,
                frames: 2,
                triangles: 30,
                device: "lavapipe".into(),
                shadow_maps_cached: true,
            },
            layers: 2,
            passes: vec![PassTime {
                name: "radiosity".into(),
                median_ms: 1.0,
                min_ms: 0.5,
            }],
            total_median_ms: 1.0,
            total_min_ms: 0.5,
            layer1_ms: 0.75,
            increment_ms: 0.25,
            passes_layers_1: None,
            increment_spread: Spread::of_differences(&[1.0, 1.1], &[0.8, 0.7]),
            increment_within_noise: Some(false),
            settings,
        });
        let v = serde_json::to_value(&b).unwrap();
        assert_eq!(v["bench"], "radiosity");
        assert_eq!(v["samples"], 13);
        assert_eq!(v["increment_within_noise"], false);
        assert!(v["increment_spread"]["q1_ms"].as_f64().is_some());
        let BenchResult::Radiosity(sb) = &b else { unreachable!() };
        let line = sb.split_line("radiosity");
        assert!(
            line.starts_with("radiosity total 1.000 ms = 0.750 (1st layer) + 0.250 (layers 2..2)"),
            "{line}"
        );
        assert!(line.contains("IQR [0.250, 0.350]") && !line.contains("noise"), "{line}");
        let mut noisy = sb.clone();
        noisy.increment_spread = Spread::of_differences(&[1.0, 0.5], &[0.8, 0.7]);
        assert!(noisy
            .split_line("radiosity")
            .contains("within the frame-to-frame noise"));
        let back: BenchResult = serde_json::from_value(v).unwrap();
        assert_eq!(back, b);
    }
}
