// DGB §3.1 deep-G-buffer ambient visibility, Eq. 1–2, sampled with §3.4's
// spiral (taps shared by all layers, per-tap MIP level).
#import "common/fullscreen.wgsl"
#import "common/frame.wgsl"
#import "common/camera.wgsl"
#import "common/packing.wgsl"
#import "common/spiral.wgsl"
#import "common/obscurance.wgsl"

override LAYERS: u32 = 2u;
// > 1: the pass runs at 1/SCALE resolution, texel t shading one pixel of its SCALE×SCALE
// block (`block_pixel`); `upsample/upsample.wgsl` brings it back (`AoSettings::scale`)
override SCALE: u32 = 1u;

#import "ao/uniforms.wgsl"

@group(0) @binding(0) var<uniform> frame: Frame;
@group(1) @binding(0) var<uniform> ao: Ao;
@group(1) @binding(1) var zmip: texture_2d<f32>;
@group(1) @binding(2) var npack: texture_2d<f32>;

// DGB Eq. 2 with this pass's r, β, ε.
fn obscurance(v: vec3f, n: vec3f) -> f32 {
    return eq2_obscurance(v, n, ao.radius, ao.bias, ao.epsilon);
}

// AV (or S with `output_obscurance`) at pixel p.
fn ambient(p: vec2i) -> vec4f {
    let z = textureLoad(zmip, p, 0).r;
    if (z <= 0.0) {
        // no surface: unoccluded (AV 1, S 0)
        return vec4f(f32(ao.output_obscurance == 0u));
    }
    let x = world_from_csz(frame, vec2f(p) + 0.5, z);
    let n = oct_decode(textureLoad(npack, p, 0).rg);
    // screen-space radius r_p of the world-space radius r at depth z
    let r_p = ao.proj_scale * ao.radius / z;
    var phi = 0.0;
    if (ao.rotate != 0u) {
        phi = pixel_angle(vec2u(p), ao.seed);
    }
    let size = vec2i(textureDimensions(zmip, 0));
    var sum = 0.0;
    for (var i = 0u; i < ao.samples; i++) {
        let tap = spiral_tap(i, ao.samples, ao.tau, r_p, phi);
        let q = p + tap_texel(tap.offset);
        if (any(q < vec2i(0)) || any(q >= size)) {
            // outside the (guard-banded) buffer: no occluder known
            continue;
        }
        let m = spiral_mip(tap.radius, ao.q, ao.max_mip);
        let t = mip_texel(zmip, q, m);
        let zs = textureLoad(zmip, t, i32(m));
        // the full-resolution pixel whose depth the MIP texel holds
        let src = mip_source_pixel(zmip, t, m);
        // Eq. 1: max over layers j of A_i^j = O(X, R(Z[j], i))
        var a = 0.0;
        for (var j = 0u; j < LAYERS; j++) {
            if (zs[j] > 0.0) {
                let y = world_from_csz(frame, vec2f(src) + 0.5, zs[j]);
                a = max(a, obscurance(y - x, n));
            }
        }
        sum += a;
    }
    let s = ao.intensity * 3.14159265358979 / f32(ao.samples) * sum;
    if (ao.output_obscurance != 0u) {
        return vec4f(s);
    }
    let av = max(0.0, 1.0 - sqrt(s));
    return vec4f(av);
}

// The pixel that output texel t shades (itself at full resolution).
fn receiver_pixel(t: vec2u) -> vec2i {
    return vec2i(block_pixel(t, SCALE, ao.seed, textureDimensions(zmip, 0)));
}

@fragment
fn fs_main(@builtin(position) pos: vec4f) -> @location(0) vec4f {
    return ambient(receiver_pixel(vec2u(pos.xy)));
}

// The same pass as compute (`AoSettings::kernel`), 8×8 pixels per workgroup.
@group(1) @binding(3) var ao_out: texture_storage_2d<r32float, write>;

@compute @workgroup_size(8, 8)
fn cs_main(@builtin(global_invocation_id) id: vec3u) {
    if (any(id.xy >= textureDimensions(ao_out))) {
        return;
    }
    textureStore(ao_out, id.xy, ambient(receiver_pixel(id.xy)));
}
