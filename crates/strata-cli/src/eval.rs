//! `strata eval`: a GPU technique against the CPU ground truth for the same
//! camera and pixel centres — FLIP, RMSE, MAE as JSON, optionally temporal
//! flicker along the camera path and an HTML report.

use std::path::Path;

use anyhow::{bail, Result};
use serde_json::json;
use strata_reference::ao::{AoBinarySettings, DiskSampling, ObscuranceSettings};
use strata_reference::Reference;
use strata_render::passes::ao::AoSettings;
use strata_render::{GpuContext, GpuOptions, RenderSettings, Renderer};
use strata_scene::{Camera, ImageBuf, Scene};

use crate::args::{EvalArgs, EvalTechnique};
use crate::metrics::{compare, ErrorStats};
use crate::output::{cameras_at, scene_and_camera};
use crate::ref_cache::RefCache;
use crate::report::{write_report, ReportImage, ReportSection};

pub fn run(a: &EvalArgs) -> Result<()> {
    match a.technique {
        EvalTechnique::Ao => ao(a),
        EvalTechnique::Gi => crate::eval_gi::run(a),
    }
}

/// One GPU AO evaluation: the image and its errors against both references.
struct AoResult {
    av: ImageBuf,
    obscurance: ErrorStats,
    obscurance_map: ImageBuf,
    binary: ErrorStats,
    binary_map: ImageBuf,
}

/// Checks the flags every technique shares and returns the reference's samples
/// per pixel (`default_spp` unless `--ref-spp`).
pub(crate) fn check_common(a: &EvalArgs, default_spp: u32) -> Result<u32> {
    let spp = a.ref_spp.unwrap_or(default_spp);
    if !(1..=65536).contains(&spp) {
        bail!("--ref-spp {spp} is out of range: must be in 1..=65536");
    }
    if let Some(n) = a.frames {
        if !(2..=1000).contains(&n) {
            bail!("--frames {n} is out of range: must be in 2..=1000");
        }
    }
    if let Some(dir) = &a.report {
        if dir.join("index.html").exists() && !a.force {
            bail!(
                "--report {}: a report exists there; pass --force to overwrite it",
                dir.display()
            );
        }
    }
    Ok(spp)
}

