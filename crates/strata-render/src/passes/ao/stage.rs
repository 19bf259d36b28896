//! The AO stage of a frame (after the shared depth MIP chain): Eq. 1 →
//! temporal filter → bilateral (horizontal, vertical) into `ao`.

use crate::frame::{Pass, TargetDesc, Targets};
use crate::gpu::GpuContext;
use crate::passes::ao::{AoPass, AoSettings};
use crate::passes::bilateral::BilateralPass;
use crate::passes::deep_gbuffer::DeepGBufferSettings;
use crate::passes::temporal::TemporalPass;
use crate::scene_gpu::GpuScene;

/// The AO passes of a frame: Eq. 1 → temporal filter → bilateral
/// (horizontal, vertical) into `ao` (after the shared depth MIP chain).
pub(crate) struct AoStage {
    pub(crate) ao: AoPass,
    pub(crate) temporal: Option<TemporalPass>,
    pub(crate) blur_h: BilateralPass,
    pub(crate) blur_v: BilateralPass,
}

impl AoStage {
    pub(crate) fn new(
        gpu: &GpuContext,
        scene: &GpuScene,
        targets: &mut Targets,
        deep: &DeepGBufferSettings,
        s: &AoSettings,
    ) -> Self {
        use wgpu::TextureFormat as F;
        targets.create(gpu, crate::passes::ao::OUTPUT);
        let mut filtered = crate::passes::ao::OUTPUT.name;
        if s.temporal.is_some() {
            for (name, doc) in [
                ("ao-temporal", "AO after the temporal filter (DGB §3.3)"),
                ("ao-temporal-history", "last frame's ao-temporal"),
            ] {
                targets.create(gpu, TargetDesc::new(name, F::R32Float, 1, doc));
            }
            filtered = "ao-temporal";
        }
        let ao = AoPass::new(gpu, scene, targets, deep.layers);
        let temporal = s.temporal.as_ref().map(|t| {
            TemporalPass::new(
                gpu,
                scene,
                targets,
                t,
                "ao-temporal",
                crate::passes::ao::OUTPUT.name,
                "ao-temporal-history",
                "ao-temporal",
                deep.layers,
            )
        });
        let [blur_h, blur_v] = reconstruction(gpu, scene, targets, &s.blur, filtered);
        Self {
            ao,
            temporal,
            blur_h,
            blur_v,
        }
    }

    pub(crate) fn passes(&self) -> Vec<&dyn Pass> {
        let mut v: Vec<&dyn Pass> = vec![&self.ao];
        if let Some(t) = &self.temporal {
            v.push(t);
        }
        v.push(&self.blur_h);
        v.push(&self.blur_v);
        v
    }
}

/// The AO's bilateral reconstruction (horizontal, vertical) from `input` into
/// `ao`, with its targets `ao-blur-h` and `ao` (every AO technique ends so).
pub(crate) fn reconstruction(
    gpu: &GpuContext,
    scene: &GpuScene,
    targets: &mut Targets,
    blur: &crate::passes::bilateral::BilateralSettings,
    input: &'static str,
) -> [BilateralPass; 2] {
    use wgpu::TextureFormat as F;
    targets.create(
        gpu,
        TargetDesc::new("ao-blur-h", F::R16Float, 1, "AO after the horizontal bilateral pass"),
    );
    targets.create(
        gpu,
        TargetDesc::new("ao", F::R16Float, 1, "ambient visibility AV (1 = unoccluded)"),
    );
    [
        BilateralPass::new(gpu, scene, targets, blur, "ao-blur-h", input, "ao-blur-h", false),
        BilateralPass::new(gpu, scene, targets, blur, "ao-blur-v", "ao-blur-h", "ao", true),
    ]
}
