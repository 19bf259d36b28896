//! `strata eval --technique gi`: deep-G-buffer radiosity against the CPU path
//! tracer for the same camera — the indirect diffuse light alone and the full
//! image (direct + indirect), as FLIP on tonemapped images and RMSE/MAE on
//! linear radiance.

use std::path::Path;

use anyhow::{bail, Result};
use serde_json::json;
use strata_reference::gi::GiSettings;
use strata_reference::Reference;
use strata_render::passes::deep_gbuffer::DeepGBufferSettings;
use strata_render::passes::lighting::LightingSettings;
use strata_render::passes::radiosity::RadiositySettings;
use strata_render::{GpuContext, GpuOptions, RenderSettings, Renderer};
use strata_scene::ImageBuf;

use crate::args::EvalArgs;
use crate::eval::scene_fingerprint;
use crate::metrics::{compare, ErrorStats};
use crate::output::{cameras_at, scene_and_camera};
use crate::ref_cache::RefCache;
use crate::report::{write_report, ReportImage, ReportSection};

/// GPU images of one configuration and their errors.
struct GiResult {
    full: ImageBuf,
    indirect: ImageBuf,
    full_stats: ErrorStats,
    full_map: ImageBuf,
    indirect_stats: ErrorStats,
    indirect_map: ImageBuf,
}

pub fn run(a: &EvalArgs) -> Result<()> {
    let spp = crate::eval::check_common(a, 64)?;
    if !(1..=64).contains(&a.bounces) {
        bail!("--bounces {} is out of range: must be in 1..=64", a.bounces);
    }
    let (mut scene, cams) = scene_and_camera(&a.scene)?;
    // Compare like with like: the reference is Lambertian with no ambient
    // term, and the sky is an environment light that screen-space radiosity
    // does not see (the light-probe fallback's job): both are removed.
    scene.settings.ambient = [0.0; 3];
    scene.settings.sky = [0.0; 3];
    let (w, h) = (a.scene.width, a.scene.height);
    let camera = cams.current;
    let rs = a.radiosity.settings().map_err(|e| anyhow::anyhow!(e))?;
    render_settings(a, a.deep.layers, &rs)
        .validate()
        .map_err(|e| anyhow::anyhow!("{e}"))?;

    let cache = RefCache::new(a.cache.clone().unwrap_or_else(RefCache::default_dir));
    let gi_settings = GiSettings {
        spp,
        bounces: a.bounces,
        ..Default::default()
    };
    let reference = Reference::new(&scene, a.scene.frame).with_progress(!a.quiet);
    let key = format!(
        "v1 gi {} {camera:?} {w}x{h} {gi_settings:?}",
        scene_fingerprint(&scene, a.scene.frame)
    );
    // one path-traced run gives both images; both are cached
    let descriptions = [format!("{key} total"), format!("{key} indirect")];
    let keys = descriptions.each_ref().map(|d| RefCache::key(d));
    let loaded = (!a.no_cache).then(|| (cache.load(&keys[0]), cache.load(&keys[1])));
    let (ref_total, ref_indirect) = match loaded {
        Some((Some(t), Some(i))) => (t, i),
        _ => {
            let g = reference.gi(&camera, w, h, &gi_settings);
            for (k, (img, d)) in keys
                .iter()
                .zip([(&g.total, &descriptions[0]), (&g.indirect, &descriptions[1])])
            {
                if let Err(e) = cache.store(k, img, d) {
                    tracing::warn!("could not cache the reference: {e:#}");
                }
            }
            (g.total, g.indirect)
        }
    };

    let gpu = GpuContext::new(&GpuOptions {
        adapter: a.gpu.adapter.clone(),
    })?;
    let exposure = scene.settings.exposure;
    let ref_full_ldr = display(&ref_total, exposure);
    let ref_indirect_ldr = display(&ref_indirect, exposure);
    let evaluate = |layers: u32| -> Result<GiResult> {
        let mut r = Renderer::new(&gpu, &scene, render_settings(a, layers, &rs))?;
        let f = a.scene.frame;
        // static warm-up at the evaluated camera: bounces and temporal history
        let fixed = strata_render::frame::FrameCameras::fixed(cameras_at(&scene, &a.scene, f).current);
        for _ in 0..a.warmup.max(1) {
            r.render(&gpu, &scene, &fixed, f)?;
        }
        r.render(&gpu, &scene, &fixed, f)?;
        let full = rgb(&r.read_target(&gpu, "hdr-full")?);
        let direct = rgb(&r.read_target(&gpu, "hdr")?);
        let mut indirect = full.clone();
        for (o, d) in indirect.data.iter_mut().zip(&direct.data) {
            *o = (*o - d).max(0.0);
        }
        let (mut full_stats, full_map) = compare(&ref_full_ldr, &display(&full, exposure))?;
        let (mut indirect_stats, indirect_map) = compare(&ref_indirect_ldr, &display(&indirect, exposure))?;
        // RMSE / MAE on linear radiance, FLIP on the tonemapped images
        (full_stats.rmse, full_stats.mae) = linear_errors(&ref_total, &full);
        (indirect_stats.rmse, indirect_stats.mae) = linear_errors(&ref_indirect, &indirect);
        Ok(GiResult {
            full,
            indirect,
            full_stats,
            full_map,
            indirect_stats,
            indirect_map,
        })
    };
    let k = a.deep.layers;
    let main = evaluate(k)?;
    let one = if a.report.is_some() && k != 1 {
        Some(evaluate(1)?)
    } else {
        None
    };
    let stats = ErrorStats::json;
    let mut out = json!({
        "scene": a.scene.scene,
        "technique": "gi",
        "layers": k,
        "variant": a.deep.variant.to_string(),
        "width": w, "height": h, "frame": a.scene.frame,
        "samples": rs.samples, "radius": rs.radius.unwrap_or(scene.settings.radiosity_radius), "normal_test": rs.normal_test, "min_mip": rs.min_mip,
        "delta": rs.delta, "boost": rs.boost, "warmup": a.warmup,
        "flip": main.indirect_stats.flip, "rmse": main.indirect_stats.rmse, "mae": main.indirect_stats.mae,
        "full": stats(&main.full_stats),
        "ref_spp": spp, "ref_bounces": a.bounces,
        "reference": "path-traced diffuse GI, sky and ambient off (indirect = light reflected at least twice)",
        "device": gpu.describe(),
    });
    if let Some(o) = &one {
        out["layers_1"] = json!({"flip": o.indirect_stats.flip, "rmse": o.indirect_stats.rmse,
            "mae": o.indirect_stats.mae, "full": stats(&o.full_stats)});
    }
    if a.fig10 {
        out["fig10"] = fig10(a, &gpu, &scene, &rs, &cache, spp)?;
    }
    if let Some(n) = a.frames {
        // temporal stability of the indirect irradiance (red channel) along the path
        let threshold = rs.temporal.map_or(0.01, |t| t.max_distance);
        let f = crate::eval::flicker(&gpu, &scene, a, render_settings(a, k, &rs), "indirect", threshold, n)?;
        out["flicker"] = json!(f.mean);
        out["flicker_frames"] = json!(f.frames);
        out["flicker_valid_fraction"] = json!(f.valid_fraction);
    }
    if let Some(dir) = &a.report {
        write_gi_report(dir, a, &main, one.as_ref(), &ref_total, &ref_indirect, exposure, &out)?;
        eprintln!("wrote {}", dir.join("index.html").display());
    }
    if a.json {
        println!("{}", serde_json::to_string(&out)?);
    } else {
        println!(
            "{} gi k={k} {w}x{h}: indirect FLIP {:.4} RMSE {:.4} MAE {:.4}; full FLIP {:.4} RMSE {:.4} (reference {spp} spp, {} bounces)",
            a.scene.scene,
            main.indirect_stats.flip,
            main.indirect_stats.rmse,
            main.indirect_stats.mae,
            main.full_stats.flip,
            main.full_stats.rmse,
            a.bounces
        );
    }
    Ok(())
}

