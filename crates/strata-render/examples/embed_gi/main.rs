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

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out = std::env::args().nth(1).unwrap_or_else(|| "embed-gi.png".into());
    let (width, height) = (480u32, 320u32);
    let mut app = app::OpenBox::new(width, height)?;
    println!("passes: {}", app.gi.pass_names().join(" → "));
    for _ in 0..16 {
        app.frame(|_, _| Ok(()))?;
    }
    app::print_timings(&app.gi.timings()?);

    // the application's composite, here on the CPU from strata's imported copies of its
    // buffers: direct B on the left, B + ρ/π · E on the right
    let e = app.gi.read_target("indirect")?;
    app.composite(&[None, Some(&e)])?.save(&out)?;
    let confidence: f64 = e.data.chunks_exact(4).map(|p| p[3] as f64).sum();
    println!(
        "wrote {out}: direct | direct + indirect, {width}x{height} each; mean confidence {:.2}",
        confidence / (width * height) as f64
    );
    Ok(())
}