fn ao(a: &EvalArgs) -> Result<()> {
    let ref_spp = check_common(a, 256)?;
    let (scene, cams) = scene_and_camera(&a.scene)?;
    let settings = a.ao.settings();
    render_settings(a, a.deep.layers, &settings)
        .validate()
        .map_err(|e| anyhow::anyhow!("{e}"))?;
    let (w, h) = (a.scene.width, a.scene.height);
    let camera = cams.current;
    let (radius, beta, epsilon) = settings.resolve(&scene);

    // Ground truth (cached): the obscurance of Eq. 2 over all surfaces with the
    // spiral's radial density, and binary visibility within r.
    let cache = RefCache::new(a.cache.clone().unwrap_or_else(RefCache::default_dir));
    let reference = Reference::new(&scene, a.scene.frame).with_progress(!a.quiet);
    let obscurance_settings = ObscuranceSettings {
        radius,
        beta,
        epsilon,
        spp: ref_spp,
        disk: DiskSampling::SpiralRadius,
        ..ObscuranceSettings::new(radius)
    };
    let binary_settings = AoBinarySettings {
        spp: ref_spp,
        ..AoBinarySettings::new(radius)
    };
    let scene_id = scene_fingerprint(&scene, a.scene.frame);
    let cam_id = format!("{camera:?} {w}x{h}");
    let ref_obscurance = cached(
        &cache,
        a.no_cache,
        &format!("v1 obscurance {scene_id} {cam_id} {obscurance_settings:?}"),
        || reference.ao_obscurance(&camera, w, h, &obscurance_settings),
    )?;
    let ref_binary = cached(
        &cache,
        a.no_cache,
        &format!("v1 binary-ao {scene_id} {cam_id} {binary_settings:?}"),
        || reference.ao_binary(&camera, w, h, &binary_settings),
    )?;

    let gpu = GpuContext::new(&GpuOptions {
        adapter: a.gpu.adapter.clone(),
    })?;
    let evaluate = |layers: u32| -> Result<AoResult> {
        let mut r = Renderer::new(&gpu, &scene, render_settings(a, layers, &settings))?;
        let av = render_frame(&mut r, &gpu, &scene, a, a.scene.frame)?;
        let (obscurance, obscurance_map) = compare(&ref_obscurance, &av)?;
        let (binary, binary_map) = compare(&ref_binary, &av)?;
        Ok(AoResult {
            av,
            obscurance,
            obscurance_map,
            binary,
            binary_map,
        })
    };
    let k = a.deep.layers;
    let main = evaluate(k)?;
    let one = if a.report.is_some() && k != 1 {
        Some(evaluate(1)?)
    } else {
        None
    };
    let flicker = match a.frames {
        Some(n) => {
            let threshold = settings.temporal.map_or(0.01, |t| t.max_distance);
            let rs = render_settings(a, a.deep.layers, &settings);
            Some(flicker(&gpu, &scene, a, rs, "ao", threshold, n)?)
        }
        None => None,
    };
    let stats = ErrorStats::json;
    let mut out = json!({
        "scene": a.scene.scene,
        "technique": "ao",
        "layers": k,
        "variant": a.deep.variant.to_string(),
        "width": w, "height": h, "frame": a.scene.frame,
        "samples": settings.samples, "radius": radius, "bias": beta, "epsilon": epsilon,
        "flip": main.obscurance.flip, "rmse": main.obscurance.rmse, "mae": main.obscurance.mae,
        "ref_spp": ref_spp,
        "reference": "obscurance (DGB Eq. 2 over all surfaces, spiral radial density)",
        "binary": stats(&main.binary),
        "device": gpu.describe(),
    });
    if let Some(f) = &flicker {
        out["flicker"] = json!(f.mean);
        out["flicker_frames"] = json!(f.frames);
        out["flicker_valid_fraction"] = json!(f.valid_fraction);
    }
    if let Some(o) = &one {
        out["layers_1"] = json!({"flip": o.obscurance.flip, "rmse": o.obscurance.rmse, "mae": o.obscurance.mae,
            "binary": stats(&o.binary)});
    }
    if let Some(dir) = &a.report {
        write_ao_report(dir, a, &main, one.as_ref(), &ref_obscurance, &ref_binary, &out)?;
        eprintln!("wrote {}", dir.join("index.html").display());
    }
    if a.json {
        println!("{}", serde_json::to_string(&out)?);
    } else {
        println!(
            "{} ao k={k} {w}x{h}: FLIP {:.4}  RMSE {:.4}  MAE {:.4} (vs obscurance, {} spp); vs binary AO: FLIP {:.4}  MAE {:.4}",
            a.scene.scene,
            main.obscurance.flip,
            main.obscurance.rmse,
            main.obscurance.mae,
            ref_spp,
            main.binary.flip,
            main.binary.mae
        );
        if let Some(f) = &flicker {
            println!(
                "flicker over {} frames: {:.5} (mean |ΔAV| after reprojection, {:.1} % of pixels valid)",
                f.frames,
                f.mean,
                100.0 * f.valid_fraction
            );
        }
    }
    Ok(())
}

fn render_settings(a: &EvalArgs, layers: u32, ao: &AoSettings) -> RenderSettings {
    RenderSettings {
        width: a.scene.width,
        height: a.scene.height,
        deep: strata_render::passes::deep_gbuffer::DeepGBufferSettings {
            layers,
            ..a.deep.settings()
        },
        guard_band: a.deep.guard_band,
        shade: false,
        ao: Some(ao.clone()),
        ..Default::default()
    }
}

/// Renders frame `f` (after frame f − 1 when the first frame has no history
/// yet and the variant needs it) and returns AV, cropped to the image.
fn render_frame(r: &mut Renderer, gpu: &GpuContext, scene: &Scene, a: &EvalArgs, f: f32) -> Result<ImageBuf> {
    if r.settings.deep.uses_history() {
        r.render(gpu, scene, &cameras_at(scene, &a.scene, f - 1.0), f - 1.0)?;
    }
    r.render(gpu, scene, &cameras_at(scene, &a.scene, f), f)?;
    Ok(r.read_target(gpu, "ao")?)
}

/// The reference image for `description`, from the cache or computed (and stored).
fn cached(cache: &RefCache, refresh: bool, description: &str, compute: impl FnOnce() -> ImageBuf) -> Result<ImageBuf> {
    let key = RefCache::key(description);
    if !refresh {
        if let Some(img) = cache.load(&key) {
            tracing::info!("reference {key} from {}", cache.dir().display());
            return Ok(img);
        }
    }
    let img = compute();
    if let Err(e) = cache.store(&key, &img, description) {
        tracing::warn!("could not cache the reference: {e:#}");
    }
    Ok(img)
}

