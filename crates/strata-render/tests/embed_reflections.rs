//! `strata_render::embed::EmbeddedReflections`: DGB §3.6's mirror reflections on an
//! application's G-buffer. Fed the renderer's own layers (hardware depth, Oct16 normals,
//! the material in the normal target's b and a, the shaded image and the second layer's
//! radiance), it finds what the renderer's pass finds; bad inputs are one-line errors.

#[path = "../examples/embed_ao/app.rs"]
mod app;
mod common;

use strata_render::embed::{
    AoInputs, EmbeddedReflections, EmbeddedReflectionsConfig, MaterialChannels, NormalEncoding, ReflectionInputs,
    TextureLayer,
};
use strata_render::frame::FrameCameras;
use strata_render::passes::reflections::ReflectionSettings;
use strata_render::{GpuContext, RenderSettings, Renderer};
use strata_scene::{ImageBuf, Scene};

const W: u32 = 160;
const H: u32 = 120;

/// The `mirror` scene without its sky: the embedded pass leaves the environment to the
/// application (rgb 0 where a ray finds nothing).
fn mirror_scene() -> Scene {
    let mut scene = common::frozen("mirror");
    scene.settings.sky = [0.0; 3];
    // the renderer reflects layer 1 as B + ambient × diffuse albedo; with no ambient that
    // is its `radiosity1`, which the tests hand over as the second layer's radiance
    scene.settings.ambient = [0.0; 3];
    scene
}

/// The embedded reflections for `scene` at W×H with `layers`, reading the renderer's
/// G-buffer (Oct16 normals; its `normal` target as the material: b = roughness,
/// a = metallic) or, `application`, the example application's (signed world normals,
/// glTF's material channels).
fn embedded(gpu: &GpuContext, scene: &Scene, layers: u32, application: bool) -> EmbeddedReflections {
    let (normals, material) = match application {
        false => (
            NormalEncoding::Octahedral,
            MaterialChannels {
                roughness: 2,
                metallic: 3,
            },
        ),
        true => (NormalEncoding::Signed, MaterialChannels::default()),
    };
    EmbeddedReflections::new(
        &gpu.adapter,
        &gpu.device,
        &gpu.queue,
        EmbeddedReflectionsConfig {
            width: W,
            height: H,
            layers,
            min_separation: scene.settings.min_separation,
            normals,
            material,
            ..EmbeddedReflectionsConfig::default()
        },
    )
    .expect("the embedded reflections build without validation errors")
}

/// Per code (a), how many pixels; and pixels whose codes differ.
fn codes(img: &ImageBuf) -> [usize; 4] {
    let mut n = [0; 4];
    for p in img.data.chunks_exact(4) {
        n[p[3] as usize] += 1;
    }
    n
}

