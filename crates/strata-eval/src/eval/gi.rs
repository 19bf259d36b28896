//! Deep-G-buffer radiosity against the CPU path tracer for the same camera: the indirect diffuse
//! light alone and the full image (direct + indirect), as FLIP on tonemapped images and RMSE/MAE
//! on linear radiance; optionally DGB Fig. 10's error-source study.

use std::path::Path;

use anyhow::{bail, Result};
use strata_reference::gi::{GiSettings, OneBounceSettings};
use strata_reference::Reference;
use strata_render::frame::FrameCameras;
use strata_render::passes::lighting::LightingSettings;
use strata_render::passes::radiosity::RadiositySettings;
use strata_render::{GpuContext, GpuOptions, RenderSettings, Renderer};
use strata_scene::{Camera, ImageBuf, Scene};

use super::{figure, flicker, write_report, EvalSettings};
use crate::cache::{scene_fingerprint, RefCache};
use crate::metrics::{compare_radiance, display};
use crate::report::Section;
use crate::results::{EvalResult, Fig10, Fig10Row, GiErrors, GiEval};

/// What only the GI evaluation takes.
#[derive(Clone, Copy, Debug)]
pub struct GiEvalSettings {
    /// Indirect bounces of the path-traced reference, 1..=64.
    pub bounces: u32,
    /// Also run DGB Fig. 10's error-source study.
    pub fig10: bool,
}

/// GPU images of one configuration and their errors.
struct GiResult {
    layers: u32,
    full: ImageBuf,
    indirect: ImageBuf,
    errors: GiErrors,
    full_map: ImageBuf,
    indirect_map: ImageBuf,
}

pub fn run(s: &EvalSettings, rs: &RadiositySettings, g: &GiEvalSettings) -> Result<GiEval> {
    let spp = s.check(64)?;
    if !(1..=64).contains(&g.bounces) {
        bail!("--bounces {} is out of range: must be in 1..=64", g.bounces);
    }
    let (mut scene, cams) = s.scene.load()?;
    // Compare like with like: the reference is Lambertian with no ambient
    // term, and the sky is an environment light that screen-space radiosity
    // does not see (the light-probe fallback's job): both are removed.
    scene.settings.ambient = [0.0; 3];
    scene.settings.sky = [0.0; 3];
    let (w, h) = (s.scene.width, s.scene.height);
    let camera = cams.current;
    render_settings(s, s.deep.layers, rs)
        .validate()
        .map_err(|e| anyhow::anyhow!("{e}"))?;

    let cache = RefCache::new(&s.cache);
    let gi_settings = GiSettings {
        spp,
        bounces: g.bounces,
        ..Default::default()
    };
    let reference = Reference::new(&scene, s.scene.frame).with_progress(s.progress);
    let key = format!(
        "v1 gi {} {camera:?} {w}x{h} {gi_settings:?}",
        scene_fingerprint(&scene, s.scene.frame)
    );
    // one path-traced run gives both images; both are cached
    let descriptions = [format!("{key} total"), format!("{key} indirect")];
    let keys = descriptions.each_ref().map(|d| RefCache::key(d));
    let loaded = (!s.no_cache).then(|| (cache.load(&keys[0]), cache.load(&keys[1])));
    let (ref_total, ref_indirect) = match loaded {
        Some((Some(t), Some(i))) => (t, i),
        _ => {
            let g = reference.gi(&camera, w, h, &gi_settings);
            cache.store_or_warn(&keys[0], &g.total, &descriptions[0]);
            cache.store_or_warn(&keys[1], &g.indirect, &descriptions[1]);
            (g.total, g.indirect)
        }
    };

    let gpu = GpuContext::new(&GpuOptions {
        adapter: s.adapter.clone(),
    })?;
    let exposure = scene.settings.exposure;
    let evaluate = |layers: u32| -> Result<GiResult> {
        let mut r = Renderer::new(&gpu, &scene, render_settings(s, layers, rs))?;
        // static warm-up at the evaluated camera: bounces and temporal history
        let renders = s.warmup.max(1) + 1;
        let (full, indirect) = render_indirect(&mut r, &gpu, &scene, camera, s.scene.frame, renders)?;
        // RMSE / MAE on linear radiance, FLIP on the tonemapped images
        let (full_stats, full_map) = compare_radiance(&ref_total, &full, exposure)?;
        let (indirect_stats, indirect_map) = compare_radiance(&ref_indirect, &indirect, exposure)?;
        Ok(GiResult {
            layers,
            full,
            indirect,
            errors: GiErrors {
                indirect: indirect_stats,
                full: full_stats,
            },
            full_map,
            indirect_map,
        })
    };
    let k = s.deep.layers;
    let mut results = s.layer_counts().into_iter().map(evaluate).collect::<Result<Vec<_>>>()?;
    let main = results.pop().expect("k is evaluated");
    let fig10 = match g.fig10 {
        true => Some(fig10(s, &gpu, &scene, rs, &cache, spp)?),
        false => None,
    };
    let flicker = match s.frames {
        Some(n) => {
            // temporal stability of the indirect irradiance (red channel) along the path
            let threshold = rs.temporal.map_or(0.01, |t| t.max_distance);
            Some(flicker(
                &gpu,
                &scene,
                &s.scene,
                render_settings(s, k, rs),
                "indirect",
                threshold,
                n,
            )?)
        }
        None => None,
    };
    let out = GiEval {
        run: s.run_info(
            spp,
            "path-traced diffuse GI, sky and ambient off (indirect = light reflected at least twice)",
            gpu.describe(),
            flicker,
        ),
        samples: rs.samples,
        radius: rs.radius.unwrap_or(scene.settings.radiosity_radius),
        normal_test: rs.normal_test,
        min_mip: rs.min_mip,
        delta: rs.delta,
        boost: rs.boost,
        warmup: s.warmup,
        ref_bounces: g.bounces,
        errors: main.errors,
        layers_1: results.first().map(|o| o.errors),
        fig10,
        by_layers: s.by_layers(results.iter().chain([&main]).map(|r| (r.layers, r.errors))),
    };
    if let Some(dir) = &s.report {
        let refs = (&ref_total, &ref_indirect);
        write_gi_report(dir, s, &out, &main, results.first(), refs, exposure)?;
    }
    Ok(out)
}

