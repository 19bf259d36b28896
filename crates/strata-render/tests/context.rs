//! GPU context behaviour: validation errors become errors, profiler timings,
//! parameter errors, declared pass order, debug views.

mod common;

use strata_render::{RenderError, RenderSettings, Renderer};
use strata_scene::procedural;

/// A shader with a type error must surface as `RenderError::Validation` from
/// `check_errors` (this is how every GPU test fails on validation errors).
#[test]
fn validation_errors_are_captured() {
    let gpu = common::gpu();
    gpu.check_errors().expect("fresh device has no errors");
    let _m = gpu.device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("broken"),
        source: wgpu::ShaderSource::Wgsl("fn f() -> f32 { return vec3f(1.0); }".into()),
    });
    match gpu.check_errors() {
        Err(RenderError::Validation(msg)) => assert!(!msg.is_empty()),
        other => panic!("expected a validation error, got {other:?}"),
    }
    // Errors are drained once reported.
    gpu.check_errors().expect("errors are drained after being reported");
}

#[test]
fn profiler_times_every_pass() {
    let gpu = common::gpu();
    let scene = procedural::builtin("cornell").unwrap();
    let mut r = Renderer::new(
        &gpu,
        &scene,
        RenderSettings {
            width: 64,
            height: 64,
            ..Default::default()
        },
    )
    .unwrap();
    let t = r
        .render(
            &gpu,
            &scene,
            &strata_render::frame::FrameCameras::fixed(scene.camera),
            0.0,
        )
        .unwrap();
    let names: Vec<&str> = r.pass_infos().iter().map(|p| p.name).collect();
    assert_eq!(names, ["shadow", "gbuffer", "pack", "lighting", "tonemap"]);
    assert!(
        gpu.has(wgpu::Features::TIMESTAMP_QUERY),
        "lavapipe exposes TIMESTAMP_QUERY"
    );
    for n in names {
        let ms = t.get(n).unwrap_or_else(|| panic!("no timing for {n}"));
        assert!(ms > 0.0 && ms < 60_000.0, "{n}: {ms} ms");
    }
}

#[test]
fn out_of_range_sizes_are_errors() {
    let gpu = common::gpu();
    let scene = procedural::builtin("plane").unwrap();
    for (w, h) in [(2, 64), (64, 0), (100_000, 64)] {
        let e = Renderer::new(
            &gpu,
            &scene,
            RenderSettings {
                width: w,
                height: h,
                ..Default::default()
            },
        )
        .err()
        .expect("too small/large sizes are rejected");
        let msg = e.to_string();
        assert!(msg.contains("out of range") && msg.contains("8..=8192"), "{msg}");
    }
}

#[test]
fn every_debug_view_reads_back_and_unknown_is_an_error() {
    let gpu = common::gpu();
    let scene = procedural::builtin("cornell").unwrap();
    let r = common::render(&gpu, &scene, &scene.camera, 48, 48);
    for v in r.debug_view_names() {
        let img = r.debug_view(&gpu, &v, false).unwrap_or_else(|e| panic!("{v}: {e}"));
        assert_eq!((img.width, img.height), (48, 48));
        assert!(img.data.iter().all(|x| x.is_finite()), "{v} has non-finite values");
    }
    // The G-buffer has content: some pixels are surfaces, normals are unit length there.
    let n = r.read_normals(&gpu).unwrap();
    let unit = n.data.chunks_exact(3).filter(|p| p.iter().any(|&c| c != 0.0)).all(|p| {
        let l = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
        (l - 1.0).abs() < 1e-3
    });
    assert!(unit);
    let e = r.debug_view(&gpu, "no-such-view", false).unwrap_err().to_string();
    assert!(e.contains("no-such-view") && e.contains("valid views"), "{e}");
}
