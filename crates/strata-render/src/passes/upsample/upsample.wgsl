// Joint bilateral upsampling (Kopf et al. 2007) of a pass run at 1/s resolution
// (`RadiositySettings::gather_scale`, `AoSettings::scale`; not in DGB): each full-resolution pixel averages
// the 2×2 low-resolution texels whose blocks' centres surround it, each standing at the
// pixel it shaded (`block_pixel`), weighted by screen distance × the bilateral filter's
// plane and normal weights (bilateral.wgsl's, on the pixel's own layer). Where no texel
// holds the pixel's surface (all weights ≈ 0: thin features), the texel whose depth is
// nearest the pixel's stands in. CPU twin: `passes::upsample::upsample_cpu`.
#import "common/fullscreen.wgsl"
#import "common/frame.wgsl"
#import "common/camera.wgsl"
#import "common/packing.wgsl"
#import "common/spiral.wgsl"
#import "common/scissor.wgsl"

override LAYERS: u32 = 2u;

// Matches `upsample::UpsampleUniforms`.
struct Upsample {
    scale: u32,
    seed: u32,
    plane_sharpness: f32,
    normal_power: u32,
    // layer 0's value where it has no surface (0 for E, 1 for AV)
    empty: f32,
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

// One layer's running sums over the texels (`accumulate`).
struct Acc {
    sum: vec4f,
    weight: f32,
    spatial: f32,
    nearest: vec4f,
    nearest_dz: f32,
}

fn new_acc() -> Acc {
    return Acc(vec4f(0.0), 0.0, 0.0, vec4f(0.0), 1e30);
}

// Adds texel value v, which stands at pixel r (depth zr, normal nr on this layer), to
// the sums of the receiver at pixel p (position x, normal n, depth zp).
fn accumulate(acc: ptr<function, Acc>, p: vec2i, x: vec3f, n: vec3f, zp: f32, r: vec2i, zr: f32, nr: vec3f, v: vec4f) {
    if (zr <= 0.0) {
        return;
    }
    // screen distance: 1 at the pixel, above 0.1 anywhere in the 2×2 blocks
    let s = f32(up.scale);
    let d = vec2f(r - p);
    let ws = max(0.0, 1.0 - dot(d, d) / (5.0 * s * s));
    let y = world_from_csz(frame, vec2f(r) + 0.5, zr);
    let plane = max(0.0, 1.0 - up.plane_sharpness * abs(dot(n, y - x)) / zp);
    let c = max(0.0, dot(n, nr));
    var normal = 1.0;
    for (var e = 0u; e < up.normal_power; e++) {
        normal *= c;
    }
    let w = ws * plane * normal;
    (*acc).sum += w * v;
    (*acc).weight += w;
    (*acc).spatial += ws;
    let dz = abs(zr - zp);
    if (dz < (*acc).nearest_dz) {
        (*acc).nearest_dz = dz;
        (*acc).nearest = v;
    }
}

fn resolve(acc: Acc) -> vec4f {
    if (acc.weight > MIN_WEIGHT * acc.spatial && acc.weight > 0.0) {
        return acc.sum / acc.weight;
    }
    return acc.nearest;
}

fn upsampled(p: vec2i) -> Out {
    var o: Out;
    let z = textureLoad(zmip, p, 0);
    if (z.x <= 0.0) {
        o.e0 = vec4f(up.empty);
        return o;
    }
    let has1 = LAYERS > 1u && z.y > 0.0;
    let np = textureLoad(npack, p, 0);
    let x0 = world_from_csz(frame, vec2f(p) + 0.5, z.x);
    let n0 = oct_decode(np.rg);
    var x1 = x0;
    var n1 = n0;
    if (has1) {
        x1 = world_from_csz(frame, vec2f(p) + 0.5, z.y);
        n1 = oct_decode(np.ba);
    }
    let size = textureDimensions(zmip, 0);
    let low = vec2i(textureDimensions(low0));
    let s = i32(up.scale);
    // the texel whose block centre s·t + (s − 1)/2 is the last at or before p, per axis
    // (⌊(2p − s + 1) / 2s⌋, kept positive for the integer division)
    let home = (2 * p + s + 1) / (2 * s) - 1;
    var a0 = new_acc();
    var a1 = new_acc();
    for (var dy = 0; dy <= 1; dy++) {
        for (var dx = 0; dx <= 1; dx++) {
            let t = home + vec2i(dx, dy);
            if (any(t < vec2i(0)) || any(t >= low)) {
                continue;
            }
            let r = vec2i(block_pixel(vec2u(t), up.scale, up.seed, size));
            let zr = textureLoad(zmip, r, 0);
            if (zr.x <= 0.0) {
                continue;
            }
            let nr = textureLoad(npack, r, 0);
            accumulate(&a0, p, x0, n0, z.x, r, zr.x, oct_decode(nr.rg), textureLoad(low0, t, 0));
            if (has1 && zr.y > 0.0) {
                accumulate(&a1, p, x1, n1, z.y, r, zr.y, oct_decode(nr.ba), textureLoad(low1, t, 0));
            }
        }
    }
    o.e0 = resolve(a0);
    if (has1) {
        o.e1 = resolve(a1);
    }
    return o;
}

@fragment
fn fs_main(@builtin(position) pos: vec4f) -> Out {
    return upsampled(vec2i(pos.xy));
}

// Layer 0 only, into one target (AO: `AoSettings::scale`; LAYERS = 1, `low1` = `low0`).
@fragment
fn fs_layer0(@builtin(position) pos: vec4f) -> @location(0) vec4f {
    return upsampled(vec2i(pos.xy)).e0;
}

// The same pass as compute (`Kernel`), 8×8 pixels per workgroup; zero outside the
// shaded rectangle (`in_scissor`).
@group(1) @binding(5) var e0_out: texture_storage_2d<rgba16float, write>;
@group(1) @binding(6) var e1_out: texture_storage_2d<rgba16float, write>;

@compute @workgroup_size(8, 8)
fn cs_main(@builtin(global_invocation_id) id: vec3u) {
    if (any(id.xy >= textureDimensions(e0_out))) {
        return;
    }
    var o: Out;
    if (in_scissor(id.xy)) {
        o = upsampled(vec2i(id.xy));
    }
    textureStore(e0_out, id.xy, o.e0);
    textureStore(e1_out, id.xy, o.e1);
}
