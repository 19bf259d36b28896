// The static light probes (DGB Fig. 9's fallback): a grid of order-2 SH irradiance
// probes with distance maps, blended per receiver as `IrradianceProbes::irradiance`
// (CPU twin) blends them. Shared by the final composition (the probe term) and the
// radiosity gather (the probes' radiance along each tap, for the screen-space detail
// term). The importer declares the storage globals `probes` (array<Probe>) and
// `probe_depth` (array<vec2f>: per probe, PROBE_DEPTH_OCT² texels of (mean, mean
// square) distance to the first surface; one dummy texel without distance maps).
#import "common/packing.wgsl"

struct Probe {
    // irradiance SH coefficients E_i (rgb), i = 0..8; c[0].w = 1 valid, 0 inside geometry;
    // (c[1].w, c[2].w, c[3].w) = the probe's relocation offset from its grid point
    c: array<vec4f, 9>,
}

// Where probe `index` (grid point g) sits: g plus its relocation offset.
fn probe_position(index: u32, g: vec3f) -> vec3f {
    return g + vec3f(probes[index].c[1].w, probes[index].c[2].w, probes[index].c[3].w);
}

struct ProbeGrid {
    // the grid's origin (xyz; w: the visibility test's offset of the receiver towards
    // the viewer); spacing (xyz; w: its offset along the normal); probes per axis (xyz;
    // w: 1 = the probes have distance maps)
    origin: vec4f,
    spacing: vec4f,
    dims: vec4u,
}

fn sh9(d: vec3f) -> array<f32, 9> {
    return array<f32, 9>(
        0.282095,
        0.488603 * d.y,
        0.488603 * d.z,
        0.488603 * d.x,
        1.092548 * d.x * d.y,
        1.092548 * d.y * d.z,
        0.315392 * (3.0 * d.z * d.z - 1.0),
        1.092548 * d.x * d.z,
        0.546274 * (d.x * d.x - d.y * d.y),
    );
}

// Probe `index`'s irradiance for a normal n whose SH basis is `basis` (sh9(n)).
fn probe_irradiance(index: u32, basis: array<f32, 9>) -> vec3f {
    var y = basis;
    var e = vec3f(0.0);
    for (var i = 0u; i < 9u; i++) {
        e += probes[index].c[i].rgb * y[i];
    }
    return max(e, vec3f(0.0));
}

// The facing weight's floor (as `probes::FACING_FLOOR`): a probe straight behind the
// receiver still counts this much.
const FACING_FLOOR: f32 = 0.002;

// As `probes::DEPTH_OCT` and `probes::VISIBILITY_FLOOR`.
const PROBE_DEPTH_OCT: i32 = 16;
const VISIBILITY_FLOOR: f32 = 0.002;

// Chebyshev's bound that a receiver at `dist` is visible from a probe whose
// first surface in that direction has distance moments m (as
// `probes::chebyshev_visibility`).
fn chebyshev_visibility(dist: f32, m: vec2f) -> f32 {
    if (dist <= m.x) {
        return 1.0;
    }
    let v = max(m.y - m.x * m.x, 1e-4 * m.x * m.x + 1e-8);
    let t = dist - m.x;
    let pr = v / (v + t * t);
    return max(pr * pr * pr, VISIBILITY_FLOOR);
}

// The texel a bilinear lookup one texel beyond the map's border reads: the edges fold
// onto themselves, the corners meet (as `probes::oct_wrap_texel`).
fn oct_wrap_texel(t: vec2i) -> vec2i {
    let n = PROBE_DEPTH_OCT;
    let out_x = t.x < 0 || t.x >= n;
    let out_y = t.y < 0 || t.y >= n;
    if (out_x && out_y) {
        return vec2i(select(0, n - 1, t.x < 0), select(0, n - 1, t.y < 0));
    }
    if (out_x) {
        return vec2i(clamp(t.x, 0, n - 1), n - 1 - t.y);
    }
    if (out_y) {
        return vec2i(n - 1 - t.x, clamp(t.y, 0, n - 1));
    }
    return t;
}

