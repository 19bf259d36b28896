// Shared by the multilayer AO's fragment pass (`aba_ao.wgsl`) and the
// compute-shader HBAO (`hbao_compute.wgsl`, ABA §V-B): the AO uniforms and
// compressed nodes (group 2, bindings 0–1), Eq. 2 with the pass's r, β, ε, one
// compressed node's occlusion, the receivers' Eq. 3–4, the two kernels (DGB
// Eq. 1 over spiral taps; HBAO) and the compressed receivers' blend. Each
// includer defines `tap_occlusion(q, x, n)` (Algorithm 1's inner loop at tap
// pixel q): the fragment pass walks lists or reads node texels, the compute
// pass reads its workgroup's staged tile.
#import "common/frame.wgsl"
#import "common/camera.wgsl"
#import "common/packing.wgsl"
#import "common/spiral.wgsl"
#import "common/obscurance.wgsl"
#import "abuffer/lists.wgsl"

// Matches `ao::AbaAoUniforms`.
struct AbaAo {
    radius: f32,
    bias: f32,
    epsilon: f32,
    intensity: f32,
    proj_scale: f32,
    tau: f32,
    samples: u32,
    seed: u32,
    // 1 = rotate the spiral per pixel
    rotate: u32,
    // 0 = only the nearest fragment of a tap pixel occludes (single-layer SSAO)
    multilayer: u32,
    // 1 = taps read the M compressed nodes (Eq. 5) instead of walking the list
    compressed: u32,
    // 0 = Poisson-disk SSAO (DGB Eq. 1 over spiral taps), 1 = HBAO,
    // 2 = compute-shader HBAO (§V-B; D = 4 axis directions, φ = 0)
    kernel: u32,
    // HBAO: directions D and steps S per direction
    directions: u32,
    steps: u32,
    // compute HBAO: tile apron in pixels staged in workgroup memory
    apron: u32,
    // multi-resolution levels L (1 = single resolution; ABA Table II, MSSAO)
    levels: u32,
}

@group(0) @binding(0) var<uniform> frame: Frame;
@group(2) @binding(0) var<uniform> ao: AbaAo;
@group(2) @binding(1) var nodes_m: texture_2d_array<u32>;

// DGB Eq. 2 with this pass's r, β, ε.
fn obscurance(v: vec3f, n: vec3f) -> f32 {
    return eq2_obscurance(v, n, ao.radius, ao.bias, ao.epsilon);
}

// α · getAO(x, f) for one compressed node word (z16 << 16 | α16) of tap pixel
// centre `centre`; 0 for an empty node (α = 0), which the callers skip.
fn node_occlusion(word: u32, centre: vec2f, x: vec3f, n: vec3f) -> f32 {
    let alpha = f32(word & 0xffffu) / 65535.0;
    let z = (f32(word >> 16u) + 0.5) / params.depth_scale;
    return alpha * obscurance(world_from_csz(frame, centre, z) - x, n);
}

// Multi-resolution: the tap radius in level-k texels (`ao::level_radius`):
// the coarsest level covers r_p / 2^k, finer ones are capped at 5 texels.
fn level_radius(r_p: f32, k: u32) -> f32 {
    let r = r_p / f32(1u << k);
    if (k + 1u >= max(ao.levels, 1u)) {
        return r;
    }
    return min(r, 5.0);
}

// The full-resolution pixel holding level k's nodes at level-k offset d from
// p's level-k texel: coarse texel (X, Y) = pixel (2^k X, 2^k Y).
fn level_pixel(p: vec2i, d: vec2i, k: u32) -> vec2i {
    return ((p >> vec2u(k)) + d) << vec2u(k);
}

// DGB Eq. 1 over the hemisphere around n at x (camera depth z) seen from
// pixel p, on resolution level k.
fn hemisphere_av(p: vec2i, x: vec3f, n: vec3f, z: f32, phi: f32, k: u32) -> f32 {
    let r_p = level_radius(ao.proj_scale * ao.radius / z, k);
    let size = vec2i(i32(params.width), i32(params.height));
    var sum = 0.0;
    for (var i = 0u; i < ao.samples; i++) {
        let tap = spiral_tap(i, ao.samples, ao.tau, r_p, phi);
        let q = level_pixel(p, tap_texel(tap.offset), k);
        if (any(q < vec2i(0)) || any(q >= size)) {
            continue;
        }
        sum += tap_occlusion(q, x, n);
    }
    return max(0.0, 1.0 - sqrt(ao.intensity * 3.14159265358979 / f32(ao.samples) * sum));
}

