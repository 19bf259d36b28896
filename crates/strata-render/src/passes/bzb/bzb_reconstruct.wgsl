// BZB §3.3 reconstruction for AO, weighting step: per pixel, the mean over its S
// directions of occlusion · (cos θ / π) / α (binary AO with the cosine-weighted
// measure; = the payload itself for cosine-weighted ω), or for the additive
// baseline the mean of the summed AOV occlusion. Output: ambient visibility
// 1 − AO in [0, 1]. The cross-bilateral filtering step follows (bilateral passes).
#import "common/fullscreen.wgsl"
#import "common/packing.wgsl"

@group(0) @binding(0) var<uniform> frame: Frame;
@group(1) @binding(0) var<uniform> bzb: Bzb;
@group(1) @binding(1) var payload: texture_2d<f32>;
@group(1) @binding(2) var directions: texture_2d<f32>;
@group(1) @binding(3) var zpack: texture_2d<f32>;
@group(1) @binding(4) var npack: texture_2d<f32>;

@fragment
fn fs_main(@builtin(position) pos: vec4f) -> @location(0) vec4f {
    let p = vec2u(pos.xy);
    if (textureLoad(zpack, vec2i(p), 0).r <= 0.0) {
        return vec4f(1.0);
    }
    let n = oct_decode(textureLoad(npack, vec2i(p), 0).rg);
    let size = vec2u(frame.size.xy);
    var occlusion = 0.0;
    var count = 0.0;
    for (var s = 0u; s < bzb.directions; s++) {
        let texel = vec2i(bzb_tile_origin(s, bzb.cols, size) + p);
        let d = textureLoad(directions, texel, 0);
        if (d.w <= 0.0) {
            continue;
        }
        let o = textureLoad(payload, texel, 0).r;
        if (bzb.visibility != 0u) {
            occlusion += o * max(0.0, dot(n, d.xyz)) / (BZB_PI * d.w);
        } else {
            occlusion += o;
        }
        count += 1.0;
    }
    let ao = select(0.0, occlusion / count, count > 0.0);
    return vec4f(clamp(1.0 - ao, 0.0, 1.0));
}
