// BZB §3.2 splatting with ambient occlusion volumes: one instance per
// (triangle, sub-image s); its 6 vertices (pulled from the triangle storage
// buffer: wgpu has no geometry shaders) span the screen rectangle of the
// triangle's AABB grown by r, a conservative bound of its occlusion volume
// {x : dist(x, T) < r}, placed in sub-image s. Each covered texel tests its own
// ray (x_p, ω) against the triangle:
//   fs_visibility: hit at t in (t_min, r) → depth t²/r², payload 1 (depth test
//                  Less, no blending: the nearest occluder along ω wins); miss → discard.
//   fs_additive:   the analytic AOV occlusion, summed by additive blending (McGuire 2010).
#import "common/camera.wgsl"
#import "common/packing.wgsl"
#import "common/zminmax.wgsl"

@group(0) @binding(0) var<uniform> frame: Frame;
@group(1) @binding(0) var<uniform> bzb: Bzb;
// 3 vec4 per triangle: world-space vertices a, b, c (w unused)
@group(1) @binding(1) var<storage, read> triangles: array<vec4f>;
@group(1) @binding(2) var origins: texture_2d<f32>;
@group(1) @binding(3) var directions: texture_2d<f32>;
@group(1) @binding(4) var npack: texture_2d<f32>;
// min/max receiver depth per tile (bzb_zminmax.wgsl)
@group(1) @binding(5) var<storage, read> tiles: array<vec2f>;

struct SplatVertex {
    @builtin(position) position: vec4f,
    @location(0) @interpolate(flat) triangle: u32,
}

@vertex
fn vs_splat(@builtin(vertex_index) vi: u32, @builtin(instance_index) ii: u32) -> SplatVertex {
    var out: SplatVertex;
    let tri = ii / bzb.directions;
    let s = ii % bzb.directions;
    out.triangle = tri;
    // degenerate (no fragments) unless the rectangle is non-empty
    out.position = vec4f(-2.0, -2.0, 0.5, 1.0);
    let a = triangles[3u * tri].xyz;
    let b = triangles[3u * tri + 1u].xyz;
    let c = triangles[3u * tri + 2u].xyz;
    if (bzb_dot2(cross(b - a, c - a)) == 0.0) {
        return out;
    }
    let lo = min(min(a, b), c) - vec3f(bzb.radius);
    let hi = max(max(a, b), c) + vec3f(bzb.radius);
    let size = frame.size.xy;
    // the camera-depth range of the grown box: every receiver it can occlude is in it
    let sb = screen_box(frame, lo, hi);
    if (!sb.visible) {
        return out;
    }
    let rmin = clamp(floor(sb.rmin) - 1.0, vec2f(0.0), size);
    let rmax = clamp(ceil(sb.rmax) + 1.0, vec2f(0.0), size);
    if (any(rmax <= rmin)) {
        return out;
    }
    // issue 13 item 4: no receiver under the splat within its depth range
    if (bzb.culling == 1u && !receivers_in_range(vec2u(size), rmin, rmax, sb.zlo, sb.zhi)) {
        return out;
    }
    // corners of two triangles: (0,0) (1,0) (0,1) / (0,1) (1,0) (1,1)
    var corners = array<vec2f, 6>(vec2f(0.0, 0.0), vec2f(1.0, 0.0), vec2f(0.0, 1.0), vec2f(0.0, 1.0), vec2f(1.0, 0.0), vec2f(1.0, 1.0));
    let corner = corners[vi];
    let origin = vec2f(bzb_tile_origin(s, bzb.cols, vec2u(size)));
    let pix = origin + mix(rmin, rmax, corner);
    let big = size * vec2f(f32(bzb.cols), f32(bzb.rows));
    out.position = vec4f(pix.x / big.x * 2.0 - 1.0, 1.0 - pix.y / big.y * 2.0, 0.5, 1.0);
    return out;
}

struct VisibilityOut {
    @location(0) occlusion: vec4f,
    @builtin(frag_depth) depth: f32,
}

fn load_triangle(tri: u32) -> array<vec3f, 3> {
    return array<vec3f, 3>(triangles[3u * tri].xyz, triangles[3u * tri + 1u].xyz, triangles[3u * tri + 2u].xyz);
}

@fragment
fn fs_visibility(in: SplatVertex) -> VisibilityOut {
    let texel = vec2i(in.position.xy);
    let o = textureLoad(origins, texel, 0);
    let d = textureLoad(directions, texel, 0);
    if (d.w <= 0.0) {
        discard;
    }
    let v = load_triangle(in.triangle);
    let t = bzb_ray_triangle(o.xyz, d.xyz, v[0], v[1], v[2]);
    if (!(t > bzb.t_min && t < bzb.radius)) {
        discard;
    }
    var out: VisibilityOut;
    // AO payload: binary occlusion (the estimator of §3.3 divides by α)
    out.occlusion = vec4f(1.0);
    // §3.2: squared distance scaled by d_max² = r² keeps z in [0, 1)
    out.depth = t * t * bzb.inv_r2;
    return out;
}

@fragment
fn fs_additive(in: SplatVertex) -> @location(0) vec4f {
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
