// Final composition (DGB §3.2, Eq. 6): direct light (+ emission, ambient, sky)
// plus the Lambertian reflection of the deep-G-buffer indirect irradiance,
// ρ/π · E · boost(ρ).
#import "common/fullscreen.wgsl"

struct Compose {
    // 1 = Eq. 7's boost on the reflected indirect light
    boost: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

@group(0) @binding(0) var<uniform> compose: Compose;
@group(0) @binding(1) var hdr: texture_2d<f32>;
@group(0) @binding(2) var albedo: texture_2d<f32>;
@group(0) @binding(3) var normal: texture_2d<f32>;
@group(0) @binding(4) var indirect: texture_2d<f32>;

// Eq. 7
fn boost(rho: vec3f) -> f32 {
    let mx = max(rho.r, max(rho.g, rho.b));
    if (mx <= 0.0) {
        return 0.0;
    }
    return (mx - min(rho.r, min(rho.g, rho.b))) / mx;
}

@fragment
fn fs_main(@builtin(position) pos: vec4f) -> @location(0) vec4f {
    let p = vec2i(pos.xy);
    let direct = textureLoad(hdr, p, 0);
    let metallic = textureLoad(normal, p, 0).a;
    let rho = textureLoad(albedo, p, 0).rgb * (1.0 - metallic);
    var k = 1.0;
    if (compose.boost != 0u) {
        k = boost(rho);
    }
    let e = textureLoad(indirect, p, 0).rgb;
    return vec4f(direct.rgb + rho / 3.14159265358979 * e * k, 1.0);
}
