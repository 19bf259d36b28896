//! The radiosity stage of a frame: propagate (§3.3) → Eq. 4–5 gather →
//! temporal filter → bilateral → compose (with the light probes).

use crate::frame::{Pass, TargetDesc, Targets};
use crate::gpu::GpuContext;
use crate::passes::bilateral::BilateralPass;
use crate::passes::deep_gbuffer::DeepGBufferSettings;
use crate::passes::radiosity::{RadiosityPass, RadiositySettings};
use crate::passes::temporal::{TemporalPass, TemporalSettings};
use crate::scene_gpu::GpuScene;

/// The radiosity passes: Eq. 4–5 gather → temporal filter → bilateral into
/// `indirect` (layer 0's irradiance E, a = confidence).
pub(crate) struct RadiosityStage {
    pub(crate) propagate: Option<crate::passes::radiosity::PropagatePass>,
    pub(crate) gather: RadiosityPass,
    /// With [`RadiositySettings::gather_scale`] > 1: the low-resolution gather's upsampling.
    pub(crate) upsample: Option<crate::passes::upsample::UpsamplePass>,
    pub(crate) temporal: Option<TemporalPass>,
    pub(crate) blur_h: BilateralPass,
    pub(crate) blur_v: BilateralPass,
    /// `None` where the frame's composite is someone else's (`embed::EmbeddedRadiosity`).
    pub(crate) compose: Option<crate::passes::compose::ComposePass>,
    /// The light probes on the GPU and compose's blend mode (1 DGB's, 2 probes + detail,
    /// 3 one-sided), for the reflections' second-layer hits.
    pub(crate) probes: Option<(crate::passes::compose::ProbeGpu, u32)>,
}

