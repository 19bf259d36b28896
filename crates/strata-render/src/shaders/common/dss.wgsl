// Deep screen space (DSS, Nalbach et al. 2014) with the bounced z-buffer (BZB
// §4): surfelization (§4.3, Fig. 6), the interleaved hierarchical framebuffer
// (§4.1, Fig. 5) and the ray–disk test of shell splatting with visibility
// (§4.2). Mirrored on the CPU by `passes::bzb::dss` (same hashes, same formulas).
#import "common/frame.wgsl"
#import "common/spiral.wgsl"
#import "common/bzb_geometry.wgsl"

const DSS_PI: f32 = 3.14159265358979;

// Matches `dss::DssUniforms`.
struct Dss {
    // l_max levels, S directions, direction grid cols × rows
    levels: u32,
    directions: u32,
    cols: u32,
    rows: u32,
    // frame W × H and the padded plane Wp × Hp (multiples of 2^(l_max − 1))
    size: vec2u,
    plane: vec2u,
    // d_max (level 0's outer shell radius), ray t_min, surfel radius in pixels,
    // fine surfels' target area as a fraction of the ideal area A*
    d_max: f32,
    t_min: f32,
    surfel_px: f32,
    fine_ratio: f32,
    // fine surfels per (sub-)triangle at most, capacities of the three buffers
    max_fine: u32,
    tri_capacity: u32,
    fine_capacity: u32,
    surfel_capacity: u32,
    seed: u32,
    // 1 = bounced z-buffer (depth test), 0 = additive shell splatting
    visibility: u32,
    // 1 = view-frustum culling of triangles (margin: the largest shell radius)
    culling: u32,
    triangles: u32,
    // largest pre-tessellation factor m (m² sub-triangles per triangle)
    max_split: u32,
    // 1 = bzb-gi: RGBA radiance payload, hit flag in alpha (0 = bzb-ao occlusion)
    gi: u32,
    // 1 = shells whose depth range misses every receiver under them are culled (§4.3)
    depth_culling: u32,
    // 1 = inner-shell fragments redirected to their level (§4.3), 0 = discarded
    redirect: u32,
}

// Hash of a world position (§4.3: "hash this position"): bit patterns of x, y, z.
fn dss_hash3(q: vec3f, seed: u32) -> u32 {
    return pcg_hash(bitcast<u32>(q.x) ^ pcg_hash(bitcast<u32>(q.y) ^ pcg_hash(bitcast<u32>(q.z) ^ pcg_hash(seed))));
}

// 24-bit uniform in [0, 1) from a hash.
fn dss_unit(h: u32) -> f32 {
    return f32(h >> 8u) * (1.0 / 16777216.0);
}

// Uniform point on triangle (a, b, c) from two uniforms (square-root warp).
fn dss_triangle_point(a: vec3f, b: vec3f, c: vec3f, u: vec2f) -> vec3f {
    let su = sqrt(u.x);
    return a * (1.0 - su) + b * (su * (1.0 - u.y)) + c * (su * u.y);
}

// §4.1, Fig. 5: the permutation of the 4^l pixels of neighbourhood `nb` of
// level l among the level's 4^l sub-images: sub-image k receives pixel
// σ(k) = (a·(k ⊕ c) + b) mod 4^l of the neighbourhood (a odd: a bijection; each
// sub-image gets a uniformly random pixel). `inverse` gives k from σ.
fn dss_layout_keys(nb: vec2u, level: u32, s: u32, seed: u32) -> vec3u {
    let h = pcg_hash(nb.x ^ pcg_hash(nb.y ^ pcg_hash(level ^ pcg_hash(s ^ pcg_hash(seed ^ 0x5bd1e995u)))));
    let h2 = pcg_hash(h);
    let h3 = pcg_hash(h2);
    return vec3u(h | 1u, h2, h3);
}

fn dss_sigma(k: u32, nb: vec2u, level: u32, s: u32, seed: u32) -> u32 {
    let mask = (1u << (2u * level)) - 1u;
    let key = dss_layout_keys(nb, level, s, seed);
    return (key.x * ((k ^ key.z) & mask) + key.y) & mask;
}

