//! `strata bench bzb`: the bounced z-buffer's stages (BZB Table 1's columns that
//! strata's AOV path has: direction setup, splatting, reconstruction, blur) with
//! the bounced z-buffer on (depth test, blending off: the nearest sender wins)
//! and off (the additive baseline: AOV, McGuire 2010, for AO; every triangle's form
//! factor times its mean radiance for GI), the cost of the visibility step as the ratio
//! of the two splat passes (the bound: ≤ 1.5×), and the memory of the bounced
//! z-buffer (Table 3's column for it). `bzb-ao` is Table 1's AO column (graveyard),
//! `bzb-gi` its indirect-light columns (still life, dominoes).

use anyhow::Result;
use strata_render::technique;

use super::stage::StageSettings;
use super::technique as technique_bench;
use crate::results::{BzbBench, DssBench, DssStages};

/// `technique`: `bzb-ao` or `bzb-gi`; `set`: its settings (`directions`, `ao-radius`,
/// `splat`, …) applied last; `visibility` is the bench's own.
pub fn run(stage: &StageSettings, technique: &str, set: &[(String, f64)]) -> Result<BzbBench> {
    if !matches!(technique, "bzb-ao" | "bzb-gi") {
        anyhow::bail!("bench bzb: technique '{technique}' is not a bounced z-buffer technique (bzb-ao, bzb-gi)");
    }
    let t = technique::find(technique)?;
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
            .find(|p| ["bzb-splat", "dss-splat", "dss-gi-splat"].contains(&p.name.as_str()))
            .map_or(f64::NAN, |p| p.median_ms)
    };
    // the settings as the frame used them (for the memory)
    let mut rs = t.settings(&stage1.render_settings(1), None)?;
    for (name, value) in set {
        t.set(&mut rs, name, *value)
            .map_err(|e| anyhow::anyhow!("--set {name}={value}: {e}"))?;
    }
    let (w, h) = (stage.scene.width, stage.scene.height);
    let tris = scene.triangle_count() as u64;
    let (directions, memory_bytes, dss) = match (&rs.bzb, &rs.bzb_gi) {
        (_, Some(g)) => {
            let dss = (g.splat == strata_render::passes::bzb::Splat::Dss)
                .then(|| {
                    let u = g.dss_uniforms(&scene, w, h, tris as u32);
                    dss_tables(stage, &scene, &rs, &on, &off, u, g.dss.levels, g.dss.surfel_px)
                })
                .transpose()?;
            (g.directions, g.estimated_bytes(&scene, w, h), dss)
        }
        (b, None) => {
            let b = b.clone().unwrap_or_default();
            let dss = (b.splat == strata_render::passes::bzb::Splat::Dss)
                .then(|| {
                    let (radius, t_min) = b.resolve(&scene);
                    let u = b.dss_uniforms(w, h, radius, t_min, tris as u32);
                    dss_tables(stage, &scene, &rs, &on, &off, u, b.dss.levels, b.dss.surfel_px)
                })
                .transpose()?;
            (b.directions, b.estimated_bytes(w, h, tris), dss)
        }
    };
    Ok(BzbBench {
        technique: technique.to_string(),
        triangles: tris,
        directions,
        splat_ratio: splat(&on) / splat(&off),
        total_ratio: on.total_median_ms / off.total_median_ms,
        memory_bytes,
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
        surfelization_ms: ms(&["dss-tessellate", "dss-fine", "dss-filter", "dss-gi-shade"]),
        tessellate_ms: ms(&["dss-tessellate"]),
        fine_ms: ms(&["dss-fine"]),
        filter_ms: ms(&["dss-filter"]),
        shade_ms: ms(&["dss-gi-shade"]),
        shuffling_ms: ms(&["bzb-directions", "dss-shuffle"]),
        splatting_ms: ms(&["dss-splat", "dss-gi-splat"]),
        unshuffling_ms: ms(&["dss-unshuffle"]),
        reduction_ms: ms(&["dss-reduce", "bzb-reconstruct"]),
        blurring_ms: ms(&[
            "bzb-blur-h",
            "bzb-blur-v",
            "bzb-gi-blur-h",
            "bzb-gi-blur-v",
            "bzb-gi-glossy-blur-h",
            "bzb-gi-glossy-blur-v",
        ]),
        total_ms: b.total_median_ms,
    }
}

/// Tables 1–3 for `splat = dss`: the stage groups of both runs, the surfel
/// counts of one frame rendered with the bench's settings, and the memory for the DSS
/// uniforms `u` (`levels` l_max, `surfel_px`).
#[allow(clippy::too_many_arguments)]
fn dss_tables(
    stage: &StageSettings,
    scene: &strata_scene::Scene,
    rs: &strata_render::RenderSettings,
    on: &crate::results::StageBench,
    off: &crate::results::StageBench,
    u: strata_render::passes::bzb::dss::DssUniforms,
    levels: u32,
    surfel_px: f32,
) -> Result<DssBench> {
    let gpu = strata_render::GpuContext::new(&strata_render::GpuOptions {
        adapter: stage.adapter.clone(),
    })?;
    let mut r = strata_render::Renderer::new(&gpu, scene, rs.clone())?;
    let cams = strata_render::frame::FrameCameras::along_path(scene, stage.scene.frame);
    r.render(&gpu, scene, &cams, stage.scene.frame)?;
    let counts = r
        .dss_counts(&gpu)
        .ok_or_else(|| anyhow::anyhow!("bench bzb: the frame has no DSS stage"))??;
    Ok(DssBench {
        stages: dss_stages(on),
        stages_no_visibility: dss_stages(off),
        counts,
        memory: strata_render::passes::bzb::dss::memory(&u),
        levels,
        surfel_px,
        d_max: u.d_max,
    })
}
