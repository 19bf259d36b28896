//! The driver of `strata bench ao | radiosity | reflections`: GPU time of a deep-G-buffer
//! technique's passes (DGB Table 4) per pass, and the paper's "1st layer + 2nd layer" split: the
//! passes' time with k = 1 and the increment of k layers over it, with the increment's spread over
//! the frames (so an increment within the frame-to-frame noise is reported as such).

use anyhow::{bail, Result};
use strata_render::passes::deep_gbuffer::{DeepGBufferSettings, Variant};
use strata_render::{GpuContext, RenderSettings, Renderer};
use strata_scene::Scene;

use super::{bench_run, check_frames, timing_gpu, PassSamples};
use crate::results::{PassTime, StageBench};
use crate::scene::SceneSpec;
use crate::stats::Spread;

/// What every stage benchmark takes: scene, frames, layers.
#[derive(Clone, Debug)]
pub struct StageSettings {
    pub scene: SceneSpec,
    pub adapter: Option<String>,
    /// Frames along the camera path to time (after one warm-up frame), 1..=10000.
    pub frames: u32,
    /// Deep G-buffer layers k, 1..=4 (compared with k = 1 for the increment).
    pub layers: u32,
    pub variant: Variant,
}

impl StageSettings {
    /// Render settings for `layers` layers of this size and variant (the rest default).
    pub fn render_settings(&self, layers: u32) -> RenderSettings {
        RenderSettings {
            width: self.scene.width,
            height: self.scene.height,
            deep: DeepGBufferSettings {
                layers,
                variant: self.variant,
                ..Default::default()
            },
            ..Default::default()
        }
    }
}

/// One technique's benchmark.
pub(crate) struct Stage<'a> {
    pub stage: &'a StageSettings,
    /// The technique's passes, in frame order.
    pub passes: &'a [&'a str],
    /// Render settings for k layers.
    pub settings: Box<dyn Fn(u32) -> RenderSettings + 'a>,
    /// The technique's settings, reported beside the times.
    pub extra: serde_json::Value,
}

/// Per-pass times and per-frame totals of one layer count.
struct Timing {
    passes: Vec<PassTime>,
    total_median_ms: f64,
    total_min_ms: f64,
    frame_totals: Vec<f64>,
}

pub(crate) fn run(b: Stage) -> Result<StageBench> {
    let s = b.stage;
    check_frames(s.frames)?;
    if !(1..=4).contains(&s.layers) {
        bail!("--layers {} is out of range: must be in 1..=4", s.layers);
    }
    let (scene, _) = s.scene.load()?;
    let gpu = timing_gpu(&s.adapter)?;
    let k = measure(&gpu, &scene, &b, s.layers)?;
    let one = if s.layers > 1 {
        Some(measure(&gpu, &scene, &b, 1)?)
    } else {
        None
    };
    let first = one.as_ref().unwrap_or(&k).total_median_ms;
    let spread = one
        .as_ref()
        .and_then(|o| Spread::of_differences(&k.frame_totals, &o.frame_totals));
    // which form ran the passes that have two (`Kernel::Auto` resolves by adapter)
    let mut settings = b.extra.as_object().cloned().unwrap_or_default();
    let rs = (b.settings)(s.layers);
    let form = |compute: bool| if compute { "compute" } else { "fragment" };
    // and the resolution divisor of the passes that may run reduced (1: every pixel)
    if let Some(ao) = &rs.ao {
        settings.insert("ao_kernel".into(), form(ao.kernel.compute_on(&gpu)).into());
        settings.insert("ao_scale".into(), ao.scale.into());
    }
    if let Some(rad) = &rs.radiosity {
        settings.insert("indirect_kernel".into(), form(rad.kernel.compute_on(&gpu)).into());
        settings.insert("gather_scale".into(), rad.gather_scale.into());
    }
    if rs.shade {
        let compute = strata_render::passes::lighting::LightingPass::compute_on(&gpu, &rs.lighting);
        settings.insert("lighting_kernel".into(), form(compute).into());
    }
    // BZB's AOV splats: the rasteriser's depth test or the compute pass
    if let Some(compute) = rs
        .bzb
        .as_ref()
        .map(|b| b.compute_splat_on(&gpu, rs.width, rs.height))
        .or(rs
            .bzb_gi
            .as_ref()
            .map(|g| g.compute_splat_on(&gpu, rs.width, rs.height)))
    {
        settings.insert("splat_kernel".into(), form(compute).into());
    }
    if let Some(refl) = &rs.reflections {
        let formats = strata_render::passes::reflections::OUTPUTS.map(|t| t.format);
        settings.insert(
            "reflection_kernel".into(),
            form(refl.kernel.compute_for(&gpu, &formats)).into(),
        );
    }
    Ok(StageBench {
        run: bench_run(&s.scene, s.frames, &scene, &gpu),
        layers: s.layers,
        total_median_ms: k.total_median_ms,
        total_min_ms: k.total_min_ms,
        layer1_ms: first,
        increment_ms: k.total_median_ms - first,
        passes: k.passes,
        passes_layers_1: one.map(|o| o.passes),
        increment_within_noise: spread.map(|s| s.includes_zero()),
        increment_spread: spread,
        settings,
    })
}

fn measure(gpu: &GpuContext, scene: &Scene, b: &Stage, layers: u32) -> Result<Timing> {
    let spec = &b.stage.scene;
    let mut r = Renderer::new(gpu, scene, (b.settings)(layers))?;
    let f0 = spec.frame;
    // warm-up frame (pipelines, first-use allocations; gives the oracle and history)
    r.render(gpu, scene, &spec.cameras_at(scene, f0 - 1.0), f0 - 1.0)?;
    let names = r
        .pass_infos()
        .iter()
        .map(|p| p.name)
        .filter(|n| b.passes.contains(n))
        .map(String::from)
        .collect();
    let mut samples = PassSamples::new(names);
    for i in 0..b.stage.frames {
        let f = f0 + i as f32;
        let t = r.render(gpu, scene, &spec.cameras_at(scene, f), f)?;
        samples.push(&t, None);
    }
    let (passes, total_median_ms, total_min_ms) = samples.summary();
    Ok(Timing {
        passes,
        total_median_ms,
        total_min_ms,
        frame_totals: samples.frame_totals,
    })
}
