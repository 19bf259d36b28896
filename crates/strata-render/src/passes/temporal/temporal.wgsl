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

// Last frame's depth of layer j at the sub-pixel position c: 1/z interpolated
// bilinearly between the four nearest texel centres (exact on planes, so a
// sub-pixel offset does not fail the test on slanted surfaces); the nearest
// texel's depth where any of the four is empty.
fn depth_at(c: vec2f, j: i32) -> f32 {
    let f = c - 0.5;
    let i0 = vec2i(floor(f));
    let t = f - floor(f);
    let last = vec2i(textureDimensions(csz_history)) - 1;
    let z00 = textureLoad(csz_history, clamp(i0, vec2i(0), last), j, 0).r;
    let z10 = textureLoad(csz_history, clamp(i0 + vec2i(1, 0), vec2i(0), last), j, 0).r;
    let z01 = textureLoad(csz_history, clamp(i0 + vec2i(0, 1), vec2i(0), last), j, 0).r;
    let z11 = textureLoad(csz_history, clamp(i0 + vec2i(1, 1), vec2i(0), last), j, 0).r;
    if (min(min(z00, z10), min(z01, z11)) <= 0.0) {
        return textureLoad(csz_history, vec2i(floor(c)), j, 0).r;
    }
    let inv = mix(mix(1.0 / z00, 1.0 / z10, t.x), mix(1.0 / z01, 1.0 / z11, t.x), t.y);
    return 1.0 / inv;
}

// Last frame's filtered value at c, bilinear between texel centres.
fn history_at(c: vec2f) -> vec4f {
    let f = c - 0.5;
    let i0 = vec2i(floor(f));
    let t = f - floor(f);
    let last = vec2i(textureDimensions(history)) - 1;
    let h00 = textureLoad(history, clamp(i0, vec2i(0), last), 0);
    let h10 = textureLoad(history, clamp(i0 + vec2i(1, 0), vec2i(0), last), 0);
    let h01 = textureLoad(history, clamp(i0 + vec2i(0, 1), vec2i(0), last), 0);
    let h11 = textureLoad(history, clamp(i0 + vec2i(1, 1), vec2i(0), last), 0);
    return mix(mix(h00, h10, t.x), mix(h01, h11, t.x), t.y);
}

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
    // accept when the point lies on either layer of last frame (clip.w is its
    // camera-space depth in frame t − 1)
    var ok = false;
    for (var j = 0u; j < min(temporal.layers, 2u); j++) {
        let zj = depth_at(c, i32(j));
        if (zj > 0.0 && abs(zj - clip.w) < temporal.max_distance) {
            ok = true;
        }
    }
    if (!ok) {
        return e;
    }
    let old = history_at(c);
    return mix(e, old, temporal.alpha);
}
