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
