//! Camera-space depth MIP chain of every deep-G-buffer layer (SAO's rotated-grid
//! subsampling, DGB §3.4's per-tap MIP levels): target `zmip`, one channel per
//! layer (RG32F for k ≤ 2, as Table 1's `zpack`; RGBA32F for k = 3, 4).

use crate::frame::{Pass, PassInfo, TargetDesc, Targets};
use crate::gpu::GpuContext;
use crate::passes::builder::{storage_texture_entry, ScreenPipeline};
use crate::scene_gpu::GpuScene;

/// Settings of the MIP chain.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DepthMipSettings {
    /// MIP levels including level 0. Default 5 (SAO's and the DGB demo's chain).
    pub levels: u32,
}

impl Default for DepthMipSettings {
    fn default() -> Self {
        Self { levels: 5 }
    }
}

/// Largest accepted level count.
pub const MAX_LEVELS: u32 = 12;

impl DepthMipSettings {
    pub fn validate(&self) -> Result<(), String> {
        if !(1..=MAX_LEVELS).contains(&self.levels) {
            return Err(format!(
                "MIP levels {} is out of range: must be in 1..={MAX_LEVELS}",
                self.levels
            ));
        }
        Ok(())
    }

    /// Levels actually built for a `w`×`h` image (no level smaller than 1×1).
    pub fn levels_for(&self, w: u32, h: u32) -> u32 {
        let max = 32 - w.min(h).max(1).leading_zeros();
        self.levels.min(max)
    }

    /// The `zmip` target for `layers` deep-G-buffer layers.
    pub fn output(&self, layers: u32, w: u32, h: u32) -> TargetDesc {
        let format = if layers > 2 {
            wgpu::TextureFormat::Rgba32Float
        } else {
            wgpu::TextureFormat::Rg32Float
        };
        TargetDesc::new(
            "zmip",
            format,
            1,
            "camera-space z MIP chain, channel j = layer j (0 = no surface)",
        )
        .with_mips(self.levels_for(w, h))
    }
}

pub struct DepthMipPass {
    level0: ScreenPipeline,
    downsample: ScreenPipeline,
    groups: Vec<wgpu::BindGroup>,
    inputs: Vec<&'static str>,
}

impl DepthMipPass {
    /// Whether the chain is built by compute passes on `gpu` for a consumer whose kernel
    /// is `kernel`, into `zmip` of `format` ([`DepthMipSettings::output`]).
    pub fn compute_on(gpu: &GpuContext, kernel: crate::passes::Kernel, format: wgpu::TextureFormat) -> bool {
        kernel.compute_for(gpu, &[format])
    }

    /// Builds the chain into `zmip` (created beforehand from [`DepthMipSettings::output`],
    /// with storage binding when `compute`: each level is then a compute pass).
    pub fn new(gpu: &GpuContext, targets: &Targets, layers: u32, compute: bool) -> Self {
        let device = &gpu.device;
        let zmip = targets.get("zmip");
        let mut entries: Vec<wgpu::BindGroupLayoutEntry> = [0, 1]
            .map(|b| crate::passes::texture_entry(b, wgpu::TextureViewDimension::D2, false))
            .to_vec();
        if compute {
            for e in &mut entries {
                e.visibility = wgpu::ShaderStages::COMPUTE;
            }
            entries.push(storage_texture_entry(2, zmip.desc.format));
        }
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("depth-mip"),
            entries: &entries,
        });
        let pl = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("depth-mip"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let module = crate::passes::builder::module_writing(
            device,
            "depth-mip",
            include_str!("depth_mip.wgsl"),
            &[zmip.desc.format],
        );
        let target = [Some(wgpu::ColorTargetState::from(zmip.desc.format))];
        let constants = [("LAYERS", layers as f64)];
        let pipeline = |label: &str, entry: &str| {
            if compute {
                ScreenPipeline::Compute(device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                    label: Some(label),
                    layout: Some(&pl),
                    module: &module,
                    entry_point: Some(&entry.replace("fs_", "cs_")),
                    compilation_options: wgpu::PipelineCompilationOptions {
                        constants: &constants,
                        ..Default::default()
                    },
                    cache: None,
                }))
            } else {
                ScreenPipeline::Fragment(crate::passes::fullscreen_pipeline_with(
                    device, label, &pl, &module, entry, &constants, &target,
                ))
            }
        };
        let level0 = pipeline("depth-mip level 0", "fs_level0");
        let downsample = pipeline("depth-mip downsample", "fs_downsample");
        let z01 = &targets.get("zpack").view;
        let z23 = if layers > 2 { &targets.get("zpack23").view } else { z01 };
        let group = |label: &str, a: &wgpu::TextureView, b: &wgpu::TextureView, m: usize| {
            let mut resources = vec![
                wgpu::BindingResource::TextureView(a),
                wgpu::BindingResource::TextureView(b),
            ];
            if compute {
                resources.push(wgpu::BindingResource::TextureView(&zmip.mip_views[m]));
            }
            crate::passes::bind_group(device, label, &layout, &resources)
        };
        let mut groups = vec![group("depth-mip level 0", z01, z23, 0)];
        for m in 1..zmip.desc.mips as usize {
            let prev = &zmip.mip_views[m - 1];
            groups.push(group("depth-mip downsample", prev, prev, m));
        }
        let mut inputs = vec!["zpack"];
        if layers > 2 {
            inputs.push("zpack23");
        }
        Self {
            level0,
            downsample,
            groups,
            inputs,
        }
    }
}

