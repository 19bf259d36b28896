//! GPU timestamp benchmarks ([`gbuffer`], [`deep`], and the deep-G-buffer techniques through the
//! shared [`stage`] driver: [`ao`], [`radiosity`], [`reflections`]) and CPU reference throughput
//! ([`reference`]). What they share is here.

use anyhow::{bail, Result};
use strata_render::{GpuContext, GpuOptions, PassTimings};
use strata_scene::Scene;

use crate::results::{BenchRun, PassTime};
use crate::scene::SceneSpec;
use crate::stats::median_min;

pub mod abuffer;
pub mod ao;
pub mod bzb;
pub mod deep;
pub mod display;
pub mod gbuffer;
pub mod ils;
pub mod radiosity;
pub mod reference;
pub mod reflections;
pub mod stage;
pub mod technique;

/// The wgpu features `strata bench` needs.
pub fn timestamp_features() -> strata_render::gpu::Features {
    strata_render::gpu::Features::TIMESTAMP_QUERY | strata_render::gpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS
}

/// Checks a `--frames` count (1..=10000).
pub(crate) fn check_frames(frames: u32) -> Result<()> {
    if !(1..=10000).contains(&frames) {
        bail!("--frames {frames} is out of range: must be in 1..=10000");
    }
    Ok(())
}

/// Opens the adapter (a name substring, or the default) and checks it has GPU timestamps.
pub(crate) fn timing_gpu(adapter: &Option<String>) -> Result<GpuContext> {
    let gpu = GpuContext::new(&GpuOptions {
        adapter: adapter.clone(),
    })?;
    if !gpu.has(timestamp_features()) {
        bail!("the adapter lacks TIMESTAMP_QUERY / TIMESTAMP_QUERY_INSIDE_ENCODERS, which `strata bench` needs");
    }
    Ok(gpu)
}

/// What a benchmark of `frames` frames of `spec` ran on.
pub(crate) fn bench_run(spec: &SceneSpec, frames: u32, scene: &Scene, gpu: &GpuContext) -> BenchRun {
    BenchRun {
        scene: spec.scene.clone(),
        width: spec.width,
        height: spec.height,
        frames,
        triangles: scene.triangle_count(),
        device: gpu.describe(),
        shadow_maps_cached: !scene.animated(),
    }
}

/// Per-pass times of `names` over frames, and the per-frame sums of those passes.
pub(crate) struct PassSamples {
    names: Vec<String>,
    samples: Vec<Vec<f64>>,
    /// Per frame: the sum of the passes (or the whole frame, see [`PassSamples::push`]).
    pub frame_totals: Vec<f64>,
}

impl PassSamples {
    pub fn new(names: Vec<String>) -> Self {
        let samples = vec![Vec::new(); names.len()];
        Self {
            names,
            samples,
            frame_totals: Vec::new(),
        }
    }

    /// Adds one frame's times of the passes (NaN where a pass did not run); its total is the sum
    /// of those passes, or `total` when given.
    pub fn push(&mut self, t: &PassTimings, total: Option<f64>) {
        let mut sum = 0.0;
        for (n, s) in self.names.iter().zip(&mut self.samples) {
            let ms = t.get(n).unwrap_or(f64::NAN);
            s.push(ms);
            sum += ms;
        }
        self.frame_totals.push(total.unwrap_or(sum));
    }

    /// Median and minimum per pass, and of the per-frame totals.
    pub fn summary(&self) -> (Vec<PassTime>, f64, f64) {
        let passes = self
            .names
            .iter()
            .zip(&self.samples)
            .map(|(n, s)| {
                let (median_ms, min_ms) = median_min(&mut s.clone());
                PassTime {
                    name: n.clone(),
                    median_ms,
                    min_ms,
                }
            })
            .collect();
        let (med, min) = median_min(&mut self.frame_totals.clone());
        (passes, med, min)
    }
}
