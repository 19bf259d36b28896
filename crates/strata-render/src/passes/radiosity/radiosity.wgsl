// DGB §3.2 single-bounce diffuse indirect illumination, Eq. 4–5, gathered from
// every deep-G-buffer layer with §3.4's spiral taps. Units: B is outgoing
// radiance (the lighting pass's Lambertian direct light + emission), so
// E(X) ≈ 2π/M · Σ B(Y) max(ω̂·n̂_X, 0) is irradiance (Eq. 4), M of N taps
// passing Eq. 5. For k ≥ 2 the same taps also give layer 1's E (Fig. 5).
#import "common/fullscreen.wgsl"
#import "common/frame.wgsl"
#import "common/camera.wgsl"
#import "common/packing.wgsl"
#import "common/spiral.wgsl"
#import "common/color.wgsl"
#import "common/probes.wgsl"
#import "common/scissor.wgsl"

override LAYERS: u32 = 2u;
// 1 = also gather for layer 1's receiver (needed only to propagate bounces
// through layer 1, §3.3 / Fig. 5)
override RECEIVER1: u32 = 1u;
// > 1: the gather runs at 1/SCALE resolution, texel t shading one pixel of its
// SCALE×SCALE block (`block_pixel`); `upsample.wgsl` brings it back to full resolution
// (`RadiositySettings::gather_scale`)
override SCALE: u32 = 1u;

// Matches `radiosity::RadiosityUniforms`.
struct Radiosity {
    radius: f32,
    proj_scale: f32,
    q: f32,
    tau: f32,
    samples: u32,
    min_mip: u32,
    max_mip: u32,
    // 1 = apply Eq. 5's n̂_Y test
    normal_test: u32,
    seed: u32,
    rotate: u32,
    // 1 = confidence M/U with U the taps that lie in the receiver's hemisphere
    // (see `hemisphere_tap`), 0 = the paper's M/N
    coverage: u32,
    // 1 = solid-angle weights (self-normalised; see `term`), 0 = Eq. 4's equal weights
    solid_angle: u32,
    // 1 = background taps (layer 0 empty) count as the sky's radiance along their
    // camera ray instead of being skipped (`sky_term`)
    open_sky: u32,
    // 1 = taps that fail Eq. 5's n̂_Y test count as black occluders instead of
    // being skipped
    hidden_black: u32,
    // `estimate`'s normaliser: 0 = Eq. 4's 2π / Σ w, 1 = cosine, 2 = bounded cosine
    normalisation: u32,
    // 1 = layer 0's output is the detail term Ê[B] − Ê[L_probe] (`probe_detail`)
    probe_detail: u32,
    grid: ProbeGrid,
    // > 1: layer-1 taps whose segment from the receiver passes through a surface the
    // layers hold (tested at this many steps, `segment_blocked`) count as nothing
    vis_steps: u32,
    // how far behind each layer's surface counts as solid: the deep G-buffer's Δz
    thickness: f32,
    // 1 = each tap's radius within its stratum, κ_i = (i + ξ)/N (`pixel_jitter`)
    radius_jitter: u32,
    // 1 = with vis_steps > 1, layer-0 taps are tested too, and every tap also by whether
    // its segment pierces the visible surface (`segment_blocked`'s crossing)
    vis_all: u32,
}

// One tap's share of the sums: c.rgb = w · B(Y) max(ω̂·n̂_X, 0), c.a = w (< 0 for an
// occluder or the sky, 0 for nothing), wc = w · max(ω̂·n̂_X, 0), dir = ω̂.
struct Term {
    c: vec4f,
    wc: f32,
    dir: vec3f,
    // max(ω̂·n̂_X, 0) of a light-carrying term, whose c.rgb `with_light` fills
    cx: f32,
}

@group(0) @binding(0) var<uniform> frame: Frame;
@group(1) @binding(0) var<uniform> rad: Radiosity;
@group(1) @binding(1) var zmip: texture_2d<f32>;
@group(1) @binding(2) var npack: texture_2d<f32>;
@group(1) @binding(3) var b0: texture_2d<f32>;
@group(1) @binding(4) var b1: texture_2d<f32>;
// the light probes (`common/probes.wgsl`; dummies without `probe_detail`)
@group(1) @binding(5) var<storage, read> probes: array<Probe>;
@group(1) @binding(6) var<storage, read> probe_depth: array<vec2f>;

struct Out {
    // rgb = E (layer 0), a = confidence M/N
    @location(0) e0: vec4f,
    // rgb = E (layer 1), a = confidence
    @location(1) e1: vec4f,
}

