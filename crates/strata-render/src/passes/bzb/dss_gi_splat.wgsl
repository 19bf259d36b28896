// bzb-gi with DSS surfels (BZB §4.2 with a radiance payload): appended to
// dss_splat.wgsl (same vertex stage, same shells, same receiver tests).
//   fs_gi_visibility: the nearest surfel hit per (receiver, direction, level)
//                     wins the depth test; payload (L(surfel → x_p), 1), L the
//                     face of the shaded surfel towards the receiver, alpha the hit flag.
//   fs_gi_additive:   every surfel in the shell adds π · F · L (F the disk's
//                     form factor, dss_disk_occlusion; L the face towards the
//                     receiver): the irradiance of DSS without visibility.
@group(1) @binding(6) var<storage, read> radiance: array<vec4f>;

// The ray–disk radius of fs_gi_visibility over the surfel's (area-preserving)
// radius (`dss::GI_COVER`): surfels placed at random with total area = the
// mesh area leave e^−1 ≈ 37 % of a surface uncovered (Poisson), so rays pass
// through blockers and miss emitters. With visibility only the nearest hit is
// kept, never a sum, so overlapping disks add no energy: radius ×2 (area ×4)
// leaves e^−4 ≈ 2 %. The additive baseline keeps the area-preserving radius.
const DSS_GI_COVER: f32 = 2.0;

// The shaded face of surfel j (normal n) seen from receiver o.
fn dss_gi_radiance(j: u32, c: vec3f, n: vec3f, o: vec3f) -> vec3f {
    return radiance[2u * j + select(1u, 0u, dot(n, o - c) >= 0.0)].rgb;
}

@fragment
fn fs_gi_visibility(in: SplatVertex) -> VisibilityOut {
    let texel = vec2i(in.position.xy);
    let o = textureLoad(origins, texel, 0);
    let d = textureLoad(directions, texel, 0);
    if (d.w <= 0.0) {
        discard;
    }
    let cr = surfels[2u * in.surfel];
    let n = surfels[2u * in.surfel + 1u].xyz;
    let shell = dss_shell(in.level, dss.d_max);
    let dist = distance(o.xyz, cr.xyz);
    // in the level's shell, or (§4.3) redirected to the finer level whose shell holds it
    let fl = dss_fragment_level(dist, in.level, dss.d_max, dss.redirect == 1u);
    if (fl == DSS_NO_LEVEL) {
        discard;
    }
    if (!(dot(receiver_normal(o.w), cr.xyz - o.xyz) > 0.0)) {
        discard;
    }
    let r = DSS_GI_COVER * cr.w * f32(1u << fl);
    let t = dss_ray_disk(o.xyz, d.xyz, cr.xyz, n, r);
    if (!dss_occluding_hit(o.xyz, cr.xyz, n, t, dss.t_min)) {
        discard;
    }
    var out: VisibilityOut;
    out.occlusion = vec4f(dss_gi_radiance(in.surfel, cr.xyz, n, o.xyz), 1.0);
    // (normalised by this level's largest: a redirected disk is smaller)
    let m = shell.y + DSS_GI_COVER * cr.w * f32(1u << in.level);
    out.depth = min(t * t / (m * m), 0.99999);
    return out;
}

@fragment
fn fs_gi_additive(in: SplatVertex) -> @location(0) vec4f {
    let a = dss_additive(in);
    if (a.f <= 0.0) {
        discard;
    }
    return vec4f(DSS_PI * a.f * dss_gi_radiance(in.surfel, a.c, a.ns, a.o), 1.0);
}