#[test]
fn embedded_reflections_on_the_renderers_layers_are_the_renderers() {
    let gpu = common::gpu();
    let scene = mirror_scene();
    let cams = FrameCameras::fixed(scene.camera);
    let (view, proj) = (scene.camera.view(), scene.camera.projection(W as f32 / H as f32));
    let mut hidden = Vec::new();
    for layers in [1, 2] {
        let settings = RenderSettings {
            reflections: Some(ReflectionSettings::default()),
            ..common::peeled_layers(&scene, W, H, layers)
        };
        let mut r = Renderer::new(&gpu, &scene, settings).unwrap();
        let mut refl = embedded(&gpu, &scene, layers, false);
        r.render(&gpu, &scene, &cams, 0.0).unwrap();
        let t = |n| r.target_texture(n).unwrap();
        let layer = |n, layer| TextureLayer { texture: t(n), layer };
        let inputs = ReflectionInputs {
            gbuffer: AoInputs {
                second: (layers == 2).then(|| (layer("depth", 1), layer("normal", 1))),
                ..AoInputs::new(layer("depth", 0), layer("normal", 0), view, proj)
            },
            material: layer("normal", 0),
            radiance: layer("hdr", 0),
            second_radiance: (layers == 2).then(|| layer("radiosity1", 0)),
        };
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        refl.encode(&mut encoder, &inputs).expect("valid inputs");
        gpu.queue.submit([encoder.finish()]);
        gpu.check_errors().expect("no wgpu validation errors");

        let (a, b) = (
            refl.read_target("reflection").unwrap(),
            r.read_target(&gpu, "reflection").unwrap(),
        );
        let (ca, cb) = (codes(&a), codes(&b));
        let mirrors = cb[1] + cb[2] + cb[3];
        let (mut other_code, mut sum, mut ref_sum) = (0usize, 0.0f64, 0.0f64);
        for (pa, pb) in a.data.chunks(4).zip(b.data.chunks(4)) {
            if pa[3] != pb[3] {
                other_code += 1;
                continue;
            }
            for k in 0..3 {
                sum += (pa[k] - pb[k]).abs() as f64;
                ref_sum += pb[k].abs() as f64;
            }
        }
        let rel = sum / ref_sum.max(1e-9);
        println!(
            "k = {layers}: codes (none, env, layer 0, layer 1) embedded {ca:?}, renderer {cb:?}; {other_code} px differ in code, mean |Δ| / mean = {rel:.2e}"
        );
        assert!(mirrors > (W * H) as usize / 5, "the mirror floor covers {mirrors} px");
        assert_eq!(ca[0], cb[0], "the same pixels are mirrors (material import)");
        assert!(cb[2] > mirrors / 4, "rays hit layer 0 ({} of {mirrors})", cb[2]);
        // the imported z is within ~1e-5 of the renderer's: a ray grazing an edge may flip
        assert!(
            other_code * 500 <= mirrors,
            "k = {layers}: {other_code} of {mirrors} mirror pixels found something else"
        );
        assert!(rel < 2e-3, "k = {layers}: reflected radiance differs ({rel})");
        if layers == 1 {
            assert_eq!(ca[3], 0, "one layer cannot hit layer 1");
        }
        hidden.push(ca[3]);

        // an application without normals: each layer's normal from its depth
        let config = EmbeddedReflectionsConfig {
            normals: NormalEncoding::FromDepth,
            ..refl.config().clone()
        };
        let mut from_depth = EmbeddedReflections::new(&gpu.adapter, &gpu.device, &gpu.queue, config).unwrap();
        let depth_only = ReflectionInputs {
            gbuffer: AoInputs {
                second: (layers == 2).then(|| (layer("depth", 1), layer("depth", 1))),
                ..AoInputs::depth_only(layer("depth", 0), view, proj)
            },
            ..inputs
        };
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        from_depth.encode(&mut encoder, &depth_only).expect("valid inputs");
        gpu.queue.submit([encoder.finish()]);
        gpu.check_errors().expect("no wgpu validation errors");
        let c = from_depth.read_target("reflection").unwrap();
        let same = c
            .data
            .chunks(4)
            .zip(b.data.chunks(4))
            .filter(|(x, y)| y[3] > 0.0 && x[3] == y[3])
            .count();
        println!("k = {layers}, normals from depth: {same} of {mirrors} mirror px find what the renderer finds");
        assert!(
            same as f64 >= 0.99 * mirrors as f64,
            "k = {layers}: {same} of {mirrors}"
        );
    }
    assert!(
        hidden[1] > 20,
        "2 layers reflect the panel hidden behind the board ({} px)",
        hidden[1]
    );
}

