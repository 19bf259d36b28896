//! `strata bench`: runs a benchmark of `strata_eval::bench` and prints its result as one JSON
//! object or a table.

use anyhow::Result;
use strata_eval::bench::{abuffer, ao, bzb, deep, display, gbuffer, ils, radiosity, reference, reflections, technique};
use strata_eval::results::{to_json_string, BenchResult, DeepBench, GbufferBench, ReferenceBench, StageBench};
use strata_render::passes::reflections::ReflectionSettings;

use crate::args::{BenchArgs, BenchStageArgs, BenchWhat};

/// One warning line per deep-G-buffer flag given to a bench that times no second layer.
fn warn_unread_layers(stage: &BenchStageArgs, bench: &str, why: &str) {
    for (id, long) in [("layers", "--layers"), ("variant", "--variant")] {
        if stage.given.iter().any(|g| g == id) {
            eprintln!("strata: warning: {long} is not read by bench {bench}: {why}");
        }
    }
}

pub fn run(a: &BenchArgs) -> Result<()> {
    match &a.what {
        BenchWhat::Ils(b) => warn_unread_layers(&b.stage, "ils", "ILS shades layer 0 alone"),
        BenchWhat::Abuffer(b) => warn_unread_layers(
            &b.stage,
            "abuffer",
            "the A-buffer keeps every fragment, with no deep G-buffer",
        ),
        BenchWhat::Bzb(b) => warn_unread_layers(
            &b.stage,
            "bzb",
            "it times the bounced z-buffer with one deep-G-buffer layer",
        ),
        _ => {}
    }
    let (result, json) = match &a.what {
        BenchWhat::Gbuffer(b) => (BenchResult::Gbuffer(gbuffer::run(&b.into())?), b.json),
        BenchWhat::Display(b) => (BenchResult::Display(display::run(&b.into())?), b.json),
        BenchWhat::DeepGbuffer(b) => (BenchResult::DeepGbuffer(deep::run(&b.into())?), b.json),
        BenchWhat::Reference(b) => (
            BenchResult::Reference(reference::run(&(&b.scene).into(), b.mrays)?),
            b.json,
        ),
        BenchWhat::Ao(b) => (
            BenchResult::Ao(ao::run(&(&b.stage).into(), &b.ao.settings())?),
            b.stage.json,
        ),
        BenchWhat::Radiosity(b) => {
            let rs = b.radiosity.settings().map_err(|e| anyhow::anyhow!(e))?;
            let r = radiosity::run(&(&b.stage).into(), b.radiosity.radiosity_preset(), &rs)?;
            (BenchResult::Radiosity(r), b.stage.json)
        }
        BenchWhat::Technique(b) => {
            let r = technique::run(&(&b.stage).into(), b.technique, b.preset.as_deref(), &b.set.values)?;
            (BenchResult::Technique(r), b.stage.json)
        }
        BenchWhat::Ils(b) => (
            BenchResult::Ils(Box::new(ils::run(
                &(&b.stage).into(),
                b.preset.as_deref(),
                &b.set.values,
            )?)),
            b.stage.json,
        ),
        BenchWhat::Abuffer(b) => (
            BenchResult::Abuffer(Box::new(abuffer::run(&(&b.stage).into(), &b.set.values)?)),
            b.stage.json,
        ),
        BenchWhat::Bzb(b) => (
            BenchResult::Bzb(Box::new(bzb::run(&(&b.stage).into(), &b.technique, &b.set.values)?)),
            b.stage.json,
        ),
        BenchWhat::Reflections(b) => {
            let rs = ReflectionSettings {
                steps: b.steps,
                max_distance: b.max_distance,
                ..Default::default()
            };
            let r = reflections::run(&(&b.stage).into(), &rs)?;
            (BenchResult::Reflections(r), b.stage.json)
        }
    };
    if json {
        println!("{}", to_json_string(&result)?);
        return Ok(());
    }
    match &result {
        BenchResult::Gbuffer(g) => print_gbuffer(g),
        BenchResult::Display(d) => {
            let r = &d.run;
            println!(
                "{} ({} target '{}') at {}x{}, {} frames on {}",
                r.scene, d.technique, d.target, r.width, r.height, r.frames, r.device
            );
            println!("{:<34} {:>10} {:>10}", "frame to window texture", "median ms", "min ms");
            println!(
                "{:<34} {:>10.3} {:>10.3}",
                "read back, to_rgba8, upload", d.readback_median_ms, d.readback_min_ms
            );
            println!("{:<34} {:>10.3} {:>10.3}", "GPU encoder", d.gpu_median_ms, d.gpu_min_ms);
            println!("GPU encoder {:.2}x faster (median)", d.speedup);
        }
        BenchResult::DeepGbuffer(d) => print_deep(d, frame_of(a)),
        BenchResult::Reference(r) => print_reference(r),
        BenchResult::Ao(s) | BenchResult::Radiosity(s) | BenchResult::Reflections(s) => print_stage(result.name(), s),
        BenchResult::Technique(s) => {
            let name = s
                .settings
                .get("technique")
                .and_then(|v| v.as_str())
                .unwrap_or("technique");
            print_stage(name, s)
        }
        BenchResult::Abuffer(b) => {
            let ms = |v: Option<f64>| v.map_or("–".to_string(), |x| format!("{x:.3}"));
            println!(
                "{:<19} {:>9} {:>9} {:>10} {:>9} {:>9} {:>9} {:>9} {:>9} {:>10} {:>10} {:>8}",
                "ABA Table I",
                "clear",
                "count",
                "prefix sum",
                "draw",
                "resolve",
                "AO",
                "AO blur",
                "total",
                "MiB",
                "fragments",
                "dropped"
            );
            for key in abuffer::KEYS.iter().chain(&abuffer::TABLE3_KEYS) {
                let Some(m) = b.methods.get(*key) else { continue };
                println!(
                    "{key:<19} {:>9} {:>9} {:>10} {:>9} {:>9} {:>9} {:>9} {:>9.3} {:>10.1} {:>10} {:>8}",
                    ms(m.clear_ms),
                    ms(m.count_ms),
                    ms(m.prefix_sum_ms),
                    ms(m.draw_ms),
                    ms(m.resolve_ms),
                    ms(m.ao_ms),
                    ms(m.ao_blur_ms),
                    m.total_ms,
                    m.memory_bytes as f64 / (1024.0 * 1024.0),
                    m.fragments,
                    m.dropped
                );
            }
            if let (Some(s), Some(f)) = (b.ao_speedup, b.ao_flip_compressed_vs_brute) {
                println!("multilayer AO, compressed vs brute force (linked list): {s:.2}x faster, FLIP {f:.4} between the AO images");
            }
        }
        BenchResult::Bzb(b) => {
            let t = &b.technique;
            print_stage(&format!("{t} (bounced z-buffer)"), &b.visibility);
            let baseline = if b.dss.is_some() {
                format!("{t} visibility=off (additive shell splatting)")
            } else {
                format!("{t} visibility=off (additive baseline)")
            };
            print_stage(&baseline, &b.no_visibility);
            println!(
                "visibility step: splat {:.2}x, whole technique {:.2}x the baseline; {} triangles, S = {}, {:.1} MiB",
                b.splat_ratio,
                b.total_ratio,
                b.triangles,
                b.directions,
                b.memory_bytes as f64 / (1024.0 * 1024.0)
            );
            if let Some(d) = &b.dss {
                let mib = |x: u64| x as f64 / (1024.0 * 1024.0);
                for (name, t) in [
                    ("bounced z-buffer", &d.stages),
                    ("additive (no visibility)", &d.stages_no_visibility),
                ] {
                    println!(
                        "DSS Table 1, {name}: surfelization {:.1} ms (tessellate {:.1}, fine {:.1}, filter {:.1}, shade {:.1}), shuffling {:.1}, splatting {:.1}, unshuffling {:.1}, reduction {:.1}, blurring {:.1}, total {:.1} ms",
                        t.surfelization_ms, t.tessellate_ms, t.fine_ms, t.filter_ms, t.shade_ms, t.shuffling_ms, t.splatting_ms, t.unshuffling_ms, t.reduction_ms, t.blurring_ms, t.total_ms
                    );
                }
                let c = &d.counts;
                println!(
                    "DSS Table 2: {} triangles, {} after frustum culling, {} after pre-tessellation, {} fine surfels, {} surfels (l_max = {}, surfel {} px, d_max {:.4})",
                    c.triangles_in, c.triangles_culled, c.subtriangles, c.fine_surfels, c.surfels, d.levels, d.surfel_px, d.d_max
                );
                let m = &d.memory;
                println!(
                    "DSS Table 3: shuffled positions {:.1} MiB, shuffled directions {:.1} MiB, layered framebuffer {:.1} MiB, layout {:.1} MiB, surfel buffers {:.1} MiB",
                    mib(m.shuffled_positions), mib(m.shuffled_directions), mib(m.layered_framebuffer), mib(m.framebuffer_layout), mib(m.surfels)
                );
            }
        }
        BenchResult::Ils(b) => {
            print_stage("ils (IS)", &b.interleaved);
            print_stage("ils (no IS: brute force)", &b.brute_force);
            println!(
                "speed-up (ILS Table 4): {:.2}x over the indirect passes, {:.2}x for the shading alone ({} VPL paths)",
                b.speedup, b.shading_speedup, b.vpls_generated
            );
        }
    }
    Ok(())
}

