//! Bounds-checked access to glTF binary data: buffers (GLB `BIN` chunk, `data:`
//! URIs, external files), accessors (every count, offset and stride is checked
//! against the bytes that are actually there before anything is allocated) and
//! images. Errors are short reasons; the caller names the file.

use std::borrow::Cow;
use std::path::Path;

use gltf::accessor::{DataType, Dimensions};

use crate::error::short;
use crate::files::FileSource;

/// Most elements an accessor without a buffer view (all zeros, optionally
/// with sparse substitutions) may have: there are no bytes to check its count
/// against.
pub const MAX_ZERO_ACCESSOR: usize = 1 << 20;

/// Checks a GLB header before `gltf` parses it: the declared total length must
/// cover the header and fit the data.
pub fn check_glb_header(bytes: &[u8]) -> Result<(), String> {
    if !bytes.starts_with(b"glTF") {
        return Ok(());
    }
    if bytes.len() < 20 {
        return Err(format!("GLB file is truncated: {} bytes", bytes.len()));
    }
    let length = u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]) as usize;
    if length < 20 || length > bytes.len() {
        return Err(format!(
            "GLB header length {length} is out of range: must be in 20..={} (the file size)",
            bytes.len()
        ));
    }
    Ok(())
}

/// Checks that every mesh primitive's attribute (and morph target) accessor
/// index is in range.
pub fn check_attribute_indices(root: &gltf::json::Root) -> Result<(), String> {
    let n = root.accessors.len();
    for (mi, m) in root.meshes.iter().enumerate() {
        for (pi, p) in m.primitives.iter().enumerate() {
            let targets = p
                .targets
                .iter()
                .flatten()
                .flat_map(|t| [t.positions, t.normals, t.tangents]);
            let attrs = p.attributes.values().map(|i| Some(*i));
            if let Some(bad) = attrs.chain(targets).flatten().find(|i| i.value() >= n) {
                return Err(format!(
                    "mesh {mi} primitive {pi}: accessor index {} is out of range (the file has {n} accessors)",
                    bad.value()
                ));
            }
        }
    }
    Ok(())
}

/// Decodes standard or URL-safe base64 (padding optional, whitespace ignored).
pub fn base64_decode(s: &str) -> Result<Vec<u8>, String> {
    fn value(c: u8) -> Option<u32> {
        Some(match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' | b'-' => 62,
            b'/' | b'_' => 63,
            _ => return None,
        } as u32)
    }
    let mut out = Vec::with_capacity(s.len() / 4 * 3 + 3);
    let (mut acc, mut bits) = (0u32, 0u32);
    let mut padding = 0usize;
    for (i, c) in s.bytes().enumerate() {
        if c.is_ascii_whitespace() {
            continue;
        }
        if c == b'=' {
            padding += 1;
            continue;
        }
        if padding > 0 {
            return Err(format!("invalid base64: data after padding at byte {i}"));
        }
        let v = value(c).ok_or_else(|| format!("invalid base64: byte {i} is {:?}", c as char))?;
        acc = (acc << 6) | v;
        bits += 6;
        if bits >= 8 {
            bits -= 8;
            out.push((acc >> bits) as u8);
            acc &= (1 << bits) - 1;
        }
    }
    if bits >= 6 || padding > 2 {
        return Err("invalid base64: truncated".into());
    }
    Ok(out)
}

/// Percent-decodes a relative URI into a path string.
pub fn percent_decode(uri: &str) -> Result<String, String> {
    let b = uri.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%' && i + 2 < b.len() {
            let hex = std::str::from_utf8(&b[i + 1..i + 3]).ok();
            if let Some(v) = hex.and_then(|h| u8::from_str_radix(h, 16).ok()) {
                out.push(v);
                i += 3;
                continue;
            }
        }
        out.push(b[i]);
        i += 1;
    }
    String::from_utf8(out).map_err(|_| format!("URI '{uri}' is not valid UTF-8 after percent-decoding"))
}

