//! Order-independent transparency from the A-buffer (ABA §IV; `--technique oit`)
//! against the CPU compositing of every surface crossing along each pixel's
//! primary ray (`strata_reference::Reference::composite`, same camera, same pixel
//! centres, the same unshadowed fragment shading `oit::shade`). The reference is
//! exact per pixel (no sampling), so it has no noise and is not cached.

use anyhow::{bail, Result};
use strata_reference::Reference;
use strata_render::frame::FrameCameras;
use strata_render::technique;
use strata_render::{GpuContext, GpuOptions, RenderSettings, Renderer};

use super::gi::rgb;
use super::{figure, write_report, EvalSettings};
use crate::metrics::{compare_radiance, display, outliers, OUTLIER_THRESHOLD};
use crate::report::Section;
use crate::results::{EvalResult, OitEval};

/// `set`: the `oit` technique's settings (`abuffer`, `pool`, `max-layers`, `compress`, …),
/// applied last and range-checked.
pub fn run(s: &EvalSettings, set: &[(String, f64)]) -> Result<OitEval> {
    if s.deep.layers != 1 {
        bail!(
            "--layers {} is out of range for --technique oit: must be 1 (the A-buffer keeps every layer)",
            s.deep.layers
        );
    }
    if s.frames.is_some() {
        bail!("--frames is not available for --technique oit (one static frame is compared)");
    }
    s.check_report()?;
    let t = technique::find("oit")?;
    let mut rs: RenderSettings = t.settings(&s.render_settings(1), None)?;
    for (name, value) in set {
        t.set(&mut rs, name, *value)
            .map_err(|e| anyhow::anyhow!("--set {name}={value}: {e}"))?;
    }
    rs.validate()?;
    let a = rs.abuffer.clone().expect("the oit technique turns the A-buffer on");

    let (scene, cams) = s.scene.load()?;
    let (w, h) = (s.scene.width, s.scene.height);
    let camera = cams.current;
    let exposure = s.display_exposure(&scene);

    let reference = Reference::new(&scene, s.scene.frame).with_progress(s.progress);
    let ref_img = reference.composite(&camera, w, h);

    let gpu = GpuContext::new(&GpuOptions {
        adapter: s.adapter.clone(),
    })?;
    let mut r = Renderer::new(&gpu, &scene, rs)?;
    r.render(&gpu, &scene, &FrameCameras::fixed(camera), s.scene.frame)?;
    let img = rgb(&r.read_target(&gpu, "hdr-oit")?);
    let lists = r.abuffer().expect("the oit frame has an A-buffer").read_lists(&gpu)?;
    gpu.check_errors()?;

    let (mut errors, map) = compare_radiance(&ref_img, &img, exposure)?;
    errors.outliers = Some(outliers(&display(&img, exposure), OUTLIER_THRESHOLD));
    errors.ref_outliers = Some(outliers(&display(&ref_img, exposure), OUTLIER_THRESHOLD));
    let mut warnings = Vec::new();
    if lists.overflow > 0 {
        let w = format!(
            "the A-buffer dropped {} of {} fragments ({}): the error includes them",
            lists.overflow,
            lists.total,
            a.overflow_hint()
        );
        eprintln!("warning: {w}");
        warnings.push(w);
    }
    let max_layers = lists.lists.iter().map(Vec::len).max().unwrap_or(0) as u32;
    let out = OitEval {
        run: s.run_info(
            1,
            "CPU compositing of every surface crossing along the pixel-centre ray (unshadowed fragment shading)",
            gpu.describe(),
            None,
            warnings,
        ),
        method: a.method.name().to_string(),
        fragments: lists.total,
        dropped: lists.overflow,
        max_fragments_per_pixel: max_layers,
        memory_bytes: a.memory_bytes(w, h),
        errors,
    };
    if let Some(dir) = &s.report {
        // the composites (tonemapped at the display exposure) and the ꟻLIP map
        std::fs::create_dir_all(dir).map_err(|e| anyhow::anyhow!("--report {}: {e}", dir.display()))?;
        let shown = |img, name: &str, caption: String| figure(dir, &display(img, exposure), name, caption);
        let section = Section::new("Composite")
            .text(format!(
                "{w}×{h} pixels, frame {}; the CPU compositing of every surface crossing along the pixel-centre ray, and the A-buffer's ({}, {} fragments, {} dropped, at most {} per pixel). Tonemapped at exposure {exposure} (the scene's unless `--set exposure`); the ꟻLIP map uses the magma scale.",
                s.scene.frame, out.method, out.fragments, out.dropped, out.max_fragments_per_pixel
            ))
            .figures(vec![
                shown(&ref_img, "reference.png", "CPU compositing".into())?,
                shown(
                    &img,
                    "oit.png",
                    format!("A-buffer: ꟻLIP {:.4}, RMSE {:.4}", out.errors.flip, out.errors.rmse),
                )?,
                figure(dir, &map, "flip-oit.png", "ꟻLIP against the CPU compositing".into())?,
            ]);
        write_report(
            dir,
            format!("strata eval: OIT on {}", s.scene.scene),
            &EvalResult::Oit(out.clone()),
            vec![section],
        )?;
    }
    Ok(out)
}
