//! `strata bench display`: what it costs to get a rendered frame onto a window. The
//! read-back path (`strata view` before 2026-11-30, and `STRATA_VIEW_READBACK=1` now) reads
//! the display target, encodes it to 8-bit sRGB on the CPU (`ImageBuf::to_rgba8`) and uploads
//! it; the GPU path encodes the same bytes in a compute pass
//! (`strata_render::display::DisplayEncoder`). Both are timed on the wall clock from an idle
//! GPU until the window's texture is ready.

use std::time::Instant;

use anyhow::Result;
use strata_render::display::DisplayEncoder;
use strata_render::technique::Technique;
use strata_render::RenderError;
use strata_render::{GpuContext, RenderSettings, Renderer};

use super::{bench_run, check_frames, timing_gpu};
use crate::results::DisplayBench;
use crate::scene::SceneSpec;
use crate::stats::median_min;

/// What to time.
#[derive(Clone)]
pub struct DisplaySettings {
    pub scene: SceneSpec,
    pub adapter: Option<String>,
    /// Frames to time (after one warm-up frame), 1..=10000.
    pub frames: u32,
    pub technique: &'static Technique,
}

fn wait(gpu: &GpuContext) {
    let _ = gpu.device.poll(wgpu::PollType::wait_indefinitely());
}

/// The read-back path: the target read back and decoded, the bytes the viewer showed,
/// uploaded to an 8-bit texture.
fn read_back(gpu: &GpuContext, r: &Renderer, target: &str, srgb: bool, tex: &wgpu::Texture) -> Result<(), RenderError> {
    let img = r.read_target(gpu, target)?;
    let mut bytes = img.to_rgba8(srgb);
    bytes.chunks_exact_mut(4).for_each(|p| p[3] = 255);
    gpu.queue.write_texture(
        tex.as_image_copy(),
        &bytes,
        wgpu::TexelCopyBufferLayout {
            offset: 0,
            bytes_per_row: Some(img.width * 4),
            rows_per_image: Some(img.height),
        },
        tex.size(),
    );
    gpu.queue.submit([]);
    wait(gpu);
    Ok(())
}

pub fn run(s: &DisplaySettings) -> Result<DisplayBench> {
    check_frames(s.frames)?;
    let (scene, _) = s.scene.load()?;
    let gpu = timing_gpu(&s.adapter)?;
    let base = RenderSettings {
        width: s.scene.width,
        height: s.scene.height,
        ..Default::default()
    };
    let settings = s.technique.settings(&base, None)?;
    let mut r = Renderer::new(&gpu, &scene, settings)?;
    let (target, srgb) = s.technique.display;
    let upload = gpu.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("bench display upload"),
        size: wgpu::Extent3d {
            width: s.scene.width,
            height: s.scene.height,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Rgba8Unorm,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    let mut enc = DisplayEncoder::new(&gpu);
    let (mut readback, mut encoded) = (Vec::new(), Vec::new());
    let f0 = s.scene.frame;
    // frame 0 is the warm-up (pipelines, first allocations), untimed
    for i in 0..=s.frames {
        let f = f0 + i as f32;
        r.render(&gpu, &scene, &s.scene.cameras_at(&scene, f), f)?;
        wait(&gpu);
        let t = Instant::now();
        read_back(&gpu, &r, target, srgb, &upload)?;
        let rb = t.elapsed().as_secs_f64() * 1e3;
        let region = r
            .display_region(target)
            .ok_or_else(|| anyhow::anyhow!("the frame has no target '{target}'"))?;
        let t = Instant::now();
        enc.encode(&gpu, &region, srgb, 1.0)?;
        wait(&gpu);
        let gp = t.elapsed().as_secs_f64() * 1e3;
        if i > 0 {
            readback.push(rb);
            encoded.push(gp);
        }
    }
    gpu.check_errors()?;
    let (readback_median_ms, readback_min_ms) = median_min(&mut readback);
    let (gpu_median_ms, gpu_min_ms) = median_min(&mut encoded);
    Ok(DisplayBench {
        run: bench_run(&s.scene, s.frames, &scene, &gpu),
        technique: s.technique.name.to_string(),
        target: target.to_string(),
        readback_median_ms,
        readback_min_ms,
        gpu_median_ms,
        gpu_min_ms,
        speedup: readback_median_ms / gpu_median_ms,
    })
}
