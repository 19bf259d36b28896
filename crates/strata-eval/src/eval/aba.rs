//! A-buffer multilayer AO (`aba-ao`, ABA Algorithm 1) against the CPU ground truth
//! of the same camera — DGB's obscurance over every surface (the estimator both
//! `aba-ao` and `ao` use) and ray-traced binary AO — with, in the same result, the
//! single-layer variant of the same A-buffer AO (`multilayer=off`: the nearest
//! fragment of each tap pixel only) and 2-layer deep-G-buffer AO (`ao`, same
//! radius, bias and ε), so one run says what the extra layers buy.
//!
//! Opaque scenes only: with transparent surfaces the obscurance reference has no
//! opacity; there the oracle is `Reference::ao_with_opacity_image` (tests) and the
//! images of `docs/abuffer.md`.

use anyhow::{bail, Result};
use strata_render::passes::abuffer::ao::AbaAoSettings;
use strata_render::passes::abuffer::ABufferSettings;
use strata_render::passes::ao::AoSettings;
use strata_render::RenderSettings;

use super::ao::{av_setup, evaluate_av, render_settings, write_side_by_side_report, DEFAULT_CAP};
use super::{noise_warnings, EvalSettings};
use crate::results::{AoEval, EvalResult};

/// `abuffer` with its `ao` as configured (radius, bias, ε default to `ao`'s, then the
/// scene's); `ao` are the DGB AO settings of the 2-layer comparison.
pub fn run(s: &EvalSettings, abuffer: &ABufferSettings, ao: &AoSettings) -> Result<AoEval> {
    if s.frames.is_some() {
        bail!("--frames is not available for --technique aba-ao (it has no temporal filter): drop --frames");
    }
    let rule = s.check(DEFAULT_CAP, 16)?;
    let (scene, cams) = s.scene.load()?;
    if let Some(m) = scene.materials.iter().find(|m| !m.is_opaque()) {
        bail!(
            "scene '{}' has a transparent material ('{}'): eval --technique aba-ao compares opaque scenes only (the obscurance reference has no opacity)",
            scene.name,
            m.name
        );
    }
    let camera = cams.current;
    let own = abuffer.ao.clone().unwrap_or_default();
    // one radius, bias and ε for ABA AO, DGB AO and both references
    let radius = own.radius.or(ao.radius).unwrap_or(scene.settings.ao_radius);
    let ao = AoSettings {
        radius: Some(radius),
        bias: own.bias.or(ao.bias),
        epsilon: own.epsilon.or(ao.epsilon),
        ..ao.clone()
    };
    let (_, beta, epsilon) = ao.resolve(&scene);
    let aba = AbaAoSettings {
        radius: Some(radius),
        bias: Some(beta),
        epsilon: Some(epsilon),
        ..own
    };
    let aba_settings = |multilayer: bool| RenderSettings {
        shade: false,
        abuffer: Some(ABufferSettings {
            ao: Some(AbaAoSettings {
                multilayer,
                ..aba.clone()
            }),
            ..abuffer.clone()
        }),
        guard_band: s.guard_band.or_default(strata_render::renderer::AO_GUARD_BAND),
        ..s.render_settings(1)
    };
    let configurations = [aba_settings(aba.multilayer), render_settings(s, 2, &ao)];
    let (ref_obscurance, ref_binary, gpu) =
        av_setup(s, &scene, &camera, &configurations, (radius, beta, epsilon), &rule)?;
    let refs = (&ref_obscurance, &ref_binary);
    // dropped fragments, if any: the lists were too small for the scene
    let dropped = |r: &strata_render::Renderer| -> Result<String> {
        let Some(a) = r.abuffer() else {
            return Ok(String::new());
        };
        let overflow = a.read_lists(&gpu)?.overflow;
        Ok(if overflow > 0 {
            format!(" ({overflow} fragments dropped: {})", a.settings().overflow_hint())
        } else {
            String::new()
        })
    };
    let evaluate = |rs: RenderSettings, what: &str| evaluate_av(&gpu, &scene, s, rs, what, refs, dropped);
    let main = evaluate(aba_settings(aba.multilayer), "aba-ao")?;
    let single = evaluate(aba_settings(false), "aba-ao multilayer=off")?;
    let dgb = evaluate(render_settings(s, 2, &ao), "ao k=2")?;
    let mut run = s.run_info(
        ref_obscurance.noise.spp,
        "obscurance (DGB Eq. 2 over all surfaces, spiral radial density), and binary AO within r",
        gpu.describe(),
        None,
        noise_warnings(&[
            ("aba-ao vs obscurance", &main.errors.obscurance),
            ("aba-ao vs binary AO", &main.errors.binary),
        ]),
    );
    run.layers = 0;
    let out = AoEval {
        run,
        samples: aba.samples,
        radius,
        bias: beta,
        epsilon,
        errors: main.errors,
        layers_1: Some(single.errors),
        by_layers: Vec::new(),
        directions: None,
        visibility: None,
        no_visibility: None,
        dgb_2_layers: Some(dgb.errors),
        temporal_alpha: None,
        warmup_frames: None,
    };
    if let Some(dir) = &s.report {
        write_side_by_side_report(
            dir,
            s,
            "aba-ao",
            &EvalResult::AbaAo(out.clone()),
            (&ref_obscurance.image, &ref_binary.image),
            &[
                ("aba-ao", &main),
                ("aba-ao multilayer=off", &single),
                ("ao, 2 layers", &dgb),
            ],
        )?;
    }
    Ok(out)
}
