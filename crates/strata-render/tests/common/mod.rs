//! Shared helpers for GPU tests (run on lavapipe when no GPU is present).
#![allow(dead_code)]

pub mod quads;

/// A scene of flat convex polygons (one mesh each, fan-triangulated, front face by
/// the winding of the first three corners), one grey material, the given camera
/// and AO radius.
pub fn polygons_scene(name: &str, polygons: &[&[glam::Vec3]], camera: Camera, ao_radius: f32) -> Scene {
    use strata_scene::model::{Material, Mesh, Object, SceneSettings};
    let mut meshes = Vec::new();
    let mut objects = Vec::new();
    for (i, p) in polygons.iter().enumerate() {
        let n = (p[1] - p[0]).cross(p[2] - p[0]).normalize();
        meshes.push(Mesh {
            name: format!("{name}-{i}"),
            positions: p.iter().map(|q| q.to_array()).collect(),
            normals: vec![n.to_array(); p.len()],
            uvs: vec![[0.0; 2]; p.len()],
            indices: (1..p.len() as u32 - 1).flat_map(|k| [0, k, k + 1]).collect(),
            material: 0,
        });
        objects.push(Object {
            name: format!("{name}-{i}"),
            mesh: i,
            transform: glam::Mat4::IDENTITY,
            animation: None,
        });
    }
    Scene {
        name: name.into(),
        meshes,
        objects,
        materials: vec![Material::diffuse("grey", [0.5; 3])],
        camera,
        settings: SceneSettings {
            ao_radius,
            ..Default::default()
        },
        ..Default::default()
    }
}

/// Scene settings with no sky and no ambient light (only lights and emitters light the
/// frame), the deep G-buffer's minimum separation 0.5 m.
pub fn unlit_settings() -> strata_scene::model::SceneSettings {
    strata_scene::model::SceneSettings {
        min_separation: 0.5,
        sky: [0.0; 3],
        ambient: [0.0; 3],
        ..Default::default()
    }
}

use strata_render::frame::FrameCameras;
use strata_render::{GpuContext, GpuOptions, RenderSettings, Renderer};
use strata_scene::{Camera, Scene};

/// The Cornell box without its camera path, sliding as a whole by `length` towards its
/// still camera between frames 0 and 1 (offset = slide · sin(2π frame / 4)): every surface
/// moves, and the walls facing the camera change depth. Returns the scene and the slide
/// (per-object motion: `tests/ao.rs`, `tests/radiosity.rs`).
pub fn sliding_cornell(length: f32) -> (Scene, glam::Vec3) {
    let mut scene = strata_scene::procedural::builtin("cornell").unwrap();
    scene.camera_path = None;
    let slide = (scene.camera.target - scene.camera.eye).normalize() * -length;
    for o in &mut scene.objects {
        o.animation = Some(strata_scene::Animation::Slide {
            amplitude: slide,
            period_frames: 4.0,
        });
    }
    (scene, slide)
}

/// Opens the GPU. Tests fail (never skip) without one: `scripts/test.sh` installs lavapipe.
pub fn gpu() -> GpuContext {
    GpuContext::new(&GpuOptions::default()).expect("a Vulkan adapter (scripts/test.sh installs Mesa lavapipe)")
}

/// A pass that has both forms, pinned: compute (`true`) or fragment (`false`).
pub fn kernel(compute: bool) -> strata_render::passes::Kernel {
    if compute {
        strata_render::passes::Kernel::Compute
    } else {
        strata_render::passes::Kernel::Fragment
    }
}

/// Whether `gpu` is a CPU adapter (lavapipe in CI): IEEE maths like Rust's, and a queue
/// that finishes each submit's work in order.
pub fn cpu_adapter(gpu: &GpuContext) -> bool {
    gpu.adapter.get_info().device_type == wgpu::DeviceType::Cpu
}

/// How many of a GPU-vs-CPU twin test's `n` pixels must equal the CPU twin. On a CPU
/// adapter (lavapipe, whose sin, cos and log2 round as Rust's do) every one. A GPU's
/// transcendentals differ from Rust's by ulps, so a tap within about 1e-4 px of a texel
/// edge, or a tap radius at a MIP level's boundary, can round the other way: 0.5 % of the
/// pixels are excused there (an H200 missed 1 to 3 of 6,144 on 2026-12-01).
pub fn twin_pixels_required(gpu: &GpuContext, n: usize) -> usize {
    if cpu_adapter(gpu) {
        n
    } else {
        n - n / 200
    }
}

