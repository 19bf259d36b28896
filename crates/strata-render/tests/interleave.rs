//! Buffer splitting (BS) / gathering (BG) of interleaved deferred shading
//! (ILS §3.2–3.4) on the GPU: split then gather is the identity bit for bit,
//! each sub-buffer holds exactly the texels (x mod n, y mod m) (against the CPU
//! twin), the three methods write identical tiled buffers, padding holds the
//! marker and never comes back, bad parameters are errors. Any wgpu validation
//! error fails (`check_errors` after every submission).

mod common;

use strata_render::passes::interleave::{min_block, Interleave, InterleaveGeometry, SplitMethod, PADDING_MARKER};
use strata_render::{GpuContext, RenderError};
use wgpu::TextureFormat as F;

const PATTERNS: [(u32, u32); 5] = [(1, 1), (2, 2), (4, 4), (8, 6), (3, 2)];
const SIZES: [(u32, u32); 3] = [(37, 23), (64, 48), (1, 1)];

/// Naive, Compute, and Blocks with the smallest valid block and one 4× larger.
fn methods(n: u32, m: u32) -> Vec<SplitMethod> {
    let lo = min_block(n, m);
    vec![
        SplitMethod::Naive,
        SplitMethod::Blocks { block: lo },
        SplitMethod::Blocks { block: lo * 4 },
        SplitMethod::Compute,
    ]
}

/// Deterministic texels: random bits per format, never NaN (whose payload a
/// driver may canonicalise) and never the all-zero padding marker.
fn texels(format: F, count: usize, seed: u64) -> Vec<Vec<u8>> {
    let mut s = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
    let mut next = move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        s
    };
    (0..count)
        .map(|_| {
            loop {
                let t: Vec<u8> = match format {
                    F::Rgba8Unorm => next().to_le_bytes()[..4].to_vec(),
                    F::Rgba16Float => {
                        let r = next();
                        (0..4)
                            .flat_map(|c| {
                                let mut h = (r >> (16 * c)) as u16;
                                if h & 0x7c00 == 0x7c00 && h & 0x03ff != 0 {
                                    h &= !0x4000; // a NaN: clear an exponent bit (finite)
                                }
                                h.to_le_bytes()
                            })
                            .collect()
                    }
                    F::Rgba32Float | F::R32Float => {
                        let k = if format == F::R32Float { 1 } else { 4 };
                        (0..k)
                            .flat_map(|_| {
                                let mut f = next() as u32;
                                if f32::from_bits(f).is_nan() {
                                    f &= !0x4000_0000; // a NaN: clear an exponent bit
                                }
                                f.to_le_bytes()
                            })
                            .collect()
                    }
                    _ => unreachable!("formats under test"),
                };
                if t.iter().any(|b| *b != 0) {
                    break t;
                }
            }
        })
        .collect()
}

fn upload(gpu: &GpuContext, texture: &wgpu::Texture, data: &[Vec<u8>]) {
    let bytes: Vec<u8> = data.concat();
    let bpp = data[0].len() as u32;
    gpu.queue.write_texture(
        texture.as_image_copy(),
        &bytes,
        wgpu::TexelCopyBufferLayout {
            offset: 0,
            bytes_per_row: Some(texture.width() * bpp),
            rows_per_image: None,
        },
        texture.size(),
    );
}

fn read(gpu: &GpuContext, texture: &wgpu::Texture, bpp: usize) -> Vec<Vec<u8>> {
    let bytes = gpu
        .read_texture(texture, 0)
        .unwrap_or_else(|e| panic!("read-back: {e}"));
    bytes.chunks_exact(bpp).map(<[u8]>::to_vec).collect()
}

/// Splits and gathers `image` with `ils`; returns (tiled, gathered) texels.
fn round_trip(gpu: &GpuContext, ils: &Interleave, image: &[Vec<u8>]) -> (Vec<Vec<u8>>, Vec<Vec<u8>>) {
    let bpp = image[0].len();
    let src = ils.create_image_texture("image");
    upload(gpu, &src, image);
    let tiled = ils.create_tiled_texture("tiled");
    let back = ils.create_image_texture("gathered");
    let v = [&src, &tiled, &back].map(|t| t.create_view(&Default::default()));
    let mut enc = gpu.device.create_command_encoder(&Default::default());
    ils.split(&mut enc, &v[0], &v[1]).expect("split records");
    ils.gather(&mut enc, &v[1], &v[2]).expect("gather records");
    gpu.queue.submit([enc.finish()]);
    gpu.check_errors().unwrap_or_else(|e| panic!("{:?}: {e}", ils.method()));
    (read(gpu, &tiled, bpp), read(gpu, &back, bpp))
}

