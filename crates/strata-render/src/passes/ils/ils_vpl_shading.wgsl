// The VPL shading of ILS §4.3 shared by `ils_snsm.wgsl` (SNSM, SSM, brute force)
// and `ils_refine.wgsl`: each declares the bindings these functions read (`frame`,
// `shade`, `vpls`, `normal_tex`, `albedo_tex`, `emission_tex`, and for SSM
// `vpl_shadow_maps`, `vpl_shadow_sampler`, `vpl_shadow_mats`) and is appended to this.
//
// ILS §4.3 SNSM: shading of the split G-buffer, visibility ignored (§6.2's
// interactive mode), and the brute-force baseline on the unsplit G-buffer;
// `fs_ssm` / `fs_brute_force_ssm`: the same with each VPL's visibility from its
// shadow map (§4.3 SSM, passes/ils/ssm.rs).
//
// VPL assignment: the N VPLs are partitioned over the S = n·m sub-buffers,
// VPL k → sub-buffer s = k mod S with s = j·n + i for sub-buffer (i, j). One
// draw covers the tiled buffer; a fragment finds its sub-buffer from its tile
// (the sub-buffers are contiguous, so every fragment of a tile runs the same
// VPL loop: the coherence §3.2 splits for). A pixel of sub-buffer s sees
// N_s = ⌈(N − s)/S⌉ VPLs and scales their sum by N / N_s (= n·m when S | N),
// so its estimate of the full sum over N VPLs is unbiased.
#import "common/fullscreen.wgsl"
#import "common/frame.wgsl"
#import "common/camera.wgsl"
#import "common/interleave.wgsl"
#import "common/vpl.wgsl"
#import "common/lights.wgsl"

struct Shade {
    geo: Interleave,
    vpl_count: u32,
    sub_buffers: u32,
    all_vpls: u32,
    // ils-refine: pixels whose blur coverage is below this are shaded with every VPL
    refine: f32,
    max_geometry: f32,
    // SSM: the shadow-map eye's offset along the VPL normal, a shadow texel's size at
    // distance 1, half a texel in face uv
    eye_offset: f32,
    texel_at_1: f32,
    half_texel: f32,
    // ils-refine: glossy receivers rougher than this keep the blur (0 = every one does)
    refine_roughness: f32,
    // ils-refine: pixels whose blur window holds a gathered texel that outshines its
    // own VPL subset one period away by more than this · n·m · the blurred irradiance
    // (channel sums; ils_peak.wgsl; 0 = off)
    refine_peak: f32,
    _pad0: u32,
    _pad1: u32,
}

// Lambert receivers: (E, 1) in location 0 and (0, 0, 0, 1) in location 1; glossy
// ones: (0, 0, 0, 1) and (L_o / A, 1) (L_o = Σ_k vpl_glossy_radiance, common/vpl.wgsl;
// A = ggx_demodulation at the pixel, which compose multiplies back after the blur).
struct ShadeOut {
    @location(0) irradiance: vec4f,
    @location(1) glossy: vec4f,
}

struct Receiver {
    glossy: bool,
    view: vec3f,
    // the glossy radiance's demodulation (common/ggx.wgsl)
    demodulation: vec3f,
    rho: vec3f,
    roughness: f32,
    metallic: f32,
}

fn receiver(pix: vec2u, x: vec3f, n: vec3f) -> Receiver {
    var r: Receiver;
    let p = vec2i(pix);
    r.glossy = textureLoad(emission_tex, p, 0).a > 1.5;
    if (r.glossy) {
        let nrm = textureLoad(normal_tex, p, 0);
        r.roughness = nrm.z;
        r.metallic = nrm.w;
        r.rho = textureLoad(albedo_tex, p, 0).rgb;
        r.view = normalize(frame.eye.xyz - x);
        r.demodulation = ggx_demodulation(dot(n, r.view), r.rho, r.roughness, r.metallic);
    }
    return r;
}

fn vpl_term(k: u32, x: vec3f, n: vec3f, r: Receiver) -> vec3f {
    if (r.glossy) {
        return vpl_glossy_radiance(vpls[k], x, n, r.view, r.rho, r.roughness, r.metallic, shade.max_geometry);
    }
    return vpl_irradiance(vpls[k], x, n, shade.max_geometry);
}

fn shade_out(e: vec3f, r: Receiver) -> ShadeOut {
    var o: ShadeOut;
    if (r.glossy) {
        o.irradiance = vec4f(0.0, 0.0, 0.0, 1.0);
        o.glossy = vec4f(e / r.demodulation, 1.0);
    } else {
        o.irradiance = vec4f(e, 1.0);
        o.glossy = vec4f(0.0, 0.0, 0.0, 1.0);
    }
    return o;
}