/// Renders `scene` with `camera` at frame 0; panics on any wgpu validation error.
pub fn render(gpu: &GpuContext, scene: &Scene, camera: &Camera, w: u32, h: u32) -> Renderer {
    let mut r = Renderer::new(
        gpu,
        scene,
        RenderSettings {
            width: w,
            height: h,
            ..Default::default()
        },
    )
    .expect("renderer builds without validation errors");
    r.render(gpu, scene, &FrameCameras::fixed(*camera), 0.0)
        .expect("frame renders without validation errors");
    r
}

/// `w`×`h` with two exactly peeled deep-G-buffer layers at the scene's minimum separation
/// (the rest default).
#[allow(dead_code)]
pub fn two_peeled_layers(scene: &Scene, w: u32, h: u32) -> RenderSettings {
    peeled_layers(scene, w, h, 2)
}

/// `layers` deep-G-buffer layers, each peeled exactly (`Variant::Peel`) with the scene's
/// minimum separation, at `w`×`h` without a guard band.
pub fn peeled_layers(scene: &Scene, w: u32, h: u32, layers: u32) -> RenderSettings {
    RenderSettings {
        width: w,
        height: h,
        deep: strata_render::passes::deep_gbuffer::DeepGBufferSettings {
            layers,
            variant: strata_render::passes::deep_gbuffer::Variant::Peel,
            min_separation: Some(scene.settings.min_separation),
            ..Default::default()
        },
        ..Default::default()
    }
}

/// `../shared/scenes/<rel>` next to the repository, if present.
pub fn shared_scene(rel: &str) -> Option<std::path::PathBuf> {
    let p = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/scenes")
        .join(rel);
    if p.exists() {
        Some(p)
    } else {
        let test = std::thread::current().name().unwrap_or("?").to_string();
        strata_scene::skip::note_skip(&test, &format!("shared scene not found at {}", p.display()));
        None
    }
}

/// How many values of `a` differ from `b`'s by more than `rel` × max(|b|, 1) (the
/// same-frame-twice comparisons of cached passes).
pub fn values_differing(a: &strata_scene::ImageBuf, b: &strata_scene::ImageBuf, rel: f32) -> usize {
    a.data
        .iter()
        .zip(&b.data)
        .filter(|(x, y)| (*x - *y).abs() > rel * y.abs().max(1.0))
        .count()
}

/// (mean |a − b|, fraction of pixels with |a − b| > `tol`) over channel 0 of two images
/// of one size (the embedded techniques against the renderer's).
pub fn channel0_diff(a: &strata_scene::ImageBuf, b: &strata_scene::ImageBuf, tol: f32) -> (f64, f64) {
    assert_eq!((a.width, a.height), (b.width, b.height));
    let n = (a.width * a.height) as usize;
    let (mut sum, mut over) = (0.0f64, 0usize);
    for i in 0..n {
        let d = (a.data[i * a.channels as usize] - b.data[i * b.channels as usize]).abs();
        sum += d as f64;
        over += (d > tol) as usize;
    }
    (sum / n as f64, over as f64 / n as f64)
}

/// Records one encoder with `record`, submits it, and fails on a wgpu validation error.
pub fn submit_checked(gpu: &GpuContext, record: impl FnOnce(&mut wgpu::CommandEncoder)) {
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    record(&mut encoder);
    gpu.queue.submit([encoder.finish()]);
    gpu.check_errors().expect("no wgpu validation errors");
}

