//! strata's interleaved deferred shading (ILS) in an application's own wgpu renderer, beside
//! its deep-G-buffer radiosity.
//!
//! The "application" draws the open box of `embed_gi` (`../embed_ao/app.rs`), lit by a sun
//! without shadows. It makes its own virtual point lights, instant radiosity's first
//! bounce (Keller 1997; ILS §2): 256 points on the sunlit front faces of its
//! triangles, in proportion to the power each face reflects, each carrying its share
//! Φ = ρ · E_sun cos θ · A. It hands them, its depth and normals and its triangles (for the
//! VPLs' shadow maps, SSM) to `strata_render::embed::EmbeddedIls` with the `clean-edges`
//! preset, and its lit G-buffer to `EmbeddedRadiosity` (2 layers, 16 frames). It composes
//! `B + ρ/π · E` with each technique's E on the CPU and writes three panels side by side
//! as a PNG: direct light, + DGB radiosity, + ILS:
//!
//! ```sh
//! cargo run --release -p strata-render --example embed_ils -- out/embed-ils.png
//! ```

#[path = "../embed_ao/app.rs"]
mod app;

use glam::Vec3;
use strata_render::embed::{EmbeddedIls, EmbeddedIlsConfig, NormalEncoding};
use strata_render::passes::ils::{GpuVpl, IlsSettings, VplShadows};

/// `count` VPLs on the front faces of `triangles` that face `sun`, allotted in proportion
/// to the power each reflects (its luminance) and placed at stratified points.
fn sun_vpls(triangles: &[app::Triangle], sun: app::Sun, count: usize) -> Vec<GpuVpl> {
    let l = sun.direction.normalize();
    // reflected power of each lit front face: ρ ⊙ E cos θ · A
    let power: Vec<(usize, Vec3)> = triangles
        .iter()
        .enumerate()
        .filter_map(|(i, (p, n, s))| {
            let cos = n[0].dot(l);
            let area = 0.5 * (p[1] - p[0]).cross(p[2] - p[0]).length();
            (cos > 0.0).then(|| (i, s.albedo * sun.irradiance * (cos * area)))
        })
        .collect();
    let luminance = |c: Vec3| c.dot(Vec3::new(0.2126, 0.7152, 0.0722));
    let total: f32 = power.iter().map(|(_, c)| luminance(*c)).sum();
    let mut vpls = Vec::with_capacity(count);
    let mut carried = 0.0f32;
    for (i, c) in &power {
        // the running total's share decides how many land here (largest remainder)
        let before = (carried / total * count as f32).round() as usize;
        carried += luminance(*c);
        let k = (carried / total * count as f32).round() as usize - before;
        let (p, n, _) = &triangles[*i];
        for j in 0..k {
            // stratified barycentric points: the golden-ratio sequence, square-root warped
            let (u, v) = ((j as f32 + 0.5) / k as f32, (j as f32 * 0.618_034).fract());
            let su = u.sqrt();
            let q = p[0] * (1.0 - su) + p[1] * (su * (1.0 - v)) + p[2] * (su * v);
            vpls.push(GpuVpl::new(q.into(), n[0].into(), (*c / k as f32).into()));
        }
    }
    vpls
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out = std::env::args().nth(1).unwrap_or_else(|| "embed-ils.png".into());
    let (width, height) = (480u32, 320u32);
    let mut app = app::OpenBox::new(width, height)?;
    let (triangles, sun, _, _) = app::open_box(width, height);
    // SSM keeps one shadow-map layer per VPL: 256 fit every device's array limit
    let vpls = sun_vpls(&triangles, sun, 256);
    let mut ils = EmbeddedIls::new(
        &app.adapter,
        &app.device,
        &app.queue,
        EmbeddedIlsConfig {
            width,
            height,
            settings: IlsSettings {
                vpls: vpls.clone().into(),
                // below d_c a VPL's 1/d² is held: 4 % of the scene's diagonal (6 m), the
                // renderer's default
                clamp_distance: Some(0.24),
                shadows: VplShadows::ShadowMaps,
                ..IlsSettings::default()
            }
            // the blur stops per axis at edges and slides its cut windows (`docs/ils.md`),
            // against the paper's filter's dotted outlines
            .with_preset("clean-edges")?,
            normals: NormalEncoding::Signed,
            // SSM (§4.3): the VPLs' shadow maps of the application's triangles
            triangles: triangles.iter().map(|t| t.0).collect(),
            ..EmbeddedIlsConfig::default()
        },
    )?;
    println!("{} VPLs; ILS passes: {}", vpls.len(), ils.pass_names().join(" → "));
    for frame in 0..16 {
        // ILS needs no history: one frame is its image (the last one is kept)
        app.frame(|encoder, layer0| match frame {
            15 => ils.encode(encoder, layer0),
            _ => Ok(()),
        })?;
    }
    println!("ILS:");
    app::print_timings(&ils.timings()?);

    // the application's composite: B | B + ρ/π · E_DGB | B + ρ/π · E_ILS
    let e_dgb = app.gi.read_target("indirect")?;
    let e_ils = ils.read_target(ils.config().settings.output().name)?;
    app.composite(&[None, Some(&e_dgb), Some(&e_ils)])?.save(&out)?;
    let mean = |e: &strata_scene::ImageBuf| {
        e.data.chunks_exact(4).map(|p| p[0] + p[1] + p[2]).sum::<f32>() / (3 * width * height) as f32
    };
    println!(
        "wrote {out}: direct | + DGB radiosity | + ILS, {width}x{height} each; mean irradiance E: DGB {:.3}, ILS {:.3}",
        mean(&e_dgb),
        mean(&e_ils)
    );
    Ok(())
}
