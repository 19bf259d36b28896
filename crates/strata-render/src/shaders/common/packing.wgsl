// Normal packing. Oct16: octahedral map of a unit vector to two 8-bit values
// (Cigolle et al. 2014), as the deep G-buffer's Table 1 layout uses.

fn oct_wrap(v: vec2f) -> vec2f {
    return (1.0 - abs(v.yx)) * select(vec2f(-1.0), vec2f(1.0), v.xy >= vec2f(0.0));
}

// Unit vector -> [0,1]^2 (store in two UNORM8 channels).
fn oct_encode(n: vec3f) -> vec2f {
    var p = n.xy / (abs(n.x) + abs(n.y) + abs(n.z));
    if (n.z < 0.0) {
        p = oct_wrap(p);
    }
    return p * 0.5 + 0.5;
}

// [0,1]^2 -> unit vector.
fn oct_decode(e: vec2f) -> vec3f {
    let f = e * 2.0 - 1.0;
    var n = vec3f(f.x, f.y, 1.0 - abs(f.x) - abs(f.y));
    let t = clamp(-n.z, 0.0, 1.0);
    n = vec3f(n.x + select(t, -t, n.x >= 0.0), n.y + select(t, -t, n.y >= 0.0), n.z);
    return normalize(n);
}
