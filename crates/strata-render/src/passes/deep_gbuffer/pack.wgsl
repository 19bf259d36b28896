// DGB Table 1 packing: camera-space z of two layers in one RG32F texel and the
// Oct16 normals of two layers in one RGBA8 texel, so a tap of a later pass
// fetches both layers at once. Layers 2–3 (k > 2) go to a second pair.
#import "common/fullscreen.wgsl"

override LAYERS: u32 = 2u;

@group(0) @binding(0) var csz_tex: texture_2d_array<f32>;
@group(0) @binding(1) var normal_tex: texture_2d_array<f32>;

struct Packed {
    // r = layer 0 z, g = layer 1 z (0 = no surface)
    @location(0) z01: vec2f,
    // rg = layer 0 Oct16 normal, ba = layer 1 Oct16 normal
    @location(1) n01: vec4f,
}

struct Packed4 {
    @location(0) z01: vec2f,
    @location(1) n01: vec4f,
    @location(2) z23: vec2f,
    @location(3) n23: vec4f,
}

fn z_of(p: vec2i, layer: u32) -> f32 {
    if (layer >= LAYERS) {
        return 0.0;
    }
    return textureLoad(csz_tex, p, i32(layer), 0).r;
}

fn n_of(p: vec2i, layer: u32) -> vec2f {
    if (layer >= LAYERS) {
        return vec2f(0.5);
    }
    return textureLoad(normal_tex, p, i32(layer), 0).rg;
}

@fragment
fn fs_pack2(@builtin(position) pos: vec4f) -> Packed {
    let p = vec2i(pos.xy);
    var o: Packed;
    o.z01 = vec2f(z_of(p, 0u), z_of(p, 1u));
    o.n01 = vec4f(n_of(p, 0u), n_of(p, 1u));
    return o;
}

@fragment
fn fs_pack4(@builtin(position) pos: vec4f) -> Packed4 {
    let p = vec2i(pos.xy);
    var o: Packed4;
    o.z01 = vec2f(z_of(p, 0u), z_of(p, 1u));
    o.n01 = vec4f(n_of(p, 0u), n_of(p, 1u));
    o.z23 = vec2f(z_of(p, 2u), z_of(p, 3u));
    o.n23 = vec4f(n_of(p, 2u), n_of(p, 3u));
    return o;
}
