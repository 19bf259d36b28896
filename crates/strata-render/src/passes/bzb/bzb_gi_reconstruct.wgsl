// bzb-gi §3.3 weighting: per pixel, the mean over its S directions of the
// payload L(y → x) times the receiver's BRDF × cos θ / α. Lambert receivers
// write the irradiance E = mean L cos θ/α (compose multiplies by ρ/π after the
// filter, as for DGB radiosity and ILS); glossy receivers write the outgoing
// radiance mean f_GGX(v, ω) L cos θ/α into the glossy target, divided by
// ggx_demodulation (compose multiplies it back after the filters). Without
// visibility the payload of sub-image 0 is already the summed irradiance
// (Lambert) or glossy radiance of every splat (bzb_gi_splat.wgsl).
#import "common/fullscreen.wgsl"
#import "common/camera.wgsl"
#import "common/packing.wgsl"

@group(0) @binding(0) var<uniform> frame: Frame;
@group(1) @binding(0) var<uniform> bzb: Bzb;
@group(1) @binding(1) var payload: texture_2d<f32>;
@group(1) @binding(2) var directions: texture_2d<f32>;
@group(1) @binding(3) var zpack: texture_2d<f32>;
@group(1) @binding(4) var npack: texture_2d<f32>;
@group(1) @binding(5) var normal_tex: texture_2d<f32>;
@group(1) @binding(6) var albedo_tex: texture_2d<f32>;
@group(1) @binding(7) var emission_tex: texture_2d<f32>;

struct Out {
    // Lambert receivers' irradiance E (glossy receivers: 0)
    @location(0) irradiance: vec4f,
    // glossy receivers' outgoing radiance (Lambert receivers: 0)
    @location(1) glossy: vec4f,
}

@fragment
fn fs_main(@builtin(position) pos: vec4f) -> Out {
    var o: Out;
    o.irradiance = vec4f(0.0, 0.0, 0.0, 1.0);
    o.glossy = vec4f(0.0, 0.0, 0.0, 1.0);
    let p = vec2u(pos.xy);
    let z = textureLoad(zpack, vec2i(p), 0).r;
    if (z <= 0.0) {
        return o;
    }
    let n = oct_decode(textureLoad(npack, vec2i(p), 0).rg);
    let x = world_from_csz(frame, vec2f(p) + 0.5, z);
    let v = normalize(frame.eye.xyz - x);
    let nrm = textureLoad(normal_tex, vec2i(p), 0);
    let glossy = textureLoad(emission_tex, vec2i(p), 0).a > 1.5;
    let rho = textureLoad(albedo_tex, vec2i(p), 0).rgb;
    let size = vec2u(frame.size.xy);
    var sum = vec3f(0.0);
    var count = 0.0;
    if (bzb.visibility == 0u) {
        // the additive baseline's sum, splatted into sub-image 0 only
        sum = textureLoad(payload, vec2i(p), 0).rgb;
        count = 1.0;
    }
    for (var s = 0u; s < bzb.directions * bzb.visibility; s++) {
        let texel = vec2i(bzb_tile_origin(s, bzb.cols, size) + p);
        let d = textureLoad(directions, texel, 0);
        if (d.w <= 0.0) {
            continue;
        }
        count += 1.0;
        // no sender within d_max (payload alpha 0): the sky, once d_max spans the scene
        let hit = textureLoad(payload, texel, 0);
        let l = select(hit.rgb, frame.sky.rgb, hit.a == 0.0 && bzb.escape_sky != 0u);
        let c = max(0.0, dot(n, d.xyz));
        if (glossy) {
            sum += ggx_eval(n, v, d.xyz, rho, nrm.z, nrm.w) * l * (c / d.w);
        } else {
            sum += l * (c / d.w);
        }
    }
    let mean = select(vec3f(0.0), sum / max(count, 1.0), count > 0.0);
    if (glossy) {
        // DSS without visibility (hemisphere = 1) sums irradiance for every
        // receiver: glossy ones reflect it as a Lambert surface of albedo ρ
        let l = select(mean, mean * rho * (1.0 / BZB_PI), bzb.hemisphere == 1u);
        // demodulated (common/ggx.wgsl): the filters blur the light, compose multiplies A back
        o.glossy = vec4f(l / ggx_demodulation(dot(n, v), rho, nrm.z, nrm.w), 1.0);
    } else {
        o.irradiance = vec4f(mean, 1.0);
    }
    return o;
}
