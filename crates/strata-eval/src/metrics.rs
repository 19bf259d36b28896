//! Image error metrics: NVIDIA's LDR ꟻLIP (via the `nv-flip` crate), RMSE and MAE between a
//! reference image and a test image, plus the ꟻLIP error map for the report; RMSE and MAE of
//! linear values ([`linear_errors`]) and the tonemapper's display values ([`display`]).
//!
//! Both images are *display values* in [0, 1]: the caller decides the encoding (exposure, tonemap,
//! sRGB or not) before calling [`compare`]; nothing here applies a transfer function.

use anyhow::{bail, Result};
use serde::{Deserialize, Serialize};
use strata_scene::ImageBuf;

/// A reference's own noise: its two independent halves (see
/// `strata_reference::converge`) compared with each other, on the same values
/// as the errors it stands beside.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct RefNoise {
    /// ꟻLIP between the halves (display values, as [`ErrorStats::flip`]).
    pub flip: f32,
    /// RMSE between the halves (as [`ErrorStats::rmse`]).
    pub rmse: f32,
    /// Samples per pixel of the whole reference (both halves).
    pub spp: u32,
    /// Whether the noise target was met (false: the sample cap stopped it).
    pub converged: bool,
}

/// Errors of a test image against a reference image.
///
/// Serialised as `{"flip", "rmse", "mae"}` (the pixel count is left out), plus, where an
/// evaluation fills them, `ref_noise` (the reference's own noise), `outliers` and
/// `ref_outliers` (speckles of the test image and of the reference, [`outliers`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ErrorStats {
    /// Mean ꟻLIP error over all pixels (0 = identical, 1 = maximal), LDR ꟻLIP at
    /// [`nv_flip::DEFAULT_PIXELS_PER_DEGREE`] on the 8-bit quantised images.
    pub flip: f32,
    /// Root mean squared difference over every channel of every pixel of the float data (unclamped).
    pub rmse: f32,
    /// Mean absolute difference over every channel of every pixel of the float data (unclamped).
    pub mae: f32,
    /// Number of pixels compared.
    #[serde(skip)]
    pub pixels: usize,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ref_noise: Option<RefNoise>,
    /// Pixels of the test image that are [`outliers`] (display values).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub outliers: Option<u32>,
    /// Pixels of the reference that are [`outliers`] (display values).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ref_outliers: Option<u32>,
    /// Mean of the test's linear values over the reference's ([`mean_ratio`]): the
    /// brightness bias (1 = none), filled where linear radiance is compared.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mean_ratio: Option<f32>,
}

impl ErrorStats {
    /// Whether the error is within 2× of the reference's own noise (ꟻLIP or RMSE): then the
    /// reference cannot tell this error apart from its noise. A metric whose noise is 0 (a
    /// noise-free reference: nothing to converge) never flags.
    pub fn within_ref_noise(&self) -> bool {
        let within = |err: f32, noise: f32| noise > 0.0 && err <= 2.0 * noise;
        self.ref_noise
            .is_some_and(|n| within(self.flip, n.flip) || within(self.rmse, n.rmse))
    }
}

/// Display-value difference from the 3×3 median above which a pixel counts as an outlier.
pub const OUTLIER_THRESHOLD: f32 = 0.25;

/// Pixels whose value differs from the median of their 3×3 neighbourhood (clamped at the image
/// border) by more than `threshold` in any channel: isolated speckles ("fireflies", black dots)
/// rather than edges, which a median follows.
pub fn outliers(img: &ImageBuf, threshold: f32) -> u32 {
    let (w, h, c) = (img.width as i64, img.height as i64, img.channels as usize);
    if w == 0 || h == 0 || c == 0 || img.data.len() < (w * h) as usize * c {
        return 0;
    }
    let mut count = 0u32;
    let mut window = [0.0f32; 9];
    for y in 0..h {
        for x in 0..w {
            let at = |xx: i64, yy: i64, ch: usize| {
                let (xx, yy) = (xx.clamp(0, w - 1), yy.clamp(0, h - 1));
                img.data[(yy * w + xx) as usize * c + ch]
            };
            let outlier = (0..c).any(|ch| {
                let mut k = 0;
                for dy in -1..=1 {
                    for dx in -1..=1 {
                        window[k] = at(x + dx, y + dy, ch);
                        k += 1;
                    }
                }
                window.sort_unstable_by(f32::total_cmp);
                (at(x, y, ch) - window[4]).abs() > threshold
            });
            count += outlier as u32;
        }
    }
    count
}

