// Bounced z-buffer (BZB, Nalbach et al. 2016) functions shared by its passes and
// mirrored on the CPU by `passes::bzb` (same hash, same formulas): the bounced
// directions of §3.1, the single-primitive ray test of §3.2 and the analytic
// ambient-occlusion-volume term of the no-visibility baseline (McGuire 2010).
// Prepended (Rust `concat!`) to bzb_directions/splat/reconstruct.wgsl.
#import "common/frame.wgsl"
#import "common/spiral.wgsl"
#import "common/bzb_geometry.wgsl"
#import "common/camera.wgsl"
#import "common/packing.wgsl"

const BZB_PI: f32 = 3.14159265358979;

// Matches `bzb::BzbUniforms`.
struct Bzb {
    // AO radius r (= d_max of §3.2), ray t_min (bias), 1 / r²
    radius: f32,
    t_min: f32,
    inv_r2: f32,
    // bzb-gi: 1 = a ray that hits no sender within d_max has left the scene (d_max ≥
    // the scene's diagonal) and brings the sky's radiance (`frame.sky`); 0 = nothing
    escape_sky: u32,
    // S directions per pixel, sub-image grid cols × rows (S <= cols·rows)
    directions: u32,
    cols: u32,
    rows: u32,
    seed: u32,
    // 0 = cosine-weighted, 1 = uniform hemisphere
    hemisphere: u32,
    // 1 = bounced z-buffer (depth test), 0 = additive AOV baseline
    visibility: u32,
    triangles: u32,
    // 1 = splats whose depth range misses every receiver under them are culled
    culling: u32,
    // 1 = AOV splats draw the box around the occlusion volume, 0 = its screen
    // rectangle only (bzb_splat.wgsl)
    box_splats: u32,
}

// §3.1 / Fig. 5: direction s of pixel p lives in sub-image s; sub-image s is the
// (W×H) tile at (s % cols, s / cols) of the bounced z-buffer.
fn bzb_tile_origin(s: u32, cols: u32, size: vec2u) -> vec2u {
    return vec2u(s % cols, s / cols) * size;
}

// The bounced z-buffer's texel at fragment position `pos`: sub-image s, pixel p, and
// layer 0's x_p and n_p there (§3.1); `ok` is false past the last direction and on the
// background.
struct BzbTexel {
    ok: bool,
    s: u32,
    p: vec2u,
    x: vec3f,
    n: vec3f,
}

fn bzb_texel(f: Frame, u: Bzb, pos: vec2f, zpack: texture_2d<f32>, npack: texture_2d<f32>) -> BzbTexel {
    var o: BzbTexel;
    let size = vec2u(f.size.xy);
    let texel = vec2u(pos);
    let tile = texel / size;
    o.s = tile.y * u.cols + tile.x;
    o.p = texel % size;
    if (o.s >= u.directions) {
        return o;
    }
    let z = textureLoad(zpack, vec2i(o.p), 0).r;
    if (z <= 0.0) {
        return o;
    }
    o.n = oct_decode(textureLoad(npack, vec2i(o.p), 0).rg);
    o.x = world_from_csz(f, vec2f(o.p) + 0.5, z);
    o.ok = true;
    return o;
}

// Two uniforms in [0, 1) from a hash of (pixel, direction index, seed); 24 bits
// each, exactly representable, identical on the CPU (`bzb::sample_uniforms`).
fn bzb_sample_uniforms(p: vec2u, s: u32, seed: u32) -> vec2f {
    let h1 = pcg_hash(p.x + pcg_hash(p.y + pcg_hash(s + pcg_hash(seed))));
    let h2 = pcg_hash(h1 ^ 0x9e3779b9u);
    return vec2f(f32(h1 >> 8u), f32(h2 >> 8u)) * (1.0 / 16777216.0);
}

// §3.1: ω on the hemisphere around n (xyz) and its pdf α (w), per solid angle.
fn bzb_direction(n: vec3f, u: vec2f, hemisphere: u32) -> vec4f {
    let phi = 2.0 * BZB_PI * u.y;
    var l: vec3f;
    var pdf: f32;
    if (hemisphere == 0u) {
        // cosine-weighted: α = cos θ / π
        let r = sqrt(u.x);
        l = vec3f(r * cos(phi), r * sin(phi), sqrt(max(0.0, 1.0 - u.x)));
        pdf = l.z / BZB_PI;
    } else {
        // uniform: α = 1 / (2π)
        let r = sqrt(max(0.0, 1.0 - u.x * u.x));
        l = vec3f(r * cos(phi), r * sin(phi), u.x);
        pdf = 0.5 / BZB_PI;
    }
    // orthonormal basis around n (Duff et al. 2017)
    let sgn = select(-1.0, 1.0, n.z >= 0.0);
    let a = -1.0 / (sgn + n.z);
    let b = n.x * n.y * a;
    let t = vec3f(1.0 + sgn * n.x * n.x * a, sgn * b, -sgn * n.x);
    let bt = vec3f(b, sgn + n.y * n.y * a, -n.y);
    return vec4f(t * l.x + bt * l.y + n * l.z, pdf);
}

