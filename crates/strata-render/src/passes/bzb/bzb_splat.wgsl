// BZB §3.2 splatting with ambient occlusion volumes: one instance per
// (triangle, sub-image s); its vertices (pulled from the triangle storage
// buffer: wgpu has no geometry shaders) draw the back faces of a box around the
// triangle's occlusion volume {x : dist(x, T) < r}, clipped to the screen
// rectangle of T's AABB grown by r (both conservative), placed in sub-image s. Each
// covered texel tests its own ray (x_p, ω) against the triangle (`splat_hit_depth`):
//   fs_visibility (below): hit at t in (t_min, r) → depth t²/r², payload 1 for AO or
//       the triangle + 1 for bzb-gi (depth test Less, no blending: the nearest
//       triangle along ω wins); miss → discard.
//   the baselines without visibility, summed by additive blending: bzb_splat_ao.wgsl's
//       fs_additive (McGuire 2010's AOV occlusion), bzb_gi_splat.wgsl's fs_gi_additive.
// bzb_splat_compute.wgsl tests the same rectangles in a compute pass (`splat-kernel`).
// For bzb-gi, r is its d_max.
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
    // the conservative rectangle (texels of the whole bounced z-buffer, [lo, hi)):
    // fragments of the box's faces outside it are discarded (`outside_rect`)
    @location(1) @interpolate(flat) rect: vec4f,
}

// Vertices per instance: a box's 6 faces × 2 triangles (`vs_splat`).
const SPLAT_VERTICES: u32 = 36u;

// Homogeneous position in the whole bounced z-buffer (sub-image at `origin`) of world
// point q, which lies beyond the near plane: the rasteriser's division gives
// `pixel_of_world(q)` + origin.
fn splat_clip(q: vec3f, origin: vec2f, big: vec2f) -> vec4f {
    let v = q - frame.eye.xyz;
    let z = dot(v, frame.cam_forward.xyz);
    let right = frame.cam_right.xyz;
    let up = frame.cam_up.xyz;
    let a = dot(v, right) / dot(right, right);
    let b = dot(v, up) / dot(up, up);
    let px = origin.x * z + (0.5 * a + 0.5 * z) * frame.size.x;
    let py = origin.y * z + (0.5 * z - 0.5 * b) * frame.size.y;
    return vec4f(px / big.x * 2.0 - z, z - py / big.y * 2.0, 0.5 * z, z);
}

fn outside_rect(in: SplatVertex) -> bool {
    return any(in.position.xy < in.rect.xy) || any(in.position.xy >= in.rect.zw);
}

// The box around T's occlusion volume {x : dist(x, T) < r}: T's extent along one of its
// edges (axis 0) and the in-plane perpendicular (axis 1) grown by r, ±r along its normal
// (axis 2), each grown a little more against rounding at the outline; of the three
// edges, the one whose box is smallest (a right triangle's leg: its AABB when it is
// axis-aligned). Returns the centre; `axes` and `half` get the axes and half sizes.
// (McGuire's AOV are prisms around T; this is their bounding box.)
fn occlusion_box(a: vec3f, b: vec3f, c: vec3f, r: f32, axes: ptr<function, array<vec3f, 3>>, half: ptr<function, vec3f>) -> vec3f {
    let v = array<vec3f, 3>(a, b, c);
    let e2 = normalize(cross(b - a, c - a));
    var best = 1e38;
    var centre = a;
    for (var k = 0u; k < 3u; k++) {
        let p0 = v[k];
        let e0 = normalize(v[(k + 1u) % 3u] - p0);
        let e1 = cross(e2, e0);
        // the third corner's in-plane coordinates (the others are (0, 0) and (|edge|, 0))
        let q1 = v[(k + 1u) % 3u] - p0;
        let q2 = v[(k + 2u) % 3u] - p0;
        let u = vec3f(0.0, dot(q1, e0), dot(q2, e0));
        let w = dot(q2, e1);
        let lo2 = vec2f(min(min(u.x, u.y), u.z), min(0.0, w));
        let hi2 = vec2f(max(max(u.x, u.y), u.z), max(0.0, w));
        let g = r * 1.001 + 1e-4 * (hi2.x - lo2.x + hi2.y - lo2.y);
        let h = 0.5 * (hi2 - lo2) + vec2f(g);
        if (h.x * h.y < best) {
            best = h.x * h.y;
            *axes = array<vec3f, 3>(e0, e1, e2);
            *half = vec3f(h, g);
            centre = p0 + e0 * (0.5 * (lo2.x + hi2.x)) + e1 * (0.5 * (lo2.y + hi2.y));
        }
    }
    return centre;
}

// The texels of the whole bounced z-buffer, [lo, hi) as (lo, hi), that instance
// (triangle a b c, sub-image s) covers: the screen rectangle of T's AABB grown by r
// (every receiver T can occlude within r lies under it), clipped to the sub-image; an
// empty rectangle (hi ≤ lo) when T is degenerate, off screen, or (culling on) no
// receiver under it lies in its depth range.
fn splat_rect(a: vec3f, b: vec3f, c: vec3f, s: u32) -> vec4f {
    if (bzb_dot2(cross(b - a, c - a)) == 0.0) {
        return vec4f(0.0);
    }
    let lo = min(min(a, b), c) - vec3f(bzb.radius);
    let hi = max(max(a, b), c) + vec3f(bzb.radius);
    let size = frame.size.xy;
    // the camera-depth range of the grown box: every receiver it can occlude is in it
    let sb = screen_box(frame, lo, hi);
    if (!sb.visible) {
        return vec4f(0.0);
    }
    let rmin = clamp(floor(sb.rmin) - 1.0, vec2f(0.0), size);
    let rmax = clamp(ceil(sb.rmax) + 1.0, vec2f(0.0), size);
    if (any(rmax <= rmin)) {
        return vec4f(0.0);
    }
    // issue 13 item 4: no receiver under the splat within its depth range
    if (bzb.culling == 1u && !receivers_in_range(vec2u(size), rmin, rmax, sb.zlo, sb.zhi)) {
        return vec4f(0.0);
    }
    let origin = vec2f(bzb_tile_origin(s, bzb.cols, vec2u(size)));
    return vec4f(origin + rmin, origin + rmax);
}

