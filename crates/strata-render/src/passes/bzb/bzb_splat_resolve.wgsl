// §3.2, the compute form's last step (`splat-kernel=compute`): per texel of the
// bounced z-buffer, bzb_splat_compute.wgsl's key (0 = no hit) into the fragment form's
// targets: the depth z = bits⁻¹(~key.hi) through frag_depth (depth test Always) and the
// payload, 1 for AO or the hit triangle + 1 for GI (`HIT_INDEX`). Texels without a
// hit keep the clear values (payload 0, depth 1), as in the fragment form.
#import "common/fullscreen.wgsl"

override HIT_INDEX: bool = false;

// the keys as (low, high) words
@group(0) @binding(0) var<storage, read> splat_keys: array<vec2u>;
@group(0) @binding(1) var origins: texture_2d<f32>;

struct ResolveOut {
    @location(0) payload: vec4f,
    @builtin(frag_depth) depth: f32,
}

@fragment
fn fs_resolve(@builtin(position) pos: vec4f) -> ResolveOut {
    let p = vec2u(pos.xy);
    let key = splat_keys[p.y * textureDimensions(origins).x + p.x];
    if (key.y == 0u) {
        discard;
    }
    var out: ResolveOut;
    out.depth = bitcast<f32>(~key.y);
    // exact in f32 below 2^24 triangles
    out.payload = select(vec4f(1.0), vec4f(f32(~key.x + 1u)), HIT_INDEX);
    return out;
}
