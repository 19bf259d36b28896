//! `strata render`.

use anyhow::Result;
use strata_render::{GpuContext, GpuOptions, RenderSettings, Renderer};

use strata_render::frame::FrameCameras;
use strata_scene::Scene;

use crate::args::{FrameArgs, RenderArgs};
use crate::output::{cameras_at, check_output, save, scene_and_camera};

/// The scene, its cameras and the render settings that `f` asks for (validated).
pub fn prepare(f: &FrameArgs) -> Result<(Scene, FrameCameras, RenderSettings)> {
    let (scene, cams) = scene_and_camera(&f.scene)?;
    let settings = settings_for(f, &scene)?;
    if let Some(w) = settings.cost_warning(&scene) {
        eprintln!("strata: warning: {w}");
    }
    Ok((scene, cams, settings))
}

/// The render settings that `f` asks for on the loaded `scene` (validated; probes baked
/// and VPLs generated where the technique uses them). `strata view` applies its panel
/// edits through this function too, so both accept and reject the same values.
pub fn settings_for(f: &FrameArgs, scene: &Scene) -> Result<RenderSettings> {
    let t = f.technique;
    let base = RenderSettings {
        width: f.scene.width,
        height: f.scene.height,
        deep: f.deep.settings(),
        guard_band: f.deep.guard_band,
        shadow: strata_render::passes::shadow::ShadowSettings {
            resolution: f.shadow_resolution,
            point_lights: f.point_shadows,
            unshadowed: f.no_shadow.clone(),
        },
        exposure: crate::args::ExposureArg::fixed(f.exposure),
        auto_exposure: crate::args::ExposureArg::auto(f.exposure),
        ao: Some(f.ao.settings()),
        ..Default::default()
    };
    // configure fails only on an unknown preset, or a preset for a technique that has none
    let mut settings = t
        .settings(&base, f.radiosity.preset.as_deref())
        .map_err(|e| anyhow::anyhow!("--preset: {e}"))?;
    if settings.radiosity.is_some() {
        // the preset, then the radiosity flags
        settings.radiosity = Some(f.radiosity.settings().map_err(|e| anyhow::anyhow!(e))?);
    }
    for (name, value) in &f.set.values {
        t.set(&mut settings, name, *value)
            .map_err(|e| anyhow::anyhow!("--set {name}={value}: {e}"))?;
    }
    settings.validate().map_err(|e| anyhow::anyhow!("{e}"))?;
    // blended with baked light probes (modulated by AO); baked only once the settings are
    // known to be valid, so a bad flag is a one-line error without a bake before it
    let cache = strata_eval::cache::RefCache::new(strata_eval::cache::RefCache::default_dir());
    if settings.radiosity.is_some() && !f.no_probes {
        settings.probes = Some(strata_eval::cache::probes::scene_probes(
            scene,
            f.radiosity.probe_bake(),
            &cache,
            false,
        )?);
    }
    // the reflection rays that find nothing on screen: a baked environment map (DGB §3.6)
    let mirrors = settings
        .reflections
        .is_some_and(|r| strata_eval::cache::environment::has_mirrors(scene, r.max_roughness));
    if mirrors && !f.no_probes {
        settings.environment = Some(strata_eval::cache::environment::scene_environment(
            scene, &cache, false,
        )?);
    }
    // ILS: VPLs by instant radiosity on the CPU, once per run (static scenes)
    strata_eval::vpls::add_vpls(&mut settings, scene, f.scene.frame);
    Ok(settings)
}

