//! Timing of BS and BG per method, pattern and block size with GPU timestamp
//! queries (ILS §5.1, Fig. 5: 1024×1024 buffer, 2×2 / 4×4 / 8×8 patterns,
//! several block sizes). Not a test: used by the `ils_timing` example and,
//! later, `strata bench ils`.

use super::{Interleave, SplitMethod};
use crate::gpu::GpuContext;
use crate::profiler::Profiler;
use crate::RenderError;

/// What to time.
#[derive(Clone, Debug, PartialEq)]
pub struct TimingConfig {
    pub width: u32,
    pub height: u32,
    pub format: wgpu::TextureFormat,
    pub patterns: Vec<(u32, u32)>,
    /// Methods to time; a `Blocks` size invalid for a pattern is skipped for it.
    pub methods: Vec<SplitMethod>,
    /// Timed repetitions (after one warm-up); the median is reported.
    pub repeats: u32,
}

impl Default for TimingConfig {
    /// Fig. 5's set-up: 1024×1024, 2×2, 4×4, 8×8, blocks 8…256 (one RGBA16F
    /// buffer: the paper's G-buffer is 16-bit float, §4.1).
    fn default() -> Self {
        let mut methods = vec![SplitMethod::Naive, SplitMethod::Compute];
        methods.extend([8, 16, 32, 64, 128, 256].map(|block| SplitMethod::Blocks { block }));
        Self {
            width: 1024,
            height: 1024,
            format: wgpu::TextureFormat::Rgba16Float,
            patterns: vec![(2, 2), (4, 4), (8, 8)],
            methods,
            repeats: 5,
        }
    }
}

/// Median GPU times of one pattern and method.
#[derive(Clone, Debug, PartialEq)]
pub struct InterleaveTiming {
    pub n: u32,
    pub m: u32,
    pub method: SplitMethod,
    /// Milliseconds per BS pass (profiler label, median ms), in pass order.
    pub split: Vec<(String, f64)>,
    /// Milliseconds per BG pass, in pass order.
    pub gather: Vec<(String, f64)>,
    /// Median wall-clock ms of one submitted BS + BG (CPU side, submit to idle).
    pub wall_ms: f64,
}

impl InterleaveTiming {
    /// Total BS time (sum of its passes' medians).
    pub fn split_ms(&self) -> f64 {
        self.split.iter().map(|(_, t)| t).sum()
    }

    /// Total BG time.
    pub fn gather_ms(&self) -> f64 {
        self.gather.iter().map(|(_, t)| t).sum()
    }
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    match v.len() {
        0 => f64::NAN,
        n if n % 2 == 1 => v[n / 2],
        n => 0.5 * (v[n / 2 - 1] + v[n / 2]),
    }
}

/// Times BS and BG for every pattern × method of `cfg` (needs timestamp
/// queries between passes: `TIMESTAMP_QUERY_INSIDE_ENCODERS`).
pub fn time_interleave(gpu: &GpuContext, cfg: &TimingConfig) -> Result<Vec<InterleaveTiming>, RenderError> {
    gpu.require(wgpu::Features::TIMESTAMP_QUERY, "ils timing")?;
    gpu.require(wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS, "ils timing")?;
    let profiler = Profiler::new(gpu, 8);
    let mut out = Vec::new();
    for &(n, m) in &cfg.patterns {
        for &method in &cfg.methods {
            if let SplitMethod::Blocks { block } = method {
                if block < super::min_block(n, m) {
                    continue;
                }
            }
            let ils = Interleave::new(gpu, cfg.format, cfg.width, cfg.height, n, m, method)?;
            let src = ils.create_image_texture("ils timing image");
            let bpp = cfg.format.block_copy_size(None).unwrap_or(4);
            let data: Vec<u8> = (0..cfg.width * cfg.height * bpp)
                .map(|i| (i.wrapping_mul(2_654_435_761) >> 24) as u8 & 0x3f)
                .collect();
            gpu.queue.write_texture(
                src.as_image_copy(),
                &data,
                wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(cfg.width * bpp),
                    rows_per_image: None,
                },
                src.size(),
            );
            let tiled = ils.create_tiled_texture("ils timing tiled");
            let back = ils.create_image_texture("ils timing gathered");
            let views = [&src, &tiled, &back].map(|t| t.create_view(&Default::default()));
            let mut split: Vec<Vec<f64>> = vec![Vec::new(); method.split_labels().len()];
            let mut gather: Vec<Vec<f64>> = vec![Vec::new(); method.gather_labels().len()];
            let mut wall = Vec::new();
            for rep in 0..=cfg.repeats {
                let mut encoder = gpu.device.create_command_encoder(&Default::default());
                profiler.reset();
                ils.split_profiled(&mut encoder, &views[0], &views[1], Some(&profiler))?;
                ils.gather_profiled(&mut encoder, &views[1], &views[2], Some(&profiler))?;
                profiler.resolve(&mut encoder);
                let t0 = std::time::Instant::now();
                gpu.queue.submit([encoder.finish()]);
                gpu.check_errors()?;
                let elapsed = t0.elapsed().as_secs_f64() * 1e3;
                let timings = profiler.read(gpu)?;
                if rep == 0 {
                    continue; // warm-up
                }
                wall.push(elapsed);
                for (acc, label) in split.iter_mut().zip(method.split_labels()) {
                    acc.extend(timings.get(label));
                }
                for (acc, label) in gather.iter_mut().zip(method.gather_labels()) {
                    acc.extend(timings.get(label));
                }
            }
            let named = |labels: &[&str], v: Vec<Vec<f64>>| {
                labels
                    .iter()
                    .zip(v)
                    .map(|(l, t)| (l.to_string(), median(t)))
                    .collect::<Vec<_>>()
            };
            out.push(InterleaveTiming {
                n,
                m,
                method,
                split: named(method.split_labels(), split),
                gather: named(method.gather_labels(), gather),
                wall_ms: median(wall),
            });
        }
    }
    Ok(out)
}
