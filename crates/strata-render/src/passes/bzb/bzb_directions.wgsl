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
    let t = bzb_texel(frame, bzb, pos.xy, zpack, npack);
    if (!t.ok) {
        return o;
    }
    o.origin = vec4f(t.x, 1.0);
    o.direction = bzb_direction(t.n, bzb_sample_uniforms(t.p, t.s, bzb.seed), bzb.hemisphere);
    return o;
}
