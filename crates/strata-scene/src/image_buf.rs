//! A float image shared by the GPU read-back path and the CPU reference, with
//! PNG (8-bit, sRGB-encoded, optional exposure/tonemap by the caller) and EXR
//! (linear float) output.

use std::path::Path;

/// Row-major float image, `channels` values per pixel (1 = grey, 3 = RGB, 4 = RGBA).
#[derive(Clone, Debug, PartialEq)]
pub struct ImageBuf {
    pub width: u32,
    pub height: u32,
    pub channels: u32,
    pub data: Vec<f32>,
}

impl ImageBuf {
    pub fn new(width: u32, height: u32, channels: u32) -> Self {
        Self {
            width,
            height,
            channels,
            data: vec![0.0; (width * height * channels) as usize],
        }
    }

    pub fn pixel(&self, x: u32, y: u32) -> &[f32] {
        let i = ((y * self.width + x) * self.channels) as usize;
        &self.data[i..i + self.channels as usize]
    }

    pub fn pixel_mut(&mut self, x: u32, y: u32) -> &mut [f32] {
        let i = ((y * self.width + x) * self.channels) as usize;
        &mut self.data[i..i + self.channels as usize]
    }

    /// One channel as a new single-channel image.
    pub fn channel(&self, c: u32) -> ImageBuf {
        let data = self
            .data
            .chunks_exact(self.channels as usize)
            .map(|p| p[c as usize])
            .collect();
        ImageBuf {
            width: self.width,
            height: self.height,
            channels: 1,
            data,
        }
    }

    fn to_rgba32(&self) -> Vec<[f32; 4]> {
        self.data
            .chunks_exact(self.channels as usize)
            .map(|p| match p.len() {
                1 => [p[0], p[0], p[0], 1.0],
                2 => [p[0], p[1], 0.0, 1.0],
                3 => [p[0], p[1], p[2], 1.0],
                _ => [p[0], p[1], p[2], p[3]],
            })
            .collect()
    }

    /// The 8-bit RGBA bytes a PNG of this image holds (values clamped to [0, 1],
    /// sRGB-encoded unless `srgb` is false); `strata view` displays these same bytes.
    pub fn to_rgba8(&self, srgb: bool) -> Vec<u8> {
        let px = self.to_rgba32();
        let mut bytes = Vec::with_capacity(px.len() * 4);
        for p in px {
            for &v in &p[..3] {
                bytes.push(to_byte(v, srgb));
            }
            bytes.push(to_byte(p[3], false));
        }
        bytes
    }

    /// Writes by extension: `.png` (values clamped to [0, 1], sRGB-encoded unless
    /// `srgb` is false) or `.exr` (linear float RGBA). Atomic: the file is encoded
    /// beside `path` and renamed into place ([`crate::atomic`]).
    pub fn save(&self, path: &Path, srgb: bool) -> Result<(), String> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(|e| e.to_ascii_lowercase());
        match ext.as_deref() {
            Some("png") => {
                let bytes = self.to_rgba8(srgb);
                let img = image::RgbaImage::from_raw(self.width, self.height, bytes).expect("size matches");
                crate::atomic::write_with(path, |tmp| {
                    img.save(tmp)
                        .map_err(|e| format!("{}: cannot write PNG: {e}", path.display()))
                })
            }
            Some("exr") => {
                let px: Vec<f32> = self.to_rgba32().into_iter().flatten().collect();
                let img = image::Rgba32FImage::from_raw(self.width, self.height, px).expect("size matches");
                let img = image::DynamicImage::ImageRgba32F(img);
                crate::atomic::write_with(path, |tmp| {
                    img.save(tmp)
                        .map_err(|e| format!("{}: cannot write EXR: {e}", path.display()))
                })
            }
            _ => Err(format!(
                "{}: unsupported output format: use .png or .exr",
                path.display()
            )),
        }
    }

    /// Reads a PNG/EXR back as linear RGBA (PNG is sRGB-decoded).
    pub fn load(path: &Path) -> Result<ImageBuf, String> {
        let mut img = Self::load_stored(path)?;
        if is_png(path) {
            for (i, v) in img.data.iter_mut().enumerate() {
                if i % 4 != 3 {
                    *v = crate::model::srgb_to_linear((*v * 255.0 + 0.5) as u8);
                }
            }
        }
        Ok(img)
    }

    /// Reads a PNG/EXR as RGBA with the values it stores: a PNG's bytes / 255 (no
    /// transfer function: sRGB-encoded display values, or the raw 255·AV bytes of
    /// ambient visibility), an EXR's floats.
    pub fn load_stored(path: &Path) -> Result<ImageBuf, String> {
        let img = image::open(path).map_err(|e| format!("{}: cannot read image: {e}", path.display()))?;
        let rgba = img.to_rgba32f();
        let (w, h) = rgba.dimensions();
        Ok(ImageBuf {
            width: w,
            height: h,
            channels: 4,
            data: rgba.into_raw(),
        })
    }
}

/// Whether `path` names a PNG (by its extension).
pub fn is_png(path: &Path) -> bool {
    path.extension().is_some_and(|e| e.eq_ignore_ascii_case("png"))
}

/// The PNG byte of one channel value: clamped to [0, 1], sRGB-encoded if `srgb`, rounded
/// ([`ImageBuf::to_rgba8`]; `strata_render::display` matches it on the GPU).
pub fn to_byte(v: f32, srgb: bool) -> u8 {
    let v = v.clamp(0.0, 1.0);
    let v = if srgb { linear_to_srgb(v) } else { v };
    (v * 255.0 + 0.5) as u8
}

pub fn linear_to_srgb(c: f32) -> f32 {
    if c <= 0.003_130_8 {
        c * 12.92
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    }
}
