// §3.2's splats in a compute pass (`splat-kernel=compute`): the bounced z-buffer's
// depth test done with 64-bit atomics instead of the rasteriser. Appended after the
// fragment form's shaders (bzb_splat.wgsl and the AO or GI entries), whose
// `splat_rect` and `splat_hit_depth` it calls, so both forms test the same texels
// with the same arithmetic.
//
// One workgroup of 8×8 invocations per instance (triangle t, sub-image s), numbered in
// the fragment form's instance order: they step over the texels of `splat_rect` in 8×8
// blocks (2D steps, no integer division per texel: llvmpipe scalarises it, and a flat
// index over 64 invocations made the pass 1.7× slower than the rasteriser there) and,
// where the texel's ray hits T at depth z, keep the larger of the texel's key and
//   (~bits(z)) << 32 | ~t.
// z ≥ 0, so a smaller z has smaller bits and a larger key; at equal z the smaller t
// wins, as the rasteriser's `Less` test keeps the first-drawn instance. 0 = no hit
// (the buffer is cleared to 0). bzb_splat_resolve.wgsl writes the keys into the
// fragment form's targets (payload or hit index, and depth).

@group(1) @binding(6) var<storage, read_write> splat_keys: array<atomic<u64>>;

// invocations per workgroup side: 8×8 step over the rectangle together
const SPLAT_SIDE: u32 = 8u;

@compute @workgroup_size(8, 8)
fn cs_splat(
    @builtin(workgroup_id) wid: vec3u,
    @builtin(num_workgroups) groups: vec3u,
    @builtin(local_invocation_id) lid: vec3u,
) {
    let ii = wid.y * groups.x + wid.x;
    let tri = ii / bzb.directions;
    if (tri >= bzb.triangles) {
        return;
    }
    // every invocation finds the same rectangle (no barrier: lanes of a GPU's wave would
    // wait idle for one that computed it, and CPU adapters pay for barriers)
    let v = load_triangle(tri);
    let rect = splat_rect(v[0], v[1], v[2], ii % bzb.directions);
    let hi = vec2u(max(rect.zw, rect.xy));
    let width = textureDimensions(origins).x;
    let low = u64(~tri);
    for (var y = u32(rect.y) + lid.y; y < hi.y; y += SPLAT_SIDE) {
        for (var x = u32(rect.x) + lid.x; x < hi.x; x += SPLAT_SIDE) {
            let z = splat_hit_depth(vec2i(vec2u(x, y)), tri);
            if (z >= 0.0) {
                let key = (u64(~bitcast<u32>(z)) << 32u) | low;
                atomicMax(&splat_keys[y * width + x], key);
            }
        }
    }
}
