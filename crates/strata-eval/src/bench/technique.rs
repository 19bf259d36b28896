//! `strata bench technique`: the GPU time of any registered technique's passes
//! (`Technique::passes`) with k = 1 and k layers, through the shared [`stage`](super::stage)
//! driver, so a new technique is benchmarked by registering.

use anyhow::Result;
use serde_json::json;
use strata_render::technique::Technique;
use strata_render::RenderSettings;

use super::stage::{self, Stage, StageSettings};
use crate::results::StageBench;

/// `preset`: one of the technique's presets (`None`: its default); `set`: registered settings
/// applied last, each checked against its declared range. Light probes are not baked here.
pub fn run(
    stage: &StageSettings,
    technique: &'static Technique,
    preset: Option<&str>,
    set: &[(String, f64)],
) -> Result<StageBench> {
    let configure = move |layers: u32| -> Result<RenderSettings> {
        // (the messages name the command's flags, like the other drivers')
        let mut s = technique
            .settings(&stage.render_settings(layers), preset)
            .map_err(|e| anyhow::anyhow!("--preset: {e}"))?;
        for (name, value) in set {
            technique
                .set(&mut s, name, *value)
                .map_err(|e| anyhow::anyhow!("--set {name}={value}: {e}"))?;
        }
        s.validate()?;
        Ok(s)
    };
    // every error (preset, setting, range) before any GPU work
    let checked = configure(stage.layers)?;
    // ILS: the caller's VPLs, generated once (static scene)
    let (vpls, vpl_maps_kept, ils_passes) = match &checked.ils {
        Some(i) => {
            let scene = stage.scene.load()?.0;
            let v = crate::vpls::scene_vpls(&scene, stage.scene.frame, i.vpl_count);
            (Some(v), i.vpl_shadow_maps_cached(&scene), i.passes(&scene))
        }
        None => (None, false, Vec::new()),
    };
    // ILS: the frame's own ILS passes (with `shadows = vpl`: ils-vpl-shadows, ils-ssm)
    let passes: Vec<&str> = match &checked.ils {
        Some(_) => {
            let before = technique.passes.iter().copied().take_while(|p| !p.starts_with("ils-"));
            before.chain(ils_passes).chain(["tonemap"]).collect()
        }
        // BZB: the splatting algorithm's own passes (AOV or DSS)
        None => match (&checked.bzb, &checked.bzb_gi) {
            (Some(b), _) => b.pass_names(),
            // bzb-gi: the registry's (AOV) passes, DSS's and the temporal filter's; the
            // frame times those it has
            (None, Some(_)) => technique
                .passes
                .iter()
                .copied()
                .chain(strata_render::passes::bzb::gi::DSS_PASSES)
                .chain(strata_render::passes::bzb::gi::TEMPORAL_PASSES)
                .collect(),
            (None, None) => technique.passes.to_vec(),
        },
    };
    // passes its settings add; the frame times those it has, in frame order
    let passes: Vec<&str> = passes
        .into_iter()
        .chain(technique.optional_passes.iter().copied())
        .collect();
    let extra = json!({
        "technique": technique.name,
        "preset": preset.or(technique.presets.first().copied()),
        "variant": stage.variant.to_string(),
        "set": set.iter().map(|(n, v)| (n.clone(), json!(v))).collect::<serde_json::Map<_, _>>(),
        // the warm-up frame draws ILS's VPL shadow maps and the timed frames keep them
        "vpl_shadow_maps_cached": vpl_maps_kept,
    });
    stage::run(Stage {
        stage,
        passes: &passes,
        settings: Box::new(move |layers| {
            let mut s = configure(layers).expect("checked before the GPU work");
            if let (Some(i), Some(v)) = (&mut s.ils, &vpls) {
                i.vpls = v.clone();
            }
            s
        }),
        extra,
    })
}
