// Not in the paper: refinement after §4.5's blur. Pixels along edges and on thin
// features find few similar neighbours, so the blur averages few of the n·m VPL
// subsets there and they keep most of their subset's ×n·m noise: bright speckles
// along silhouettes. The blur's alpha says which share of the subsets each pixel
// averaged (`coverage` in ils_filter.wgsl); pixels below `shade.refine` are shaded
// again with all N VPLs (the brute force at that pixel), and so are glossy receivers
// smoother than `shade.refine_roughness` (sharp lobes: n×m blocks), and Lambert receivers
// whose blur window holds a gathered texel that outshines its own VPL subset one period
// away by more than `shade.refine_peak` · n·m · the blurred irradiance (a VPL close to
// the receivers: ils_peak.wgsl); the others keep the
// blurred values. Appended to ils_vpl_shading.wgsl.
//
// Two steps, so that the few refined pixels do not hold up the many kept ones (a
// fragment shader that shaded them in place made every SIMD group holding one refined
// pixel wait for its N-VPL loop): `fs_refine_select` writes every pixel's blurred
// value and appends the refined pixels to `refine_list`, and `cs_refine` shades the
// list, 64 pixels per workgroup, dispatched indirectly with the list's own count.
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
// The refined pixels: `groups`, `y`, `z` are `cs_refine`'s indirect dispatch
// (⌈count / REFINE_GROUP⌉, 1, 1), cleared to zero before `fs_refine_select`; each
// pixel is packed as x | y << 16.
struct RefineList {
    groups: atomic<u32>,
    y: atomic<u32>,
    z: atomic<u32>,
    count: atomic<u32>,
    pixels: array<u32>,
}
@group(1) @binding(8) var<storage, read_write> refine_list: RefineList;
// the largest spike of a gathered texel over its own VPL subset one period away within
// the blur's window (ils_peak.wgsl; with refine_peak > 0, else unread)
@group(1) @binding(9) var peak_tex: texture_2d<f32>;
// cs_refine's outputs (fs_refine_select writes them as colour attachments)
@group(1) @binding(10) var refined_out: texture_storage_2d<rgba16float, write>;
@group(1) @binding(11) var glossy_refined_out: texture_storage_2d<rgba16float, write>;
// SSM only (as in ils_snsm.wgsl)
@group(1) @binding(12) var vpl_shadow_maps: texture_depth_2d_array;
@group(1) @binding(13) var vpl_shadow_sampler: sampler_comparison;
@group(1) @binding(14) var<storage, read> vpl_shadow_mats: array<mat4x4f>;

const REFINE_GROUP: u32 = 64u;

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
    let glossy = textureLoad(emission_tex, p_i, 0).a > 1.5;
    let sharp = glossy && textureLoad(normal_tex, p_i, 0).z < shade.refine_roughness;
    // a glossy receiver's irradiance is 0 (its light is in the glossy target)
    // refine-peak: the window's largest spike against the pixel's blurred irradiance B,
    // spike > refine_peak · n·m · B in channel sums
    let b = r.keep.irradiance.rgb;
    let limit = shade.refine_peak * f32(shade.sub_buffers) * (b.r + b.g + b.b);
    let peak = shade.refine_peak > 0.0 && !glossy && textureLoad(peak_tex, p_i, 0).r > limit;
    r.refined = r.g.w > 0.0 && (r.keep.irradiance.a < shade.refine || sharp || peak);
    return r;
}

// Every pixel's blurred value; the refined ones are also appended to the list
// (their value here is replaced by cs_refine).
@fragment
fn fs_refine_select(@builtin(position) pos: vec4f) -> ShadeOut {
    let p = vec2u(pos.xy);
    let r = refined_at(p);
    if (r.refined) {
        let i = atomicAdd(&refine_list.count, 1u);
        refine_list.pixels[i] = p.x | (p.y << 16u);
        if (i % REFINE_GROUP == 0u) {
            atomicAdd(&refine_list.groups, 1u);
            if (i == 0u) {
                atomicStore(&refine_list.y, 1u);
                atomicStore(&refine_list.z, 1u);
            }
        }
    }
    return r.keep;
}

// The list's pixel `i` as (x, y, 1), or z = 0 past the list's end.
fn listed(i: u32) -> vec3u {
    if (i >= atomicLoad(&refine_list.count)) {
        return vec3u(0u, 0u, 0u);
    }
    let packed = refine_list.pixels[i];
    return vec3u(packed & 0xffffu, packed >> 16u, 1u);
}

fn store_refined(p: vec2u, o: ShadeOut) {
    textureStore(refined_out, vec2i(p), o.irradiance);
    textureStore(glossy_refined_out, vec2i(p), o.glossy);
}

// The listed pixels shaded with all N VPLs (the brute force at that pixel).
@compute @workgroup_size(REFINE_GROUP)
fn cs_refine(@builtin(global_invocation_id) id: vec3u) {
    let l = listed(id.x);
    if (l.z == 0u) {
        return;
    }
    store_refined(l.xy, vpl_sum(textureLoad(gbuffer, vec2i(l.xy), 0), l.xy, 0u, 1u));
}

// With VPL shadows (SSM): the refined pixels test each VPL's shadow map, as the
// brute force does.
@compute @workgroup_size(REFINE_GROUP)
fn cs_refine_ssm(@builtin(global_invocation_id) id: vec3u) {
    let l = listed(id.x);
    if (l.z == 0u) {
        return;
    }
    store_refined(l.xy, vpl_sum_ssm(textureLoad(gbuffer, vec2i(l.xy), 0), l.xy, 0u, 1u));
}
