//! Bounced-z-buffer AO (`bzb-ao`, BZB §3 with AOV splats, or §4 with DSS surfels
//! for `splat = dss`) against the CPU ground truth of the same camera — ray-traced
//! binary AO within r, the quantity its estimator targets, and DGB's obscurance —
//! with, in the same result, the errors of the same splatting without visibility
//! (additive AOV, or additive shell splatting) and of 2-layer deep-G-buffer AO, so
//! one run says which is closest.

use anyhow::Result;
use strata_render::passes::ao::AoSettings;
use strata_render::passes::bzb::BzbSettings;
use strata_render::RenderSettings;

use super::ao::{av_setup, evaluate_av, render_settings, write_side_by_side_report, DEFAULT_CAP};
use super::{noise_warnings, EvalSettings, GiImages};
use crate::results::{AoEval, EvalResult};

/// `bzb` as configured (its radius and bias default to `ao`'s, then the scene's);
/// `ao` are the DGB AO settings of the 2-layer comparison.
pub fn run(s: &EvalSettings, bzb: &BzbSettings, ao: &AoSettings) -> Result<AoEval> {
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
    // the AV's flicker along the camera path (`--frames`)
    let flicker = flicker_along_path(&gpu, &scene, s, bzb_settings(bzb.visibility), "ao", bzb.temporal)?;
    let mut run = s.run_info(
        ref_binary.noise.spp,
        "binary AO within r (cosine-weighted hemisphere rays), and DGB Eq. 2 obscurance over all surfaces",
        gpu.describe(),
        flicker,
        noise_warnings(&[("bzb-ao vs binary AO", &main.errors.binary)]),
    );
    run.layers = 1;
    let out = AoEval {
        run,
        samples: bzb.directions,
        radius,
        bias: bzb.bias.unwrap_or(0.01 * radius),
        epsilon,
        errors: main.errors,
        layers_1: None,
        by_layers: Vec::new(),
        directions: Some(bzb.directions),
        visibility: Some(bzb.visibility),
        no_visibility: Some(no_visibility.errors),
        dgb_2_layers: Some(dgb.errors),
        temporal_alpha: bzb.temporal.as_ref().map(|t| t.alpha),
        warmup_frames: bzb.temporal.is_some().then_some(s.warmup),
    };
    if let Some(dir) = &s.report {
        write_side_by_side_report(
            dir,
            s,
            "bzb-ao",
            &EvalResult::Bzb(out.clone()),
            (&ref_obscurance.image, &ref_binary.image),
            &[
                ("bzb-ao", &main),
                ("bzb-ao visibility=off (additive)", &no_visibility),
                ("ao, 2 layers", &dgb),
            ],
        )?;
    }
    Ok(out)
}