/// Every method, pattern and size for one format: BS∘BG = identity, the tiled
/// buffer equals the CPU twin's (sub-buffer (i, j) holds texels (x mod n, y mod
/// m) at (x div n, y div m), padding = all-zero marker), and all methods agree.
fn identity_for_format(format: F) {
    let gpu = common::gpu();
    let bpp = format.block_copy_size(None).unwrap() as usize;
    for (n, m) in PATTERNS {
        for (w, h) in SIZES {
            let image = texels(format, (w * h) as usize, (w * 131 + h * 7 + n * 3 + m) as u64);
            let g = InterleaveGeometry::new(w, h, n, m, SplitMethod::Naive).unwrap();
            let expected = g.split_cpu(&image, vec![0u8; bpp]);
            let mut first: Option<(SplitMethod, Vec<Vec<u8>>)> = None;
            for method in methods(n, m) {
                let what = format!("{format:?} {n}x{m} {w}x{h} {method:?}");
                let ils = Interleave::new(&gpu, format, w, h, n, m, method).unwrap_or_else(|e| panic!("{what}: {e}"));
                assert_eq!(ils.tiled_size(), g.tiled_size());
                assert_eq!(ils.padding(), PADDING_MARKER);
                let (tiled, back) = round_trip(&gpu, &ils, &image);
                if let Some(k) = (0..image.len()).find(|&k| back[k] != image[k]) {
                    panic!(
                        "{what}: gathered texel ({}, {}) is {:?}, image has {:?}",
                        k as u32 % w,
                        k as u32 / w,
                        back[k],
                        image[k]
                    );
                }
                let tw = g.tiled_size()[0];
                if let Some(k) = (0..expected.len()).find(|&k| tiled[k] != expected[k]) {
                    let (tx, ty) = (k as u32 % tw, k as u32 / tw);
                    panic!(
                        "{what}: tiled texel ({tx}, {ty}) = image texel {:?} is {:?}, expected {:?}",
                        g.gather_index(tx, ty),
                        tiled[k],
                        expected[k]
                    );
                }
                match &first {
                    None => first = Some((method, tiled)),
                    Some((m0, t0)) => assert!(*t0 == tiled, "{what}: tiled buffer differs from {m0:?}'s"),
                }
            }
        }
    }
}

#[test]
fn split_then_gather_is_identity_rgba16float() {
    identity_for_format(F::Rgba16Float);
}

#[test]
fn split_then_gather_is_identity_rgba32float() {
    identity_for_format(F::Rgba32Float);
}

#[test]
fn split_then_gather_is_identity_r32float() {
    identity_for_format(F::R32Float);
}

#[test]
fn split_then_gather_is_identity_rgba8unorm() {
    identity_for_format(F::Rgba8Unorm);
}

/// A non-zero marker (so not a clear colour) lands on exactly the padding
/// texels with every method and is never gathered back.
#[test]
fn padding_holds_the_marker_and_never_gathers_back() {
    let gpu = common::gpu();
    let marker = [1.0f32, 0.0, 1.0, 1.0];
    for format in [F::Rgba16Float, F::Rgba8Unorm, F::R32Float] {
        let bpp = format.block_copy_size(None).unwrap() as usize;
        let marker_bytes: Vec<u8> = match format {
            F::Rgba16Float => [0x3c00u16, 0, 0x3c00, 0x3c00]
                .iter()
                .flat_map(|h| h.to_le_bytes())
                .collect(),
            F::Rgba8Unorm => vec![255, 0, 255, 255],
            F::R32Float => 1.0f32.to_le_bytes().to_vec(),
            _ => unreachable!(),
        };
        let (n, m, w, h) = (8, 6, 37, 23);
        // an image without the marker value, so a leaked marker would show
        let image: Vec<Vec<u8>> = texels(format, (w * h) as usize, 5)
            .into_iter()
            .map(|t| if t == marker_bytes { vec![1; bpp] } else { t })
            .collect();
        for method in methods(n, m) {
            let mut ils = Interleave::new(&gpu, format, w, h, n, m, method).unwrap();
            ils.set_padding(&gpu, marker);
            let g = *ils.geometry();
            let (tiled, back) = round_trip(&gpu, &ils, &image);
            let [tw, th] = g.tiled_size();
            let mut pads = 0;
            for ty in 0..th {
                for tx in 0..tw {
                    let t = &tiled[(ty * tw + tx) as usize];
                    match g.gather_index(tx, ty) {
                        None => {
                            pads += 1;
                            assert_eq!(t, &marker_bytes, "{format:?} {method:?} padding ({tx}, {ty})");
                        }
                        Some([x, y]) => assert_eq!(t, &image[(y * w + x) as usize]),
                    }
                }
            }
            assert_eq!(pads, tw * th - w * h);
            assert!(
                back.iter().all(|t| t != &marker_bytes),
                "{format:?} {method:?}: marker gathered"
            );
            assert!(back == image, "{format:?} {method:?}: BS then BG is not the identity");
        }
    }
}

/// The Blocks method's intermediate is Fig. 2 (c): every block split into n×m
/// sub-blocks, against the CPU twin's block splitting.
#[test]
fn block_splitting_matches_fig2c() {
    let gpu = common::gpu();
    let (n, m, w, h) = (3, 2, 37, 23);
    let format = F::R32Float;
    let image = texels(format, (w * h) as usize, 9);
    for block in [4, 8, 16] {
        let ils = Interleave::new(&gpu, format, w, h, n, m, SplitMethod::Blocks { block }).unwrap();
        let g = *ils.geometry();
        round_trip(&gpu, &ils, &image);
        let inter = read(&gpu, ils.block_split_texture().unwrap(), 4);
        let [bw, bh] = g.block_split_size();
        assert_eq!(inter.len(), (bw * bh) as usize);
        for y in 0..h {
            for x in 0..w {
                let [qx, qy] = g.block_split_index(x, y);
                assert_eq!(
                    inter[(qy * bw + qx) as usize],
                    image[(y * w + x) as usize],
                    "block {block} ({x}, {y})"
                );
            }
        }
    }
}