fn frame_of(a: &BenchArgs) -> f32 {
    match &a.what {
        BenchWhat::DeepGbuffer(b) => b.scene.frame,
        _ => 0.0,
    }
}

fn print_gbuffer(g: &GbufferBench) {
    let r = &g.run;
    println!(
        "{} at {}x{}, {} triangles, {} frames on {}",
        r.scene, r.width, r.height, r.triangles, r.frames, r.device
    );
    println!("{:<10} {:>10} {:>10}", "pass", "median ms", "min ms");
    for p in &g.passes {
        println!("{:<10} {:>10.3} {:>10.3}", p.name, p.median_ms, p.min_ms);
    }
    println!("{:<10} {:>10.3} {:>10.3}", "total", g.total_median_ms, g.total_min_ms);
    if r.shadow_maps_cached {
        println!("(no object moves: the shadow maps are drawn in the warm-up frame and kept, so `shadow` is ~0)");
    }
}

fn print_stage(name: &str, s: &StageBench) {
    let r = &s.run;
    println!(
        "{} {name} at {}x{}, k = {}, {} frames on {}",
        r.scene, r.width, r.height, s.layers, r.frames, r.device
    );
    println!("{:<18} {:>10} {:>10}", "pass", "median ms", "min ms");
    for p in &s.passes {
        println!("{:<18} {:>10.3} {:>10.3}", p.name, p.median_ms, p.min_ms);
    }
    println!("{}", s.split_line(name));
    let forms: Vec<String> = [
        ("ao_kernel", "AO pass"),
        ("indirect_kernel", "radiosity gather and blurs"),
        ("lighting_kernel", "lighting"),
        ("reflection_kernel", "reflections"),
    ]
    .iter()
    .filter_map(|(key, what)| {
        s.settings
            .get(*key)
            .and_then(|v| v.as_str())
            .map(|v| format!("{what}: {v}"))
    })
    .collect();
    if !forms.is_empty() {
        println!(
            "({}; --set ao-kernel / indirect-kernel / lighting-kernel / reflection-kernel choose)",
            forms.join(", ")
        );
    }
    let reduced: Vec<String> = [("ao_scale", "AO pass"), ("gather_scale", "radiosity gather")]
        .iter()
        .filter_map(|(key, what)| {
            let s = s.settings.get(*key)?.as_u64().filter(|&v| v > 1)?;
            Some(format!("{what} at 1/{s}"))
        })
        .collect();
    if !reduced.is_empty() {
        println!(
            "({} resolution, upsampled; --set ao-scale / gather-scale choose)",
            reduced.join(", ")
        );
    }
    if s.settings.get("vpl_shadow_maps_cached") == Some(&serde_json::Value::Bool(true)) {
        println!("(the VPLs and the scene hold still: the VPL shadow maps are drawn in the warm-up frame and kept, so `ils-vpl-shadows` is ~0; --set vpl-shadow-cache=0 times their redraw)");
    }
}

