//! Interleaved deferred shading (ILS §4, §6.2; `--technique ils`) measured twice:
//!
//! - against the **brute force of the same VPLs** (every pixel shades all N; Table 4's
//!   "no IS"): what interleaving + the §4.5 blur cost in quality (`flip_vs_brute`,
//!   `rmse_vs_brute` on the tonemapped images, full and indirect alone);
//! - against the **path tracer with one indirect bounce** (the converged, cached GI
//!   reference of `eval gi` with `--bounces 1`: light → surface → surface → eye is
//!   exactly one VPL bounce). With `shadows = none` (SNSM) the VPLs' visibility is
//!   ignored, so that distance includes the missing-occlusion bias; `shadows = vpl`
//!   (SSM, §4.3) removes most of it.

use anyhow::{bail, Result};
use strata_render::passes::lighting::LightingSettings;
use strata_render::technique;
use strata_render::{GpuContext, GpuOptions, RenderSettings, Renderer};
use strata_scene::ImageBuf;

use super::gi::{indirect, render_indirect, total, DEFAULT_CAP};
use super::{figure, gi_report_sections, noise_warnings, write_report, EvalSettings, GiImages, RefImage};
use crate::metrics::{compare, compare_radiance, display};
use crate::report::Section;
use crate::results::{EvalResult, GiErrors, IlsEval};

