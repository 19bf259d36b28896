// The 8-bit display bytes of a target, on the GPU: the bytes `ImageBuf::to_rgba8` (and so
// every PNG strata writes) holds for the same texels, without reading the target back.
// The encoding is settled by thresholds (see `display/mod.rs`): the smallest f32 that
// the CPU encodes to each byte 1..=255, so GPU and CPU agree bit for bit.

struct Params {
    origin: vec2<u32>,
    size: vec2<u32>,
    // the viewer's display gain (1: the PNG's bytes)
    gain: f32,
    // the ImageBuf channels the CPU decodes this format to (1: grey, 2: RG, 3 or 4: RGB)
    channels: u32,
    // 1: an 8-bit format read as its raw bytes and decoded through `decode`
    bytes: u32,
    // 1: sRGB-encode (the threshold table's second half)
    srgb: u32,
}

@group(0) @binding(0) var src: texture_2d<f32>;
// 510 thresholds (linear, then sRGB), four to a vec4 (uniform arrays are 16-byte strided)
@group(0) @binding(1) var<uniform> thresholds: array<vec4<f32>, 128>;

fn threshold(i: u32) -> f32 {
    return thresholds[i / 4u][i % 4u];
}
@group(0) @binding(2) var<storage, read> decode: array<f32, 256>;
@group(0) @binding(3) var<uniform> p: Params;
@group(0) @binding(4) var out: texture_storage_2d<rgba8unorm, write>;

// The byte: how many of the 255 sorted thresholds are <= v. A first guess from the
// GPU's own encoding is within one byte of it; two threshold tests settle it (CPU twin
// `encode_cpu`). NaN gives 0, as the CPU's saturating cast does.
fn encode(v: f32) -> u32 {
    if (bitcast<u32>(v) & 0x7fffffffu) > 0x7f800000u {
        return 0u;
    }
    let base = select(0u, 255u, p.srgb != 0u);
    let c = clamp(v, 0.0, 1.0);
    var e = c;
    if p.srgb != 0u {
        // (uniform over the dispatch: a linear target skips the pow)
        e = select(1.055 * pow(c, 1.0 / 2.4) - 0.055, c * 12.92, c <= 0.0031308);
    }
    var b = min(u32(max(e * 255.0 + 0.5, 0.0)), 255u);
    // byte >= k exactly when v >= thresholds[base + k - 1]
    if b > 0u && v < threshold(base + max(b, 1u) - 1u) {
        b -= 1u;
    } else if b < 255u && v >= threshold(base + min(b, 254u)) {
        b += 1u;
    }
    return b;
}

fn channel(x: f32) -> f32 {
    if p.bytes != 0u {
        // the raw byte (an exact multiple of 1/255), decoded as the CPU decodes it
        return decode[min(u32(x * 255.0 + 0.5), 255u)];
    }
    return x;
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= p.size.x || id.y >= p.size.y {
        return;
    }
    let t = textureLoad(src, vec2<i32>(p.origin + id.xy), 0);
    var c = vec3<f32>(channel(t.x), channel(t.y), channel(t.z));
    if p.channels == 1u {
        c = vec3<f32>(c.x);
    } else if p.channels == 2u {
        c.z = 0.0;
    }
    if p.gain != 1.0 {
        c = c * p.gain;
    }
    let b = vec3<f32>(f32(encode(c.x)), f32(encode(c.y)), f32(encode(c.z)));
    textureStore(out, vec2<i32>(id.xy), vec4<f32>(b / 255.0, 1.0));
}
