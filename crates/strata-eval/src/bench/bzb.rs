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
use crate::results::BzbBench;

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
            .find(|p| p.name == "bzb-splat")
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
    Ok(BzbBench {
        triangles: scene.triangle_count() as u64,
        directions: b.directions,
        splat_ratio: splat(&on) / splat(&off),
        total_ratio: on.total_median_ms / off.total_median_ms,
        memory_bytes: b.estimated_bytes(w, h, scene.triangle_count() as u64),
        visibility: on,
        no_visibility: off,
    })
}
