//! `strata bench radiosity`: the deep-G-buffer radiosity passes (DGB Table 4, indirect columns)
//! for a Table 2 preset.

use anyhow::Result;
use serde_json::json;
use strata_render::passes::radiosity::RadiositySettings;
use strata_render::RenderSettings;

use super::stage::{self, Stage, StageSettings};
use crate::results::StageBench;

/// The radiosity stage's passes, in frame order (declared by the technique registry).
pub use strata_render::technique::RADIOSITY_PASSES;

/// `preset` is the Table 2 preset's name the settings came from (reported, not applied).
pub fn run(stage: &StageSettings, preset: &str, rs: &RadiositySettings) -> Result<StageBench> {
    let extra = json!({"preset": preset, "samples": rs.samples, "blur_taps": rs.blur.taps(),
        "normal_test": rs.normal_test, "min_mip": rs.min_mip, "variant": stage.variant.to_string()});
    stage::run(Stage {
        stage,
        passes: RADIOSITY_PASSES,
        settings: Box::new(move |layers| RenderSettings {
            radiosity: Some(rs.clone()),
            ..stage.render_settings(layers)
        }),
        extra,
    })
}
