//! Seed inputs: small, realistic files generated here (glTF with a base64
//! buffer and embedded PNG, GLB, OBJ/MTL, TOML scenes, camera paths, presets,
//! PNG/JPEG/EXR encoded with `image`), the repo's TOML scenes and presets, and
//! the small shared scenes (Cornell box OBJ/MTL) when present.

use std::path::{Path, PathBuf};

use crate::Format;

/// Little-endian bytes of floats.
fn f32_bytes(v: &[f32]) -> Vec<u8> {
    v.iter().flat_map(|x| x.to_le_bytes()).collect()
}

/// Standard base64 with padding.
pub fn base64_encode(data: &[u8]) -> String {
    const A: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(data.len().div_ceil(3) * 4);
    for c in data.chunks(3) {
        let b = [c[0], *c.get(1).unwrap_or(&0), *c.get(2).unwrap_or(&0)];
        let n = (b[0] as u32) << 16 | (b[1] as u32) << 8 | b[2] as u32;
        for k in 0..4 {
            if k <= c.len() {
                out.push(A[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// Packs JSON and a binary chunk into a GLB container.
pub fn glb(json: &[u8], bin: Option<&[u8]>) -> Vec<u8> {
    let mut j = json.to_vec();
    while !j.len().is_multiple_of(4) {
        j.push(b' ');
    }
    let mut b = bin.map(<[u8]>::to_vec);
    if let Some(b) = &mut b {
        while !b.len().is_multiple_of(4) {
            b.push(0);
        }
    }
    let total = 12 + 8 + j.len() + b.as_ref().map_or(0, |b| 8 + b.len());
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(j.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&j);
    if let Some(b) = b {
        out.extend_from_slice(&(b.len() as u32).to_le_bytes());
        out.extend_from_slice(b"BIN\0");
        out.extend_from_slice(&b);
    }
    out
}

/// Splits a GLB into (JSON, BIN) when its chunk headers are consistent.
pub fn glb_split(data: &[u8]) -> Option<(Vec<u8>, Option<Vec<u8>>)> {
    if data.len() < 20 || &data[0..4] != b"glTF" {
        return None;
    }
    let jl = u32::from_le_bytes(data[12..16].try_into().ok()?) as usize;
    let json = data.get(20..20usize.checked_add(jl)?)?.to_vec();
    let rest = &data[20 + jl..];
    let bin = if rest.len() >= 8 {
        let bl = u32::from_le_bytes(rest[0..4].try_into().ok()?) as usize;
        rest.get(8..8usize.checked_add(bl)?).map(<[u8]>::to_vec)
    } else {
        None
    };
    Some((json, bin))
}

fn encode(img: image::DynamicImage, format: image::ImageFormat) -> Vec<u8> {
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, format).expect("encode seed image");
    out.into_inner()
}

fn gradient_rgba(w: u32, h: u32) -> image::RgbaImage {
    image::RgbaImage::from_fn(w, h, |x, y| {
        image::Rgba([(x * 60) as u8, (y * 60) as u8, ((x + y) * 30) as u8, 200])
    })
}

/// A 2×2 RGBA PNG.
pub fn tiny_png() -> Vec<u8> {
    encode(
        image::DynamicImage::ImageRgba8(gradient_rgba(2, 2)),
        image::ImageFormat::Png,
    )
}

pub fn png_seeds() -> Vec<Vec<u8>> {
    vec![
        tiny_png(),
        encode(
            image::DynamicImage::ImageRgba8(gradient_rgba(5, 3)),
            image::ImageFormat::Png,
        ),
        encode(
            image::DynamicImage::ImageRgb8(image::RgbImage::from_fn(4, 4, |x, y| {
                image::Rgb([x as u8 * 50, y as u8 * 50, 7])
            })),
            image::ImageFormat::Png,
        ),
        encode(
            image::DynamicImage::ImageLuma16(image::ImageBuffer::from_fn(3, 3, |x, y| {
                image::Luma([(x * 9000 + y * 300) as u16])
            })),
            image::ImageFormat::Png,
        ),
        encode(
            image::DynamicImage::ImageLumaA8(image::ImageBuffer::from_fn(2, 5, |x, y| {
                image::LumaA([(x * 90 + y) as u8, 99])
            })),
            image::ImageFormat::Png,
        ),
    ]
}

pub fn jpeg_seeds() -> Vec<Vec<u8>> {
    vec![
        encode(
            image::DynamicImage::ImageRgb8(image::RgbImage::from_fn(8, 8, |x, y| {
                image::Rgb([x as u8 * 30, y as u8 * 30, 90])
            })),
            image::ImageFormat::Jpeg,
        ),
        encode(
            image::DynamicImage::ImageRgb8(image::RgbImage::from_fn(17, 9, |x, y| {
                image::Rgb([(x * y) as u8, 200, x as u8])
            })),
            image::ImageFormat::Jpeg,
        ),
        encode(
            image::DynamicImage::ImageLuma8(image::GrayImage::from_fn(16, 16, |x, y| {
                image::Luma([(x ^ y) as u8 * 16])
            })),
            image::ImageFormat::Jpeg,
        ),
    ]
}

pub fn exr_seeds() -> Vec<Vec<u8>> {
    vec![
        encode(
            image::DynamicImage::ImageRgba32F(image::Rgba32FImage::from_fn(4, 4, |x, y| {
                image::Rgba([x as f32 * 0.25, y as f32 * 0.5, 1.5, 1.0])
            })),
            image::ImageFormat::OpenExr,
        ),
        encode(
            image::DynamicImage::ImageRgb32F(image::Rgb32FImage::from_fn(3, 2, |x, y| {
                image::Rgb([x as f32, y as f32, 0.5])
            })),
            image::ImageFormat::OpenExr,
        ),
    ]
}

/// Binary data of the tiny glTF/GLB quad: (bin, positions at 0, normals at
/// 48, uvs at 96, u16 indices at 128, png at 140).
fn quad_bin() -> (Vec<u8>, usize) {
    let mut bin = Vec::new();
    bin.extend(f32_bytes(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 1.0, 0.0])); // 0..48
    bin.extend(f32_bytes(&[0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0])); // 48..96
    bin.extend(f32_bytes(&[0.0, 1.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0])); // 96..128
    bin.extend([0u16, 1, 2, 0, 2, 3].iter().flat_map(|i| i.to_le_bytes())); // 128..140
    let png = tiny_png();
    let png_len = png.len();
    bin.extend(png); // 140..
    (bin, png_len)
}

/// The glTF JSON of the quad, with `buffer` as the buffer object and `image`
/// as the image object.
fn quad_json(bin_len: usize, png_len: usize, buffer: &str, image: &str) -> String {
    format!(
        r#"{{
"asset":{{"version":"2.0"}},
"extensionsUsed":["KHR_materials_emissive_strength"],
"scene":0,
"scenes":[{{"nodes":[0,2,3]}}],
"nodes":[
 {{"name":"parent","translation":[1,0,0],"children":[1]}},
 {{"name":"quad","mesh":0,"scale":[2,2,2]}},
 {{"name":"cam","camera":0,"translation":[0,0,5]}},
 {{"name":"mirrored","mesh":0,"matrix":[-1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1]}}
],
"cameras":[{{"type":"perspective","perspective":{{"yfov":0.8,"znear":0.1}}}}],
"meshes":[{{"name":"quadmesh","primitives":[{{"attributes":{{"POSITION":0,"NORMAL":1,"TEXCOORD_0":2}},"indices":3,"material":0}}]}}],
"materials":[{{"name":"mat","pbrMetallicRoughness":{{"baseColorFactor":[0.5,0.25,1.0,0.5],"baseColorTexture":{{"index":0}},"metallicFactor":0.3,"roughnessFactor":0.6}},"emissiveFactor":[1.0,0.5,0.0],"alphaMode":"BLEND","extensions":{{"KHR_materials_emissive_strength":{{"emissiveStrength":2.0}}}}}}],
"textures":[{{"source":0}}],
"images":[{image}],
"accessors":[
 {{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}},
 {{"bufferView":1,"componentType":5126,"count":4,"type":"VEC3"}},
 {{"bufferView":2,"componentType":5126,"count":4,"type":"VEC2"}},
 {{"bufferView":3,"componentType":5123,"count":6,"type":"SCALAR"}}
],
"bufferViews":[
 {{"buffer":0,"byteOffset":0,"byteLength":48}},
 {{"buffer":0,"byteOffset":48,"byteLength":48}},
 {{"buffer":0,"byteOffset":96,"byteLength":32}},
 {{"buffer":0,"byteOffset":128,"byteLength":12}},
 {{"buffer":0,"byteOffset":140,"byteLength":{png_len}}}
],
"buffers":[{buffer}]
}}"#,
        buffer = buffer.replace("LEN", &bin_len.to_string()),
    )
}

/// A strip + sparse + interleaved-stride glTF (JSON with a data-URI buffer).
fn strip_sparse_gltf() -> Vec<u8> {
    // Interleaved position+uv (20 bytes stride), 4 vertices: 0..80.
    let mut bin = Vec::new();
    for (p, t) in [
        ([0.0f32, 0.0, 0.0], [0.0f32, 0.0]),
        ([1.0, 0.0, 0.0], [1.0, 0.0]),
        ([0.0, 1.0, 0.0], [0.0, 1.0]),
        ([1.0, 1.0, 0.5], [1.0, 1.0]),
    ] {
        bin.extend(f32_bytes(&p));
        bin.extend(f32_bytes(&t));
    }
    bin.extend([0u8, 1, 2, 3]); // 80..84 u8 strip indices
    bin.extend([3u8, 0, 0, 0]); // 84..88 sparse index (u8) + padding
    bin.extend(f32_bytes(&[1.0, 1.0, -0.5])); // 88..100 sparse value
    let uri = format!("data:application/octet-stream;base64,{}", base64_encode(&bin));
    format!(
        r#"{{"asset":{{"version":"2.0"}},
"nodes":[{{"mesh":0,"rotation":[0,0.7071068,0,0.7071068]}},{{"mesh":1,"translation":[0,2,0]}}],
"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0,"TEXCOORD_0":1}},"indices":2,"mode":5}}]}},
 {{"name":"fan","primitives":[{{"attributes":{{"POSITION":3}},"mode":6}},{{"attributes":{{"POSITION":0}},"mode":1}}]}}],
"accessors":[
 {{"bufferView":0,"byteOffset":0,"componentType":5126,"count":4,"type":"VEC3"}},
 {{"bufferView":0,"byteOffset":12,"componentType":5126,"count":4,"type":"VEC2"}},
 {{"bufferView":1,"componentType":5121,"count":4,"type":"SCALAR"}},
 {{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3","sparse":{{"count":1,"indices":{{"bufferView":2,"componentType":5121}},"values":{{"bufferView":3}}}}}}
],
"bufferViews":[
 {{"buffer":0,"byteOffset":0,"byteLength":80,"byteStride":20}},
 {{"buffer":0,"byteOffset":80,"byteLength":4}},
 {{"buffer":0,"byteOffset":84,"byteLength":1}},
 {{"buffer":0,"byteOffset":88,"byteLength":12}}
],
"buffers":[{{"byteLength":{},"uri":"{uri}"}}]}}"#,
        bin.len()
    )
    .into_bytes()
}

/// External files the glTF/OBJ/TOML targets may refer to (relative to the
/// input's folder).
pub fn companion_files() -> Vec<(&'static str, Vec<u8>)> {
    let (bin, png_len) = quad_bin();
    vec![
        ("buf.bin", bin.clone()),
        ("tex.png", tiny_png()),
        ("in.mtl", TINY_MTL.as_bytes().to_vec()),
        ("tiny.obj", TINY_OBJ.as_bytes().to_vec()),
        (
            "tiny.glb",
            glb(
                quad_json(
                    bin.len(),
                    png_len,
                    r#"{"byteLength":LEN}"#,
                    r#"{"bufferView":4,"mimeType":"image/png"}"#,
                )
                .as_bytes(),
                Some(&bin),
            ),
        ),
    ]
}

pub const TINY_OBJ: &str = "# tiny cube corner\nmtllib in.mtl\no box\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 -1\nvn 0 -1 0\nusemtl red\nf 1/1/1 3/3/1 2/2/1\nf 1/1/1 4/4/1 3/3/1\ng floor\nusemtl lamp\nf 1/1/2 2/2/2 6/3/2 5/4/2\ns 1\nf -6 -3 -1\n";

pub const TINY_MTL: &str = "newmtl red\nKd 0.8 0.1 0.1\nKs 0.5 0.5 0.5\nNs 50\nd 1.0\nmap_Kd tex.png\nnewmtl lamp\nKd 0 0 0\nKe 10 9 8\nTr 0.25\nNs 0\nillum 2\n";

/// A camera-path scene: a built-in plane, a camera and unevenly spaced keyframes.
pub const PATH_TOML: &str = "builtin = \"plane\"\n\n[camera]\neye = [0.0, 2.0, 6.0]\ntarget = [0.0, 0.0, 0.0]\nfov = 50.0\nnear = 0.05\n\n[camera_path]\nkeyframes = [\n  { frame = 0, eye = [0.0, 2.0, 6.0], target = [0.0, 0.0, 0.0] },\n  { frame = 7.5, eye = [3.0, 2.5, 4.0], target = [0.0, 0.5, 0.0] },\n  { frame = 10, eye = [4.0, 1.0, 0.0], target = [0.0, 0.0, 0.0] },\n  { frame = 60, eye = [-4.0, 3.0, -2.0], target = [1.0, 0.0, 0.0] },\n]\n";

const FULL_TOML: &str = r#"name = "fuzz seed"
builtin = "cornell"
scale = 1.5
translate = [0.0, 0.1, 0.0]

[camera]
eye = [0.0, 1.0, 3.5]
target = [0.0, 1.0, 0.0]
up = [0.0, 1.0, 0.0]
fov = 45.0
near = 0.01

[[light]]
type = "sun"
direction = [-0.3, -1.0, -0.4]
color = [1.0, 0.9, 0.8]
illuminance = 3.0

[[light]]
type = "point"
position = [0.0, 1.8, 0.0]
intensity = 20.0

[[light]]
type = "spot"
position = [0.5, 1.9, 0.5]
direction = [0.0, -1.0, 0.0]
intensity = 50.0
inner_deg = 15.0
outer_deg = 25.0

[[light]]
type = "rect"
center = [0.0, 1.95, 0.0]
half_u = [0.2, 0.0, 0.0]
half_v = [0.0, 0.0, 0.2]
radiance = [5.0, 5.0, 5.0]
emitter = true

[settings]
ao_radius = 0.5
min_separation = 0.1
radiosity_radius = 2.0
exposure = 1.2
sky = [0.3, 0.45, 0.75]
ambient = [0.02, 0.02, 0.02]

[ground]
y = 0.0
size = 10.0
color = [0.5, 0.5, 0.5]

[[animate]]
object = "light3"
type = "slide"
amplitude = [0.0, 0.0, 0.5]
period_frames = 60.0
"#;

const MESH_TOML: &str = "mesh = \"tiny.obj\"\nscale = 2.0\n\n[ground]\nsize = 4.0\n\n[[animate]]\nobject = \"box\"\ntype = \"swing\"\npivot = [0, 0, 0]\naxis = [0, 1, 0]\namplitude_deg = 30\nperiod_frames = 40\n";

/// `<repo root>` (from this crate's manifest folder).
pub fn repo_root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The shared scenes folder, `<repo>/../shared/scenes` or `/work/shared/scenes`.
pub fn shared_scenes() -> Option<PathBuf> {
    [
        repo_root().join("../shared/scenes"),
        PathBuf::from("/work/shared/scenes"),
    ]
    .into_iter()
    .find(|p| p.is_dir())
}

/// A small shared file, or `None` with the reason on stderr (once per call).
fn shared(rel: &str, notes: &mut Vec<String>) -> Option<Vec<u8>> {
    let Some(dir) = shared_scenes() else {
        notes.push(format!("skipping shared seed {rel}: no shared scenes folder"));
        return None;
    };
    match std::fs::read(dir.join(rel)) {
        Ok(b) => Some(b),
        Err(e) => {
            notes.push(format!("skipping shared seed {rel}: {e}"));
            None
        }
    }
}

/// The repo's TOML scenes with their `mesh` pointed at the small companion
/// files (the originals need the large shared scenes).
fn repo_toml_scenes(notes: &mut Vec<String>) -> Vec<Vec<u8>> {
    let dir = repo_root().join("scenes");
    let mut paths: Vec<PathBuf> = match std::fs::read_dir(&dir) {
        Ok(rd) => rd
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|e| e == "toml"))
            .collect(),
        Err(e) => {
            notes.push(format!("skipping repo TOML scenes: {}: {e}", dir.display()));
            return Vec::new();
        }
    };
    paths.sort();
    let mut out = Vec::new();
    for (i, p) in paths.iter().enumerate() {
        let Ok(text) = std::fs::read_to_string(p) else { continue };
        let mesh = if i % 2 == 0 { "tiny.obj" } else { "tiny.glb" };
        let text: Vec<String> = text
            .lines()
            .map(|l| {
                if l.trim_start().starts_with("mesh") {
                    format!("mesh = \"{mesh}\"")
                } else {
                    l.to_string()
                }
            })
            .collect();
        out.push(text.join("\n").into_bytes());
    }
    out
}