/// An application's own G-buffer of the `mirror` scene (its pipeline and peel, signed world
/// normals, glTF's material texture) finds what the renderer's pass finds at ≥ 99 % of the
/// mirror pixels, the hidden panel with 2 layers included. Its lighting is its own, so only
/// what each ray found (a) is compared.
#[test]
fn embedded_reflections_on_an_applications_gbuffer_find_the_renderers_hits() {
    let gpu = common::gpu();
    let scene = mirror_scene();
    let cams = FrameCameras::fixed(scene.camera);
    let (view, proj) = (scene.camera.view(), scene.camera.projection(W as f32 / H as f32));
    let tris = app::scene_triangles(&scene);
    let sun = app::Sun {
        direction: glam::Vec3::new(0.3, 1.0, 0.8),
        irradiance: glam::Vec3::splat(3.0),
    };
    let dz = scene.settings.min_separation;
    // strata's camera: a reversed, infinite projection
    let layout = app::Layout {
        reversed: true,
        ..app::Layout::standard()
    };
    let first = app::GBuffer::lit(&gpu.device, [W, H], layout, &tris, sun);
    let second = app::GBuffer::second_layer_lit(&gpu.device, &first, dz, &tris);
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    first.draw(&gpu.queue, &mut encoder, view, proj);
    second.draw(&gpu.queue, &mut encoder, view, proj);
    gpu.queue.submit([encoder.finish()]);
    let ((_, b0), (_, b1)) = (first.shading.as_ref().unwrap(), second.shading.as_ref().unwrap());
    for layers in [1, 2] {
        let settings = RenderSettings {
            reflections: Some(ReflectionSettings::default()),
            ..common::peeled_layers(&scene, W, H, layers)
        };
        let mut r = Renderer::new(&gpu, &scene, settings).unwrap();
        r.render(&gpu, &scene, &cams, 0.0).unwrap();
        let reference = r.read_target(&gpu, "reflection").unwrap();
        let mut refl = embedded(&gpu, &scene, layers, true);
        let inputs = ReflectionInputs {
            gbuffer: AoInputs {
                second: (layers == 2).then(|| ((&second.depth).into(), (&second.normals).into())),
                ..AoInputs::new((&first.depth).into(), (&first.normals).into(), view, proj)
            },
            material: first.material.as_ref().unwrap().into(),
            radiance: b0.into(),
            second_radiance: (layers == 2).then(|| b1.into()),
        };
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        refl.encode(&mut encoder, &inputs).expect("valid inputs");
        gpu.queue.submit([encoder.finish()]);
        gpu.check_errors().expect("no wgpu validation errors");
        let ours = refl.read_target("reflection").unwrap();
        let (ca, cb) = (codes(&ours), codes(&reference));
        let mirrors = cb[1] + cb[2] + cb[3];
        let same = ours
            .data
            .chunks(4)
            .zip(reference.data.chunks(4))
            .filter(|(a, b)| b[3] > 0.0 && a[3] == b[3])
            .count();
        println!("k = {layers}: codes application {ca:?}, renderer {cb:?}; {same} of {mirrors} mirror px agree");
        assert!(mirrors > (W * H) as usize / 5);
        assert!(
            same as f64 >= 0.99 * mirrors as f64,
            "k = {layers}: {same} of {mirrors} agree"
        );
        if layers == 2 {
            assert!(ca[3] > 20, "the hidden panel is reflected ({} px)", ca[3]);
        }
    }
}

/// Bad configurations and inputs are one-line errors naming the parameter.
/// A cube map of 4×4 texels per face (Rgba8Unorm) in WebGPU's face order +x, −x, +y, −y,
/// +z, −z. Texel (column i, row j) of face k is (20 + 60 i, 20 + 60 j, 20 + 40 k): under
/// bilinear filtering r and g are linear in the face coordinates (s, t) between the
/// texel centres, and b names the face.
fn face_cube(gpu: &GpuContext) -> wgpu::Texture {
    let t = strata_render::passes::reflections::cube_texture(
        gpu,
        4,
        wgpu::TextureFormat::Rgba8Unorm,
        wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
    );
    let mut data = Vec::new();
    for k in 0..6u8 {
        for j in 0..4u8 {
            for i in 0..4u8 {
                data.extend([20 + 60 * i, 20 + 60 * j, 20 + 40 * k, 255]);
            }
        }
    }
    gpu.queue.write_texture(
        t.as_image_copy(),
        &data,
        wgpu::TexelCopyBufferLayout {
            offset: 0,
            bytes_per_row: Some(16),
            rows_per_image: Some(4),
        },
        t.size(),
    );
    t
}