#[test]
fn invalid_parameters_are_errors_not_panics() {
    let gpu = common::gpu();
    let f = F::Rgba16Float;
    let cases: [(u32, u32, u32, u32, SplitMethod, &str); 9] = [
        (32, 32, 0, 2, SplitMethod::Naive, "n = 0"),
        (32, 32, 17, 2, SplitMethod::Compute, "n = 17"),
        (32, 32, 2, 0, SplitMethod::Naive, "m = 0"),
        (32, 32, 2, 17, SplitMethod::Blocks { block: 32 }, "m = 17"),
        (32, 32, 4, 4, SplitMethod::Blocks { block: 12 }, "block size 12"),
        (32, 32, 8, 6, SplitMethod::Blocks { block: 4 }, "block size 4"),
        (32, 32, 2, 2, SplitMethod::Blocks { block: 4096 }, "block size 4096"),
        (0, 32, 2, 2, SplitMethod::Naive, "size 0x32"),
        (1 << 20, 32, 2, 2, SplitMethod::Naive, "too large"),
    ];
    for (w, h, n, m, method, needle) in cases {
        match Interleave::new(&gpu, f, w, h, n, m, method) {
            Err(RenderError::Parameter(e)) => assert!(e.contains(needle) && !e.contains('\n'), "{e}"),
            Err(e) => panic!("{needle}: wrong error kind: {e}"),
            Ok(_) => panic!("{needle}: accepted"),
        }
    }
    for (format, method) in [
        (F::Rgba8UnormSrgb, SplitMethod::Naive),
        (F::Rgba8Snorm, SplitMethod::Compute),
        (F::R32Uint, SplitMethod::Naive),
        (F::Depth32Float, SplitMethod::Blocks { block: 4 }),
    ] {
        let e = Interleave::new(&gpu, format, 16, 16, 2, 2, method)
            .err()
            .expect("format refused");
        assert!(e.to_string().contains("format"), "{e}");
    }
    // wrong textures at record time: size, format, same texture for both
    let ils = Interleave::new(&gpu, f, 37, 23, 3, 2, SplitMethod::Compute).unwrap();
    let image = ils.create_image_texture("image").create_view(&Default::default());
    let tiled = ils.create_tiled_texture("tiled").create_view(&Default::default());
    let other = Interleave::new(&gpu, F::R32Float, 37, 23, 3, 2, SplitMethod::Compute).unwrap();
    let wrong_format = other.create_tiled_texture("r32").create_view(&Default::default());
    let mut enc = gpu.device.create_command_encoder(&Default::default());
    assert!(ils
        .split(&mut enc, &tiled, &image)
        .unwrap_err()
        .to_string()
        .contains("expected"));
    assert!(ils
        .split(&mut enc, &image, &wrong_format)
        .unwrap_err()
        .to_string()
        .contains("format"));
    assert!(ils.gather(&mut enc, &tiled, &tiled).is_err());
    let naive = Interleave::new(&gpu, f, 37, 23, 3, 2, SplitMethod::Naive).unwrap();
    let no_render = ils.create_tiled_texture("storage only"); // STORAGE_BINDING, no RENDER_ATTACHMENT
    let no_render = no_render.create_view(&Default::default());
    assert!(naive
        .split(&mut enc, &image, &no_render)
        .unwrap_err()
        .to_string()
        .contains("usage"));
    gpu.queue.submit([enc.finish()]);
    gpu.check_errors().expect("refused calls record nothing invalid");
}

/// The largest patterns (16×16 and a mixed 16×5): one compute workgroup covers
/// a 2×2 rectangle of every sub-buffer; sub-buffers of 1–3 texels with padding.
#[test]
fn largest_patterns_round_trip() {
    let gpu = common::gpu();
    let format = F::Rgba16Float;
    for (n, m) in [(16, 16), (16, 5)] {
        for (w, h) in [(37, 23), (64, 48), (15, 1)] {
            let image = texels(format, (w * h) as usize, (w + h + n + m) as u64);
            let g = InterleaveGeometry::new(w, h, n, m, SplitMethod::Naive).unwrap();
            let expected = g.split_cpu(&image, vec![0u8; 8]);
            for method in methods(n, m) {
                let ils = Interleave::new(&gpu, format, w, h, n, m, method).unwrap();
                let (tiled, back) = round_trip(&gpu, &ils, &image);
                assert!(
                    back == image,
                    "{n}x{m} {w}x{h} {method:?}: BS then BG is not the identity"
                );
                assert!(
                    tiled == expected,
                    "{n}x{m} {w}x{h} {method:?}: tiled buffer differs from the CPU twin"
                );
            }
        }
    }
}
