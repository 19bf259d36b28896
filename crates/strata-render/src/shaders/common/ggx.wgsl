// The metallic-roughness GGX BRDF of glossy materials, the WGSL twin of
// `strata_reference::brdf::Ggx::eval` (same formulas, same clamps; see brdf.rs):
//   f(v, l) = (1 − m) ρ/π (1 − F_d(n·v)) (1 − F_d(n·l))
//           + F(v·h) D(h) G2(v, l) / (4 (n·v)(n·l))
// with α = max(r², 0.002), F0 = mix(0.04, ρ, m), height-correlated Smith G2 and
// Schlick F. (lighting.wgsl's `specular_brdf` is an older, approximate lobe for
// direct light; this one matches the path tracer bit for bit up to f32 rounding.)

const GGX_PI: f32 = 3.14159265358979;
const GGX_ALPHA_MIN: f32 = 0.002;
const GGX_DIELECTRIC_F0: f32 = 0.04;

fn ggx_d(cos_h: f32, alpha: f32) -> f32 {
    if (cos_h <= 0.0) {
        return 0.0;
    }
    let a2 = alpha * alpha;
    let k = (1.0 - cos_h) * (1.0 + cos_h) + a2 * cos_h * cos_h;
    return a2 / (GGX_PI * k * k);
}

fn ggx_smith_lambda(c: f32, alpha: f32) -> f32 {
    let c2 = max(c * c, 1e-12);
    let tan2 = max(1.0 - c2, 0.0) / c2;
    return 0.5 * (sqrt(1.0 + alpha * alpha * tan2) - 1.0);
}

fn ggx_pow5(x: f32) -> f32 {
    let x2 = x * x;
    return x2 * x2 * x;
}

fn ggx_schlick_dielectric(c: f32) -> f32 {
    return GGX_DIELECTRIC_F0 + (1.0 - GGX_DIELECTRIC_F0) * ggx_pow5(1.0 - clamp(c, 0.0, 1.0));
}

// f(v, l) for unit normal n, unit view v and unit light l (both away from the
// surface), base colour rho, roughness and metallic (clamped to [0, 1]).
fn ggx_eval(n: vec3f, v: vec3f, l: vec3f, rho: vec3f, roughness: f32, metallic: f32) -> vec3f {
    let nl = dot(n, l);
    if (nl <= 0.0) {
        return vec3f(0.0);
    }
    let m = clamp(metallic, 0.0, 1.0);
    let r = clamp(roughness, 0.0, 1.0);
    let alpha = max(r * r, GGX_ALPHA_MIN);
    let nv = dot(n, v);
    let f0 = mix(vec3f(GGX_DIELECTRIC_F0), rho, m);
    let diffuse = rho * (1.0 - m) * (1.0 - ggx_schlick_dielectric(nv)) * 0.31830988618379067;
    var f = diffuse * (1.0 - ggx_schlick_dielectric(nl));
    if (nv > 1e-4) {
        let hv = v + l;
        let hl = length(hv);
        if (hl > 0.0) {
            let h = hv / hl;
            let d = ggx_d(dot(n, h), alpha);
            if (d > 0.0) {
                let g = 1.0 / (1.0 + ggx_smith_lambda(nv, alpha) + ggx_smith_lambda(nl, alpha));
                let k = ggx_pow5(1.0 - clamp(dot(v, h), 0.0, 1.0));
                let fr = f0 + (vec3f(1.0) - f0) * k;
                f += fr * (d * g / (4.0 * nv * nl));
            }
        }
    }
    return f;
}

// A smooth stand-in for f's directional albedo ∫ f(v, l) (n·l) dl at n·v = nv, the
// twin of `strata_reference::brdf::demodulation_albedo`: the diffuse lobe exactly,
// the specular lobe by Karis's fit of the split sum's scale and bias (F0 · A + B;
// Karis 2014, "Physically based shading on mobile"). Glossy radiance is divided by
// it before the screen-space filters and multiplied back in compose, so the filters
// blur the lighting and not the textures. At least 1e-3 per channel.
fn ggx_demodulation(nv: f32, rho: vec3f, roughness: f32, metallic: f32) -> vec3f {
    let m = clamp(metallic, 0.0, 1.0);
    let r = clamp(roughness, 0.0, 1.0);
    let c = clamp(nv, 0.0, 1.0);
    let f0 = mix(vec3f(GGX_DIELECTRIC_F0), rho, m);
    let q = r * vec4f(-1.0, -0.0275, -0.572, 0.022) + vec4f(1.0, 0.0425, 1.04, -0.04);
    let a004 = min(q.x * q.x, exp2(-9.28 * c)) * q.x + q.y;
    let scale = -1.04 * a004 + q.z;
    let bias = 1.04 * a004 + q.w;
    // 1 − F_d(n·l) averaged over the cosine-weighted hemisphere
    let transmitted = 1.0 - (GGX_DIELECTRIC_F0 + (1.0 - GGX_DIELECTRIC_F0) * (2.0 / 42.0));
    let diffuse = rho * ((1.0 - m) * (1.0 - ggx_schlick_dielectric(c)) * transmitted);
    return max(diffuse + f0 * scale + vec3f(bias), vec3f(1e-3));
}