/// Identifies a scene's content at one frame for the cache key: name, triangle
/// and vertex counts, an FNV-1a hash of every vertex position and index, the
/// materials, the object transforms at `frame`, and the scene settings.
pub(crate) fn scene_fingerprint(scene: &Scene, frame: f32) -> String {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    let mut eat = |bytes: &[u8]| {
        for &b in bytes {
            h = (h ^ b as u64).wrapping_mul(0x0100_0000_01b3);
        }
    };
    for m in &scene.meshes {
        eat(bytemuck::cast_slice(&m.positions));
        eat(bytemuck::cast_slice(&m.indices));
        eat(&(m.material as u64).to_le_bytes());
    }
    for o in &scene.objects {
        eat(bytemuck::cast_slice(&o.transform_at(frame).to_cols_array()));
        eat(&(o.mesh as u64).to_le_bytes());
    }
    eat(format!("{:?}{:?}", scene.materials, scene.settings).as_bytes());
    format!("scene={} tris={} geometry={h:016x}", scene.name, scene.triangle_count(),)
}

/// Last frame's depth and AV at sub-pixel position (px, py): 1/z and AV
/// interpolated bilinearly between the four nearest texel centres (1/z is
/// exact on planes); `None` where any of the four has no surface.
fn reproject(csz: &ImageBuf, av: &ImageBuf, px: f32, py: f32) -> Option<(f32, f32)> {
    let (fx, fy) = (px - 0.5, py - 0.5);
    let (x0, y0) = (fx.floor(), fy.floor());
    let (tx, ty) = (fx - x0, fy - y0);
    let clampx = |x: f32| (x.max(0.0) as u32).min(csz.width - 1);
    let clampy = |y: f32| (y.max(0.0) as u32).min(csz.height - 1);
    let (mut inv, mut value) = (0.0f32, 0.0f32);
    for (dx, dy, w) in [
        (0.0, 0.0, (1.0 - tx) * (1.0 - ty)),
        (1.0, 0.0, tx * (1.0 - ty)),
        (0.0, 1.0, (1.0 - tx) * ty),
        (1.0, 1.0, tx * ty),
    ] {
        let (x, y) = (clampx(x0 + dx), clampy(y0 + dy));
        let z = csz.pixel(x, y)[0];
        if z <= 0.0 {
            return None;
        }
        inv += w / z;
        value += w * av.pixel(x, y)[0];
    }
    Some((1.0 / inv, value))
}

/// Temporal instability: mean |AV_t(p) − AV_{t−1}(p')| over pixels whose surface
/// reprojects (p' in frame t − 1, interpolated) onto the same surface, averaged
/// over consecutive frame pairs.
pub(crate) struct Flicker {
    pub mean: f64,
    pub frames: u32,
    pub valid_fraction: f64,
}

/// Flicker of channel 0 of target `target` rendered with `settings` along the
/// camera path from `--frame` (reprojection accepted within `threshold`).
pub(crate) fn flicker(
    gpu: &GpuContext,
    scene: &Scene,
    a: &EvalArgs,
    settings: RenderSettings,
    target: &str,
    threshold: f32,
    frames: u32,
) -> Result<Flicker> {
    let mut r = Renderer::new(gpu, scene, settings)?;
    let (w, h) = (a.scene.width, a.scene.height);
    let mut prev: Option<(Camera, ImageBuf, ImageBuf)> = None;
    let (mut sum, mut pairs, mut valid, mut counted) = (0.0f64, 0u32, 0u64, 0u64);
    // one warm-up frame so the first measured pair already has history
    let f0 = a.scene.frame;
    r.render(gpu, scene, &cameras_at(scene, &a.scene, f0 - 1.0), f0 - 1.0)?;
    for i in 0..frames {
        let f = f0 + i as f32;
        let cams = cameras_at(scene, &a.scene, f);
        r.render(gpu, scene, &cams, f)?;
        let av = r.read_target(gpu, target)?.channel(0);
        let csz = r.read_target(gpu, "csz")?;
        if let Some((pcam, pav, pcsz)) = &prev {
            let vp = pcam.view_projection(w as f32 / h as f32);
            let (mut d, mut n) = (0.0f64, 0u64);
            for y in 0..h {
                for x in 0..w {
                    let z = csz.pixel(x, y)[0];
                    if z <= 0.0 {
                        continue;
                    }
                    counted += 1;
                    let p = cams.current.eye + cams.current.pixel_dir(x, y, w, h) * z;
                    let clip = vp * p.extend(1.0);
                    if clip.w <= 0.0 {
                        continue;
                    }
                    let (px, py) = (
                        (clip.x / clip.w * 0.5 + 0.5) * w as f32,
                        (0.5 - 0.5 * clip.y / clip.w) * h as f32,
                    );
                    if !(px >= 0.0 && py >= 0.0 && px < w as f32 && py < h as f32) {
                        continue;
                    }
                    let Some((zq, prev_av)) = reproject(pcsz, pav, px, py) else {
                        continue;
                    };
                    if (zq - clip.w).abs() >= threshold {
                        continue;
                    }
                    d += (av.pixel(x, y)[0] - prev_av).abs() as f64;
                    n += 1;
                }
            }
            if n > 0 {
                sum += d / n as f64;
                pairs += 1;
            }
            valid += n;
        }
        prev = Some((cams.current, av, csz));
    }
    Ok(Flicker {
        mean: if pairs > 0 { sum / pairs as f64 } else { 0.0 },
        frames,
        valid_fraction: if counted > 0 {
            valid as f64 / counted as f64
        } else {
            0.0
        },
    })
}

