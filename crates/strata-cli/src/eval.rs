//! `strata eval`: a GPU technique against the CPU ground truth (`strata_eval::eval`), printed as
//! one JSON object or a line of numbers.

use anyhow::Result;
use strata_eval::eval::{aba, ao, bzb, gi, ils, oit, views, EvalSettings};
use strata_eval::results::{to_json_string, EvalResult};

use strata_render::technique::EvalKind;

use crate::args::EvalArgs;

pub fn run(a: &EvalArgs) -> Result<()> {
    let s = EvalSettings::from(a);
    for w in a.unread_flags() {
        eprintln!("strata: warning: {w}");
    }
    // the registry's eval kind picks the comparison
    let is_bzb = a.technique.name == "bzb-ao";
    let is_aba = a.technique.name == "aba-ao";
    let is_bzb_gi = a.technique.name == "bzb-gi";
    if let (Some(p), true) = (&a.radiosity.preset, a.technique.presets.is_empty()) {
        anyhow::bail!("--preset: technique '{}' has no presets (got '{p}')", a.technique.name);
    }
    // flags that only the deep-G-buffer GI comparison reads: an error elsewhere, not ignored
    // (--views reads --probes-from too)
    if a.views || a.technique.eval != EvalKind::Radiance || is_bzb_gi {
        let gi_only = [
            ("--fig10", a.fig10),
            ("--oracle", a.oracle),
            ("--no-probes", a.no_probes),
            ("--probes-from", a.probes_from.is_some() && !a.views),
        ];
        if let Some((flag, _)) = gi_only.iter().find(|f| f.1) {
            anyhow::bail!("{flag} is only read by eval --technique gi or full (the deep-G-buffer radiosity against the path tracer, without --views)");
        }
    }
    // the warm-up along the camera path: the comparisons with a temporal filter (bzb-ao's
    // `--set alpha`, BZB §6's re-projection)
    // (DGB AO and bzb-ao; DGB radiosity and bzb-gi, whose `--set alpha` is BZB §6's
    // re-projection)
    let ao = a.technique.eval == EvalKind::AmbientVisibility && !is_aba;
    let radiance = a.technique.eval == EvalKind::Radiance;
    if a.moving && (a.views || !(ao || radiance)) {
        anyhow::bail!("--moving is only read by eval --technique gi, full, ao, bzb-ao or bzb-gi (the deep-G-buffer radiosity or AO, or the bounced z-buffer, along the camera path, without --views)");
    }
    // --layer-scale reduces layers >= 1: an error where no configuration builds one (ILS and
    // the OIT composite shade layer 0 alone; bzb-ao, aba-ao and bzb-gi compare against DGB
    // with 2 layers)
    let builds_second_layer = match a.technique.eval {
        EvalKind::VplRadiance | EvalKind::Composite => false,
        _ => is_bzb || is_aba || is_bzb_gi || a.deep.layers >= 2,
    };
    if a.deep.layer_scale > 1 && !builds_second_layer {
        if matches!(a.technique.eval, EvalKind::VplRadiance | EvalKind::Composite) {
            anyhow::bail!(
                "--layer-scale {}: eval --technique {} shades one layer and builds no second layer to reduce (--layer-scale must be 1)",
                a.deep.layer_scale,
                a.technique.name
            );
        }
        anyhow::bail!(
            "--layer-scale {}: eval --technique {} with --layers {} builds no second layer to reduce (it needs --layers 2..=4)",
            a.deep.layer_scale,
            a.technique.name,
            a.deep.layers
        );
    }
    if a.views {
        return views(a, &s);
    }
    if a.progressive.is_some() && a.technique.eval != EvalKind::VplRadiance {
        anyhow::bail!("--progressive is only read by --technique ils (ILS §6.3's physically-based mode)");
    }
    let result = match a.technique.eval {
        EvalKind::VplRadiance => EvalResult::Ils(ils::run(
            &s,
            a.radiosity.preset.as_deref(),
            &a.set.values,
            a.progressive.map(|k| (k, a.bounces)),
        )?),
        EvalKind::Composite => EvalResult::Oit(oit::run(&s, &a.set.values)?),
        // the registry's settings (--set), with --ao-radius/--ao-bias carried over
        EvalKind::AmbientVisibility if is_bzb || is_aba => {
            let mut rs = a
                .technique
                .settings(
                    &strata_render::RenderSettings {
                        ao: Some(a.ao.settings()),
                        ..Default::default()
                    },
                    None,
                )
                .map_err(|e| anyhow::anyhow!("{e}"))?;
            for (name, value) in &a.set.values {
                a.technique
                    .set(&mut rs, name, *value)
                    .map_err(|e| anyhow::anyhow!("--set {name}={value}: {e}"))?;
            }
            if is_aba {
                let ab = rs.abuffer.unwrap_or_default();
                EvalResult::AbaAo(aba::run(&s, &ab, &a.ao.settings())?)
            } else {
                let b = rs.bzb.unwrap_or_default();
                EvalResult::Bzb(bzb::run(&s, &b, &a.ao.settings())?)
            }
        }
        EvalKind::AmbientVisibility => {
            // the AO flags, then the registry's `--set` names (e.g. temporal-clamp)
            let mut render = strata_render::RenderSettings {
                ao: Some(a.ao.settings()),
                ..Default::default()
            };
            for (name, value) in &a.set.values {
                a.technique
                    .set(&mut render, name, *value)
                    .map_err(|e| anyhow::anyhow!("--set {name}={value}: {e}"))?;
            }
            EvalResult::Ao(ao::run(&s, &render.ao.expect("set above"))?)
        }
        EvalKind::None => unreachable!("the argument parser admits only comparable techniques"),
        EvalKind::Radiance if is_bzb_gi => {
            let rs = a.radiosity.settings().map_err(|e| anyhow::anyhow!(e))?;
            EvalResult::BzbGi(bzb::run_gi(&s, &a.set.values, &rs)?)
        }
        EvalKind::Radiance => {
            // the radiosity flags, then the registry's `--set` names (e.g. open-sky)
            let mut render = strata_render::RenderSettings {
                radiosity: Some(a.radiosity.settings().map_err(|e| anyhow::anyhow!(e))?),
                ..Default::default()
            };
            for (name, value) in &a.set.values {
                let had_ao = render.ao.is_some();
                a.technique
                    .set(&mut render, name, *value)
                    .map_err(|e| anyhow::anyhow!("--set {name}={value}: {e}"))?;
                // this comparison runs no AO: an AO setting, or how AO darkens the probes,
                // would change nothing
                if (!had_ao && render.ao.is_some()) || name == "probe-ao" {
                    anyhow::bail!(
                        "--set {name}: eval --technique {} compares the radiosity and probes without AO, so AO settings have no effect here (--views measures the frame with AO)",
                        a.technique.name
                    );
                }
            }
            let rs = render.radiosity.expect("set above");
            let g = gi::GiEvalSettings {
                bounces: a.bounces,
                fig10: a.fig10,
                oracle: a.oracle,
                probes: !a.no_probes,
                probes_from: a.probes_from.clone(),
                probe_bake: a.radiosity.probe_bake(),
            };
            EvalResult::Gi(gi::run(&s, &rs, &g)?)
        }
    };
    if let Some(dir) = &a.report {
        eprintln!("wrote {}", dir.join("index.html").display());
    }
    if a.json {
        println!("{}", to_json_string(&result)?);
        return Ok(());
    }
    let (run, k, (w, h)) = (result.run(), a.deep.layers, (a.scene.width, a.scene.height));
    match &result {
        EvalResult::Ao(e) => {
            let (o, b) = (&e.errors.obscurance, &e.errors.binary);
            println!(
                "{} ao k={k} {w}x{h}: FLIP {:.4}  RMSE {:.4}  MAE {:.4} (vs obscurance, {} spp, reference noise FLIP {:.4}); vs binary AO: FLIP {:.4}  MAE {:.4}",
                run.scene, o.flip, o.rmse, o.mae, run.ref_spp, noise(o), b.flip, b.mae
            );
            print_av_flicker(run);
        }
        EvalResult::Bzb(e) => {
            let line = |what: &str, x: &strata_eval::results::AoErrors| {
                println!(
                    "  {what:<28} vs binary AO: FLIP {:.4}  RMSE {:.4}  MAE {:.4}; vs obscurance: FLIP {:.4}  MAE {:.4}",
                    x.binary.flip, x.binary.rmse, x.binary.mae, x.obscurance.flip, x.obscurance.mae
                )
            };
            println!(
                "{} bzb-ao S={}{} {w}x{h} (reference {} spp, noise FLIP {:.4}):",
                run.scene,
                e.samples,
                match (e.temporal_alpha, e.warmup_frames) {
                    (Some(a), Some(n)) => format!(" temporal α={a} after {n} frames"),
                    _ => String::new(),
                },
                run.ref_spp,
                noise(&e.errors.binary)
            );
            line(
                if e.visibility == Some(false) {
                    "bzb-ao (visibility off)"
                } else {
                    "bzb-ao (bounced z-buffer)"
                },
                &e.errors,
            );
            if let Some(x) = &e.no_visibility {
                line("AOV, no visibility", x);
            }
            if let Some(x) = &e.dgb_2_layers {
                line("DGB AO, 2 layers", x);
            }
            print_av_flicker(run);
        }
        EvalResult::AbaAo(e) => {
            let line = |what: &str, x: &strata_eval::results::AoErrors| {
                println!(
                    "  {what:<28} vs obscurance: FLIP {:.4}  RMSE {:.4}  MAE {:.4}; vs binary AO: FLIP {:.4}  MAE {:.4}",
                    x.obscurance.flip, x.obscurance.rmse, x.obscurance.mae, x.binary.flip, x.binary.mae
                )
            };
            println!(
                "{} aba-ao N={} {w}x{h} (reference {} spp, noise FLIP {:.4}):",
                run.scene,
                e.samples,
                run.ref_spp,
                noise(&e.errors.obscurance)
            );
            line("aba-ao (multilayer)", &e.errors);
            if let Some(x) = &e.layers_1 {
                line("aba-ao (nearest layer only)", x);
            }
            if let Some(x) = &e.dgb_2_layers {
                line("DGB AO, 2 layers", x);
            }
        }
        EvalResult::Gi(e) => {
            let (i, f) = (&e.errors.indirect, &e.errors.full);
            println!(
                "{} gi k={k} {w}x{h}: indirect FLIP {:.4} RMSE {:.4} MAE {:.4} mean ×{:.3}; full FLIP {:.4} RMSE {:.4} (reference {} spp, {} bounces, noise FLIP {:.4} indirect / {:.4} full)",
                run.scene, i.flip, i.rmse, i.mae, i.mean_ratio.unwrap_or(f32::NAN), f.flip, f.rmse, run.ref_spp, e.ref_bounces, noise(i), noise(f)
            );
            if let Some(o) = &e.oracle {
                let twin = match o.probe_twin_error {
                    Some(e) => format!("; probe twin off by {:.2} %", 100.0 * e),
                    None => "; no probes".into(),
                };
                println!(
                    "  perfect gather (oracle, {} spp, noise FLIP {:.4}; r = {:.3}{twin}):",
                    o.noise.spp, o.noise.flip, o.radius,
                );
                for row in &o.by_layers {
                    println!(
                        "    k={}: c {:.3} ({:.3} within r); GPU's denoised RMSE {:.5}",
                        row.layers, row.confidence, row.confidence_within_radius, row.gpu_rmse_denoised
                    );
                    if let Some(g) = &row.gather {
                        let [r, gr, b] = g.irradiance_ratio;
                        println!(
                            "      the GPU's gather: c {:.3}; E_dgb / perfect Ê (R, G, B) {r:.3} {gr:.3} {b:.3} over {} px with c ≥ {}",
                            g.confidence, g.pixels, g.min_confidence
                        );
                    }
                    for x in &row.entries {
                        println!(
                            "      {:<8} {:<9} indirect FLIP {:.4} RMSE {:.5} (denoised {:.5}) mean ×{:.3}",
                            x.blend,
                            if x.within_radius { "within r" } else { "anywhere" },
                            x.errors.flip,
                            x.errors.rmse,
                            x.rmse_denoised,
                            x.errors.mean_ratio.unwrap_or(f32::NAN)
                        );
                    }
                }
            }
        }
        EvalResult::BzbGi(e) => {
            let line = |what: &str, x: &strata_eval::results::GiErrors| {
                println!(
                    "  {what:<28} indirect FLIP {:.4}  RMSE {:.4}  MAE {:.4}; full FLIP {:.4}  RMSE {:.4}",
                    x.indirect.flip, x.indirect.rmse, x.indirect.mae, x.full.flip, x.full.rmse
                )
            };
            println!(
                "{} bzb-gi S={} d_max={:.3}{} {w}x{h} (reference {} spp, 1 bounce, noise FLIP {:.4}); bzb-splat {:.0} ms with visibility, {:.0} ms without:",
                run.scene,
                e.directions,
                e.d_max,
                match (e.temporal_alpha, e.warmup_frames) {
                    (Some(a), Some(n)) => format!(" temporal α={a} after {n} frames"),
                    _ => String::new(),
                },
                run.ref_spp,
                noise(&e.errors.indirect),
                e.splat_ms,
                e.splat_ms_no_visibility
            );
            line("bzb-gi (bounced z-buffer)", &e.errors);
            line("no visibility (additive)", &e.no_visibility);
            line("DGB radiosity, 2 layers", &e.dgb_2_layers);
            if let Some(f) = &run.flicker {
                println!(
                    "flicker over {} frames: {:.5} (mean |ΔE| of the indirect irradiance's red channel after reprojection, {:.1} % of pixels valid)",
                    f.frames,
                    f.mean,
                    100.0 * f.valid_fraction
                );
            }
        }
        EvalResult::Oit(e) => {
            println!(
                "{} oit {} {w}x{h}: FLIP {:.4}  RMSE {:.4}  MAE {:.4} vs the CPU compositing; {} fragments ({} dropped, at most {} per pixel), A-buffer {:.1} MiB",
                run.scene,
                e.method,
                e.errors.flip,
                e.errors.rmse,
                e.errors.mae,
                e.fragments,
                e.dropped,
                e.max_fragments_per_pixel,
                e.memory_bytes as f64 / (1024.0 * 1024.0)
            );
        }
        EvalResult::Ils(e) => {
            let (i, f) = (&e.errors.indirect, &e.errors.full);
            println!(
                "{} ils {} {} VPLs shadows={} preset={} {w}x{h}: vs brute force FLIP {:.4} RMSE {:.4} (indirect FLIP {:.4} RMSE {:.4}); vs path tracer indirect FLIP {:.4} RMSE {:.4}, full FLIP {:.4} RMSE {:.4} (brute force: indirect FLIP {:.4}, full FLIP {:.4}; reference {} spp, 1 bounce, noise FLIP {:.4})",
                run.scene, e.pattern, e.vpls, e.shadows, e.preset, e.flip_vs_brute, e.rmse_vs_brute, e.indirect_flip_vs_brute,
                e.indirect_rmse_vs_brute, i.flip, i.rmse, f.flip, f.rmse, e.brute_force.indirect.flip,
                e.brute_force.full.flip, run.ref_spp, noise(i)
            );
            if let Some(r) = e.refined_share {
                println!(
                    "  ils-refine shaded {:.1} % of the pixels again (refine {}, refine-roughness {}, refine-peak {})",
                    100.0 * r,
                    e.refine,
                    e.refine_roughness,
                    e.refine_peak
                );
            }
            if let Some(p) = &e.progressive {
                for q in &p.patterns {
                    match (q.frames_to_target, q.gpu_ms_to_target, q.vpl_ms_to_target) {
                        (Some(k), Some(g), Some(v)) => println!(
                            "  §6.3 {}: < {:.0} % RMS after {k} frames: {g:.0} ms GPU + {v:.0} ms VPL generation ({:.0} ms GPU per frame)",
                            q.pattern, 100.0 * p.target_rms, q.gpu_ms_per_frame
                        ),
                        _ => println!(
                            "  §6.3 {}: {:.0} % RMS not reached in {} frames (last {:.4})",
                            q.pattern,
                            100.0 * p.target_rms,
                            p.sets,
                            q.rms_curve.last().map_or(f64::NAN, |c| c.1)
                        ),
                    }
                    println!(
                        "  §6.3 {}: one set {:.4} relative RMS → {} frames to < {:.0} % of the expectation ≈ {:.1} s GPU ({:.1} s with a static view) + {:.1} s VPL generation (predicted)",
                        q.pattern,
                        q.per_set_rel_rms,
                        q.predicted_frames_to_target,
                        100.0 * p.target_rms,
                        q.predicted_gpu_ms_to_target / 1e3,
                        q.predicted_static_view_gpu_ms_to_target / 1e3,
                        q.predicted_vpl_ms_to_target / 1e3
                    );
                }
                let d = &p.converged_vs_path_tracer;
                println!(
                    "  §6.3 converged ({} sets x {} paths, {} bounces) vs path tracer: FLIP {:.4}  RMSE {:.4}  MAE {:.4} ({} spp)",
                    p.sets, p.vpl_paths, p.bounces, d.flip, d.rmse, d.mae, p.ref_spp
                );
            }
        }
    }
    Ok(())
}

