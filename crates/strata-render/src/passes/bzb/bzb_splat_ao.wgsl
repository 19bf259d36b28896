// bzb-ao §3.2: the fragment entries of the AOV splats (appended after bzb.wgsl and
// bzb_splat.wgsl, whose vertex shader draws them):
//   fs_visibility: hit at t in (t_min, r) → depth t²/r², payload 1 (depth test
//                  Less, no blending: the nearest occluder along ω wins); miss → discard.
//   fs_additive:   the analytic AOV occlusion, summed by additive blending (McGuire 2010).
// `splat_hit_depth` is also the test of the compute form (bzb_splat_compute.wgsl).

// The bounced z-buffer's depth of triangle `tri` at `texel`: t²/r² (§3.2's squared
// distance scaled by d_max² = r², in [0, 1)) when the texel's ray (x_p, ω) hits it at
// t in (t_min, r); -1 otherwise.
fn splat_hit_depth(texel: vec2i, tri: u32) -> f32 {
    let o = textureLoad(origins, texel, 0);
    let d = textureLoad(directions, texel, 0);
    if (d.w <= 0.0) {
        return -1.0;
    }
    let v = load_triangle(tri);
    let t = bzb_ray_triangle(o.xyz, d.xyz, v[0], v[1], v[2]);
    if (!(t > bzb.t_min && t < bzb.radius)) {
        return -1.0;
    }
    return t * t * bzb.inv_r2;
}

struct VisibilityOut {
    @location(0) occlusion: vec4f,
    @builtin(frag_depth) depth: f32,
}

@fragment
fn fs_visibility(in: SplatVertex) -> VisibilityOut {
    if (outside_rect(in)) {
        discard;
    }
    let z = splat_hit_depth(vec2i(in.position.xy), in.triangle);
    if (z < 0.0) {
        discard;
    }
    var out: VisibilityOut;
    // AO payload: binary occlusion (the estimator of §3.3 divides by α)
    out.occlusion = vec4f(1.0);
    out.depth = z;
    return out;
}

@fragment
fn fs_additive(in: SplatVertex) -> @location(0) vec4f {
    if (outside_rect(in)) {
        discard;
    }
    let texel = vec2i(in.position.xy);
    let o = textureLoad(origins, texel, 0);
    if (o.w <= 0.0) {
        discard;
    }
    let p = vec2i(vec2u(in.position.xy) % vec2u(frame.size.xy));
    let n = oct_decode(textureLoad(npack, p, 0).rg);
    let v = load_triangle(in.triangle);
    let a = bzb_aov_occlusion(o.xyz, n, v[0], v[1], v[2], bzb.radius, bzb.t_min);
    if (a <= 0.0) {
        discard;
    }
    return vec4f(a);
}