fn render_settings(s: &EvalSettings, layers: u32, radiosity: &RadiositySettings) -> RenderSettings {
    RenderSettings {
        lighting: LightingSettings {
            // the reference is Lambertian
            specular: false,
            ..Default::default()
        },
        radiosity: Some(radiosity.clone()),
        ..s.render_settings(layers)
    }
}

/// Renders `renders` frames at the fixed `camera` (bounces and temporal history converge) and
/// returns the composed image and its indirect part (composed − direct), RGB.
fn render_indirect(
    r: &mut Renderer,
    gpu: &GpuContext,
    scene: &Scene,
    camera: Camera,
    frame: f32,
    renders: u32,
) -> Result<(ImageBuf, ImageBuf)> {
    let fixed = FrameCameras::fixed(camera);
    for _ in 0..renders {
        r.render(gpu, scene, &fixed, frame)?;
    }
    let full = rgb(&r.read_target(gpu, "hdr-full")?);
    let direct = rgb(&r.read_target(gpu, "hdr")?);
    let mut indirect = full.clone();
    for (o, d) in indirect.data.iter_mut().zip(&direct.data) {
        *o = (*o - d).max(0.0);
    }
    Ok((full, indirect))
}

fn rgb(img: &ImageBuf) -> ImageBuf {
    let mut out = ImageBuf::new(img.width, img.height, 3);
    for (o, p) in out
        .data
        .chunks_exact_mut(3)
        .zip(img.data.chunks_exact(img.channels as usize))
    {
        o.copy_from_slice(&p[..3]);
    }
    out
}

