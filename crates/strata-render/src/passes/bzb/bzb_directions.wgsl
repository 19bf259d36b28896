// BZB §3.1 direction setup: for every texel of the bounced z-buffer (sub-image s,
// pixel p) the ray origin x_p from layer 0 of the deep G-buffer and a direction
// ω on the hemisphere around n_p with its pdf α (stored for §3.3's weighting).
#import "common/fullscreen.wgsl"
#import "common/camera.wgsl"
#import "common/packing.wgsl"

@group(0) @binding(0) var<uniform> frame: Frame;
@group(1) @binding(0) var<uniform> bzb: Bzb;
@group(1) @binding(1) var zpack: texture_2d<f32>;
@group(1) @binding(2) var npack: texture_2d<f32>;

struct DirectionsOut {
    // xyz = x_p, w = 1 (0: no sample)
    @location(0) origin: vec4f,
    // xyz = ω, w = α (0: no sample)
    @location(1) direction: vec4f,
}

@fragment
fn fs_main(@builtin(position) pos: vec4f) -> DirectionsOut {
    var o: DirectionsOut;
    let size = vec2u(frame.size.xy);
    let texel = vec2u(pos.xy);
    let tile = texel / size;
    let s = tile.y * bzb.cols + tile.x;
    let p = texel % size;
    if (s >= bzb.directions) {
        return o;
    }
    let z = textureLoad(zpack, vec2i(p), 0).r;
    if (z <= 0.0) {
        return o;
    }
    let n = oct_decode(textureLoad(npack, vec2i(p), 0).rg);
    o.origin = vec4f(world_from_csz(frame, vec2f(p) + 0.5, z), 1.0);
    o.direction = bzb_direction(n, bzb_sample_uniforms(p, s, bzb.seed), bzb.hemisphere);
    return o;
}
