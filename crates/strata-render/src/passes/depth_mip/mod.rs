//! Camera-space depth MIP chain of every deep-G-buffer layer (SAO's rotated-grid
//! subsampling, DGB §3.4's per-tap MIP levels): target `zmip`, one channel per
//! layer (RG32F for k ≤ 2, as Table 1's `zpack`; RGBA32F for k = 3, 4).

use crate::frame::{Pass, PassInfo, TargetDesc, Targets};
use crate::gpu::GpuContext;
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
    level0: wgpu::RenderPipeline,
    downsample: wgpu::RenderPipeline,
    groups: Vec<wgpu::BindGroup>,
    inputs: Vec<&'static str>,
}

impl DepthMipPass {
    /// Builds the chain into `zmip` (created beforehand from [`DepthMipSettings::output`]).
    pub fn new(gpu: &GpuContext, targets: &Targets, layers: u32) -> Self {
        let device = &gpu.device;
        let zmip = targets.get("zmip");
        let entries = [0, 1].map(|b| crate::passes::texture_entry(b, wgpu::TextureViewDimension::D2, false));
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("depth-mip"),
            entries: &entries,
        });
        let pl = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("depth-mip"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let module = crate::shader::module(device, "depth-mip", include_str!("depth_mip.wgsl"));
        let target = [Some(wgpu::ColorTargetState::from(zmip.desc.format))];
        let constants = [("LAYERS", layers as f64)];
        let level0 = crate::passes::fullscreen_pipeline_with(
            device,
            "depth-mip level 0",
            &pl,
            &module,
            "fs_level0",
            &constants,
            &target,
        );
        let downsample = crate::passes::fullscreen_pipeline_with(
            device,
            "depth-mip downsample",
            &pl,
            &module,
            "fs_downsample",
            &constants,
            &target,
        );
        let z01 = &targets.get("zpack").view;
        let z23 = if layers > 2 { &targets.get("zpack23").view } else { z01 };
        let mut groups = vec![crate::passes::bind_group(
            device,
            "depth-mip level 0",
            &layout,
            &[
                wgpu::BindingResource::TextureView(z01),
                wgpu::BindingResource::TextureView(z23),
            ],
        )];
        for m in 1..zmip.desc.mips {
            let prev = &zmip.mip_views[m as usize - 1];
            groups.push(crate::passes::bind_group(
                device,
                "depth-mip downsample",
                &layout,
                &[
                    wgpu::BindingResource::TextureView(prev),
                    wgpu::BindingResource::TextureView(prev),
                ],
            ));
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
            crate::passes::fullscreen_pass(encoder, "depth-mip", pipeline, &[&zmip.mip_views[m]], &[group]);
        }
    }
}

/// CPU mirror of the downsampling: the level-(m−1) texel that level-m texel
/// (x, y) copies.
pub fn child_texel(x: u32, y: u32) -> (u32, u32) {
    (2 * x + ((y & 1) ^ 1), 2 * y + ((x & 1) ^ 1))
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
