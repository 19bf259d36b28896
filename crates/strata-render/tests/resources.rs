//! Issue 16: resources are checked before anything is allocated, the estimate is
//! an upper bound of what a renderer allocates, and a lost device is an error.

mod common;

use strata_render::frame::FrameCameras;
use strata_render::passes::deep_gbuffer::DeepGBufferSettings;
use strata_render::technique;
use strata_render::{GpuContext, RenderError, RenderSettings, Renderer};
use strata_scene::procedural;

fn allocated(gpu: &GpuContext) -> u64 {
    gpu.device
        .generate_allocator_report()
        .expect("the Vulkan backend reports its allocations")
        .total_allocated_bytes
}

fn settings(technique: &str, w: u32, h: u32, layers: u32) -> RenderSettings {
    let base = RenderSettings {
        width: w,
        height: h,
        deep: DeepGBufferSettings {
            layers,
            ..Default::default()
        },
        ..Default::default()
    };
    technique::find(technique).unwrap().settings(&base, None).unwrap()
}

#[test]
fn estimate_bounds_what_a_renderer_allocates() {
    let gpu = common::gpu();
    let mut results = Vec::new();
    // (…, a setting of the technique, e.g. DSS splats for the bounced z-buffer)
    for (scene_name, technique, w, h, layers, set) in [
        ("cornell", "direct", 160, 120, 1, None),
        ("atrium", "ao", 256, 144, 2, None),
        ("atrium", "full", 256, 144, 2, None),
        ("warehouse", "full", 200, 100, 3, None),
        ("cornell", "ils", 150, 100, 1, None),
        ("atrium", "ils", 256, 144, 2, None),
        // the AOV splats at 256×128: at 96×64 the 64×128 padding and the fixed 1 MiB
        // slack alone make the estimate 3.6× the 1.2 MB allocated
        ("cornell", "bzb-ao", 256, 128, 1, None),
        ("cornell", "bzb-ao", 96, 64, 1, Some(("splat", 1.0))),
        ("cornell", "bzb-gi", 96, 64, 1, None),
        ("cornell", "bzb-gi", 96, 64, 1, Some(("splat", 1.0))),
    ] {
        let scene = procedural::builtin(scene_name).unwrap();
        let mut s = settings(technique, w, h, layers);
        if let Some((name, value)) = set {
            technique::find(technique).unwrap().set(&mut s, name, value).unwrap();
        }
        let estimate = s.estimated_bytes(&scene);
        let before = allocated(&gpu);
        let mut r = Renderer::new(&gpu, &scene, s).unwrap();
        r.render(&gpu, &scene, &FrameCameras::fixed(scene.camera), 0.0).unwrap();
        let used = allocated(&gpu) - before;
        if std::env::var_os("STRATA_LIST_ALLOCATIONS").is_some() {
            let mut list: Vec<_> = gpu
                .device
                .generate_allocator_report()
                .unwrap()
                .allocations
                .into_iter()
                .map(|a| (a.size, a.name))
                .collect();
            list.sort();
            for (size, name) in list {
                eprintln!("  {scene_name} {technique}: {size:>10} {name}");
            }
        }
        eprintln!("{scene_name} {technique} {w}x{h} k={layers}: estimate {estimate} B, allocated {used} B");
        results.push((scene_name, technique, estimate, used));
        drop(r);
    }
    // every case is printed before any is judged (drivers pad differently)
    for (scene_name, technique, estimate, used) in results {
        assert!(
            estimate >= used,
            "{scene_name} {technique}: estimate {estimate} < allocated {used}"
        );
        assert!(
            estimate <= 3 * used,
            "{scene_name} {technique}: estimate {estimate} is not a tight bound of {used}"
        );
    }
}

#[test]
fn over_budget_is_refused_before_allocating() {
    let gpu = common::gpu();
    let scene = procedural::builtin("atrium").unwrap();
    let s = settings("ao", 8192, 8192, 4);
    assert!(s.estimated_bytes(&scene) > strata_render::renderer::DEFAULT_MEMORY_BUDGET);
    let before = allocated(&gpu);
    let e = match Renderer::new(&gpu, &scene, s) {
        Err(RenderError::Parameter(e)) => e,
        Err(e) => panic!("wrong error kind: {e}"),
        Ok(_) => panic!("an 8192x8192 four-layer frame fits the 8 GiB budget?"),
    };
    assert_eq!(allocated(&gpu), before, "nothing may be allocated before the check");
    for needle in [
        "width 8192",
        "height 8192",
        "layers 4",
        "MiB",
        "STRATA_MEMORY_BUDGET_MB",
    ] {
        assert!(e.contains(needle), "'{e}' lacks '{needle}'");
    }
    assert!(!e.contains('\n'), "one line: {e}");
}

#[test]
fn a_lost_device_is_an_error_not_a_hang() {
    let gpu = common::gpu();
    let scene = procedural::builtin("cornell").unwrap();
    let mut r = Renderer::new(&gpu, &scene, settings("direct", 64, 64, 1)).unwrap();
    gpu.device.destroy();
    let t = std::time::Instant::now();
    let result = r.render(&gpu, &scene, &FrameCameras::fixed(scene.camera), 0.0);
    assert!(result.is_err(), "rendering on a destroyed device must fail");
    assert!(t.elapsed().as_secs() < 30, "took {:?}", t.elapsed());
}
