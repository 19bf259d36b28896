// Geometry shared by the bounced z-buffer's AOV splats (passes/bzb/bzb.wgsl)
// and its DSS surfelization (common/dss.wgsl); CPU twin `bzb::triangle_dist2`.

fn bzb_dot2(v: vec3f) -> f32 {
    return dot(v, v);
}

// Squared distance from p to triangle (a, b, c) (non-degenerate).
fn bzb_triangle_dist2(p: vec3f, a: vec3f, b: vec3f, c: vec3f) -> f32 {
    let ba = b - a;
    let pa = p - a;
    let cb = c - b;
    let pb = p - b;
    let ac = a - c;
    let pc = p - c;
    let nor = cross(ba, ac);
    let outside = sign(dot(cross(ba, nor), pa)) + sign(dot(cross(cb, nor), pb)) + sign(dot(cross(ac, nor), pc)) < 2.0;
    if (outside) {
        let ea = bzb_dot2(ba * clamp(dot(ba, pa) / bzb_dot2(ba), 0.0, 1.0) - pa);
        let eb = bzb_dot2(cb * clamp(dot(cb, pb) / bzb_dot2(cb), 0.0, 1.0) - pb);
        let ec = bzb_dot2(ac * clamp(dot(ac, pc) / bzb_dot2(ac), 0.0, 1.0) - pc);
        return min(min(ea, eb), ec);
    }
    let h = dot(nor, pa);
    return h * h / bzb_dot2(nor);
}