fn write_gi_report(
    dir: &Path,
    s: &EvalSettings,
    out: &GiEval,
    main: &GiResult,
    one: Option<&GiResult>,
    (ref_total, ref_indirect): (&ImageBuf, &ImageBuf),
    exposure: f32,
) -> Result<()> {
    std::fs::create_dir_all(dir).map_err(|e| anyhow::anyhow!("--report {}: {e}", dir.display()))?;
    let k = s.deep.layers;
    let fig = |img: &ImageBuf, name: &str, caption: String| figure(dir, &display(img, exposure), name, caption);
    let map = |img: &ImageBuf, name: &str, caption: String| figure(dir, img, name, caption);
    let st = &main.errors.indirect;
    let mut sections = vec![
        Section::new(format!("Indirect diffuse light, {k} layers, against the path tracer"))
            .text(format!(
                "Tonemapped with the scene exposure ({exposure}); GPU indirect = composed image − direct. Reference: {} spp, {} bounces.",
                out.run.ref_spp, out.ref_bounces
            ))
            .figures(vec![
                fig(&main.indirect, &format!("indirect-k{k}.png"), format!("GPU, k = {k}: FLIP {:.4}", st.flip))?,
                fig(ref_indirect, "reference-indirect.png", "path-traced indirect".into())?,
                map(&main.indirect_map, &format!("flip-indirect-k{k}.png"), format!("FLIP error, k = {k}"))?,
            ]),
        Section::new("Direct + indirect").figures(vec![
            fig(&main.full, &format!("full-k{k}.png"), format!("GPU, k = {k}: FLIP {:.4}", main.errors.full.flip))?,
            fig(ref_total, "reference-full.png", "path-traced".into())?,
            map(&main.full_map, &format!("flip-full-k{k}.png"), format!("FLIP error, k = {k}"))?,
        ]),
    ];
    if let Some(o) = one.filter(|_| k != 1) {
        sections.push(
            Section::new(format!("1 layer vs {k} layers (indirect)"))
                .text("Light from surfaces hidden behind the first layer only reaches the gather through layer 1.")
                .figures(vec![
                    fig(
                        &o.indirect,
                        "indirect-k1.png",
                        format!("GPU, k = 1: FLIP {:.4}", o.errors.indirect.flip),
                    )?,
                    fig(
                        &main.indirect,
                        &format!("indirect-k{k}.png"),
                        format!("GPU, k = {k}: FLIP {:.4}", st.flip),
                    )?,
                    map(&o.indirect_map, "flip-indirect-k1.png", "FLIP error, k = 1".into())?,
                ]),
        );
    }
    write_report(
        dir,
        format!("strata eval: GI on {}", s.scene.scene),
        &EvalResult::Gi(out.clone()),
        sections,
    )
}

/// DGB Fig. 10's error sources: one GPU bounce (δ = 0) with and without the n̂_Y
/// test, each against single-bounce references with traced visibility and with
/// mutual visibility assumed (indirect radiance; FLIP on tonemapped images).
fn fig10(
    s: &EvalSettings,
    gpu: &GpuContext,
    scene: &Scene,
    rs: &RadiositySettings,
    cache: &RefCache,
    spp: u32,
) -> Result<Fig10> {
    let (w, h) = (s.scene.width, s.scene.height);
    let camera = s.scene.cameras_at(scene, s.scene.frame).current;
    let reference = Reference::new(scene, s.scene.frame).with_progress(s.progress);
    let mut refs = Vec::new();
    for visibility in [true, false] {
        let settings = OneBounceSettings {
            spp,
            visibility,
            ..Default::default()
        };
        let d = format!(
            "v1 one-bounce {} {camera:?} {w}x{h} {settings:?}",
            scene_fingerprint(scene, s.scene.frame)
        );
        refs.push(cache.get_or_compute(s.no_cache, &d, || reference.one_bounce(&camera, w, h, &settings)));
    }
    let exposure = scene.settings.exposure;
    let row = |normal_test: bool| -> Result<Fig10Row> {
        let settings = RadiositySettings {
            normal_test,
            delta: 0.0,
            ..rs.clone()
        };
        let mut r = Renderer::new(gpu, scene, render_settings(s, s.deep.layers, &settings))?;
        let (_, indirect) = render_indirect(&mut r, gpu, scene, camera, s.scene.frame, s.warmup + 1)?;
        Ok(Fig10Row {
            vs_visibility: compare_radiance(&refs[0], &indirect, exposure)?.0,
            vs_mutual_visibility: compare_radiance(&refs[1], &indirect, exposure)?.0,
        })
    };
    Ok(Fig10 {
        normal_test: row(true)?,
        no_normal_test: row(false)?,
    })
}
