// Final composition (DGB §3.2, Eq. 6, Fig. 9): direct light (+ emission, sky)
// plus the Lambertian reflection ρ/π · E · boost(ρ) of the indirect
// irradiance E. With light probes, E = c · E_dgb + (1 − c) · G · E_probe: the
// deep-G-buffer result where its confidence c = M/N is high, the static
// probes where it is not, darkened by AO when it runs (G = AV as in the paper,
// or GTAO's multi-bounce G(AV, ρ): `radiosity::ProbeAo`).
#import "common/fullscreen.wgsl"
#import "common/color.wgsl"
#import "common/frame.wgsl"
#import "common/camera.wgsl"
#import "common/packing.wgsl"

struct Compose {
    // 1 = Eq. 7's boost on the reflected indirect light
    boost: u32,
    // 1 = blend with the light probes
    use_probes: u32,
    // the probe term × AV (1), × GTAO's multi-bounce G(AV, rho) (2), or not (0)
    use_ao: u32,
    // 1 = add the glossy receivers' radiance (ILS `ils-glossy`) as is
    use_glossy: u32,
    // probe grid: origin (xyz), spacing (xyz; w: the visibility test's normal
    // offset of the receiver), probes per axis (w: 1 = the probes have distance maps)
    origin: vec4f,
    spacing: vec4f,
    dims: vec4u,
}

struct Probe {
    // irradiance SH coefficients E_i (rgb), i = 0..8; c[0].w = 1 valid, 0 inside geometry
    c: array<vec4f, 9>,
}

@group(0) @binding(0) var<uniform> frame: Frame;
@group(1) @binding(0) var<uniform> compose: Compose;
@group(1) @binding(1) var hdr: texture_2d<f32>;
@group(1) @binding(2) var albedo: texture_2d<f32>;
@group(1) @binding(3) var normal: texture_2d<f32>;
@group(1) @binding(4) var indirect: texture_2d<f32>;
@group(1) @binding(5) var csz: texture_2d<f32>;
@group(1) @binding(6) var ao: texture_2d<f32>;
@group(1) @binding(7) var<storage, read> probes: array<Probe>;
// outgoing radiance of glossy receivers (rgb; use_glossy), else any target
@group(1) @binding(8) var glossy: texture_2d<f32>;
// per probe, PROBE_DEPTH_OCT² texels (row-major) of (mean, mean square) distance to
// the first surface (`IrradianceProbes::depth`); one dummy texel without distance maps
@group(1) @binding(9) var<storage, read> probe_depth: array<vec2f>;