/// With an environment cube map, a ray that finds nothing (a = 1) reflects the cube along
/// itself. The cube's colours encode face and face coordinates ([`face_cube`]), so per
/// mirror pixel they say where the pass looked: the CPU's reflection of the pixel's view
/// ray about its decoded normal must point there (within 3/255; away from the texel
/// centres' border, where filtering clamps or blends faces). Hits (a = 2, 3) are what they
/// are without the cube.
#[test]
fn an_environment_cube_map_lights_the_rays_that_find_nothing() {
    use glam::Vec3;
    let gpu = common::gpu();
    let scene = mirror_scene();
    let cams = FrameCameras::fixed(scene.camera);
    let (view, proj) = (scene.camera.view(), scene.camera.projection(W as f32 / H as f32));
    let settings = RenderSettings {
        reflections: Some(ReflectionSettings::default()),
        ..common::peeled_layers(&scene, W, H, 1)
    };
    let mut r = Renderer::new(&gpu, &scene, settings).unwrap();
    r.render(&gpu, &scene, &cams, 0.0).unwrap();
    let cube = face_cube(&gpu);
    let plain = embedded(&gpu, &scene, 1, false);
    let config = EmbeddedReflectionsConfig {
        environment: Some(cube.clone()),
        ..plain.config().clone()
    };
    let lit = EmbeddedReflections::new(&gpu.adapter, &gpu.device, &gpu.queue, config).unwrap();
    let t = |n| r.target_texture(n).unwrap();
    let layer = |n| TextureLayer {
        texture: t(n),
        layer: 0,
    };
    let inputs = ReflectionInputs {
        gbuffer: AoInputs::new(layer("depth"), layer("normal"), view, proj),
        material: layer("normal"),
        radiance: layer("hdr"),
        second_radiance: None,
    };
    let mut out = Vec::new();
    for mut refl in [plain, lit] {
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        refl.encode(&mut encoder, &inputs).expect("valid inputs");
        gpu.queue.submit([encoder.finish()]);
        gpu.check_errors().expect("no wgpu validation errors");
        out.push(refl.read_target("reflection").unwrap());
    }
    let normals = r.read_target_full(&gpu, "normal", 0).unwrap();
    let u = r.frame_uniforms();
    let v3 = |a: [f32; 4]| Vec3::new(a[0], a[1], a[2]);
    let (fwd, right, up) = (v3(u.cam_forward), v3(u.cam_right), v3(u.cam_up));
    let (mut checked, mut wrong, mut faces) = (0, 0, [0usize; 6]);
    for (i, (a, b)) in out[0].data.chunks_exact(4).zip(out[1].data.chunks_exact(4)).enumerate() {
        assert_eq!(a[3], b[3], "pixel {i}: the cube changed what the ray found");
        if a[3] >= 2.0 {
            assert_eq!(a[..3], b[..3], "pixel {i}: a hit's radiance changed");
        }
        if a[3] != 1.0 {
            continue;
        }
        assert_eq!(a[..3], [0.0; 3], "without a cube, rgb 0 where nothing is found");
        let (x, y) = ((i as u32 % W) as f32, (i as u32 / W) as f32);
        let ndc = (2.0 * (x + 0.5) / W as f32 - 1.0, 1.0 - 2.0 * (y + 0.5) / H as f32);
        let d = (fwd + right * ndc.0 + up * ndc.1).normalize();
        let q = |c: f32| (c * 255.0).round() as u8;
        let n = strata_render::packing::oct16_unpack([q(normals.data[i * 4]), q(normals.data[i * 4 + 1])]);
        let rd = d - 2.0 * d.dot(n) * n;
        let (face, fs, ft) = strata_scene::environment::cube_face(rd);
        if !(0.15..=0.85).contains(&fs) || !(0.15..=0.85).contains(&ft) {
            continue;
        }
        // between the texel centres (k + ½) / 4: 20 + 60 (4 s − ½)
        let expected = [
            (20.0 + 60.0 * (4.0 * fs - 0.5)) / 255.0,
            (20.0 + 60.0 * (4.0 * ft - 0.5)) / 255.0,
            (20.0 + 40.0 * face as f32) / 255.0,
        ];
        checked += 1;
        faces[face] += 1;
        if (0..3).any(|k| (b[k] - expected[k]).abs() > 3.0 / 255.0) {
            if wrong < 3 {
                println!("pixel {i}: {:?} against {expected:?}", &b[..3]);
            }
            wrong += 1;
        }
    }
    println!("{checked} environment pixels checked, per face {faces:?}, {wrong} wrong");
    assert!(checked > 500, "only {checked} mirror pixels reflect the environment");
    assert_eq!(wrong, 0, "{wrong} of {checked} pixels reflect another face");
}