/// Bytes referenced by a URI: a `data:` URI's payload, or a file (absolute
/// `file:` / `file://` path, or relative to `base`).
pub fn uri_bytes(uri: &str, base: &Path, files: &dyn FileSource) -> Result<Vec<u8>, String> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let Some((_, payload)) = rest.split_once(";base64,") else {
            return Err("data URI is not base64 (';base64,' missing)".into());
        };
        return base64_decode(payload);
    }
    let file = if let Some(p) = uri.strip_prefix("file://").or_else(|| uri.strip_prefix("file:")) {
        base.join(percent_decode(p)?)
    } else if uri.contains(':') {
        return Err(format!("unsupported URI scheme in '{}'", short(uri)));
    } else {
        base.join(percent_decode(uri)?)
    };
    files.read(&file).map_err(|e| format!("{}: {e}", file.display()))
}

/// Loads every buffer, each cut to its declared `byteLength` (an error when
/// fewer bytes are there).
pub fn load_buffers<'a>(
    doc: &gltf::Document,
    blob: Option<&'a [u8]>,
    base: &Path,
    files: &dyn FileSource,
) -> Result<Vec<Cow<'a, [u8]>>, String> {
    let mut out = Vec::with_capacity(doc.buffers().len());
    for b in doc.buffers() {
        let data: Cow<'a, [u8]> = match b.source() {
            gltf::buffer::Source::Bin => Cow::Borrowed(
                blob.ok_or_else(|| format!("buffer {}: refers to a GLB BIN chunk but there is none", b.index()))?,
            ),
            gltf::buffer::Source::Uri(uri) => {
                Cow::Owned(uri_bytes(uri, base, files).map_err(|e| format!("buffer {}: {e}", b.index()))?)
            }
        };
        let length = b.length();
        if data.len() < length {
            return Err(format!(
                "buffer {}: byteLength is {length} but only {} bytes are there",
                b.index(),
                data.len()
            ));
        }
        out.push(match data {
            Cow::Borrowed(d) => Cow::Borrowed(&d[..length]),
            Cow::Owned(mut d) => {
                d.truncate(length);
                Cow::Owned(d)
            }
        });
    }
    Ok(out)
}

/// The bytes of a buffer view, checked against its buffer.
pub fn view_bytes<'b>(view: &gltf::buffer::View, buffers: &'b [Cow<'_, [u8]>]) -> Result<&'b [u8], String> {
    let bi = view.buffer().index();
    let buf = buffers
        .get(bi)
        .ok_or_else(|| format!("buffer view {}: buffer {bi} is missing", view.index()))?;
    let (start, len) = (view.offset(), view.length());
    start
        .checked_add(len)
        .and_then(|end| buf.get(start..end))
        .ok_or_else(|| {
            format!(
                "buffer view {}: bytes {start}..{start}+{len} are out of range (buffer {bi} has {} bytes)",
                view.index(),
                buf.len()
            )
        })
}

fn data_type_name(t: DataType) -> &'static str {
    match t {
        DataType::I8 => "BYTE",
        DataType::U8 => "UNSIGNED_BYTE",
        DataType::I16 => "SHORT",
        DataType::U16 => "UNSIGNED_SHORT",
        DataType::U32 => "UNSIGNED_INT",
        DataType::F32 => "FLOAT",
    }
}

/// One component as f32 (normalized integers mapped to [0, 1] / [−1, 1]).
fn component_f32(t: DataType, normalized: bool, b: &[u8]) -> f32 {
    match t {
        DataType::F32 => f32::from_le_bytes([b[0], b[1], b[2], b[3]]),
        DataType::U8 if normalized => b[0] as f32 / 255.0,
        DataType::U8 => b[0] as f32,
        DataType::I8 if normalized => (b[0] as i8 as f32 / 127.0).max(-1.0),
        DataType::I8 => b[0] as i8 as f32,
        DataType::U16 if normalized => u16::from_le_bytes([b[0], b[1]]) as f32 / 65535.0,
        DataType::U16 => u16::from_le_bytes([b[0], b[1]]) as f32,
        DataType::I16 if normalized => (i16::from_le_bytes([b[0], b[1]]) as f32 / 32767.0).max(-1.0),
        DataType::I16 => i16::from_le_bytes([b[0], b[1]]) as f32,
        DataType::U32 if normalized => (u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64 / u32::MAX as f64) as f32,
        DataType::U32 => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f32,
    }
}