fn print_deep(d: &DeepBench, f0: f32) {
    let r = &d.run;
    let scale = match d.layer_scale {
        1 => String::new(),
        s => format!(" (layers >= 1 at 1/{s} resolution)"),
    };
    println!(
        "{} at {}x{}, {} layers{scale}, {} triangles, {} frames from frame {} on {}",
        r.scene, r.width, r.height, d.layers, r.triangles, r.frames, f0, r.device
    );
    println!(
        "{:<13} {:>10} {:>10} {:>12} {:>10} {:>8} {:>10} {:>14}",
        "method", "layer1 ms", "layer2 ms", "upsample ms", "total ms", "l2/l1", "mismatch %", "multiview ms"
    );
    let or_dash = |v: Option<f64>| v.map(|v| format!("{v:.3}")).unwrap_or_else(|| "-".into());
    for row in &d.rows {
        println!(
            "{:<13} {:>10.3} {:>10.3} {:>12} {:>10.3} {:>8.2} {:>10.3} {:>14}",
            row.method,
            row.layer1_ms,
            row.layer2_ms,
            or_dash(row.upsample_ms),
            row.total_ms,
            row.layer2_ms / row.layer1_ms,
            row.mismatch_pct,
            or_dash(row.multiview_total_ms)
        );
    }
    if d.layer_scale > 1 {
        println!("(every method ran one submission per layer, as a reduced layer needs; layer2 ms includes the upsampling of the reduced layers into the full-resolution arrays, which also checks every method's layer against this frame's layer 0 as the peel does)");
    } else {
        println!("(peel, and single-pass methods with a multiview column, ran one submission per layer)");
    }
}

fn print_reference(r: &ReferenceBench) {
    println!(
        "{}: {} triangles, BVH {:.2} s; {:.1} M rays (primary + 1 diffuse bounce) in {:.2} s on {} threads = {:.2} M rays/s",
        r.scene,
        r.triangles,
        r.bvh_build_s,
        r.rays as f64 * 1e-6,
        r.seconds,
        r.threads,
        r.mrays_per_s
    );
}
