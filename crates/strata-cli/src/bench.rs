//! `strata bench`: GPU timestamp benchmarks and reference throughput.

use anyhow::Result;
use serde_json::json;
use strata_render::{GpuContext, GpuOptions, RenderSettings, Renderer};

use crate::args::{BenchArgs, BenchGbufferArgs, BenchWhat};
use crate::output::{cameras_at, scene_and_camera};

pub fn run(a: &BenchArgs) -> Result<()> {
    match &a.what {
        BenchWhat::Gbuffer(b) => gbuffer(b),
        BenchWhat::DeepGbuffer(b) => crate::bench_deep::run(b),
        BenchWhat::Reference(b) => crate::reference::bench(b),
        BenchWhat::Ao(b) => crate::bench_gi::ao(b),
        BenchWhat::Radiosity(b) => crate::bench_gi::radiosity(b),
        BenchWhat::Reflections(b) => crate::bench_gi::reflections(b),
    }
}

/// Median and minimum of a sample.
pub fn median_min(v: &mut [f64]) -> (f64, f64) {
    v.sort_by(|a, b| a.total_cmp(b));
    let n = v.len();
    let med = if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    };
    (med, v[0])
}

fn gbuffer(a: &BenchGbufferArgs) -> Result<()> {
    if !(1..=10000).contains(&a.frames) {
        anyhow::bail!("--frames {} is out of range: must be in 1..=10000", a.frames);
    }
    let (scene, _) = scene_and_camera(&a.scene)?;
    let gpu = GpuContext::new(&GpuOptions {
        adapter: a.gpu.adapter.clone(),
    })?;
    if !gpu.has(wgpu_ts()) {
        anyhow::bail!(
            "the adapter lacks TIMESTAMP_QUERY / TIMESTAMP_QUERY_INSIDE_ENCODERS, which `strata bench` needs"
        );
    }
    let settings = RenderSettings {
        width: a.scene.width,
        height: a.scene.height,
        ..Default::default()
    };
    let mut r = Renderer::new(&gpu, &scene, settings)?;
    // Warm-up frame (pipeline creation, first-use allocations).
    let f0 = a.scene.frame;
    r.render(&gpu, &scene, &cameras_at(&scene, &a.scene, f0), f0)?;
    let names: Vec<&str> = r.pass_infos().iter().map(|p| p.name).collect();
    let mut samples: Vec<Vec<f64>> = vec![Vec::new(); names.len()];
    let mut totals = Vec::new();
    for i in 0..a.frames {
        let f = a.scene.frame + i as f32;
        let t = r.render(&gpu, &scene, &cameras_at(&scene, &a.scene, f), f)?;
        for (k, n) in names.iter().enumerate() {
            samples[k].push(t.get(n).unwrap_or(f64::NAN));
        }
        totals.push(t.total());
    }
    let rows: Vec<_> = names
        .iter()
        .zip(samples.iter_mut())
        .map(|(n, s)| {
            let (med, min) = median_min(s);
            (n.to_string(), med, min)
        })
        .collect();
    let (tmed, tmin) = median_min(&mut totals);
    if a.json {
        let v = json!({
            "bench": "gbuffer",
            "scene": a.scene.scene, "width": a.scene.width, "height": a.scene.height, "frames": a.frames,
            "triangles": scene.triangle_count(),
            "device": gpu.describe(),
            "passes": rows.iter().map(|(n, med, min)| json!({"name": n, "median_ms": med, "min_ms": min})).collect::<Vec<_>>(),
            "total_median_ms": tmed, "total_min_ms": tmin,
        });
        println!("{}", serde_json::to_string(&v)?);
    } else {
        println!(
            "{} at {}x{}, {} triangles, {} frames on {}",
            a.scene.scene,
            a.scene.width,
            a.scene.height,
            scene.triangle_count(),
            a.frames,
            gpu.describe()
        );
        println!("{:<10} {:>10} {:>10}", "pass", "median ms", "min ms");
        for (n, med, min) in &rows {
            println!("{n:<10} {med:>10.3} {min:>10.3}");
        }
        println!("{:<10} {:>10.3} {:>10.3}", "total", tmed, tmin);
    }
    Ok(())
}

pub fn wgpu_ts() -> strata_render::gpu::Features {
    strata_render::gpu::Features::TIMESTAMP_QUERY | strata_render::gpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS
}
