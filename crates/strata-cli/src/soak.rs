//! `strata soak`: many frames along the camera path (scene animation included),
//! with resident memory and wgpu's allocations sampled every N frames, so a leak
//! shows as growth between samples.

use anyhow::Result;
use strata_render::{GpuContext, GpuOptions, Renderer};

use crate::args::SoakArgs;
use crate::output::cameras_at;

/// Resident set size of this process in bytes (Linux: /proc/self/status), if known.
pub fn resident_bytes() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmRSS:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

/// One memory sample of the soak.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Sample {
    /// Frames rendered so far.
    pub frame: u32,
    pub rss_bytes: Option<u64>,
    /// wgpu's allocator report (bytes allocated / reserved), where the backend gives one.
    pub gpu_allocated_bytes: Option<u64>,
    pub gpu_reserved_bytes: Option<u64>,
    /// Seconds since the first frame.
    pub seconds: f64,
}

/// Growth of resident memory from the first sample to the last, in percent.
pub fn growth_percent(samples: &[Sample]) -> Option<f64> {
    let first = samples.first()?.rss_bytes? as f64;
    let last = samples.last()?.rss_bytes? as f64;
    Some(100.0 * (last - first) / first)
}

pub fn run(a: &SoakArgs) -> Result<()> {
    if let Some(m) = a.max_growth_percent {
        if !(0.0..=1000.0).contains(&m) {
            anyhow::bail!("--max-growth-percent {m} is out of range: must be in 0..=1000");
        }
    }
    let f = &a.frame;
    let (scene, _, settings) = crate::render::prepare(f)?;
    for w in f.unread_flags(&settings, false) {
        eprintln!("strata: warning: {w}");
    }
    let gpu = GpuContext::new(&GpuOptions {
        adapter: f.gpu.adapter.clone(),
    })?;
    let mut r = Renderer::new(&gpu, &scene, settings)?;
    let start = std::time::Instant::now();
    let sample = |frame: u32| {
        let report = gpu.device.generate_allocator_report();
        Sample {
            frame,
            rss_bytes: resident_bytes(),
            gpu_allocated_bytes: report.as_ref().map(|r| r.total_allocated_bytes),
            gpu_reserved_bytes: report.as_ref().map(|r| r.total_reserved_bytes),
            seconds: start.elapsed().as_secs_f64(),
        }
    };
    let mut samples = Vec::new();
    for i in 0..a.frames {
        let t = f.scene.frame + i as f32;
        // ILS with moving objects: this frame's VPLs (the first frame's were built in)
        if i > 0 {
            strata_eval::vpls::refresh_vpls(&mut r, &gpu, &scene, t)?;
        }
        r.render(&gpu, &scene, &cameras_at(&scene, &f.scene, t), t)?;
        let done = i + 1;
        // the first sample after one interval: allocator pools and caches are warm by then
        if done % a.sample_every == 0 || done == a.frames {
            let s = sample(done);
            if !a.json {
                eprintln!(
                    "frame {:>8}  rss {:>8.1} MB  {:.1} s",
                    s.frame,
                    s.rss_bytes.unwrap_or(0) as f64 / 1e6,
                    s.seconds
                );
            }
            samples.push(s);
        }
    }
    let growth = growth_percent(&samples);
    if a.json {
        let v = serde_json::json!({
            "scene": scene.name,
            "technique": f.technique.name,
            "layers": r.settings.deep.layers,
            "variant": r.settings.deep.variant.name(),
            "width": f.scene.width,
            "height": f.scene.height,
            "frames": a.frames,
            "sample_every": a.sample_every,
            "device": gpu.describe(),
            "samples": samples,
            "rss_growth_percent": growth,
        });
        println!("{}", serde_json::to_string_pretty(&v)?);
    } else if let Some(g) = growth {
        eprintln!("resident memory growth after the first sample: {g:+.2} %");
    }
    if let (Some(max), Some(g)) = (a.max_growth_percent, growth) {
        if g > max {
            anyhow::bail!("resident memory grew {g:.2} % after the first sample (--max-growth-percent {max})");
        }
    }
    Ok(())
}
