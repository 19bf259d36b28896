//! Texture images: decoding (PNG, JPEG, EXR, … by content) to RGBA8 with
//! bounded memory, and reading texture files through a [`FileSource`].
//!
//! [`decode_texture`] bounds the memory an image may claim: at most
//! [`MAX_TEXTURE_SIDE`] texels a side, and a decoded size of at most
//! `max(16 MiB, 1024 × encoded size)` (capped at 1 GiB) — about the best
//! compression ratio DEFLATE can reach, so a real PNG is never refused while a
//! few hundred bytes claiming 30000 × 30000 texels are refused before anything
//! is allocated.
//!
//! EXR headers are checked first ([`check_exr_header`]): the `exr` decoder
//! allocates a whole tile outside the `image` crate's limits.

use std::collections::HashMap;
use std::hash::Hash;
use std::path::Path;

use crate::files::FileSource;
use crate::model::Texture;

/// Largest texture width or height.
pub const MAX_TEXTURE_SIDE: u32 = 16384;

/// Floor of the decoded-size budget of a texture (bytes).
pub const TEXTURE_BUDGET_FLOOR: u64 = 16 << 20;

/// Decoded bytes allowed per encoded byte.
pub const TEXTURE_BUDGET_RATIO: u64 = 1024;

/// Ceiling of the decoded-size budget of a texture (bytes).
pub const TEXTURE_BUDGET_CAP: u64 = 1 << 30;

/// Tiles may exceed a small data window up to this side.
pub const EXR_TILE_SLACK: i64 = 1024;

