// Virtual point lights of instant radiosity, the light samples of interleaved
// deferred shading (ILS §6). A VPL at y with unit normal n_y and flux Φ is a
// cosine emitter; a receiver x with unit normal n_x gets the irradiance-like term
//   Φ/π · cos θ_y · cos θ_x / d²      (visibility ignored: SNSM, §4.3, §6.2)
// with the geometry term cos θ_y cos θ_x / d² clamped to `max_geometry` (the
// usual bound on the 1/d² singularity near a VPL). Multiply by ρ_x/π for the
// reflected radiance. CPU twin: `strata_reference::Vpl::irradiance_at`.
// Layout mirrors `passes::ils::GpuVpl` (w components unused).
#import "common/ggx.wgsl"

struct Vpl {
    position: vec4f,
    normal: vec4f,
    flux: vec4f,
}

// xyz: the unit direction w from the VPL to x; w: the clamped geometry term
// min(cos θ_y cos θ_x / d², max_geometry), or 0 (and w = 0) when either side
// faces away or x is at the VPL.
fn vpl_geometry(v: Vpl, x: vec3f, n: vec3f, max_geometry: f32) -> vec4f {
    let d = x - v.position.xyz;
    let d2 = dot(d, d);
    if (!(d2 > 0.0)) {
        return vec4f(0.0);
    }
    let w = d / sqrt(d2);
    let cos_y = dot(v.normal.xyz, w);
    let cos_x = -dot(n, w);
    if (cos_y <= 0.0 || cos_x <= 0.0) {
        return vec4f(0.0);
    }
    return vec4f(w, min(cos_y * cos_x / d2, max_geometry));
}

fn vpl_irradiance(v: Vpl, x: vec3f, n: vec3f, max_geometry: f32) -> vec3f {
    let wg = vpl_geometry(v, x, n, max_geometry);
    if (wg.w <= 0.0) {
        return vec3f(0.0);
    }
    return v.flux.rgb * (wg.w * 0.31830988618379067);
}

// Glossy receivers: outgoing radiance toward the unit view direction `view`
//   f(view, l) · Φ/π · min(cos θ_y cos θ_x / d², max_geometry),  l = −w
// with f the GGX BRDF (common/ggx.wgsl) — with f = ρ/π it is ρ/π times
// `vpl_irradiance`. CPU twin: `strata_reference::Vpl::glossy_radiance_at`.
fn vpl_glossy_radiance(v: Vpl, x: vec3f, n: vec3f, view: vec3f, rho: vec3f, roughness: f32, metallic: f32, max_geometry: f32) -> vec3f {
    let wg = vpl_geometry(v, x, n, max_geometry);
    if (wg.w <= 0.0) {
        return vec3f(0.0);
    }
    return ggx_eval(n, view, -wg.xyz, rho, roughness, metallic) * v.flux.rgb * (wg.w * 0.31830988618379067);
}