fn normal_of(p: vec2i, layer: u32) -> vec3f {
    let n = textureLoad(npack, p, 0);
    if (layer == 0u) {
        return oct_decode(n.rg);
    }
    return oct_decode(n.ba);
}

fn radiosity_of(p: vec2i, layer: u32) -> vec3f {
    if (layer == 0u) {
        return textureLoad(b0, p, 0).rgb;
    }
    return textureLoad(b1, p, 0).rgb;
}

// Eq. 4–5 term of sample Y (layer j, pixel src, normal ny: read once per tap for
// both layers and receivers) for receiver X (normal n), with w = 1 (Eq. 4) or,
// with `solid_angle`, w ∝ the solid angle the tap's screen area subtends at X
// (`solid_angle_weight`); c.a = w when Y passes Eq. 5 (and lies within r). `h` =
// the tap's screen radius.
fn term(x: vec3f, n: vec3f, y: vec3f, ny: vec3f, j: u32, src: vec2i, h: f32) -> Term {
    var none: Term;
    let v = y - x;
    let vv = dot(v, v);
    if (!(vv < rad.radius * rad.radius) || vv <= 0.0) {
        return none;
    }
    let w = v * inverseSqrt(vv);
    let cos_x = dot(w, n);
    if (cos_x <= 0.0) {
        return none;
    }
    var wt = 1.0;
    if (rad.normal_test != 0u || rad.solid_angle != 0u) {
        if (rad.normal_test != 0u && dot(w, ny) >= 0.0) {
            if (rad.hidden_black != 0u) {
                // a black occluder: weight, no light (a < 0 marks it)
                var wo = 1.0;
                if (rad.solid_angle != 0u) {
                    wo = solid_angle_weight(y, ny, w, vv, h);
                }
                return Term(vec4f(0.0, 0.0, 0.0, -wo), wo * cos_x, w, 0.0);
            }
            return none;
        }
        if (rad.solid_angle != 0u) {
            wt = solid_angle_weight(y, ny, w, vv, h);
        }
    }
    // c.rgb = B(Y)·cos·w once `with_light` has read B (once for both receivers)
    return Term(vec4f(0.0, 0.0, 0.0, wt), wt * cos_x, w, cos_x);
}

// One point of a visibility segment against the layers at its pixel: zl = both layers'
// csz there, d = the point's own csz; ok = false off screen or behind the eye.
struct SegPoint {
    ok: bool,
    zl: vec2f,
    d: f32,
}

fn seg_point(pt: vec3f) -> SegPoint {
    var o: SegPoint;
    let pix = pixel_of_world(frame, pt);
    let q = vec2i(floor(pix.xy));
    if (pix.z == 0.0 || any(q < vec2i(0)) || any(q >= vec2i(textureDimensions(zmip, 0)))) {
        return o;
    }
    let z = textureLoad(zmip, q, 0);
    return SegPoint(true, z.xy, csz_of(frame, pt));
}

// The point lies behind layer 0's surface at its pixel (beyond 0.1 % + 1 cm).
fn seg_behind(p: SegPoint) -> bool {
    return p.zl.x > 0.0 && p.d > p.zl.x * 1.001 + 0.01;
}

// Two points' pixels show one continuous visible surface: their layer-0 depths differ by
// no more than the points' own depths do, plus the thickness Δz.
fn seg_continuous(a: SegPoint, b: SegPoint) -> bool {
    return abs(b.zl.x - a.zl.x) <= abs(b.d - a.d) + rad.thickness;
}

// Whether the segment from receiver x to sender y passes through a surface the deep
// G-buffer holds, tested at its `vis_steps − 1` inner points:
// - slab: a point lies behind a layer's surface on its camera ray by less than
//   `thickness` (inside that surface's object; the layers say nothing of the Δz behind
//   each surface);
// - crossing: a point lies behind layer 0's surface while the previous one (first the
//   receiver itself) lay in front of it on one continuous visible surface
//   (`seg_continuous`): the segment went through that surface, as a ray through a thin
//   wall does, which the slab test misses when no point lands inside the wall. Where two
//   steps' pixels show different surfaces (the segment passes a silhouette, e.g. a wall's
//   top seen from above), `SEG_SUB − 1` more points between them join the chain, for the
//   short stretch just behind the wall that the camera does not see.
// CPU twin: `radiosity::segment_blocked`.
const SEG_SUB: u32 = 4u;

