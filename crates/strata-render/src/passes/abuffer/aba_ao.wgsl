// Opacity-aware multilayer ambient occlusion over the A-buffer (ABA §III,
// Algorithm 1, Eq. 3–4), "separate" integration: every fragment of the pixel's
// list (in depth order) is a receiver; its AO is blended front to back with
// the colour's weights into one ambient visibility, over a background of 1.
// With compression (§III-B) the receivers and the occluders of every tap are
// the M compressed nodes: one texel fetch per tap, no list walk.
//
// getAO is DGB's obscurance (Eq. 2) at the spiral's taps (a Poisson-like disk,
// DGB §3.4) and the estimator of DGB Eq. 1, so `aba-ao` and `ao` mean the same
// thing on one camera. Algorithm 1: per tap, the strongest occluder over every
// fragment of the tap pixel's list, each weighted by its α (ABA: "occluder
// opacity weights its occlusion"). The CPU twin is
// `passes::abuffer::ao::ambient_visibility_cpu`.
#import "common/frame.wgsl"
#import "common/fullscreen.wgsl"
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
    // 0 = Poisson-disk SSAO (DGB Eq. 1 over spiral taps), 1 = HBAO
    kernel: u32,
    // HBAO: directions D and steps S per direction
    directions: u32,
    steps: u32,
    _pad0: u32,
}

@group(0) @binding(0) var<uniform> frame: Frame;
@group(2) @binding(0) var<uniform> ao: AbaAo;
@group(2) @binding(1) var nodes_m: texture_2d_array<u32>;

// DGB Eq. 2 with this pass's r, β, ε.
fn obscurance(v: vec3f, n: vec3f) -> f32 {
    return eq2_obscurance(v, n, ao.radius, ao.bias, ao.epsilon);
}

// Algorithm 1's inner loop at tap pixel q: max over the occluders f of
// α_f · getAO(x, f); without `multilayer`, the nearest fragment alone.
fn tap_occlusion(q: vec2i, x: vec3f, n: vec3f) -> f32 {
    let centre = vec2f(q) + 0.5;
    var a = 0.0;
    if (ao.compressed == 1u) {
        // nodes sorted by depth; empty ones have α = 0
        for (var l = 0u; l < (params.compress + 3u) / 4u; l++) {
            let v = textureLoad(nodes_m, q, i32(l), 0);
            for (var e = 0u; e < 4u; e++) {
                let j = 4u * l + e;
                if (j >= params.compress) {
                    break;
                }
                let alpha = f32(v[e] & 0xffffu) / 65535.0;
                if (alpha <= 0.0) {
                    continue;
                }
                let z = (f32(v[e] >> 16u) + 0.5) / params.depth_scale;
                a = max(a, alpha * obscurance(world_from_csz(frame, centre, z) - x, n));
                if (ao.multilayer == 0u) {
                    return a;
                }
            }
        }
        return a;
    }
    let p = u32(q.y) * params.width + u32(q.x);
    var w = walk_begin(p);
    var nearest = 0xffffffffu;
    var nearest_d = 0xffffffffu;
    loop {
        let i = walk_next(&w);
        if (i == 0xffffffffu) {
            break;
        }
        let f = nodes[i];
        if (ao.multilayer == 0u) {
            let d = bitcast<u32>(f.depth);
            if (key_less(d, i, nearest_d, nearest)) {
                nearest_d = d;
                nearest = i;
            }
            continue;
        }
        let alpha = unpack2x16float(f.ba).y;
        a = max(a, alpha * obscurance(world_from_csz(frame, centre, f.depth) - x, n));
    }
    if (ao.multilayer == 0u && nearest != 0xffffffffu) {
        let f = nodes[nearest];
        let alpha = unpack2x16float(f.ba).y;
        a = alpha * obscurance(world_from_csz(frame, centre, f.depth) - x, n);
    }
    return a;
}