fn index_u32(t: DataType, b: &[u8]) -> u32 {
    match t {
        DataType::U8 | DataType::I8 => b[0] as u32,
        DataType::U16 | DataType::I16 => u16::from_le_bytes([b[0], b[1]]) as u32,
        _ => u32::from_le_bytes([b[0], b[1], b[2], b[3]]),
    }
}

/// Calls `f(i, element_bytes)` for each of `count` elements of `elem` bytes,
/// `stride` apart from `offset` in `data`, after checking they all fit.
fn for_each_element(
    what: &str,
    data: &[u8],
    offset: usize,
    stride: usize,
    elem: usize,
    count: usize,
    mut f: impl FnMut(usize, &[u8]),
) -> Result<(), String> {
    if count == 0 {
        return Ok(());
    }
    let need = stride
        .checked_mul(count - 1)
        .and_then(|x| x.checked_add(elem))
        .and_then(|x| x.checked_add(offset));
    match need {
        Some(n) if n <= data.len() => {}
        _ => {
            return Err(format!(
                "{what}: {count} elements of {elem} bytes, {stride} apart from byte {offset}, need more than the {} bytes of its buffer view",
                data.len()
            ));
        }
    }
    for i in 0..count {
        let s = offset + i * stride;
        f(i, &data[s..s + elem]);
    }
    Ok(())
}

