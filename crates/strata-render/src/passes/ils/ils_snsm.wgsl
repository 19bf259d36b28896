// ILS §4.3 SNSM: shading of the split G-buffer, visibility ignored (§6.2's
// interactive mode), and the brute-force baseline on the unsplit G-buffer.
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

struct Shade {
    geo: Interleave,
    vpl_count: u32,
    sub_buffers: u32,
    all_vpls: u32,
    _pad0: u32,
    max_geometry: f32,
    _pad1: f32,
    _pad2: f32,
    _pad3: f32,
}

@group(0) @binding(0) var<uniform> frame: Frame;
@group(1) @binding(0) var<uniform> shade: Shade;
// packed G-buffer: world normal (xyz), csz (w); split or not
@group(1) @binding(1) var gbuffer: texture_2d<f32>;
@group(1) @binding(2) var<storage, read> vpls: array<Vpl>;

// Σ over VPLs first, first + step, … < N of Φ/π cos θ_y cos θ_x / d² at the
// surface of image pixel `pix` with packed G-buffer texel `g`.
fn vpl_sum(g: vec4f, pix: vec2u, first: u32, step: u32) -> vec3f {
    let x = world_from_csz(frame, vec2f(pix) + 0.5, g.w);
    var e = vec3f(0.0);
    for (var k = first; k < shade.vpl_count; k += step) {
        e += vpl_irradiance(vpls[k], x, g.xyz, shade.max_geometry);
    }
    return e;
}

// SNSM on the tiled sub-buffers (writes the tiled irradiance buffer, Fig. 3 c).
@fragment
fn fs_snsm(@builtin(position) pos: vec4f) -> @location(0) vec4f {
    let t = vec2u(pos.xy);
    if (ils_is_padding(t, shade.geo)) {
        return vec4f(0.0);
    }
    let g = textureLoad(gbuffer, vec2i(t), 0);
    if (g.w <= 0.0) {
        return vec4f(0.0);
    }
    let pix = ils_gather_index(t, shade.geo);
    if (shade.all_vpls != 0u) {
        return vec4f(vpl_sum(g, pix, 0u, 1u), 1.0);
    }
    let ij = ils_sub_buffer(t, shade.geo);
    let s = ij.y * shade.geo.pattern.x + ij.x;
    let big_s = shade.sub_buffers;
    if (s >= shade.vpl_count) {
        // fewer VPLs than sub-buffers: this one has none
        return vec4f(0.0, 0.0, 0.0, 1.0);
    }
    let n_s = (shade.vpl_count - s + big_s - 1u) / big_s;
    let e = vpl_sum(g, pix, s, big_s) * (f32(shade.vpl_count) / f32(n_s));
    return vec4f(e, 1.0);
}

// Brute force ("no IS", Table 4): every pixel, all N VPLs.
@fragment
fn fs_brute_force(@builtin(position) pos: vec4f) -> @location(0) vec4f {
    let p = vec2u(pos.xy);
    let g = textureLoad(gbuffer, vec2i(p), 0);
    if (g.w <= 0.0) {
        return vec4f(0.0);
    }
    return vec4f(vpl_sum(g, p, 0u, 1u), 1.0);
}
