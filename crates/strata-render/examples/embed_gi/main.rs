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

use strata_render::embed::{AoInputs, EmbeddedRadiosity, EmbeddedRadiosityConfig, NormalEncoding, RadiosityInputs};
use strata_render::passes::radiosity::RadiositySettings;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out = std::env::args().nth(1).unwrap_or_else(|| "embed-gi.png".into());
    let (width, height) = (480u32, 320u32);
    // the radiosity buffers are R11G11B10 render targets (DGB Table 1)
    let (adapter, device, queue) = app::open_device(wgpu::Features::RG11B10UFLOAT_RENDERABLE)?;

    let (triangles, sun, view, proj) = app::open_box(width, height);
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