struct Out {
    @location(0) hdr: vec4f,
    // blended E (rgb), confidence (a)
    @location(1) blended: vec4f,
    // probe irradiance × AO's factor G (rgb), AV (a)
    @location(2) probe: vec4f,
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

fn probe_irradiance(index: u32, n: vec3f) -> vec3f {
    let y = sh9(n);
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
const PROBE_DEPTH_OCT: i32 = 8;
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

// How visible the receiver p (normal n) is from probe `index` at `probe_pos`
// (as `IrradianceProbes::visibility`): its distance map, bilinear between texel
// centres, at the direction to p moved off its surface.
fn probe_visibility(index: u32, probe_pos: vec3f, p: vec3f, n: vec3f) -> f32 {
    if (compose.dims.w == 0u) {
        return 1.0;
    }
    let d = p + n * compose.spacing.w - probe_pos;
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
        let t = clamp(vec2i(base) + o, vec2i(0), vec2i(PROBE_DEPTH_OCT - 1));
        m += w * probe_depth[index * u32(PROBE_DEPTH_OCT * PROBE_DEPTH_OCT) + u32(t.y * PROBE_DEPTH_OCT + t.x)];
    }
    return chebyshev_visibility(dist, m);
}

// Trilinear blend of the valid ones of the 8 probes around p, weighted by how
// much each faces the receiver and how visible the receiver is from it (as
// `IrradianceProbes::irradiance`).
fn probe_field(p: vec3f, n: vec3f) -> vec3f {
    let dims = compose.dims.xyz;
    let mx = vec3f(dims) - 1.0;
    let g = min(max((p - compose.origin.xyz) / compose.spacing.xyz, vec3f(0.0)), mx);
    let i0 = floor(g);
    let t = g - i0;
    var e = vec3f(0.0);
    var sum = 0.0;
    var e_all = vec3f(0.0);
    var sum_all = 0.0;
    for (var corner = 0u; corner < 8u; corner++) {
        let o = vec3f(f32(corner & 1u), f32((corner >> 1u) & 1u), f32((corner >> 2u) & 1u));
        let c = vec3u(min(i0 + o, mx));
        let w3 = mix(1.0 - t, t, o);
        var w = w3.x * w3.y * w3.z;
        let index = c.x + dims.x * (c.y + dims.y * c.z);
        // probes behind the receiver's tangent plane see the other side of its
        // surface (as `probes::facing_weight`)
        let probe_pos = compose.origin.xyz + vec3f(c) * compose.spacing.xyz;
        let to_probe = probe_pos - p;
        let len = length(to_probe);
        var f = 0.5;
        if (len > 1e-4) {
            f = 0.5 * (dot(to_probe / len, n) + 1.0);
        }
        w *= (f * f + FACING_FLOOR) * probe_visibility(index, probe_pos, p, n);
        let pe = probe_irradiance(index, n);
        e_all += pe * w;
        sum_all += w;
        // probes inside geometry (validity in coefficient 0's w) get no weight
        let v = probes[index].c[0].w;
        e += pe * (w * v);
        sum += w * v;
    }
    if (sum > 1e-6) {
        return e / sum;
    }
    return e_all / max(sum_all, 1e-6);
}

// GTAO's multi-bounce fit G(AV, rho) per channel (Jimenez et al. 2016; CPU twin
// `radiosity::ao_multibounce`): occluders within the AO radius reflect light too.
fn ao_multibounce(av: f32, rho: vec3f) -> vec3f {
    let a = 2.0404 * rho - 0.3324;
    let b = -4.7951 * rho + 0.6417;
    let c = 2.7552 * rho + 0.6903;
    return max(vec3f(av), ((av * a + b) * av + c) * av);
}

@fragment
fn fs_main(@builtin(position) pos: vec4f) -> Out {
    let p = vec2i(pos.xy);
    var o: Out;
    let direct = textureLoad(hdr, p, 0);
    o.hdr = direct;
    let z = textureLoad(csz, p, 0).r;
    if (z <= 0.0) {
        return o;
    }
    let nrm = textureLoad(normal, p, 0);
    let rho = textureLoad(albedo, p, 0).rgb * (1.0 - nrm.a);
    var k = 1.0;
    if (compose.boost != 0u) {
        k = boost(rho);
    }
    let g = textureLoad(indirect, p, 0);
    var e = g.rgb;
    let c = clamp(g.a, 0.0, 1.0);
    if (compose.use_probes != 0u) {
        var av = 1.0;
        var occlusion = vec3f(1.0);
        if (compose.use_ao != 0u) {
            av = textureLoad(ao, p, 0).r;
            occlusion = vec3f(av);
            if (compose.use_ao == 2u) {
                occlusion = ao_multibounce(av, rho);
            }
        }
        let x = world_from_csz(frame, vec2f(p) + 0.5, z);
        let ep = probe_field(x, oct_decode(nrm.rg)) * occlusion;
        o.probe = vec4f(ep, av);
        e = c * g.rgb + (1.0 - c) * ep;
    }
    o.blended = vec4f(e, c);
    o.hdr = vec4f(direct.rgb + rho / 3.14159265358979 * e * k, direct.a);
    if (compose.use_glossy != 0u) {
        o.hdr = vec4f(o.hdr.rgb + textureLoad(glossy, p, 0).rgb, o.hdr.a);
    }
    return o;
}