/// Compares `test` against `reference`; returns the error statistics and the ꟻLIP error map.
///
/// Both images must have the same size and the same channel count, 1 (grey) or 3 (RGB), with values
/// meant for display in [0, 1]. RMSE and MAE use the float data as is. ꟻLIP uses each value
/// quantised to 8 bits as `round(clamp(v, 0, 1) * 255)` (see [`ldr_bytes`]) with no transfer
/// function; grey images are replicated to RGB. `nv-flip` treats the bytes as sRGB-encoded, so the
/// caller should pass sRGB-encoded display values for a perceptually meaningful ꟻLIP.
///
/// The error map is a 3-channel image of the per-pixel ꟻLIP error coloured with ꟻLIP's magma LUT,
/// each value an exact byte / 255. Save it with `ImageBuf::save(path, false)`: with `srgb = false`
/// a PNG stores `round(v * 255)`, i.e. the LUT's bytes unchanged, whereas `srgb = true` would
/// sRGB-encode the already display-ready colours a second time and wash them out.
pub fn compare(reference: &ImageBuf, test: &ImageBuf) -> Result<(ErrorStats, ImageBuf)> {
    if (reference.width, reference.height, reference.channels) != (test.width, test.height, test.channels) {
        bail!(
            "cannot compare images of different shapes: reference is {}x{} with {} channel(s), test is {}x{} with {} \
             channel(s)",
            reference.width,
            reference.height,
            reference.channels,
            test.width,
            test.height,
            test.channels
        );
    }
    for (name, img) in [("reference", reference), ("test", test)] {
        check_image(name, img)?;
    }

    let (mut sum_abs, mut sum_sq) = (0.0f64, 0.0f64);
    for (&r, &t) in reference.data.iter().zip(&test.data) {
        let d = f64::from(t) - f64::from(r);
        sum_abs += d.abs();
        sum_sq += d * d;
    }
    let n = reference.data.len() as f64;
    let (w, h) = (reference.width, reference.height);

    let ref_flip = nv_flip::FlipImageRgb8::with_data(w, h, &ldr_bytes(reference));
    let test_flip = nv_flip::FlipImageRgb8::with_data(w, h, &ldr_bytes(test));
    let error = nv_flip::flip(ref_flip, test_flip, nv_flip::DEFAULT_PIXELS_PER_DEGREE);
    let flip = nv_flip::FlipPool::from_image(&error).mean();
    let coloured = error.apply_color_lut(&nv_flip::magma_lut()).to_vec();
    let map = ImageBuf {
        width: w,
        height: h,
        channels: 3,
        data: coloured.into_iter().map(|b| f32::from(b) / 255.0).collect(),
    };

    let stats = ErrorStats {
        flip,
        rmse: (sum_sq / n).sqrt() as f32,
        mae: (sum_abs / n) as f32,
        pixels: w as usize * h as usize,
        ..Default::default()
    };
    Ok((stats, map))
}

/// RMSE and MAE of linear values (every channel of every pixel; images of the same shape).
pub fn linear_errors(reference: &ImageBuf, test: &ImageBuf) -> (f32, f32) {
    let n = reference.data.len().max(1) as f64;
    let (mut se, mut ae) = (0.0f64, 0.0f64);
    for (r, t) in reference.data.iter().zip(&test.data) {
        let d = (*t - *r) as f64;
        se += d * d;
        ae += d.abs();
    }
    ((se / n).sqrt() as f32, (ae / n) as f32)
}

/// Sum of the test's values over the reference's (every channel of every pixel): > 1 when
/// the test is brighter on average. `None` when the reference sums to zero.
pub fn mean_ratio(reference: &ImageBuf, test: &ImageBuf) -> Option<f32> {
    let sum = |img: &ImageBuf| img.data.iter().map(|v| *v as f64).sum::<f64>();
    let r = sum(reference);
    (r > 0.0).then(|| (sum(test) / r) as f32)
}