fn write_ao_report(
    dir: &Path,
    a: &EvalArgs,
    main: &AoResult,
    one: Option<&AoResult>,
    ref_obscurance: &ImageBuf,
    ref_binary: &ImageBuf,
    numbers: &serde_json::Value,
) -> Result<()> {
    std::fs::create_dir_all(dir).map_err(|e| anyhow::anyhow!("--report {}: {e}", dir.display()))?;
    let k = a.deep.layers;
    let save = |img: &ImageBuf, name: &str| -> Result<ReportImage> {
        // AV and FLIP maps are display values: bytes written as is
        img.save(&dir.join(name), false).map_err(|e| anyhow::anyhow!(e))?;
        Ok(ReportImage {
            caption: String::new(),
            file: name.into(),
        })
    };
    let fig = |img: &ImageBuf, name: &str, caption: String| -> Result<ReportImage> {
        Ok(ReportImage {
            caption,
            ..save(img, name)?
        })
    };
    let s = &main.obscurance;
    let mut sections = vec![ReportSection {
        title: format!("{k}-layer deep-G-buffer AO against the ray-traced obscurance"),
        text: format!(
            "AV = 1 − AO (white = unoccluded), {}×{} pixels, frame {}. The reference evaluates DGB Eq. 2 with the same r, β, ε over every surface along each sample ray ({} spp, spiral radial density). Values are shown as grey bytes 255·AV; FLIP maps use the magma scale.",
            a.scene.width, a.scene.height, a.scene.frame, numbers["ref_spp"]
        ),
        images: vec![
            fig(&main.av, &format!("gpu-k{k}.png"), format!("GPU, k = {k}: FLIP {:.4}, MAE {:.4}", s.flip, s.mae))?,
            fig(ref_obscurance, "reference-obscurance.png", "reference: obscurance, all layers".into())?,
            fig(&main.obscurance_map, &format!("flip-k{k}.png"), format!("FLIP error, k = {k}"))?,
        ],
    }];
    if let Some(o) = one {
        sections.push(ReportSection {
            title: format!("1 layer vs {k} layers"),
            text:
                "Occluders hidden behind the first surface are only seen by later layers (DGB Eq. 1's max over layers)."
                    .into(),
            images: vec![
                fig(
                    &o.av,
                    "gpu-k1.png",
                    format!("GPU, k = 1: FLIP {:.4}, MAE {:.4}", o.obscurance.flip, o.obscurance.mae),
                )?,
                fig(
                    &main.av,
                    &format!("gpu-k{k}.png"),
                    format!("GPU, k = {k}: FLIP {:.4}, MAE {:.4}", s.flip, s.mae),
                )?,
                fig(&o.obscurance_map, "flip-k1.png", "FLIP error, k = 1".into())?,
                fig(
                    &main.obscurance_map,
                    &format!("flip-k{k}.png"),
                    format!("FLIP error, k = {k}"),
                )?,
            ],
        });
    }
    sections.push(ReportSection {
        title: "Against binary ambient visibility".into(),
        text: "Cosine-weighted hit/miss within r (a different quantity from Eq. 2's obscurance; shown for scale)."
            .into(),
        images: vec![
            fig(ref_binary, "reference-binary.png", "reference: binary AV".into())?,
            fig(
                &main.binary_map,
                &format!("flip-binary-k{k}.png"),
                format!("FLIP vs binary, k = {k}: {:.4}", main.binary.flip),
            )?,
        ],
    });
    write_report(
        dir,
        &format!("strata eval: AO on {}", a.scene.scene),
        &sections,
        numbers,
    )?;
    Ok(())
}
