// BZB §4.3 surfelization (Fig. 6) as compute passes (wgpu has no tessellation
// or geometry shaders, so no transform feedback either: stages append to
// storage buffers with atomic counters).
//   cs_tessellate (Fig. 6a): per scene triangle, view-frustum culling with a
//       safety margin, then pre-tessellation into m² sub-triangles so that none
//       needs more than max_fine fine surfels.
//   cs_fine (Fig. 6b): per sub-triangle, N fine surfels of area A/N ≤ fine_ratio·A*;
//       each takes the world position of a regular pattern point, hashes it and
//       is placed uniformly at random on the sub-triangle from that hash.
//   cs_filter (Fig. 6c): per fine surfel, discard with probability
//       max(1 − A/A*, 0); survivors get the ideal radius r* (constant projected size).
//   cs_args: the splat pass's indirect draw arguments (6 vertices, surfels·L·S instances).
// Mirrored on the CPU by `dss::surfelize`.
#import "common/dss.wgsl"

@group(0) @binding(0) var<uniform> frame: Frame;
@group(1) @binding(0) var<uniform> dss: Dss;
// 3 vec4 per scene triangle (world space)
@group(1) @binding(1) var<storage, read> triangles: array<vec4f>;
// 3 vec4 per sub-triangle
@group(1) @binding(2) var<storage, read_write> subtris: array<vec4f>;
// 2 vec4 per fine surfel: (position, area), (normal, 0)
@group(1) @binding(3) var<storage, read_write> fine: array<vec4f>;
// 2 vec4 per surfel: (position, radius), (normal, 0)
@group(1) @binding(4) var<storage, read_write> surfels: array<vec4f>;
// 0: sub-triangles, 1: fine surfels, 2: surfels, 3: triangles after culling
@group(1) @binding(5) var<storage, read_write> counters: array<atomic<u32>, 8>;
// draw_indirect arguments: vertex count, instance count, first vertex, first instance
@group(1) @binding(6) var<storage, read_write> args: array<u32, 4>;

// World-space radius of a pixel at camera depth 1 (2 tan(fov_y/2) / H).
fn pixel_scale() -> f32 {
    return 2.0 * length(frame.cam_up.xyz) / frame.size.y;
}

// Distance of q from the eye, at least the near plane's: the ideal size uses
// the distance, not the camera depth, so that surfels beside and behind the
// camera (occluders of visible receivers within the frustum margin) get sizes
// that grow with distance too (a depth clamped to the near plane would make
// them tiny and numerous). In view the two differ by 1/cos of the off-axis angle.
fn depth_of(q: vec3f) -> f32 {
    return max(distance(q, frame.eye.xyz), frame.eye.w);
}

// Ideal surfel area A* at eye distance z: a disk of surfel_px pixels' radius.
fn ideal_area(z: f32) -> f32 {
    let r = dss.surfel_px * z * pixel_scale();
    return DSS_PI * r * r;
}

fn tri_area(a: vec3f, b: vec3f, c: vec3f) -> f32 {
    return 0.5 * length(cross(b - a, c - a));
}

// Smallest eye distance over the triangle (clamped to the near plane).
fn min_depth(a: vec3f, b: vec3f, c: vec3f) -> f32 {
    return max(sqrt(bzb_triangle_dist2(frame.eye.xyz, a, b, c)), frame.eye.w);
}

// Fine surfels of a (sub-)triangle: ceil(A / (fine_ratio · A*(z_min))).
fn fine_count(a: vec3f, b: vec3f, c: vec3f) -> f32 {
    return ceil(tri_area(a, b, c) / (dss.fine_ratio * ideal_area(min_depth(a, b, c))));
}

// Whether the bounding sphere of the triangle grown by `margin` meets the view frustum.
fn in_frustum(a: vec3f, b: vec3f, c: vec3f, margin: f32) -> bool {
    let m = (a + b + c) / 3.0;
    let rad = sqrt(max(max(dot(a - m, a - m), dot(b - m, b - m)), dot(c - m, c - m))) + margin;
    let v = m - frame.eye.xyz;
    let f = frame.cam_forward.xyz;
    let z = dot(v, f);
    if (z < frame.eye.w - rad) {
        return false;
    }
    // side planes through the eye: unit normals (pointing out) from the frustum's half-extents
    let tx = length(frame.cam_right.xyz);
    let ty = length(frame.cam_up.xyz);
    let r = frame.cam_right.xyz / tx;
    let u = frame.cam_up.xyz / ty;
    let x = dot(v, r);
    let y = dot(v, u);
    let kx = inverseSqrt(1.0 + tx * tx);
    let ky = inverseSqrt(1.0 + ty * ty);
    return (x - tx * z) * kx <= rad && (-x - tx * z) * kx <= rad && (y - ty * z) * ky <= rad && (-y - ty * z) * ky <= rad;
}

