// DGB §3.4 quasi-Monte Carlo spiral sampling and pixel hashing; mirrored on the
// CPU by `strata_render::spiral` (same integer hash, same formulas). τ comes from
// the pass's uniforms (Listing 3 is applied on the CPU).

const SPIRAL_TWO_PI: f32 = 6.28318530717958647;

// PCG hash (Jarzynski & Olano 2020).
fn pcg_hash(v: u32) -> u32 {
    let s = v * 747796405u + 2891336453u;
    let w = ((s >> ((s >> 28u) + 4u)) ^ s) * 277803737u;
    return (w >> 22u) ^ w;
}

// Per-pixel rotation φ in [0, 2π) from a hash of the pixel and `seed`
// (0 = fixed pattern; the frame index for temporally varying noise).
fn pixel_angle(p: vec2u, seed: u32) -> f32 {
    let h = pcg_hash(p.x + pcg_hash(p.y + pcg_hash(seed)));
    return f32(h >> 8u) * (1.0 / 16777216.0) * SPIRAL_TWO_PI;
}

// The full-resolution pixel that texel t of a gather run at 1/s resolution shades
// (`RadiositySettings::gather_scale`): one pixel of t's s×s block, the block's own hashed
// phase plus `seed` (the frame index with temporal noise) stepping through all s² pixels
// in s² frames, clamped into the image of `size` pixels. s = 1: t itself.
fn block_pixel(t: vec2u, s: u32, seed: u32, size: vec2u) -> vec2u {
    let k = (pcg_hash(t.x + pcg_hash(t.y ^ 0x68e31da4u)) + seed) % (s * s);
    return min(t * s + vec2u(k % s, k / s), size - 1u);
}

struct SpiralTap {
    // screen offset in pixels
    offset: vec2f,
    // h_i = r_p κ_i
    radius: f32,
}

// Per-pixel offset ξ in [0, 1) of the taps' radii (`spiral_tap_at`): a second hash,
// independent of `pixel_angle`'s for the same pixel and seed.
fn pixel_jitter(p: vec2u, seed: u32) -> f32 {
    let h = pcg_hash(pcg_hash(p.x + pcg_hash(p.y + pcg_hash(seed))) ^ 0x5bd1e995u);
    return f32(h >> 8u) * (1.0 / 16777216.0);
}

// The i-th of n taps: κ_i = (i + 0.5)/n, h_i = r_p κ_i, θ_i = 2π κ_i τ + φ.
fn spiral_tap(i: u32, n: u32, tau: f32, r_p: f32, phi: f32) -> SpiralTap {
    return spiral_tap_at(i, n, tau, r_p, phi, 0.5);
}

// `spiral_tap` with κ_i = (i + ξ)/n: ξ = ½ is the paper's spiral; a per-pixel, per-frame
// ξ in [0, 1) spreads each tap over its whole stratum of radii.
fn spiral_tap_at(i: u32, n: u32, tau: f32, r_p: f32, phi: f32, xi: f32) -> SpiralTap {
    let kappa = (f32(i) + xi) / f32(n);
    let h = r_p * kappa;
    let theta = SPIRAL_TWO_PI * kappa * tau + phi;
    return SpiralTap(vec2f(h * cos(theta), h * sin(theta)), h);
}

// m_i = ⌊log2(h_i / q)⌋ clamped to [0, max_level].
fn spiral_mip(h: f32, q: f32, max_level: u32) -> u32 {
    let m = floor(log2(h / q));
    if (!(m >= 0.0)) {
        return 0u;
    }
    return min(u32(m), max_level);
}

// Integer texel offset of a tap: ⌊offset + ½⌋ per axis.
fn tap_texel(offset: vec2f) -> vec2i {
    return vec2i(floor(offset + vec2f(0.5)));
}

// The size of level m of `zmip`: ⌊size₀ / 2^m⌋, at least 1 (wgpu's rule), from level 0's
// size. lavapipe's fragment shaders answer textureDimensions with a level that differs
// between the pixels of a quad wrongly, so no level is passed.
fn mip_size(zmip: texture_2d<f32>, m: u32) -> vec2i {
    return max(vec2i(textureDimensions(zmip, 0) >> vec2u(m)), vec2i(1));
}

// The level-m texel of `zmip` that level-0 pixel q reads. Levels have floor sizes
// (depth_mip.wgsl), so a level whose finer level has an odd size has no texel for the
// last row or column of pixels: there the last texel stands in (one past it would be
// an out-of-bounds load, whose value the backend picks).
fn mip_texel(zmip: texture_2d<f32>, q: vec2i, m: u32) -> vec2i {
    return min(q >> vec2u(m), mip_size(zmip, m) - 1);
}

// The level-0 pixel whose depth level-m texel t of the depth MIP chain `zmip`
// holds (depth_mip.wgsl's rotated grid applied m times, children clamped to
// each level), so a tap is reconstructed where its depth was seen.
fn mip_source_pixel(zmip: texture_2d<f32>, t: vec2i, m: u32) -> vec2i {
    var c = t;
    for (var l = m; l > 0u; l--) {
        let last = mip_size(zmip, l - 1u) - 1;
        c = min(c * 2 + vec2i((c.y & 1) ^ 1, (c.x & 1) ^ 1), last);
    }
    return c;
}
