// Deferred direct lighting: Lambert + a GGX specular lobe, shadows, emission,
// a constant ambient term and the sky behind everything.
#import "common/camera.wgsl"
#import "common/packing.wgsl"
#import "common/fullscreen.wgsl"
#import "common/lights.wgsl"
#import "common/shadow.wgsl"


struct LightingParams {
    light_count: u32,
    // 1 = add the specular lobe to `hdr`
    specular: u32,
    // PCF kernel radius in texels (0 = single bilinear comparison)
    pcf_radius: i32,
    shadow_size: f32,
    // 1 = emission enters the radiosity B (0 when emitters are Rect lights)
    emission_in_radiosity: u32,
    // 1 = Rect lights' shadows are PCSS penumbrae (`shadow_visibility_rect`), 0 = hard, from the centre
    area_penumbrae: u32,
    _pad1: u32,
    _pad2: u32,
}

@group(0) @binding(0) var<uniform> frame: Frame;
@group(1) @binding(0) var csz_tex: texture_2d<f32>;
@group(1) @binding(1) var normal_tex: texture_2d<f32>;
@group(1) @binding(2) var albedo_tex: texture_2d<f32>;
@group(1) @binding(3) var emission_tex: texture_2d<f32>;
@group(1) @binding(4) var<storage, read> lights: array<GpuLight>;
@group(1) @binding(5) var shadow_maps: texture_depth_2d_array;
@group(1) @binding(6) var shadow_sampler: sampler_comparison;
@group(1) @binding(7) var<uniform> params: LightingParams;
// view-projection of every shadow-map layer (a point light's six cube faces included)
@group(1) @binding(8) var<storage, read> shadow_mats: array<mat4x4f>;

const PI: f32 = 3.14159265358979;
// light_visibility: common/shadow.wgsl (shared with bzb-gi's senders)
fn shadow_visibility(l: GpuLight, p: vec3f, n: vec3f, dist: f32) -> f32 {
    return light_visibility(l, p, n, dist, params.pcf_radius, params.shadow_size, params.area_penumbrae);
}

// GGX / Smith-correlated specular BRDF times cos, Schlick Fresnel.
fn specular_brdf(n: vec3f, v: vec3f, l: vec3f, roughness: f32, f0: vec3f) -> vec3f {
    let h = normalize(v + l);
    let a = max(roughness * roughness, 0.002);
    let a2 = a * a;
    let nh = max(dot(n, h), 0.0);
    let nv = max(dot(n, v), 1e-4);
    let nl = max(dot(n, l), 0.0);
    let d = a2 / (PI * pow(nh * nh * (a2 - 1.0) + 1.0, 2.0));
    let gv = nl * sqrt(nv * nv * (1.0 - a2) + a2);
    let gl = nv * sqrt(nl * nl * (1.0 - a2) + a2);
    let vis = 0.5 / max(gv + gl, 1e-5);
    let f = f0 + (1.0 - f0) * pow(1.0 - max(dot(v, h), 0.0), 5.0);
    return d * vis * f;
}

struct LightingOut {
    // total HDR radiance
    @location(0) hdr: vec4f,
    // Lambertian direct outgoing radiance (the radiosity pass's initial B)
    @location(1) direct_diffuse: vec4f,
    // visibility of light 0 (shadow debug view)
    @location(2) shadow: vec4f,
    // DGB Table 1 radiosity B of layer 0 (R11G11B10): Lambertian direct + emission
    @location(3) radiosity: vec4f,
}

// Direct light at the surface of pixel `px` of the bound layer (z > 0).
struct Direct {
    // Lambertian direct outgoing radiance
    lambert: vec3f,
    // GGX specular outgoing radiance
    spec: vec3f,
    emission: vec3f,
    diffuse_albedo: vec3f,
    // visibility of light 0
    shadow0: f32,
}

