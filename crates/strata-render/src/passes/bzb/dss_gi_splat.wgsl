// bzb-gi with DSS surfels (BZB §4.2 with a radiance payload): appended to
// dss_splat.wgsl (same vertex stage, same shells, same receiver tests).
//   fs_gi_visibility: the nearest surfel hit per (receiver, direction, level)
//                     wins the depth test; payload (L(surfel → x_p), 1), L the
//                     face of the shaded surfel towards the receiver, alpha the hit flag.
//   fs_gi_additive:   every surfel in the shell adds π · F · L (F the disk's
//                     form factor, dss_disk_occlusion; L the face towards the
//                     receiver): the irradiance of DSS without visibility.
@group(1) @binding(6) var<storage, read> radiance: array<vec4f>;
// the scene's triangles (3 vec4 each: a vertex, w = 1 where the edge to the next
// vertex is open: gi::gi_triangle_data), the surfels' sources
@group(1) @binding(7) var<storage, read> gi_triangles: array<vec4f>;

// The ray–disk radius of fs_gi_visibility over the surfel's (area-preserving)
// radius (`dss::GI_COVER`): surfels placed at random with total area = the
// mesh area leave e^−1 ≈ 37 % of a surface uncovered (Poisson), so rays pass
// through blockers and miss emitters. With visibility only the nearest hit is
// kept, never a sum, so overlapping disks add no energy: radius ×2 (area ×4)
// leaves e^−4 ≈ 2 %. The additive baseline keeps the area-preserving radius.
const DSS_GI_COVER: f32 = 2.0;

// Whether the point p of a disk lies within its source triangle's open edges
// (dss::open_edges: outlines and creases, flagged in each vertex's w), p projected
// onto the triangle's plane. The enlarged disks (DSS_GI_COVER) would otherwise
// overhang a surface's silhouette and occlude what lies behind it; across a smooth
// edge the overhang lies on the neighbouring triangle, and is kept.
fn dss_within_open_edges(p: vec3f, tri: u32) -> bool {
    let a = gi_triangles[3u * tri].xyz;
    let e1 = gi_triangles[3u * tri + 1u].xyz - a;
    let e2 = gi_triangles[3u * tri + 2u].xyz - a;
    let q = p - a;
    let d11 = dot(e1, e1);
    let d12 = dot(e1, e2);
    let d22 = dot(e2, e2);
    let det = d11 * d22 - d12 * d12;
    if (!(det > 0.0)) {
        return true;
    }
    let b = vec2f(d22 * dot(q, e1) - d12 * dot(q, e2), d11 * dot(q, e2) - d12 * dot(q, e1)) / det;
    // vertex k's w: the edge from it to the next is open; edge a–b bounds b.y, b–c
    // 1 − b.x − b.y, c–a b.x
    let open = vec3f(gi_triangles[3u * tri].w, gi_triangles[3u * tri + 1u].w, gi_triangles[3u * tri + 2u].w) > vec3f(0.5);
    return (!open.x || b.y >= 0.0) && (!open.y || 1.0 - b.x - b.y >= 0.0) && (!open.z || b.x >= 0.0);
}

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
    // the surfel's source triangle (normal.w)
    let nw = surfels[2u * in.surfel + 1u].w;
    if (!dss_within_open_edges(o.xyz + t * d.xyz, u32(nw + 0.5))) {
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