// One link of the crossing chain: whether `cur` lies behind a surface continuous with the
// last point in front; then `cur` becomes the last point.
fn seg_chain(prev: ptr<function, SegPoint>, was_front: ptr<function, bool>, cur: SegPoint) -> bool {
    if (!cur.ok) {
        *was_front = false;
        return false;
    }
    let behind = seg_behind(cur);
    let hit = *was_front && behind && seg_continuous(*prev, cur);
    *was_front = cur.zl.x > 0.0 && !behind;
    *prev = cur;
    return hit;
}

fn segment_blocked(x: vec3f, y: vec3f, slab: bool, crossing: bool) -> bool {
    var prev = seg_point(x);
    var was_front = prev.ok && prev.zl.x > 0.0 && !seg_behind(prev);
    var prev_t = 0.0;
    for (var s = 1u; s < rad.vis_steps; s++) {
        let t = f32(s) / f32(rad.vis_steps);
        let cur = seg_point(mix(x, y, t));
        if (slab && cur.ok) {
            for (var j = 0u; j < min(LAYERS, 2u); j++) {
                if (cur.zl[j] > 0.0 && cur.d > cur.zl[j] * 1.001 + 0.01 && cur.d < cur.zl[j] + rad.thickness) {
                    return true;
                }
            }
        }
        if (crossing) {
            if (was_front && cur.ok && !seg_continuous(prev, cur)) {
                for (var k = 1u; k < SEG_SUB; k++) {
                    let tk = mix(prev_t, t, f32(k) / f32(SEG_SUB));
                    if (seg_chain(&prev, &was_front, seg_point(mix(x, y, tk)))) {
                        return true;
                    }
                }
            }
            if (seg_chain(&prev, &was_front, cur)) {
                return true;
            }
        }
        prev_t = t;
    }
    return false;
}

// A light-carrying term (c.a > 0) with its radiosity B filled in.
fn with_light(t: Term, b: vec3f) -> Term {
    var o = t;
    if (t.c.a > 0.0) {
        o.c = vec4f(b * t.cx * t.c.a, t.c.a);
    }
    return o;
}

// Solid angle (up to a constant) that the screen area represented by a tap at
// screen radius h (the spiral's taps are spread linearly in radius, so tap i
// stands for an annulus of area ∝ h) covers on the surface at Y (normal n_y)
// as seen from X (ω̂ from X to Y, |Y − X|² = vv): pixel footprint z² / cos_view
// times cos θ_Y / d². cos_view and d are clamped (grazing views, taps next
// to X) so that one tap cannot dominate.
fn solid_angle_weight(y: vec3f, ny: vec3f, w: vec3f, vv: f32, h: f32) -> f32 {
    let to_eye = frame.eye.xyz - y;
    let z2 = dot(to_eye, to_eye);
    let cos_view = max(abs(dot(ny, to_eye * inverseSqrt(z2))), 0.25);
    let cos_y = max(abs(dot(w, ny)), 0.0);
    let dmin = 0.05 * rad.radius;
    return h * z2 * cos_y / (cos_view * max(vv, dmin * dmin));
}

// Of two candidate terms, the one with the larger contribution (the union of
// layers, as for AO's max in Eq. 1).
// A light-carrying term (a > 0) wins over an occluder (a < 0), which wins over
// nothing (a = 0).
fn union_term(a: Term, b: Term) -> Term {
    if (b.c.a > 0.0 && (a.c.a <= 0.0 || luminance(b.c.rgb) > luminance(a.c.rgb))) {
        return b;
    }
    if (b.c.a < 0.0 && a.c.a == 0.0) {
        return b;
    }
    return a;
}

// A background tap (nothing in any layer) as the sky seen along its camera ray
// from X: radiance sky · cos, weight = the solid-angle weight's limit for a
// surface at infinity (z²/d² → 1, cos_y/cos_view → 1), i.e. the tap's h.
fn sky_term(x: vec3f, n: vec3f, src: vec2i, h: f32) -> Term {
    let y = world_from_csz(frame, vec2f(src) + 0.5, 1.0e4);
    let d = normalize(y - x);
    let cos_x = dot(d, n);
    if (cos_x <= 0.0) {
        var none: Term;
        return none;
    }
    var wt = 1.0;
    if (rad.solid_angle != 0u) {
        wt = h;
    }
    return Term(vec4f(frame.sky.rgb * cos_x * wt, -wt), wt * cos_x, d, 0.0);
}