/// The error of an embedded technique that reads one layer, given `AoInputs` with a second
/// (blank `w`×`h` depth and normal textures, an identity view).
pub fn second_layer_error(
    gpu: &GpuContext,
    [w, h]: [u32; 2],
    encode: impl FnOnce(
        &mut wgpu::CommandEncoder,
        &strata_render::embed::AoInputs<'_>,
    ) -> Result<(), strata_render::RenderError>,
) -> String {
    let texture = |format| {
        gpu.device.create_texture(&wgpu::TextureDescriptor {
            label: None,
            size: wgpu::Extent3d {
                width: w,
                height: h,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::RENDER_ATTACHMENT,
            view_formats: &[],
        })
    };
    let (d, n) = (
        texture(wgpu::TextureFormat::Depth32Float),
        texture(wgpu::TextureFormat::Rgba16Float),
    );
    let proj = glam::camera::rh::proj::directx::perspective(1.0, w as f32 / h as f32, 0.1, 10.0);
    let inputs = strata_render::embed::AoInputs {
        second: Some(((&d).into(), (&n).into())),
        ..strata_render::embed::AoInputs::new((&d).into(), (&n).into(), glam::Mat4::IDENTITY, proj)
    };
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    encode(&mut encoder, &inputs)
        .expect_err("a second layer is refused")
        .to_string()
}

/// Where the device times passes (lavapipe does): `timings` (an embedded technique's last
/// frame) has one time per pass of `names`, in order, none negative.
pub fn check_pass_timings(
    gpu: &GpuContext,
    timings: impl FnOnce() -> Result<strata_render::PassTimings, strata_render::RenderError>,
    names: Vec<&'static str>,
    what: &str,
) {
    if gpu.has(wgpu::Features::TIMESTAMP_QUERY | wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS) {
        let t = timings().unwrap();
        let got: Vec<&str> = t.passes.iter().map(|p| p.0.as_str()).collect();
        assert_eq!(got, names, "{what}: one time per pass, in order");
        assert!(t.passes.iter().all(|p| p.1 >= 0.0) && t.total() > 0.0, "{what}: {t:?}");
    }
}

/// How many values of target `name` differ in their bits between renderers `a` and `b`
/// (the same-image checks of settings that must not change the image).
pub fn target_bits_differing(gpu: &GpuContext, a: &Renderer, b: &Renderer, name: &str) -> usize {
    let (x, y) = (a.read_target(gpu, name).unwrap(), b.read_target(gpu, name).unwrap());
    assert_eq!(x.data.len(), y.data.len(), "{name}: sizes differ");
    x.data
        .iter()
        .zip(&y.data)
        .filter(|(p, q)| p.to_bits() != q.to_bits())
        .count()
}

/// The values of target `name` in `a` and `b` that differ by more than `rel` of the larger
/// of the two (or of 10⁻⁴ × the target's largest value, if that is larger), and the largest
/// such relative difference: for sums whose order a GPU does not fix (atomics, blending of
/// surfels appended in any order).
pub fn target_values_differing(gpu: &GpuContext, a: &Renderer, b: &Renderer, name: &str, rel: f32) -> (usize, f32) {
    let (x, y) = (a.read_target(gpu, name).unwrap(), b.read_target(gpu, name).unwrap());
    assert_eq!(x.data.len(), y.data.len(), "{name}: sizes differ");
    let top = x.data.iter().chain(&y.data).fold(0.0f32, |m, v| m.max(v.abs()));
    let floor = 1e-4 * top;
    let (mut n, mut worst) = (0, 0.0f32);
    for (p, q) in x.data.iter().zip(&y.data) {
        let d = (p - q).abs() / p.abs().max(q.abs()).max(floor).max(f32::MIN_POSITIVE);
        worst = worst.max(d);
        n += (d > rel) as usize;
    }
    (n, worst)
}

/// World normals of layer `layer` (0 or 1) decoded from a read-back `npack`
/// (Oct16, RGBA8) exactly as the shaders decode them.
pub fn npack_normals(npack: &strata_scene::ImageBuf, layer: usize) -> strata_scene::ImageBuf {
    let mut out = strata_scene::ImageBuf::new(npack.width, npack.height, 3);
    for (o, p) in out.data.chunks_exact_mut(3).zip(npack.data.chunks_exact(4)) {
        let q = |v: f32| (v * 255.0).round() as u8;
        let n = strata_render::packing::oct16_unpack([q(p[2 * layer]), q(p[2 * layer + 1])]);
        o.copy_from_slice(&n.to_array());
    }
    out
}

/// Runs compute shader `src` (entry `entry`, workgroup size 64, one invocation per
/// output element) with `input` bound as a read-only storage buffer at binding 0
/// and an `output_bytes` read-write storage buffer at binding 1, over `threads`
/// invocations; returns the output buffer's bytes. A wgpu validation error fails
/// the test. The harness of the GPU-equals-CPU-twin tests of shader functions.
pub fn run_compute(
    gpu: &GpuContext,
    label: &str,
    src: &str,
    entry: &str,
    input: &[u8],
    output_bytes: u64,
    threads: u32,
) -> Vec<u8> {
    use wgpu::util::DeviceExt;
    let d = &gpu.device;
    let input = d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some(label),
        contents: input,
        usage: wgpu::BufferUsages::STORAGE,
    });
    let buffer = |usage| {
        d.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: output_bytes,
            usage,
            mapped_at_creation: false,
        })
    };
    let output = buffer(wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC);
    let staging = buffer(wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST);
    let module = strata_render::shader::module(d, label, src);
    let pipeline = d.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some(label),
        layout: None,
        module: &module,
        entry_point: Some(entry),
        compilation_options: Default::default(),
        cache: None,
    });
    let group = d.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some(label),
        layout: &pipeline.get_bind_group_layout(0),
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: input.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: output.as_entire_binding(),
            },
        ],
    });
    let mut enc = d.create_command_encoder(&Default::default());
    {
        let mut pass = enc.begin_compute_pass(&Default::default());
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &group, &[]);
        pass.dispatch_workgroups(threads.div_ceil(64), 1, 1);
    }
    enc.copy_buffer_to_buffer(&output, 0, &staging, 0, output_bytes);
    gpu.queue.submit([enc.finish()]);
    gpu.check_errors()
        .unwrap_or_else(|e| panic!("{label}: wgpu validation error: {e}"));
    gpu.read_buffer(&staging)
        .unwrap_or_else(|e| panic!("{label}: read back: {e}"))
}

