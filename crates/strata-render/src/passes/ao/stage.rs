//! The AO stage of a frame (after the shared depth MIP chain): Eq. 1 →
//! temporal filter → bilateral (horizontal, vertical) into `ao`. With
//! `deinterleave = n×m`, Eq. 1 is `ao-deint-copy` → `ao-deint-split-z`,
//! `ao-deint-split-n` (ILS BS, naive method) → `ao-deint` (every sub-buffer in
//! its tile) → `ao-deint-gather` (ILS BG) into the same `ao-raw`.

use crate::frame::{Pass, PassInfo, TargetDesc, Targets};
use crate::gpu::GpuContext;
use crate::passes::ao::{AoPass, AoSettings};
use crate::passes::bilateral::BilateralPass;
use crate::passes::deep_gbuffer::DeepGBufferSettings;
use crate::passes::ils::InterleavePass;
use crate::passes::interleave::{Interleave, SplitMethod};
use crate::passes::temporal::TemporalPass;
use crate::scene_gpu::GpuScene;
use crate::RenderError;

/// The AO passes of a frame: Eq. 1 → temporal filter → bilateral
/// (horizontal, vertical) into `ao` (after the shared depth MIP chain).
pub(crate) struct AoStage {
    /// Deinterleaved: the copy of zmip level 0 and the two splits, before `ao`.
    pub(crate) deint_before: Vec<Box<dyn Pass>>,
    pub(crate) ao: AoPass,
    /// With [`AoSettings::scale`] > 1: `ao-raw-low`'s upsampling into `ao-raw`.
    pub(crate) upsample: Option<crate::passes::upsample::UpsamplePass>,
    /// Deinterleaved: the gather of `ao-raw-tiled` into `ao-raw`.
    pub(crate) deint_gather: Option<InterleavePass>,
    pub(crate) temporal: Option<TemporalPass>,
    pub(crate) blur_h: BilateralPass,
    pub(crate) blur_v: BilateralPass,
    /// `filter_obscurance`: AV = max(0, 1 − √S) of the filtered S into `ao`.
    pub(crate) resolve: Option<crate::passes::builder::FullscreenPass>,
}

