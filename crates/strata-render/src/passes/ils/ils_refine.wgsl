// Not in the paper: refinement after §4.5's blur. Pixels along edges and on thin
// features find few similar neighbours, so the blur averages few of the n·m VPL
// subsets there and they keep most of their subset's ×n·m noise: bright speckles
// along silhouettes. The blur's alpha says which share of the subsets each pixel
// averaged (`coverage` in ils_filter.wgsl); pixels below `shade.refine` are shaded
// again with all N VPLs (the brute force at that pixel), and so are glossy receivers
// smoother than `shade.refine_roughness` (sharp lobes: n×m blocks); the others keep the
// blurred values. Appended to ils_vpl_shading.wgsl.
#import "common/fullscreen.wgsl"
#import "common/frame.wgsl"
#import "common/camera.wgsl"
#import "common/interleave.wgsl"
#import "common/vpl.wgsl"

@group(0) @binding(0) var<uniform> frame: Frame;
@group(1) @binding(0) var<uniform> shade: Shade;
// the unsplit packed G-buffer: world normal (xyz), csz (w)
@group(1) @binding(1) var gbuffer: texture_2d<f32>;
@group(1) @binding(2) var<storage, read> vpls: array<Vpl>;
@group(1) @binding(3) var normal_tex: texture_2d<f32>;
@group(1) @binding(4) var albedo_tex: texture_2d<f32>;
@group(1) @binding(5) var emission_tex: texture_2d<f32>;
// the blurred irradiance (a = coverage) and glossy radiance
@group(1) @binding(6) var blurred: texture_2d<f32>;
@group(1) @binding(7) var blurred_glossy: texture_2d<f32>;
// SSM only (as in ils_snsm.wgsl)
@group(1) @binding(8) var vpl_shadow_maps: texture_depth_2d_array;
@group(1) @binding(9) var vpl_shadow_sampler: sampler_comparison;
@group(1) @binding(10) var<storage, read> vpl_shadow_mats: array<mat4x4f>;

// The blurred values, alpha = coverage (`refined` false), or the pixel's G-buffer
// sample to shade with every VPL.
struct Refined {
    keep: ShadeOut,
    g: vec4f,
    refined: bool,
}

fn refined_at(p: vec2u) -> Refined {
    var r: Refined;
    r.keep.irradiance = textureLoad(blurred, vec2i(p), 0);
    r.keep.glossy = textureLoad(blurred_glossy, vec2i(p), 0);
    r.g = textureLoad(gbuffer, vec2i(p), 0);
    let p_i = vec2i(p);
    let sharp = textureLoad(emission_tex, p_i, 0).a > 1.5 && textureLoad(normal_tex, p_i, 0).z < shade.refine_roughness;
    r.refined = r.g.w > 0.0 && (r.keep.irradiance.a < shade.refine || sharp);
    return r;
}

@fragment
fn fs_refine(@builtin(position) pos: vec4f) -> ShadeOut {
    let p = vec2u(pos.xy);
    let r = refined_at(p);
    if (!r.refined) {
        return r.keep;
    }
    return vpl_sum(r.g, p, 0u, 1u);
}

// With VPL shadows (SSM): the refined pixels test each VPL's shadow map, as the
// brute force does.
@fragment
fn fs_refine_ssm(@builtin(position) pos: vec4f) -> ShadeOut {
    let p = vec2u(pos.xy);
    let r = refined_at(p);
    if (!r.refined) {
        return r.keep;
    }
    return vpl_sum_ssm(r.g, p, 0u, 1u);
}