// How visible the receiver p (normal n, unit direction v towards the viewer) is from
// probe `index` at `probe_pos` (as `IrradianceProbes::visibility`): its distance map,
// bilinear between texel centres, at the direction to p moved off its surface and
// towards the viewer.
fn probe_visibility(grid: ProbeGrid, index: u32, probe_pos: vec3f, p: vec3f, n: vec3f, v: vec3f) -> f32 {
    if (grid.dims.w == 0u) {
        return 1.0;
    }
    let d = p + n * grid.spacing.w + v * grid.origin.w - probe_pos;
    let dist = length(d);
    if (dist <= 1e-6) {
        return 1.0;
    }
    let st = oct_encode(d / dist) * f32(PROBE_DEPTH_OCT) - 0.5;
    let base = floor(st);
    let f = st - base;
    var m = vec2f(0.0);
    for (var k = 0; k < 4; k++) {
        let o = vec2i(k & 1, k >> 1);
        let w = select(1.0 - f.x, f.x, o.x == 1) * select(1.0 - f.y, f.y, o.y == 1);
        let t = oct_wrap_texel(vec2i(base) + o);
        m += w * probe_depth[index * u32(PROBE_DEPTH_OCT * PROBE_DEPTH_OCT) + u32(t.y * PROBE_DEPTH_OCT + t.x)];
    }
    return chebyshev_visibility(dist, m);
}

// One of the 8 probes around p (corner bits x, y, z) and its blend weight for a
// receiver at p (normal n): trilinear × how much it faces the receiver × how
// visible the receiver is from it (as `IrradianceProbes::irradiance`).
struct ProbeCorner {
    index: u32,
    w: f32,
}

// The grid cell of p: its lowest corner and p's position in it.
struct ProbeCell {
    i0: vec3f,
    t: vec3f,
}

fn probe_cell(grid: ProbeGrid, p: vec3f) -> ProbeCell {
    let mx = vec3f(grid.dims.xyz) - 1.0;
    let g = min(max((p - grid.origin.xyz) / grid.spacing.xyz, vec3f(0.0)), mx);
    let i0 = floor(g);
    return ProbeCell(i0, g - i0);
}

fn probe_corner(grid: ProbeGrid, cell: ProbeCell, p: vec3f, n: vec3f, v: vec3f, corner: u32) -> ProbeCorner {
    let dims = grid.dims.xyz;
    let mx = vec3f(dims) - 1.0;
    let i0 = cell.i0;
    let t = cell.t;
    let o = vec3f(f32(corner & 1u), f32((corner >> 1u) & 1u), f32((corner >> 2u) & 1u));
    let c = vec3u(min(i0 + o, mx));
    let w3 = mix(1.0 - t, t, o);
    let w = w3.x * w3.y * w3.z;
    let index = c.x + dims.x * (c.y + dims.y * c.z);
    if (w == 0.0) {
        return ProbeCorner(index, 0.0);
    }
    // probes behind the receiver's tangent plane see the other side of its
    // surface (as `probes::facing_weight`)
    let probe_pos = probe_position(index, grid.origin.xyz + vec3f(c) * grid.spacing.xyz);
    let to_probe = probe_pos - p;
    let len = length(to_probe);
    var f = 0.5;
    if (len > 1e-4) {
        f = 0.5 * (dot(to_probe / len, n) + 1.0);
    }
    return ProbeCorner(index, w * (f * f + FACING_FLOOR) * probe_visibility(grid, index, probe_pos, p, n, v));
}

// The 8 corners with their weights; `valid` = 0 for probes inside geometry.
struct ProbeCorners {
    index: array<u32, 8>,
    w: array<f32, 8>,
    valid: array<f32, 8>,
}

fn probe_corners(grid: ProbeGrid, p: vec3f, n: vec3f, v: vec3f) -> ProbeCorners {
    var out: ProbeCorners;
    let cell = probe_cell(grid, p);
    for (var corner = 0u; corner < 8u; corner++) {
        let k = probe_corner(grid, cell, p, n, v, corner);
        out.index[corner] = k.index;
        out.w[corner] = k.w;
        // probes inside geometry (validity in coefficient 0's w) get no weight
        out.valid[corner] = probes[k.index].c[0].w;
    }
    return out;
}

