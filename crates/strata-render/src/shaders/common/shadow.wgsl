// Shadow-map lookups of the analytic lights (`lights::GpuLight`), shared by the
// deferred lighting pass and bzb-gi's sender shading (BZB §3.2: the payload is
// the sender's direct light, shadowed as the lighting pass shadows it). The
// importer declares the globals `shadow_maps` (texture_depth_2d_array),
// `shadow_sampler` (sampler_comparison) and `shadow_mats` (storage
// array<mat4x4f>: the view-projection of every shadow-map layer).
#import "common/lights.wgsl"

const NO_SHADOW: u32 = 0xffffffffu;

// The shadow-map layer of light `l` for a surface at p: its own, or for a point
// light the cube face of the major axis of p − light (faces +X, −X, +Y, −Y, +Z, −Z).
fn shadow_layer(l: GpuLight, p: vec3f) -> u32 {
    if (l.kind.x != 1u) {
        return l.kind.y;
    }
    return l.kind.y + cube_face(p - l.position.xyz);
}

// Where p (normal n, distance `dist` to a local light) falls in light `l`'s
// shadow map, moved ~1.5 shadow texels along n (a texel grows with distance for
// perspective maps): its layer, uv, ndc depth z, clip w (the distance along a
// perspective map's axis) and the moved point q; `inside` is false off the map.
struct ShadowCoords {
    layer: u32,
    uv: vec2f,
    z: f32,
    w: f32,
    q: vec3f,
    inside: bool,
}

fn shadow_coords(l: GpuLight, p: vec3f, n: vec3f, dist: f32) -> ShadowCoords {
    var out: ShadowCoords;
    out.layer = shadow_layer(l, p);
    var texel = l.cone.z;
    if (l.kind.x != 0u) {
        texel = texel * dist;
    }
    out.q = p + n * texel * 1.5;
    let c = shadow_mats[out.layer] * vec4f(out.q, 1.0);
    let ndc = c.xyz / c.w;
    out.inside = !(c.w <= 0.0 || any(abs(ndc.xy) > vec2f(1.0)) || ndc.z > 1.0);
    out.uv = vec2f(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5);
    out.z = ndc.z;
    out.w = c.w;
    return out;
}

// Visibility of light `l` at p (normal n, distance `dist` to a local light):
// (2r+1)² bilinear comparisons, r = `pcf_radius`, of a `shadow_size`² map.
fn shadow_visibility_pcf(l: GpuLight, p: vec3f, n: vec3f, dist: f32, pcf_radius: i32, shadow_size: f32) -> f32 {
    if (l.kind.y == NO_SHADOW) {
        return 1.0;
    }
    let sc = shadow_coords(l, p, n, dist);
    if (!sc.inside) {
        return 1.0;
    }
    let layer = sc.layer;
    let uv = sc.uv;
    let r = pcf_radius;
    var sum = 0.0;
    var count = 0.0;
    for (var y = -r; y <= r; y++) {
        for (var x = -r; x <= r; x++) {
            let o = vec2f(f32(x), f32(y)) / shadow_size;
            sum += textureSampleCompareLevel(shadow_maps, shadow_sampler, uv + o, i32(layer), sc.z);
            count += 1.0;
        }
    }
    return sum / count;
}

// Percentage-closer soft shadows (PCSS) of a Rect light: the share of the
// rectangle that p sees, from the one shadow map at the light's centre. A
// blocker at distance d_b (along the map's axis) in front of a receiver at d_r
// hides the light's point c + s·hu + t·hv at the map position of p offset by
// (s·hu + t·hv)·k, k = 1/d_b − 1/d_r = (z_r − z_b) / C (ndc depths; C is
// `GpuLight.cone.w`, `lights::depth_scale`): the light's image through a
// blocker plane is the rectangle scaled by k. So
// 1) blocker search: PCSS_SEARCH_TAPS² taps (four bilinearly weighted depth
//    loads each) over the image at k = PCSS_SEARCH / d_r (blockers from
//    d_r / (1 + PCSS_SEARCH) on): the blockers' mean depth, or fully lit if none;
// 2) filter: bilinear comparisons over the image at the blockers' k, on a
//    lattice fixed in the image's coordinates (`pcss_lattice`), each against
//    the receiver's tangent plane where that tap's ray from the light's centre
//    meets it (so a kernel many texels wide does not shadow a tilted receiver
//    with itself).
// Falls back to `shadow_visibility_pcf` where the image is under a texel.
const PCSS_SEARCH: f32 = 2.0;
const PCSS_SEARCH_TAPS: i32 = 4;
const PCSS_CELLS: f32 = 8.0;