/// Layer 0's surface under one pixel of a rendered frame.
pub struct SurfacePoint {
    /// Pixel index y·W + x.
    pub i: usize,
    pub x: u32,
    pub y: u32,
    /// World position from csz through the pixel centre (common/camera.wgsl's twin).
    pub p: glam::Vec3,
    /// Decoded world normal.
    pub n: glam::Vec3,
}

/// Every covered pixel (csz > 0) of `r`'s last frame, row by row; panics on a
/// wgpu validation error.
pub fn surface_points(gpu: &GpuContext, r: &Renderer) -> Vec<SurfacePoint> {
    use glam::Vec3;
    let csz = r.read_target(gpu, "csz").unwrap();
    let normals = r.read_normals(gpu).unwrap();
    gpu.check_errors().unwrap();
    let u = r.frame_uniforms();
    let v = |a: [f32; 4]| Vec3::new(a[0], a[1], a[2]);
    let mut out = Vec::new();
    for y in 0..csz.height {
        for x in 0..csz.width {
            let i = (y * csz.width + x) as usize;
            let z = csz.data[i];
            if z <= 0.0 {
                continue;
            }
            let ndc_x = (x as f32 + 0.5) * u.size[2] * 2.0 - 1.0;
            let ndc_y = 1.0 - (y as f32 + 0.5) * u.size[3] * 2.0;
            let p = v(u.eye) + z * (v(u.cam_forward) + v(u.cam_right) * ndc_x + v(u.cam_up) * ndc_y);
            let n = Vec3::from_slice(&normals.data[i * 3..i * 3 + 3]);
            out.push(SurfacePoint { i, x, y, p, n });
        }
    }
    out
}

/// A `w`×`h` renderer of technique `ils` with `ils`, after one frame of `scene`'s camera
/// at frame 0; panics on any wgpu validation error.
pub fn ils_renderer(
    gpu: &GpuContext,
    scene: &Scene,
    ils: strata_render::passes::ils::IlsSettings,
    (w, h): (u32, u32),
) -> Renderer {
    let t = strata_render::technique::find("ils").unwrap();
    let base = RenderSettings {
        width: w,
        height: h,
        ..Default::default()
    };
    let mut s = t.settings(&base, None).unwrap();
    s.ils = Some(ils);
    let mut r = Renderer::new(gpu, scene, s).expect("renderer builds without validation errors");
    r.render(gpu, scene, &FrameCameras::fixed(scene.camera), 0.0)
        .expect("frame renders without validation errors");
    r
}

