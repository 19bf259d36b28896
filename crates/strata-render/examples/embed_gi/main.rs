//! strata's deep-G-buffer radiosity in an application's own wgpu renderer.
//!
//! The "application" draws an open box (a red wall on the left, a green one on the right, a
//! white floor and back wall) around two white blocks. Its lighting is a sun without
//! shadows, which gives each pixel's albedo and outgoing diffuse radiance
//! (`../embed_ao/app.rs`). It peels DGB's second layer and lights that too, and asks
//! `strata_render::embed::EmbeddedRadiosity` for the indirect irradiance E of 16 frames
//! (the progressive bounces build up). It then composes `B + ρ/π · E` on the CPU and writes
//! the direct light and the composite side by side as a PNG:
//!
//! ```sh
//! cargo run --release -p strata-render --example embed_gi -- out/embed-gi.png
//! ```

#[path = "../embed_ao/app.rs"]
mod app;

use glam::Vec3;
use strata_render::embed::{AoInputs, EmbeddedRadiosity, EmbeddedRadiosityConfig, NormalEncoding, RadiosityInputs};
use strata_render::passes::radiosity::RadiositySettings;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out = std::env::args().nth(1).unwrap_or_else(|| "embed-gi.png".into());
    let (width, height) = (480u32, 320u32);
    // the radiosity buffers are R11G11B10 render targets (DGB Table 1)
    let (adapter, device, queue) = app::open_device(wgpu::Features::RG11B10UFLOAT_RENDERABLE)?;

    let (white, red, green) = (
        Vec3::splat(0.75),
        Vec3::new(0.75, 0.08, 0.06),
        Vec3::new(0.1, 0.6, 0.12),
    );
    let mut triangles = app::cuboid(Vec3::new(-2.0, -0.1, -2.0), Vec3::new(2.0, 0.0, 2.0), white);
    triangles.extend(app::cuboid(Vec3::new(-2.0, 0.0, -2.0), Vec3::new(-1.9, 2.0, 2.0), red));
    triangles.extend(app::cuboid(Vec3::new(1.9, 0.0, -2.0), Vec3::new(2.0, 2.0, 2.0), green));
    triangles.extend(app::cuboid(
        Vec3::new(-1.9, 0.0, -2.0),
        Vec3::new(1.9, 2.0, -1.9),
        white,
    ));
    triangles.extend(app::cuboid(
        Vec3::new(-1.2, 0.0, -1.0),
        Vec3::new(-0.4, 0.8, -0.2),
        white,
    ));
    triangles.extend(app::cuboid(Vec3::new(0.4, 0.0, -1.3), Vec3::new(1.0, 1.4, -0.7), white));
    // from the right and above: it lights the red wall, the floor and the blocks' right faces
    let sun = app::Sun {
        direction: Vec3::new(1.0, 0.8, 0.2),
        irradiance: Vec3::splat(4.0),
    };
    use glam::camera::rh;
    let view = rh::view::look_at_mat4(Vec3::new(0.0, 1.4, 4.2), Vec3::new(0.0, 0.7, -0.5), Vec3::Y);
    let proj = rh::proj::directx::perspective(45f32.to_radians(), width as f32 / height as f32, 0.05, 50.0);
    let layout = app::Layout::standard();
    let first = app::GBuffer::lit(&device, [width, height], layout, &triangles, sun);
    let second = app::GBuffer::second_layer_lit(&device, &first, 0.3, &triangles);

    let mut gi = EmbeddedRadiosity::new(
        &adapter,
        &device,
        &queue,
        EmbeddedRadiosityConfig {
            width,
            height,
            layers: 2,
            settings: RadiositySettings {
                radius: Some(2.0),
                ..RadiositySettings::default()
            },
            min_separation: 0.3,
            normals: NormalEncoding::Signed,
            ..EmbeddedRadiosityConfig::default()
        },
    )?;
    println!("passes: {}", gi.pass_names().join(" → "));
    let (a0, b0) = first.shading.as_ref().ok_or("lit")?;
    let (a1, b1) = second.shading.as_ref().ok_or("lit")?;
    for _ in 0..16 {
        let mut encoder = device.create_command_encoder(&Default::default());
        first.draw(&queue, &mut encoder, view, proj);
        second.draw(&queue, &mut encoder, view, proj);
        let inputs = RadiosityInputs {
            gbuffer: AoInputs {
                second: Some(((&second.depth).into(), (&second.normals).into())),
                ..AoInputs::new((&first.depth).into(), (&first.normals).into(), view, proj)
            },
            albedo: a0.into(),
            radiance: b0.into(),
            second: Some((a1.into(), b1.into())),
        };
        gi.encode(&mut encoder, &inputs)?;
        queue.submit([encoder.finish()]);
    }
    app::print_timings(&gi.timings()?);

    // the application's composite, here on the CPU from strata's imported copies of its
    // buffers: direct B on the left, B + ρ/π · E on the right
    let (e, albedo, b) = (
        gi.read_target("indirect")?,
        gi.read_target("albedo")?,
        gi.read_target("radiosity0")?,
    );
    let mut img = image::RgbImage::new(2 * width, height);
    let mut confidence = 0.0;
    for y in 0..height {
        for x in 0..width {
            let (pe, pa, pb) = (e.pixel(x, y), albedo.pixel(x, y), b.pixel(x, y));
            confidence += pe[3] as f64;
            for k in 0..3 {
                let indirect = pa[k] / std::f32::consts::PI * pe[k];
                img.get_pixel_mut(x, y)[k] = app::display(pb[k]);
                img.get_pixel_mut(width + x, y)[k] = app::display(pb[k] + indirect);
            }
        }
    }
    img.save(&out)?;
    println!(
        "wrote {out}: direct | direct + indirect, {width}x{height} each; mean confidence {:.2}",
        confidence / (width * height) as f64
    );
    Ok(())
}
