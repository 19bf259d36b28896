// bzb-ao §3.2: the AOV splats' baseline without visibility (appended after bzb.wgsl and
// bzb_splat.wgsl, whose vertex shader draws the splats and whose `fs_visibility` tests
// them with visibility: hit at t in (t_min, r) → depth t²/r², payload 1):
//   fs_additive: the analytic AOV occlusion, summed by additive blending (McGuire 2010).

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
