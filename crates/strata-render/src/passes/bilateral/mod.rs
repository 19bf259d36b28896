//! Separable bilateral reconstruction with normal and plane weights (DGB §3.1,
//! [SGNS07]), reusable by every noisy screen-space estimate: a horizontal and a
//! vertical [`BilateralPass`].

use crate::frame::Targets;
use crate::gpu::GpuContext;
use crate::passes::builder::{FullscreenPass, PassBuilder};
use crate::scene_gpu::GpuScene;

/// Defaults: radius 4 taps with step 2 pixels (SAO's AO blur: 9 taps spanning
/// ±8 px per direction), Gaussian σ = 0.75·radius taps (SAO's radius-4 kernel has
/// σ ≈ 3), plane weight max(0, 1 − 100·d/z) (zero once the tap's surface is 1 % of
/// X's depth off X's tangent plane), normal weight (n_X·n_Y)^8.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BilateralSettings {
    /// Taps on each side (0 disables the filter).
    pub radius: u32,
    /// Pixels between taps.
    pub step: u32,
    pub plane_sharpness: f32,
    /// Exponent of the normal weight (n_X·n_Y)^p, 0..=32.
    pub normal_power: u32,
}

impl Default for BilateralSettings {
    fn default() -> Self {
        Self {
            radius: 4,
            step: 2,
            plane_sharpness: 100.0,
            normal_power: 8,
        }
    }
}

impl BilateralSettings {
    pub fn validate(&self) -> Result<(), String> {
        if self.radius > 32 {
            return Err(format!(
                "blur radius {} is out of range: must be in 0..=32",
                self.radius
            ));
        }
        if !(1..=8).contains(&self.step) {
            return Err(format!("blur step {} is out of range: must be in 1..=8", self.step));
        }
        if !(self.plane_sharpness >= 0.0 && self.plane_sharpness.is_finite()) {
            return Err(format!(
                "blur plane sharpness {} is out of range: must be >= 0",
                self.plane_sharpness
            ));
        }
        if self.normal_power > 32 {
            return Err(format!(
                "blur normal power {} is out of range: must be in 0..=32",
                self.normal_power
            ));
        }
        Ok(())
    }

    /// Total taps per direction (the paper's "reconstruction filter taps").
    pub fn taps(&self) -> u32 {
        2 * self.radius + 1
    }
}

/// Mirrors `Bilateral` in `bilateral.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct BilateralUniforms {
    radius: i32,
    step: i32,
    plane_sharpness: f32,
    normal_power: u32,
    /// Gaussian weight of tap |k| (k ≤ 32, index k).
    gauss: [f32; 36],
}

impl BilateralUniforms {
    pub fn new(s: &BilateralSettings) -> Self {
        let sigma = (0.75 * s.radius as f32).max(0.5);
        let gauss = std::array::from_fn(|k| (-((k * k) as f32) / (2.0 * sigma * sigma)).exp());
        Self {
            radius: s.radius as i32,
            step: s.step as i32,
            plane_sharpness: s.plane_sharpness,
            normal_power: s.normal_power,
            gauss,
        }
    }
}

/// One direction of the separable filter, from target `input` into `output`.
pub struct BilateralPass {
    pass: FullscreenPass,
}

impl BilateralPass {
    /// `vertical` picks the direction; `output` must already exist in `targets`.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        gpu: &GpuContext,
        scene: &GpuScene,
        targets: &Targets,
        settings: &BilateralSettings,
        name: &'static str,
        input: &'static str,
        output: &'static str,
        vertical: bool,
    ) -> Self {
        let pass = PassBuilder::new(gpu, targets, name)
            .shader("bilateral", include_str!("bilateral.wgsl"))
            .constant("DIRECTION", vertical as u32 as f64)
            .frame(scene)
            .uniforms(&BilateralUniforms::new(settings))
            .read(input)
            .read("zpack")
            .read("npack")
            .write(output)
            .build();
        Self { pass }
    }
}

crate::passes::builder::delegate_pass!(BilateralPass);