#[test]
fn bad_embedded_reflections_input_is_a_one_line_error() {
    use wgpu::TextureFormat as F;
    let gpu = common::gpu();
    let config = EmbeddedReflectionsConfig {
        width: W,
        height: H,
        ..EmbeddedReflectionsConfig::default()
    };
    let new = |f: &dyn Fn(&mut EmbeddedReflectionsConfig)| {
        let mut c = config.clone();
        f(&mut c);
        EmbeddedReflections::new(&gpu.adapter, &gpu.device, &gpu.queue, c)
    };
    let one_line = |e: String, words: &[&str]| common::assert_one_line(&e, words);
    let err = |f: &dyn Fn(&mut EmbeddedReflectionsConfig)| new(f).err().expect("an error").to_string();
    one_line(
        err(&|c| c.material.metallic = 4),
        &["embedded reflections", "material.metallic channel 4", "0..=3"],
    );
    one_line(err(&|c| c.min_separation = 0.0), &["min_separation 0", "> 0"]);
    one_line(
        err(&|c| c.settings.steps = 0),
        &["embedded reflections", "steps 0", "1..=1024"],
    );
    one_line(err(&|c| c.settings.max_roughness = 2.0), &["max_roughness 2", "0..=1"]);
    one_line(err(&|c| c.layers = 3), &["layers 3", "1..=2"]);
    one_line(err(&|c| c.width = 0), &["size 0x120"]);
    let flat = common::app_texture(&gpu, [8, 8], F::Rgba8Unorm, wgpu::TextureUsages::TEXTURE_BINDING, 1);
    one_line(
        err(&|c| c.environment = Some(flat.clone())),
        &["embedded reflections: environment", "8x8x1", "6 square layers"],
    );
    let unfiltered =
        strata_render::passes::reflections::cube_texture(&gpu, 4, F::R32Uint, wgpu::TextureUsages::TEXTURE_BINDING);
    one_line(
        err(&|c| c.environment = Some(unfiltered.clone())),
        &["environment format R32Uint", "filterable float"],
    );

    let texture = |format| common::app_texture(&gpu, [W, H], format, wgpu::TextureUsages::TEXTURE_BINDING, 1);
    let (depth, normals) = (texture(F::Depth32Float), texture(F::Rgba16Float));
    let (material, srgb, hdr) = (
        texture(F::Rgba8Unorm),
        texture(F::Rgba8UnormSrgb),
        texture(F::Rgba16Float),
    );
    let cam = strata_scene::Camera::default();
    let gbuffer = AoInputs::new(
        (&depth).into(),
        (&normals).into(),
        cam.view(),
        cam.projection(W as f32 / H as f32),
    );
    let ok = ReflectionInputs {
        gbuffer,
        material: (&material).into(),
        radiance: (&hdr).into(),
        second_radiance: None,
    };
    let mut refl = new(&|_| {}).unwrap();
    let mut encode = |i: ReflectionInputs<'_>| {
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        let e = refl.encode(&mut encoder, &i).err().map(|e| e.to_string());
        gpu.queue.submit([encoder.finish()]);
        e
    };
    one_line(
        encode(ReflectionInputs {
            material: (&srgb).into(),
            ..ok
        })
        .expect("an error"),
        &[
            "embedded reflections: material has format Rgba8UnormSrgb",
            "linear twin",
        ],
    );
    one_line(
        encode(ReflectionInputs {
            second_radiance: Some((&hdr).into()),
            ..ok
        })
        .expect("an error"),
        &["ReflectionInputs::second_radiance", "1 layer"],
    );
    one_line(
        encode(ReflectionInputs {
            radiance: (&depth).into(),
            ..ok
        })
        .expect("an error"),
        &["embedded reflections: radiance has format Depth32Float"],
    );
    // an sRGB radiance (a display-referred image) is decoded and taken
    assert_eq!(
        encode(ReflectionInputs {
            radiance: (&srgb).into(),
            ..ok
        }),
        None
    );
    assert_eq!(encode(ok), None);
    gpu.check_errors().expect("no wgpu validation errors");

    let mut two = new(&|c| c.layers = 2).unwrap();
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    let e = two
        .encode(
            &mut encoder,
            &ReflectionInputs {
                gbuffer: AoInputs {
                    second: Some(((&depth).into(), (&normals).into())),
                    ..gbuffer
                },
                ..ok
            },
        )
        .unwrap_err()
        .to_string();
    one_line(e, &["2 layers need ReflectionInputs::second_radiance"]);
    // resizing keeps the config and checks the new size
    two.resize(64, 48).unwrap();
    assert_eq!(
        (two.config().width, two.config().height, two.config().layers),
        (64, 48, 2)
    );
    one_line(two.resize(0, 48).unwrap_err().to_string(), &["size 0x48"]);
    assert_eq!(two.config().width, 64, "the old size stays on error");
}