fn dss_sigma_inverse(j: u32, nb: vec2u, level: u32, s: u32, seed: u32) -> u32 {
    let mask = (1u << (2u * level)) - 1u;
    let key = dss_layout_keys(nb, level, s, seed);
    // inverse of the odd a modulo 2^32 (Newton: x ← x (2 − a x))
    var inv = key.x;
    for (var i = 0u; i < 5u; i++) {
        inv = inv * (2u - key.x * inv);
    }
    return ((inv * (j - key.y)) & mask) ^ (key.z & mask);
}

// The stacked DSS framebuffer: level l is the band of rows·Hp rows at
// y = l·rows·Hp; in it direction s is the Wp × Hp tile (s % cols, s / cols), and
// in that tile sub-image k of level l is the (Wp/2^l × Hp/2^l) block
// (k % 2^l, k / 2^l). Texel of neighbourhood `nb` of sub-image k:
fn dss_texel(level: u32, s: u32, k: u32, nb: vec2u, cols: u32, rows: u32, plane: vec2u) -> vec2u {
    let b = 1u << level;
    let sub = plane / b;
    return vec2u(0u, level * rows * plane.y) + vec2u(s % cols, s / cols) * plane + vec2u(k % b, k / b) * sub + nb;
}

// §4.2: ray o + t·d against the disk (centre c, unit normal n, radius r), both
// faces: t, or -1 on a miss (parallel ray or outside the disk).
fn dss_ray_disk(o: vec3f, d: vec3f, c: vec3f, n: vec3f, r: f32) -> f32 {
    let dn = dot(d, n);
    if (abs(dn) < 1e-8) {
        return -1.0;
    }
    let t = dot(c - o, n) / dn;
    let q = o + t * d - c;
    if (dot(q, q) > r * r) {
        return -1.0;
    }
    return t;
}

// A hit occludes when it lies past t_min and the disk's plane does not pass
// within DSS_COPLANAR·t_min of the receiver: such a disk holds the receiver's
// own surface, and a receiver reconstructed a few 1e-5 off it (NVIDIA 580;
// lavapipe reconstructs it on the plane) would see it hit at grazing angles.
// Rust twin: dss::occluding_hit, dss::COPLANAR.
const DSS_COPLANAR: f32 = 0.1;

fn dss_occluding_hit(o: vec3f, c: vec3f, ns: vec3f, t: f32, t_min: f32) -> bool {
    return t > t_min && abs(dot(c - o, ns)) > DSS_COPLANAR * t_min;
}

// Shell of level l around a surfel (§4.1): (inner, outer] = (0, d_max] on
// level 0, (d_max·2^(l−1), d_max·2^l] above.
fn dss_shell(level: u32, d_max: f32) -> vec2f {
    let outer = d_max * f32(1u << level);
    return vec2f(select(0.5 * outer, 0.0, level == 0u), outer);
}

const DSS_NO_LEVEL: u32 = 0xffffffffu;

// The level whose disk radius a fragment of the level-`level` splat uses for a
// receiver at distance `dist` from the surfel, or DSS_NO_LEVEL (discard): `level`
// inside its shell; with `redirect` (§4.3, "more efficient use of fill rate") the
// finer level whose shell holds a receiver inside the inner radius, instead of the
// original DSS discard. Rust twin: dss::fragment_level.
fn dss_fragment_level(dist: f32, level: u32, d_max: f32, redirect: bool) -> u32 {
    let shell = dss_shell(level, d_max);
    if (dist > shell.x && dist <= shell.y) {
        return level;
    }
    if (!redirect || !(dist > 0.0) || dist > shell.x) {
        return DSS_NO_LEVEL;
    }
    for (var l = 0u; l < level; l++) {
        if (dist <= dss_shell(l, d_max).y) {
            return l;
        }
    }
    return DSS_NO_LEVEL;
}

// The original DSS AO term of one disk (area A, normal ns, centre at v = c − x
// from the receiver, receiver normal n): the disk-to-point form factor
// A cos θ_r |cos θ_s| / (π |v|² + A), 0 below the receiver's horizon (+ bias).
fn dss_disk_occlusion(v: vec3f, n: vec3f, ns: vec3f, area: f32, bias: f32) -> f32 {
    let d2 = dot(v, v);
    let h = dot(n, v);
    if (h <= bias || d2 <= 0.0) {
        return 0.0;
    }
    let inv = inverseSqrt(d2);
    return area * (h * inv) * abs(dot(ns, v) * inv) / (DSS_PI * d2 + area);
}
