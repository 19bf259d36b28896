//! `strata render`.

use anyhow::Result;
use strata_render::{GpuContext, GpuOptions, RenderSettings, Renderer};

use strata_render::frame::FrameCameras;
use strata_scene::Scene;

use crate::args::{FrameArgs, RenderArgs, Technique};
use crate::output::{cameras_at, check_output, save, scene_and_camera};

/// The scene, its cameras and the render settings that `f` asks for (validated).
pub fn prepare(f: &FrameArgs) -> Result<(Scene, FrameCameras, RenderSettings)> {
    let (scene, cams) = scene_and_camera(&f.scene)?;
    let radiosity = match f.technique {
        Technique::Full => Some(f.radiosity.settings().map_err(|e| anyhow::anyhow!(e))?),
        _ => None,
    };
    // the full image: radiosity blended with baked light probes (modulated by AO), reflections
    let probes = match f.technique {
        Technique::Full if !f.no_probes => Some(strata_eval::cache::probes::scene_probes(
            &scene,
            &strata_eval::cache::RefCache::new(strata_eval::cache::RefCache::default_dir()),
            false,
        )?),
        _ => None,
    };
    let settings = RenderSettings {
        width: f.scene.width,
        height: f.scene.height,
        deep: f.deep.settings(),
        guard_band: f.deep.guard_band,
        shadow: strata_render::passes::shadow::ShadowSettings {
            resolution: f.shadow_resolution,
        },
        exposure: f.exposure,
        // AO alone needs no lighting passes
        shade: f.technique != Technique::Ao,
        ao: (f.technique != Technique::Direct).then(|| f.ao.settings()),
        probes,
        reflections: (f.technique == Technique::Full).then(Default::default),
        radiosity,
        ..Default::default()
    };
    settings.validate().map_err(|e| anyhow::anyhow!("{e}"))?;
    Ok((scene, cams, settings))
}

pub fn run(a: &RenderArgs) -> Result<()> {
    let f = &a.frame;
    let (scene, cams, settings) = prepare(f)?;
    if let Some(out) = &a.out {
        check_output(out, a.force)?;
    }
    let gpu = GpuContext::new(&GpuOptions {
        adapter: f.gpu.adapter.clone(),
    })?;
    let mut r = Renderer::new(&gpu, &scene, settings)?;
    if a.list_passes {
        println!("frame of '{}' ({:?}):", scene.name, f.technique);
        for p in r.pass_infos() {
            println!(
                "  {:<12} reads [{}] writes [{}]",
                p.name,
                p.inputs.join(", "),
                p.outputs.join(", ")
            );
        }
        println!("debug views: {}", r.debug_view_names().join(", "));
        return Ok(());
    }
    let out = a.out.as_ref().expect("clap requires --out");
    let exr = out.extension().is_some_and(|e| e.eq_ignore_ascii_case("exr"));
    if let Some(v) = &a.debug_view {
        if !r.debug_view_names().iter().any(|n| n == v) {
            anyhow::bail!(
                "--debug-view '{v}' is unknown: valid views are {}",
                r.debug_view_names().join(", ")
            );
        }
    }
    // Frames before the output one: single-pass layers test against last
    // frame's depths, temporal filters and progressive bounces accumulate.
    let warmup = a.warmup.max(r.settings.deep.uses_history() as u32);
    for i in (1..=warmup).rev() {
        let t = f.scene.frame - i as f32;
        r.render(&gpu, &scene, &cameras_at(&scene, &f.scene, t), t)?;
    }
    let t = r.render(&gpu, &scene, &cams, f.scene.frame)?;
    let (img, srgb) = match (&a.debug_view, f.technique, exr) {
        (Some(v), _, _) => (r.debug_view(&gpu, v, exr)?, true),
        // AV itself: PNG byte = 255·AV (no transfer function), EXR linear
        (None, Technique::Ao, _) => (r.read_target(&gpu, "ao")?, false),
        (None, Technique::Direct, true) => (r.read_target(&gpu, "hdr")?, true),
        (None, Technique::Full, true) => (r.read_target(&gpu, "hdr-reflected")?, true),
        (None, _, false) => (r.read_target(&gpu, "ldr")?, true),
    };
    // ldr/albedo are already linear after read-back decode; PNG re-encodes sRGB.
    save(&img, out, srgb)?;
    if a.timings {
        for (n, ms) in &t.passes {
            eprintln!("{n:<12} {ms:8.3} ms");
        }
    }
    eprintln!(
        "wrote {} ({}x{}, {} triangles)",
        out.display(),
        f.scene.width,
        f.scene.height,
        scene.triangle_count()
    );
    Ok(())
}
