//! Issue 16's validation matrix: every registered technique × preset × layer
//! count × deep-G-buffer variant, at 64×64 over three frames of the camera path
//! on `cornell` and `atrium`. Every frame renders without a wgpu validation
//! error (the renderer checks after each frame and returns it as an error),
//! every target (every array layer, every MIP level) holds only finite values,
//! and every debug view renders, finite. A technique joins the matrix by
//! registering in `strata_render::technique`, not by editing this test.

mod common;

use strata_render::frame::FrameCameras;
use strata_render::passes::deep_gbuffer::{DeepGBufferSettings, Variant};
use strata_render::passes::ils::GpuVpl;
use strata_render::technique::{registry, Range};
use strata_render::{GpuContext, RenderError, RenderSettings, Renderer};
use strata_scene::probes::IrradianceProbes;
use strata_scene::{procedural, ImageBuf, Scene};

/// Every valid (layers, variant): one layer has no variant; DELAY and PREDICT stop at two.
fn deep_configs() -> Vec<(u32, Variant)> {
    let mut v = vec![(1, Variant::Reproject)];
    for k in 2..=4 {
        for variant in Variant::ALL {
            let d = DeepGBufferSettings {
                layers: k,
                variant,
                ..Default::default()
            };
            if d.validate().is_ok() {
                v.push((k, variant));
            }
        }
    }
    v
}

/// A small probe grid with a sky-like constant irradiance (the CPU bake is
/// tested elsewhere; here the probes only have to flow through the passes).
fn probes(scene: &Scene) -> IrradianceProbes {
    let (lo, hi) = scene.bounds(0.0);
    let mut p = IrradianceProbes::grid(lo, hi, [2, 2, 2]);
    for c in &mut p.coeffs {
        c[0] = [0.3, 0.35, 0.4];
    }
    p
}

fn non_finite(img: &ImageBuf) -> usize {
    img.data.iter().filter(|v| !v.is_finite()).count()
}

/// Renders three frames and checks every target and debug view; returns the
/// number of images checked.
fn check(gpu: &GpuContext, scene: &Scene, settings: RenderSettings, declared: &[&str], what: &str) -> usize {
    let mut r = Renderer::new(gpu, scene, settings).unwrap_or_else(|e| panic!("{what}: renderer: {e}"));
    let frame: Vec<&str> = r.pass_infos().iter().map(|p| p.name).collect();
    for p in declared {
        assert!(
            frame.contains(p),
            "{what}: declared pass '{p}' is not in the frame {frame:?}"
        );
    }
    for f in 0..3 {
        let t = f as f32;
        r.render(gpu, scene, &FrameCameras::along_path(scene, t), t)
            .unwrap_or_else(|e| panic!("{what}: frame {f}: {e}"));
    }
    let mut checked = 0;
    for name in r.target_names() {
        let d = r.target_desc(name).expect("listed target");
        for layer in 0..d.layers {
            let img = r
                .read_target_layer(gpu, name, layer)
                .unwrap_or_else(|e| panic!("{what}: {name}[{layer}]: {e}"));
            assert_eq!(
                non_finite(&img),
                0,
                "{what}: target {name} layer {layer} has non-finite texels"
            );
            checked += 1;
        }
        for mip in 1..d.mips {
            let img = r
                .read_target_mip(gpu, name, mip)
                .unwrap_or_else(|e| panic!("{what}: {name} mip {mip}: {e}"));
            assert_eq!(
                non_finite(&img),
                0,
                "{what}: target {name} MIP {mip} has non-finite texels"
            );
            checked += 1;
        }
    }
    for view in r.debug_view_names() {
        let img = r
            .debug_view(gpu, &view, true)
            .unwrap_or_else(|e| panic!("{what}: debug view {view}: {e}"));
        assert_eq!(non_finite(&img), 0, "{what}: debug view {view} has non-finite values");
        checked += 1;
    }
    gpu.check_errors().unwrap_or_else(|e| panic!("{what}: read-back: {e}"));
    checked
}

/// The caller's VPLs for ILS (instant radiosity, default settings, frame 0).
fn scene_vpls(scene: &Scene) -> std::sync::Arc<[GpuVpl]> {
    strata_reference::Reference::new(scene, 0.0)
        .vpls(&Default::default())
        .iter()
        .map(|v| GpuVpl::new(v.position.into(), v.normal.into(), v.flux.into()))
        .collect()
}

