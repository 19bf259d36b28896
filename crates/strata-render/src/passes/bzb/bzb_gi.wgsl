// bzb-gi: the GI half of the bounced z-buffer (BZB §3 with a radiance payload).
// Shared by the GI direction, splat and reconstruction passes; appended after
// bzb.wgsl. CPU twins: `passes::bzb::gi` (same hashes, same formulas).
#import "common/ggx.wgsl"

// Matches `bzb::gi::GiUniforms`.
struct BzbGi {
    light_count: u32,
    // PCF radius and size of the shadow maps (the lighting pass's)
    pcf_radius: i32,
    shadow_size: f32,
    // 1: emissive senders add their emission (no Rect light carries it already)
    emission_in: u32,
    d_max: f32,
    t_min: f32,
    visibility: u32,
    seed: u32,
    // payload clamp: largest RGB component kept (0 = off; biased)
    clamp: f32,
    // 1: Rect lights' shadows are PCSS penumbrae (the lighting pass's `area_penumbrae`)
    area_penumbrae: u32,
    _pad1: u32,
    _pad2: u32,
}

// The optional firefly clamp of the payload: L scaled so that its largest
// component is at most `gi.clamp` (off when 0).
fn bzb_gi_clamp(l: vec3f, c: f32) -> vec3f {
    let m = max(l.x, max(l.y, l.z));
    if (c > 0.0 && m > c) {
        return l * (c / m);
    }
    return l;
}

// The third uniform of sample (p, s): the lobe choice of a glossy receiver.
fn bzb_gi_lobe_uniform(p: vec2u, s: u32, seed: u32) -> f32 {
    let h1 = pcg_hash(p.x + pcg_hash(p.y + pcg_hash(s + pcg_hash(seed))));
    let h2 = pcg_hash(h1 ^ 0x9e3779b9u);
    let h3 = pcg_hash(h2 ^ 0x85ebca6bu);
    return f32(h3 >> 8u) * (1.0 / 16777216.0);
}

fn bzb_gi_luminance(c: vec3f) -> f32 {
    return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z;
}

// Probability of the specular lobe P_s (strata_reference::brdf::Ggx::new):
// Y(F(n·v)) / (Y(F(n·v)) + Y((1 − m)ρ)(1 − F_d(n·v))), 0 when n·v ≤ 1e-4.
fn bzb_gi_p_spec(nv: f32, rho: vec3f, metallic: f32) -> f32 {
    if (nv <= 1e-4) {
        return 0.0;
    }
    let m = clamp(metallic, 0.0, 1.0);
    let f0 = mix(vec3f(GGX_DIELECTRIC_F0), rho, m);
    let k = ggx_pow5(1.0 - clamp(nv, 0.0, 1.0));
    let ws = bzb_gi_luminance(f0 + (vec3f(1.0) - f0) * k);
    let wd = bzb_gi_luminance(rho * (1.0 - m)) * (1.0 - ggx_schlick_dielectric(nv));
    let sum = ws + wd;
    if (!(sum > 0.0)) {
        return 0.5;
    }
    return clamp(ws / sum, 0.0, 1.0);
}

// Solid-angle pdf of `bzb_gi_direction` for a glossy receiver (Ggx::pdf): the
// mixture (1 − P_s) cos θ/π + P_s G1(v) D(h) / (4 n·v).
fn bzb_gi_ggx_pdf(n: vec3f, v: vec3f, l: vec3f, rho: vec3f, roughness: f32, metallic: f32) -> f32 {
    let nv = dot(n, v);
    let ps = bzb_gi_p_spec(nv, rho, metallic);
    var p = 0.0;
    if (ps < 1.0) {
        p += (1.0 - ps) * max(dot(n, l), 0.0) * (1.0 / BZB_PI);
    }
    if (ps > 0.0) {
        let hv = v + l;
        let hl = length(hv);
        if (hl > 0.0) {
            let h = hv / hl;
            if (dot(v, h) > 0.0) {
                let r = clamp(roughness, 0.0, 1.0);
                let alpha = max(r * r, GGX_ALPHA_MIN);
                let g1 = 1.0 / (1.0 + ggx_smith_lambda(nv, alpha));
                p += ps * g1 * ggx_d(dot(n, h), alpha) / (4.0 * nv);
            }
        }
    }
    return p;
}

// GGX visible-normal sample in the local frame (sampling::ggx_vndf_local).
fn bzb_gi_vndf(v: vec3f, alpha: f32, u: vec2f) -> vec3f {
    let vs = normalize(vec3f(v.x * alpha, v.y * alpha, v.z));
    let phi = 2.0 * BZB_PI * u.x;
    let z = (1.0 - u.y) * (1.0 + vs.z) - vs.z;
    let s = sqrt(max(1.0 - z * z, 0.0));
    let hs = vec3f(s * cos(phi), s * sin(phi), z) + vs;
    let h = vec3f(hs.x * alpha, hs.y * alpha, max(hs.z, 0.0));
    let len = length(h);
    if (!(len > 0.0)) {
        return vec3f(0.0, 0.0, 1.0);
    }
    return h / len;
}

// BZB §3.1 for GI: ω importance-sampled by the receiver's BRDF × cosine, and its
// pdf (w). Lambert receivers: cosine-weighted (pdf cos θ/π). Glossy receivers:
// the reference's mixture (Ggx::sample): the GGX visible normals reflected
// about h with probability P_s (u_lobe < P_s), else the cosine lobe.
fn bzb_gi_direction(n: vec3f, v: vec3f, glossy: bool, rho: vec3f, roughness: f32, metallic: f32, u_lobe: f32, u: vec2f) -> vec4f {
    let sgn = select(-1.0, 1.0, n.z >= 0.0);
    let a = -1.0 / (sgn + n.z);
    let b = n.x * n.y * a;
    let t = vec3f(1.0 + sgn * n.x * n.x * a, sgn * b, -sgn * n.x);
    let bt = vec3f(b, sgn + n.y * n.y * a, -n.y);
    var l: vec3f;
    let nv = dot(n, v);
    if (glossy && u_lobe < bzb_gi_p_spec(nv, rho, metallic)) {
        let r = clamp(roughness, 0.0, 1.0);
        let alpha = max(r * r, GGX_ALPHA_MIN);
        let hl = bzb_gi_vndf(vec3f(dot(v, t), dot(v, bt), nv), alpha, u);
        let h = t * hl.x + bt * hl.y + n * hl.z;
        let rl = 2.0 * dot(v, h) * h - v;
        let len = length(rl);
        l = select(n, rl / len, len > 0.0);
    } else {
        let r = sqrt(u.x);
        let phi = 2.0 * BZB_PI * u.y;
        l = normalize(t * (r * cos(phi)) + bt * (r * sin(phi)) + n * sqrt(max(0.0, 1.0 - u.x)));
    }
    if (glossy) {
        return vec4f(l, bzb_gi_ggx_pdf(n, v, l, rho, roughness, metallic));
    }
    return vec4f(l, max(dot(n, l), 0.0) / BZB_PI);
}