/// The reference noise (ꟻLIP between its halves) beside an error.
fn noise(e: &strata_eval::metrics::ErrorStats) -> f32 {
    e.ref_noise.map_or(f32::NAN, |n| n.flip)
}

/// `--views`: `render --technique full`'s settings (preset, radiosity flags, probes) at the
/// evaluated camera, measured by [`views::run`].
fn views(a: &EvalArgs, s: &EvalSettings) -> Result<()> {
    if a.technique.eval != EvalKind::Radiance {
        anyhow::bail!("--views is only read by --technique full (the probe/blended views)");
    }
    let (scene, _) = s.scene.load()?;
    let base = strata_render::RenderSettings {
        width: a.scene.width,
        height: a.scene.height,
        deep: a.deep.settings(),
        guard_band: a.deep.guard_band,
        ao: Some(a.ao.settings()),
        ..Default::default()
    };
    let mut settings = a
        .technique
        .settings(&base, a.radiosity.preset.as_deref())
        .map_err(|e| anyhow::anyhow!("--preset: {e}"))?;
    settings.radiosity = Some(a.radiosity.settings().map_err(|e| anyhow::anyhow!(e))?);
    for (name, value) in &a.set.values {
        a.technique
            .set(&mut settings, name, *value)
            .map_err(|e| anyhow::anyhow!("--set {name}={value}: {e}"))?;
    }
    settings.validate().map_err(|e| anyhow::anyhow!("{e}"))?;
    let cache = strata_eval::cache::RefCache::new(&s.cache);
    // the reflections' environment map, as `render` bakes it
    if settings
        .reflections
        .is_some_and(|r| strata_eval::cache::environment::has_mirrors(&scene, r.max_roughness))
    {
        settings.environment = Some(strata_eval::cache::environment::scene_environment(
            &scene,
            &cache,
            !s.progress,
        )?);
    }
    // the probes of another scene (`--probes-from`): a bake that has not seen a change
    let source = match &a.probes_from {
        Some(other) => strata_scene::load_scene(other).map_err(|e| anyhow::anyhow!("--probes-from: {e}"))?,
        None => scene,
    };
    settings.probes = Some(strata_eval::cache::probes::scene_probes(
        &source,
        a.radiosity.probe_bake(),
        &cache,
        !s.progress,
    )?);
    let mut e = views::run(s, settings)?;
    e.probes_from = a.probes_from.clone();
    if a.json {
        println!("{}", to_json_string(&e)?);
        return Ok(());
    }
    for v in &e.views {
        println!(
            "{:<14} clipped {:6.2} %  mean {:6.1}/255  outliers {}",
            v.view,
            100.0 * v.clip_fraction,
            v.mean,
            v.outliers
        );
    }
    println!("path-traced frame: outliers {}", e.reference_outliers);
    println!(
        "|blended - probe-only| {:.2}/255, mean confidence {:.3}",
        e.blended_vs_probe_only, e.mean_confidence
    );
    println!(
        "FLIP against the path-traced frame: blended {:.4}  probe-only {:.4}  gbuffer-only {:.4}",
        e.flip_blended, e.flip_probe_only, e.flip_gbuffer_only
    );
    for r in &e.regions {
        println!(
            "region {:<12} {:5} px  chroma reference {:5.2}  probe-only {:5.2}  blended {:5.2}  gbuffer-only {:5.2}; (a*,b*) error probe-only {:5.2}  blended {:5.2}  gbuffer-only {:5.2}; |blended - probe-only| {:5.2}/255  confidence {:.3}",
            r.name, r.pixels, r.chroma_reference, r.chroma_probe_only, r.chroma_blended, r.chroma_gbuffer_only,
            r.ab_error_probe_only, r.ab_error_blended, r.ab_error_gbuffer_only, r.blended_vs_probe_only, r.confidence
        );
    }
    Ok(())
}

/// `--frames`: the AV's flicker along the camera path (ao, bzb-ao).
fn print_av_flicker(run: &strata_eval::results::EvalRun) {
    if let Some(f) = &run.flicker {
        println!(
            "flicker over {} frames: {:.5} (mean |ΔAV| after reprojection, {:.1} % of pixels valid)",
            f.frames,
            f.mean,
            100.0 * f.valid_fraction
        );
    }
}
