//! `strata_render::display`: the GPU's display bytes of a target are the bytes
//! `ImageBuf::to_rgba8` writes for the read-back target (what `strata view` showed before,
//! and what every PNG holds), byte for byte.

mod common;

use strata_render::display::{thresholds, DisplayEncoder, Region};
use strata_render::frame::FrameCameras;
use strata_render::renderer::{crop, decode_texels, GuardBand};
use strata_render::{GpuContext, RenderSettings, Renderer};
use strata_scene::{procedural, ImageBuf};
use wgpu::TextureFormat as F;

/// What the viewer showed from a read-back image: `to_rgba8` of the values × gain,
/// alpha 255.
fn cpu_bytes(img: &ImageBuf, srgb: bool, gain: f32) -> Vec<u8> {
    let mut img = img.clone();
    if gain != 1.0 {
        img.data.iter_mut().for_each(|v| *v *= gain);
    }
    let mut b = img.to_rgba8(srgb);
    b.chunks_exact_mut(4).for_each(|p| p[3] = 255);
    b
}

fn gpu_bytes(gpu: &GpuContext, enc: &mut DisplayEncoder, region: &Region<'_>, srgb: bool, gain: f32) -> Vec<u8> {
    let out = enc.encode(gpu, region, srgb, gain).unwrap();
    let b = gpu.read_texture(out, 0).unwrap();
    gpu.check_errors().expect("no wgpu validation errors");
    b
}

/// Texel values that probe the encoding: every threshold of both tables and the f32 just
/// below it, the special values, then pseudo-random values over [−0.1, 1.3].
fn probe_values(n: usize, seed: u32) -> Vec<f32> {
    let mut v = Vec::with_capacity(n);
    for srgb in [false, true] {
        for t in thresholds(srgb) {
            v.push(t);
            v.push(f32::from_bits(t.to_bits() - 1));
        }
    }
    v.extend([
        f32::NAN,
        f32::INFINITY,
        f32::NEG_INFINITY,
        -0.0,
        0.0,
        1.0,
        -1.0,
        1e-30,
        2.5,
    ]);
    let mut s = seed | 1;
    while v.len() < n {
        s ^= s << 13;
        s ^= s >> 17;
        s ^= s << 5;
        v.push(s as f32 / u32::MAX as f32 * 1.4 - 0.1);
    }
    v.truncate(n);
    v
}

fn f32_to_f16_bits(x: f32) -> u16 {
    // round-trip exactness does not matter: the texel's own value is what both sides read
    let b = x.to_bits();
    let sign = ((b >> 16) & 0x8000) as u16;
    if x.is_nan() {
        return sign | 0x7e00;
    }
    let e = ((b >> 23) & 0xff) as i32 - 127 + 15;
    if e >= 31 {
        return sign | 0x7c00;
    }
    if e <= 0 {
        return sign;
    }
    sign | ((e as u16) << 10) | ((b >> 13) & 0x3ff) as u16
}

/// Texel bytes of `format` for `n` texels.
fn texels(format: F, n: usize, seed: u32) -> Vec<u8> {
    let comps = match format {
        F::R32Float | F::R16Float => 1,
        F::Rg32Float => 2,
        _ => 4,
    };
    let vals = probe_values(n * comps, seed);
    match format {
        F::R32Float | F::Rg32Float | F::Rgba32Float => bytemuck::cast_slice(&vals).to_vec(),
        F::R16Float | F::Rgba16Float => {
            let h: Vec<u16> = vals.iter().map(|&x| f32_to_f16_bits(x)).collect();
            bytemuck::cast_slice(&h).to_vec()
        }
        F::Rg11b10Ufloat => {
            // every bit pattern is a valid texel (inf and NaN included)
            let mut s = seed | 1;
            (0..n)
                .flat_map(|_| {
                    s ^= s << 13;
                    s ^= s >> 17;
                    s ^= s << 5;
                    s.to_le_bytes()
                })
                .collect()
        }
        // every byte value, then pseudo-random ones
        F::Rgba8Unorm | F::Rgba8UnormSrgb => (0..n * 4)
            .map(|i| ((i as u32).wrapping_mul(2_654_435_761) >> 7) as u8)
            .collect(),
        _ => unreachable!(),
    }
}

