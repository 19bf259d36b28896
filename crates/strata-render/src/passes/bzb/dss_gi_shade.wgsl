// bzb-gi with DSS surfels (BZB §4.3: "surfels shaded with direct light (shadow
// map)"): after dss-filter, one thread per surfel computes its outgoing
// radiance with the shared sender shading of bzb_gi_sender.wgsl (direct light
// of every analytic light, shadow-mapped as the lighting pass does, × ρ/π or
// f_GGX towards the surfel's normal, + emission when no Rect light carries it)
// at the surfel's centre on its source triangle (surfel normal .w). Both faces
// (surfaces are two-sided): radiance[2j] towards +n (emission included),
// radiance[2j + 1] towards −n. The splat takes the face towards the receiver.

@group(1) @binding(0) var<uniform> gi: BzbGi;
@group(1) @binding(1) var<storage, read> triangles: array<vec4f>;
@group(1) @binding(2) var<storage, read> gi_tris: array<vec4f>;
@group(1) @binding(3) var<storage, read> lights: array<GpuLight>;
@group(1) @binding(4) var shadow_maps: texture_depth_2d_array;
@group(1) @binding(5) var shadow_sampler: sampler_comparison;
@group(1) @binding(6) var<storage, read> shadow_mats: array<mat4x4f>;
@group(1) @binding(7) var<storage, read> surfels: array<vec4f>;
// dss counters: [sub-triangles, fine surfels, surfels, triangles after culling]
@group(1) @binding(8) var<storage, read> counters: array<u32>;
@group(1) @binding(9) var<storage, read_write> radiance: array<vec4f>;
@group(1) @binding(10) var<storage, read> sender_texels: array<u32>;

@compute @workgroup_size(64)
fn cs_main(@builtin(global_invocation_id) id: vec3u) {
    let j = id.x;
    if (j >= min(counters[2], arrayLength(&radiance) / 2u)) {
        return;
    }
    let y = surfels[2u * j].xyz;
    let nw = surfels[2u * j + 1u];
    let tri = u32(nw.w + 0.5);
    let v = gi_triangle(tri);
    let bary = gi_barycentrics(y, v[0], v[1], v[2]);
    radiance[2u * j] = vec4f(bzb_gi_clamp(gi_sender(tri, y, bary, nw.xyz), gi.clamp), 1.0);
    radiance[2u * j + 1u] = vec4f(bzb_gi_clamp(gi_sender(tri, y, bary, -nw.xyz), gi.clamp), 1.0);
}