pub fn run(a: &RenderArgs) -> Result<()> {
    let f = &a.frame;
    let (scene, cams, settings) = prepare(f)?;
    for w in f.unread_flags(&settings, a.debug_view.is_some()) {
        eprintln!("strata: warning: {w}");
    }
    if a.list_lights {
        print_lights(&scene, &settings.shadow);
        return Ok(());
    }
    if let Some(out) = &a.out {
        check_output(out, a.force)?;
    }
    let gpu = GpuContext::new(&GpuOptions {
        adapter: f.gpu.adapter.clone(),
    })?;
    let mut r = Renderer::new(&gpu, &scene, settings)?;
    if a.list_passes {
        println!("frame of '{}' ({}):", scene.name, f.technique.name);
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
    let warmup = a
        .warmup
        .unwrap_or(if r.accumulates() {
            strata_render::ACCUMULATION_WARMUP
        } else {
            0
        })
        .max(r.settings.deep.uses_history() as u32);
    for i in (1..=warmup).rev() {
        let t = f.scene.frame - i as f32;
        r.render(&gpu, &scene, &cameras_at(&scene, &f.scene, t), t)?;
    }
    let t = r.render(&gpu, &scene, &cams, f.scene.frame)?;
    let (img, srgb) = match (&a.debug_view, exr) {
        (Some(v), _) => (r.debug_view(&gpu, v, exr)?, true),
        // EXR: the linear result
        (None, true) => (r.read_target(&gpu, f.technique.output)?, true),
        // PNG: tonemapped sRGB, or raw values (AO: byte = 255·AV)
        (None, false) => (r.read_target(&gpu, f.technique.display.0)?, f.technique.display.1),
    };

    // ldr/albedo are already linear after read-back decode; PNG re-encodes sRGB.
    save(&img, out, srgb)?;
    // A-buffer overflow (ABA): fragments dropped for lack of room are reported, never silent
    if let Some(a) = r.abuffer() {
        let lists = a.read_lists(&gpu)?;
        if lists.overflow > 0 {
            let room = match a.settings().slots() {
                0 => format!("pool {} nodes", a.pool()),
                k => format!("{k} slots per pixel"),
            };
            eprintln!(
                "A-buffer: dropped {} of {} fragments ({room}; {})",
                lists.overflow,
                lists.total,
                a.settings().overflow_hint()
            );
        }
    }
    if let Some(overflow) = r.dss_overflow(&gpu) {
        if let Some(message) = overflow? {
            eprintln!("warning: {message}");
        }
    }
    if a.timings {
        for (n, ms) in &t.passes {
            eprintln!("{n:<12} {ms:8.3} ms");
        }
        // BZB Table 2: DSS surfelization counts
        if let Some(c) = r.dss_counts(&gpu) {
            let c = c?;
            eprintln!(
                "dss surfelization: {} triangles, {} after frustum culling, {} after pre-tessellation, {} fine surfels, {} surfels",
                c.triangles_in, c.triangles_culled, c.subtriangles, c.fine_surfels, c.surfels
            );
        }
    }
    if r.settings.auto_exposure.is_some() {
        eprintln!("exposure (metered): {:.4}", r.displayed_exposure(&gpu)?);
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

/// `--list-lights`: one line per light and camera, in strata's units.
fn print_lights(scene: &strata_scene::Scene, shadow: &strata_render::passes::shadow::ShadowSettings) {
    let budget = shadow.point_lights;
    use strata_scene::Light;
    let v = |v: glam::Vec3| format!("({:.3}, {:.3}, {:.3})", v.x, v.y, v.z);
    println!("lights of '{}': {}", scene.name, scene.lights.len());
    let gpu_lights = strata_render::lights::gpu_lights_for(scene, 0.0, shadow);
    for (i, l) in scene.lights.iter().enumerate() {
        let shadowed = gpu_lights
            .get(i)
            .is_some_and(|g| g.kind[1] != strata_render::lights::NO_SHADOW);
        let line = match l {
            Light::Sun { direction, color, illuminance } => {
                format!("sun   direction {} color {color:?} illuminance {illuminance}", v(*direction))
            }
            Light::Point { position, color, intensity } => {
                format!("point position {} color {color:?} intensity {intensity}", v(*position))
            }
            Light::Spot { position, direction, color, intensity, inner_deg, outer_deg } => format!(
                "spot  position {} direction {} color {color:?} intensity {intensity} cone {inner_deg:.2}°..{outer_deg:.2}°",
                v(*position),
                v(*direction)
            ),
            Light::Rect { center, half_u, half_v, radiance } => format!(
                "rect  center {} half_u {} half_v {} radiance {radiance:?}",
                v(*center),
                v(*half_u),
                v(*half_v)
            ),
        };
        let why = if shadowed {
            ""
        } else if shadow.unshadowed.contains(&i) {
            " (no shadow: --no-shadow)"
        } else {
            " (no shadow)"
        };
        println!("  {i}: {line}{why}");
    }
    let unshadowed = strata_render::lights::unshadowed_point_lights(scene, budget);
    if unshadowed > 0 {
        println!("  {unshadowed} point light(s) unshadowed: only the {budget} most intense get cube shadow maps (--point-shadows)");
    }
    println!("cameras in the file: {}", scene.cameras.len());
    for (i, c) in scene.cameras.iter().enumerate() {
        println!("  {i}: eye {} target {} fov {:.2}°", v(c.eye), v(c.target), c.fov_y_deg);
    }
}
