//! strata's deep-G-buffer mirror reflections (DGB §3.6) in an application's own wgpu
//! renderer.
//!
//! The "application" draws a polished metal floor in front of a grey board that stands
//! 0.5 above it. Behind the board, hidden from the camera, stands a red panel; a blue wall
//! closes the room. Its lighting is a sun without shadows (`../embed_ao/app.rs`), which
//! gives each pixel's outgoing radiance and its glTF material (roughness, metallic). It
//! peels DGB's second layer and lights that too, and asks
//! `strata_render::embed::EmbeddedReflections` for the reflected radiance with one layer
//! and with two. It composes `B + F0 · L` on the CPU (its sky where the ray found nothing)
//! and writes three images side by side as a PNG: without reflections, one layer, two
//! layers. Only the second layer holds the red panel that the floor reflects under the
//! board.
//!
//! ```sh
//! cargo run --release -p strata-render --example embed_reflect -- out/embed-reflect.png
//! ```

#[path = "../embed_ao/app.rs"]
mod app;

use glam::Vec3;
use strata_render::embed::{
    AoInputs, EmbeddedReflections, EmbeddedReflectionsConfig, MaterialChannels, NormalEncoding, ReflectionInputs,
};

/// The floor's F0: the application's metal.
const MIRROR_F0: Vec3 = Vec3::splat(0.9);
/// The application's sky, for reflection rays that find nothing on screen.
const SKY: Vec3 = Vec3::new(0.4, 0.5, 0.7);
/// Δz of the application's second layer.
const MIN_SEPARATION: f32 = 0.2;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out = std::env::args().nth(1).unwrap_or_else(|| "embed-reflect.png".into());
    let (width, height) = (320u32, 240u32);
    let (adapter, device, queue) = app::open_device(wgpu::Features::empty())?;

    let mut triangles = app::cuboid(
        Vec3::new(-4.0, -0.1, -3.0),
        Vec3::new(4.0, 0.0, 3.5),
        app::Surface::mirror(MIRROR_F0),
    );
    triangles.extend(app::cuboid(
        Vec3::new(-1.2, 0.5, -0.05),
        Vec3::new(1.2, 1.8, 0.0),
        Vec3::splat(0.5),
    ));
    triangles.extend(app::cuboid(
        Vec3::new(-0.8, 0.45, -0.85),
        Vec3::new(0.8, 1.3, -0.8),
        Vec3::new(0.8, 0.1, 0.05),
    ));
    triangles.extend(app::cuboid(
        Vec3::new(-4.0, 0.0, -3.05),
        Vec3::new(4.0, 4.0, -3.0),
        Vec3::new(0.3, 0.4, 0.7),
    ));
    // from above and in front: it lights the board, the panel and the wall's faces
    let sun = app::Sun {
        direction: Vec3::new(0.3, 1.0, 0.8),
        irradiance: Vec3::splat(3.0),
    };
    use glam::camera::rh;
    let view = rh::view::look_at_mat4(Vec3::new(0.0, 1.0, 4.0), Vec3::new(0.0, 0.5, 0.0), Vec3::Y);
    let proj = rh::proj::directx::perspective(50f32.to_radians(), width as f32 / height as f32, 0.05, 50.0);
    let layout = app::Layout::standard();
    let first = app::GBuffer::lit(&device, [width, height], layout, &triangles, sun);
    let second = app::GBuffer::second_layer_lit(&device, &first, MIN_SEPARATION, &triangles);

    let config = |layers| EmbeddedReflectionsConfig {
        width,
        height,
        layers,
        min_separation: MIN_SEPARATION,
        normals: NormalEncoding::Signed,
        // the application's material texture is glTF's: roughness in g, metallic in b
        material: MaterialChannels::default(),
        ..EmbeddedReflectionsConfig::default()
    };
    let mut one = EmbeddedReflections::new(&adapter, &device, &queue, config(1))?;
    let mut two = EmbeddedReflections::new(&adapter, &device, &queue, config(2))?;
    println!("passes: {}", two.pass_names().join(" → "));
    let (_, b0) = first.shading.as_ref().ok_or("lit")?;
    let (_, b1) = second.shading.as_ref().ok_or("lit")?;
    let material = first.material.as_ref().ok_or("lit")?;

    // a few frames, as an application runs: the timings are the last frame's
    for _ in 0..4 {
        let mut encoder = device.create_command_encoder(&Default::default());
        first.draw(&queue, &mut encoder, view, proj);
        second.draw(&queue, &mut encoder, view, proj);
        let inputs = ReflectionInputs {
            gbuffer: AoInputs::new((&first.depth).into(), (&first.normals).into(), view, proj),
            material: material.into(),
            radiance: b0.into(),
            second_radiance: None,
        };
        one.encode(&mut encoder, &inputs)?;
        two.encode(
            &mut encoder,
            &ReflectionInputs {
                gbuffer: AoInputs {
                    second: Some(((&second.depth).into(), (&second.normals).into())),
                    ..inputs.gbuffer
                },
                second_radiance: Some(b1.into()),
                ..inputs
            },
        )?;
        queue.submit([encoder.finish()]);
    }
    app::print_timings(&two.timings()?);

    // the application's composite, here on the CPU from strata's imported copy of its
    // image: B, then B + F0 · L with one layer and with two (the sky where a = 1)
    let base = two.read_target("hdr")?;
    let mut img = image::RgbImage::new(3 * width, height);
    let mut hidden = 0;
    for (panel, refl) in [(1, one.read_target("reflection")?), (2, two.read_target("reflection")?)] {
        for y in 0..height {
            for x in 0..width {
                let (b, r) = (base.pixel(x, y), refl.pixel(x, y));
                let l = match r[3] {
                    0.0 => Vec3::ZERO,
                    1.0 => SKY,
                    _ => Vec3::new(r[0], r[1], r[2]),
                };
                if panel == 2 && r[3] == 3.0 {
                    hidden += 1;
                }
                let f = if r[3] > 0.0 { MIRROR_F0 * l } else { Vec3::ZERO };
                for k in 0..3 {
                    img.get_pixel_mut(x, y)[k] = app::display(b[k]);
                    img.get_pixel_mut(panel * width + x, y)[k] = app::display(b[k] + f[k]);
                }
            }
        }
    }
    img.save(&out)?;
    println!(
        "wrote {out}: no reflections | 1 layer | 2 layers, {width}x{height} each; {hidden} px reflect the second layer"
    );
    Ok(())
}
