//! Exposure and ACES filmic tonemapping of `hdr` into the sRGB `ldr` target.

use crate::frame::{TargetDesc, Targets};
use crate::gpu::GpuContext;
use crate::passes::builder::{FullscreenPass, PassBuilder};
use crate::scene_gpu::GpuScene;

pub const OUTPUTS: &[TargetDesc] = &[TargetDesc::new(
    "ldr",
    wgpu::TextureFormat::Rgba8UnormSrgb,
    1,
    "tonemapped display image (sRGB)",
)];

pub struct TonemapPass {
    pass: FullscreenPass,
}

impl TonemapPass {
    /// Tonemaps target `input` (normally "hdr").
    pub fn new(gpu: &GpuContext, scene: &GpuScene, targets: &Targets, input: &'static str) -> Self {
        let pass = PassBuilder::new(gpu, targets, "tonemap")
            .shader("tonemap", include_str!("tonemap.wgsl"))
            .frame(scene)
            .read(input)
            .write(OUTPUTS[0].name)
            .build();
        Self { pass }
    }
}

crate::passes::builder::delegate_pass!(TonemapPass);