// Whether the tap at pixel `src` with layer-0 depth `z0` (0: background) tells the
// receiver X (normal n) anything about its hemisphere: its direction from X lies above
// X's tangent plane by more than COVERAGE_COS (taps on X's own plane, or behind it,
// carry no light to X whatever they hold). A background tap's direction is its
// camera ray's: the sky or distant geometry, which screen space does not see.
const COVERAGE_COS: f32 = 0.1;
fn hemisphere_tap(x: vec3f, n: vec3f, src: vec2i, z0: f32) -> f32 {
    var y: vec3f;
    if (z0 > 0.0) {
        y = world_from_csz(frame, vec2f(src) + 0.5, z0);
    } else {
        y = world_from_csz(frame, vec2f(src) + 0.5, 1.0e4);
    }
    return select(0.0, 1.0, dot(normalize(y - x), n) > COVERAGE_COS);
}

// `sum` = (Σ w·B·cos, Σ w), `wc` = Σ w·cos; `m`: the contributing taps M; `u`: the
// taps in the receiver's hemisphere (coverage confidence), ≥ M.
fn estimate(sum: vec4f, wc: f32, m: f32, u: f32) -> vec4f {
    if (sum.a == 0.0) {
        return vec4f(0.0);
    }
    // Eq. 4: 2π/M Σ (w = 1) or 2π Σ w·B·cos / Σ w = π Σ w·B·cos / (½ Σ w). Uniform
    // solid-angle taps have mean cos ½, so Σ w·cos ≈ ½ Σ w; screen-space taps that
    // cluster near n̂_X make Eq. 4 over-estimate E. Cosine: π / Σ w·cos (exact for a
    // uniform surround); bounded: π / max(Σ w·cos, ½ Σ w), never above Eq. 4.
    // Confidence M/N (paper) or M/U (coverage).
    var denom = 0.5 * sum.a;
    if (rad.normalisation == 1u) {
        denom = wc;
    } else if (rad.normalisation == 2u) {
        denom = max(wc, denom);
    }
    var c = m / f32(rad.samples);
    if (rad.coverage != 0u) {
        c = m / max(u, m);
    }
    return vec4f(sum.rgb * (3.14159265358979 / denom), c);
}