/// `strata eval --technique bzb-gi`: the bounced-z-buffer GI (one bounce) against the
/// path tracer with one indirect bounce (the cached reference of `eval gi --bounces 1`
/// and `eval ils`), and in the same result the additive baseline (`visibility = off`)
/// and DGB radiosity with 2 layers (single bounce, δ = 0) for the same camera.
/// `set`: the technique's settings (`--set directions=8` …); `radiosity`: DGB's.
pub fn run_gi(
    s: &EvalSettings,
    set: &[(String, f64)],
    radiosity: &strata_render::passes::radiosity::RadiositySettings,
) -> Result<crate::results::BzbGiEval> {
    use strata_render::frame::FrameCameras;
    use strata_render::passes::lighting::LightingSettings;
    use strata_render::{GpuContext, GpuOptions, Renderer};
    use strata_scene::ImageBuf;

    use super::gi::{indirect, rgb, total};
    use super::RefImage;

    use crate::metrics::{compare_radiance, display};
    use crate::results::GiErrors;

    let rule = s.check(super::gi::DEFAULT_CAP, 8)?;
    let t = strata_render::technique::find("bzb-gi")?;
    let base = RenderSettings {
        // as eval gi / ils: the GPU's direct specular lobe is not the reference's model
        lighting: LightingSettings {
            specular: false,
            ..Default::default()
        },
        ..s.render_settings(1)
    };
    let mut main = t.settings(&base, None)?;
    for (name, value) in set {
        t.set(&mut main, name, *value)
            .map_err(|e| anyhow::anyhow!("--set {name}={value}: {e}"))?;
    }
    main.validate()?;
    let gi = main.bzb_gi.clone().expect("bzb-gi turns its stage on");
    let mut baseline = main.clone();
    if let Some(g) = &mut baseline.bzb_gi {
        g.visibility = !gi.visibility;
    }
    let dgb = super::gi::render_settings(
        s,
        2,
        &strata_render::passes::radiosity::RadiositySettings {
            delta: 0.0,
            ..radiosity.clone()
        },
    );

    let (mut scene, cams) = s.scene.load()?;
    // as eval gi / ils: no ambient term, no sky light (neither method gathers it)
    scene.settings.ambient = [0.0; 3];
    scene.settings.sky = [0.0; 3];
    let (_w, _h) = (s.scene.width, s.scene.height);
    let camera = cams.current;
    let exposure = s.display_exposure(&scene);
    let shown = |img: &ImageBuf| display(img, exposure);
    let converged = super::gi::converged_gi(s, &scene, camera, 1, &rule);
    let ref_total = RefImage::of(&converged, total, shown)?;
    let ref_indirect = RefImage::of(&converged, indirect, shown)?;

    let gpu = GpuContext::new(&GpuOptions {
        adapter: s.adapter.clone(),
    })?;
    let fixed = FrameCameras::fixed(camera);
    // (errors, splat ms, frame ms, images) of one configuration after `renders` frames
    let evaluate = |rs: RenderSettings, renders: u32| -> Result<(GiErrors, f64, f64, GiImages)> {
        let mut r = Renderer::new(&gpu, &scene, rs)?;
        let mut timings = Default::default();
        if s.moving {
            // the warm-up follows the camera path up to the evaluated frame (--moving)
            timings = super::render_along_path(&mut r, &gpu, &scene, s, s.scene.frame)?;
        } else {
            for _ in 0..renders {
                timings = r.render(&gpu, &scene, &fixed, s.scene.frame)?;
            }
        }
        let full = rgb(&r.read_target(&gpu, "hdr-full")?);
        let direct = rgb(&r.read_target(&gpu, "hdr")?);
        let mut ind = full.clone();
        for (o, d) in ind.data.iter_mut().zip(&direct.data) {
            *o = (*o - d).max(0.0);
        }
        gpu.check_errors()?;
        let (f, full_map) = compare_radiance(&ref_total.image, &full, exposure)?;
        let (i, indirect_map) = compare_radiance(&ref_indirect.image, &ind, exposure)?;
        let errors = GiErrors {
            full: ref_total.annotate(f, &display(&full, exposure)),
            indirect: ref_indirect.annotate(i, &display(&ind, exposure)),
        };
        // AOV-style triangle splats: bzb-splat; DSS surfels: dss-splat
        let splat = timings.get("bzb-splat").or_else(|| timings.get("dss-splat"));
        let images = GiImages {
            full,
            indirect: ind,
            full_map,
            indirect_map,
        };
        Ok((errors, splat.unwrap_or(f64::NAN), timings.total(), images))
    };
    // a frame stands alone, unless the temporal filter (`--set alpha`) accumulates new
    // directions on the still camera, or the warm-up follows the path (--moving): then
    // --warmup frames before the evaluated one, as the DGB configuration has
    let renders = if gi.temporal.is_some() || s.moving {
        s.warmup.max(1) + 1
    } else {
        1
    };
    let (errors, splat_ms, frame_ms, images) = evaluate(main.clone(), renders)?;
    let (no_visibility, splat_ms_no_visibility, _, images_no_visibility) = evaluate(baseline, renders)?;
    let (dgb_2_layers, _, _, images_dgb) = evaluate(dgb, s.warmup.max(1) + 1)?;
    let (errors, no_visibility, images, images_no_visibility) = if gi.visibility {
        (errors, no_visibility, images, images_no_visibility)
    } else {
        (no_visibility, errors, images_no_visibility, images)
    };
    let (splat_ms, splat_ms_no_visibility) = if gi.visibility {
        (splat_ms, splat_ms_no_visibility)
    } else {
        (splat_ms_no_visibility, splat_ms)
    };
    let (d_max, t_min) = gi.resolve(&scene);
    // the flicker of the indirect irradiance's red channel (as `eval gi`), `--frames`
    let flicker = flicker_along_path(&gpu, &scene, s, main.clone(), "indirect", gi.temporal)?;
    let mut run = s.run_info(
        converged.spp(),
        "path-traced GI (GGX for glossy materials) with 1 indirect bounce, sky and ambient off; \
         errors of the indirect light (composed − direct) at top level, the full image in `full`",
        gpu.describe(),
        flicker,
        noise_warnings(&[("bzb-gi indirect", &errors.indirect), ("bzb-gi full", &errors.full)]),
    );
    run.layers = 1;
    let out = crate::results::BzbGiEval {
        run,
        directions: gi.directions,
        visibility: true,
        d_max,
        t_min,
        errors,
        no_visibility,
        dgb_2_layers,
        splat_ms,
        splat_ms_no_visibility,
        frame_ms,
        temporal_alpha: gi.temporal.as_ref().map(|t| t.alpha),
        warmup_frames: Some(renders - 1),
    };
    if let Some(dir) = &s.report {
        write_gi_report(
            dir,
            s,
            &out,
            (&ref_indirect.image, &ref_total.image),
            exposure,
            &[
                ("bzb-gi", &out.errors, &images),
                (
                    "bzb-gi visibility=off (additive)",
                    &out.no_visibility,
                    &images_no_visibility,
                ),
                ("DGB radiosity, 2 layers, one bounce", &out.dgb_2_layers, &images_dgb),
            ],
        )?;
    }
    Ok(out)
}