/// [`compare`] on display values (`display(·, exposure)`: FLIP and the map) with RMSE and MAE
/// replaced by those of the linear radiance, and its [`mean_ratio`].
pub fn compare_radiance(reference: &ImageBuf, test: &ImageBuf, exposure: f32) -> Result<(ErrorStats, ImageBuf)> {
    let (mut stats, map) = compare(&display(reference, exposure), &display(test, exposure))?;
    (stats.rmse, stats.mae) = linear_errors(reference, test);
    stats.mean_ratio = mean_ratio(reference, test);
    Ok((stats, map))
}

/// ACES filmic fit (as `color.wgsl`), clamped to [0, 1].
pub fn aces(x: f32) -> f32 {
    ((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14)).clamp(0.0, 1.0)
}

/// The tonemapper's display values: exposure, ACES fit (as `color.wgsl`), sRGB.
pub fn display(img: &ImageBuf, exposure: f32) -> ImageBuf {
    let mut out = img.clone();
    for v in &mut out.data {
        *v = strata_scene::image_buf::linear_to_srgb(aces(*v * exposure));
    }
    out
}

/// Validates what `compare` (and `nv-flip`, which panics on short data) relies on.
fn check_image(name: &str, img: &ImageBuf) -> Result<()> {
    if img.channels != 1 && img.channels != 3 {
        bail!(
            "{name} image has {} channels: only 1 (grey) or 3 (RGB) can be compared",
            img.channels
        );
    }
    if img.width == 0 || img.height == 0 {
        bail!(
            "{name} image is empty ({}x{}): nothing to compare",
            img.width,
            img.height
        );
    }
    let expected = img.width as usize * img.height as usize * img.channels as usize;
    if img.data.len() != expected {
        bail!(
            "{name} image holds {} values but {}x{} with {} channel(s) needs {expected}",
            img.data.len(),
            img.width,
            img.height,
            img.channels
        );
    }
    Ok(())
}