/// Checks an OpenEXR header (other data passes) before decoding: the `exr`
/// decoder allocates a whole tile before reading any pixel data, outside the
/// `image` crate's allocation limit, so a tile must not exceed the data window (or [`EXR_TILE_SLACK`]),
/// and the data window must be at most [`MAX_TEXTURE_SIDE`] a side.
pub fn check_exr_header(bytes: &[u8]) -> Result<(), String> {
    if !bytes.starts_with(&[0x76, 0x2f, 0x31, 0x01]) || bytes.len() < 8 {
        return Ok(());
    }
    let mut at = 8;
    let mut window: Option<(i64, i64)> = None;
    let mut tiles: Option<(u32, u32)> = None;
    // Attributes: name\0 type\0 size(i32 LE) value, until an empty name.
    let cstr = |at: &mut usize| -> Option<&[u8]> {
        let end = bytes.get(*at..)?.iter().position(|&b| b == 0)?;
        let s = &bytes[*at..*at + end];
        *at += end + 1;
        Some(s)
    };
    while let Some(name) = cstr(&mut at) {
        if name.is_empty() {
            break;
        }
        let Some(_ty) = cstr(&mut at) else { break };
        let Some(size) = bytes
            .get(at..at + 4)
            .map(|b| i32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        else {
            break;
        };
        at += 4;
        let Some(value) = usize::try_from(size)
            .ok()
            .and_then(|n| bytes.get(at..at.checked_add(n)?))
        else {
            break;
        };
        at += value.len();
        let i32_at = |k: usize| {
            value
                .get(4 * k..4 * k + 4)
                .map(|b| i32::from_le_bytes([b[0], b[1], b[2], b[3]]) as i64)
        };
        match name {
            b"dataWindow" => {
                if let (Some(x0), Some(y0), Some(x1), Some(y1)) = (i32_at(0), i32_at(1), i32_at(2), i32_at(3)) {
                    window = Some((x1 - x0 + 1, y1 - y0 + 1));
                }
            }
            b"tiles" => {
                if let (Some(w), Some(h)) = (i32_at(0), i32_at(1)) {
                    tiles = Some((w as u32, h as u32));
                }
            }
            _ => {}
        }
    }
    if let Some((w, h)) = window {
        if !(1..=MAX_TEXTURE_SIDE as i64).contains(&w) || !(1..=MAX_TEXTURE_SIDE as i64).contains(&h) {
            return Err(format!(
                "cannot decode image: EXR data window {w}×{h} is out of range: 1 to {MAX_TEXTURE_SIDE} a side"
            ));
        }
        if let Some((tw, th)) = tiles {
            let (mw, mh) = (w.max(EXR_TILE_SLACK), h.max(EXR_TILE_SLACK));
            if tw == 0 || th == 0 || tw as i64 > mw || th as i64 > mh {
                return Err(format!(
                    "cannot decode image: EXR tile size {tw}×{th} is out of range: 1 to {mw}×{mh} (the data window {w}×{h}, at least {EXR_TILE_SLACK})"
                ));
            }
        }
    }
    Ok(())
}

/// The decoded-size budget of an image of `encoded_len` bytes.
pub fn texture_budget(encoded_len: usize) -> u64 {
    (encoded_len as u64)
        .saturating_mul(TEXTURE_BUDGET_RATIO)
        .clamp(TEXTURE_BUDGET_FLOOR, TEXTURE_BUDGET_CAP)
}

/// Decodes an encoded image (PNG, JPEG, EXR, … by content) to an RGBA8
/// [`Texture`] (8-bit texels kept as stored, i.e. sRGB-encoded for colour
/// maps), within the limits in the module docs.
pub fn decode_texture(bytes: &[u8], name: &str) -> Result<Texture, String> {
    check_exr_header(bytes)?;
    let mut reader = image::ImageReader::new(std::io::Cursor::new(bytes))
        .with_guessed_format()
        .map_err(|e| format!("cannot decode image: {e}"))?;
    let mut limits = image::Limits::default();
    limits.max_image_width = Some(MAX_TEXTURE_SIDE);
    limits.max_image_height = Some(MAX_TEXTURE_SIDE);
    limits.max_alloc = Some(texture_budget(bytes.len()));
    reader.limits(limits);
    let img = reader.decode().map_err(|e| match e {
        image::ImageError::Limits(_) => format!(
            "cannot decode image: its declared size is out of range: at most {MAX_TEXTURE_SIDE} texels a side and {} MiB decoded for {} encoded bytes",
            texture_budget(bytes.len()) >> 20,
            bytes.len()
        ),
        e => format!("cannot decode image: {e}"),
    })?;
    let (width, height) = (img.width(), img.height());
    if width == 0 || height == 0 {
        return Err("image is empty".into());
    }
    if width > MAX_TEXTURE_SIDE || height > MAX_TEXTURE_SIDE {
        return Err(format!(
            "image is {width}×{height}: width and height must be at most {MAX_TEXTURE_SIDE}"
        ));
    }
    let rgba8 = img.into_rgba8().into_raw();
    Ok(Texture {
        name: name.to_string(),
        width,
        height,
        rgba8,
    })
}

/// Reads the image file `path` through `files` and decodes it (the texture is
/// named after the file).
pub(super) fn read_texture(path: &Path, files: &dyn FileSource) -> Result<Texture, String> {
    let bytes = files.read(path)?;
    let name = path
        .file_name()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    decode_texture(&bytes, &name)
}

/// The textures of a file's materials, each loaded once: materials that refer
/// to the same key (glTF image index, OBJ texture path) share one texture.
pub(super) struct TextureCache<K> {
    index: HashMap<K, usize>,
}

impl<K: Hash + Eq> TextureCache<K> {
    pub(super) fn new() -> Self {
        TextureCache { index: HashMap::new() }
    }

    /// The index in `textures` of the texture for `key`: loaded by `load` and
    /// appended the first time `key` is seen.
    pub(super) fn get_or_load<E>(
        &mut self,
        textures: &mut Vec<Texture>,
        key: K,
        load: impl FnOnce(&K) -> Result<Texture, E>,
    ) -> Result<usize, E> {
        if let Some(&ti) = self.index.get(&key) {
            return Ok(ti);
        }
        textures.push(load(&key)?);
        self.index.insert(key, textures.len() - 1);
        Ok(textures.len() - 1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An EXR header (magic, version, then `dataWindow` and `tiles` attributes and the
    /// terminating empty name) with a data window of `w`×`h` and tiles of `tw`×`th`.
    fn exr_header(w: i32, h: i32, tiles: Option<(u32, u32)>) -> Vec<u8> {
        let mut b = vec![0x76, 0x2f, 0x31, 0x01, 2, 2, 0, 0];
        let mut attr = |name: &str, ty: &str, value: &[u8]| {
            b.extend(name.bytes().chain([0]));
            b.extend(ty.bytes().chain([0]));
            b.extend((value.len() as i32).to_le_bytes());
            b.extend(value);
        };
        let window: Vec<u8> = [0, 0, w - 1, h - 1]
            .iter()
            .flat_map(|v: &i32| v.to_le_bytes())
            .collect();
        attr("dataWindow", "box2i", &window);
        if let Some((tw, th)) = tiles {
            let desc: Vec<u8> = tw
                .to_le_bytes()
                .into_iter()
                .chain(th.to_le_bytes())
                .chain([0])
                .collect();
            attr("tiles", "tiledesc", &desc);
        }
        b.push(0);
        b
    }

    /// The fuzzer's finding (docs/reliability.md, "tile-size-huge"): a tiled EXR whose
    /// tiles are far larger than its data window is refused before decoding, in one line
    /// naming the tile size and its range; tiles within the window (or the slack) and
    /// scanline files pass; a data window past the side limit is refused; bytes that are
    /// not an EXR are left to the decoders.
    #[test]
    fn exr_headers_with_huge_tiles_or_windows_are_refused_before_decoding() {
        let huge = exr_header(4, 4, Some((64, 536_870_912)));
        let e = check_exr_header(&huge).unwrap_err();
        assert!(
            e.contains("tile size 64×536870912") && e.contains("1 to 1024×1024") && !e.contains('\n'),
            "{e}"
        );
        let e = decode_texture(&huge, "huge.exr").unwrap_err();
        assert!(e.contains("tile size"), "{e}");
        assert!(check_exr_header(&exr_header(4, 4, Some((4, 4)))).is_ok());
        assert!(check_exr_header(&exr_header(4, 4, Some((EXR_TILE_SLACK as u32, 1)))).is_ok());
        assert!(check_exr_header(&exr_header(2048, 8, Some((2048, 8)))).is_ok());
        assert!(check_exr_header(&exr_header(2048, 8, Some((2049, 8)))).is_err());
        assert!(check_exr_header(&exr_header(4, 4, Some((0, 4)))).is_err());
        assert!(check_exr_header(&exr_header(64, 64, None)).is_ok());
        let e = check_exr_header(&exr_header(MAX_TEXTURE_SIDE as i32 + 1, 1, None)).unwrap_err();
        assert!(e.contains("data window"), "{e}");
        assert!(check_exr_header(b"\x89PNG\r\n\x1a\n").is_ok());
    }
}
