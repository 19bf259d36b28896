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

/// The CPU twin of `tonemap.wgsl` for one linear channel: `exposure · x` through the ACES
/// filmic fit of `color.wgsl`, clamped to [0, 1] (the sRGB encoding is the image writer's).
/// Debug views of radiance use it so they show what the final image shows.
pub fn tonemap(x: f32, exposure: f32) -> f32 {
    let x = x * exposure;
    ((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14)).clamp(0.0, 1.0)
}

pub struct TonemapPass {
    pass: FullscreenPass,
}

impl TonemapPass {
    /// Tonemaps target `input` (normally "hdr") with the frame's exposure, or with the
    /// exposure `metered` holds in its first f32 ([`crate::passes::exposure`]).
    pub fn new(
        gpu: &GpuContext,
        scene: &GpuScene,
        targets: &Targets,
        input: &'static str,
        metered: Option<&wgpu::Buffer>,
    ) -> Self {
        // without metering the binding holds a stand-in, unread
        let stand_in = metered.is_none().then(|| {
            gpu.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("tonemap exposure stand-in"),
                size: 8,
                usage: wgpu::BufferUsages::STORAGE,
                mapped_at_creation: false,
            })
        });
        let b = PassBuilder::new(gpu, targets, "tonemap")
            .shader("tonemap", include_str!("tonemap.wgsl"))
            .constant("AUTO_EXPOSURE", metered.is_some() as u32 as f64)
            .frame(scene)
            .read(input);
        let b = match metered {
            Some(m) => b.input("exposure").storage(m),
            None => b.storage(stand_in.as_ref().expect("no metering")),
        };
        let pass = b.write(OUTPUTS[0].name).build();
        Self { pass }
    }
}

crate::passes::builder::delegate_pass!(TonemapPass);
