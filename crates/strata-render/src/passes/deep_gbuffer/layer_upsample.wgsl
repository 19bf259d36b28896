// A deep-G-buffer layer j ≥ 1 built at a reduced resolution (DGB Fig. 11:
// "the resolution of our second layer") written into the full-resolution
// arrays, so every later pass reads layer j as if it were built at full size.
//
// Each full-resolution pixel p takes one reduced texel whole (no blending: a
// layer holds surfaces, and a mix of two surfaces is neither). The choice keeps
// the layer's definition at p, against this frame's layer j − 1 at p:
// - the texel q = ⌊p / s⌋ that covers p, if its surface lies more than Δz
//   behind layer j − 1 at p;
// - else the nearest such surface among q's 8 neighbours (the layer is the
//   nearest surface beyond the separation), first in row order on ties;
// - else no surface (also where layer j − 1 has none).
// Its depth at p is not the texel's own: that belongs to the texel's centre, up to
// 1.5·s pixels away, and on p's ray it would put the point off its surface (a
// staircase, which AO taps read as occluders). It is where p's ray meets the plane
// through the texel's point with the texel's normal, unless that plane is seen too
// obliquely or breaks the separation (then the texel's depth).
// Rust twins: deep_gbuffer::upsample_pick, deep_gbuffer::upsample_depth.
#import "common/fullscreen.wgsl"
#import "common/camera.wgsl"
#import "common/packing.wgsl"

struct UpsampleParams {
    // minimum separation Δz, scene units
    min_separation: f32,
    // the reduced targets' divisor s
    scale: u32,
    // the camera's near plane: reversed-Z infinite depth is near / z
    near: f32,
    pad0: u32,
}

@group(0) @binding(0) var<uniform> params: UpsampleParams;
@group(0) @binding(1) var reduced_csz: texture_2d<f32>;
@group(0) @binding(2) var reduced_normal: texture_2d<f32>;
@group(0) @binding(3) var reduced_albedo: texture_2d<f32>;
@group(0) @binding(4) var reduced_emission: texture_2d<f32>;
// the reduced motion where the motion target exists (else a stand-in, never stored)
@group(0) @binding(5) var reduced_motion: texture_2d<f32>;
// this frame's layer j − 1 at full resolution
@group(0) @binding(6) var front_csz: texture_2d<f32>;
@group(1) @binding(0) var<uniform> frame: Frame;

// deep_gbuffer::SURFACE_TOLERANCE
const SURFACE_TOLERANCE: f32 = 1e-4;

// Does a surface at depth z lie more than Δz behind the front layer's z_front?
fn is_behind(z: f32, z_front: f32) -> bool {
    return z > 0.0 && z > z_front + params.min_separation + SURFACE_TOLERANCE * z_front;
}

// The reduced texel full-resolution pixel p takes, or (−1, −1) for no surface.
fn pick(p: vec2i) -> vec2i {
    let z_front = textureLoad(front_csz, p, 0).r;
    if (z_front <= 0.0) {
        return vec2i(-1);
    }
    let last = vec2i(textureDimensions(reduced_csz)) - 1;
    let q = min(p / i32(params.scale), last);
    if (is_behind(textureLoad(reduced_csz, q, 0).r, z_front)) {
        return q;
    }
    var best = vec2i(-1);
    var best_z = 0.0;
    for (var dy = -1; dy <= 1; dy++) {
        for (var dx = -1; dx <= 1; dx++) {
            let t = q + vec2i(dx, dy);
            if ((dx == 0 && dy == 0) || any(t < vec2i(0)) || any(t > last)) {
                continue;
            }
            let z = textureLoad(reduced_csz, t, 0).r;
            if (is_behind(z, z_front) && (best.x < 0 || z < best_z)) {
                best = t;
                best_z = z;
            }
        }
    }
    return best;
}

// Largest relative change of a texel's depth the plane may make (beyond: seen too obliquely).
const MAX_PLANE_CHANGE: f32 = 0.25;

// Camera-space depth at full-resolution pixel position `p` of the plane through reduced
// texel t's surface point (depth z_t at its centre) with world normal n.
fn plane_depth(t: vec2i, z_t: f32, n: vec3f, p: vec2f, z_front: f32) -> f32 {
    let d_t = pixel_dir(frame, (vec2f(t) + 0.5) * f32(params.scale));
    let d_p = pixel_dir(frame, p);
    let z = z_t * dot(n, d_t) / dot(n, d_p);
    // (NaN, infinite or negative depths fail the first test)
    if (!(abs(z - z_t) <= MAX_PLANE_CHANGE * z_t) || !is_behind(z, z_front)) {
        return z_t;
    }
    return z;
}

struct LayerOut {
    @location(0) csz: f32,
    @location(1) normal: vec4f,
    @location(2) albedo: vec4f,
    @location(3) emission: vec4f,
    @location(4) motion: vec4f,
    @builtin(frag_depth) depth: f32,
}

@fragment
fn fs_upsample(@builtin(position) pos: vec4f) -> LayerOut {
    let p = vec2i(floor(pos.xy));
    let t = pick(p);
    // no surface: the values a geometry pass clears to
    var o: LayerOut;
    o.depth = 0.0;
    if (t.x < 0) {
        return o;
    }
    o.normal = textureLoad(reduced_normal, t, 0);
    let z_front = textureLoad(front_csz, p, 0).r;
    o.csz = plane_depth(t, textureLoad(reduced_csz, t, 0).r, oct_decode(o.normal.xy), pos.xy, z_front);
    o.albedo = textureLoad(reduced_albedo, t, 0);
    o.emission = textureLoad(reduced_emission, t, 0);
    o.motion = textureLoad(reduced_motion, t, 0);
    // the hardware depth of the same point (Camera::projection), without a depth-texture read
    o.depth = params.near / o.csz;
    return o;
}