fn shadow_visibility_rect(l: GpuLight, p: vec3f, n: vec3f, dist: f32, pcf_radius: i32, shadow_size: f32) -> f32 {
    if (l.kind.y == NO_SHADOW || l.cone.w <= 0.0) {
        return shadow_visibility_pcf(l, p, n, dist, pcf_radius, shadow_size);
    }
    let sc = shadow_coords(l, p, n, dist);
    if (!sc.inside) {
        return 1.0;
    }
    let layer = sc.layer;
    let m = shadow_mats[layer];
    let q = sc.q;
    let uv = sc.uv;
    // the light's half-edges as map (uv) offsets per unit of k
    let au = (m * vec4f(l.half_u.xyz, 0.0)).xy * vec2f(0.5, -0.5);
    let av = (m * vec4f(l.half_v.xyz, 0.0)).xy * vec2f(0.5, -0.5);
    // receiver plane: the ray through c + (s·hu + t·hv)·k·d_r meets it at ndc depth
    // z_r + k·(s·gu + t·gv) (first order in the offset, exact for a plane)
    let to_q = (q - l.position.xyz) / sc.w;
    let facing = min(dot(to_q, n), -0.05);
    let gu = -l.cone.w * dot(l.half_u.xyz, n) / (sc.w * facing);
    let gv = -l.cone.w * dot(l.half_v.xyz, n) / (sc.w * facing);
    let size = vec2i(textureDimensions(shadow_maps));
    // 1) blocker search: each tap weighs its four texels bilinearly, so the
    //    blockers' share and mean depth move smoothly with p (no blocks where a
    //    point load would flip)
    let ks = PCSS_SEARCH / sc.w;
    var z_sum = 0.0;
    var blockers = 0.0;
    for (var j = 0; j < PCSS_SEARCH_TAPS; j++) {
        for (var i = 0; i < PCSS_SEARCH_TAPS; i++) {
            let s = (f32(2 * i + 1) / f32(PCSS_SEARCH_TAPS) - 1.0);
            let t = (f32(2 * j + 1) / f32(PCSS_SEARCH_TAPS) - 1.0);
            let z_plane = sc.z + ks * (s * gu + t * gv);
            let st = (uv + (s * au + t * av) * ks) * vec2f(size) - 0.5;
            let base = floor(st);
            let f = st - base;
            for (var k = 0; k < 4; k++) {
                let o = vec2i(k & 1, k >> 1);
                let w = select(1.0 - f.x, f.x, o.x == 1) * select(1.0 - f.y, f.y, o.y == 1);
                let texel = clamp(vec2i(base) + o, vec2i(0), size - 1);
                let zb = textureLoad(shadow_maps, texel, i32(layer), 0);
                if (zb < z_plane) {
                    z_sum += w * zb;
                    blockers += w;
                }
            }
        }
    }
    if (blockers < 1e-4) {
        return 1.0;
    }
    // 2) filter: the light's image at the blockers' mean depth is the box
    //    [a_p ± k] × [b_p ± k] in the image coordinates (a, b)
    let k = max(sc.z - z_sum / blockers, 0.0) / l.cone.w;
    let extent = max(length(au), length(av)) * k * shadow_size;
    let det = au.x * av.y - au.y * av.x;
    if (!(extent >= 1.0) || abs(det) < 1e-12) {
        return shadow_visibility_pcf(l, p, n, dist, pcf_radius, shadow_size);
    }
    let ab = vec2f(av.y * uv.x - av.x * uv.y, au.x * uv.y - au.y * uv.x) / det;
    let cell = exp2(ceil(log2(2.0 * k / PCSS_CELLS)));
    return pcss_lattice(layer, ab, k, cell, au, av, gu, gv, sc.z);
}

// Visibility over the box [ab ± k] in the light's image coordinates (a, b)
// (uv = a·au + b·av) from the taps of a lattice fixed in (a, b), spacing `cell`
// (a power of two, PCSS_CELLS/2 < 2k/Δ ≤ PCSS_CELLS), each weighing the box's
// overlap with its tent: the visibility moves smoothly with p, where a grid that
// travels with p steps across a blocker's edge (blocky penumbrae). Where Δ
// halves, the estimate changes by the two lattices' difference (faint seams).
fn pcss_lattice(layer: u32, ab: vec2f, k: f32, cell: f32, au: vec2f, av: vec2f, gu: f32, gv: f32, z: f32) -> f32 {
    // the box narrowed so that box ⊗ tent has the box's variance: k'²/3 + Δ²/6 = k²/3
    let kn = sqrt(max(k * k - 0.5 * cell * cell, 0.0));
    let lo = (ab - kn) / cell;
    let hi = (ab + kn) / cell;
    let first = vec2i(floor(lo));
    // at most PCSS_CELLS + 3 taps a side (2k'/Δ ≤ PCSS_CELLS)
    let last = min(vec2i(ceil(hi)), first + i32(PCSS_CELLS) + 3);
    var sum = 0.0;
    var weight = 0.0;
    for (var j = first.y; j <= last.y; j++) {
        let wb = tent_overlap(lo.y, hi.y, f32(j));
        for (var i = first.x; i <= last.x; i++) {
            let w = tent_overlap(lo.x, hi.x, f32(i)) * wb;
            let a = vec2f(f32(i), f32(j)) * cell;
            let d = a - ab;
            let st = a.x * au + a.y * av;
            sum += w * textureSampleCompareLevel(shadow_maps, shadow_sampler, st, i32(layer), z + d.x * gu + d.y * gv);
            weight += w;
        }
    }
    return sum / max(weight, 1e-6);
}

// ∫ over [lo, hi] of the unit tent max(0, 1 − |x − c|) (lattice units).
fn tent_overlap(lo: f32, hi: f32, c: f32) -> f32 {
    return tent_integral(hi - c) - tent_integral(lo - c);
}

// ∫ from −∞ to u of max(0, 1 − |x|).
fn tent_integral(u: f32) -> f32 {
    let v = clamp(u, -1.0, 1.0);
    if (v <= 0.0) {
        return 0.5 * (v + 1.0) * (v + 1.0);
    }
    return 1.0 - 0.5 * (1.0 - v) * (1.0 - v);
}

// Visibility of light `l` at p as the lighting pass shades it: PCSS for a Rect
// light when `area_penumbrae` is 1, else `pcf_radius` PCF.
fn light_visibility(l: GpuLight, p: vec3f, n: vec3f, dist: f32, pcf_radius: i32, shadow_size: f32, area_penumbrae: u32) -> f32 {
    if (l.kind.x == 3u && area_penumbrae != 0u) {
        return shadow_visibility_rect(l, p, n, dist, pcf_radius, shadow_size);
    }
    return shadow_visibility_pcf(l, p, n, dist, pcf_radius, shadow_size);
}