impl RadiosityStage {
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn new(
        gpu: &GpuContext,
        scene: &GpuScene,
        targets: &mut Targets,
        deep: &DeepGBufferSettings,
        s: &RadiositySettings,
        guard: u32,
        probes: Option<&strata_scene::probes::IrradianceProbes>,
        ao_radius: f32,
        compose: bool,
    ) -> Self {
        use wgpu::TextureFormat as F;
        // the compute gather and blurs write their outputs as storage textures
        let compute = s.kernel.compute_on(gpu);
        let usage = if compute {
            wgpu::TextureUsages::STORAGE_BINDING
        } else {
            wgpu::TextureUsages::empty()
        };
        for t in crate::passes::radiosity::OUTPUTS {
            targets.create_with_usage(gpu, t, [targets.width, targets.height], usage);
        }
        let scale = s.gather_scale;
        if scale > 1 {
            let size = crate::passes::upsample::low_size(targets.width, targets.height, scale);
            for t in crate::passes::radiosity::LOW_OUTPUTS {
                targets.create_with_usage(gpu, t, size, usage);
            }
        }
        let mut filtered = "indirect-raw";
        // the temporal filter's count is R16F: compute where the adapter writes it
        let temporal_compute = s.kernel.compute_for(gpu, &[F::Rgba16Float, F::R16Float]);
        if s.temporal.is_some() {
            for (name, doc) in [
                ("indirect-temporal", "indirect E after the temporal filter (DGB §3.3)"),
                ("indirect-temporal-history", "last frame's indirect-temporal"),
            ] {
                targets.create_storable(gpu, TargetDesc::new(name, F::Rgba16Float, 1, doc), temporal_compute);
            }
            for t in crate::passes::temporal::frames_targets(INDIRECT_FRAMES) {
                targets.create_storable(gpu, t, temporal_compute);
            }
            filtered = "indirect-temporal";
        }
        for (name, doc) in [
            ("indirect-blur-h", "indirect E after the horizontal bilateral pass"),
            ("indirect", "indirect irradiance E of layer 0 (rgb), confidence (a)"),
        ] {
            let size = [targets.width, targets.height];
            targets.create_with_usage(gpu, TargetDesc::new(name, F::Rgba16Float, 1, doc), size, usage);
        }
        let propagate = (s.delta > 0.0).then(|| {
            let bounce = crate::passes::radiosity::BOUNCE_OUTPUTS;
            let compute = s.kernel.compute_for(gpu, &bounce.map(|t| t.format));
            for t in bounce {
                targets.create_storable(gpu, t, compute);
            }
            for (name, doc) in [
                ("indirect-history", "last frame's final indirect E of layer 0"),
                ("indirect1-history", "last frame's indirect E of layer 1"),
            ] {
                targets.create(gpu, TargetDesc::new(name, F::Rgba16Float, 1, doc));
            }
            // the indirect filter's reprojection rule (its default when the filter is off)
            let t = s.temporal.unwrap_or_default();
            crate::passes::radiosity::PropagatePass::new(gpu, scene, targets, deep.layers, s, &t, compute)
        });
        let b = if propagate.is_some() {
            ["bounce0", "bounce1"]
        } else {
            ["radiosity0", "radiosity1"]
        };
        let region = crate::passes::radiosity::shaded_region(targets.width, targets.height, guard, s.guard_band_shaded);
        // without the visibility test the probes blend as if they had no distance maps
        let blind;
        let probes = match probes {
            Some(p) if !s.probe_visibility && !p.depth.is_empty() => {
                blind = strata_scene::probes::IrradianceProbes {
                    depth: Vec::new(),
                    ..p.clone()
                };
                Some(&blind)
            }
            other => other,
        };
        let open_radius = (s.probe_ao == crate::passes::radiosity::ProbeAo::Relative).then_some(ao_radius);
        let probe_gpu = probes.map(|p| crate::passes::compose::ProbeGpu::new(gpu, Some(p), open_radius));
        let detail = s.probe_detail && probe_gpu.is_some();
        let gather = RadiosityPass::new(
            gpu,
            scene,
            targets,
            deep.layers,
            b,
            region,
            propagate.is_some(),
            // the compose pass's buffers (the detail term reads them; otherwise unread)
            probe_gpu.as_ref(),
            compute,
            scale,
        );
        let upsample = (scale > 1).then(|| {
            crate::passes::upsample::UpsamplePass::new(
                gpu,
                scene,
                targets,
                "radiosity-upsample",
                deep.layers,
                crate::passes::upsample::UpsampleUniforms::new(scale, &s.blur),
                crate::passes::radiosity::LOW_OUTPUTS.map(|t| t.name),
                crate::passes::radiosity::OUTPUTS.map(|t| t.name),
                region,
                compute,
            )
        });
        // the reduced gather's noise is correlated over s×s blocks: the blur's taps step
        // over blocks, s pixels apart, so that as many independent samples are averaged
        let blur = crate::passes::bilateral::BilateralSettings {
            step: s.blur.step * scale,
            ..s.blur
        };
        let temporal = s.temporal.as_ref().map(|t: &TemporalSettings| {
            TemporalPass::new(
                gpu,
                scene,
                targets,
                t,
                "indirect-temporal",
                "indirect-raw",
                "indirect-temporal-history",
                "indirect-temporal",
                INDIRECT_FRAMES,
                deep.layers,
                temporal_compute,
            )
        });
        let blur_h = BilateralPass::new(
            gpu,
            scene,
            targets,
            &blur,
            "indirect-blur-h",
            filtered,
            "indirect-blur-h",
            false,
            compute,
            None,
        );
        let blur_v = BilateralPass::new(
            gpu,
            scene,
            targets,
            &blur,
            "indirect-blur-v",
            "indirect-blur-h",
            "indirect",
            true,
            compute,
            None,
        );
        let compose = compose.then(|| {
            for t in crate::passes::compose::OUTPUTS {
                targets.create_with_usage(gpu, t, [targets.width, targets.height], usage);
            }
            crate::passes::compose::ComposePass::new(
                gpu,
                scene,
                targets,
                s.boost,
                probe_gpu.as_ref().map(|p| crate::passes::compose::ComposeProbes {
                    probes: p,
                    ao: s.probe_ao,
                    detail,
                    one_sided: s.one_sided_confidence,
                }),
                "indirect",
                None,
                compute,
            )
        });
        let mode = match (detail, s.one_sided_confidence) {
            (true, _) => 2,
            (false, true) => 3,
            (false, false) => 1,
        };
        Self {
            propagate,
            gather,
            upsample,
            temporal,
            blur_h,
            blur_v,
            compose,
            probes: probe_gpu.map(|p| (p, mode)),
        }
    }

    /// This frame's gather uniforms, and the upsampling's seed from them.
    pub(crate) fn set_frame(&self, gpu: &GpuContext, u: crate::passes::radiosity::RadiosityUniforms) {
        self.gather.set_frame(gpu, u);
        if let Some(up) = &self.upsample {
            up.set_frame(gpu, u.seed);
        }
    }

    pub(crate) fn passes(&self) -> Vec<&dyn Pass> {
        let mut v: Vec<&dyn Pass> = Vec::new();
        if let Some(p) = &self.propagate {
            v.push(p);
        }
        v.push(&self.gather);
        if let Some(u) = &self.upsample {
            v.push(u);
        }
        if let Some(t) = &self.temporal {
            v.push(t);
        }
        v.push(&self.blur_h);
        v.push(&self.blur_v);
        if let Some(c) = &self.compose {
            v.push(c);
        }
        v
    }
}

/// The indirect temporal filter's per-pixel count and its copy from last frame.
pub(crate) const INDIRECT_FRAMES: [&str; 2] = ["indirect-temporal-frames", "indirect-temporal-frames-history"];
