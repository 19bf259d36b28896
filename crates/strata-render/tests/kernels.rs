//! The screen passes' compute forms write what their fragment forms write. GPUs run the
//! compute forms (`Kernel::Auto`), lavapipe the fragment forms, so CI checks the GPUs'
//! passes here by forcing `compute` (`*-kernel` settings). Each compute run also shows
//! that the compute form ran: its outputs were made with storage binding, which the
//! fragment form does not ask for.

mod common;

use strata_render::frame::FrameCameras;
use strata_render::technique;
use strata_render::{GpuContext, RenderSettings, Renderer};
use strata_scene::{ImageBuf, Scene};

const FRAGMENT: f64 = 1.0;
const COMPUTE: f64 = 2.0;

/// `full` (BALANCED, two layers) after three frames with each of `kernels` set to `kernel`
/// and each of `fixed` set to the fragment form.
fn render(gpu: &GpuContext, scene: &Scene, kernels: &[&str], fixed: &[&str], kernel: f64) -> Renderer {
    let t = technique::find("full").unwrap();
    let base = RenderSettings {
        width: 96,
        height: 64,
        ..Default::default()
    };
    let mut s = t.settings(&base, Some("balanced")).unwrap();
    s.deep.layers = 2;
    for name in kernels {
        t.set(&mut s, name, kernel).unwrap();
    }
    for name in fixed {
        t.set(&mut s, name, FRAGMENT).unwrap();
    }
    let mut r = Renderer::new(gpu, scene, s).unwrap();
    for f in 0..3 {
        r.render(gpu, scene, &FrameCameras::fixed(scene.camera), f as f32)
            .expect("frame renders without validation errors");
    }
    gpu.check_errors().unwrap();
    r
}

fn storage(r: &Renderer, name: &str) -> bool {
    r.target_texture(name)
        .unwrap_or_else(|| panic!("target {name}"))
        .usage()
        .contains(wgpu::TextureUsages::STORAGE_BINDING)
}

fn read(gpu: &GpuContext, r: &Renderer, name: &str) -> ImageBuf {
    r.read_target(gpu, name).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// The direct lighting (layer 0's four outputs and layer 1's radiosity) and the mirror
/// reflections: the same bits in both forms. The AO and indirect passes stay fragment
/// passes in both runs, so every input is the same.
#[test]
fn lighting_and_reflection_compute_forms_write_the_fragment_forms_bits() {
    let gpu = common::gpu();
    let scene = common::frozen("mirror-sign");
    let kernels = ["lighting-kernel", "reflection-kernel"];
    let fixed = ["ao-kernel", "indirect-kernel"];
    let fragment = render(&gpu, &scene, &kernels, &fixed, FRAGMENT);
    let compute = render(&gpu, &scene, &kernels, &fixed, COMPUTE);
    for name in ["hdr", "radiosity1", "reflection"] {
        assert!(
            !storage(&fragment, name),
            "{name}: the fragment form has no storage binding"
        );
        assert!(storage(&compute, name), "{name}: the compute form ran");
    }
    let mut mirrors = 0;
    for name in [
        "hdr",
        "direct-diffuse",
        "shadow",
        "radiosity0",
        "radiosity1",
        "reflection",
        "hdr-reflected",
    ] {
        let (a, b) = (read(&gpu, &fragment, name), read(&gpu, &compute, name));
        let differ = a.data.iter().zip(&b.data).filter(|(x, y)| x != y).count();
        eprintln!("{name}: {differ} of {} values differ", a.data.len());
        assert_eq!(differ, 0, "{name}: compute and fragment forms differ");
        if name == "reflection" {
            mirrors = a.data.chunks(4).filter(|p| p[3] >= 2.0).count();
        }
    }
    assert!(mirrors > 100, "the rays hit something on screen ({mirrors} pixels)");
}

/// The depth MIP chain, and the AO and indirect light's filters (temporal, bilateral h and
/// v) and the multi-bounce propagation. The AO's input is the same in both forms, so the filtered AO is the same bits. The indirect light's
/// input is not: lavapipe's compute gather rounds some values differently from its
/// fragment twin (that predates these filters' compute forms), so the filters must not
/// move the two further apart than their input is. Both filters average (convex weights
/// from the same depths and normals), so the largest and the mean difference can only
/// shrink; a filter reading the wrong texel, axis or binding would raise them.
#[test]
fn ao_and_indirect_filter_compute_forms_match_the_fragment_forms() {
    let gpu = common::gpu();
    let scene = common::frozen("atrium");
    let kernels = ["ao-kernel", "indirect-kernel"];
    let fragment = render(&gpu, &scene, &kernels, &[], FRAGMENT);
    let compute = render(&gpu, &scene, &kernels, &[], COMPUTE);
    for name in [
        "zmip",
        "ao-temporal",
        "ao-blur-h",
        "ao",
        "bounce0",
        "indirect-temporal",
        "indirect",
    ] {
        assert!(
            !storage(&fragment, name),
            "{name}: the fragment form has no storage binding"
        );
        assert!(storage(&compute, name), "{name}: the compute form ran");
    }
    // mean and largest |difference| over the first `channels` channels
    let difference = |name: &str, channels: usize| {
        let (a, b) = (read(&gpu, &fragment, name), read(&gpu, &compute, name));
        let stride = a.channels as usize;
        let (mut sum, mut max, mut n) = (0.0f64, 0.0f32, 0usize);
        for (p, q) in a.data.chunks(stride).zip(b.data.chunks(stride)) {
            for c in 0..channels {
                let d = (p[c] - q[c]).abs();
                sum += d as f64;
                max = max.max(d);
                n += 1;
            }
        }
        eprintln!("{name}: mean |difference| {:.2e}, max {max:.4}", sum / n as f64);
        (sum / n as f64, max)
    };
    // the depth MIP chain: copies, the same bits at every level
    let mips = fragment.target_desc("zmip").unwrap().mips;
    assert!(mips >= 4, "a chain of {mips} levels");
    for m in 0..mips {
        let a = fragment.read_target_mip(&gpu, "zmip", m).unwrap();
        let b = compute.read_target_mip(&gpu, "zmip", m).unwrap();
        assert!(a.data.iter().any(|&z| z > 0.0), "level {m} holds depths");
        assert_eq!(a.data, b.data, "zmip level {m}: the forms differ");
    }
    for name in ["ao-raw", "ao-temporal", "ao-blur-h", "ao"] {
        assert_eq!(difference(name, 1), (0.0, 0.0), "{name}: the forms differ");
    }
    // the propagation reads last frame's E, which differs as the gathers do; on its
    // first frame (no history) it is B = direct, here the same bits
    // (on a device whose two gathers agree, both bounds are 0: the same bits)
    let (raw_mean, raw_max) = difference("indirect-raw", 3);
    for name in ["indirect-temporal", "indirect"] {
        let (mean, max) = difference(name, 3);
        assert!(
            mean <= raw_mean,
            "{name}: mean difference {mean} > the input's {raw_mean}"
        );
        assert!(
            max <= raw_max,
            "{name}: largest difference {max} > the input's {raw_max}"
        );
    }
}