/// `preset`: one of the `ils` technique's presets (`None`: standard); `set`: its settings
/// (`vpls`, `interleave-n`, `shadows`, …), applied last and range-checked; the brute force
/// is the same with `brute-force = 1`.
/// `progressive`: §6.3's physically-based mode with (K sets, B bounces) ([`super::ils_progressive`]).
pub fn run(
    s: &EvalSettings,
    preset: Option<&str>,
    set: &[(String, f64)],
    progressive: Option<(u32, u32)>,
) -> Result<IlsEval> {
    let rule = s.check(DEFAULT_CAP, 8)?;
    if s.deep.layers != 1 {
        bail!(
            "--layers {} is out of range for --technique ils: must be 1 (ILS shades layer 0)",
            s.deep.layers
        );
    }
    if s.frames.is_some() {
        bail!("--frames is not available for --technique ils (static VPLs: no temporal filter to measure)");
    }
    let t = technique::find("ils")?;
    let configure = |brute: bool| -> Result<RenderSettings> {
        let base = RenderSettings {
            // the reference is Lambertian
            lighting: LightingSettings {
                specular: false,
                ..Default::default()
            },
            ..s.render_settings(1)
        };
        let mut r = t
            .settings(&base, preset)
            .map_err(|e| anyhow::anyhow!("--preset: {e}"))?;
        for (name, value) in set {
            t.set(&mut r, name, *value)
                .map_err(|e| anyhow::anyhow!("--set {name}={value}: {e}"))?;
        }
        if brute {
            t.set(&mut r, "brute-force", 1.0)?;
        }
        r.validate()?;
        Ok(r)
    };
    let (is_settings, brute_settings) = (configure(false)?, configure(true)?);
    let ils = is_settings.ils.clone().expect("the ils technique turns ILS on");

    let (mut scene, cams) = s.scene.load()?;
    // as `eval gi`: the reference has no ambient term and the VPLs carry no sky light
    scene.settings.ambient = [0.0; 3];
    scene.settings.sky = [0.0; 3];
    let (_w, _h) = (s.scene.width, s.scene.height);
    let camera = cams.current;
    let exposure = s.display_exposure(&scene);

    // One indirect bounce = one VPL bounce (§6.2); the same cache entry as `eval gi --bounces 1`.
    let shown = |img: &ImageBuf| display(img, exposure);
    let converged = super::gi::converged_gi(s, &scene, camera, 1, &rule);
    let ref_total = RefImage::of(&converged, total, shown)?;
    let ref_indirect = RefImage::of(&converged, indirect, shown)?;

    // one set of VPLs for both GPU images (static scene: generated once)
    let vpls = crate::vpls::scene_vpls(&scene, s.scene.frame, ils.vpl_count);
    let gpu = GpuContext::new(&GpuOptions {
        adapter: s.adapter.clone(),
    })?;
    let render = |mut rs: RenderSettings| -> Result<(ImageBuf, ImageBuf, Option<f32>)> {
        if let Some(i) = &mut rs.ils {
            i.vpls = vpls.clone();
        }
        let mut r = Renderer::new(&gpu, &scene, rs)?;
        let (full, ind) = render_indirect(&mut r, &gpu, &scene, camera, s.scene.frame, 1)?;
        let refined = refined_share(&r, &gpu)?;
        gpu.check_errors()?;
        Ok((full, ind, refined))
    };
    let progressive = match progressive {
        Some((k, b)) => Some(super::ils_progressive::run(
            s,
            &is_settings,
            &scene,
            camera,
            &gpu,
            k,
            b,
        )?),
        None => None,
    };
    let (full, ind, refined_share) = render(is_settings)?;
    let (brute_full, brute_ind, _) = render(brute_settings)?;

    let vs_reference = |full: ImageBuf, indirect: ImageBuf| -> Result<(GiErrors, GiImages)> {
        let (f, full_map) = compare_radiance(&ref_total.image, &full, exposure)?;
        let (i, indirect_map) = compare_radiance(&ref_indirect.image, &indirect, exposure)?;
        let errors = GiErrors {
            full: ref_total.annotate(f, &display(&full, exposure)),
            indirect: ref_indirect.annotate(i, &display(&indirect, exposure)),
        };
        Ok((
            errors,
            GiImages {
                full,
                indirect,
                full_map,
                indirect_map,
            },
        ))
    };
    // vs the brute force: ꟻLIP and RMSE of the tonemapped display values
    let (vs_brute, _) = compare(&display(&brute_full, exposure), &display(&full, exposure))?;
    let (vs_brute_ind, vs_brute_map) = compare(&display(&brute_ind, exposure), &display(&ind, exposure))?;
    let (errors, images) = vs_reference(full, ind)?;
    let (brute_force, brute_images) = vs_reference(brute_full, brute_ind)?;

    let shadows = ils.shadows.name();
    let reference_text = format!(
        "path-traced diffuse GI with 1 indirect bounce (= one VPL bounce, ILS §6.2), sky and ambient off; {}",
        if ils.shadows.traced() {
            "SSM: VPL visibility from per-VPL shadow maps (§4.3), so the distance to the path tracer is \
             interleaving, blur, VPL sampling, the geometry-term clamp and shadow-map error"
        } else {
            "SNSM ignores VPL visibility, so the distance to the path tracer includes that bias \
             (light through occluders) besides interleaving, blur, VPL sampling and the geometry-term clamp"
        }
    );
    let out = IlsEval {
        run: s.run_info(
            converged.spp(),
            &reference_text,
            gpu.describe(),
            None,
            noise_warnings(&[("ils indirect", &errors.indirect), ("ils full", &errors.full)]),
        ),
        vpl_paths: ils.vpl_count,
        vpls: vpls.len() as u32,
        pattern: format!("{}x{}", ils.pattern[0], ils.pattern[1]),
        split: ils.method.name().to_string(),
        blur: ils.blur,
        bilinear: ils.bilinear,
        refine: ils.refine,
        clamp_distance: Some(ils.clamp_distance_for(&scene)),
        refine_roughness: ils.refine_roughness,
        refine_peak: ils.refine_peak,
        blur_slide: ils.slide_window,
        per_axis_db: ils.per_axis_discontinuities,
        refined_share,
        preset: preset.unwrap_or(strata_render::passes::ils::PRESETS[0]).to_string(),
        shadows: shadows.into(),
        flip_vs_brute: vs_brute.flip,
        rmse_vs_brute: vs_brute.rmse,
        indirect_flip_vs_brute: vs_brute_ind.flip,
        indirect_rmse_vs_brute: vs_brute_ind.rmse,
        errors,
        brute_force,
        progressive,
    };
    if let Some(dir) = &s.report {
        let label = format!("ILS {}, {} ({} VPLs)", out.pattern, out.preset, out.vpls);
        let mut sections = gi_report_sections(
            dir,
            s,
            out.run.ref_spp,
            &out.run.reference,
            (&ref_indirect.image, &ref_total.image),
            exposure,
            &[
                (label.as_str(), &out.errors, &images),
                ("brute force (every pixel, all N VPLs)", &out.brute_force, &brute_images),
            ],
        )?;
        // ILS §4's own target: the interleaved frame against the brute force
        sections.push(Section::new("Interleaved against the brute force").figures(vec![figure(
            dir,
            &vs_brute_map,
            "flip-indirect-vs-brute-force.png",
            format!(
                "ꟻLIP of the indirect light against the brute force: {:.4} (RMSE {:.4})",
                out.indirect_flip_vs_brute, out.indirect_rmse_vs_brute
            ),
        )?]));
        write_report(
            dir,
            format!("strata eval: ILS on {}", s.scene.scene),
            &EvalResult::Ils(out.clone()),
            sections,
        )?;
    }
    Ok(out)
}

/// With `refine`, `refine-roughness` or `refine-peak`: the share of the pixels `ils-refine` shaded again,
/// those whose refined irradiance or glossy radiance differs from the blurred one.
fn refined_share(r: &Renderer, gpu: &GpuContext) -> Result<Option<f32>> {
    let names = r.target_names();
    if !names.contains(&"ils-refined") {
        return Ok(None);
    }
    let glossy_blurred = if names.contains(&"ils-glossy-blurred") {
        "ils-glossy-blurred"
    } else {
        "ils-glossy"
    };
    let pairs = [("indirect", "ils-refined"), (glossy_blurred, "ils-glossy-refined")];
    let mut refined = Vec::new();
    for (before, after) in pairs {
        let (a, b) = (r.read_target(gpu, before)?, r.read_target(gpu, after)?);
        let c = a.channels as usize;
        let differs = a.data.chunks(c).zip(b.data.chunks(c)).map(|(x, y)| x[..3] != y[..3]);
        if refined.is_empty() {
            refined = differs.collect();
        } else {
            refined.iter_mut().zip(differs).for_each(|(r, d)| *r |= d);
        }
    }
    let n = refined.iter().filter(|&&x| x).count();
    Ok(Some(n as f32 / refined.len().max(1) as f32))
}