/// Technique `t`'s settings with `preset` at 64×64 over the deep G-buffer `deep`, with the
/// caller's light probes and VPLs (generated once per scene) where it reads them.
fn configured(
    t: &strata_render::technique::Technique,
    preset: Option<&str>,
    deep: DeepGBufferSettings,
    scene: &Scene,
    vpls: &std::sync::Arc<[GpuVpl]>,
) -> RenderSettings {
    let base = RenderSettings {
        width: 64,
        height: 64,
        deep,
        ..Default::default()
    };
    let mut s = t.settings(&base, preset).expect("registered presets configure");
    if s.radiosity.is_some() {
        s.probes = Some(probes(scene));
    }
    if let Some(ils) = &mut s.ils {
        ils.vpls = vpls.clone();
    }
    s
}

#[test]
fn every_technique_preset_layer_count_and_variant_renders_cleanly() {
    let gpu = common::gpu();
    let configs = deep_configs();
    // k = 1, then 5 variants at k = 2 and the 3 multi-pass-capable ones at k = 3, 4
    assert_eq!(configs.len(), 1 + 5 + 3 + 3);
    let (mut runs, mut images) = (0, 0);
    for scene_name in ["cornell", "atrium"] {
        let scene = procedural::builtin(scene_name).expect("built-in scene");
        let vpls = scene_vpls(&scene);
        for t in registry() {
            let presets: Vec<Option<&str>> = if t.presets.is_empty() {
                vec![None]
            } else {
                t.presets.iter().map(|p| Some(*p)).collect()
            };
            for preset in presets {
                for &(layers, variant) in &configs {
                    let deep = DeepGBufferSettings {
                        layers,
                        variant,
                        ..Default::default()
                    };
                    let s = configured(t, preset, deep, &scene, &vpls);
                    let what = format!("{scene_name} {} {} k={layers} {variant}", t.name, preset.unwrap_or("-"));
                    images += check(&gpu, &scene, s, t.passes, &what);
                    runs += 1;
                }
            }
        }
    }
    let techniques: usize = registry().iter().map(|t| t.presets.len().max(1)).sum();
    assert_eq!(runs, 2 * techniques * configs.len());
    eprintln!("validation matrix: {runs} configurations × 3 frames, {images} images checked, 0 validation errors, 0 non-finite values");
}

/// Settings that switch a technique to another algorithm rather than another
/// preset (they add or replace passes): each must render cleanly too — no
/// validation error, finite targets and debug views — at one and two layers,
/// on both scenes.
#[test]
fn algorithm_switching_settings_render_cleanly() {
    const VARIANTS: &[(&str, &[(&str, &str)])] = &[
        ("bzb-ao", &[("splat", "dss")]),
        ("bzb-ao", &[("splat", "dss"), ("visibility", "off")]),
        ("bzb-gi", &[("visibility", "off")]),
        ("bzb-gi", &[("splat", "dss")]),
        ("bzb-gi", &[("splat", "dss"), ("visibility", "off")]),
        ("aba-ao", &[("kernel", "hbao-compute")]),
        ("aba-ao", &[("kernel", "hbao-compute"), ("multilayer", "off")]),
        ("ils", &[("split", "compute")]),
        ("ils", &[("split", "blocks"), ("shadows", "vpl")]),
        ("ils", &[("refine-peak", "0.2")]),
        ("ils", &[("refine-peak", "0.2"), ("shadows", "vpl"), ("refine", "0.5")]),
        ("full", &[("gather-scale", "2")]),
        ("ao", &[("ao-scale", "2")]),
        ("full", &[("ao-scale", "3"), ("ao-kernel", "compute")]),
        ("full", &[("gather-scale", "3"), ("indirect-kernel", "compute")]),
        // every screen pass in its compute form, as GPUs run them (`tests/kernels.rs`
        // compares the forms' values)
        (
            "full",
            &[
                ("ao-kernel", "compute"),
                ("indirect-kernel", "compute"),
                ("lighting-kernel", "compute"),
                ("reflection-kernel", "compute"),
            ],
        ),
    ];
    let gpu = common::gpu();
    let mut images = 0;
    for scene_name in ["cornell", "atrium"] {
        let scene = procedural::builtin(scene_name).expect("built-in scene");
        for &(technique, sets) in VARIANTS {
            let t = strata_render::technique::find(technique).expect("registered technique");
            for layers in [1, 2] {
                let base = RenderSettings {
                    width: 64,
                    height: 64,
                    deep: DeepGBufferSettings {
                        layers,
                        ..Default::default()
                    },
                    ..Default::default()
                };
                let mut s = t.settings(&base, None).expect("default settings");
                for &(name, text) in sets {
                    let info = t.setting_list().find(|i| i.name == name).expect("registered setting");
                    let value = info.parse_value(text).expect("valid value");
                    t.set(&mut s, name, value).expect("in range");
                }
                if let Some(ils) = &mut s.ils {
                    ils.vpls = scene_vpls(&scene);
                }
                let what = format!("{scene_name} {technique} {sets:?} k={layers}");
                images += check(&gpu, &scene, s, &[], &what);
            }
        }
    }
    assert!(images > 4 * VARIANTS.len(), "only {images} images checked");
    eprintln!(
        "algorithm settings: {} configurations, {images} images checked",
        2 * 2 * VARIANTS.len()
    );
}

