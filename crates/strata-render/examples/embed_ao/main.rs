//! strata's deep-G-buffer AO in an application's own wgpu renderer.
//!
//! The "application" opens its own device, draws a few boxes on a floor into its own
//! depth and normal textures (`app.rs`, plain wgpu, standard depth, signed world
//! normals), peels DGB's second layer behind them (the nearest surfaces at least Δz = 0.5
//! further), and asks `strata_render::embed::EmbeddedAo` for the ambient visibility of
//! both layers. It warms the temporal filter up for 8 frames and writes the AO as a PNG:
//!
//! ```sh
//! cargo run --release -p strata-render --example embed_ao -- out/embed-ao.png
//! # an application without a normal buffer: strata reconstructs the normals from depth
//! cargo run --release -p strata-render --example embed_ao -- out/embed-ao-depth.png --normals-from-depth
//! ```

mod app;

use glam::Vec3;
use strata_render::embed::{AoInputs, EmbeddedAo, EmbeddedAoConfig, NormalEncoding};
use strata_render::passes::ao::AoSettings;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out = std::env::args().nth(1).unwrap_or_else(|| "embed-ao.png".into());
    let from_depth = std::env::args().any(|a| a == "--normals-from-depth");
    let (width, height) = (640u32, 360u32);

    // the application's device (any adapter: lavapipe where there is no GPU)
    let (adapter, device, queue) = app::open_device(wgpu::Features::empty())?;

    // its scene and camera (right-handed, standard depth in [0, 1])
    let grey = Vec3::splat(0.5);
    let mut triangles = app::cuboid(Vec3::new(-6.0, -0.2, -6.0), Vec3::new(6.0, 0.0, 6.0), grey);
    triangles.extend(app::cuboid(Vec3::new(-1.5, 0.0, -1.0), Vec3::new(-0.5, 1.0, 0.0), grey));
    triangles.extend(app::cuboid(Vec3::new(0.2, 0.0, -0.6), Vec3::new(0.8, 2.0, -0.1), grey));
    triangles.extend(app::cuboid(Vec3::new(-3.0, 0.0, -3.0), Vec3::new(3.0, 3.0, -2.6), grey));
    use glam::camera::rh;
    let view = rh::view::look_at_mat4(Vec3::new(1.5, 2.2, 4.0), Vec3::new(-0.3, 0.6, -1.0), Vec3::Y);
    let proj = rh::proj::directx::perspective(50f32.to_radians(), width as f32 / height as f32, 0.05, 100.0);
    let first = app::GBuffer::new(&device, [width, height], app::Layout::standard(), &triangles);
    let second = app::GBuffer::second_layer(&device, &first, 0.5, &triangles);

    // strata's AO on that G-buffer: the radius is in the application's units (metres here)
    let mut ao = EmbeddedAo::new(
        &adapter,
        &device,
        &queue,
        EmbeddedAoConfig {
            width,
            height,
            layers: 2,
            settings: AoSettings {
                radius: Some(0.6),
                ..AoSettings::default()
            },
            normals: if from_depth {
                NormalEncoding::FromDepth
            } else {
                NormalEncoding::Signed
            },
            ..EmbeddedAoConfig::default()
        },
    )?;
    println!("passes: {}", ao.pass_names().join(" → "));
    for _ in 0..8 {
        let mut encoder = device.create_command_encoder(&Default::default());
        first.draw(&queue, &mut encoder, view, proj);
        second.draw(&queue, &mut encoder, view, proj);
        let inputs = match from_depth {
            false => AoInputs {
                second: Some(((&second.depth).into(), (&second.normals).into())),
                ..AoInputs::new((&first.depth).into(), (&first.normals).into(), view, proj)
            },
            true => AoInputs {
                second: Some(((&second.depth).into(), (&second.depth).into())),
                ..AoInputs::depth_only((&first.depth).into(), view, proj)
            },
        };
        ao.encode(&mut encoder, &inputs)?;
        queue.submit([encoder.finish()]);
    }

    app::print_timings(&ao.timings()?);

    // what the application's lighting pass would sample: AV in [0, 1]
    let av = ao.read_target("ao")?;
    let grey: Vec<u8> = av
        .data
        .iter()
        .map(|v| (v.clamp(0.0, 1.0) * 255.0).round() as u8)
        .collect();
    image::GrayImage::from_raw(width, height, grey)
        .ok_or("AO size")?
        .save(&out)?;
    let mean = av.data.iter().sum::<f32>() / av.data.len() as f32;
    println!("wrote {out}: {width}x{height}, mean AV {mean:.3}");
    Ok(())
}
