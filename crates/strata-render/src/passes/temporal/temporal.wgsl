// DGB §3.3 temporal filter: E_t = (1 − α)·E + α·reproject(E_{t−1}), falling
// back to E_t = E where the reprojected point is not within `max_distance` of
// either layer of last frame's deep G-buffer (a failed reprojection).
#import "common/fullscreen.wgsl"
#import "common/frame.wgsl"
#import "common/camera.wgsl"

// Matches `temporal::TemporalUniforms`.
struct Temporal {
    alpha: f32,
    max_distance: f32,
    // 0 before the first frame (or after a cut): no history
    has_history: u32,
    // layers in csz-history
    layers: u32,
}

@group(0) @binding(0) var<uniform> frame: Frame;
@group(1) @binding(0) var<uniform> temporal: Temporal;
@group(1) @binding(1) var current: texture_2d<f32>;
@group(1) @binding(2) var history: texture_2d<f32>;
@group(1) @binding(3) var zpack: texture_2d<f32>;
@group(1) @binding(4) var csz_history: texture_2d_array<f32>;

@fragment
fn fs_main(@builtin(position) pos: vec4f) -> @location(0) vec4f {
    let p = vec2i(pos.xy);
    let e = textureLoad(current, p, 0);
    let z = textureLoad(zpack, p, 0).r;
    if (temporal.has_history == 0u || z <= 0.0) {
        return e;
    }
    // reverse reprojection of X = layer 0's surface into frame t − 1
    let x = world_from_csz(frame, vec2f(p) + 0.5, z);
    let clip = frame.prev_view_proj * vec4f(x, 1.0);
    if (clip.w <= 0.0) {
        return e;
    }
    let ndc = clip.xy / clip.w;
    let c = vec2f((ndc.x * 0.5 + 0.5) * frame.size.x, (0.5 - 0.5 * ndc.y) * frame.size.y);
    if (c.x < 0.0 || c.y < 0.0 || c.x >= frame.size.x || c.y >= frame.size.y) {
        return e;
    }
    let ci = vec2i(floor(c));
    // accept when the point lies on either layer of last frame (clip.w is its
    // camera-space depth in frame t − 1)
    var ok = false;
    for (var j = 0u; j < min(temporal.layers, 2u); j++) {
        let zj = textureLoad(csz_history, ci, i32(j), 0).r;
        if (zj > 0.0 && abs(zj - clip.w) < temporal.max_distance) {
            ok = true;
        }
    }
    if (!ok) {
        return e;
    }
    let old = textureLoad(history, ci, 0);
    return mix(e, old, temporal.alpha);
}
