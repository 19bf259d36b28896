// BZB §4.1–4.2 shell splatting into the stacked hierarchical framebuffer, one
// instanced indirect draw (vertex pulling: wgpu has no geometry shaders).
// Instance i = (surfel j, level l, direction s); its 6 vertices span, in the
// random sub-image k(j, l, s) of level l of direction tile s, the rectangle of
// neighbourhoods covered by the bounding box of the surfel's level-l shell
// (outer radius d_max·2^l). Each fragment reads its receiver x_p and ω_p
// (shuffled there by dss-shuffle) and keeps only receivers in the shell
// (inner, outer]; the surfel stands for 4^l surfels on level l (one of 4^l
// sub-images receives it), so it is enlarged to radius r·2^l. With §4.3's
// redirection (`dss.redirect`) a receiver inside the inner radius is tested as on
// the finer level l' whose shell holds it (radius r·2^l') instead of discarded; the
// reduction keeps the finest level's hit, so this only fills misses.
//   fs_visibility: disks centred above the receiver's tangent plane only;
//                  ray–disk hit at t > t_min, disk plane not through the
//                  receiver (dss_occluding_hit) → depth t²/(outer + r·2^l)², payload 1
//                  (depth test Less per level band, no blending); miss → discard.
//   fs_additive:   the disk's form-factor occlusion, summed by additive blending
//                  (the original shell splatting, no visibility).
#import "common/camera.wgsl"
#import "common/dss.wgsl"
#import "common/packing.wgsl"
#import "common/zminmax.wgsl"

@group(0) @binding(0) var<uniform> frame: Frame;
@group(1) @binding(0) var<uniform> dss: Dss;
@group(1) @binding(1) var<storage, read> surfels: array<vec4f>;
@group(1) @binding(2) var origins: texture_2d<f32>;
@group(1) @binding(3) var directions: texture_2d<f32>;
@group(1) @binding(4) var npack: texture_2d<f32>;
// min/max receiver depth per tile (bzb_zminmax.wgsl), for §4.3's splat culling
@group(1) @binding(5) var<storage, read> tiles: array<vec2f>;

// The receiver's normal: origins.w = 1 + its pixel index (dss-shuffle).
fn receiver_normal(w: f32) -> vec3f {
    let i = u32(w) - 1u;
    return oct_decode(textureLoad(npack, vec2i(vec2u(i % dss.size.x, i / dss.size.x)), 0).rg);
}

struct SplatVertex {
    @builtin(position) position: vec4f,
    @location(0) @interpolate(flat) surfel: u32,
    @location(1) @interpolate(flat) level: u32,
}

// §4.1: the sub-image of level l receiving surfel (position c) for direction s.
fn dss_surfel_subimage(c: vec3f, level: u32, s: u32) -> u32 {
    let mask = (1u << (2u * level)) - 1u;
    return pcg_hash(dss_hash3(c, dss.seed ^ 0x2545f491u) ^ pcg_hash(level + 16u * s)) & mask;
}

