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
#import "common/probes.wgsl"
#import "common/ggx.wgsl"

struct Compose {
    // 1 = Eq. 7's boost on the reflected indirect light
    boost: u32,
    // 1 = blend with the light probes by the confidence c, 2 = the probes plus c × the
    // gather's screen-space detail (`radiosity::RadiositySettings::probe_detail`), 3 = as 1
    // with a one-sided c (`radiosity::probe_blend`)
    use_probes: u32,
    // the probe term × AV (1), × GTAO's multi-bounce G(AV, rho) (2), × G(AV, rho) /
    // G(V_probe, rho) at most 1 (3, `radiosity::ProbeAo::Relative`), or not (0)
    use_ao: u32,
    // 1 = add the glossy receivers' radiance (ILS `ils-glossy`, `bzb-gi-glossy`), stored
    // divided by ggx_demodulation (so the filters before compose keep textures sharp)
    use_glossy: u32,
    grid: ProbeGrid,
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

// GTAO's multi-bounce fit G(AV, rho) per channel (Jimenez et al. 2016; CPU twin
// `radiosity::ao_multibounce`): occluders within the AO radius reflect light too.
fn ao_multibounce(av: f32, rho: vec3f) -> vec3f {
    let a = 2.0404 * rho - 0.3324;
    let b = -4.7951 * rho + 0.6417;
    let c = 2.7552 * rho + 0.6903;
    return max(vec3f(av), ((av * a + b) * av + c) * av);
}

// The composed pixel p.
fn composed(p: vec2i) -> Out {
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
            if (compose.use_ao >= 2u) {
                occlusion = ao_multibounce(av, rho);
            }
        }
        let x = world_from_csz(frame, vec2f(p) + 0.5, z);
        let field = probe_field(compose.grid, x, oct_decode(nrm.rg), normalize(frame.eye.xyz - x));
        if (compose.use_ao == 3u) {
            // only the occlusion the probes do not hold (`radiosity::probe_ao_factor`)
            occlusion = min(occlusion / max(ao_multibounce(field.a, rho), vec3f(1e-3)), vec3f(1.0));
        }
        let ep = field.rgb * occlusion;
        o.probe = vec4f(ep, av);
        if (compose.use_probes == 2u) {
            // E = G·E_probe + c·(Ê[B] − Ê[L_probe]): the gather's estimate of what the
            // probes miss in the directions its taps saw
            e = max(ep + c * g.rgb, vec3f(0.0));
        } else {
            // DGB Fig. 9; one-sided (3): c × min(1, Y(E_dgb) / Y(E_probe)), as
            // `radiosity::probe_blend`
            var cb = c;
            if (compose.use_probes == 3u) {
                let y = vec3f(0.2126, 0.7152, 0.0722);
                cb = c * min(1.0, dot(g.rgb, y) / max(dot(ep, y), 1e-6));
            }
            e = cb * g.rgb + (1.0 - cb) * ep;
        }
    }
    o.blended = vec4f(e, c);
    o.hdr = vec4f(direct.rgb + rho / 3.14159265358979 * e * k, direct.a);
    if (compose.use_glossy != 0u) {
        let x = world_from_csz(frame, vec2f(p) + 0.5, z);
        let nv = dot(oct_decode(nrm.rg), normalize(frame.eye.xyz - x));
        let a = ggx_demodulation(nv, textureLoad(albedo, p, 0).rgb, nrm.z, nrm.w);
        o.hdr = vec4f(o.hdr.rgb + textureLoad(glossy, p, 0).rgb * a, o.hdr.a);
    }
    return o;
}

@fragment
fn fs_main(@builtin(position) pos: vec4f) -> Out {
    return composed(vec2i(pos.xy));
}

// The same pass as compute (`Kernel`, the radiosity stage's), 8×8 pixels per workgroup.
@group(1) @binding(10) var hdr_out: texture_storage_2d<rgba16float, write>;
@group(1) @binding(11) var blended_out: texture_storage_2d<rgba16float, write>;
@group(1) @binding(12) var probe_out: texture_storage_2d<rgba16float, write>;

@compute @workgroup_size(8, 8)
fn cs_main(@builtin(global_invocation_id) id: vec3u) {
    if (any(id.xy >= textureDimensions(hdr_out))) {
        return;
    }
    let o = composed(vec2i(id.xy));
    textureStore(hdr_out, id.xy, o.hdr);
    textureStore(blended_out, id.xy, o.blended);
    textureStore(probe_out, id.xy, o.probe);
}
