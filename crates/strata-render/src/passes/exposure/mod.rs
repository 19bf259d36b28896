//! Auto-exposure (`RenderSettings::auto_exposure`, `strata render --exposure auto`): not
//! in the four papers, which hand-set their exposures. The tonemapper's exposure maps the
//! image's typical luminance L̄ to a key value (Reinhard et al. 2002, Eq. 2: key / L̄),
//! adapted over frames in log space. L̄ is 2^(mean log2 L) over the non-black pixels
//! between two percentiles of a log2-luminance histogram, the way game engines meter eye
//! adaptation: Eq. 1's plain log-average over every pixel metered the Cornell box, half of
//! whose frame is black background, at 197 (its scene exposure is 1). Two compute
//! dispatches (`exposure.wgsl`): each 16×16 tile's histogram added into one, then the
//! exposure, into a storage buffer the tonemapper reads; nothing is read back unless
//! asked ([`ExposurePass::read`]).

use crate::frame::{Pass, PassInfo, Targets};
use crate::gpu::GpuContext;
use crate::passes::builder::{ComputePass, PassBuilder};
use crate::scene_gpu::GpuScene;

/// Histogram bins (as `exposure.wgsl`): 4 per stop from 2^−16, 32 stops.
pub const BINS: usize = 128;
const BINS_PER_STOP: f32 = 4.0;
const MIN_LOG2: f32 = -16.0;
/// The exposure stays within [1e-6, 1e6] (as `exposure.wgsl`).
pub const EXPOSURE_RANGE: (f32, f32) = (1e-6, 1e6);

/// Auto-exposure settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AutoExposure {
    /// The value L̄ maps to before the tone curve. Default 0.18, the photographic middle
    /// grey of Reinhard et al.'s Eq. 2.
    pub key: f32,
    /// The percentile window metered: the pixels from the `low` to the `high` fraction,
    /// darkest first. Default 0.5–0.95: the brighter half without its brightest 5 %, so
    /// neither a black background nor a few highlights set the exposure.
    pub low: f32,
    pub high: f32,
    /// The new exposure's weight per frame, in log space: 1 takes it at once (default:
    /// a still image needs no adaptation), smaller values adapt over about 1/adaptation
    /// frames.
    pub adaptation: f32,
}

impl Default for AutoExposure {
    fn default() -> Self {
        Self {
            key: 0.18,
            low: 0.5,
            high: 0.95,
            adaptation: 1.0,
        }
    }
}

impl AutoExposure {
    /// The exposure follows the metering over several frames (adaptation < 1).
    pub fn adapts(&self) -> bool {
        self.adaptation < 1.0
    }

    pub fn validate(&self) -> Result<(), String> {
        if !(self.key > 0.0 && self.key <= 10.0) {
            return Err(format!(
                "auto-exposure key {} is out of range: must be in (0, 10]",
                self.key
            ));
        }
        if !(self.low >= 0.0 && self.low < self.high && self.high <= 1.0) {
            return Err(format!(
                "auto-exposure percentiles {}..{} are out of range: must satisfy 0 <= low < high <= 1",
                self.low, self.high
            ));
        }
        if !(self.adaptation > 0.0 && self.adaptation <= 1.0) {
            return Err(format!(
                "auto-exposure adaptation {} is out of range: must be in (0, 1]",
                self.adaptation
            ));
        }
        Ok(())
    }
}

/// The histogram bin of a linear rgb pixel (as `bin_of` in `exposure.wgsl`).
pub fn bin_of(c: [f32; 3]) -> usize {
    let l = 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
    // NaN fails the comparison too
    if l.is_nan() || l <= 0.0 {
        return 0;
    }
    ((l.log2() - MIN_LOG2) * BINS_PER_STOP)
        .floor()
        .clamp(0.0, (BINS - 1) as f32) as usize
}

/// The CPU twin of `exposure.wgsl` without history: (exposure, L̄) of the linear rgb
/// pixels in `data` (`channels` ≥ 3 per pixel, the first three read). Black pixels (bin
/// 0) are not metered; an all-black image meters L̄ = 1.
pub fn metered_exposure(data: &[f32], channels: usize, a: &AutoExposure) -> (f32, f32) {
    let mut histogram = [0u32; BINS];
    for c in data.chunks_exact(channels.max(3)) {
        histogram[bin_of([c[0], c[1], c[2]])] += 1;
    }
    // bin 0 (black) is not metered
    let total = histogram[1..].iter().map(|&n| n as f32).sum::<f32>();
    let (lo, hi) = (a.low * total, a.high * total);
    let (mut below, mut weight, mut sum) = (0.0f32, 0.0f32, 0.0f32);
    for (b, &n) in histogram.iter().enumerate().skip(1) {
        let n = n as f32;
        let w = (below + n).min(hi) - below.max(lo);
        let w = w.max(0.0);
        sum += w * (MIN_LOG2 + (b as f32 + 0.5) / BINS_PER_STOP);
        weight += w;
        below += n;
    }
    let mean = if weight > 0.0 { sum / weight } else { 0.0 };
    let e = (a.key.log2() - mean).clamp(EXPOSURE_RANGE.0.log2(), EXPOSURE_RANGE.1.log2());
    (e.exp2(), mean.exp2())
}

