//! `strata reference`: CPU ground truth images (its throughput benchmark is
//! `strata_eval::bench::reference`).

use std::path::{Path, PathBuf};

use anyhow::{bail, Result};
use strata_reference::ao::{AoBinarySettings, ObscuranceSettings};
use strata_reference::gi::GiSettings;
use strata_reference::layers::LayerSettings;
use strata_reference::Reference;
use strata_scene::ImageBuf;

use crate::args::{ReferenceArgs, ReferenceKind};
use crate::output::{check_output, save, scene_and_camera};

pub fn run(a: &ReferenceArgs) -> Result<()> {
    for w in a.unread_flags() {
        eprintln!("strata: warning: {w}");
    }
    let (scene, cams) = scene_and_camera(&a.scene)?;
    let camera = cams.current;
    let (w, h) = (a.scene.width, a.scene.height);
    if a.bounces > 64 {
        bail!("--bounces {} is out of range: must be in 0..=64", a.bounces);
    }
    if !(1..=8).contains(&a.layers) {
        bail!("--layers {} is out of range: must be in 1..=8", a.layers);
    }
    let radius = a.ao_radius.unwrap_or(scene.settings.ao_radius);
    if !(radius > 0.0 && radius.is_finite()) {
        bail!("--ao-radius {radius} is out of range: must be > 0");
    }
    let dz = a.min_separation.unwrap_or(scene.settings.min_separation);
    if !(dz >= 0.0 && dz.is_finite()) {
        bail!("--min-separation {dz} is out of range: must be >= 0");
    }
    let reference = Reference::new(&scene, a.scene.frame).with_progress(!a.quiet);
    let outputs: Vec<(PathBuf, ImageBuf)> = match a.kind {
        ReferenceKind::Ao => {
            check_output(&a.out, a.force)?;
            let s = AoBinarySettings {
                radius,
                spp: a.spp,
                seed: a.seed,
            };
            vec![(a.out.clone(), reference.ao_binary(&camera, w, h, &s))]
        }
        ReferenceKind::Obscurance => {
            check_output(&a.out, a.force)?;
            let s = ObscuranceSettings {
                spp: a.spp,
                seed: a.seed,
                ..ObscuranceSettings::new(radius)
            };
            vec![(a.out.clone(), reference.ao_obscurance(&camera, w, h, &s))]
        }
        ReferenceKind::AoOpacity => {
            check_output(&a.out, a.force)?;
            let s = AoBinarySettings {
                radius,
                spp: a.spp,
                seed: a.seed,
            };
            // channel 0: the strongest-occluder model (ABA Algorithm 1's max)
            let img = reference.ao_with_opacity_image(&camera, w, h, &s);
            let av = ImageBuf {
                width: w,
                height: h,
                channels: 1,
                data: img.data.chunks(3).map(|p| p[0]).collect(),
            };
            vec![(a.out.clone(), av)]
        }
        ReferenceKind::Composite => {
            check_output(&a.out, a.force)?;
            let img = reference.composite(&camera, w, h);
            let img = if is_png(&a.out) {
                tonemap(&img, scene.settings.exposure)
            } else {
                img
            };
            vec![(a.out.clone(), img)]
        }
        ReferenceKind::Gi | ReferenceKind::Indirect => {
            check_output(&a.out, a.force)?;
            let s = GiSettings {
                spp: a.spp,
                bounces: a.bounces,
                seed: a.seed,
                ..Default::default()
            };
            let g = reference.gi(&camera, w, h, &s);
            let img = if a.kind == ReferenceKind::Gi {
                g.total
            } else {
                g.indirect
            };
            let img = if is_png(&a.out) {
                tonemap(&img, scene.settings.exposure)
            } else {
                img
            };
            vec![(a.out.clone(), img)]
        }
        ReferenceKind::Layers => {
            let deep = reference.layers(&camera, w, h, &LayerSettings::new(a.layers as usize, dz));
            let mut v = Vec::new();
            for (j, l) in deep.layers.iter().enumerate() {
                let png = is_png(&a.out);
                let mut depth = l.depth.clone();
                if png {
                    let max = depth
                        .data
                        .iter()
                        .filter(|z| z.is_finite())
                        .fold(0.0f32, |m, &z| m.max(z))
                        .max(1e-9);
                    depth
                        .data
                        .iter_mut()
                        .for_each(|z| *z = if z.is_finite() { *z / max } else { 0.0 });
                }
                let mut normal = l.normal.clone();
                if png {
                    normal.data.iter_mut().for_each(|c| *c = 0.5 + 0.5 * *c);
                }
                v.push((sibling(&a.out, &format!("layer{j}-depth")), depth));
                v.push((sibling(&a.out, &format!("layer{j}-normal")), normal));
                v.push((sibling(&a.out, &format!("layer{j}-albedo")), l.albedo.clone()));
            }
            for (p, _) in &v {
                check_output(p, a.force)?;
            }
            v
        }
    };
    // ambient visibility PNGs hold raw bytes 255·AV, as `render`'s AO PNGs do
    // (so the two compare directly); everything else is sRGB-encoded
    let raw = matches!(
        a.kind,
        ReferenceKind::Ao | ReferenceKind::Obscurance | ReferenceKind::AoOpacity
    );
    for (p, img) in &outputs {
        save(img, p, !raw)?;
        eprintln!("wrote {}", p.display());
    }
    let s = reference.stats();
    eprintln!(
        "{} triangles, BVH built in {:.2} s; {:.1} M rays in {:.2} s = {:.2} M rays/s",
        scene.triangle_count(),
        reference.build_seconds(),
        s.rays as f64 * 1e-6,
        s.seconds,
        s.mrays_per_second()
    );
    Ok(())
}

fn is_png(p: &Path) -> bool {
    p.extension().is_some_and(|e| e.eq_ignore_ascii_case("png"))
}

/// `dir/stem.ext` → `dir/stem-suffix.ext`.
fn sibling(p: &Path, suffix: &str) -> PathBuf {
    let stem = p.file_stem().and_then(|s| s.to_str()).unwrap_or("reference");
    let ext = p.extension().and_then(|s| s.to_str()).unwrap_or("exr");
    p.with_file_name(format!("{stem}-{suffix}.{ext}"))
}

/// Exposure + the GPU's ACES curve, for PNG output of radiance images.
fn tonemap(img: &ImageBuf, exposure: f32) -> ImageBuf {
    let mut o = img.clone();
    o.data
        .iter_mut()
        .for_each(|v| *v = strata_eval::metrics::aces(*v * exposure));
    o
}