/// The image as tightly packed 8-bit RGB, each value `round(clamp(v, 0, 1) * 255)` with no transfer
/// function (NaN becomes 0). Grey (1-channel) images are replicated to RGB; with 2 channels the
/// third is 0, with 4 or more only the first three are used.
pub fn ldr_bytes(img: &ImageBuf) -> Vec<u8> {
    let c = img.channels.max(1) as usize;
    let q = |v: f32| {
        if v.is_nan() {
            0
        } else {
            (v.clamp(0.0, 1.0) * 255.0).round() as u8
        }
    };
    let mut out = Vec::with_capacity(img.data.len() / c * 3);
    for p in img.data.chunks_exact(c) {
        match p.len() {
            1 => out.extend_from_slice(&[q(p[0]); 3]),
            2 => out.extend_from_slice(&[q(p[0]), q(p[1]), 0]),
            _ => out.extend_from_slice(&[q(p[0]), q(p[1]), q(p[2])]),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A smooth RGB test pattern in [0.1, 0.7] so offsets up to 0.3 stay inside [0, 1].
    fn pattern(w: u32, h: u32) -> ImageBuf {
        let mut img = ImageBuf::new(w, h, 3);
        for y in 0..h {
            for x in 0..w {
                let p = img.pixel_mut(x, y);
                p[0] = 0.1 + 0.6 * x as f32 / (w - 1) as f32;
                p[1] = 0.1 + 0.6 * y as f32 / (h - 1) as f32;
                p[2] = 0.4;
            }
        }
        img
    }

    fn offset(img: &ImageBuf, d: f32) -> ImageBuf {
        let mut out = img.clone();
        out.data.iter_mut().for_each(|v| *v += d);
        out
    }

    #[test]
    fn identical_images_have_zero_error() {
        let a = pattern(32, 24);
        let (s, map) = compare(&a, &a).unwrap();
        assert_eq!(s.flip, 0.0);
        assert_eq!(s.rmse, 0.0);
        assert_eq!(s.mae, 0.0);
        assert_eq!(s.pixels, 32 * 24);
        assert_eq!((map.width, map.height, map.channels), (32, 24, 3));
        assert_eq!(map.data.len(), 32 * 24 * 3);
        // Zero error maps to the LUT's first entry everywhere.
        let first = map.pixel(0, 0).to_vec();
        assert!(map.data.chunks_exact(3).all(|p| p == first.as_slice()));
    }

    #[test]
    fn constant_offset_gives_mae_and_rmse_equal_to_offset() {
        let a = pattern(16, 16);
        for d in [0.05f32, -0.1, 0.25] {
            let b = offset(&a, d);
            let (s, _) = compare(&a, &b).unwrap();
            // The offset as actually stored after f32 rounding differs from d by a few ulps.
            assert!((s.mae - d.abs()).abs() < 1e-6, "d = {d}: mae = {}", s.mae);
            assert!((s.rmse - d.abs()).abs() < 1e-6, "d = {d}: rmse = {}", s.rmse);
        }
    }

    #[test]
    fn rmse_and_mae_use_unclamped_values() {
        let a = ImageBuf {
            width: 2,
            height: 1,
            channels: 1,
            data: vec![1.0, 0.0],
        };
        let b = ImageBuf {
            width: 2,
            height: 1,
            channels: 1,
            data: vec![3.0, 0.0],
        };
        let (s, _) = compare(&a, &b).unwrap();
        assert!((s.mae - 1.0).abs() < 1e-6);
        assert!((s.rmse - 2.0f32.sqrt()).abs() < 1e-6);
        // Both clamp to 1.0 before quantisation, so ꟻLIP sees identical images.
        assert_eq!(s.flip, 0.0);
    }

    #[test]
    fn larger_difference_gives_larger_flip() {
        let a = pattern(48, 32);
        let (small, small_map) = compare(&a, &offset(&a, 0.05)).unwrap();
        let (large, _) = compare(&a, &offset(&a, 0.3)).unwrap();
        assert!(small.flip > 0.0, "flip = {}", small.flip);
        assert!(large.flip > small.flip, "{} <= {}", large.flip, small.flip);
        assert!(large.flip <= 1.0);
        assert!(small_map.data.iter().all(|v| (0.0..=1.0).contains(v)));
    }

    #[test]
    fn grey_images_are_compared_like_replicated_rgb() {
        let grey = pattern(20, 20).channel(0);
        let grey_test = offset(&grey, 0.2);
        let rgb = |g: &ImageBuf| ImageBuf {
            width: g.width,
            height: g.height,
            channels: 3,
            data: g.data.iter().flat_map(|&v| [v; 3]).collect(),
        };
        let (sg, mg) = compare(&grey, &grey_test).unwrap();
        let (sc, mc) = compare(&rgb(&grey), &rgb(&grey_test)).unwrap();
        assert!(sg.flip > 0.0);
        assert_eq!(sg.flip, sc.flip);
        assert_eq!(mg, mc);
    }

    #[test]
    fn ldr_bytes_rounds_clamps_and_replicates() {
        let g = ImageBuf {
            width: 4,
            height: 1,
            channels: 1,
            data: vec![-1.0, 0.5, 2.0, f32::NAN],
        };
        assert_eq!(ldr_bytes(&g), vec![0, 0, 0, 128, 128, 128, 255, 255, 255, 0, 0, 0]);
        let c = ImageBuf {
            width: 1,
            height: 1,
            channels: 3,
            data: vec![1.0 / 255.0, 0.499 / 255.0, 0.2],
        };
        assert_eq!(ldr_bytes(&c), vec![1, 0, 51]);
    }

    #[test]
    fn linear_errors_and_display() {
        let a = pattern(2, 2).channel(0);
        let b = offset(&a, 2.0);
        let (rmse, mae) = linear_errors(&a, &b);
        assert!((mae - 2.0).abs() < 1e-6 && (rmse - 2.0).abs() < 1e-6);
        assert_eq!(mean_ratio(&a, &a), Some(1.0));
        let twice = ImageBuf {
            data: a.data.iter().map(|v| 2.0 * v).collect(),
            ..a.clone()
        };
        assert!((mean_ratio(&a, &twice).unwrap() - 2.0).abs() < 1e-6);
        assert_eq!(
            mean_ratio(&ImageBuf::new(2, 2, 1), &a),
            None,
            "a black reference has no ratio"
        );
        let d = display(&b, 1.0);
        assert!(d.data.iter().all(|v| *v > 0.9 && *v <= 1.0), "{:?}", d.data);
        assert_eq!(display(&ImageBuf::new(2, 2, 1), 1.0).data, vec![0.0; 4]);
        let json = serde_json::to_value(compare(&a, &b).unwrap().0).unwrap();
        let keys: Vec<_> = json.as_object().unwrap().keys().cloned().collect();
        assert_eq!(keys, ["flip", "mae", "rmse"]);
    }

    #[test]
    fn outliers_are_isolated_speckles_not_edges() {
        let mut img = pattern(24, 16).channel(0);
        assert_eq!(outliers(&img, OUTLIER_THRESHOLD), 0, "a smooth ramp has none");
        // a hard vertical edge: the median follows it
        for y in 0..16 {
            for x in 12..24 {
                img.pixel_mut(x, y)[0] = 1.0;
            }
        }
        assert_eq!(outliers(&img, OUTLIER_THRESHOLD), 0, "an edge is not an outlier");
        // two isolated black dots, one in a corner (clamped border), and a 2-pixel vertical run
        img.pixel_mut(18, 8)[0] = 0.0;
        img.pixel_mut(23, 0)[0] = 0.0;
        img.pixel_mut(16, 3)[0] = 0.0;
        img.pixel_mut(16, 4)[0] = 0.0;
        assert_eq!(outliers(&img, OUTLIER_THRESHOLD), 4);
        // a stripe two pixels thick is a feature (the median follows it); one pixel thick, every
        // pixel of it is an outlier (what a 3×3 median calls a speckle)
        let mut blob = ImageBuf::new(9, 9, 3);
        blob.data.iter_mut().for_each(|v| *v = 1.0);
        for y in 3..5 {
            for x in 0..9 {
                blob.pixel_mut(x, y).copy_from_slice(&[0.0; 3]);
            }
        }
        assert_eq!(outliers(&blob, OUTLIER_THRESHOLD), 0);
        let mut line = blob.clone();
        for x in 0..9 {
            line.pixel_mut(x, 4).copy_from_slice(&[1.0; 3]);
        }
        assert_eq!(outliers(&line, OUTLIER_THRESHOLD), 9);
        blob.pixel_mut(0, 8)[1] = 0.5; // one channel off by 0.5
        assert_eq!(outliers(&blob, OUTLIER_THRESHOLD), 1);
        assert_eq!(outliers(&ImageBuf::new(0, 0, 1), 0.1), 0);
    }

    #[test]
    fn errors_within_twice_the_reference_noise_are_flagged() {
        let noise = RefNoise {
            flip: 0.02,
            rmse: 0.01,
            spp: 64,
            converged: true,
        };
        let e = |flip, rmse| ErrorStats {
            flip,
            rmse,
            ref_noise: Some(noise),
            ..Default::default()
        };
        assert!(e(0.039, 0.5).within_ref_noise());
        assert!(e(0.5, 0.02).within_ref_noise());
        assert!(!e(0.041, 0.021).within_ref_noise());
        assert!(!ErrorStats::default().within_ref_noise(), "no noise measured, no flag");
        // a noise-free reference (a scene without indirect light: both halves 0) flags
        // nothing, not even an exact match; noise in one metric still counts
        let exact = RefNoise {
            flip: 0.0,
            rmse: 0.0,
            ..noise
        };
        let f = |flip, rmse, n| ErrorStats {
            flip,
            rmse,
            ref_noise: Some(n),
            ..Default::default()
        };
        assert!(!f(0.0, 0.0, exact).within_ref_noise());
        assert!(!f(0.0, 0.004, exact).within_ref_noise());
        assert!(f(0.0, 0.004, RefNoise { rmse: 0.01, ..exact }).within_ref_noise());
    }

    #[test]
    fn shape_mismatch_is_an_error() {
        let a = pattern(16, 16);
        let e = compare(&a, &pattern(16, 8)).unwrap_err().to_string();
        assert!(e.contains("16x16") && e.contains("16x8"), "{e}");
        let e = compare(&a.channel(0), &a).unwrap_err().to_string();
        assert!(e.contains("1 channel") && e.contains("3 channel"), "{e}");
    }

    #[test]
    fn unsupported_or_inconsistent_images_are_errors() {
        let rgba = ImageBuf::new(4, 4, 4);
        assert!(compare(&rgba, &rgba).unwrap_err().to_string().contains("4 channels"));
        let empty = ImageBuf::new(0, 4, 3);
        assert!(compare(&empty, &empty).is_err());
        let mut short = ImageBuf::new(4, 4, 3);
        short.data.pop();
        assert!(compare(&short, &short).unwrap_err().to_string().contains("47 values"));
    }
}
