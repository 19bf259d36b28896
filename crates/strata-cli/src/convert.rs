//! Command-line arguments → the settings structs of `strata-eval`.

use strata_eval::bench::deep::DeepSettings;
use strata_eval::bench::gbuffer::GbufferSettings;
use strata_eval::bench::stage::StageSettings;
use strata_eval::cache::RefCache;
use strata_eval::eval::EvalSettings;
use strata_eval::scene::SceneSpec;

use crate::args::{BenchDeepArgs, BenchDisplayArgs, BenchGbufferArgs, BenchStageArgs, EvalArgs, SceneArgs};

impl From<&SceneArgs> for SceneSpec {
    fn from(a: &SceneArgs) -> Self {
        SceneSpec {
            scene: a.scene.clone(),
            frame: a.frame,
            width: a.width,
            height: a.height,
            eye: a.eye,
            target: a.target,
            up: a.up,
            fov: a.fov,
            camera: a.camera,
        }
    }
}

impl From<&EvalArgs> for EvalSettings {
    fn from(a: &EvalArgs) -> Self {
        // the direct light's `--set` names (area-shadows, shadow-resolution); a name
        // this technique does not have is reported by the comparison that reads the
        // rest of `--set`
        let mut direct = strata_render::RenderSettings::default();
        for (name, value) in &a.set.values {
            let _ = a.technique.set(&mut direct, name, *value);
        }
        EvalSettings {
            scene: (&a.scene).into(),
            adapter: a.gpu.adapter.clone(),
            deep: a.deep.settings(),
            guard_band: a.deep.guard_band,
            ref_spp: a.ref_spp,
            ref_noise: a.ref_noise,
            warmup: a.warmup,
            moving: a.moving,
            cache: a.cache.clone().unwrap_or_else(RefCache::default_dir),
            no_cache: a.no_cache,
            frames: a.frames,
            report: a.report.clone(),
            force: a.force,
            progress: !a.quiet,
            lighting: direct.lighting,
            shadow: direct.shadow,
            exposure: direct.exposure,
        }
    }
}

impl From<&BenchStageArgs> for StageSettings {
    fn from(a: &BenchStageArgs) -> Self {
        StageSettings {
            scene: (&a.scene).into(),
            adapter: a.gpu.adapter.clone(),
            frames: a.frames,
            layers: a.layers,
            variant: a.variant,
        }
    }
}

impl From<&BenchDisplayArgs> for strata_eval::bench::display::DisplaySettings {
    fn from(a: &BenchDisplayArgs) -> Self {
        strata_eval::bench::display::DisplaySettings {
            scene: (&a.scene).into(),
            adapter: a.gpu.adapter.clone(),
            frames: a.frames,
            technique: a.technique,
        }
    }
}

impl From<&BenchGbufferArgs> for GbufferSettings {
    fn from(a: &BenchGbufferArgs) -> Self {
        GbufferSettings {
            scene: (&a.scene).into(),
            adapter: a.gpu.adapter.clone(),
            frames: a.frames,
        }
    }
}

impl From<&BenchDeepArgs> for DeepSettings {
    fn from(a: &BenchDeepArgs) -> Self {
        DeepSettings {
            scene: (&a.scene).into(),
            adapter: a.gpu.adapter.clone(),
            frames: a.frames,
            layers: a.layers,
            min_separation: a.min_separation,
            layer_scale: a.layer_scale,
            images: a.images.clone(),
            force: a.force,
        }
    }
}
