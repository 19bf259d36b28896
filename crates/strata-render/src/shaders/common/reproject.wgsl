// Reverse reprojection into the previous frame (DGB §3.3), shared by the
// temporal filter and the radiosity propagation.
#import "common/frame.wgsl"

struct Reprojected {
    // pixel position in frame t − 1
    c: vec2f,
    // camera-space depth of the point in frame t − 1
    z: f32,
    // false when behind the old camera or outside its image
    valid: bool,
}

// Where world point `x` was seen in the previous frame.
fn reproject(f: Frame, x: vec3f) -> Reprojected {
    var r: Reprojected;
    let clip = f.prev_view_proj * vec4f(x, 1.0);
    r.z = clip.w;
    if (clip.w <= 0.0) {
        r.valid = false;
        return r;
    }
    let ndc = clip.xy / clip.w;
    r.c = vec2f((ndc.x * 0.5 + 0.5) * f.size.x, (0.5 - 0.5 * ndc.y) * f.size.y);
    r.valid = r.c.x >= 0.0 && r.c.y >= 0.0 && r.c.x < f.size.x && r.c.y < f.size.y;
    return r;
}

// Layer j's depth of `csz` (an array of per-layer depths) at sub-pixel
// position c: 1/z interpolated bilinearly between the four nearest texel
// centres (exact on planes); the nearest texel where any of the four is empty.
fn depth_at(csz: texture_2d_array<f32>, c: vec2f, j: i32) -> f32 {
    let f = c - 0.5;
    let i0 = vec2i(floor(f));
    let t = f - floor(f);
    let last = vec2i(textureDimensions(csz)) - 1;
    let z00 = textureLoad(csz, clamp(i0, vec2i(0), last), j, 0).r;
    let z10 = textureLoad(csz, clamp(i0 + vec2i(1, 0), vec2i(0), last), j, 0).r;
    let z01 = textureLoad(csz, clamp(i0 + vec2i(0, 1), vec2i(0), last), j, 0).r;
    let z11 = textureLoad(csz, clamp(i0 + vec2i(1, 1), vec2i(0), last), j, 0).r;
    if (min(min(z00, z10), min(z01, z11)) <= 0.0) {
        return textureLoad(csz, vec2i(floor(c)), j, 0).r;
    }
    let inv = mix(mix(1.0 / z00, 1.0 / z10, t.x), mix(1.0 / z01, 1.0 / z11, t.x), t.y);
    return 1.0 / inv;
}

// `tex` at sub-pixel position c, bilinear between texel centres.
fn bilinear_at(tex: texture_2d<f32>, c: vec2f) -> vec4f {
    let f = c - 0.5;
    let i0 = vec2i(floor(f));
    let t = f - floor(f);
    let last = vec2i(textureDimensions(tex)) - 1;
    let h00 = textureLoad(tex, clamp(i0, vec2i(0), last), 0);
    let h10 = textureLoad(tex, clamp(i0 + vec2i(1, 0), vec2i(0), last), 0);
    let h01 = textureLoad(tex, clamp(i0 + vec2i(0, 1), vec2i(0), last), 0);
    let h11 = textureLoad(tex, clamp(i0 + vec2i(1, 1), vec2i(0), last), 0);
    return mix(mix(h00, h10, t.x), mix(h01, h11, t.x), t.y);
}

// Which layer (0 or 1) of last frame's `csz` holds the reprojected point
// within `max_distance`; -1 when neither does (a failed reprojection).
fn matching_layer(csz: texture_2d_array<f32>, r: Reprojected, layers: u32, max_distance: f32) -> i32 {
    if (!r.valid) {
        return -1;
    }
    for (var j = 0; j < i32(min(layers, 2u)); j++) {
        let zj = depth_at(csz, r.c, j);
        if (zj > 0.0 && abs(zj - r.z) < max_distance) {
            return j;
        }
    }
    return -1;
}
