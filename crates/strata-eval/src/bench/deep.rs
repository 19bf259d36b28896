//! `strata bench deep-gbuffer`: DGB Table 5 (layer times per construction
//! method) and Fig. 3 (second-layer surfaces that differ from the exact peel of
//! the same frame, along the camera path).

use std::path::Path;

use std::path::PathBuf;

use anyhow::{bail, Result};
use strata_render::passes::deep_gbuffer::{DeepGBufferSettings, LayerComparison, Submission, Variant};
use strata_render::{GpuContext, RenderSettings, Renderer};
use strata_scene::ImageBuf;

use super::{bench_run, check_frames, timing_gpu};
use crate::files::{check_output_for, save};
use crate::results::{DeepBench, DeepRow};
use crate::scene::SceneSpec;
use crate::stats::median_min;

/// What to compare.
#[derive(Clone, Debug)]
pub struct DeepSettings {
    pub scene: SceneSpec,
    pub adapter: Option<String>,
    /// Frames along the camera path to time and compare (after one warm-up frame), 1..=10000.
    pub frames: u32,
    /// Deep G-buffer layers k, 2..=4 (delay and predict run only for k = 2).
    pub layers: u32,
    /// Minimum separation Δz in scene units (default: the scene's).
    pub min_separation: Option<f32>,
    /// Resolution divisor s of layers ≥ 1 for every method (DGB Fig. 11), 1..=4.
    pub layer_scale: u32,
    /// Write Fig. 3-style images into this folder.
    pub images: Option<PathBuf>,
    /// Overwrite existing images.
    pub force: bool,
}

/// One construction method being measured.
struct Method {
    name: &'static str,
    renderer: Renderer,
    /// Single-pass variants: the same variant forced into one multiview pass
    /// (timed only; see `deep_gbuffer::Submission`).
    multiview: Option<Renderer>,
    multiview_totals: Vec<f64>,
    /// Per frame: (first layer ms, whole construction ms).
    times: Vec<(f64, f64)>,
    /// Per frame: the reduced layers' upsampling ms (`layer_scale` > 1).
    upsample: Vec<f64>,
    mismatched: u64,
    counted: u64,
}