impl AoStage {
    pub(crate) fn new(
        gpu: &GpuContext,
        scene: &GpuScene,
        targets: &mut Targets,
        deep: &DeepGBufferSettings,
        s: &AoSettings,
        radius: f32,
    ) -> Result<Self, RenderError> {
        use wgpu::TextureFormat as F;
        // the compute AO pass writes its output as a storage texture
        let compute = s.deinterleave.is_none() && s.kernel.compute_on(gpu);
        let usage = if compute {
            wgpu::TextureUsages::STORAGE_BINDING
        } else {
            wgpu::TextureUsages::empty()
        };
        targets.create_with_usage(gpu, crate::passes::ao::OUTPUT, [targets.width, targets.height], usage);
        let scale = s.scale;
        if scale > 1 {
            let size = crate::passes::upsample::low_size(targets.width, targets.height, scale);
            targets.create_with_usage(gpu, crate::passes::ao::OUTPUT_LOW, size, usage);
        }
        let (ao, deint_before, deint_gather) = match s.deinterleave {
            None => (
                AoPass::new(gpu, scene, targets, deep.layers, compute, scale),
                Vec::new(),
                None,
            ),
            Some([n, m]) => {
                let (ao, before, gather) = deinterleaved(gpu, scene, targets, deep.layers, n, m)?;
                (ao, before, Some(gather))
            }
        };
        let upsample = (scale > 1).then(|| {
            crate::passes::upsample::UpsamplePass::layer0(
                gpu,
                scene,
                targets,
                "ao-upsample",
                crate::passes::upsample::UpsampleUniforms {
                    // the AO pass's value where there is no surface: AV 1, or S 0
                    empty: (!s.filter_obscurance) as u32 as f32,
                    ..crate::passes::upsample::UpsampleUniforms::new(scale, &s.reconstruction(radius))
                },
                crate::passes::ao::OUTPUT_LOW.name,
                crate::passes::ao::OUTPUT.name,
            )
        });
        let mut filtered = crate::passes::ao::OUTPUT.name;
        // the filters write R16F (the temporal filter's count, the blurs' outputs): compute
        // where the adapter writes that format (`Kernel::compute_for`)
        let filters_compute = s.kernel.compute_for(gpu, &[F::R32Float, F::R16Float]);
        if s.temporal.is_some() {
            for (name, doc) in [
                ("ao-temporal", "AO after the temporal filter (DGB §3.3)"),
                ("ao-temporal-history", "last frame's ao-temporal"),
            ] {
                targets.create_storable(gpu, TargetDesc::new(name, F::R32Float, 1, doc), filters_compute);
            }
            for t in crate::passes::temporal::frames_targets(AO_FRAMES) {
                targets.create_storable(gpu, t, filters_compute);
            }
            filtered = "ao-temporal";
        }
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
                AO_FRAMES,
                deep.layers,
                filters_compute,
            )
        });
        let blurred = if s.filter_obscurance {
            targets.create_storable(
                gpu,
                TargetDesc::new(
                    "ao-obscurance",
                    F::R16Float,
                    1,
                    "filtered obscurance mean S (Eq. 1 before the square root; filter_obscurance)",
                ),
                filters_compute,
            );
            "ao-obscurance"
        } else {
            "ao"
        };
        // unlike the radiosity gather's, the blur keeps its step at any scale: stepping over
        // s×s blocks blurred AO's contact shadows (atrium ꟻLIP 0.0495 → 0.0602 at s = 2)
        let [blur_h, blur_v] = reconstruction(
            gpu,
            scene,
            targets,
            &s.reconstruction(radius),
            filtered,
            blurred,
            filters_compute,
        );
        let resolve = s.filter_obscurance.then(|| {
            crate::passes::builder::PassBuilder::new(gpu, targets, "ao-resolve")
                .shader("ao-resolve", include_str!("ao_resolve.wgsl"))
                .read("ao-obscurance")
                .write("ao")
                .build()
        });
        Ok(Self {
            deint_before,
            ao,
            upsample,
            deint_gather,
            temporal,
            blur_h,
            blur_v,
            resolve,
        })
    }

    /// This frame's AO uniforms, and the upsampling's seed from them.
    pub(crate) fn set_frame(&self, gpu: &GpuContext, u: crate::passes::ao::AoUniforms) {
        self.ao.set_frame(gpu, u);
        if let Some(up) = &self.upsample {
            up.set_frame(gpu, u.seed);
        }
    }

    pub(crate) fn passes(&self) -> Vec<&dyn Pass> {
        let mut v: Vec<&dyn Pass> = self.deint_before.iter().map(|p| p.as_ref()).collect();
        v.push(&self.ao);
        if let Some(u) = &self.upsample {
            v.push(u);
        }
        if let Some(g) = &self.deint_gather {
            v.push(g);
        }
        if let Some(t) = &self.temporal {
            v.push(t);
        }
        v.push(&self.blur_h);
        v.push(&self.blur_v);
        if let Some(r) = &self.resolve {
            v.push(r);
        }
        v
    }
}

/// The AO's bilateral reconstruction (horizontal, vertical) from `input` into
/// `output`, creating `ao-blur-h` and `ao` (every AO technique ends in `ao`).
pub(crate) fn reconstruction(
    gpu: &GpuContext,
    scene: &GpuScene,
    targets: &mut Targets,
    blur: &crate::passes::bilateral::BilateralSettings,
    input: &'static str,
    output: &'static str,
    compute: bool,
) -> [BilateralPass; 2] {
    use wgpu::TextureFormat as F;
    targets.create_storable(
        gpu,
        TargetDesc::new("ao-blur-h", F::R16Float, 1, "AO after the horizontal bilateral pass"),
        compute,
    );
    targets.create_storable(
        gpu,
        TargetDesc::new("ao", F::R16Float, 1, "ambient visibility AV (1 = unoccluded)"),
        compute,
    );
    let pass = |name, input, output, vertical| {
        BilateralPass::new(gpu, scene, targets, blur, name, input, output, vertical, compute, None)
    };
    [
        pass("ao-blur-h", input, "ao-blur-h", false),
        pass("ao-blur-v", "ao-blur-h", output, true),
    ]
}

