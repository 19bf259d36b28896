// §3.2's splats in a compute pass (`splat-kernel=compute`): the bounced z-buffer's
// depth test done with 64-bit atomics instead of the rasteriser. Appended after the
// fragment form's shaders (bzb_splat.wgsl and the AO or GI entries), whose
// `splat_rect` and `splat_hit_depth` it calls, so both forms test the same texels
// with the same arithmetic.
//
// One workgroup per instance (triangle t, sub-image s), in the fragment form's
// instance order: it walks the texels of `splat_rect` and, where the texel's ray hits
// T at depth z, keeps the larger of the texel's key and
//   (~bits(z)) << 32 | ~t.
// z ≥ 0, so a smaller z has smaller bits and a larger key; at equal z the smaller t
// wins, as the rasteriser's `Less` test keeps the first-drawn instance. 0 = no hit
// (the buffer is cleared to 0). bzb_splat_resolve.wgsl writes the keys into the
// fragment form's targets (payload or hit index, and depth).

@group(1) @binding(6) var<storage, read_write> splat_keys: array<atomic<u64>>;

const SPLAT_GROUP: u32 = 64u;

var<workgroup> splat_group_rect: vec4f;

@compute @workgroup_size(64)
fn cs_splat(
    @builtin(workgroup_id) wid: vec3u,
    @builtin(num_workgroups) groups: vec3u,
    @builtin(local_invocation_index) lid: u32,
) {
    let ii = wid.y * groups.x + wid.x;
    let tri = ii / bzb.directions;
    if (lid == 0u) {
        var rect = vec4f(0.0);
        if (tri < bzb.triangles) {
            let v = load_triangle(tri);
            rect = splat_rect(v[0], v[1], v[2], ii % bzb.directions);
        }
        splat_group_rect = rect;
    }
    let rect = workgroupUniformLoad(&splat_group_rect);
    let lo = vec2u(rect.xy);
    let extent = vec2u(max(rect.zw - rect.xy, vec2f(0.0)));
    let n = extent.x * extent.y;
    let width = textureDimensions(origins).x;
    let low = u64(~tri);
    for (var i = lid; i < n; i += SPLAT_GROUP) {
        let texel = lo + vec2u(i % extent.x, i / extent.x);
        let z = splat_hit_depth(vec2i(texel), tri);
        if (z >= 0.0) {
            let key = (u64(~bitcast<u32>(z)) << 32u) | low;
            atomicMax(&splat_keys[texel.y * width + texel.x], key);
        }
    }
}