fn render_settings(a: &EvalArgs, layers: u32, radiosity: &RadiositySettings) -> RenderSettings {
    RenderSettings {
        width: a.scene.width,
        height: a.scene.height,
        deep: DeepGBufferSettings {
            layers,
            ..a.deep.settings()
        },
        guard_band: a.deep.guard_band,
        lighting: LightingSettings {
            // the reference is Lambertian
            specular: false,
            ..Default::default()
        },
        radiosity: Some(radiosity.clone()),
        ..Default::default()
    }
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

/// The tonemapper's display values: exposure, ACES fit (as `color.wgsl`), sRGB.
pub fn display(img: &ImageBuf, exposure: f32) -> ImageBuf {
    let aces = |x: f32| ((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14)).clamp(0.0, 1.0);
    let mut out = img.clone();
    for v in &mut out.data {
        *v = strata_scene::image_buf::linear_to_srgb(aces(*v * exposure));
    }
    out
}

/// RMSE and MAE of linear values.
fn linear_errors(reference: &ImageBuf, test: &ImageBuf) -> (f32, f32) {
    let n = reference.data.len().max(1) as f64;
    let (mut se, mut ae) = (0.0f64, 0.0f64);
    for (r, t) in reference.data.iter().zip(&test.data) {
        let d = (*t - *r) as f64;
        se += d * d;
        ae += d.abs();
    }
    ((se / n).sqrt() as f32, (ae / n) as f32)
}

#[allow(clippy::too_many_arguments)]
fn write_gi_report(
    dir: &Path,
    a: &EvalArgs,
    main: &GiResult,
    one: Option<&GiResult>,
    ref_total: &ImageBuf,
    ref_indirect: &ImageBuf,
    exposure: f32,
    numbers: &serde_json::Value,
) -> Result<()> {
    std::fs::create_dir_all(dir).map_err(|e| anyhow::anyhow!("--report {}: {e}", dir.display()))?;
    let k = a.deep.layers;
    let fig = |img: &ImageBuf, name: &str, caption: String| -> Result<ReportImage> {
        img.save(&dir.join(name), false).map_err(|e| anyhow::anyhow!(e))?;
        Ok(ReportImage {
            caption,
            file: name.into(),
        })
    };
    let s = &main.indirect_stats;
    let mut sections = vec![
        ReportSection {
            title: format!("Indirect diffuse light, {k} layers, against the path tracer"),
            text: format!(
                "Tonemapped with the scene exposure ({exposure}); GPU indirect = composed image − direct. Reference: {} spp, {} bounces.",
                numbers["ref_spp"], a.bounces
            ),
            images: vec![
                fig(&display(&main.indirect, exposure), &format!("indirect-k{k}.png"), format!("GPU, k = {k}: FLIP {:.4}", s.flip))?,
                fig(&display(ref_indirect, exposure), "reference-indirect.png", "path-traced indirect".into())?,
                fig(&main.indirect_map, &format!("flip-indirect-k{k}.png"), format!("FLIP error, k = {k}"))?,
            ],
        },
        ReportSection {
            title: "Direct + indirect".into(),
            text: String::new(),
            images: vec![
                fig(&display(&main.full, exposure), &format!("full-k{k}.png"), format!("GPU, k = {k}: FLIP {:.4}", main.full_stats.flip))?,
                fig(&display(ref_total, exposure), "reference-full.png", "path-traced".into())?,
                fig(&main.full_map, &format!("flip-full-k{k}.png"), format!("FLIP error, k = {k}"))?,
            ],
        },
    ];
    if let Some(o) = one {
        sections.push(ReportSection {
            title: format!("1 layer vs {k} layers (indirect)"),
            text: "Light from surfaces hidden behind the first layer only reaches the gather through layer 1.".into(),
            images: vec![
                fig(
                    &display(&o.indirect, exposure),
                    "indirect-k1.png",
                    format!("GPU, k = 1: FLIP {:.4}", o.indirect_stats.flip),
                )?,
                fig(
                    &display(&main.indirect, exposure),
                    &format!("indirect-k{k}.png"),
                    format!("GPU, k = {k}: FLIP {:.4}", s.flip),
                )?,
                fig(&o.indirect_map, "flip-indirect-k1.png", "FLIP error, k = 1".into())?,
            ],
        });
    }
    write_report(
        dir,
        &format!("strata eval: GI on {}", a.scene.scene),
        &sections,
        numbers,
    )?;
    Ok(())
}

/// DGB Fig. 10's error sources: one GPU bounce (δ = 0) with and without the n̂_Y
/// test, each against single-bounce references with traced visibility and with
/// mutual visibility assumed (indirect radiance; FLIP on tonemapped images).
fn fig10(
    a: &EvalArgs,
    gpu: &GpuContext,
    scene: &strata_scene::Scene,
    rs: &RadiositySettings,
    cache: &RefCache,
    spp: u32,
) -> Result<serde_json::Value> {
    use strata_reference::gi::OneBounceSettings;
    let (w, h) = (a.scene.width, a.scene.height);
    let camera = cameras_at(scene, &a.scene, a.scene.frame).current;
    let reference = Reference::new(scene, a.scene.frame).with_progress(!a.quiet);
    let mut refs = Vec::new();
    for visibility in [true, false] {
        let s = OneBounceSettings {
            spp,
            visibility,
            ..Default::default()
        };
        let d = format!(
            "v1 one-bounce {} {camera:?} {w}x{h} {s:?}",
            scene_fingerprint(scene, a.scene.frame)
        );
        let key = RefCache::key(&d);
        let img = match cache.load(&key).filter(|_| !a.no_cache) {
            Some(img) => img,
            None => {
                let img = reference.one_bounce(&camera, w, h, &s);
                if let Err(e) = cache.store(&key, &img, &d) {
                    tracing::warn!("could not cache the reference: {e:#}");
                }
                img
            }
        };
        refs.push(img);
    }
    let exposure = scene.settings.exposure;
    let mut out = serde_json::Map::new();
    for normal_test in [true, false] {
        let settings = RadiositySettings {
            normal_test,
            delta: 0.0,
            ..rs.clone()
        };
        let mut r = Renderer::new(gpu, scene, render_settings(a, a.deep.layers, &settings))?;
        let fixed = strata_render::frame::FrameCameras::fixed(camera);
        for _ in 0..=a.warmup {
            r.render(gpu, scene, &fixed, a.scene.frame)?;
        }
        let full = rgb(&r.read_target(gpu, "hdr-full")?);
        let direct = rgb(&r.read_target(gpu, "hdr")?);
        let mut indirect = full;
        for (o, d) in indirect.data.iter_mut().zip(&direct.data) {
            *o = (*o - d).max(0.0);
        }
        let mut row = serde_json::Map::new();
        for (name, reference) in [("vs_visibility", &refs[0]), ("vs_mutual_visibility", &refs[1])] {
            let (mut st, _) = compare(&display(reference, exposure), &display(&indirect, exposure))?;
            (st.rmse, st.mae) = linear_errors(reference, &indirect);
            row.insert(name.into(), st.json());
        }
        out.insert(
            if normal_test { "normal_test" } else { "no_normal_test" }.into(),
            serde_json::Value::Object(row),
        );
    }
    Ok(serde_json::Value::Object(out))
}