// Layer 0's and layer 1's E at pixel p (zero where layer 0 is empty).
fn gather(p: vec2i) -> Out {
    var o: Out;
    let z = textureLoad(zmip, p, 0);
    if (z.x <= 0.0) {
        return o;
    }
    // receivers: layer 0 and (k ≥ 2) layer 1 at this pixel; one set of taps,
    // sized by layer 0's depth, serves both (§3.3: propagation across layers
    // shares the gathered samples)
    let x0 = world_from_csz(frame, vec2f(p) + 0.5, z.x);
    let n0 = normal_of(p, 0u);
    let has1 = RECEIVER1 != 0u && LAYERS > 1u && z.y > 0.0;
    var x1 = x0;
    var n1 = n0;
    if (has1) {
        x1 = world_from_csz(frame, vec2f(p) + 0.5, z.y);
        n1 = normal_of(p, 1u);
    }
    let r_p = rad.proj_scale * rad.radius / z.x;
    var phi = 0.0;
    if (rad.rotate != 0u) {
        phi = pixel_angle(vec2u(p), rad.seed);
    }
    var xi = 0.5;
    if (rad.radius_jitter != 0u) {
        xi = pixel_jitter(vec2u(p), rad.seed);
    }
    let size = vec2i(textureDimensions(zmip, 0));
    var sum0 = vec4f(0.0);
    var sum1 = vec4f(0.0);
    var wc0 = 0.0;
    var wc1 = 0.0;
    var m0 = 0.0;
    var m1 = 0.0;
    var u0 = 0.0;
    var u1 = 0.0;
    // probe_detail: the probes' radiance along layer 0's taps, Σ w·L_probe(ω̂)·cos
    var lsh: array<vec3f, 9>;
    if (rad.probe_detail != 0u) {
        lsh = probe_radiance_sh(rad.grid, x0, n0, normalize(frame.eye.xyz - x0));
    }
    var sum_probe = vec3f(0.0);
    for (var i = 0u; i < rad.samples; i++) {
        let tap = spiral_tap_at(i, rad.samples, rad.tau, r_p, phi, xi);
        let q = p + tap_texel(tap.offset);
        if (any(q < vec2i(0)) || any(q >= size)) {
            continue;
        }
        let m = max(spiral_mip(tap.radius, rad.q, rad.max_mip), min(rad.min_mip, rad.max_mip));
        let t = mip_texel(zmip, q, m);
        let zs = textureLoad(zmip, t, i32(m));
        let src = mip_source_pixel(zmip, t, m);
        var best0: Term;
        var best1: Term;
        // both layers' normals live in one npack texel
        var nn = vec4f(0.0);
        if ((rad.normal_test != 0u || rad.solid_angle != 0u) && zs.x > 0.0) {
            nn = textureLoad(npack, src, 0);
        }
        for (var j = 0u; j < min(LAYERS, 2u); j++) {
            if (zs[j] <= 0.0) {
                continue;
            }
            let y = world_from_csz(frame, vec2f(src) + 0.5, zs[j]);
            let ny = oct_decode(select(nn.ba, nn.rg, j == 0u));
            var t0 = term(x0, n0, y, ny, j, src, tap.radius);
            var t1: Term;
            if (has1) {
                t1 = term(x1, n1, y, ny, j, src, tap.radius);
            }
            // a sender that the layers show behind a surface from layer 0's receiver sends
            // nothing to it (`RadiositySettings::tap_visibility`: hidden, layer-1 senders,
            // and with `vis_all` the visible ones too; layer 1's receiver, whose E only
            // feeds the next bounce, is not tested)
            if (rad.vis_steps > 1u && (j == 1u || rad.vis_all != 0u) && t0.c.a > 0.0
                && segment_blocked(x0, y, j == 1u, rad.vis_all != 0u)) {
                var none: Term;
                t0 = none;
            }
            if (t0.c.a > 0.0 || t1.c.a > 0.0) {
                let b = radiosity_of(src, j);
                t0 = with_light(t0, b);
                t1 = with_light(t1, b);
            }
            best0 = union_term(best0, t0);
            if (has1) {
                best1 = union_term(best1, t1);
            }
        }
        if (rad.open_sky != 0u && zs.x <= 0.0) {
            best0 = sky_term(x0, n0, src, tap.radius);
            if (has1) {
                best1 = sky_term(x1, n1, src, tap.radius);
            }
        }
        // occluders and the sky add weight (and the sky its light) but do not count in M
        sum0 += vec4f(best0.c.rgb, abs(best0.c.a));
        sum1 += vec4f(best1.c.rgb, abs(best1.c.a));
        wc0 += best0.wc;
        wc1 += best1.wc;
        if (rad.probe_detail != 0u && best0.c.a != 0.0) {
            sum_probe += sh_radiance(lsh, best0.dir) * best0.wc;
        }
        let hit0 = select(0.0, 1.0, best0.c.a > 0.0);
        let hit1 = select(0.0, 1.0, best1.c.a > 0.0);
        m0 += hit0;
        m1 += hit1;
        if (rad.coverage != 0u) {
            u0 += max(hit0, hemisphere_tap(x0, n0, src, zs.x));
            if (has1) {
                u1 += max(hit1, hemisphere_tap(x1, n1, src, zs.x));
            }
        }
    }
    // probe_detail: Ê[B] − Ê[L_probe], the same taps, weights and normaliser (a control
    // variate: what the probes miss in the directions the taps saw)
    o.e0 = estimate(sum0 - vec4f(sum_probe, 0.0), wc0, m0, u0);
    o.e1 = estimate(sum1, wc1, m1, u1);
    return o;
}

// The pixel that output texel t shades (itself at full resolution).
fn receiver_pixel(t: vec2u) -> vec2i {
    return vec2i(block_pixel(t, SCALE, rad.seed, textureDimensions(zmip, 0)));
}

@fragment
fn fs_main(@builtin(position) pos: vec4f) -> Out {
    return gather(receiver_pixel(vec2u(pos.xy)));
}

// The same gather as a compute pass (`RadiositySettings::kernel`), 8×8 texels per
// workgroup, into storage textures; zero outside the shaded rectangle (`in_scissor`).
@group(1) @binding(7) var e0_out: texture_storage_2d<rgba16float, write>;
@group(1) @binding(8) var e1_out: texture_storage_2d<rgba16float, write>;

@compute @workgroup_size(8, 8)
fn cs_main(@builtin(global_invocation_id) id: vec3u) {
    if (any(id.xy >= textureDimensions(e0_out))) {
        return;
    }
    var o: Out;
    if (in_scissor(id.xy)) {
        o = gather(receiver_pixel(id.xy));
    }
    textureStore(e0_out, id.xy, o.e0);
    textureStore(e1_out, id.xy, o.e1);
}