/// `--report` of `eval --technique bzb-gi`: the result's tables, then
/// [`super::gi_report_sections`] for the path tracer and each configuration (`rows`).
fn write_gi_report(
    dir: &std::path::Path,
    s: &EvalSettings,
    out: &crate::results::BzbGiEval,
    references: (&strata_scene::ImageBuf, &strata_scene::ImageBuf),
    exposure: f32,
    rows: &[(&str, &crate::results::GiErrors, &GiImages)],
) -> Result<()> {
    use super::write_report;
    let sections = super::gi_report_sections(
        dir,
        s,
        out.run.ref_spp,
        &format!("{} directions per pixel, d_max {:.3}.", out.directions, out.d_max),
        references,
        exposure,
        rows,
    )?;
    write_report(
        dir,
        format!("strata eval: bzb-gi on {}", s.scene.scene),
        &crate::results::EvalResult::BzbGi(out.clone()),
        sections,
    )
}

/// `--frames N`: the flicker of `target` along the camera path (BZB §6: "the sampling
/// directions are randomly selected for each frame [...] leading to flickering in animated
/// scenes"), pairing pixels within the temporal filter's distance threshold (else 1 cm).
fn flicker_along_path(
    gpu: &strata_render::GpuContext,
    scene: &strata_scene::Scene,
    s: &EvalSettings,
    settings: RenderSettings,
    target: &str,
    temporal: Option<strata_render::passes::temporal::TemporalSettings>,
) -> Result<Option<crate::results::Flicker>> {
    let threshold = temporal.map_or(0.01, |t| t.max_distance);
    s.frames
        .map(|n| super::flicker(gpu, scene, &s.scene, settings, target, threshold, n))
        .transpose()
}
