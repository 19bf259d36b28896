// Colour helpers.

fn luminance(c: vec3f) -> f32 {
    return dot(c, vec3f(0.2126, 0.7152, 0.0722));
}

// ACES filmic curve fit (Narkowicz 2015), input already exposed.
fn tonemap_aces(x: vec3f) -> vec3f {
    let a = 2.51;
    let b = 0.03;
    let c = 2.43;
    let d = 0.59;
    let e = 0.14;
    return clamp((x * (a * x + b)) / (x * (c * x + d) + e), vec3f(0.0), vec3f(1.0));
}

// DGB Eq. 7: boost(ρ) = (max ρ − min ρ) / max ρ, 0 for black.
fn boost(rho: vec3f) -> f32 {
    let mx = max(rho.r, max(rho.g, rho.b));
    if (mx <= 0.0) {
        return 0.0;
    }
    return (mx - min(rho.r, min(rho.g, rho.b))) / mx;
}