// The corners' normalised weights: over the valid probes, or over all of them when no
// valid probe has weight.
fn probe_weights(corners: ProbeCorners) -> array<f32, 8> {
    var k = corners;
    var sum = 0.0;
    var sum_all = 0.0;
    for (var i = 0u; i < 8u; i++) {
        sum += k.w[i] * k.valid[i];
        sum_all += k.w[i];
    }
    var out: array<f32, 8>;
    for (var i = 0u; i < 8u; i++) {
        if (sum > 1e-6) {
            out[i] = k.w[i] * k.valid[i] / sum;
        } else {
            out[i] = k.w[i] / max(sum_all, 1e-6);
        }
    }
    return out;
}

// Probe `index`'s openness within the AO radius for a normal whose SH basis is `basis`:
// order-1 SH in c[4..7].w, clamped to [0, 1] (as `IrradianceProbes::openness`).
fn probe_openness(index: u32, basis: array<f32, 9>) -> f32 {
    var y = basis;
    var v = 0.0;
    for (var i = 0u; i < 4u; i++) {
        v += probes[index].c[4u + i].w * y[i];
    }
    return clamp(v, 0.0, 1.0);
}

// The probes' irradiance (rgb) and openness (a) at receiver p with normal n, seen along v:
// `probe_weights`' blend in one pass over the corners (no per-pixel arrays: the
// composition's hot path; as `IrradianceProbes::irradiance` and `openness_at`).
fn probe_field(grid: ProbeGrid, p: vec3f, n: vec3f, v: vec3f) -> vec4f {
    var sum = 0.0;
    var sum_all = 0.0;
    var e = vec4f(0.0);
    var e_all = vec4f(0.0);
    let cell = probe_cell(grid, p);
    let basis = sh9(n);
    for (var corner = 0u; corner < 8u; corner++) {
        let k = probe_corner(grid, cell, p, n, v, corner);
        if (k.w == 0.0) {
            // outside the grid (clamped) or on a cell face: skip the reads
            continue;
        }
        let valid = probes[k.index].c[0].w;
        let ek = vec4f(probe_irradiance(k.index, basis), probe_openness(k.index, basis));
        sum += k.w * valid;
        sum_all += k.w;
        e += ek * (k.w * valid);
        e_all += ek * k.w;
    }
    if (sum > 1e-6) {
        return e / sum;
    }
    return e_all / max(sum_all, 1e-6);
}

// The blended probes' incident radiance at p (receiver normal n, seen along v) as order-2 SH:
// L_lm = E_lm / Â_l with Â = (π, 2π/3, π/4) (Ramamoorthi & Hanrahan 2001), so that
// ∫ L(ω) max(ω·n, 0) dω over the hemisphere returns the irradiance the SH holds.
fn probe_radiance_sh(grid: ProbeGrid, p: vec3f, n: vec3f, v: vec3f) -> array<vec3f, 9> {
    // `var`: naga indexes arrays dynamically only through memory
    var k = probe_corners(grid, p, n, v);
    var w = probe_weights(k);
    var l: array<vec3f, 9>;
    for (var i = 0u; i < 8u; i++) {
        for (var j = 0u; j < 9u; j++) {
            l[j] += probes[k.index[i]].c[j].rgb * w[i];
        }
    }
    l[0] *= 1.0 / 3.14159265358979;
    for (var j = 1u; j < 4u; j++) {
        l[j] *= 1.5 / 3.14159265358979;
    }
    for (var j = 4u; j < 9u; j++) {
        l[j] *= 4.0 / 3.14159265358979;
    }
    return l;
}

// Radiance along direction d of SH coefficients `l` (≥ 0: order 2 rings).
fn sh_radiance(coeffs: array<vec3f, 9>, d: vec3f) -> vec3f {
    var l = coeffs;
    var y = sh9(d);
    var r = vec3f(0.0);
    for (var j = 0u; j < 9u; j++) {
        r += l[j] * y[j];
    }
    return max(r, vec3f(0.0));
}