// Vertex vi of instance ii (triangle t = ii / S, sub-image s = ii % S): the faces of
// `occlusion_box` that look away from the camera, which cover the box's screen outline
// once without overlap (the others are dropped). Where a box corner lies before the near
// plane the instance falls back to the screen rectangle of T's grown AABB (vertices
// 0–5). Fragments are clipped to that rectangle in either case (`rect`).
@vertex
fn vs_splat(@builtin(vertex_index) vi: u32, @builtin(instance_index) ii: u32) -> SplatVertex {
    var out: SplatVertex;
    let tri = ii / bzb.directions;
    let s = ii % bzb.directions;
    out.triangle = tri;
    // degenerate (no fragments) unless the rectangle is non-empty
    out.position = vec4f(-2.0, -2.0, 0.5, 1.0);
    out.rect = vec4f(0.0);
    let a = triangles[3u * tri].xyz;
    let b = triangles[3u * tri + 1u].xyz;
    let c = triangles[3u * tri + 2u].xyz;
    let rect = splat_rect(a, b, c, s);
    if (any(rect.zw <= rect.xy)) {
        return out;
    }
    let size = frame.size.xy;
    let origin = vec2f(bzb_tile_origin(s, bzb.cols, vec2u(size)));
    let big = size * vec2f(f32(bzb.cols), f32(bzb.rows));
    out.rect = rect;
    var axes: array<vec3f, 3>;
    var half: vec3f;
    var centre = a;
    // the box only for box splats (rectangles, the default, skip its cost)
    var box_ok = bzb.box_splats != 0u;
    if (box_ok) {
        centre = occlusion_box(a, b, c, bzb.radius, &axes, &half);
    }
    for (var k = 0u; k < 8u && box_ok; k++) {
        let q = centre + axes[0] * select(-half.x, half.x, (k & 1u) != 0u)
            + axes[1] * select(-half.y, half.y, (k & 2u) != 0u)
            + axes[2] * select(-half.z, half.z, (k & 4u) != 0u);
        box_ok = box_ok && csz_of(frame, q) > frame.eye.w;
    }
    // corners of two triangles: (0,0) (1,0) (0,1) / (0,1) (1,0) (1,1)
    var corners = array<vec2f, 6>(vec2f(0.0, 0.0), vec2f(1.0, 0.0), vec2f(0.0, 1.0), vec2f(0.0, 1.0), vec2f(1.0, 0.0), vec2f(1.0, 1.0));
    let corner = corners[vi % 6u];
    if (!box_ok) {
        if (vi < 6u) {
            let pix = mix(rect.xy, rect.zw, corner);
            out.position = vec4f(pix.x / big.x * 2.0 - 1.0, 1.0 - pix.y / big.y * 2.0, 0.5, 1.0);
        }
        return out;
    }
    // face f = vi / 6: axis f / 2, side ±; drawn when the camera is on its inner side
    let f = vi / 6u;
    let k = f / 2u;
    let sgn = select(-1.0, 1.0, (f & 1u) != 0u);
    let m = axes[k] * sgn;
    let face = centre + m * half[k];
    if (dot(m, frame.eye.xyz - face) >= 0.0) {
        return out;
    }
    let k1 = (k + 1u) % 3u;
    let k2 = (k + 2u) % 3u;
    let q = face + axes[k1] * (half[k1] * (2.0 * corner.x - 1.0)) + axes[k2] * (half[k2] * (2.0 * corner.y - 1.0));
    out.position = splat_clip(q, origin, big);
    return out;
}

fn load_triangle(tri: u32) -> array<vec3f, 3> {
    return array<vec3f, 3>(triangles[3u * tri].xyz, triangles[3u * tri + 1u].xyz, triangles[3u * tri + 2u].xyz);
}

// The bounced z-buffer's depth of triangle `tri` at `texel`: t²/d_max² (§3.2's squared
// distance scaled by d_max², in [0, 1); d_max = r for AO, bzb-gi's d_max for GI) when the
// texel's ray (x_p, ω) hits it at t in (t_min, d_max); -1 otherwise. The test of both
// forms: the fragment entries (bzb_splat_ao.wgsl, bzb_gi_splat.wgsl) and the compute
// pass (bzb_splat_compute.wgsl).
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

// What a hit writes besides its depth: 1 for AO's binary occlusion (the estimator of
// §3.3 divides by α), or, with HIT_INDEX, the hit triangle + 1 for bzb-gi-hit (exact in
// f32 below 2^24 triangles; `bzb-gi-shade` computes its radiance).
override HIT_INDEX: bool = false;

struct VisibilityOut {
    @location(0) payload: vec4f,
    @builtin(frag_depth) depth: f32,
}

// With visibility (§3.2): a hit writes its depth and payload (depth test Less, no
// blending: the nearest triangle along ω wins); a miss discards.
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
    out.payload = select(vec4f(1.0), vec4f(f32(in.triangle + 1u)), HIT_INDEX);
    out.depth = z;
    return out;
}
