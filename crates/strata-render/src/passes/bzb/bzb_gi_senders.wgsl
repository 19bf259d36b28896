// bzb-gi baseline (visibility off): each triangle's mean outgoing radiance L̄_T,
// the constant radiance a classic splat carries (DSS shades its surfels once at
// surfelization): the mean of gi_sender over an 8 × 8 stratified set of points
// of the triangle (uniform by area), towards the triangle's own normal.
// One thread per triangle.

@group(0) @binding(0) var<uniform> gi: BzbGi;
@group(0) @binding(1) var<storage, read> triangles: array<vec4f>;
@group(0) @binding(2) var<storage, read> gi_tris: array<vec4f>;
@group(0) @binding(3) var<storage, read> lights: array<GpuLight>;
@group(0) @binding(4) var shadow_maps: texture_depth_2d_array;
@group(0) @binding(5) var shadow_sampler: sampler_comparison;
@group(0) @binding(6) var<storage, read> shadow_mats: array<mat4x4f>;
@group(0) @binding(7) var<storage, read_write> mean_radiance: array<vec4f>;
@group(0) @binding(8) var<storage, read> sender_texels: array<u32>;

const GI_SENDER_GRID: u32 = 8u;

@compute @workgroup_size(64)
fn cs_main(@builtin(global_invocation_id) id: vec3u) {
    let tri = id.x;
    if (tri >= arrayLength(&mean_radiance)) {
        return;
    }
    let v = gi_triangle(tri);
    let c = cross(v[1] - v[0], v[2] - v[0]);
    let len = length(c);
    if (!(len > 0.0)) {
        mean_radiance[tri] = vec4f(0.0);
        return;
    }
    let ng = c / len;
    var sum = vec3f(0.0);
    for (var i = 0u; i < GI_SENDER_GRID; i++) {
        for (var j = 0u; j < GI_SENDER_GRID; j++) {
            let u = (vec2f(f32(i), f32(j)) + 0.5) / f32(GI_SENDER_GRID);
            let su = sqrt(u.x);
            let bary = vec2f(u.y * su, 1.0 - su);
            let y = v[0] + bary.x * (v[1] - v[0]) + bary.y * (v[2] - v[0]);
            sum += bzb_gi_clamp(gi_sender(tri, y, bary, ng), gi.clamp);
        }
    }
    mean_radiance[tri] = vec4f(sum / f32(GI_SENDER_GRID * GI_SENDER_GRID), 1.0);
}
