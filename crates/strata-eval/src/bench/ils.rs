//! `strata bench ils`: interleaved deferred shading (ILS Table 4): the GPU time
//! of the interleaved passes (BC packing, BS, SNSM, BG, DB, blur, compose) and of
//! the brute force of the same frame (every pixel, all N VPLs: "no IS"), with
//! the same VPLs, and the speed-up. The BS/BG times are those of the frame's
//! `ils-bs` / `ils-bg` passes (all BS or BG passes of the method together).

use anyhow::Result;
use serde_json::json;
use strata_render::passes::ils::BRUTE_FORCE_PASS;
use strata_render::technique;

use super::stage::{self, Stage, StageSettings};
use crate::results::IlsBench;

/// `preset`: one of the `ils` technique's presets (`None`: standard); `set`: its settings
/// (`vpls`, `interleave-n`, …), applied last and range-checked; the brute-force run is the
/// same with `brute-force = 1`.
pub fn run(stage: &StageSettings, preset: Option<&str>, set: &[(String, f64)]) -> Result<IlsBench> {
    let t = technique::find("ils")?;
    let (scene, _) = stage.scene.load()?;
    let configure = |brute: bool| -> Result<strata_render::RenderSettings> {
        let mut s = t
            .settings(&stage.render_settings(1), preset)
            .map_err(|e| anyhow::anyhow!("--preset: {e}"))?;
        for (name, value) in set {
            t.set(&mut s, name, *value)
                .map_err(|e| anyhow::anyhow!("--set {name}={value}: {e}"))?;
        }
        if brute {
            t.set(&mut s, "brute-force", 1.0)?;
        }
        s.validate()?;
        Ok(s)
    };
    let base = configure(false)?;
    let ils = base.ils.clone().expect("the ils technique turns ILS on");
    // one set of VPLs for both runs (static scene: generated once)
    let vpls = crate::vpls::scene_vpls(&scene, stage.scene.frame, ils.vpl_count);
    let with_vpls = move |mut s: strata_render::RenderSettings| {
        if let Some(i) = &mut s.ils {
            i.vpls = vpls.clone();
        }
        s
    };
    let stage1 = StageSettings {
        layers: 1,
        ..stage.clone()
    };
    let extra = json!({
        "preset": preset.unwrap_or(strata_render::passes::ils::PRESETS[0]),
        "vpls": ils.vpl_count,
        "pattern": format!("{}x{}", ils.pattern[0], ils.pattern[1]),
        "split": ils.method.name(),
        "blur": ils.blur,
        "bilinear": ils.bilinear,
        "shadows": ils.shadows.name(),
        // the warm-up frame draws the VPL shadow maps and the timed frames keep them
        "vpl_shadow_maps_cached": ils.vpl_shadow_maps_cached(&scene),
    });
    let brute = configure(true)?;
    // the frames' own pass lists (with `shadows = vpl`: ils-vpl-shadows, ils-ssm)
    let is_passes = ils.passes(&scene);
    // "no IS" (Table 4): the brute force's own passes (it is never blurred)
    let brute_passes = brute.ils.as_ref().expect("ILS is on").passes(&scene);
    let (w1, w2) = (with_vpls.clone(), with_vpls);
    let interleaved = stage::run(Stage {
        stage: &stage1,
        passes: &is_passes,
        settings: Box::new(move |_| w1(base.clone())),
        extra: extra.clone(),
    })?;
    let brute_force = stage::run(Stage {
        stage: &stage1,
        passes: &brute_passes,
        settings: Box::new(move |_| w2(brute.clone())),
        extra,
    })?;
    let time = |b: &crate::results::StageBench, n: &str| {
        b.passes.iter().find(|p| p.name == n).map_or(f64::NAN, |p| p.median_ms)
    };
    let shading = time(&interleaved, ils.shading_pass());
    let brute_shading = time(&brute_force, BRUTE_FORCE_PASS);
    Ok(IlsBench {
        vpls_generated: ils.vpl_count,
        speedup: brute_force.total_median_ms / interleaved.total_median_ms,
        shading_speedup: brute_shading / shading,
        interleaved,
        brute_force,
    })
}