/// Reduced-resolution layers (`DeepGBufferSettings::layer_scale`, DGB Fig. 11) under every
/// registered technique: the reduced targets, their upsampling and every pass that reads
/// the layers render cleanly, at an odd scale that does not divide the size (64 = 3·21 + 1).
#[test]
fn every_technique_renders_cleanly_with_reduced_layers() {
    let gpu = common::gpu();
    let mut runs = 0;
    for scene_name in ["cornell", "atrium"] {
        let scene = procedural::builtin(scene_name).expect("built-in scene");
        let vpls = scene_vpls(&scene);
        for t in registry() {
            for (layers, variant, layer_scale) in [(2, Variant::Reproject, 3), (3, Variant::Peel, 2)] {
                let deep = DeepGBufferSettings {
                    layers,
                    variant,
                    layer_scale,
                    ..Default::default()
                };
                let s = configured(t, None, deep, &scene, &vpls);
                let what = format!("{scene_name} {} k={layers} {variant} layer-scale {layer_scale}", t.name);
                check(&gpu, &scene, s, t.passes, &what);
                runs += 1;
            }
        }
    }
    assert_eq!(runs, 2 * 2 * registry().len());
}

/// The values at the ends of a declared range that a user can type (`Range::ends`),
/// and for an unbounded range a large one too (10³ × the lower end, at least 10³).
fn range_ends(range: Range, integer: bool) -> Vec<f64> {
    let mut v = range.ends(integer);
    if let Range::AtLeast(a) | Range::Above(a) = range {
        v.push((a * 1e3).max(1e3));
    }
    v
}

/// Every registered setting of every technique, alone at each end of its declared
/// range (`range_ends`), on top of the technique's defaults, two layers: the frame
/// renders twice (temporal filters see history) without a wgpu validation error and
/// the technique's output holds only finite values. A resource refusal before any GPU
/// work (an A-buffer pool over the adapter's largest buffer) is the one accepted error,
/// and it must name the limit. A new setting joins by registering.
#[test]
fn every_setting_renders_cleanly_at_both_ends_of_its_range() {
    let gpu = common::gpu();
    let scene = procedural::builtin("cornell").expect("built-in scene");
    let vpls = scene_vpls(&scene);
    let (mut rendered, mut refused) = (0, 0);
    for t in registry() {
        for info in t.setting_list() {
            for v in range_ends(info.range, info.integer) {
                let base = RenderSettings {
                    width: 32,
                    height: 32,
                    deep: DeepGBufferSettings {
                        layers: 2,
                        ..Default::default()
                    },
                    ..Default::default()
                };
                let mut s = t.settings(&base, None).expect("default settings");
                t.set(&mut s, info.name, v)
                    .unwrap_or_else(|e| panic!("{} {}={v}: the declared end is refused: {e}", t.name, info.name));
                if s.radiosity.is_some() {
                    s.probes = Some(probes(&scene));
                }
                if let Some(ils) = &mut s.ils {
                    ils.vpls = vpls.clone();
                }
                let what = format!("{} {}={v}", t.name, info.name);
                let mut r = match Renderer::new(&gpu, &scene, s) {
                    Ok(r) => r,
                    Err(e) => {
                        let text = e.to_string();
                        assert!(
                            !matches!(e, RenderError::Validation(_)) && text.contains("largest storage buffer"),
                            "{what}: renderer: {text}"
                        );
                        refused += 1;
                        continue;
                    }
                };
                for f in 0..2 {
                    let time = f as f32;
                    r.render(&gpu, &scene, &FrameCameras::along_path(&scene, time), time)
                        .unwrap_or_else(|e| panic!("{what}: frame {f}: {e}"));
                }
                let out = r
                    .read_target_full(&gpu, t.output, 0)
                    .unwrap_or_else(|e| panic!("{what}: {}: {e}", t.output));
                assert_eq!(non_finite(&out), 0, "{what}: {} has non-finite values", t.output);
                gpu.check_errors().unwrap_or_else(|e| panic!("{what}: read-back: {e}"));
                rendered += 1;
            }
        }
    }
    // at most the two A-buffer techniques' largest pool
    assert!(refused <= 2, "{refused} refusals");
    assert!(rendered > 200, "only {rendered} configurations rendered");
    eprintln!(
        "setting range ends: {rendered} configurations rendered cleanly, {refused} refused with a one-line error"
    );
}