pub fn run(a: &DeepSettings) -> Result<DeepBench> {
    check_frames(a.frames)?;
    if !(2..=strata_render::passes::deep_gbuffer::MAX_LAYERS).contains(&a.layers) {
        bail!("--layers {} is out of range: must be in 2..=4", a.layers);
    }
    let (scene, _) = a.scene.load()?;
    if let Some(dir) = &a.images {
        for m in Variant::ALL {
            check_output_for("--images", &dir.join(format!("{m}-layer1.png")), a.force)?;
            if m != Variant::Peel {
                check_output_for("--images", &dir.join(format!("{m}-diff.png")), a.force)?;
            }
        }
    }
    let gpu = timing_gpu(&a.adapter)?;
    let settings = |layers: u32, variant: Variant, submission: Submission| RenderSettings {
        width: a.scene.width,
        height: a.scene.height,
        deep: DeepGBufferSettings {
            layers,
            variant,
            min_separation: a.min_separation,
            submission,
            layer_scale: if layers >= 2 { a.layer_scale } else { 1 },
        },
        shade: false,
        ..Default::default()
    };
    let mut methods = vec![Method {
        name: "single-layer",
        renderer: Renderer::new(&gpu, &scene, settings(1, Variant::Reproject, Submission::Auto))?,
        multiview: None,
        multiview_totals: Vec::new(),
        times: Vec::new(),
        upsample: Vec::new(),
        mismatched: 0,
        counted: 0,
    }];
    for v in Variant::ALL {
        if v.has_predicted_view() && a.layers != 2 {
            continue;
        }
        let default = Renderer::new(&gpu, &scene, settings(a.layers, v, Submission::Auto))?;
        // a reduced layer needs per-layer submission: no multiview twin
        let multiview = (v.is_single_pass()
            && a.layer_scale == 1
            && default.settings.deep.submission_on(&gpu) != Submission::Multiview)
            .then(|| Renderer::new(&gpu, &scene, settings(a.layers, v, Submission::Multiview)))
            .transpose()?;
        methods.push(Method {
            name: v.name(),
            renderer: default,
            multiview,
            multiview_totals: Vec::new(),
            times: Vec::new(),
            upsample: Vec::new(),
            mismatched: 0,
            counted: 0,
        });
    }

    let f0 = a.scene.frame;
    let last = f0 + (a.frames - 1) as f32;
    // Frame f0 − 1 is the warm-up (and gives the single-pass variants their first oracle).
    for i in -1..a.frames as i32 {
        let f = f0 + i as f32;
        let cams = a.scene.cameras_at(&scene, f);
        let mut peel_layer1: Option<ImageBuf> = None;
        for m in methods.iter_mut() {
            let t = m.renderer.render(&gpu, &scene, &cams, f)?;
            let mv = match &mut m.multiview {
                Some(r) => Some(r.render(&gpu, &scene, &cams, f)?),
                None => None,
            };
            if i < 0 {
                continue;
            }
            let first = t.get("gbuffer").unwrap_or(f64::NAN);
            m.times.push((first, geometry_ms(&t)));
            m.upsample.push(
                t.passes
                    .iter()
                    .filter(|(n, _)| n.ends_with("-upsample"))
                    .map(|(_, ms)| ms)
                    .sum(),
            );
            if let Some(mv) = mv {
                m.multiview_totals.push(geometry_ms(&mv));
            }
            if m.name == "single-layer" {
                continue;
            }
            let z1 = m.renderer.read_target_layer(&gpu, "csz", 1)?;
            if m.name == "peel" {
                peel_layer1 = Some(z1);
                continue;
            }
            let exact = peel_layer1.as_ref().expect("peel runs before the single-pass methods");
            let c = LayerComparison::new(&z1.data, &exact.data);
            m.mismatched += c.mismatched;
            m.counted += c.counted;
            if let (Some(dir), true) = (&a.images, f == last) {
                write_images(&gpu, &m.renderer, dir, m.name, Some(&c))?;
            }
        }
        if let (Some(dir), true) = (&a.images, f == last) {
            let peel = methods
                .iter()
                .find(|m| m.name == "peel")
                .expect("peel is always measured");
            write_images(&gpu, &peel.renderer, dir, "peel", None)?;
        }
    }

    // Single-layer times of the same frames: the first-layer cost every method is compared with.
    let mut single: Vec<f64> = methods[0].times.iter().map(|t| t.1).collect();
    let (single_med, _) = median_min(&mut single);
    let mut rows = Vec::new();
    for m in &methods {
        let mut totals: Vec<f64> = m.times.iter().map(|t| t.1).collect();
        let (total, _) = median_min(&mut totals);
        let (layer1, layer2) = match m.name {
            "single-layer" => (single_med, 0.0),
            "peel" => {
                let mut firsts: Vec<f64> = m.times.iter().map(|t| t.0).collect();
                let mut seconds: Vec<f64> = m.times.iter().map(|t| t.1 - t.0).collect();
                (median_min(&mut firsts).0, median_min(&mut seconds).0)
            }
            _ => (single_med, total - single_med),
        };
        let mismatch = if m.counted == 0 {
            0.0
        } else {
            100.0 * m.mismatched as f64 / m.counted as f64
        };
        let mut mv: Vec<f64> = m.multiview_totals.clone();
        let multiview_total = (!mv.is_empty()).then(|| median_min(&mut mv).0);
        let mut up = m.upsample.clone();
        let upsample = (m.renderer.settings.deep.is_reduced()).then(|| median_min(&mut up).0);
        let submission = if m.renderer.settings.deep.submission_on(&gpu) == Submission::Multiview {
            "multiview"
        } else {
            "per-layer"
        };
        rows.push((
            m.name,
            layer1,
            layer2,
            total,
            mismatch,
            multiview_total,
            upsample,
            submission,
        ));
    }

    Ok(DeepBench {
        run: bench_run(&a.scene, a.frames, &scene, &gpu),
        layers: a.layers,
        layer_scale: a.layer_scale,
        rows: rows
            .iter()
            .map(|&(m, l1, l2, t, mm, mv, up, sub)| DeepRow {
                method: m.into(),
                layer1_ms: l1,
                layer2_ms: l2,
                total_ms: t,
                mismatch_pct: mm,
                submission: sub.into(),
                multiview_total_ms: mv,
                multiview_layer2_ms: mv.map(|mv| mv - l1),
                upsample_ms: up,
            })
            .collect(),
    })
}

/// GPU time of a frame's G-buffer construction: every geometry pass (layer 0,
/// peels, per-layer submissions, the predicted-layer oracle, or the one
/// multiview pass), not packing, history or shading.
fn geometry_ms(t: &strata_render::PassTimings) -> f64 {
    t.passes
        .iter()
        .filter(|(n, _)| {
            n == "gbuffer" || n == "deep_gbuffer" || n == "oracle" || n.starts_with("peel") || n.starts_with("layer")
        })
        .map(|(_, ms)| ms)
        .sum()
}

/// Fig. 3 images of one method at the last frame: its layer-1 albedo and, with
/// a comparison, the differences from the peel in red over grey layer-1 depth.
fn write_images(gpu: &GpuContext, r: &Renderer, dir: &Path, name: &str, diff: Option<&LayerComparison>) -> Result<()> {
    let albedo = r.debug_view(gpu, "layer1-albedo", false)?;
    save(&albedo, &dir.join(format!("{name}-layer1.png")), true)?;
    if let Some(c) = diff {
        let z = r.debug_view(gpu, "layer1-csz", false)?;
        let mut img = ImageBuf::new(z.width, z.height, 3);
        for (i, px) in img.data.chunks_exact_mut(3).enumerate() {
            if c.mask[i] {
                px.copy_from_slice(&[1.0, 0.0, 0.0]);
            } else {
                let g = 0.15 + 0.6 * z.data[i];
                px.copy_from_slice(&[g, g, g]);
            }
        }
        save(&img, &dir.join(format!("{name}-diff.png")), true)?;
    }
    Ok(())
}