// §3.2's single-primitive intersection (Möller–Trumbore, both faces): the ray
// parameter t of o + t·d on triangle (a, b, c), or -1 on a miss.
fn bzb_ray_triangle(o: vec3f, d: vec3f, a: vec3f, b: vec3f, c: vec3f) -> f32 {
    let e1 = b - a;
    let e2 = c - a;
    let pv = cross(d, e2);
    let det = dot(e1, pv);
    if (det == 0.0) {
        return -1.0;
    }
    let inv = 1.0 / det;
    let tv = o - a;
    let u = dot(tv, pv) * inv;
    if (u < 0.0 || u > 1.0) {
        return -1.0;
    }
    let qv = cross(tv, e1);
    let v = dot(d, qv) * inv;
    if (v < 0.0 || u + v > 1.0) {
        return -1.0;
    }
    return dot(e2, qv) * inv;
}

// Form-factor term of one polygon edge seen from x (unit normal n):
// angle(u0, u1) · n·normalize(u0 × u1), with u = unit vectors towards the vertices.
fn bzb_edge_term(n: vec3f, v0: vec3f, v1: vec3f) -> f32 {
    let u0 = normalize(v0);
    let u1 = normalize(v1);
    let c = cross(u0, u1);
    let len = length(c);
    if (len <= 1e-12) {
        return 0.0;
    }
    let angle = atan2(len, dot(u0, u1));
    return angle * dot(n, c) / len;
}

// Point-to-polygon form factor of triangle (a, b, c) seen from x (normal n), clipped
// to x's hemisphere above height β (the bias: T's own plane never occludes):
// (1/2π)|Σ edge terms| of the clipped polygon. bzb-gi's additive baseline uses it bare.
fn bzb_clipped_form_factor(x: vec3f, n: vec3f, a: vec3f, b: vec3f, c: vec3f, beta: f32) -> f32 {
    // clip the triangle (relative to x) to n·v >= β (Sutherland–Hodgman, ≤ 4 vertices)
    var v = array<vec3f, 3>(a - x, b - x, c - x);
    var poly: array<vec3f, 4>;
    var count = 0u;
    for (var i = 0u; i < 3u; i++) {
        let p = v[i];
        let q = v[(i + 1u) % 3u];
        let hp = dot(n, p) - beta;
        let hq = dot(n, q) - beta;
        if (hp >= 0.0) {
            poly[count] = p;
            count++;
        }
        if ((hp >= 0.0) != (hq >= 0.0)) {
            poly[count] = p + (q - p) * (hp / (hp - hq));
            count++;
        }
    }
    if (count < 3u) {
        return 0.0;
    }
    var sum = 0.0;
    for (var i = 0u; i < count; i++) {
        sum += bzb_edge_term(n, poly[i], poly[(i + 1u) % count]);
    }
    return min(1.0, abs(sum) / (2.0 * BZB_PI));
}

// The no-visibility baseline's analytic AOV occlusion of triangle (a, b, c) at x
// (normal n): 0 outside the volume {dist(x, T) < r}; inside, the clipped form factor
// (`bzb_clipped_form_factor`) times the falloff 1 − (h/r)² with h the distance from x
// to T's plane (exact binary AO within r of an infinite plane).
fn bzb_aov_occlusion(x: vec3f, n: vec3f, a: vec3f, b: vec3f, c: vec3f, r: f32, beta: f32) -> f32 {
    if (!(bzb_triangle_dist2(x, a, b, c) < r * r)) {
        return 0.0;
    }
    let ff = bzb_clipped_form_factor(x, n, a, b, c, beta);
    if (ff == 0.0) {
        return 0.0;
    }
    let nor = normalize(cross(b - a, c - a));
    let h = abs(dot(nor, x - a));
    let falloff = max(0.0, 1.0 - h * h / (r * r));
    return ff * falloff;
}
