//! `strata_render::embed` over a long run: an application that records the embedded AO,
//! radiosity, reflections, bounced-z-buffer AO (its triangles rewritten each frame) and ILS
//! (its VPLs and its shadow maps' occluders rewritten each frame) every frame for hundreds of frames (two layers, a moving
//! camera) holds its GPU allocations, the Rust heap and resident memory flat. The import's
//! bind group is kept while the textures stay the same; before it was (2026-12-01), each
//! frame made one with views of the application's textures, and NVIDIA's driver kept
//! about 2 KB of each frame's (+2.9 % resident over 2,800 frames on an H200). Its own
//! test binary: resident memory is per process, and other tests would move it.

mod common;

#[path = "../examples/embed_ao/app.rs"]
mod app;

use strata_render::embed::{
    AoInputs, EmbeddedAo, EmbeddedAoConfig, EmbeddedBzbAo, EmbeddedBzbAoConfig, EmbeddedIls, EmbeddedIlsConfig,
    EmbeddedRadiosity, EmbeddedRadiosityConfig, EmbeddedReflections, EmbeddedReflectionsConfig, NormalEncoding,
    RadiosityInputs, ReflectionInputs,
};
use strata_render::passes::ao::AoSettings;
use strata_render::passes::ils::{GpuVpl, IlsSettings};
use strata_render::passes::radiosity::RadiositySettings;

/// Rust's heap, counted: the bytes strata and wgpu hold live. Resident memory also counts
/// the driver's own heap, which wgpu's allocator report does not see and which Rust's
/// allocator does not serve.
struct CountingAllocator;

static LIVE_HEAP: std::sync::atomic::AtomicI64 = std::sync::atomic::AtomicI64::new(0);

/// The most bytes live since the last sample ([`take_peak_heap_bytes`]).
static PEAK_HEAP: std::sync::atomic::AtomicI64 = std::sync::atomic::AtomicI64::new(0);

fn heap_add(bytes: i64) {
    let live = LIVE_HEAP.fetch_add(bytes, std::sync::atomic::Ordering::Relaxed) + bytes;
    PEAK_HEAP.fetch_max(live, std::sync::atomic::Ordering::Relaxed);
}

fn take_peak_heap_bytes() -> i64 {
    PEAK_HEAP.swap(live_heap_bytes(), std::sync::atomic::Ordering::Relaxed)
}

// SAFETY: every call is passed to the system allocator unchanged; the counter only adds up
// the sizes it was asked for.
unsafe impl std::alloc::GlobalAlloc for CountingAllocator {
    unsafe fn alloc(&self, layout: std::alloc::Layout) -> *mut u8 {
        let p = unsafe { std::alloc::System.alloc(layout) };
        if !p.is_null() {
            heap_add(layout.size() as i64);
        }
        p
    }
    unsafe fn alloc_zeroed(&self, layout: std::alloc::Layout) -> *mut u8 {
        let p = unsafe { std::alloc::System.alloc_zeroed(layout) };
        if !p.is_null() {
            heap_add(layout.size() as i64);
        }
        p
    }
    unsafe fn dealloc(&self, p: *mut u8, layout: std::alloc::Layout) {
        unsafe { std::alloc::System.dealloc(p, layout) };
        heap_add(-(layout.size() as i64));
    }
    unsafe fn realloc(&self, p: *mut u8, layout: std::alloc::Layout, size: usize) -> *mut u8 {
        let q = unsafe { std::alloc::System.realloc(p, layout, size) };
        if !q.is_null() {
            heap_add(size as i64 - layout.size() as i64);
        }
        q
    }
}

#[global_allocator]
static HEAP: CountingAllocator = CountingAllocator;

fn live_heap_bytes() -> i64 {
    LIVE_HEAP.load(std::sync::atomic::Ordering::Relaxed)
}

fn resident_bytes() -> u64 {
    let status = std::fs::read_to_string("/proc/self/status").expect("Linux /proc");
    let line = status.lines().find(|l| l.starts_with("VmRSS:")).expect("VmRSS");
    line.split_whitespace().nth(1).unwrap().parse::<u64>().unwrap() * 1024
}

