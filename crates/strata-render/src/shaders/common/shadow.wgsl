// Shadow-map lookups of the analytic lights (`lights::GpuLight`), shared by the
// deferred lighting pass and bzb-gi's sender shading (BZB §3.2: the payload is
// the sender's direct light, shadowed as the lighting pass shadows it). The
// importer declares the globals `shadow_maps` (texture_depth_2d_array),
// `shadow_sampler` (sampler_comparison) and `shadow_mats` (storage
// array<mat4x4f>: the view-projection of every shadow-map layer).
#import "common/lights.wgsl"

const NO_SHADOW: u32 = 0xffffffffu;

// The shadow-map layer of light `l` for a surface at p: its own, or for a point
// light the cube face of the major axis of p − light (faces +X, −X, +Y, −Y, +Z, −Z).
fn shadow_layer(l: GpuLight, p: vec3f) -> u32 {
    if (l.kind.x != 1u) {
        return l.kind.y;
    }
    let d = p - l.position.xyz;
    let a = abs(d);
    var face = 4u;
    if (a.x >= a.y && a.x >= a.z) {
        face = 0u;
    } else if (a.y >= a.z) {
        face = 2u;
    }
    if ((face == 0u && d.x < 0.0) || (face == 2u && d.y < 0.0) || (face == 4u && d.z < 0.0)) {
        face += 1u;
    }
    return l.kind.y + face;
}

// Visibility of light `l` at p (normal n, distance `dist` to a local light):
// (2r+1)² bilinear comparisons, r = `pcf_radius`, of a `shadow_size`² map.
fn shadow_visibility_pcf(l: GpuLight, p: vec3f, n: vec3f, dist: f32, pcf_radius: i32, shadow_size: f32) -> f32 {
    if (l.kind.y == NO_SHADOW) {
        return 1.0;
    }
    let layer = shadow_layer(l, p);
    // Normal offset of ~1.5 shadow texels (texel size grows with distance for perspective maps).
    var texel = l.cone.z;
    if (l.kind.x != 0u) {
        texel = texel * dist;
    }
    let q = p + n * texel * 1.5;
    let c = shadow_mats[layer] * vec4f(q, 1.0);
    let ndc = c.xyz / c.w;
    if (c.w <= 0.0 || any(abs(ndc.xy) > vec2f(1.0)) || ndc.z > 1.0) {
        return 1.0;
    }
    let uv = vec2f(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5);
    let r = pcf_radius;
    var sum = 0.0;
    var count = 0.0;
    for (var y = -r; y <= r; y++) {
        for (var x = -r; x <= r; x++) {
            let o = vec2f(f32(x), f32(y)) / shadow_size;
            sum += textureSampleCompareLevel(shadow_maps, shadow_sampler, uv + o, i32(layer), ndc.z);
            count += 1.0;
        }
    }
    return sum / count;
}
