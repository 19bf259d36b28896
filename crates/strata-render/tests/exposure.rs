//! Auto-exposure (`passes::exposure`, not in the papers): the metered exposure against its
//! CPU twin, its invariance to the lights' scale, and its adaptation over frames.

mod common;

use strata_render::frame::FrameCameras;
use strata_render::passes::exposure::{bin_of, metered_exposure, AutoExposure, BINS};
use strata_render::{GpuContext, RenderSettings, Renderer};
use strata_scene::{procedural, ImageBuf, Light, Scene};

fn auto(a: AutoExposure) -> RenderSettings {
    RenderSettings {
        width: 160,
        height: 120,
        auto_exposure: Some(a),
        ..Default::default()
    }
}

fn frame(gpu: &GpuContext, r: &mut Renderer, scene: &Scene, cam: strata_scene::camera::Camera) -> (ImageBuf, f32) {
    r.render(gpu, scene, &FrameCameras::fixed(cam), 0.0).unwrap();
    gpu.check_errors().expect("no wgpu validation errors");
    (r.read_target(gpu, "hdr").unwrap(), r.displayed_exposure(gpu).unwrap())
}

/// Every light, the sky, the ambient term and the emission × k.
fn brighter(scene: &Scene, k: f32) -> Scene {
    let mut s = scene.clone();
    for l in &mut s.lights {
        match l {
            Light::Sun { illuminance: v, .. }
            | Light::Point { intensity: v, .. }
            | Light::Spot { intensity: v, .. } => *v *= k,
            Light::Rect { radiance, .. } => radiance.iter_mut().for_each(|c| *c *= k),
        }
    }
    s.settings.sky.iter_mut().for_each(|c| *c *= k);
    s.settings.ambient.iter_mut().for_each(|c| *c *= k);
    s.materials
        .iter_mut()
        .for_each(|m| m.emission.iter_mut().for_each(|c| *c *= k));
    s
}

/// The GPU's histogram is the CPU's of the read-back `hdr` inside the guard band (but for
/// pixels whose log2 luminance lies on a bin edge), and its exposure the CPU twin's; the
/// tonemapper uses it.
#[test]
fn metered_exposure_matches_its_cpu_twin() {
    let gpu = common::gpu();
    for (name, guard) in [("cornell", 0), ("atrium", 0), ("atrium", 12)] {
        let scene = procedural::builtin(name).unwrap();
        let a = AutoExposure::default();
        let settings = RenderSettings {
            guard_band: strata_render::renderer::GuardBand::Pixels(guard),
            ..auto(a)
        };
        let mut r = Renderer::new(&gpu, &scene, settings).unwrap();
        let (hdr, e) = frame(&gpu, &mut r, &scene, scene.camera);
        let mut cpu = vec![0u32; BINS];
        for c in hdr.data.chunks_exact(hdr.channels as usize) {
            cpu[bin_of([c[0], c[1], c[2]])] += 1;
        }
        let gpu_hist = r.exposure_histogram(&gpu).unwrap().expect("auto exposure");
        let moved: u32 = cpu.iter().zip(&gpu_hist).map(|(a, b)| a.abs_diff(*b)).sum();
        let (e_cpu, lbar) = metered_exposure(&hdr.data, hdr.channels as usize, &a);
        eprintln!(
            "{name}, guard band {guard}: exposure GPU {e} CPU {e_cpu} (L̄ {lbar}); histogram differs by {moved} counts"
        );
        assert_eq!(
            gpu_hist.iter().sum::<u32>(),
            160 * 120,
            "{name}: the guard band was metered"
        );
        assert!(moved <= 2 * (hdr.data.len() as u32 / 4) / 1000, "{name}: {moved}");
        assert!((e / e_cpu - 1.0).abs() < 2e-3, "{name}: GPU {e}, CPU {e_cpu}");
        assert!(
            e != scene.settings.exposure,
            "{name}: the metered exposure is the scene's"
        );
        // ldr = ACES(exposure · hdr), read back linear
        let ldr = r.read_target(&gpu, "ldr").unwrap();
        let worst = hdr
            .data
            .chunks_exact(4)
            .zip(ldr.data.chunks_exact(4))
            .flat_map(|(h, l)| (0..3).map(move |c| (strata_render::passes::tonemap::tonemap(h[c], e) - l[c]).abs()))
            .fold(0.0f32, f32::max);
        assert!(
            worst < 0.01,
            "{name}: ldr is not tonemapped with the metered exposure ({worst})"
        );
    }
}