impl Pass for DepthMipPass {
    fn info(&self) -> PassInfo {
        PassInfo {
            name: "depth-mip",
            inputs: self.inputs.clone(),
            outputs: vec!["zmip"],
        }
    }

    fn encode(&self, _gpu: &GpuContext, _scene: &GpuScene, targets: &Targets, encoder: &mut wgpu::CommandEncoder) {
        let zmip = targets.get("zmip");
        for (m, group) in self.groups.iter().enumerate() {
            let pipeline = if m == 0 { &self.level0 } else { &self.downsample };
            let size = [(zmip.texture.width() >> m).max(1), (zmip.texture.height() >> m).max(1)];
            pipeline.record(encoder, "depth-mip", &[&zmip.mip_views[m]], &[group], size);
        }
    }
}

/// CPU mirror of the downsampling: the level-(m−1) texel that level-m texel
/// (x, y) copies.
pub fn child_texel(x: u32, y: u32) -> (u32, u32) {
    (2 * x + ((y & 1) ^ 1), 2 * y + ((x & 1) ^ 1))
}

/// The level-`m` texel that level-0 pixel (x, y) of a chain with level-0 size `w`×`h`
/// reads (`mip_texel` in common/spiral.wgsl): (x, y) >> m, clamped to the level's floor
/// size, whose last texel stands in for the pixels of a partial block.
pub fn mip_texel(x: u32, y: u32, m: u32, w: u32, h: u32) -> (u32, u32) {
    ((x >> m).min((w >> m).max(1) - 1), (y >> m).min((h >> m).max(1) - 1))
}

/// The level-0 pixel whose depth level-`m` texel (x, y) of a chain with level-0
/// size `w`×`h` holds (children clamped to each level's size, as the shader does).
pub fn source_pixel(x: u32, y: u32, m: u32, w: u32, h: u32) -> (u32, u32) {
    (1..=m).rev().fold((x, y), |(x, y), l| {
        let (cx, cy) = child_texel(x, y);
        let (lw, lh) = ((w >> (l - 1)).max(1), (h >> (l - 1)).max(1));
        (cx.min(lw - 1), cy.min(lh - 1))
    })
}

#[cfg(test)]
mod tests {
    use super::{mip_texel, source_pixel};

    /// Every pixel of a chain whose levels end in partial blocks reads a texel inside its
    /// level, and that texel's source pixel lies within one block of the pixel (the block
    /// of 2^m pixels, or the level's last, partial one); inside whole blocks it is q >> m.
    #[test]
    fn every_pixel_reads_a_texel_inside_its_level() {
        for (w, h) in [(203u32, 117u32), (96, 64), (1, 1), (640, 360)] {
            for m in 0..5 {
                let (lw, lh) = ((w >> m).max(1), (h >> m).max(1));
                for y in 0..h {
                    for x in 0..w {
                        let (tx, ty) = mip_texel(x, y, m, w, h);
                        assert!(tx < lw && ty < lh, "{w}x{h} level {m}: ({x},{y}) -> ({tx},{ty})");
                        if (x >> m) < lw && (y >> m) < lh {
                            assert_eq!((tx, ty), (x >> m, y >> m));
                        }
                        let (sx, sy) = source_pixel(tx, ty, m, w, h);
                        let reach = 2 << m;
                        assert!(
                            sx.abs_diff(x) < reach && sy.abs_diff(y) < reach,
                            "{w}x{h} level {m}: ({x},{y}) reads ({sx},{sy})"
                        );
                    }
                }
            }
        }
    }
}
