//! Bounced-z-buffer AO (`bzb-ao`, BZB §3 with AOV splats, or §4 with DSS surfels
//! for `splat = dss`) against the CPU ground truth of the same camera — ray-traced
//! binary AO within r, the quantity its estimator targets, and DGB's obscurance —
//! with, in the same result, the errors of the same splatting without visibility
//! (additive AOV, or additive shell splatting) and of 2-layer deep-G-buffer AO, so
//! one run says which is closest.

use anyhow::{bail, Result};
use strata_render::passes::ao::AoSettings;
use strata_render::passes::bzb::BzbSettings;
use strata_render::RenderSettings;

use super::ao::{av_setup, evaluate_av, render_settings, DEFAULT_CAP};
use super::{noise_warnings, EvalSettings};
use crate::results::AoEval;

/// `bzb` as configured (its radius and bias default to `ao`'s, then the scene's);
/// `ao` are the DGB AO settings of the 2-layer comparison.
pub fn run(s: &EvalSettings, bzb: &BzbSettings, ao: &AoSettings) -> Result<AoEval> {
    if s.report.is_some() {
        bail!("--report is not available for --technique bzb-ao yet: drop --report (the JSON has every error)");
    }
    if s.frames.is_some() {
        bail!("--frames is not available for --technique bzb-ao (it has no temporal filter): drop --frames");
    }
    let rule = s.check(DEFAULT_CAP, 16)?;
    let (scene, cams) = s.scene.load()?;
    let camera = cams.current;
    // one radius for BZB, DGB AO and both references
    let radius = bzb.radius.or(ao.radius).unwrap_or(scene.settings.ao_radius);
    let ao = AoSettings {
        radius: Some(radius),
        ..ao.clone()
    };
    let (_, beta, epsilon) = ao.resolve(&scene);
    let bzb = BzbSettings {
        radius: Some(radius),
        bias: bzb.bias.or(ao.bias),
        ..bzb.clone()
    };
    let bzb_settings = |visibility: bool| RenderSettings {
        shade: false,
        bzb: Some(BzbSettings {
            visibility,
            ..bzb.clone()
        }),
        // BZB reads layer 0 only
        ..s.render_settings(1)
    };
    let configurations = [bzb_settings(bzb.visibility), render_settings(s, 2, &ao)];
    let (ref_obscurance, ref_binary, gpu) =
        av_setup(s, &scene, &camera, &configurations, (radius, beta, epsilon), &rule)?;
    let refs = (&ref_obscurance, &ref_binary);
    let evaluate = |rs: RenderSettings, what: &str| evaluate_av(&gpu, &scene, s, rs, what, refs, |_| Ok(String::new()));
    let main = evaluate(bzb_settings(bzb.visibility), "bzb-ao")?;
    let no_visibility = evaluate(bzb_settings(false), "bzb-ao visibility=off")?;
    let dgb = evaluate(render_settings(s, 2, &ao), "ao k=2")?;
    let mut run = s.run_info(
        ref_binary.noise.spp,
        "binary AO within r (cosine-weighted hemisphere rays), and DGB Eq. 2 obscurance over all surfaces",
        gpu.describe(),
        None,
        noise_warnings(&[("bzb-ao vs binary AO", &main.binary)]),
    );
    run.layers = 1;
    Ok(AoEval {
        run,
        samples: bzb.directions,
        radius,
        bias: bzb.bias.unwrap_or(0.01 * radius),
        epsilon,
        errors: main,
        layers_1: None,
        by_layers: Vec::new(),
        directions: Some(bzb.directions),
        visibility: Some(bzb.visibility),
        no_visibility: Some(no_visibility),
        dgb_2_layers: Some(dgb),
    })
}