/// Copies level 0 of `zmip` into a single-level texture (the split passes take
/// single-level textures).
struct CopyLevel0 {
    src: &'static str,
    dst: &'static str,
}

impl Pass for CopyLevel0 {
    fn info(&self) -> PassInfo {
        PassInfo {
            name: "ao-deint-copy",
            inputs: vec![self.src],
            outputs: vec![self.dst],
        }
    }

    fn encode(&self, _gpu: &GpuContext, _scene: &GpuScene, targets: &Targets, encoder: &mut wgpu::CommandEncoder) {
        let (src, dst) = (&targets.get(self.src).texture, &targets.get(self.dst).texture);
        encoder.copy_texture_to_texture(
            src.as_image_copy(),
            dst.as_image_copy(),
            wgpu::Extent3d {
                width: dst.width(),
                height: dst.height(),
                depth_or_array_layers: 1,
            },
        );
    }
}

/// `ao-deint`, the passes before it (copy, splits) and the gather.
type DeinterleavedPasses = (AoPass, Vec<Box<dyn Pass>>, InterleavePass);

/// The passes of the deinterleaved Eq. 1 (see the module docs): BS of zmip
/// level 0 and of npack with the one-pass method (the fastest on lavapipe,
/// `docs/ils-split.md`), the AO over the tiled buffer, BG into `ao-raw`.
fn deinterleaved(
    gpu: &GpuContext,
    scene: &GpuScene,
    targets: &mut Targets,
    layers: u32,
    n: u32,
    m: u32,
) -> Result<DeinterleavedPasses, RenderError> {
    use crate::passes::ao::{DEINT_N_SPLIT, DEINT_RAW_TILED, DEINT_Z, DEINT_Z_SPLIT, OUTPUT};
    let (w, h) = (targets.width, targets.height);
    let zformat = targets.get("zmip").desc.format;
    let method = SplitMethod::Naive;
    let split_z = Interleave::new(gpu, zformat, w, h, n, m, method)?;
    let split_n = Interleave::new(gpu, DEINT_N_SPLIT.format, w, h, n, m, method)?;
    let gather = Interleave::new(gpu, DEINT_RAW_TILED.format, w, h, n, m, method)?;
    let tiled = split_z.tiled_size();
    let geometry = *split_z.geometry();
    targets.create(
        gpu,
        TargetDesc {
            format: zformat,
            ..DEINT_Z
        },
    );
    targets.create_sized(
        gpu,
        TargetDesc {
            format: zformat,
            ..DEINT_Z_SPLIT
        },
        tiled,
    );
    targets.create_sized(gpu, DEINT_N_SPLIT, tiled);
    targets.create_sized(gpu, DEINT_RAW_TILED, tiled);
    let before: Vec<Box<dyn Pass>> = vec![
        Box::new(CopyLevel0 {
            src: "zmip",
            dst: DEINT_Z.name,
        }),
        Box::new(InterleavePass {
            name: "ao-deint-split-z",
            interleave: split_z,
            src: DEINT_Z.name,
            dst: DEINT_Z_SPLIT.name,
            split: true,
        }),
        Box::new(InterleavePass {
            name: "ao-deint-split-n",
            interleave: split_n,
            src: "npack",
            dst: DEINT_N_SPLIT.name,
            split: true,
        }),
    ];
    let ao = AoPass::new_deinterleaved(gpu, scene, targets, layers, &geometry);
    let gather = InterleavePass {
        name: "ao-deint-gather",
        interleave: gather,
        src: DEINT_RAW_TILED.name,
        dst: OUTPUT.name,
        split: false,
    };
    Ok((ao, before, gather))
}

/// The AO temporal filter's per-pixel count and its copy from last frame.
pub(crate) const AO_FRAMES: [&str; 2] = ["ao-temporal-frames", "ao-temporal-frames-history"];
