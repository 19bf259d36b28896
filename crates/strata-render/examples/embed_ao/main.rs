//! strata's deep-G-buffer AO in an application's own wgpu renderer.
//!
//! The "application" opens its own device, draws a few boxes on a floor into its own
//! depth and normal textures (`gbuffer.rs`, plain wgpu, standard depth, signed world
//! normals), peels DGB's second layer behind them (the nearest surfaces at least Δz = 0.5
//! further), and asks `strata_render::embed::EmbeddedAo` for the ambient visibility of
//! both layers. It warms the temporal filter up for 8 frames and writes the AO as a PNG:
//!
//! ```sh
//! cargo run --release -p strata-render --example embed_ao -- out/embed-ao.png
//! ```

mod gbuffer;

use glam::Vec3;
use strata_render::embed::{AoInputs, EmbeddedAo, EmbeddedAoConfig, NormalEncoding};
use strata_render::passes::ao::AoSettings;

/// A box's 12 triangles (outward normals, counter-clockwise seen from outside).
fn cuboid(lo: Vec3, hi: Vec3) -> Vec<([Vec3; 3], [Vec3; 3])> {
    let c = |i: usize| {
        Vec3::new(
            if i & 1 != 0 { hi.x } else { lo.x },
            if i & 2 != 0 { hi.y } else { lo.y },
            if i & 4 != 0 { hi.z } else { lo.z },
        )
    };
    // each face: four corners counter-clockwise from outside, and its normal
    let faces = [
        ([0, 4, 6, 2], -Vec3::X),
        ([1, 3, 7, 5], Vec3::X),
        ([0, 1, 5, 4], -Vec3::Y),
        ([2, 6, 7, 3], Vec3::Y),
        ([0, 2, 3, 1], -Vec3::Z),
        ([4, 5, 7, 6], Vec3::Z),
    ];
    faces
        .iter()
        .flat_map(|(q, n)| {
            let p = q.map(c);
            [([p[0], p[1], p[2]], [*n; 3]), ([p[0], p[2], p[3]], [*n; 3])]
        })
        .collect()
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out = std::env::args().nth(1).unwrap_or_else(|| "embed-ao.png".into());
    let (width, height) = (640u32, 360u32);

    // the application's device (any adapter: lavapipe where there is no GPU)
    let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
    let adapter = pollster::block_on(instance.request_adapter(&Default::default()))?;
    // timestamps, where the adapter has them, let strata report its passes' GPU time
    let timing = wgpu::Features::TIMESTAMP_QUERY | wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS;
    let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
        required_features: adapter.features() & timing,
        ..Default::default()
    }))?;

    // its scene and camera (right-handed, standard depth in [0, 1])
    let mut triangles = cuboid(Vec3::new(-6.0, -0.2, -6.0), Vec3::new(6.0, 0.0, 6.0));
    triangles.extend(cuboid(Vec3::new(-1.5, 0.0, -1.0), Vec3::new(-0.5, 1.0, 0.0)));
    triangles.extend(cuboid(Vec3::new(0.2, 0.0, -0.6), Vec3::new(0.8, 2.0, -0.1)));
    triangles.extend(cuboid(Vec3::new(-3.0, 0.0, -3.0), Vec3::new(3.0, 3.0, -2.6)));
    use glam::camera::rh;
    let view = rh::view::look_at_mat4(Vec3::new(1.5, 2.2, 4.0), Vec3::new(-0.3, 0.6, -1.0), Vec3::Y);
    let proj = rh::proj::directx::perspective(50f32.to_radians(), width as f32 / height as f32, 0.05, 100.0);
    let first = gbuffer::GBuffer::new(
        &device,
        [width, height],
        gbuffer::Layout {
            depth: wgpu::TextureFormat::Depth32Float,
            normal: wgpu::TextureFormat::Rgba16Float,
            normals: gbuffer::Normals::WorldSigned,
            reversed: false,
        },
        &triangles,
    );
    let second = gbuffer::GBuffer::second_layer(&device, &first, 0.5, &triangles);

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
            normals: NormalEncoding::Signed,
            ..EmbeddedAoConfig::default()
        },
    )?;
    println!("passes: {}", ao.pass_names().join(" → "));
    for _ in 0..8 {
        let mut encoder = device.create_command_encoder(&Default::default());
        first.draw(&queue, &mut encoder, view, proj);
        second.draw(&queue, &mut encoder, view, proj);
        let inputs = AoInputs {
            second: Some(((&second.depth).into(), (&second.normals).into())),
            ..AoInputs::new((&first.depth).into(), (&first.normals).into(), view, proj)
        };
        ao.encode(&mut encoder, &inputs)?;
        queue.submit([encoder.finish()]);
    }

    let timings = ao.timings()?;
    if !timings.passes.is_empty() {
        let each: Vec<String> = timings.passes.iter().map(|(n, ms)| format!("{n} {ms:.2}")).collect();
        println!("GPU ms, last frame: {} (total {:.2})", each.join(", "), timings.total());
    }

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
