// DGB §3.3 temporal filter: E_t = (1 − α)·E + α·reproject(E_{t−1}), falling
// back to E_t = E where the reprojected point is not within `max_distance` of
// either layer of last frame's deep G-buffer (a failed reprojection).
#import "common/fullscreen.wgsl"
#import "common/frame.wgsl"
#import "common/camera.wgsl"
#import "common/reproject.wgsl"

// Matches `temporal::TemporalUniforms`.
struct Temporal {
    alpha: f32,
    max_distance: f32,
    // layers in csz-history
    layers: u32,
    // 1 = clamp the history to the current input's 3×3 range
    clamp_history: u32,
    // 0 before the first frame (or after a cut): no history
    has_history: u32,
    // 1 = the start-up ramp: the history's weight is min(α, n/(n + 1)) where it has
    // been accepted n frames in a row (`TemporalSettings::history_weight`)
    ramp: u32,
    // 1 = per-object velocities: move the point back by `motion` before reprojecting
    motion: u32,
    pad: u32,
}

struct Out {
    @location(0) e: vec4f,
    // how many frames in a row this pixel's history has been accepted (capped)
    @location(1) frames: vec4f,
}

// The count's cap: far beyond where the ramp reaches α (fits f16 exactly).
const MAX_FRAMES: f32 = 1024.0;

@group(0) @binding(0) var<uniform> frame: Frame;
@group(1) @binding(0) var<uniform> temporal: Temporal;
@group(1) @binding(1) var current: texture_2d<f32>;
@group(1) @binding(2) var history: texture_2d<f32>;
@group(1) @binding(3) var zpack: texture_2d<f32>;
@group(1) @binding(4) var csz_history: texture_2d_array<f32>;
// last frame's per-pixel count (`frames` output)
@group(1) @binding(5) var frames_history: texture_2d<f32>;
// layer 0's world-space motion since last frame (the deep G-buffer's `motion`)
@group(1) @binding(6) var motion: texture_2d<f32>;

// The filtered estimate and count at pixel p.
fn filtered(p: vec2i) -> Out {
    let e = textureLoad(current, p, 0);
    var o = Out(e, vec4f(0.0));
    let z = textureLoad(zpack, p, 0).r;
    if (temporal.has_history == 0u || z <= 0.0) {
        return o;
    }
    // reverse reprojection of X = layer 0's surface into frame t − 1 (where its object
    // held it then, with per-object motion); accept when it lies on either layer of last
    // frame
    var x = world_from_csz(frame, vec2f(p) + 0.5, z);
    if (temporal.motion != 0u) {
        x -= textureLoad(motion, p, 0).xyz;
    }
    let r = reproject(frame, x);
    if (matching_layer(csz_history, r, temporal.layers, temporal.max_distance) < 0) {
        return o;
    }
    // the count at the reprojected point's nearest pixel, plus this frame
    let last = vec2i(textureDimensions(frames_history)) - 1;
    let n = min(textureLoad(frames_history, clamp(vec2i(floor(r.c)), vec2i(0), last), 0).r + 1.0, MAX_FRAMES);
    o.frames = vec4f(n, 0.0, 0.0, 0.0);
    var alpha = temporal.alpha;
    if (temporal.ramp != 0u) {
        alpha = min(alpha, n / (n + 1.0));
    }
    var h = bilinear_at(history, r.c);
    if (temporal.clamp_history != 0u) {
        // the range this frame's estimate spans around p (per channel)
        let size = vec2i(textureDimensions(current, 0));
        var lo = e;
        var hi = e;
        for (var dy = -1; dy <= 1; dy++) {
            for (var dx = -1; dx <= 1; dx++) {
                let q = clamp(p + vec2i(dx, dy), vec2i(0), size - 1);
                let c = textureLoad(current, q, 0);
                lo = min(lo, c);
                hi = max(hi, c);
            }
        }
        h = clamp(h, lo, hi);
    }
    o.e = mix(e, h, alpha);
    return o;
}

@fragment
fn fs_main(@builtin(position) pos: vec4f) -> Out {
    return filtered(vec2i(pos.xy));
}

// The same pass as compute (`Kernel`), 8×8 pixels per workgroup.
@group(1) @binding(7) var e_out: texture_storage_2d<STORAGE_FORMAT_0, write>;
@group(1) @binding(8) var frames_out: texture_storage_2d<STORAGE_FORMAT_1, write>;

@compute @workgroup_size(8, 8)
fn cs_main(@builtin(global_invocation_id) id: vec3u) {
    if (any(id.xy >= textureDimensions(e_out))) {
        return;
    }
    let o = filtered(vec2i(id.xy));
    textureStore(e_out, id.xy, o.e);
    textureStore(frames_out, id.xy, o.frames);
}
