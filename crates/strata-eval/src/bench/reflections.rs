//! `strata bench reflections`: the deep-G-buffer mirror-reflection ray march (DGB §3.6).

use anyhow::Result;
use serde_json::json;
use strata_render::passes::reflections::ReflectionSettings;
use strata_render::RenderSettings;

use super::stage::{self, Stage, StageSettings};
use crate::results::StageBench;

pub fn run(stage: &StageSettings, rs: &ReflectionSettings) -> Result<StageBench> {
    let extra = json!({"steps": rs.steps, "max_distance": rs.max_distance, "variant": stage.variant.to_string()});
    let rs = *rs;
    stage::run(Stage {
        stage,
        passes: &["reflections"],
        settings: Box::new(move |layers| RenderSettings {
            reflections: Some(rs),
            ..stage.render_settings(layers)
        }),
        extra,
    })
}
