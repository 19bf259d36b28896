// Joint bilateral upsampling (Kopf et al. 2007) of a gather run at 1/s resolution
// (`RadiositySettings::gather_scale`; not in DGB): each full-resolution pixel averages
// the 3×3 low-resolution texels around its own, each standing at the pixel it shaded
// (`block_pixel`), weighted by screen distance × the bilateral filter's plane and
// normal weights (bilateral.wgsl's, on the pixel's own layer). Where no texel holds the
// pixel's surface (all weights ≈ 0: thin features), the texel whose depth is nearest
// the pixel's (relative) stands in. CPU twin: `radiosity::upsample::upsample_cpu`.
#import "common/fullscreen.wgsl"
#import "common/frame.wgsl"
#import "common/camera.wgsl"
#import "common/packing.wgsl"
#import "common/spiral.wgsl"

override LAYERS: u32 = 2u;

// Matches `upsample::UpsampleUniforms`.
struct Upsample {
    scale: u32,
    seed: u32,
    plane_sharpness: f32,
    normal_power: u32,
}

@group(0) @binding(0) var<uniform> frame: Frame;
@group(1) @binding(0) var<uniform> up: Upsample;
@group(1) @binding(1) var low0: texture_2d<f32>;
@group(1) @binding(2) var low1: texture_2d<f32>;
@group(1) @binding(3) var zmip: texture_2d<f32>;
@group(1) @binding(4) var npack: texture_2d<f32>;

struct Out {
    @location(0) e0: vec4f,
    @location(1) e1: vec4f,
}

// Below this share of the spatial weights the joint weights count as none.
const MIN_WEIGHT: f32 = 1e-3;

fn layer_normal(p: vec2i, j: u32) -> vec3f {
    let n = textureLoad(npack, p, 0);
    return oct_decode(select(n.ba, n.rg, j == 0u));
}

fn low_value(t: vec2i, j: u32) -> vec4f {
    if (j == 0u) {
        return textureLoad(low0, t, 0);
    }
    return textureLoad(low1, t, 0);
}

// Layer j's upsampled value at pixel p, whose layer-j depth is zp > 0.
fn upsampled_layer(p: vec2i, j: u32, zp: f32) -> vec4f {
    let size = textureDimensions(zmip, 0);
    let low = vec2i(textureDimensions(low0));
    let s = i32(up.scale);
    let x = world_from_csz(frame, vec2f(p) + 0.5, zp);
    let n = layer_normal(p, j);
    let home = p / s;
    var sum = vec4f(0.0);
    var weight = 0.0;
    var spatial = 0.0;
    var nearest = vec4f(0.0);
    var nearest_dz = 1e30;
    for (var dy = -1; dy <= 1; dy++) {
        for (var dx = -1; dx <= 1; dx++) {
            let t = home + vec2i(dx, dy);
            if (any(t < vec2i(0)) || any(t >= low)) {
                continue;
            }
            let r = vec2i(block_pixel(vec2u(t), up.scale, up.seed, size));
            let zr = textureLoad(zmip, r, 0)[j];
            if (zr <= 0.0) {
                continue;
            }
            let v = low_value(t, j);
            // screen distance: 1 at the pixel, 0 at 2s pixels
            let d = vec2f(r - p);
            let ws = max(0.0, 1.0 - dot(d, d) / f32(4 * s * s));
            let y = world_from_csz(frame, vec2f(r) + 0.5, zr);
            let plane = max(0.0, 1.0 - up.plane_sharpness * abs(dot(n, y - x)) / zp);
            let c = max(0.0, dot(n, layer_normal(r, j)));
            var normal = 1.0;
            for (var e = 0u; e < up.normal_power; e++) {
                normal *= c;
            }
            let w = ws * plane * normal;
            sum += w * v;
            weight += w;
            spatial += ws;
            let dz = abs(zr - zp);
            if (dz < nearest_dz) {
                nearest_dz = dz;
                nearest = v;
            }
        }
    }
    if (weight > MIN_WEIGHT * spatial && weight > 0.0) {
        return sum / weight;
    }
    return nearest;
}

fn upsampled(p: vec2i) -> Out {
    var o: Out;
    let z = textureLoad(zmip, p, 0);
    if (z.x > 0.0) {
        o.e0 = upsampled_layer(p, 0u, z.x);
    }
    if (LAYERS > 1u && z.y > 0.0) {
        o.e1 = upsampled_layer(p, 1u, z.y);
    }
    return o;
}

@fragment
fn fs_main(@builtin(position) pos: vec4f) -> Out {
    return upsampled(vec2i(pos.xy));
}

// The same pass as compute (`Kernel`), 8×8 pixels per workgroup. Outside the shaded
// rectangle [SCISSOR_X0, SCISSOR_X1) × [SCISSOR_Y0, SCISSOR_Y1) it stores zero, as the
// fragment pass's clear leaves there.
override SCISSOR_X0: u32 = 0u;
override SCISSOR_Y0: u32 = 0u;
override SCISSOR_X1: u32 = 0xffffffffu;
override SCISSOR_Y1: u32 = 0xffffffffu;
@group(1) @binding(5) var e0_out: texture_storage_2d<rgba16float, write>;
@group(1) @binding(6) var e1_out: texture_storage_2d<rgba16float, write>;

@compute @workgroup_size(8, 8)
fn cs_main(@builtin(global_invocation_id) id: vec3u) {
    if (any(id.xy >= textureDimensions(e0_out))) {
        return;
    }
    var o: Out;
    if (all(id.xy >= vec2u(SCISSOR_X0, SCISSOR_Y0)) && all(id.xy < vec2u(SCISSOR_X1, SCISSOR_Y1))) {
        o = upsampled(vec2i(id.xy));
    }
    textureStore(e0_out, id.xy, o.e0);
    textureStore(e1_out, id.xy, o.e1);
}
