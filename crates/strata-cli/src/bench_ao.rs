//! `strata bench ao`: GPU time of the deep-G-buffer AO passes (DGB Table 4's
//! AO column) per pass, and the paper's "1st layer + 2nd layer" split: the AO
//! passes' time with k = 1 and the increment of k layers over it.

use anyhow::{bail, Result};
use serde_json::json;
use strata_render::passes::deep_gbuffer::DeepGBufferSettings;
use strata_render::{GpuContext, GpuOptions, RenderSettings, Renderer};
use strata_scene::Scene;

use crate::args::BenchAoArgs;
use crate::bench::{median_min, wgpu_ts};
use crate::output::{cameras_at, scene_and_camera};

/// The AO stage's passes, in frame order.
pub const AO_PASSES: [&str; 5] = ["depth-mip", "ao", "ao-temporal", "ao-blur-h", "ao-blur-v"];

/// Per-pass (name, median ms, min ms) over the timed frames, and the median
/// per-frame sum of the AO passes.
struct Timing {
    passes: Vec<(String, f64, f64)>,
    ao_median_ms: f64,
    ao_min_ms: f64,
}

pub fn run(a: &BenchAoArgs) -> Result<()> {
    if !(1..=10000).contains(&a.frames) {
        bail!("--frames {} is out of range: must be in 1..=10000", a.frames);
    }
    if !(1..=4).contains(&a.layers) {
        bail!("--layers {} is out of range: must be in 1..=4", a.layers);
    }
    let (scene, _) = scene_and_camera(&a.scene)?;
    let gpu = GpuContext::new(&GpuOptions {
        adapter: a.gpu.adapter.clone(),
    })?;
    if !gpu.has(wgpu_ts()) {
        bail!("the adapter lacks TIMESTAMP_QUERY / TIMESTAMP_QUERY_INSIDE_ENCODERS, which `strata bench` needs");
    }
    let k = measure(&gpu, &scene, a, a.layers)?;
    let one = if a.layers > 1 {
        Some(measure(&gpu, &scene, a, 1)?)
    } else {
        None
    };
    let first = one.as_ref().unwrap_or(&k).ao_median_ms;
    let increment = k.ao_median_ms - first;
    let rows = |t: &Timing| {
        t.passes
            .iter()
            .map(|(n, med, min)| json!({"name": n, "median_ms": med, "min_ms": min}))
            .collect::<Vec<_>>()
    };
    if a.json {
        let s = a.ao.settings();
        let mut v = json!({
            "bench": "ao",
            "scene": a.scene.scene, "width": a.scene.width, "height": a.scene.height, "frames": a.frames,
            "layers": a.layers, "variant": a.variant.to_string(), "samples": s.samples,
            "blur_taps": s.blur.taps(), "temporal_alpha": s.temporal.map_or(0.0, |t| t.alpha),
            "triangles": scene.triangle_count(),
            "device": gpu.describe(),
            "passes": rows(&k),
            "ao_total_median_ms": k.ao_median_ms, "ao_total_min_ms": k.ao_min_ms,
            "layer1_ms": first, "increment_ms": increment,
        });
        if let Some(o) = &one {
            v["passes_layers_1"] = json!(rows(o));
        }
        println!("{}", serde_json::to_string(&v)?);
    } else {
        println!(
            "{} AO at {}x{}, k = {}, {} frames on {}",
            a.scene.scene,
            a.scene.width,
            a.scene.height,
            a.layers,
            a.frames,
            gpu.describe()
        );
        println!("{:<12} {:>10} {:>10}", "pass", "median ms", "min ms");
        for (n, med, min) in &k.passes {
            println!("{n:<12} {med:>10.3} {min:>10.3}");
        }
        println!(
            "AO total {:.3} ms = {first:.3} (1st layer) + {increment:.3} (layers 2..{})",
            k.ao_median_ms, a.layers
        );
    }
    Ok(())
}

fn measure(gpu: &GpuContext, scene: &Scene, a: &BenchAoArgs, layers: u32) -> Result<Timing> {
    let settings = RenderSettings {
        width: a.scene.width,
        height: a.scene.height,
        deep: DeepGBufferSettings {
            layers,
            variant: a.variant,
            ..Default::default()
        },
        shade: false,
        ao: Some(a.ao.settings()),
        ..Default::default()
    };
    let mut r = Renderer::new(gpu, scene, settings)?;
    let f0 = a.scene.frame;
    // warm-up frame (pipelines, first-use allocations; gives the oracle and history)
    r.render(gpu, scene, &cameras_at(scene, &a.scene, f0 - 1.0), f0 - 1.0)?;
    let names: Vec<&str> = r
        .pass_infos()
        .iter()
        .map(|p| p.name)
        .filter(|n| AO_PASSES.contains(n))
        .collect();
    let mut samples: Vec<Vec<f64>> = vec![Vec::new(); names.len()];
    let mut totals = Vec::new();
    for i in 0..a.frames {
        let f = f0 + i as f32;
        let t = r.render(gpu, scene, &cameras_at(scene, &a.scene, f), f)?;
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
    let (ao_median_ms, ao_min_ms) = median_min(&mut totals);
    Ok(Timing {
        passes,
        ao_median_ms,
        ao_min_ms,
    })
}
