//! `strata bench bzb`: the bounced z-buffer's stages (BZB Table 1's columns that
//! strata's AOV path has: direction setup, splatting, reconstruction, blur) with
//! the bounced z-buffer on (depth test, blending off: the nearest occluder wins)
//! and off (the additive AOV baseline, McGuire 2010), the cost of the visibility
//! step as the ratio of the two splat passes (the bound: ≤ 1.5×), and the
//! memory of the bounced z-buffer (Table 3's column for it).

use anyhow::Result;
use strata_render::technique;

use super::stage::StageSettings;
use super::technique as technique_bench;
use crate::results::{BzbBench, DssBench, DssStages};

/// `set`: the `bzb-ao` technique's settings (`directions`, `ao-radius`, …) applied
/// last; `visibility` is the bench's own.
pub fn run(stage: &StageSettings, set: &[(String, f64)]) -> Result<BzbBench> {
    let t = technique::find("bzb-ao")?;
    let (scene, _) = stage.scene.load()?;
    let stage1 = StageSettings {
        layers: 1,
        ..stage.clone()
    };
    let with = |visibility: f64| {
        let mut s: Vec<(String, f64)> = set.iter().filter(|(n, _)| n != "visibility").cloned().collect();
        s.push(("visibility".into(), visibility));
        s
    };
    let on = technique_bench::run(&stage1, t, None, &with(1.0))?;
    let off = technique_bench::run(&stage1, t, None, &with(0.0))?;
    let splat = |b: &crate::results::StageBench| {
        b.passes
            .iter()
            .find(|p| p.name == "bzb-splat" || p.name == "dss-splat")
            .map_or(f64::NAN, |p| p.median_ms)
    };
    // the settings as the frame used them (for the memory)
    let mut rs = t.settings(&stage1.render_settings(1), None)?;
    for (name, value) in set {
        t.set(&mut rs, name, *value)
            .map_err(|e| anyhow::anyhow!("--set {name}={value}: {e}"))?;
    }
    let b = rs.bzb.clone().unwrap_or_default();
    let (w, h) = (stage.scene.width, stage.scene.height);
    let dss = if b.splat == strata_render::passes::bzb::Splat::Dss {
        Some(dss_tables(stage, &scene, &rs, &on, &off)?)
    } else {
        None
    };
    Ok(BzbBench {
        triangles: scene.triangle_count() as u64,
        directions: b.directions,
        splat_ratio: splat(&on) / splat(&off),
        total_ratio: on.total_median_ms / off.total_median_ms,
        memory_bytes: b.estimated_bytes(w, h, scene.triangle_count() as u64),
        visibility: on,
        no_visibility: off,
        dss,
    })
}

/// BZB Table 1's DSS stage groups from the per-pass medians.
fn dss_stages(b: &crate::results::StageBench) -> DssStages {
    let ms = |names: &[&str]| -> f64 {
        b.passes
            .iter()
            .filter(|p| names.contains(&p.name.as_str()))
            .map(|p| p.median_ms)
            .sum()
    };
    DssStages {
        surfelization_ms: ms(&["dss-tessellate", "dss-fine", "dss-filter"]),
        tessellate_ms: ms(&["dss-tessellate"]),
        fine_ms: ms(&["dss-fine"]),
        filter_ms: ms(&["dss-filter"]),
        shuffling_ms: ms(&["bzb-directions", "dss-shuffle"]),
        splatting_ms: ms(&["dss-splat"]),
        unshuffling_ms: ms(&["dss-unshuffle"]),
        reduction_ms: ms(&["dss-reduce", "bzb-reconstruct"]),
        blurring_ms: ms(&["bzb-blur-h", "bzb-blur-v"]),
        total_ms: b.total_median_ms,
    }
}

/// Tables 1–3 for `splat = dss`: the stage groups of both runs, the surfel
/// counts of one frame rendered with the bench's settings, and the memory.
fn dss_tables(
    stage: &StageSettings,
    scene: &strata_scene::Scene,
    rs: &strata_render::RenderSettings,
    on: &crate::results::StageBench,
    off: &crate::results::StageBench,
) -> Result<DssBench> {
    let gpu = strata_render::GpuContext::new(&strata_render::GpuOptions {
        adapter: stage.adapter.clone(),
    })?;
    let b = rs.bzb.clone().unwrap_or_default();
    let mut r = strata_render::Renderer::new(&gpu, scene, rs.clone())?;
    let cams = strata_render::frame::FrameCameras::along_path(scene, stage.scene.frame);
    r.render(&gpu, scene, &cams, stage.scene.frame)?;
    let counts = r
        .dss_counts(&gpu)
        .ok_or_else(|| anyhow::anyhow!("bench bzb: the frame has no DSS stage"))??;
    let (radius, t_min) = b.resolve(scene);
    let (w, h) = (stage.scene.width, stage.scene.height);
    let u = b.dss_uniforms(w, h, radius, t_min, scene.triangle_count() as u32);
    Ok(DssBench {
        stages: dss_stages(on),
        stages_no_visibility: dss_stages(off),
        counts,
        memory: strata_render::passes::bzb::dss::memory(&u),
        levels: b.dss.levels,
        surfel_px: b.dss.surfel_px,
        d_max: b.dss.d_max(radius),
    })
}