#[test]
fn embedded_ao_radiosity_reflections_bzb_and_ils_soak_flat() {
    let gpu = common::gpu();
    let mut scene = strata_scene::procedural::builtin("atrium").unwrap();
    scene.camera_path = None;
    let tris = app::scene_triangles(&scene);
    let (w, h) = (64u32, 36u32);
    let layout = app::Layout::standard();
    let first = app::GBuffer::new(&gpu.device, [w, h], layout, &tris);
    let second = app::GBuffer::second_layer(&gpu.device, &first, scene.settings.min_separation, &tris);
    let mut ao = EmbeddedAo::new(
        &gpu.adapter,
        &gpu.device,
        &gpu.queue,
        EmbeddedAoConfig {
            width: w,
            height: h,
            layers: 2,
            settings: AoSettings {
                radius: Some(scene.settings.ao_radius),
                ..AoSettings::default()
            },
            normals: NormalEncoding::Signed,
            ..EmbeddedAoConfig::default()
        },
    )
    .unwrap();
    let mut gi = EmbeddedRadiosity::new(
        &gpu.adapter,
        &gpu.device,
        &gpu.queue,
        EmbeddedRadiosityConfig {
            width: w,
            height: h,
            layers: 2,
            settings: RadiositySettings {
                radius: Some(scene.settings.radiosity_radius),
                ..RadiositySettings::default()
            },
            ..EmbeddedRadiosityConfig::default()
        },
    )
    .unwrap();
    let mut refl = EmbeddedReflections::new(
        &gpu.adapter,
        &gpu.device,
        &gpu.queue,
        EmbeddedReflectionsConfig {
            width: w,
            height: h,
            layers: 2,
            ..EmbeddedReflectionsConfig::default()
        },
    )
    .unwrap();
    // a few hundred occluders and one direction keep the splat short on lavapipe
    let mut occluders: Vec<[glam::Vec3; 3]> = tris.iter().take(512).map(|t| t.0).collect();
    let mut bzb = EmbeddedBzbAo::new(
        &gpu.adapter,
        &gpu.device,
        &gpu.queue,
        EmbeddedBzbAoConfig {
            width: w,
            height: h,
            settings: strata_render::passes::bzb::BzbSettings {
                radius: Some(scene.settings.ao_radius),
                directions: 1,
                temporal: Some(strata_render::passes::bzb::temporal_filter()),
                ..Default::default()
            },
            ..EmbeddedBzbAoConfig::default()
        },
        &occluders,
    )
    .unwrap();
    // 96 VPLs above the atrium's floor, moved a little every frame (set_vpls in place)
    let vpl = |k: usize, f: u32| {
        let a = k as f32 * 0.7 + f as f32 * 0.05;
        GpuVpl::new(
            [3.0 * a.cos(), 1.0 + 0.01 * k as f32, 3.0 * a.sin()],
            [0.0, -1.0, 0.0],
            [0.5; 3],
        )
    };
    let mut vpls: Vec<GpuVpl> = (0..96).map(|k| vpl(k, 0)).collect();
    let mut ils = EmbeddedIls::new(
        &gpu.adapter,
        &gpu.device,
        &gpu.queue,
        EmbeddedIlsConfig {
            width: w,
            height: h,
            settings: IlsSettings {
                vpls: vpls.clone().into(),
                clamp_distance: Some(0.5),
                // VPL shadow maps of the bounced z-buffer's occluders, which move in place
                shadows: strata_render::passes::ils::VplShadows::ShadowMaps,
                ..IlsSettings::default()
            },
            triangles: occluders.clone().into(),
            // the bobbing triangle may leave the box by its 1 cm: the margin keeps it in place
            occluder_margin: 0.1,
            ..EmbeddedIlsConfig::default()
        },
    )
    .unwrap();
    let ils_output = ils.output().clone();
    let cam = scene.camera;
    let proj =
        glam::camera::rh::proj::directx::perspective(cam.fov_y_deg.to_radians(), w as f32 / h as f32, cam.near, 500.0);
    // STRATA_SOAK_FRAMES runs longer (a diagnosis); the test's own length is 600
    let frames = std::env::var("STRATA_SOAK_FRAMES")
        .ok()
        .and_then(|v| v.parse::<u32>().ok())
        .map_or(600, |n| n.max(300));
    let first_sample = 200u32;
    // On a GPU the application waits for each frame, as presenting to a window makes it:
    // without that, the submits run hundreds of frames ahead of the GPU, and how far they got
    // sets the high-water mark of what is in flight (an H200: resident memory rose in 4 MiB
    // steps up to frame ~5,000 of 10,000, then stayed). lavapipe finishes each submit's work
    // before the next, so there the test never polls but for its samples.
    // STRATA_SOAK_WAIT=0 or 1 overrides this (a diagnosis).
    let cpu_adapter = common::cpu_adapter(&gpu);
    let wait_each_frame = match std::env::var("STRATA_SOAK_WAIT").as_deref() {
        Ok("1") => true,
        Ok("0") => false,
        _ => !cpu_adapter,
    };
    let mut samples = Vec::new();
    for f in 1..=frames {
        // the camera sways sideways, so the temporal filter reprojects every frame
        let sway = cam.basis().0 * (0.2 * (f as f32 * 0.1).sin());
        let view = glam::camera::rh::view::look_at_mat4(cam.eye + sway, cam.target + sway, cam.up);
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        first.draw(&gpu.queue, &mut encoder, view, proj);
        second.draw(&gpu.queue, &mut encoder, view, proj);
        let inputs = AoInputs {
            second: Some(((&second.depth).into(), (&second.normals).into())),
            ..AoInputs::new((&first.depth).into(), (&first.normals).into(), view, proj)
        };
        ao.encode(&mut encoder, &inputs).unwrap();
        // (the normals stand in for albedo and radiance: any values do for memory)
        let shading = RadiosityInputs {
            gbuffer: inputs,
            albedo: (&first.normals).into(),
            radiance: (&first.normals).into(),
            second: Some(((&second.normals).into(), (&second.normals).into())),
        };
        gi.encode(&mut encoder, &shading).unwrap();
        // (the normals as the material: roughness = n.y, metallic = n.z, so the walls that
        // face +z are mirrors and their rays march)
        let mirrors = ReflectionInputs {
            gbuffer: inputs,
            material: (&first.normals).into(),
            radiance: (&first.normals).into(),
            second_radiance: Some((&second.normals).into()),
        };
        refl.encode(&mut encoder, &mirrors).unwrap();
        // the first triangle bobs up and down: written in place every frame, all of the
        // triangles on even frames and its range alone on odd ones
        let lift = glam::Vec3::Y * (0.01 * (f as f32 * 0.3).sin());
        occluders[0] = tris[0].0.map(|p| p + lift);
        if f % 2 == 0 {
            bzb.set_triangles(&occluders).unwrap();
            ils.set_triangles(&occluders).unwrap();
        } else {
            bzb.set_triangle_range(0, &occluders[..1]).unwrap();
            ils.set_triangle_range(0, &occluders[..1]).unwrap();
        }
        bzb.encode(&mut encoder, &AoInputs { second: None, ..inputs }).unwrap();
        for (k, v) in vpls.iter_mut().enumerate() {
            *v = vpl(k, f);
        }
        ils.set_vpls(&vpls).unwrap();
        ils.encode(&mut encoder, &AoInputs { second: None, ..inputs }).unwrap();
        gpu.queue.submit([encoder.finish()]);
        if wait_each_frame {
            let _ = gpu.device.poll(wgpu::PollType::wait_indefinitely());
        }
        if f >= first_sample && (f % 100 == 0 || f == frames) {
            // each sample waits for the GPU, so work still in flight is not counted as
            // kept (sampled without this wait, an H200 showed +4.1 % over 400 frames)
            let _ = gpu.device.poll(wgpu::PollType::wait_indefinitely());
            gpu.check_errors().expect("no wgpu validation errors");
            let report = gpu.device.generate_allocator_report().map(|r| r.total_allocated_bytes);
            samples.push((f, resident_bytes(), report, live_heap_bytes(), take_peak_heap_bytes()));
        }
    }
    for (f, rss, alloc, heap, peak) in &samples {
        println!(
            "frame {f}: resident {rss} bytes, Rust heap {heap} bytes (peak since the last sample {peak}), \
             wgpu allocated {alloc:?}"
        );
    }
    let (a, b) = (&samples[0], &samples[samples.len() - 1]);
    let growth = 100.0 * (b.1 as f64 - a.1 as f64) / a.1 as f64;
    let heap_growth = b.3 - a.3;
    println!(
        "frames {} → {}: resident {} → {} bytes ({growth:+.2} %), Rust heap {} → {} bytes ({heap_growth:+}), \
         wgpu allocated {:?} → {:?}",
        a.0, b.0, a.1, b.1, a.3, b.3, a.2, b.2
    );
    let marched = refl
        .read_target("reflection")
        .unwrap()
        .data
        .chunks(4)
        .filter(|p| p[3] > 0.0)
        .count();
    assert!(marched > 0, "some pixels are mirrors, so the reflections march");
    let lit = ils
        .read_target(ils.config().settings.output().name)
        .unwrap()
        .data
        .chunks(4)
        .filter(|p| p[0] > 0.0)
        .count();
    assert!(lit > 0, "the VPLs light some pixels, so ILS shades");
    assert!(
        *ils.output() == ils_output,
        "the occluders moved in place: ILS was never rebuilt"
    );
    assert_eq!(a.2, b.2, "wgpu's allocations stay the same");
    // Where each frame is waited for (or the adapter is lavapipe), nothing may pile up: what
    // strata and wgpu hold on the heap stays within 64 KiB (a leak of 200 bytes a frame
    // passes that by frame 528), and resident memory, which also counts the driver's heap,
    // within 1 %. Without the waits on a GPU both carry the in-flight high-water mark, so
    // they are printed, not judged.
    if cpu_adapter || wait_each_frame {
        assert!(
            heap_growth.abs() <= 64 << 10,
            "the Rust heap grew {heap_growth} bytes over {} frames",
            b.0 - a.0
        );
        assert!(
            growth <= 1.0,
            "resident memory grew {growth:.2} % over {} frames",
            b.0 - a.0
        );
    }
}