// Eq. 3–4 for one receiver fragment: w = α (front face) or 1 − α (back
// face); n (decoded from `nf`) faces the camera.
fn receiver_av(p: vec2i, alpha: f32, depth: f32, nf: u32, phi: f32) -> f32 {
    let x = world_from_csz(frame, vec2f(p) + 0.5, depth);
    let n = oct_decode(vec2f(f32(nf & 0xffu), f32((nf >> 8u) & 0xffu)) / 255.0);
    var wt = alpha;
    if (((nf >> 16u) & 1u) == 0u) {
        wt = 1.0 - alpha;
    }
    var a = 0.0;
    if (wt > 0.0) {
        a += wt * hemisphere(p, x, n, depth, phi);
    }
    if (wt < 1.0) {
        a += (1.0 - wt) * hemisphere(p, x, -n, depth, phi);
    }
    return a;
}

// HBAO (Bavoil, Sainz, Dimitrov 2008) with Algorithm 1 inside: D screen
// directions (rotated by φ), S steps each out to r_p; a direction's occlusion
// is its highest horizon, max over its steps of the strongest occluder of
// every layer — Eq. 2's (v·n − β)/|v| is the sine of the sample's elevation
// above the tangent plane, (1 − |v|²/r²) HBAO's attenuation W; AV = 1 −
// intensity · mean over the directions.
fn hemisphere_hbao(p: vec2i, x: vec3f, n: vec3f, z: f32, phi: f32, k: u32) -> f32 {
    let r_p = level_radius(ao.proj_scale * ao.radius / z, k);
    let size = vec2i(i32(params.width), i32(params.height));
    var sum = 0.0;
    for (var d = 0u; d < ao.directions; d++) {
        let ang = phi + 6.28318530717959 * f32(d) / f32(ao.directions);
        let dir = vec2f(cos(ang), sin(ang));
        var horizon = 0.0;
        for (var s = 0u; s < ao.steps; s++) {
            let h = r_p * (f32(s) + 0.5) / f32(ao.steps);
            let q = level_pixel(p, tap_texel(dir * h), k);
            if (any(q < vec2i(0)) || any(q >= size)) {
                break;
            }
            horizon = max(horizon, tap_occlusion(q, x, n));
        }
        sum += horizon;
    }
    return max(0.0, 1.0 - ao.intensity * sum / f32(ao.directions));
}

fn hemisphere_level(p: vec2i, x: vec3f, n: vec3f, z: f32, phi: f32, k: u32) -> f32 {
    if (ao.kernel >= 1u) {
        return hemisphere_hbao(p, x, n, z, phi, k);
    }
    return hemisphere_av(p, x, n, z, phi, k);
}

// Multi-resolution (ABA Table II after MSSAO): the levels' occlusions
// O_k = 1 - AV_k combine as O = 1 - (1 - max O_k)(1 - mean O_k).
fn hemisphere(p: vec2i, x: vec3f, n: vec3f, z: f32, phi: f32) -> f32 {
    let levels = max(ao.levels, 1u);
    if (levels == 1u) {
        return hemisphere_level(p, x, n, z, phi, 0u);
    }
    var max_o = 0.0;
    var sum_o = 0.0;
    for (var k = 0u; k < levels; k++) {
        let o = 1.0 - hemisphere_level(p, x, n, z, phi, k);
        max_o = max(max_o, o);
        sum_o += o;
    }
    return (1.0 - max_o) * (1.0 - sum_o / f32(levels));
}

// The compressed receivers of pixel p (§III-B: the M nodes, sorted by depth,
// with their normals), blended front to back into `av` with transmittance `t`.
fn compressed_receivers(p: vec2i, phi: f32, av: ptr<function, f32>, t: ptr<function, f32>) {
    let layers = (params.compress + 3u) / 4u;
    for (var l = 0u; l < layers; l++) {
        let v = textureLoad(nodes_m, p, i32(l), 0);
        let nv = textureLoad(nodes_m, p, i32(l + layers), 0);
        for (var e = 0u; e < 4u; e++) {
            if (4u * l + e >= params.compress || *t < T_MIN) {
                break;
            }
            let alpha = f32(v[e] & 0xffffu) / 65535.0;
            if (alpha <= 0.0) {
                continue;
            }
            let z = (f32(v[e] >> 16u) + 0.5) / params.depth_scale;
            *av += *t * alpha * receiver_av(p, alpha, z, nv[e], phi);
            *t *= 1.0 - alpha;
        }
    }
}
