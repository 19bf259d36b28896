// Deep G-buffer with minimum separation (DGB §2). One shader serves the
// two-pass depth peel (Listing 1: one pipeline per layer, the oracle is this
// frame's previous layer) and the single-pass variants (Listing 2: one
// multiview pass, view j = layer j, plus a depth-only predicted layer for
// DELAY/PREDICT, the oracle is last frame's buffers).
#import "common/camera.wgsl"
#import "common/packing.wgsl"
#import "common/scene.wgsl"

// Oracle kinds (deep_gbuffer::Variant::oracle()).
const ORACLE_NONE: u32 = 0u;
const ORACLE_PEEL: u32 = 1u;
const ORACLE_DELAY: u32 = 2u;
const ORACLE_PREVIOUS: u32 = 3u;
const ORACLE_PREDICT: u32 = 4u;
const ORACLE_REPROJECT: u32 = 5u;

override ORACLE: u32 = 0u;
// Layer written by view 0 (the peel renders layer j in its own pass).
override LAYER_BASE: u32 = 0u;
// G-buffer layers written by this pipeline's views; view LAYERS (DELAY/PREDICT
// only) is the depth-only layer 0 of frame t + 1.
override LAYERS: u32 = 1u;

struct DeepParams {
    // minimum separation Δz, scene units
    min_separation: f32,
    // 0 on a single-pass variant's first frame: no oracle yet, accept every fragment
    has_history: u32,
    // full-resolution pixels per pixel of this pass's targets (> 1: a reduced layer,
    // DeepGBufferSettings::layer_scale)
    scale: f32,
    pad0: u32,
}

@group(0) @binding(0) var<uniform> frame: Frame;
@group(1) @binding(0) var<uniform> object: ObjectUniforms;
@group(2) @binding(0) var<uniform> material: MaterialUniforms;
@group(2) @binding(1) var base_tex: texture_2d<f32>;
@group(2) @binding(2) var base_sampler: sampler;
@group(3) @binding(0) var<uniform> deep: DeepParams;
// Peel: this frame's layer LAYER_BASE − 1 (one layer). Single pass: last
// frame's camera-space depth of every layer (+ the predicted layer).
@group(3) @binding(1) var oracle_csz: texture_2d_array<f32>;

struct VsOut {
    @builtin(position) clip: vec4f,
    @location(0) normal: vec3f,
    @location(1) uv: vec2f,
    // camera-space depth in this view's camera (clip w of the reversed-Z projection)
    @location(2) cam_z: f32,
    // REPROJECT: the vertex at t − 1 in t − 1's clip space (reverse reprojection)
    @location(3) prev_clip: vec4f,
    // the vertex's world-space motion since t − 1, model·p − prev_model·p (0 when static)
    @location(4) motion: vec3f,
}

fn is_predicted_view(view: u32) -> bool {
    return (ORACLE == ORACLE_DELAY || ORACLE == ORACLE_PREDICT) && view == LAYERS;
}

fn vertex(view: u32, position: vec3f, normal: vec3f, uv: vec2f) -> VsOut {
    let p = vec4f(position, 1.0);
    var o: VsOut;
    if (is_predicted_view(view)) {
        // Listing 2 line 6: emit T_{t+1}(tri) to the oracle layer.
        o.clip = frame.next_view_proj * (object.next_model * p);
    } else {
        o.clip = frame.view_proj * (object.model * p);
    }
    o.cam_z = o.clip.w;
    // exact across the triangle: both transforms are affine, and world-space varyings
    // interpolate perspective-correctly
    o.motion = (object.model * p - object.prev_model * p).xyz;
    o.normal = (object.normal_matrix * vec4f(normal, 0.0)).xyz;
    o.uv = uv;
    if (ORACLE == ORACLE_REPROJECT) {
        o.prev_clip = frame.prev_view_proj * (object.prev_model * p);
    } else {
        o.prev_clip = vec4f(0.0);
    }
    return o;
}

@vertex
fn vs_multiview(
    @builtin(view_index) view: u32,
    @location(0) position: vec3f,
    @location(1) normal: vec3f,
    @location(2) uv: vec2f,
) -> VsOut {
    return vertex(view, position, normal, uv);
}

// The depth-only layer of frame t + 1 as its own submission (DELAY/PREDICT
// where per-view positions in one multiview pass are unreliable, see mod.rs).
@vertex
fn vs_oracle(@location(0) position: vec3f, @location(1) normal: vec3f, @location(2) uv: vec2f) -> VsOut {
    return vertex(LAYERS, position, normal, uv);
}

@vertex
fn vs_single(@location(0) position: vec3f, @location(1) normal: vec3f, @location(2) uv: vec2f) -> VsOut {
    return vertex(0u, position, normal, uv);
}

// Relative depth within which a fragment counts as the oracle's surface (Rust
// twin: deep_gbuffer::SURFACE_TOLERANCE).
const SURFACE_TOLERANCE: f32 = 1e-4;

// Index of the oracle layer that layer `layer` is tested against.
fn oracle_layer(layer: u32) -> i32 {
    switch (ORACLE) {
        case ORACLE_PEEL: { return 0; }
        case ORACLE_DELAY, ORACLE_PREDICT: { return i32(LAYERS); }
        default: { return i32(layer) - 1; }
    }
}