@compute @workgroup_size(64)
fn cs_tessellate(@builtin(global_invocation_id) gid: vec3u) {
    let t = gid.x;
    if (t >= dss.triangles) {
        return;
    }
    let a = triangles[3u * t].xyz;
    let b = triangles[3u * t + 1u].xyz;
    let c = triangles[3u * t + 2u].xyz;
    if (tri_area(a, b, c) <= 0.0) {
        return;
    }
    // safety margin: the outermost shell radius d_max·2^(l_max − 1)
    if (dss.culling == 1u && !in_frustum(a, b, c, dss.d_max * f32(1u << (dss.levels - 1u)))) {
        return;
    }
    atomicAdd(&counters[3], 1u);
    // m² congruent sub-triangles, m = ⌈√(N / max_fine)⌉
    let n = fine_count(a, b, c);
    let m = min(u32(ceil(sqrt(n / f32(dss.max_fine)))), dss.max_split);
    let m1 = max(m, 1u);
    let fm = f32(m1);
    let e1 = (b - a) / fm;
    let e2 = (c - a) / fm;
    for (var i = 0u; i < m1; i++) {
        for (var j = 0u; i + j < m1; j++) {
            let p = a + f32(i) * e1 + f32(j) * e2;
            // upright sub-triangle, then (except on the diagonal) the inverted one
            let two = select(1u, 2u, i + j + 1u < m1);
            for (var q = 0u; q < two; q++) {
                let idx = atomicAdd(&counters[0], 1u);
                if (idx < dss.tri_capacity) {
                    if (q == 0u) {
                        subtris[3u * idx] = vec4f(p, f32(t));
                        subtris[3u * idx + 1u] = vec4f(p + e1, 0.0);
                        subtris[3u * idx + 2u] = vec4f(p + e2, 0.0);
                    } else {
                        subtris[3u * idx] = vec4f(p + e1, f32(t));
                        subtris[3u * idx + 1u] = vec4f(p + e1 + e2, 0.0);
                        subtris[3u * idx + 2u] = vec4f(p + e2, 0.0);
                    }
                }
            }
        }
    }
}

@compute @workgroup_size(64)
fn cs_fine(@builtin(global_invocation_id) gid: vec3u) {
    let t = gid.x;
    if (t >= min(atomicLoad(&counters[0]), dss.tri_capacity)) {
        return;
    }
    let a = subtris[3u * t].xyz;
    let b = subtris[3u * t + 1u].xyz;
    let c = subtris[3u * t + 2u].xyz;
    let n = u32(clamp(fine_count(a, b, c), 1.0, f32(dss.max_fine)));
    let area = tri_area(a, b, c) / f32(n);
    let nor = normalize(cross(b - a, c - a));
    for (var k = 0u; k < n; k++) {
        // the pattern point (what the tessellator would emit): a stratified
        // barycentric sample, k-th of n (golden-ratio sequence)
        let g = vec2f((f32(k) + 0.5) / f32(n), fract((f32(k) + 0.5) * 0.618034));
        let q = dss_triangle_point(a, b, c, g);
        // §4.3: hash the world position into the random placement on the triangle
        let h = dss_hash3(q, dss.seed);
        let u = vec2f(dss_unit(h), dss_unit(pcg_hash(h)));
        let x = dss_triangle_point(a, b, c, u);
        let idx = atomicAdd(&counters[1], 1u);
        if (idx < dss.fine_capacity) {
            fine[2u * idx] = vec4f(x, area);
            // w: the source scene triangle index (exact in f32 below 2^24), for bzb-gi's surfel shading
            fine[2u * idx + 1u] = vec4f(nor, subtris[3u * t].w);
        }
    }
}

@compute @workgroup_size(64)
fn cs_filter(@builtin(global_invocation_id) gid: vec3u) {
    let f = gid.x;
    if (f >= min(atomicLoad(&counters[1]), dss.fine_capacity)) {
        return;
    }
    let pa = fine[2u * f];
    let a_ideal = ideal_area(depth_of(pa.xyz));
    // §4.3: discard with probability max(1 − A/A*, 0), i.e. keep with
    // probability A/A*: the survivors, enlarged to A*, keep the expected area
    // (the paper prints max(1 − A*/A, 0), which would keep every fine surfel
    // smaller than ideal and not preserve the area; see docs/bzb.md)
    let keep = dss_unit(pcg_hash(dss_hash3(pa.xyz, dss.seed ^ 0x68e31da4u)));
    if (keep >= pa.w / a_ideal) {
        return;
    }
    let idx = atomicAdd(&counters[2], 1u);
    if (idx < dss.surfel_capacity) {
        surfels[2u * idx] = vec4f(pa.xyz, sqrt(a_ideal / DSS_PI));
        surfels[2u * idx + 1u] = fine[2u * f + 1u];
    }
}

@compute @workgroup_size(1)
fn cs_args() {
    let n = min(atomicLoad(&counters[2]), dss.surfel_capacity);
    args[0] = 6u;
    args[1] = n * dss.levels * dss.directions;
    args[2] = 0u;
    args[3] = 0u;
}
