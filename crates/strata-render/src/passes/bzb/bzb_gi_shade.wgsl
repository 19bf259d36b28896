// bzb-gi §3.2 payload, deferred: per texel of the bounced z-buffer whose ray
// hit a sender (bzb-gi-hit = triangle + 1), the sender's outgoing radiance
// L(y → x_p) at the hit y (bzb_gi_sender.wgsl) into bzb-gi-payload.
#import "common/fullscreen.wgsl"

@group(0) @binding(0) var<uniform> frame: Frame;
@group(1) @binding(0) var<uniform> gi: BzbGi;
@group(1) @binding(1) var origins: texture_2d<f32>;
@group(1) @binding(2) var directions: texture_2d<f32>;
@group(1) @binding(3) var hits: texture_2d<f32>;
@group(1) @binding(4) var<storage, read> triangles: array<vec4f>;
@group(1) @binding(5) var<storage, read> gi_tris: array<vec4f>;
@group(1) @binding(6) var<storage, read> lights: array<GpuLight>;
@group(1) @binding(7) var shadow_maps: texture_depth_2d_array;
@group(1) @binding(8) var shadow_sampler: sampler_comparison;
@group(1) @binding(9) var<storage, read> shadow_mats: array<mat4x4f>;
@group(1) @binding(10) var<storage, read> sender_texels: array<u32>;

@fragment
fn fs_main(@builtin(position) pos: vec4f) -> @location(0) vec4f {
    let texel = vec2i(pos.xy);
    let id = u32(textureLoad(hits, texel, 0).r + 0.5);
    if (id == 0u) {
        return vec4f(0.0);
    }
    let tri = id - 1u;
    let o = textureLoad(origins, texel, 0).xyz;
    let d = textureLoad(directions, texel, 0).xyz;
    let v = gi_triangle(tri);
    let t = bzb_ray_triangle(o, d, v[0], v[1], v[2]);
    let y = o + max(t, 0.0) * d;
    return vec4f(bzb_gi_clamp(gi_sender(tri, y, gi_barycentrics(y, v[0], v[1], v[2]), -d), gi.clamp), 1.0);
}
