//! `strata bench gbuffer`: per-pass GPU time of the single-layer frame (shadow, gbuffer,
//! lighting, tonemap).

use anyhow::Result;
use strata_render::{RenderSettings, Renderer};

use super::{bench_run, check_frames, timing_gpu, PassSamples};
use crate::results::GbufferBench;
use crate::scene::SceneSpec;

/// What to time.
#[derive(Clone, Debug)]
pub struct GbufferSettings {
    pub scene: SceneSpec,
    /// Adapter name substring (default: the first real GPU).
    pub adapter: Option<String>,
    /// Frames to time after one warm-up frame, 1..=10000.
    pub frames: u32,
}

pub fn run(s: &GbufferSettings) -> Result<GbufferBench> {
    check_frames(s.frames)?;
    let (scene, _) = s.scene.load()?;
    let gpu = timing_gpu(&s.adapter)?;
    let settings = RenderSettings {
        width: s.scene.width,
        height: s.scene.height,
        ..Default::default()
    };
    let mut r = Renderer::new(&gpu, &scene, settings)?;
    // Warm-up frame (pipeline creation, first-use allocations).
    let f0 = s.scene.frame;
    r.render(&gpu, &scene, &s.scene.cameras_at(&scene, f0), f0)?;
    let names = r.pass_infos().iter().map(|p| p.name.to_string()).collect();
    let mut samples = PassSamples::new(names);
    for i in 0..s.frames {
        let f = f0 + i as f32;
        let t = r.render(&gpu, &scene, &s.scene.cameras_at(&scene, f), f)?;
        samples.push(&t, Some(t.total()));
    }
    let (passes, total_median_ms, total_min_ms) = samples.summary();
    Ok(GbufferBench {
        run: bench_run(&s.scene, s.frames, &scene, &gpu),
        passes,
        total_median_ms,
        total_min_ms,
    })
}