/// Mirrors `Meter` in `exposure.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct MeterUniforms {
    key: f32,
    adaptation: f32,
    low: f32,
    high: f32,
    has_history: u32,
    _pad: [u32; 3],
    image: [u32; 4],
}

impl MeterUniforms {
    fn new(a: &AutoExposure, has_history: bool, image: [u32; 4]) -> Self {
        Self {
            key: a.key,
            adaptation: a.adaptation,
            low: a.low,
            high: a.high,
            has_history: has_history as u32,
            _pad: [0; 3],
            image,
        }
    }
}

/// The two dispatches and the exposure they leave in [`ExposurePass::buffer`].
pub struct ExposurePass {
    input: &'static str,
    histogram_pass: ComputePass,
    exposure_pass: ComputePass,
    /// The image inside the guard band: origin and size in texels.
    image: [u32; 4],
    settings: AutoExposure,
    histogram: wgpu::Buffer,
    /// [0] the exposure, [1] L̄.
    buffer: wgpu::Buffer,
    /// The read-back that does not wait ([`ExposurePass::read_latest`]): a copy of `buffer`,
    /// its state (0 idle, 1 mapping, 2 mapped, 3 failed) and the last value that arrived.
    staging: wgpu::Buffer,
    staging_state: std::sync::Arc<std::sync::atomic::AtomicU8>,
    latest: std::sync::Mutex<Option<(f32, f32)>>,
}

/// Pixels per tile side of `cs_histogram`.
const TILE: u32 = 16;

impl ExposurePass {
    /// Meters the image inside a guard band of `guard` texels of target `input` (the
    /// tonemapper's).
    pub fn new(gpu: &GpuContext, targets: &Targets, input: &'static str, guard: u32, settings: AutoExposure) -> Self {
        let t = &targets.get(input).texture;
        let image = [
            guard,
            guard,
            t.width().saturating_sub(2 * guard).max(1),
            t.height().saturating_sub(2 * guard).max(1),
        ];
        let storage = |label, bytes: u64| {
            gpu.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: bytes,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        };
        let histogram = storage("exposure histogram", 4 * BINS as u64);
        let buffer = storage("exposure", 8);
        let build = |entry: &'static str| {
            PassBuilder::new(gpu, targets, "exposure")
                .compute()
                .entry(entry)
                .shader("exposure", include_str!("exposure.wgsl"))
                .uniforms(&MeterUniforms::new(&settings, false, image))
                .read(input)
                .storage_rw(&histogram)
                .storage_rw(&buffer)
                .build_compute()
        };
        let (histogram_pass, exposure_pass) = (build("cs_histogram"), build("cs_exposure"));
        let staging = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("exposure read-back"),
            size: 8,
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        Self {
            input,
            histogram_pass,
            exposure_pass,
            image,
            settings,
            histogram,
            buffer,
            staging,
            staging_state: Default::default(),
            latest: Default::default(),
        }
    }

    /// The (exposure, L̄) of the latest frame whose read-back has arrived, without waiting
    /// for the GPU: each call collects the copy an earlier call started, if it has landed,
    /// and starts a copy of the current value. `None` until the first lands (a frame or so
    /// behind [`ExposurePass::read`], which waits). For a window's label, not for the image.
    pub fn read_latest(&self, gpu: &GpuContext) -> Option<(f32, f32)> {
        use std::sync::atomic::Ordering;
        let _ = gpu.device.poll(wgpu::PollType::Poll);
        let mut latest = self.latest.lock().unwrap_or_else(|p| p.into_inner());
        match self.staging_state.load(Ordering::Acquire) {
            1 => return *latest,
            2 => {
                if let Ok(b) = self.staging.get_mapped_range(..) {
                    let f = |i: usize| f32::from_le_bytes([b[4 * i], b[4 * i + 1], b[4 * i + 2], b[4 * i + 3]]);
                    *latest = Some((f(0), f(1)));
                }
                self.staging.unmap();
            }
            _ => {}
        }
        let mut enc = gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("exposure read-back"),
        });
        enc.copy_buffer_to_buffer(&self.buffer, 0, &self.staging, 0, 8);
        gpu.queue.submit([enc.finish()]);
        self.staging_state.store(1, Ordering::Release);
        let state = self.staging_state.clone();
        self.staging.map_async(wgpu::MapMode::Read, .., move |r| {
            state.store(if r.is_ok() { 2 } else { 3 }, Ordering::Release);
        });
        *latest
    }

    /// The storage buffer holding the exposure (f32 [0]) and L̄ ([1]).
    pub fn buffer(&self) -> &wgpu::Buffer {
        &self.buffer
    }

    /// Before encoding a frame: whether an earlier frame left an exposure to adapt from.
    pub fn set_frame(&self, gpu: &GpuContext, has_history: bool) {
        let u = MeterUniforms::new(&self.settings, has_history, self.image);
        self.histogram_pass.set_uniforms(gpu, &u);
        self.exposure_pass.set_uniforms(gpu, &u);
    }

    /// The last frame's (exposure, L̄), read back.
    pub fn read(&self, gpu: &GpuContext) -> Result<(f32, f32), crate::RenderError> {
        let b = gpu.read_storage(&self.buffer)?;
        let f = |i: usize| f32::from_le_bytes([b[4 * i], b[4 * i + 1], b[4 * i + 2], b[4 * i + 3]]);
        Ok((f(0), f(1)))
    }

    /// The last frame's histogram, read back (pixels per bin, [`bin_of`]).
    pub fn read_histogram(&self, gpu: &GpuContext) -> Result<Vec<u32>, crate::RenderError> {
        let b = gpu.read_storage(&self.histogram)?;
        Ok(b.chunks_exact(4)
            .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect())
    }
}

