// DGB Eq. 2: obscurance at X (normal n) due to a surface point at v = Y − X,
// with radius r, bias β and ε (CPU twin: `passes::ao::obscurance`).
fn eq2_obscurance(v: vec3f, n: vec3f, radius: f32, bias: f32, epsilon: f32) -> f32 {
    let vv = dot(v, v);
    let r2 = radius * radius;
    if (!(vv < r2)) {
        return 0.0;
    }
    return (1.0 - vv / r2) * max((dot(v, n) - bias) / sqrt(vv + epsilon), 0.0);
}
