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
#import "common/fullscreen.wgsl"
#import "abuffer/ao_common.wgsl"

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
                if ((v[e] & 0xffffu) == 0u) {
                    continue;
                }
                a = max(a, node_occlusion(v[e], centre, x, n));
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
        compressed_receivers(p, phi, &av, &t);
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