fn repo_presets(notes: &mut Vec<String>) -> Vec<Vec<u8>> {
    let dir = repo_root().join("presets");
    let mut paths: Vec<PathBuf> = std::fs::read_dir(&dir)
        .map(|rd| rd.filter_map(|e| e.ok().map(|e| e.path())).collect())
        .unwrap_or_default();
    paths.sort();
    let mut out: Vec<Vec<u8>> = paths.iter().filter_map(|p| std::fs::read(p).ok()).collect();
    if out.is_empty() {
        notes.push(format!("no presets in {}", dir.display()));
    }
    out.push(b"name = \"x\"\nsamples = 3\nreconstruction_taps = 1\nnormal_test = false\nmin_mip = 0\nguard_band_shaded = 0.0\n".to_vec());
    out
}

/// All seeds of a format, plus notes about skipped ones.
pub fn seeds(format: Format) -> (Vec<Vec<u8>>, Vec<String>) {
    let mut notes = Vec::new();
    let (bin, png_len) = quad_bin();
    let seeds = match format {
        Format::Gltf => {
            let data_uri = format!(
                r#"{{"byteLength":LEN,"uri":"data:application/octet-stream;base64,{}"}}"#,
                base64_encode(&bin)
            );
            let png_uri = format!(r#"{{"uri":"data:image/png;base64,{}"}}"#, base64_encode(&tiny_png()));
            vec![
                quad_json(bin.len(), png_len, &data_uri, r#"{"bufferView":4,"mimeType":"image/png"}"#).into_bytes(),
                quad_json(bin.len(), png_len, r#"{"byteLength":LEN,"uri":"buf.bin"}"#, r#"{"uri":"tex.png"}"#).into_bytes(),
                quad_json(bin.len(), png_len, &data_uri, &png_uri).into_bytes(),
                strip_sparse_gltf(),
            ]
        }
        Format::Glb => {
            let json = quad_json(bin.len(), png_len, r#"{"byteLength":LEN}"#, r#"{"bufferView":4,"mimeType":"image/png"}"#);
            // u32 indices, no normals, no texture.
            let mut bin2 = bin[..140].to_vec();
            bin2.truncate(128);
            bin2.extend([0u32, 1, 2, 0, 2, 3].iter().flat_map(|i| i.to_le_bytes()));
            let json2 = r#"{"asset":{"version":"2.0"},"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0,"children":[1],"matrix":[1,0,0,0,0,1,0,0,0,0,1,0,0.5,0,0,1]},{"mesh":0,"scale":[0.5,0.5,0.5]}],
"meshes":[{"primitives":[{"attributes":{"POSITION":0,"TEXCOORD_0":1},"indices":2}]}],
"accessors":[{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3"},{"bufferView":1,"componentType":5126,"count":4,"type":"VEC2"},{"bufferView":2,"componentType":5125,"count":6,"type":"SCALAR"}],
"bufferViews":[{"buffer":0,"byteLength":48},{"buffer":0,"byteOffset":96,"byteLength":32},{"buffer":0,"byteOffset":128,"byteLength":24}],
"buffers":[{"byteLength":152}]}"#
                .replace("152", &bin2.len().to_string());
            vec![glb(json.as_bytes(), Some(&bin)), glb(json2.as_bytes(), Some(&bin2))]
        }
        Format::Obj => {
            let mut v = vec![
                TINY_OBJ.as_bytes().to_vec(),
                b"v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0.5 1.5 0\nvn 0 0 1\nf 1//1 2//1 3//1 5//1 4//1\nl 1 2\np 3\n".to_vec(),
                b"o quad\nv -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1\nvt 0 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf -4/-4 -1/-1 -2/-2 -3/-3\n".to_vec(),
            ];
            v.extend(shared("cornell_box/cornell_box.obj", &mut notes));
            v
        }
        Format::Mtl => {
            let mut v = vec![
                TINY_MTL.as_bytes().to_vec(),
                b"newmtl red\nKa 0 0 0\nKd 1 1 1\nKe 0 0 0\nd 0.5\nNs 1000\nmap_Kd -s 1 1 1 -o 0 0 0 tex.png\nnewmtl lamp\nmap_Kd tex.png\n".to_vec(),
            ];
            v.extend(shared("cornell_box/cornell_box.mtl", &mut notes));
            v
        }
        Format::Toml => {
            let mut v = vec![
                FULL_TOML.as_bytes().to_vec(),
                MESH_TOML.as_bytes().to_vec(),
                b"builtin = \"plane\"\n[camera]\neye = [0, 1, 5]\ntarget = [0, 0, 0]\nup = [0, 1, 0]\nfov = 179.0\n".to_vec(),
            ];
            v.extend(repo_toml_scenes(&mut notes));
            v
        }
        Format::Path => vec![
            PATH_TOML.as_bytes().to_vec(),
            b"builtin = \"plane\"\n[camera_path]\nkeyframes = [ { frame = 0, eye = [0, 1, 5], target = [0, 0, 0] }, { frame = 1, eye = [0.1, 1, 5], target = [0, 0, 0] } ]\n".to_vec(),
            b"builtin = \"plane\"\n[camera_path]\nkeyframes = [ { frame = 3, eye = [1, 1, 1], target = [0, 0, 0] } ]\n".to_vec(),
        ],
        Format::Preset => repo_presets(&mut notes),
        Format::Png => png_seeds(),
        Format::Jpeg => jpeg_seeds(),
        Format::Exr => exr_seeds(),
    };
    (seeds, notes)
}

/// The fixed folder inputs are loaded from (in memory; nothing is written).
pub fn input_dir() -> &'static Path {
    Path::new("/fuzz")
}