// DGB Eq. 1 over the hemisphere around n at x (camera depth z) seen from pixel p.
fn hemisphere_av(p: vec2i, x: vec3f, n: vec3f, z: f32, phi: f32) -> f32 {
    let r_p = ao.proj_scale * ao.radius / z;
    let size = vec2i(i32(params.width), i32(params.height));
    var sum = 0.0;
    for (var i = 0u; i < ao.samples; i++) {
        let tap = spiral_tap(i, ao.samples, ao.tau, r_p, phi);
        let q = p + tap_texel(tap.offset);
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
fn hemisphere_hbao(p: vec2i, x: vec3f, n: vec3f, z: f32, phi: f32) -> f32 {
    let r_p = ao.proj_scale * ao.radius / z;
    let size = vec2i(i32(params.width), i32(params.height));
    var sum = 0.0;
    for (var d = 0u; d < ao.directions; d++) {
        let ang = phi + 6.28318530717959 * f32(d) / f32(ao.directions);
        let dir = vec2f(cos(ang), sin(ang));
        var horizon = 0.0;
        for (var s = 0u; s < ao.steps; s++) {
            let h = r_p * (f32(s) + 0.5) / f32(ao.steps);
            let q = p + tap_texel(dir * h);
            if (any(q < vec2i(0)) || any(q >= size)) {
                break;
            }
            horizon = max(horizon, tap_occlusion(q, x, n));
        }
        sum += horizon;
    }
    return max(0.0, 1.0 - ao.intensity * sum / f32(ao.directions));
}

fn hemisphere(p: vec2i, x: vec3f, n: vec3f, z: f32, phi: f32) -> f32 {
    if (ao.kernel == 1u) {
        return hemisphere_hbao(p, x, n, z, phi);
    }
    return hemisphere_av(p, x, n, z, phi);
}

// The pixel's blended AV and, for the list path, the two ways ABA §III
// integrates AO with the OIT colour: `inside` = Σ T_i α_i AV_i L_i + T·sky
// (AO applied to each fragment inside the blend) and `separate` = (Σ T_i α_i
// L_i + T·sky) × AV_pixel (the colour and the AO blended apart, then
// multiplied: what the bilateral-filtered pipeline does, here before the blur).
struct Integrated {
    av: f32,
    inside: vec3f,
    separate: vec3f,
}

fn integrate(p: vec2i) -> Integrated {
    let pix = u32(p.y) * params.width + u32(p.x);
    var phi = 0.0;
    if (ao.rotate != 0u) {
        phi = pixel_angle(vec2u(p), ao.seed);
    }
    var r: Integrated;
    var av = 0.0;
    var t = 1.0;
    var colour = vec3f(0.0);
    var inside = vec3f(0.0);
    if (ao.compressed == 1u) {
        // receivers: the M compressed nodes (sorted by depth) with their normals
        let layers = (params.compress + 3u) / 4u;
        for (var l = 0u; l < layers; l++) {
            let v = textureLoad(nodes_m, p, i32(l), 0);
            let nv = textureLoad(nodes_m, p, i32(l + layers), 0);
            for (var e = 0u; e < 4u; e++) {
                if (4u * l + e >= params.compress || t < T_MIN) {
                    break;
                }
                let alpha = f32(v[e] & 0xffffu) / 65535.0;
                if (alpha <= 0.0) {
                    continue;
                }
                let z = (f32(v[e] >> 16u) + 0.5) / params.depth_scale;
                av += t * alpha * receiver_av(p, alpha, z, nv[e], phi);
                t *= 1.0 - alpha;
            }
        }
    } else {
        var last_d = 0u;
        var last_i = 0u;
        var started = false;
        loop {
            var kd: array<u32, SORT_BOUND>;
            var ki: array<u32, SORT_BOUND>;
            let k = sorted_batch(pix, started, last_d, last_i, &kd, &ki);
            for (var j = 0u; j < k; j++) {
                if (t < T_MIN) {
                    break;
                }
                let f = nodes[ki[j]];
                let ba = unpack2x16float(f.ba);
                let alpha = ba.y;
                if (alpha <= 0.0) {
                    continue;
                }
                let a = receiver_av(p, alpha, f.depth, f.normal_facing, phi);
                let radiance = vec3f(unpack2x16float(f.rg), ba.x);
                av += t * alpha * a;
                colour += t * alpha * radiance;
                inside += t * alpha * a * radiance;
                t *= 1.0 - alpha;
            }
            if (k < SORT_BOUND || t < T_MIN) {
                break;
            }
            last_d = kd[k - 1u];
            last_i = ki[k - 1u];
            started = true;
        }
    }
    if (t >= T_MIN) {
        av += t;
        colour += t * frame.sky.rgb;
        inside += t * frame.sky.rgb;
    }
    r.av = av;
    r.inside = inside;
    r.separate = colour * av;
    return r;
}

@fragment
fn fs_main(@builtin(position) pos: vec4f) -> @location(0) vec4f {
    return vec4f(integrate(vec2i(pos.xy)).av);
}

struct InsideOut {
    @location(0) av: vec4f,
    @location(1) inside: vec4f,
    @location(2) separate: vec4f,
}

// `integration = inside`: also the two colour integrations (list path only).
@fragment
fn fs_inside(@builtin(position) pos: vec4f) -> InsideOut {
    let r = integrate(vec2i(pos.xy));
    var o: InsideOut;
    o.av = vec4f(r.av);
    o.inside = vec4f(r.inside, 1.0);
    o.separate = vec4f(r.separate, 1.0);
    return o;
}