@vertex
fn vs_splat(@builtin(vertex_index) vi: u32, @builtin(instance_index) ii: u32) -> SplatVertex {
    var out: SplatVertex;
    let s = ii % dss.directions;
    let level = (ii / dss.directions) % dss.levels;
    let j = ii / (dss.directions * dss.levels);
    out.surfel = j;
    out.level = level;
    out.position = vec4f(-2.0, -2.0, 0.5, 1.0);
    let c = surfels[2u * j].xyz;
    let outer = dss_shell(level, dss.d_max).y;
    let lo = c - vec3f(outer);
    let hi = c + vec3f(outer);
    let sb = screen_box(frame, lo, hi);
    if (!sb.visible) {
        return out;
    }
    // §4.3 "Min/Max MIP-map for splat culling": no receiver under the shell's box lies
    // in its depth range (the AOV path's tiles over the frame's pixels)
    let size = vec2f(dss.size);
    let pmin = clamp(floor(sb.rmin) - 1.0, vec2f(0.0), size);
    let pmax = clamp(ceil(sb.rmax) + 1.0, vec2f(0.0), size);
    if (dss.depth_culling == 1u && !receivers_in_range(dss.size, pmin, pmax, sb.zlo, sb.zhi)) {
        return out;
    }
    // in neighbourhoods of 2^l × 2^l pixels (the sub-image's texels)
    let b = f32(1u << level);
    let sub = vec2f(dss.plane >> vec2u(level));
    let rmin = clamp(floor(sb.rmin / b) - 1.0, vec2f(0.0), sub);
    let rmax = clamp(ceil(sb.rmax / b) + 1.0, vec2f(0.0), sub);
    if (any(rmax <= rmin)) {
        return out;
    }
    var corners = array<vec2f, 6>(vec2f(0.0, 0.0), vec2f(1.0, 0.0), vec2f(0.0, 1.0), vec2f(0.0, 1.0), vec2f(1.0, 0.0), vec2f(1.0, 1.0));
    let k = dss_surfel_subimage(c, level, s);
    let origin = vec2f(dss_texel(level, s, k, vec2u(0u), dss.cols, dss.rows, dss.plane));
    let pix = origin + mix(rmin, rmax, corners[vi]);
    let big = vec2f(f32(dss.cols * dss.plane.x), f32(dss.levels * dss.rows * dss.plane.y));
    out.position = vec4f(pix.x / big.x * 2.0 - 1.0, 1.0 - pix.y / big.y * 2.0, 0.5, 1.0);
    return out;
}

struct VisibilityOut {
    @location(0) occlusion: vec4f,
    @builtin(frag_depth) depth: f32,
}

@fragment
fn fs_visibility(in: SplatVertex) -> VisibilityOut {
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
    // only disks centred above the receiver's tangent plane occlude: a disk
    // centred below it (a neighbour on the same convex or curved surface) reaches
    // into the hemisphere only by its size (BZB Fig. 9's protruding surfels)
    if (!(dot(receiver_normal(o.w), cr.xyz - o.xyz) > 0.0)) {
        discard;
    }
    let r = cr.w * f32(1u << fl);
    let t = dss_ray_disk(o.xyz, d.xyz, cr.xyz, n, r);
    if (!dss_occluding_hit(o.xyz, cr.xyz, n, t, dss.t_min)) {
        discard;
    }
    var out: VisibilityOut;
    out.occlusion = vec4f(1.0);
    // §3.2 / §4.2: squared distance over the level's largest, t ≤ outer + r
    // (normalised by this level's largest: a redirected disk is smaller)
    let m = shell.y + cr.w * f32(1u << in.level);
    out.depth = min(t * t / (m * m), 0.99999);
    return out;
}

// DSS's additive shell splatting at one fragment (the baseline without
// visibility): the form factor f of the fragment's surfel (centre c, normal
// ns) at the receiver o, 0 where the texel has no receiver, the surfel lies
// outside this level's shell or faces away.
struct DssAdditive {
    f: f32,
    o: vec3f,
    c: vec3f,
    ns: vec3f,
}

fn dss_additive(in: SplatVertex) -> DssAdditive {
    var a: DssAdditive;
    let texel = vec2i(in.position.xy);
    let o = textureLoad(origins, texel, 0);
    // without visibility the shuffle stores the receiver normal in `directions`
    let nr = textureLoad(directions, texel, 0);
    let cr = surfels[2u * in.surfel];
    a.o = o.xyz;
    a.c = cr.xyz;
    a.ns = surfels[2u * in.surfel + 1u].xyz;
    if (o.w <= 0.0) {
        return a;
    }
    let shell = dss_shell(in.level, dss.d_max);
    let v = cr.xyz - o.xyz;
    let dist = length(v);
    if (!(dist > shell.x && dist <= shell.y)) {
        return a;
    }
    let r = cr.w * f32(1u << in.level);
    a.f = dss_disk_occlusion(v, nr.xyz, a.ns, DSS_PI * r * r, dss.t_min);
    return a;
}

@fragment
fn fs_additive(in: SplatVertex) -> @location(0) vec4f {
    let a = dss_additive(in);
    if (a.f <= 0.0) {
        discard;
    }
    return vec4f(a.f);
}