/// With every light and the sky 16× brighter (4 stops: 16 bins exactly), the metered
/// exposure is 16× smaller and the displayed image the same; a fixed exposure shows the
/// change.
#[test]
fn auto_exposure_cancels_a_brighter_scene() {
    let gpu = common::gpu();
    let scene = procedural::builtin("atrium").unwrap();
    let bright = brighter(&scene, 16.0);
    let a = AutoExposure::default();
    let ldr = |s: &Scene, settings: RenderSettings| {
        let mut r = Renderer::new(&gpu, s, settings).unwrap();
        let (_, e) = frame(&gpu, &mut r, s, s.camera);
        (r.read_target(&gpu, "ldr").unwrap(), e)
    };
    let (base, e) = ldr(&scene, auto(a));
    let (same, e16) = ldr(&bright, auto(a));
    assert!((e / e16 / 16.0 - 1.0).abs() < 1e-4, "exposures {e} and {e16}");
    let differ = |x: &ImageBuf, y: &ImageBuf| {
        x.data
            .iter()
            .zip(&y.data)
            .filter(|(p, q)| (*p - *q).abs() > 1.5 / 255.0)
            .count()
    };
    assert_eq!(differ(&base, &same), 0, "the displayed image changed");
    let fixed = RenderSettings {
        auto_exposure: None,
        exposure: Some(e),
        ..auto(a)
    };
    let (f1, _) = ldr(&scene, fixed.clone());
    let (f16, _) = ldr(&bright, fixed);
    assert!(
        differ(&f1, &f16) > f1.data.len() / 10,
        "a fixed exposure shows the brighter scene"
    );
}

/// With adaptation α the exposure moves from the last frame's by α of the way in log2
/// towards the new image's; after a cut (`reset_history`) it takes the new one at once.
#[test]
fn exposure_adapts_in_log_space() {
    let gpu = common::gpu();
    let scene = procedural::builtin("atrium").unwrap();
    let a = AutoExposure {
        adaptation: 0.25,
        ..AutoExposure::default()
    };
    let mut r = Renderer::new(&gpu, &scene, auto(a)).unwrap();
    let bright_view = scene.camera;
    // towards the shaded colonnade
    let mut dark_view = scene.camera;
    dark_view.target = dark_view.eye + glam::Vec3::new(-0.2, -0.3, -1.0);
    let (hdr0, e0) = frame(&gpu, &mut r, &scene, bright_view);
    let t0 = metered_exposure(&hdr0.data, 4, &a).0;
    assert!(
        (e0 / t0 - 1.0).abs() < 2e-3,
        "the first frame takes its own exposure: {e0} vs {t0}"
    );
    let (hdr1, e1) = frame(&gpu, &mut r, &scene, dark_view);
    let t1 = metered_exposure(&hdr1.data, 4, &a).0;
    assert!(
        (t1.log2() - t0.log2()).abs() > 0.5,
        "the two views meter alike: {t0}, {t1}"
    );
    let want = (t0.log2() + 0.25 * (t1.log2() - t0.log2())).exp2();
    assert!((e1 / want - 1.0).abs() < 3e-3, "adapted {e1}, expected {want}");
    r.reset_history();
    let (_, e2) = frame(&gpu, &mut r, &scene, dark_view);
    assert!((e2 / t1 - 1.0).abs() < 3e-3, "after a cut: {e2} vs {t1}");
}

/// `latest_exposure` (the viewer's label; it never waits): a fixed exposure at once; a
/// metered one from the read-back an earlier call started, so it trails
/// `displayed_exposure` by one call and then equals it exactly.
#[test]
fn latest_exposure_trails_the_waiting_read_by_one_call() {
    let gpu = common::gpu();
    let scene = procedural::builtin("atrium").unwrap();
    let fixed = RenderSettings {
        width: 160,
        height: 120,
        exposure: Some(0.7),
        ..Default::default()
    };
    let mut r = Renderer::new(&gpu, &scene, fixed).unwrap();
    r.render(&gpu, &scene, &FrameCameras::fixed(scene.camera), 0.0).unwrap();
    assert_eq!(r.latest_exposure(&gpu), Some(0.7));
    assert_eq!(r.displayed_exposure(&gpu).unwrap(), 0.7);

    let a = AutoExposure {
        adaptation: 0.25,
        ..AutoExposure::default()
    };
    let mut r = Renderer::new(&gpu, &scene, auto(a)).unwrap();
    let mut dark_view = scene.camera;
    dark_view.target = dark_view.eye + glam::Vec3::new(-0.2, -0.3, -1.0);
    let (_, e0) = frame(&gpu, &mut r, &scene, scene.camera);
    assert_eq!(r.latest_exposure(&gpu), None, "nothing has arrived yet");
    gpu.check_errors().unwrap(); // waits for the GPU
    assert_eq!(r.latest_exposure(&gpu), Some(e0), "the first frame's, exactly");
    let (_, e1) = frame(&gpu, &mut r, &scene, dark_view);
    assert!((e1 / e0 - 1.0).abs() > 0.05, "the exposure adapts: {e0} → {e1}");
    gpu.check_errors().unwrap();
    // the copy collected now was started before frame 1
    assert_eq!(r.latest_exposure(&gpu), Some(e0), "one call behind");
    gpu.check_errors().unwrap();
    assert_eq!(r.latest_exposure(&gpu), Some(e1), "then frame 1's");
    gpu.check_errors()
        .expect("no wgpu validation errors (a mapped buffer is never copied into)");
}

/// Out-of-range settings are one-line errors naming the parameter.
#[test]
fn bad_auto_exposure_settings_are_refused() {
    let gpu = common::gpu();
    let scene = procedural::builtin("cornell").unwrap();
    let bad = AutoExposure {
        low: 0.9,
        high: 0.2,
        ..AutoExposure::default()
    };
    let err = Renderer::new(&gpu, &scene, auto(bad))
        .err()
        .expect("refused")
        .to_string();
    assert!(
        err.contains("auto-exposure percentiles") && !err.contains('\n'),
        "{err}"
    );
}
