//! strata's bounced-z-buffer AO (BZB §3) in an application's own wgpu renderer.
//!
//! The "application" (`../embed_ao/app.rs`) draws a floor, the boxes of the `embed_ao`
//! example and a table whose top lies above the camera's view: the camera crouches under
//! it. The G-buffer therefore holds the floor beneath the table but not the table top.
//! It asks for the ambient visibility of the same frame twice:
//! - `EmbeddedAo` (DGB's screen-space AO) sees only the G-buffer, so the floor under the
//!   table stays white;
//! - `EmbeddedBzbAo` splats the application's triangles into the bounced z-buffer, so the
//!   table top it never sees darkens the floor under it (binary AO within r = 0.6).
//!
//! Both warm their temporal filters up for 8 frames; the PNG has them side by side:
//!
//! ```sh
//! cargo run --release -p strata-render --example embed_bzb -- out/embed-bzb.png
//! ```

#[path = "../embed_ao/app.rs"]
mod app;

use glam::Vec3;
use strata_render::embed::{AoInputs, EmbeddedAo, EmbeddedAoConfig, EmbeddedBzbAo, EmbeddedBzbAoConfig};
use strata_render::passes::ao::AoSettings;
use strata_render::passes::bzb::{self, BzbSettings};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out = std::env::args().nth(1).unwrap_or_else(|| "embed-bzb.png".into());
    let (width, height) = (480u32, 320u32);
    let (adapter, device, queue) = app::open_device(wgpu::Features::empty())?;

    // the scene: a floor, three boxes, a wall, and a table over the camera
    let grey = Vec3::splat(0.5);
    let mut scene = app::cuboid(Vec3::new(-6.0, -0.2, -6.0), Vec3::new(6.0, 0.0, 6.0), grey);
    scene.extend(app::cuboid(
        Vec3::new(-1.5, 0.0, -3.0),
        Vec3::new(-0.5, 1.0, -2.0),
        grey,
    ));
    scene.extend(app::cuboid(Vec3::new(0.2, 0.0, -2.6), Vec3::new(0.8, 2.0, -2.1), grey));
    scene.extend(app::cuboid(Vec3::new(-3.0, 0.0, -5.0), Vec3::new(3.0, 3.0, -4.6), grey));
    scene.extend(app::cuboid(Vec3::new(-1.2, 0.5, -1.0), Vec3::new(1.2, 0.55, 1.4), grey));
    for (x, z) in [(-1.15, -0.95), (1.1, -0.95), (-1.15, 1.3), (1.1, 1.3)] {
        scene.extend(app::cuboid(
            Vec3::new(x, 0.0, z),
            Vec3::new(x + 0.05, 0.5, z + 0.05),
            grey,
        ));
    }
    let triangles: Vec<[Vec3; 3]> = scene.iter().map(|t| t.0).collect();
    use glam::camera::rh;
    let view = rh::view::look_at_mat4(Vec3::new(0.0, 0.35, 0.6), Vec3::new(0.0, 0.0, -1.0), Vec3::Y);
    let proj = rh::proj::directx::perspective(30f32.to_radians(), width as f32 / height as f32, 0.05, 100.0);
    let gbuffer = app::GBuffer::new(&device, [width, height], app::Layout::standard(), &scene);

    let radius = 0.6;
    let mut dgb = EmbeddedAo::new(
        &adapter,
        &device,
        &queue,
        EmbeddedAoConfig {
            width,
            height,
            settings: AoSettings {
                radius: Some(radius),
                ..AoSettings::default()
            },
            ..EmbeddedAoConfig::default()
        },
    )?;
    // the application's triangles, in world space (again with `set_triangles` when they move)
    let mut bzb = EmbeddedBzbAo::new(
        &adapter,
        &device,
        &queue,
        EmbeddedBzbAoConfig {
            width,
            height,
            settings: BzbSettings {
                radius: Some(radius),
                // BZB §6's re-projection: a still camera averages 4 new directions a frame
                temporal: Some(bzb::temporal_filter()),
                ..BzbSettings::default()
            },
            ..EmbeddedBzbAoConfig::default()
        },
        &triangles,
    )?;
    println!("bzb passes: {}", bzb.pass_names().join(" → "));
    for _ in 0..8 {
        let mut encoder = device.create_command_encoder(&Default::default());
        gbuffer.draw(&queue, &mut encoder, view, proj);
        let inputs = AoInputs::new((&gbuffer.depth).into(), (&gbuffer.normals).into(), view, proj);
        dgb.encode(&mut encoder, &inputs)?;
        bzb.encode(&mut encoder, &inputs)?;
        queue.submit([encoder.finish()]);
    }
    println!("DGB AO (screen space):");
    app::print_timings(&dgb.timings()?);
    println!("bounced z-buffer ({} triangles):", bzb.triangle_count());
    app::print_timings(&bzb.timings()?);

    let (a, b) = (dgb.read_target("ao")?, bzb.read_target("ao")?);
    let mut img = image::GrayImage::new(2 * width, height);
    for (k, av) in [&a, &b].into_iter().enumerate() {
        for y in 0..height {
            for x in 0..width {
                let v = av.data[(y * width + x) as usize].clamp(0.0, 1.0);
                img.put_pixel(k as u32 * width + x, y, image::Luma([(v * 255.0).round() as u8]));
            }
        }
    }
    img.save(&out)?;
    let mean = |av: &strata_scene::ImageBuf| av.data.iter().sum::<f32>() / av.data.len() as f32;
    println!(
        "wrote {out}: left DGB AO (mean AV {:.3}), right bounced z-buffer AO (mean AV {:.3})",
        mean(&a),
        mean(&b)
    );
    Ok(())
}
