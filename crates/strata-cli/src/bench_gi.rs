//! `strata bench ao` and `strata bench radiosity`: GPU time of the
//! deep-G-buffer AO or radiosity passes (DGB Table 4) per pass, and the paper's
//! "1st layer + 2nd layer" split: the technique's passes' time with k = 1 and
//! the increment of k layers over it.

use anyhow::{bail, Result};
use serde_json::json;
use strata_render::passes::deep_gbuffer::DeepGBufferSettings;
use strata_render::{GpuContext, GpuOptions, RenderSettings, Renderer};
use strata_scene::Scene;

use crate::args::{BenchAoArgs, BenchRadiosityArgs, BenchReflectionsArgs, SceneArgs};
use crate::bench::{median_min, wgpu_ts};
use crate::output::{cameras_at, scene_and_camera};

/// The AO stage's passes, in frame order.
pub const AO_PASSES: [&str; 5] = ["depth-mip", "ao", "ao-temporal", "ao-blur-h", "ao-blur-v"];

/// The radiosity stage's passes, in frame order (Table 4 includes the
/// spatial and temporal reconstruction).
pub const RADIOSITY_PASSES: [&str; 7] = [
    "depth-mip",
    "propagate",
    "radiosity",
    "indirect-temporal",
    "indirect-blur-h",
    "indirect-blur-v",
    "compose",
];

/// What one benchmark run measures.
struct Bench<'a> {
    name: &'static str,
    scene: &'a SceneArgs,
    frames: u32,
    layers: u32,
    passes: &'a [&'a str],
    /// Render settings for k layers.
    settings: Box<dyn Fn(u32) -> RenderSettings + 'a>,
    extra: serde_json::Value,
}

pub fn radiosity(a: &BenchRadiosityArgs) -> Result<()> {
    let rs = a.radiosity.settings().map_err(|e| anyhow::anyhow!(e))?;
    let extra = json!({"preset": a.radiosity.preset, "samples": rs.samples, "blur_taps": rs.blur.taps(),
        "normal_test": rs.normal_test, "min_mip": rs.min_mip, "variant": a.stage.variant.to_string()});
    run_bench(
        &a.stage.gpu.adapter,
        a.stage.json,
        Bench {
            name: "radiosity",
            scene: &a.stage.scene,
            frames: a.stage.frames,
            layers: a.stage.layers,
            passes: &RADIOSITY_PASSES,
            settings: Box::new(move |layers| RenderSettings {
                width: a.stage.scene.width,
                height: a.stage.scene.height,
                deep: DeepGBufferSettings {
                    layers,
                    variant: a.stage.variant,
                    ..Default::default()
                },
                radiosity: Some(rs.clone()),
                ..Default::default()
            }),
            extra,
        },
    )
}

/// Per-pass (name, median ms, min ms) over the timed frames, and the median
/// per-frame sum of the technique's passes.
struct Timing {
    passes: Vec<(String, f64, f64)>,
    total_median_ms: f64,
    total_min_ms: f64,
}

pub fn reflections(a: &BenchReflectionsArgs) -> Result<()> {
    let rs = strata_render::passes::reflections::ReflectionSettings {
        steps: a.steps,
        max_distance: a.max_distance,
        ..Default::default()
    };
    let extra = json!({"steps": rs.steps, "max_distance": rs.max_distance, "variant": a.stage.variant.to_string()});
    run_bench(
        &a.stage.gpu.adapter,
        a.stage.json,
        Bench {
            name: "reflections",
            scene: &a.stage.scene,
            frames: a.stage.frames,
            layers: a.stage.layers,
            passes: &["reflections"],
            settings: Box::new(move |layers| RenderSettings {
                width: a.stage.scene.width,
                height: a.stage.scene.height,
                deep: DeepGBufferSettings {
                    layers,
                    variant: a.stage.variant,
                    ..Default::default()
                },
                reflections: Some(rs),
                ..Default::default()
            }),
            extra,
        },
    )
}

pub fn ao(a: &BenchAoArgs) -> Result<()> {
    let s = a.ao.settings();
    let extra = json!({"samples": s.samples, "blur_taps": s.blur.taps(),
        "temporal_alpha": s.temporal.map_or(0.0, |t| t.alpha), "variant": a.stage.variant.to_string()});
    run_bench(
        &a.stage.gpu.adapter,
        a.stage.json,
        Bench {
            name: "ao",
            scene: &a.stage.scene,
            frames: a.stage.frames,
            layers: a.stage.layers,
            passes: &AO_PASSES,
            settings: Box::new(move |layers| RenderSettings {
                width: a.stage.scene.width,
                height: a.stage.scene.height,
                deep: DeepGBufferSettings {
                    layers,
                    variant: a.stage.variant,
                    ..Default::default()
                },
                shade: false,
                ao: Some(s.clone()),
                ..Default::default()
            }),
            extra,
        },
    )
}