fn direct_light(px: vec2i, frag: vec2f, z: f32) -> Direct {
    let p = world_from_csz(frame, frag, z);
    let nrm = textureLoad(normal_tex, px, 0);
    let n = oct_decode(nrm.xy);
    let roughness = nrm.z;
    let metallic = nrm.w;
    let albedo = textureLoad(albedo_tex, px, 0).rgb;
    let v = normalize(frame.eye.xyz - p);
    let diffuse_albedo = albedo * (1.0 - metallic);
    let f0 = mix(vec3f(0.04), albedo, metallic);

    var diffuse = vec3f(0.0);
    var spec = vec3f(0.0);
    var shadow0 = 1.0;
    for (var i = 0u; i < params.light_count; i++) {
        let li = lights[i];
        var l: vec3f;
        var e: vec3f;
        var dist = 1.0;
        switch li.kind.x {
            case 0u: {
                l = -li.direction.xyz;
                e = li.color.rgb;
            }
            default: {
                let d = li.position.xyz - p;
                dist = length(d);
                l = d / dist;
                var falloff = 1.0 / (dist * dist);
                if (li.kind.x == 2u) {
                    falloff *= smoothstep(li.cone.x, li.cone.y, dot(-l, li.direction.xyz));
                } else if (li.kind.x == 3u) {
                    // the GGX lobe's point approximation: intensity L·A·cos θ at the centre
                    let area = 4.0 * length(cross(li.half_u.xyz, li.half_v.xyz));
                    falloff *= area * max(dot(-l, li.direction.xyz), 0.0);
                }
                e = li.color.rgb * falloff;
            }
        }
        if (li.kind.x == 3u) {
            // area light: exact unoccluded Lambertian irradiance times the light's
            // visible share (PCSS), or shadowed from the centre
            let f = rect_irradiance(p, n, li.position.xyz, li.half_u.xyz, li.half_v.xyz, li.direction.xyz);
            var vis_r = 0.0;
            if (f > 0.0) {
                vis_r = shadow_visibility(li, p, n, dist);
            }
            if (i == 0u) {
                shadow0 = vis_r;
            }
            diffuse += li.color.rgb * f * vis_r;
            if (dot(n, l) > 0.0) {
                spec += specular_brdf(n, v, l, roughness, f0) * e * dot(n, l) * vis_r;
            }
            continue;
        }
        let nl = dot(n, l);
        var vis = 0.0;
        if (nl > 0.0) {
            vis = shadow_visibility(li, p, n, dist);
        }
        if (i == 0u) {
            shadow0 = vis;
        }
        if (nl <= 0.0) {
            continue;
        }
        let irradiance = e * nl * vis;
        diffuse += irradiance;
        spec += specular_brdf(n, v, l, roughness, f0) * irradiance;
    }
    var d: Direct;
    d.lambert = diffuse_albedo / PI * diffuse;
    d.spec = spec;
    d.emission = textureLoad(emission_tex, px, 0).rgb;
    d.diffuse_albedo = diffuse_albedo;
    d.shadow0 = shadow0;
    return d;
}

// Layer 0's outputs at pixel px, whose centre is `centre`.
fn lit(px: vec2i, centre: vec2f) -> LightingOut {
    let z = textureLoad(csz_tex, px, 0).r;
    var o: LightingOut;
    if (z <= 0.0) {
        o.hdr = vec4f(frame.sky.rgb, 1.0);
        o.direct_diffuse = vec4f(0.0);
        o.shadow = vec4f(1.0);
        o.radiosity = vec4f(0.0);
        return o;
    }
    let d = direct_light(px, centre, z);
    var total = d.lambert + d.emission + frame.ambient.rgb * d.diffuse_albedo;
    if (params.specular == 1u) {
        total += d.spec;
    }
    o.hdr = vec4f(total, 1.0);
    o.direct_diffuse = vec4f(d.lambert, 1.0);
    o.shadow = vec4f(d.shadow0, d.shadow0, d.shadow0, 1.0);
    o.radiosity = vec4f(d.lambert + d.emission * f32(params.emission_in_radiosity), 1.0);
    return o;
}

// DGB §3.2: the initial radiosity B of a deeper layer (bound instead of layer
// 0) = its Lambertian direct light + emission (unless emitters are Rect lights).
fn layer_radiosity(px: vec2i, centre: vec2f) -> vec4f {
    let z = textureLoad(csz_tex, px, 0).r;
    if (z <= 0.0) {
        return vec4f(0.0);
    }
    let d = direct_light(px, centre, z);
    return vec4f(d.lambert + d.emission * f32(params.emission_in_radiosity), 1.0);
}

@fragment
fn fs_main(@builtin(position) frag: vec4f) -> LightingOut {
    return lit(vec2i(frag.xy), frag.xy);
}

@fragment
fn fs_layer_radiosity(@builtin(position) frag: vec4f) -> @location(0) vec4f {
    return layer_radiosity(vec2i(frag.xy), frag.xy);
}

// The same passes as compute (`Kernel`), 8×8 pixels per workgroup: layer 0's four
// outputs, and a deeper layer's radiosity.
@group(1) @binding(9) var hdr_out: texture_storage_2d<STORAGE_FORMAT_0, write>;
@group(1) @binding(10) var direct_out: texture_storage_2d<STORAGE_FORMAT_1, write>;
@group(1) @binding(11) var shadow_out: texture_storage_2d<STORAGE_FORMAT_2, write>;
@group(1) @binding(12) var radiosity_out: texture_storage_2d<STORAGE_FORMAT_3, write>;
@group(1) @binding(13) var layer_out: texture_storage_2d<STORAGE_FORMAT_3, write>;

@compute @workgroup_size(8, 8)
fn cs_main(@builtin(global_invocation_id) id: vec3u) {
    if (any(id.xy >= textureDimensions(hdr_out))) {
        return;
    }
    let o = lit(vec2i(id.xy), vec2f(id.xy) + 0.5);
    textureStore(hdr_out, id.xy, o.hdr);
    textureStore(direct_out, id.xy, o.direct_diffuse);
    textureStore(shadow_out, id.xy, o.shadow);
    textureStore(radiosity_out, id.xy, o.radiosity);
}

@compute @workgroup_size(8, 8)
fn cs_layer_radiosity(@builtin(global_invocation_id) id: vec3u) {
    if (any(id.xy >= textureDimensions(layer_out))) {
        return;
    }
    textureStore(layer_out, id.xy, layer_radiosity(vec2i(id.xy), vec2f(id.xy) + 0.5));
}