impl Pass for ExposurePass {
    fn info(&self) -> PassInfo {
        PassInfo {
            name: "exposure",
            inputs: vec![self.input],
            outputs: vec!["exposure"],
        }
    }

    fn encode(&self, _gpu: &GpuContext, scene: &GpuScene, _targets: &Targets, encoder: &mut wgpu::CommandEncoder) {
        encoder.clear_buffer(&self.histogram, 0, None);
        // one invocation per tile, 8×8 per workgroup
        let tiles = [self.image[2].div_ceil(TILE), self.image[3].div_ceil(TILE)];
        self.histogram_pass.encode_grid(scene, encoder, tiles, [8, 8]);
        self.exposure_pass.encode_grid(scene, encoder, [1, 1], [1, 1]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A uniform image meters at its own bin's centre; a black half below the window does
    /// not move the exposure; a window over both halves meters their geometric mean.
    #[test]
    fn metered_exposure_is_the_key_over_the_windowed_log_mean() {
        let a = AutoExposure::default();
        let centre = |l: f32| (MIN_LOG2 + (bin_of([l; 3]) as f32 + 0.5) / BINS_PER_STOP).exp2();
        let grey = [0.5f32; 12];
        let (e, lbar) = metered_exposure(&grey, 3, &a);
        assert_eq!(lbar, centre(0.5));
        assert!((e - 0.18 / lbar).abs() < 1e-6, "{e}");
        // black pixels are not metered: half black, half 0.5 meters 0.5 with any window
        let mut half = vec![0.0f32; 12];
        half.extend([0.5f32; 12]);
        let all = AutoExposure {
            low: 0.0,
            high: 1.0,
            ..a
        };
        assert_eq!(metered_exposure(&half, 3, &all).1, centre(0.5));
        assert_eq!(metered_exposure(&[0.0; 6], 3, &a), (0.18, 1.0));
        // the whole range over 0.1 and 1.6 (four stops apart): their geometric mean; the
        // default window (the brighter half without its top 5 %) only the brighter
        let two = [0.1f32, 0.1, 0.1, 1.6, 1.6, 1.6];
        let (_, lbar) = metered_exposure(&two, 3, &all);
        assert!((lbar / (centre(0.1) * centre(1.6)).sqrt() - 1.0).abs() < 1e-5, "{lbar}");
        assert_eq!(metered_exposure(&two, 3, &a).1, centre(1.6));
        // NaN and negatives are black
        assert_eq!(bin_of([f32::NAN, 0.0, 0.0]), 0);
        assert_eq!(bin_of([-1.0, 0.0, 0.0]), 0);
        assert_eq!(bin_of([1e30; 3]), BINS - 1);
        for bad in [
            AutoExposure { key: 0.0, ..a },
            AutoExposure {
                low: 0.9,
                high: 0.5,
                ..a
            },
            AutoExposure { high: 1.5, ..a },
            AutoExposure { adaptation: 0.0, ..a },
        ] {
            assert!(bad.validate().is_err(), "{bad:?}");
        }
        assert!(a.validate().is_ok());
    }
}
