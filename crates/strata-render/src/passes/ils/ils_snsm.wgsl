// ILS §4.3 shading passes (fs_snsm, fs_ssm on the split G-buffer; fs_brute_force,
// fs_brute_force_ssm on the unsplit one); appended to ils_vpl_shading.wgsl, which
// has the VPL assignment and the shading functions.
#import "common/fullscreen.wgsl"
#import "common/frame.wgsl"
#import "common/camera.wgsl"
#import "common/interleave.wgsl"
#import "common/vpl.wgsl"

@group(0) @binding(0) var<uniform> frame: Frame;
@group(1) @binding(0) var<uniform> shade: Shade;
// packed G-buffer: world normal (xyz), csz (w); split or not
@group(1) @binding(1) var gbuffer: texture_2d<f32>;
@group(1) @binding(2) var<storage, read> vpls: array<Vpl>;
// layer 0 in image space, read at the pixel's gather index: rg = normal, b =
// roughness, a = metallic; base colour; emission (a = 2: glossy material)
@group(1) @binding(3) var normal_tex: texture_2d<f32>;
@group(1) @binding(4) var albedo_tex: texture_2d<f32>;
@group(1) @binding(5) var emission_tex: texture_2d<f32>;
// SSM only: one layer per VPL, its six cube faces in a 3×2 atlas; 6 matrices per VPL
@group(1) @binding(6) var vpl_shadow_maps: texture_depth_2d_array;
@group(1) @binding(7) var vpl_shadow_sampler: sampler_comparison;
@group(1) @binding(8) var<storage, read> vpl_shadow_mats: array<mat4x4f>;

// SNSM on the tiled sub-buffers (writes the tiled irradiance buffer, Fig. 3 c).
@fragment
fn fs_snsm(@builtin(position) pos: vec4f) -> ShadeOut {
    let a = share_of(vec2u(pos.xy));
    if (a.state < 2u) {
        return empty(f32(a.state));
    }
    return scaled(vpl_sum(a.g, a.pix, a.first, a.stride), a.scale);
}

// Brute force ("no IS", Table 4): every pixel, all N VPLs.
@fragment
fn fs_brute_force(@builtin(position) pos: vec4f) -> ShadeOut {
    let p = vec2u(pos.xy);
    let g = textureLoad(gbuffer, vec2i(p), 0);
    if (g.w <= 0.0) {
        return empty(0.0);
    }
    return vpl_sum(g, p, 0u, 1u);
}

// SSM on the tiled sub-buffers (same assignment and scaling as fs_snsm).
@fragment
fn fs_ssm(@builtin(position) pos: vec4f) -> ShadeOut {
    let a = share_of(vec2u(pos.xy));
    if (a.state < 2u) {
        return empty(f32(a.state));
    }
    return scaled(vpl_sum_ssm(a.g, a.pix, a.first, a.stride), a.scale);
}

// Brute force with VPL shadows: every pixel, all N VPLs, each with its visibility.
@fragment
fn fs_brute_force_ssm(@builtin(position) pos: vec4f) -> ShadeOut {
    let p = vec2u(pos.xy);
    let g = textureLoad(gbuffer, vec2i(p), 0);
    if (g.w <= 0.0) {
        return empty(0.0);
    }
    return vpl_sum_ssm(g, p, 0u, 1u);
}