/// For each format a target can have, a two-layer texture of probe values: a region of
/// layer 1 encoded on the GPU equals the CPU's bytes of the read-back layer, for both
/// encodings and with a display gain.
#[test]
fn display_encoder_equals_to_rgba8() {
    let gpu = common::gpu();
    let mut enc = DisplayEncoder::new(&gpu);
    let (w, h) = (61u32, 37u32);
    for format in [
        F::R32Float,
        F::R16Float,
        F::Rg32Float,
        F::Rgba16Float,
        F::Rgba32Float,
        F::Rg11b10Ufloat,
        F::Rgba8Unorm,
        F::Rgba8UnormSrgb,
    ] {
        let tex = gpu.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("display probe"),
            size: wgpu::Extent3d {
                width: w,
                height: h,
                depth_or_array_layers: 2,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST | wgpu::TextureUsages::COPY_SRC,
            view_formats: if format == F::Rgba8UnormSrgb {
                &[F::Rgba8Unorm]
            } else {
                &[]
            },
        });
        let bpp = format.block_copy_size(None).unwrap();
        for layer in 0..2 {
            gpu.queue.write_texture(
                wgpu::TexelCopyTextureInfo {
                    texture: &tex,
                    mip_level: 0,
                    origin: wgpu::Origin3d { x: 0, y: 0, z: layer },
                    aspect: wgpu::TextureAspect::All,
                },
                &texels(format, (w * h) as usize, 7 + layer),
                wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(w * bpp),
                    rows_per_image: Some(h),
                },
                wgpu::Extent3d {
                    width: w,
                    height: h,
                    depth_or_array_layers: 1,
                },
            );
        }
        let full = decode_texels(&gpu.read_texture(&tex, 1).unwrap(), format, w, h).unwrap();
        let (origin, size) = ([5, 3], [w - 9, h - 4]);
        let region = crop(&full, origin[0], origin[1], size[0], size[1]);
        for srgb in [false, true] {
            for gain in [1.0, 1.7, 0.3] {
                let g = gpu_bytes(
                    &gpu,
                    &mut enc,
                    &Region {
                        texture: &tex,
                        layer: 1,
                        origin,
                        size,
                    },
                    srgb,
                    gain,
                );
                let c = cpu_bytes(&region, srgb, gain);
                let differ = g.iter().zip(&c).filter(|(a, b)| a != b).count();
                assert_eq!(
                    differ,
                    0,
                    "{format:?}, srgb {srgb}, gain {gain}: {differ} of {} bytes differ",
                    c.len()
                );
            }
        }
    }
}

/// Rendered frames: the display target inside the guard band, as the viewer shows it
/// (`ldr` sRGB-encoded, `ao` linear), equals the bytes of `read_target`.
#[test]
fn display_of_a_rendered_frame_equals_its_png_bytes() {
    let gpu = common::gpu();
    let mut enc = DisplayEncoder::new(&gpu);
    let scene = procedural::builtin("cornell").unwrap();
    for (technique, target, srgb) in [("direct", "ldr", true), ("full", "ldr", true), ("ao", "ao", false)] {
        let base = RenderSettings {
            width: 96,
            height: 64,
            guard_band: GuardBand::Pixels(6),
            ..Default::default()
        };
        let settings = strata_render::technique::find(technique)
            .unwrap()
            .settings(&base, None)
            .unwrap();
        let mut r = Renderer::new(&gpu, &scene, settings).unwrap();
        r.render(&gpu, &scene, &FrameCameras::fixed(scene.camera), 0.0).unwrap();
        let region = r.display_region(target).unwrap();
        assert_eq!(
            (region.origin, region.size),
            ([6, 6], [96, 64]),
            "the image inside the guard band"
        );
        let shown = gpu_bytes(&gpu, &mut enc, &region, srgb, 1.0);
        let png = cpu_bytes(&r.read_target(&gpu, target).unwrap(), srgb, 1.0);
        assert_eq!(shown.len(), png.len());
        let differ = shown.iter().zip(&png).filter(|(a, b)| a != b).count();
        assert_eq!(differ, 0, "{technique}: {differ} bytes differ");
        let distinct: std::collections::HashSet<_> = png.chunks_exact(4).map(|p| [p[0], p[1], p[2]]).collect();
        assert!(
            distinct.len() > 20,
            "{technique}: the frame is not flat ({} colours)",
            distinct.len()
        );
    }
}

/// A region outside the texture, and a format the encoder cannot show, are one-line
/// errors, not validation errors.
#[test]
fn display_encoder_rejects_a_bad_region_or_format() {
    let gpu = common::gpu();
    let mut enc = DisplayEncoder::new(&gpu);
    let make = |format| {
        gpu.device.create_texture(&wgpu::TextureDescriptor {
            label: None,
            size: wgpu::Extent3d {
                width: 16,
                height: 8,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage: wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        })
    };
    let region = |texture, layer, origin| Region {
        texture,
        layer,
        origin,
        size: [16, 8],
    };
    let t = make(F::Rgba16Float);
    let e = enc
        .encode(&gpu, &region(&t, 0, [4, 0]), true, 1.0)
        .unwrap_err()
        .to_string();
    common::assert_one_line(&e, &["display", "outside", "16×8×1"]);
    let e = enc
        .encode(&gpu, &region(&t, 1, [0, 0]), true, 1.0)
        .unwrap_err()
        .to_string();
    common::assert_one_line(&e, &["layer 1"]);
    let d = make(F::Depth32Float);
    let e = enc
        .encode(&gpu, &region(&d, 0, [0, 0]), true, 1.0)
        .unwrap_err()
        .to_string();
    common::assert_one_line(&e, &["Depth32Float", "cannot be shown"]);
    gpu.check_errors().expect("no wgpu validation errors");
}