// §4.3 SSM: visibility of surface point x (normal n) from VPL k, from its cube
// shadow map (face by the major axis of the direction from the VPL, as a point
// light's: lighting.wgsl), 2×2 PCF by the comparison sampler.
fn vpl_visibility(k: u32, v: Vpl, x: vec3f, n: vec3f) -> f32 {
    let eye = v.position.xyz + v.normal.xyz * shade.eye_offset;
    // normal offset of 1.5 texels at the receiver's distance
    let q = x + n * (1.5 * shade.texel_at_1 * length(x - eye));
    let face = cube_face(q - eye);
    let c = vpl_shadow_mats[k * 6u + face] * vec4f(q, 1.0);
    let ndc = c.xyz / c.w;
    if (c.w <= 0.0 || ndc.z > 1.0) {
        return 1.0;
    }
    let uv_face = clamp(vec2f(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5), vec2f(shade.half_texel), vec2f(1.0 - shade.half_texel));
    let uv = (vec2f(f32(face % 3u), f32(face / 3u)) + uv_face) / vec2f(3.0, 2.0);
    return textureSampleCompareLevel(vpl_shadow_maps, vpl_shadow_sampler, uv, i32(k), ndc.z);
}

// vpl_sum with each VPL's term times its visibility (SSM).
fn vpl_sum_ssm(g: vec4f, pix: vec2u, first: u32, step: u32) -> ShadeOut {
    let x = world_from_csz(frame, vec2f(pix) + 0.5, g.w);
    let r = receiver(pix, x, g.xyz);
    var e = vec3f(0.0);
    for (var k = first; k < shade.vpl_count; k += step) {
        let term = vpl_term(k, x, g.xyz, r);
        if (any(term > vec3f(0.0))) {
            e += term * vpl_visibility(k, vpls[k], x, g.xyz);
        }
    }
    return shade_out(e, r);
}

// Σ over VPLs first, first + step, … < N of Φ/π cos θ_y cos θ_x / d² (Lambert
// receivers; glossy ones: of f(v, l)·Φ/π cos θ_y cos θ_x / d²) at the surface
// of image pixel `pix` with packed G-buffer texel `g`.
fn vpl_sum(g: vec4f, pix: vec2u, first: u32, step: u32) -> ShadeOut {
    let x = world_from_csz(frame, vec2f(pix) + 0.5, g.w);
    let r = receiver(pix, x, g.xyz);
    var e = vec3f(0.0);
    for (var k = first; k < shade.vpl_count; k += step) {
        e += vpl_term(k, x, g.xyz, r);
    }
    return shade_out(e, r);
}

fn scaled(o: ShadeOut, s: f32) -> ShadeOut {
    var r = o;
    r.irradiance = vec4f(o.irradiance.rgb * s, 1.0);
    r.glossy = vec4f(o.glossy.rgb * s, 1.0);
    return r;
}

fn empty(a: f32) -> ShadeOut {
    var o: ShadeOut;
    o.irradiance = vec4f(0.0, 0.0, 0.0, a);
    o.glossy = vec4f(0.0, 0.0, 0.0, a);
    return o;
}

// What a tiled texel shades (Fig. 3 c): the G-buffer sample `g` at image pixel `pix`,
// VPLs first, first + stride, … (its sub-buffer's share, or all of them), the sum
// scaled by `scale` = N / N_s. `state`: 0 = nothing (padding, background), 1 = a
// sub-buffer without VPLs (fewer VPLs than sub-buffers), 2 = shade.
struct Share {
    g: vec4f,
    pix: vec2u,
    first: u32,
    stride: u32,
    scale: f32,
    state: u32,
}

fn share_of(t: vec2u) -> Share {
    var o: Share;
    if (ils_is_padding(t, shade.geo)) {
        return o;
    }
    o.g = textureLoad(gbuffer, vec2i(t), 0);
    if (o.g.w <= 0.0) {
        return o;
    }
    o.pix = ils_gather_index(t, shade.geo);
    o.state = 2u;
    o.stride = 1u;
    o.scale = 1.0;
    if (shade.all_vpls != 0u) {
        return o;
    }
    let ij = ils_sub_buffer(t, shade.geo);
    let s = ij.y * shade.geo.pattern.x + ij.x;
    let big_s = shade.sub_buffers;
    if (s >= shade.vpl_count) {
        o.state = 1u;
        return o;
    }
    let n_s = (shade.vpl_count - s + big_s - 1u) / big_s;
    o.first = s;
    o.stride = big_s;
    o.scale = f32(shade.vpl_count) / f32(n_s);
    return o;
}
