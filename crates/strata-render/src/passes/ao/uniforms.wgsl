// The DGB AO pass's uniforms, shared by ao.wgsl and ao_deint.wgsl.
// Matches `ao::AoUniforms`.
struct Ao {
    // r (world units), β, ε, intensity
    radius: f32,
    bias: f32,
    epsilon: f32,
    intensity: f32,
    // pixels spanned by 1 world unit at depth 1; q; τ
    proj_scale: f32,
    q: f32,
    tau: f32,
    // 1 = rotate the spiral per pixel (φ from the hash), 0 = φ = 0
    rotate: u32,
    samples: u32,
    max_mip: u32,
    seed: u32,
    // 1: return the obscurance mean S (Eq. 1 before the square root) instead of AV
    output_obscurance: u32,
}