// Listing 1 line 13 / Listing 2 lines 13–23: keep a fragment of layer ≥ 1 only
// if it lies more than Δz behind the oracle's surface at the comparison texel C.
// No oracle (first frame, C off screen or behind the old camera) accepts the
// fragment; an oracle texel without a surface rejects it (infinitely far).
fn passes_min_separation(in: VsOut, layer: u32) -> bool {
    if (layer == 0u || ORACLE == ORACLE_NONE) {
        return true;
    }
    if (ORACLE != ORACLE_PEEL && deep.has_history == 0u) {
        return true;
    }
    // the fragment's position in the oracle's full-resolution pixels
    var c = in.clip.xy * deep.scale;
    var z = in.cam_z;
    if (ORACLE == ORACLE_REPROJECT) {
        // C = (x_{t−1}, y_{t−1}, z_{t−1}): where this point was last frame.
        if (in.prev_clip.w <= 0.0) {
            return true;
        }
        let ndc = in.prev_clip.xy / in.prev_clip.w;
        c = vec2f((ndc.x * 0.5 + 0.5) * frame.size.x, (0.5 - 0.5 * ndc.y) * frame.size.y);
        z = in.prev_clip.w;
    }
    if (deep.scale > 1.0) {
        // A reduced pixel's centre lies on a corner of four full-resolution pixels at even
        // scales; a quarter pixel up-left picks one of them for every fragment, where the
        // rounding of the reprojected position would flip between two from row to row (at
        // odd scales it stays in the centre's own pixel). Kept on screen at the left and
        // top edges.
        c = max(c - vec2f(0.25), vec2f(0.0));
    }
    if (c.x < 0.0 || c.y < 0.0 || c.x >= frame.size.x || c.y >= frame.size.y) {
        return true;
    }
    let zc = textureLoad(oracle_csz, vec2i(floor(c)), oracle_layer(layer), 0).r;
    // An empty oracle texel is infinitely far: nothing lies beyond it. Within
    // SURFACE_TOLERANCE·zc of the oracle is the oracle's own surface: without
    // it, Δz = 0 re-captures that surface wherever this pass interpolates its
    // depth slightly beyond the stored one.
    return zc > 0.0 && z > zc + deep.min_separation + SURFACE_TOLERANCE * zc;
}

struct GBufferOut {
    // camera-space depth (0 = no surface)
    @location(0) csz: f32,
    // rg = Oct16 world normal, b = roughness, a = metallic
    @location(1) normal: vec4f,
    // rgb = albedo (sRGB target), a = opacity
    @location(2) albedo: vec4f,
    // rgb = emitted radiance, a = 1 (2: glossy material)
    @location(3) emission: vec4f,
    // rgb = world-space motion of the surface point since frame t − 1 (per-object
    // velocities for the temporal filters' reverse reprojection, DGB §3.3)
    @location(4) motion: vec4f,
}

// The shading function S of Listings 1–2: material properties. Double-sided:
// back faces get their normal flipped toward the viewer.
fn shade(in: VsOut, front: bool) -> GBufferOut {
    var base = material.base_color;
    var tex = vec4f(1.0);
    if (material.params.z > 0.5) {
        tex = textureSample(base_tex, base_sampler, in.uv);
        base = base * tex;
    }
    // MASK cut-outs only: the deep G-buffer holds surfaces, and a blended
    // (transparent) surface is a surface here as in the CPU reference
    if (fragment_alpha(material, tex) < 0.0) {
        discard;
    }
    var n = normalize(in.normal);
    if (!front) {
        n = -n;
    }
    var o: GBufferOut;
    o.csz = in.cam_z;
    o.normal = vec4f(oct_encode(n), material.params.x, material.params.y);
    o.albedo = vec4f(base.rgb, base.a);
    // a = 1, or 2 for a glossy material (ILS shades those with GGX)
    o.emission = vec4f(material.emission.rgb, 1.0 + material.flags.x);
    o.motion = vec4f(in.motion, 0.0);
    return o;
}

@fragment
fn fs_multiview(in: VsOut, @builtin(view_index) view: u32, @builtin(front_facing) front: bool) -> GBufferOut {
    if (is_predicted_view(view)) {
        // Listing 2 lines 25–26: depth only (csz kept for next frame's oracle).
        var o: GBufferOut;
        o.csz = in.cam_z;
        return o;
    }
    // Test first, shade only survivors (discard demotes to a helper invocation,
    // so the texture fetch in `shade` keeps its derivatives).
    if (!passes_min_separation(in, view)) {
        discard;
    }
    return shade(in, front);
}

@fragment
fn fs_oracle(in: VsOut) -> GBufferOut {
    var o: GBufferOut;
    o.csz = in.cam_z;
    return o;
}

@fragment
fn fs_single(in: VsOut, @builtin(front_facing) front: bool) -> GBufferOut {
    if (!passes_min_separation(in, LAYER_BASE)) {
        discard;
    }
    return shade(in, front);
}