/// ILS §4.3's VPL sum at pixel (x, y): Σ_k `term(k)` over all `n_all` VPLs
/// (`brute_force`) or over the pixel's sub-buffer subset of pattern n×m
/// (k ≡ j·n + i mod n·m for sub-buffer (i, j) = (x mod n, y mod m)), scaled by N/N_s.
pub fn ils_vpl_sum(
    [n, m]: [u32; 2],
    n_all: usize,
    brute_force: bool,
    (x, y): (u32, u32),
    mut term: impl FnMut(usize) -> glam::Vec3,
) -> glam::Vec3 {
    let (first, step) = if brute_force {
        (0, 1)
    } else {
        (((y % m) * n + x % n) as usize, (n * m) as usize)
    };
    let (mut e, mut count) = (glam::Vec3::ZERO, 0);
    for k in (first..n_all).step_by(step) {
        e += term(k);
        count += 1;
    }
    if count > 0 {
        e *= n_all as f32 / count as f32;
    }
    e
}

/// The radiosity gather's read-back inputs after a frame (the depth MIP chain, both layers'
/// normals and radiosity, the frame and gather uniforms): what `irradiance_cpu` evaluates.
pub struct GatherBuffers {
    pub zmip: Vec<strata_scene::ImageBuf>,
    pub normals: [strata_scene::ImageBuf; 2],
    pub radiosity: [strata_scene::ImageBuf; 2],
    pub frame: strata_render::frame::FrameUniforms,
    pub uniforms: strata_render::passes::radiosity::RadiosityUniforms,
}

impl GatherBuffers {
    pub fn read(gpu: &GpuContext, r: &Renderer) -> Self {
        let uniforms = r.radiosity_uniforms().unwrap();
        let zmip = (0..=uniforms.max_mip)
            .map(|m| r.read_target_mip(gpu, "zmip", m).unwrap())
            .collect();
        let npack = r.read_target_full(gpu, "npack", 0).unwrap();
        Self {
            zmip,
            normals: [npack_normals(&npack, 0), npack_normals(&npack, 1)],
            radiosity: [
                r.read_target_full(gpu, "radiosity0", 0).unwrap(),
                r.read_target_full(gpu, "radiosity1", 0).unwrap(),
            ],
            frame: r.frame_uniforms(),
            uniforms,
        }
    }

    /// Two layers, and `probes` for the detail term.
    pub fn inputs<'a>(
        &'a self,
        probes: Option<&'a strata_scene::probes::IrradianceProbes>,
    ) -> strata_render::passes::radiosity::GatherInputs<'a> {
        strata_render::passes::radiosity::GatherInputs {
            zmip: &self.zmip,
            normals: [&self.normals[0], &self.normals[1]],
            radiosity: [&self.radiosity[0], &self.radiosity[1]],
            frame: &self.frame,
            uniforms: &self.uniforms,
            layers: 2,
            probes,
        }
    }
}

/// A 2D texture of the application's, `size` texels of `format` with `usage` and `samples`:
/// the embedded techniques' bad-input tests make their inputs with it.
#[allow(dead_code)]
pub fn app_texture(
    gpu: &GpuContext,
    size: [u32; 2],
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
    samples: u32,
) -> wgpu::Texture {
    gpu.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("app"),
        size: wgpu::Extent3d {
            width: size[0],
            height: size[1],
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: samples,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage,
        view_formats: &[],
    })
}

/// Asserts that error `e` is one line naming each of `words`.
#[allow(dead_code)]
pub fn assert_one_line(e: &str, words: &[&str]) {
    assert!(!e.contains('\n'), "one line: {e}");
    for w in words {
        assert!(e.contains(w), "'{e}' names '{w}'");
    }
}

/// Built-in scene `name` held still: no camera path, no animation.
#[allow(dead_code)]
pub fn frozen(name: &str) -> Scene {
    let mut s = strata_scene::procedural::builtin(name).unwrap();
    s.camera_path = None;
    for o in &mut s.objects {
        o.animation = None;
    }
    s
}
