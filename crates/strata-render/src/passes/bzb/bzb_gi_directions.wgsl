// bzb-gi §3.1 direction setup: for every texel of the bounced z-buffer
// (sub-image s, pixel p) the ray origin x_p from layer 0 and a direction ω
// importance-sampled by the receiver's BRDF × cosine (bzb_gi_direction), with
// its pdf α stored for §3.3's weighting.
#import "common/fullscreen.wgsl"
#import "common/camera.wgsl"
#import "common/packing.wgsl"

@group(0) @binding(0) var<uniform> frame: Frame;
@group(1) @binding(0) var<uniform> bzb: Bzb;
@group(1) @binding(1) var zpack: texture_2d<f32>;
@group(1) @binding(2) var npack: texture_2d<f32>;
// layer 0: roughness (z), metallic (w); base colour; emission (a = 2: glossy)
@group(1) @binding(3) var normal_tex: texture_2d<f32>;
@group(1) @binding(4) var albedo_tex: texture_2d<f32>;
@group(1) @binding(5) var emission_tex: texture_2d<f32>;

struct DirectionsOut {
    @location(0) origin: vec4f,
    @location(1) direction: vec4f,
}

@fragment
fn fs_main(@builtin(position) pos: vec4f) -> DirectionsOut {
    var o: DirectionsOut;
    let t = bzb_texel(frame, bzb, pos.xy, zpack, npack);
    if (!t.ok) {
        return o;
    }
    let p = vec2i(t.p);
    let nrm = textureLoad(normal_tex, p, 0);
    let glossy = textureLoad(emission_tex, p, 0).a > 1.5;
    let rho = textureLoad(albedo_tex, p, 0).rgb;
    let v = normalize(frame.eye.xyz - t.x);
    o.origin = vec4f(t.x, 1.0);
    o.direction = bzb_gi_direction(
        t.n,
        v,
        glossy,
        rho,
        nrm.z,
        nrm.w,
        bzb_gi_lobe_uniform(t.p, t.s, bzb.seed),
        bzb_sample_uniforms(t.p, t.s, bzb.seed),
    );
    return o;
}
