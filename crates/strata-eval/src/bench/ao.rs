//! `strata bench ao`: the deep-G-buffer AO passes (DGB Table 4, AO column).

use anyhow::Result;
use serde_json::json;
use strata_render::passes::ao::AoSettings;
use strata_render::RenderSettings;

use super::stage::{self, Stage, StageSettings};
use crate::results::StageBench;

/// The AO stage's passes, in frame order (declared by the technique registry).
pub use strata_render::technique::AO_PASSES;

pub fn run(stage: &StageSettings, ao: &AoSettings) -> Result<StageBench> {
    let extra = json!({"samples": ao.samples, "blur_taps": ao.blur.taps(),
        "temporal_alpha": ao.temporal.map_or(0.0, |t| t.alpha), "variant": stage.variant.to_string(),
        "deinterleave": ao.deinterleave.map_or("off".to_string(), |[n, m]| format!("{n}x{m}")),
        "filter_obscurance": ao.filter_obscurance});
    // the deinterleaved frame replaces `ao` by its split, `ao-deint` and gather passes; at
    // `ao-scale` > 1 the upsampling follows `ao`
    let passes: Vec<&str> = AO_PASSES
        .iter()
        .chain(strata_render::passes::ao::DEINTERLEAVED_PASSES)
        .chain(strata_render::technique::AO_OPTIONAL_PASSES)
        .copied()
        .collect();
    stage::run(Stage {
        stage,
        passes: &passes,
        settings: Box::new(move |layers| RenderSettings {
            shade: false,
            ao: Some(ao.clone()),
            ..stage.render_settings(layers)
        }),
        extra,
    })
}