fn run_bench(adapter: &Option<String>, as_json: bool, b: Bench) -> Result<()> {
    if !(1..=10000).contains(&b.frames) {
        bail!("--frames {} is out of range: must be in 1..=10000", b.frames);
    }
    if !(1..=4).contains(&b.layers) {
        bail!("--layers {} is out of range: must be in 1..=4", b.layers);
    }
    let (scene, _) = scene_and_camera(b.scene)?;
    let gpu = GpuContext::new(&GpuOptions {
        adapter: adapter.clone(),
    })?;
    if !gpu.has(wgpu_ts()) {
        bail!("the adapter lacks TIMESTAMP_QUERY / TIMESTAMP_QUERY_INSIDE_ENCODERS, which `strata bench` needs");
    }
    let k = measure(&gpu, &scene, &b, b.layers)?;
    let one = if b.layers > 1 {
        Some(measure(&gpu, &scene, &b, 1)?)
    } else {
        None
    };
    let first = one.as_ref().unwrap_or(&k).total_median_ms;
    let increment = k.total_median_ms - first;
    let rows = |t: &Timing| {
        t.passes
            .iter()
            .map(|(n, med, min)| json!({"name": n, "median_ms": med, "min_ms": min}))
            .collect::<Vec<_>>()
    };
    let sa = b.scene;
    if as_json {
        let mut v = json!({
            "bench": b.name,
            "scene": sa.scene, "width": sa.width, "height": sa.height, "frames": b.frames,
            "layers": b.layers,
            "triangles": scene.triangle_count(),
            "device": gpu.describe(),
            "passes": rows(&k),
            "total_median_ms": k.total_median_ms, "total_min_ms": k.total_min_ms,
            "layer1_ms": first, "increment_ms": increment,
        });
        if let (Some(o), Some(m)) = (&one, v.as_object_mut()) {
            m.insert("passes_layers_1".into(), json!(rows(o)));
        }
        if let (Some(m), Some(e)) = (v.as_object_mut(), b.extra.as_object()) {
            m.extend(e.clone());
        }
        println!("{}", serde_json::to_string(&v)?);
    } else {
        println!(
            "{} {} at {}x{}, k = {}, {} frames on {}",
            sa.scene,
            b.name,
            sa.width,
            sa.height,
            b.layers,
            b.frames,
            gpu.describe()
        );
        println!("{:<18} {:>10} {:>10}", "pass", "median ms", "min ms");
        for (n, med, min) in &k.passes {
            println!("{n:<18} {med:>10.3} {min:>10.3}");
        }
        println!(
            "{} total {:.3} ms = {first:.3} (1st layer) + {increment:.3} (layers 2..{})",
            b.name, k.total_median_ms, b.layers
        );
    }
    Ok(())
}

fn measure(gpu: &GpuContext, scene: &Scene, b: &Bench, layers: u32) -> Result<Timing> {
    let a = b.scene;
    let settings = (b.settings)(layers);
    let mut r = Renderer::new(gpu, scene, settings)?;
    let f0 = a.frame;
    // warm-up frame (pipelines, first-use allocations; gives the oracle and history)
    r.render(gpu, scene, &cameras_at(scene, a, f0 - 1.0), f0 - 1.0)?;
    let names: Vec<&str> = r
        .pass_infos()
        .iter()
        .map(|p| p.name)
        .filter(|n| b.passes.contains(n))
        .collect();
    let mut samples: Vec<Vec<f64>> = vec![Vec::new(); names.len()];
    let mut totals = Vec::new();
    for i in 0..b.frames {
        let f = f0 + i as f32;
        let t = r.render(gpu, scene, &cameras_at(scene, a, f), f)?;
        let mut sum = 0.0;
        for (k, n) in names.iter().enumerate() {
            let ms = t.get(n).unwrap_or(f64::NAN);
            samples[k].push(ms);
            sum += ms;
        }
        totals.push(sum);
    }
    let passes = names
        .iter()
        .zip(samples.iter_mut())
        .map(|(n, s)| {
            let (med, min) = median_min(s);
            (n.to_string(), med, min)
        })
        .collect();
    let (total_median_ms, total_min_ms) = median_min(&mut totals);
    Ok(Timing {
        passes,
        total_median_ms,
        total_min_ms,
    })
}