/// Reads an accessor as `count × comps` components, converted by `conv`.
fn read_accessor<T: Copy + Default>(
    acc: &gltf::Accessor,
    buffers: &[Cow<'_, [u8]>],
    conv: impl Fn(DataType, bool, &[u8]) -> T,
) -> Result<Vec<T>, String> {
    let what = format!("accessor {}", acc.index());
    let t = acc.data_type();
    let comps = acc.dimensions().multiplicity();
    let csize = t.size();
    let elem = comps * csize;
    let count = acc.count();
    let normalized = acc.normalized();
    let mut out: Vec<T>;
    match acc.view() {
        Some(view) => {
            let data = view_bytes(&view, buffers).map_err(|e| format!("{what}: {e}"))?;
            let stride = view.stride().unwrap_or(elem);
            if stride < elem {
                return Err(format!(
                    "{what}: byteStride {stride} of buffer view {} is smaller than the element size {elem}",
                    view.index()
                ));
            }
            // `for_each_element` checks the data holds every element before
            // the output (bounded by that data) is allocated.
            for_each_element(&what, data, acc.offset(), stride, elem, count, |_, _| {})?;
            out = Vec::with_capacity(count * comps);
            for_each_element(&what, data, acc.offset(), stride, elem, count, |_, e| {
                for c in 0..comps {
                    out.push(conv(t, normalized, &e[c * csize..(c + 1) * csize]));
                }
            })?;
        }
        None => {
            if acc.sparse().is_none() {
                return Err(format!("{what}: has neither a buffer view nor sparse values"));
            }
            if count > MAX_ZERO_ACCESSOR {
                return Err(format!(
                    "{what}: count {count} without a buffer view is out of range: at most {MAX_ZERO_ACCESSOR}"
                ));
            }
            out = vec![T::default(); count * comps];
        }
    }
    if let Some(sparse) = acc.sparse() {
        let n = sparse.count();
        if n > count {
            return Err(format!("{what}: sparse count {n} exceeds the accessor count {count}"));
        }
        let iv = sparse.indices();
        let it = match iv.index_type() {
            gltf::accessor::sparse::IndexType::U8 => DataType::U8,
            gltf::accessor::sparse::IndexType::U16 => DataType::U16,
            gltf::accessor::sparse::IndexType::U32 => DataType::U32,
        };
        let idata = view_bytes(&iv.view(), buffers).map_err(|e| format!("{what}: sparse indices: {e}"))?;
        let mut indices = Vec::new();
        for_each_element(
            &format!("{what} sparse indices"),
            idata,
            iv.offset(),
            it.size(),
            it.size(),
            n,
            |_, _| {},
        )?;
        indices.reserve(n);
        for_each_element(
            &format!("{what} sparse indices"),
            idata,
            iv.offset(),
            it.size(),
            it.size(),
            n,
            |_, b| indices.push(index_u32(it, b) as usize),
        )?;
        let vv = sparse.values();
        let vdata = view_bytes(&vv.view(), buffers).map_err(|e| format!("{what}: sparse values: {e}"))?;
        let mut bad = None;
        for_each_element(
            &format!("{what} sparse values"),
            vdata,
            vv.offset(),
            elem,
            elem,
            n,
            |k, e| {
                let i = indices[k];
                if i >= count {
                    bad.get_or_insert(i);
                    return;
                }
                for c in 0..comps {
                    out[i * comps + c] = conv(t, normalized, &e[c * csize..(c + 1) * csize]);
                }
            },
        )?;
        if let Some(i) = bad {
            return Err(format!("{what}: sparse index {i} is out of range (count {count})"));
        }
    }
    Ok(out)
}

/// Reads a float attribute accessor of the given type as `N`-vectors.
pub fn read_vectors<const N: usize>(acc: &gltf::Accessor, buffers: &[Cow<'_, [u8]>]) -> Result<Vec<[f32; N]>, String> {
    let want = match N {
        2 => Dimensions::Vec2,
        3 => Dimensions::Vec3,
        _ => Dimensions::Vec4,
    };
    if acc.dimensions() != want {
        return Err(format!(
            "accessor {}: type {:?} is not {want:?}",
            acc.index(),
            acc.dimensions()
        ));
    }
    let flat = read_accessor(acc, buffers, component_f32)?;
    Ok(flat.chunks_exact(N).map(|c| std::array::from_fn(|k| c[k])).collect())
}

/// Reads an index accessor (SCALAR, UNSIGNED_BYTE/SHORT/INT).
pub fn read_indices(acc: &gltf::Accessor, buffers: &[Cow<'_, [u8]>]) -> Result<Vec<u32>, String> {
    let t = acc.data_type();
    if acc.dimensions() != Dimensions::Scalar || !matches!(t, DataType::U8 | DataType::U16 | DataType::U32) {
        return Err(format!(
            "accessor {}: indices must be SCALAR UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT, not {:?} {}",
            acc.index(),
            acc.dimensions(),
            data_type_name(t)
        ));
    }
    read_accessor(acc, buffers, |t, _, b| index_u32(t, b))
}

/// The encoded bytes of glTF image `index` (read from the JSON: `gltf`'s
/// `Image::source` panics on an image without a `uri` or a buffer view
/// without a `mimeType`).
pub fn image_bytes<'b>(
    doc: &gltf::Document,
    index: usize,
    buffers: &'b [Cow<'_, [u8]>],
    base: &Path,
    files: &dyn FileSource,
) -> Result<Cow<'b, [u8]>, String> {
    let image = doc
        .as_json()
        .images
        .get(index)
        .ok_or_else(|| format!("image {index} is missing"))?;
    if let Some(v) = image.buffer_view {
        let view = doc
            .views()
            .nth(v.value())
            .ok_or_else(|| format!("buffer view {} is missing", v.value()))?;
        view_bytes(&view, buffers).map(Cow::Borrowed)
    } else if let Some(uri) = &image.uri {
        uri_bytes(uri, base, files).map(Cow::Owned)
    } else {
        Err("the image has neither a bufferView nor a uri".into())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_round_trip() {
        assert_eq!(base64_decode("aGVsbG8=").unwrap(), b"hello");
        assert_eq!(base64_decode("aGVsbG8").unwrap(), b"hello");
        assert_eq!(base64_decode("AAECAw==").unwrap(), [0, 1, 2, 3]);
        assert!(base64_decode("aGV$bG8=").is_err());
        assert!(base64_decode("a").is_err());
        assert!(base64_decode("aG=Vs").is_err());
    }

    #[test]
    fn percent_decoding() {
        assert_eq!(percent_decode("a%20b.bin").unwrap(), "a b.bin");
        assert_eq!(percent_decode("100%").unwrap(), "100%");
        assert_eq!(percent_decode("%4").unwrap(), "%4");
        assert!(percent_decode("%FF.bin").is_err());
    }
}
