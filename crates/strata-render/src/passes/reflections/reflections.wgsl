// DGB §3.6 mirror reflections traced through the deep G-buffer: march the
// reflection ray in world space, project each step into the layers, and hit
// when the ray lies within [z, z + Δz] of a layer's surface; the reflected
// radiance is that surface's outgoing radiance. After `max_distance` or when
// the ray leaves the (guard-banded) buffer: the environment (the sky, or a cube map).
#import "common/fullscreen.wgsl"
#import "common/frame.wgsl"
#import "common/camera.wgsl"
#import "common/packing.wgsl"
#import "common/color.wgsl"
#import "common/probes.wgsl"

override LAYERS: u32 = 2u;
// 1: layer 1's radiance is the renderer's B (Lambertian direct + emission), and a hit
// there adds the ambient term that layer 0's shaded image holds (ambient × diffuse albedo)
override LAYER1_AMBIENT: u32 = 0u;
// a hit on layer 1 adds its indirect light ρ/π · k · E as compose adds layer 0's: E blends
// the gather's layer-1 irradiance (`indirect1`, confidence in a) with the light probes at
// the hit. 0: no; 1: DGB's blend by the confidence; 2: the probes + c × the gather;
// 3: DGB's blend with the one-sided confidence (compose's modes); 4: the gather alone (no
// probes)
override LAYER1_INDIRECT: u32 = 0u;
// 1: k = boost(ρ) (Eq. 7), as compose
override LAYER1_BOOST: u32 = 0u;

// 1: a ray that finds no surface takes the radiance of the environment cube map along
// it (an application's, `embed::EmbeddedReflectionsConfig::environment`); 0: the scene's
// sky colour
override ENVIRONMENT: u32 = 0u;

// Matches `reflections::ReflectionUniforms`.
struct Reflections {
    max_distance: f32,
    steps: u32,
    // thickness Δz of a layer's surface
    thickness: f32,
    max_roughness: f32,
    // the light probes (LAYER1_INDIRECT)
    grid: ProbeGrid,
}

@group(0) @binding(0) var<uniform> frame: Frame;
@group(1) @binding(0) var<uniform> refl: Reflections;
@group(1) @binding(1) var csz: texture_2d_array<f32>;
@group(1) @binding(2) var normal: texture_2d_array<f32>;
@group(1) @binding(3) var albedo: texture_2d_array<f32>;
// outgoing radiance of layer 0 (the shaded image) and of layer 1 (its B)
@group(1) @binding(4) var radiance0: texture_2d<f32>;
@group(1) @binding(5) var radiance1: texture_2d<f32>;
// layer 1's gather irradiance E (rgb) and confidence (a) (LAYER1_INDIRECT)
@group(1) @binding(6) var indirect1: texture_2d<f32>;
@group(1) @binding(7) var<storage, read> probes: array<Probe>;
@group(1) @binding(8) var<storage, read> probe_depth: array<vec2f>;
// the environment (ENVIRONMENT; a 1-texel stand-in otherwise) and its linear sampler
@group(1) @binding(9) var environment: texture_cube<f32>;
@group(1) @binding(10) var environment_sampler: sampler;

// What a ray r that finds no surface reflects.
fn missed(r: vec3f) -> vec3f {
    if (ENVIRONMENT != 0u) {
        return textureSampleLevel(environment, environment_sampler, r, 0.0).rgb;
    }
    return frame.sky.rgb;
}

// What a layer-1 hit at pixel t adds besides its B: ambient and indirect light, seen from
// the mirror point x.
fn layer1_extra(t: vec2i, x: vec3f) -> vec3f {
    let nrm = textureLoad(normal, t, 1, 0);
    let rho = textureLoad(albedo, t, 1, 0).rgb * (1.0 - nrm.a);
    var l = vec3f(0.0);
    if (LAYER1_AMBIENT != 0u) {
        l += frame.ambient.rgb * rho;
    }
    if (LAYER1_INDIRECT != 0u) {
        let g = textureLoad(indirect1, t, 0);
        // no probes (4): the gather's E, as compose without them
        var e = g.rgb;
        if (LAYER1_INDIRECT != 4u) {
            let c = clamp(g.a, 0.0, 1.0);
            let y = world_from_csz(frame, vec2f(t) + 0.5, textureLoad(csz, t, 1, 0).r);
            let ep = probe_field(refl.grid, y, oct_decode(nrm.rg), normalize(x - y)).rgb;
            if (LAYER1_INDIRECT == 2u) {
                e = max(ep + c * g.rgb, vec3f(0.0));
            } else {
                var cb = c;
                if (LAYER1_INDIRECT == 3u) {
                    let luma = vec3f(0.2126, 0.7152, 0.0722);
                    cb = c * min(1.0, dot(g.rgb, luma) / max(dot(ep, luma), 1e-6));
                }
                e = cb * g.rgb + (1.0 - cb) * ep;
            }
        }
        var k = 1.0;
        if (LAYER1_BOOST != 0u) {
            k = boost(rho);
        }
        l += rho / 3.14159265358979 * e * k;
    }
    return l;
}

struct Out {
    // rgb = reflected radiance, a = 0 not a mirror, 1 environment, 2 layer 0, 3 layer 1
    @location(0) reflection: vec4f,
    // the input image with F · reflected radiance added on mirrors
    @location(1) hdr: vec4f,
}

// Screen position (xy), camera-space depth (z) of world point q; w = -1 when
// behind the near plane or outside the buffer.
fn project(q: vec3f) -> vec4f {
    let clip = frame.view_proj * vec4f(q, 1.0);
    if (clip.w <= frame.eye.w) {
        return vec4f(0.0, 0.0, 0.0, -1.0);
    }
    let ndc = clip.xy / clip.w;
    let c = vec2f((ndc.x * 0.5 + 0.5) * frame.size.x, (0.5 - 0.5 * ndc.y) * frame.size.y);
    if (c.x < 0.0 || c.y < 0.0 || c.x >= frame.size.x || c.y >= frame.size.y) {
        return vec4f(c, 0.0, -1.0);
    }
    return vec4f(c, dot(q - frame.eye.xyz, frame.cam_forward.xyz), 1.0);
}

fn layer_depths(s: vec4f) -> vec2f {
    let t = vec2i(s.xy);
    var z = vec2f(0.0);
    for (var j = 0u; j < min(LAYERS, 2u); j++) {
        z[j] = textureLoad(csz, t, i32(j), 0).r;
    }
    return z;
}

// Whether ray sample `s` lies behind layer j's surface by at most the allowance: Δz, or —
// when the previous sample (depth prev_z, surface depths prev_zl) was in front of that
// layer — the depth the ray and the surface moved apart over the step, so no step jumps
// over a layer. A candidate only: `confirmed` applies the paper's test.
// `zl`: the layers' depths at the sample's pixel.
fn behind_layer(j: u32, s: vec4f, zl: vec2f, prev_z: f32, prev_zl: vec2f) -> bool {
    let zj = zl[j];
    var allowance = refl.thickness;
    // `<=`: the mirror point itself lies on layer 0 (prev_z = prev_zl[0] before the first
    // step), and the ray leaves it on the viewer's side
    if (prev_z <= prev_zl[j]) {
        allowance = max(allowance, abs(s.z - prev_z) + abs(zj - prev_zl[j]));
    }
    return zj > 0.0 && s.z >= zj && s.z <= zj + allowance;
}

// Whether sample s lies in pixel p, the mirror's own: a ray cannot hit the surface it
// leaves, and within that pixel the surface's depth is its centre's. Tested in the first
// step only: after it the ray has left the pixel (or faces the viewer and is in front).
fn own_pixel(s: vec4f, p: vec2i) -> bool {
    return all(vec2i(s.xy) == p);
}

// DGB §3.6's hit test at the refined point `sh`, `slack` the ray's depth change over
// the bisection's last interval: within [z, z + Δz] of layer j. A candidate that fails
// it crossed a silhouette more than Δz behind the surface (the ray passes behind an
// edge, where the second layer may hold what it sees): the march goes on.
fn confirmed(j: u32, sh: vec4f, slack: f32) -> bool {
    let zj = layer_depths(sh)[j];
    return zj > 0.0 && sh.z >= zj && sh.z <= zj + refl.thickness + slack;
}

// The reflection at pixel p.
fn reflected(p: vec2i) -> Out {
    var o: Out;
    let base = textureLoad(radiance0, p, 0);
    o.hdr = base;
    let z = textureLoad(csz, p, 0, 0).r;
    let nrm = textureLoad(normal, p, 0, 0);
    if (z <= 0.0 || nrm.a < 0.5 || nrm.b > refl.max_roughness) {
        return o;
    }
    let x = world_from_csz(frame, vec2f(p) + 0.5, z);
    let n = oct_decode(nrm.rg);
    let v = normalize(x - frame.eye.xyz);
    let r = reflect(v, n);
    var l = missed(r);
    var code = 1.0;
    let step = refl.max_distance / f32(refl.steps);
    var prev_t = 0.0;
    var prev_z = z;
    var prev_zl = layer_depths(vec4f(vec2f(p) + 0.5, z, 1.0));
    // start one step out so the mirror does not hit itself; sample the end of step i, or
    // before it a point where the ray may cross a surface's silhouette (`detour`)
    var i = 1u;
    var t = step;
    var detour = false;
    var detoured = 0u;
    loop {
        if (i > refl.steps) {
            break;
        }
        var q = x + r * t;
        var s = project(q);
        var leaving = false;
        if (s.w < 0.0) {
            // leaving the buffer (or passing the near plane) within this step:
            // test the last point still inside, then take the environment
            var lo = prev_t;
            var hi = t;
            for (var k = 0; k < 6; k++) {
                let mid = 0.5 * (lo + hi);
                if (project(x + r * mid).w >= 0.0) {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            q = x + r * lo;
            s = project(q);
            leaving = true;
            if (s.w < 0.0) {
                break;
            }
        }
        // the mirror's own pixel is tested in the first step only: after it the ray has
        // left the pixel (or faces the viewer and is in front)
        let first = prev_t == 0.0;
        var hit = -1;
        var cross = -1.0;
        let zl = layer_depths(s);
        for (var j = 0u; j < min(LAYERS, 2u) && hit < 0; j++) {
            if ((first && own_pixel(s, p)) || !behind_layer(j, s, zl, prev_z, prev_zl)) {
                // The ray was in front of layer j and is now deeper than that surface was
                // at the previous sample, yet this sample is not behind it: it may have
                // crossed the surface and left its silhouette within the step (a wall's
                // top edge seen in a mirror floor). Sample next the point just past that
                // depth (by Δz/2 at most), where the ray crosses a surface facing the
                // camera; once per step.
                if (detoured != i && !leaving && prev_z < prev_zl[j] && s.z > prev_zl[j]) {
                    let past = prev_zl[j] + 0.5 * min(refl.thickness, s.z - prev_zl[j]);
                    let tc = prev_t + (t - prev_t) * (past - prev_z) / (s.z - prev_z);
                    cross = select(tc, min(cross, tc), cross > 0.0);
                }
                continue;
            }
            // refine between the previous sample and this one: the first point behind
            var lo = prev_t;
            var hi = length(q - x);
            for (var k = 0; k < 6; k++) {
                let mid = 0.5 * (lo + hi);
                let sm = project(x + r * mid);
                if (sm.w >= 0.0 && !(first && own_pixel(sm, p)) && behind_layer(j, sm, layer_depths(sm), prev_z, prev_zl)) {
                    hi = mid;
                } else {
                    lo = mid;
                }
            }
            let sh = project(x + r * hi);
            let slack = abs(sh.z - dot(x + r * lo - frame.eye.xyz, frame.cam_forward.xyz));
            if (!confirmed(j, sh, slack)) {
                continue;
            }
            hit = i32(j);
            let th = vec2i(sh.xy);
            if (j == 0u) {
                l = textureLoad(radiance0, th, 0).rgb;
                code = 2.0;
            } else {
                l = textureLoad(radiance1, th, 0).rgb + layer1_extra(th, x);
                code = 3.0;
            }
        }
        if (hit >= 0 || leaving) {
            break;
        }
        if (cross > prev_t) {
            // the silhouette point, then this step's end again from there
            detoured = i;
            detour = true;
            t = cross;
            continue;
        }
        prev_t = t;
        prev_z = s.z;
        prev_zl = zl;
        if (detour) {
            detour = false;
        } else {
            i++;
        }
        t = step * f32(i);
    }
    // Fresnel at normal incidence: the metal's albedo (F0)
    let f0 = mix(vec3f(0.04), textureLoad(albedo, p, 0, 0).rgb, nrm.a);
    o.reflection = vec4f(l, code);
    o.hdr = vec4f(base.rgb + f0 * l, base.a);
    return o;
}

@fragment
fn fs_main(@builtin(position) pos: vec4f) -> Out {
    return reflected(vec2i(pos.xy));
}

// The same pass as compute (`Kernel`), 8×8 pixels per workgroup.
@group(1) @binding(11) var reflection_out: texture_storage_2d<STORAGE_FORMAT_0, write>;
@group(1) @binding(12) var hdr_out: texture_storage_2d<STORAGE_FORMAT_1, write>;

@compute @workgroup_size(8, 8)
fn cs_main(@builtin(global_invocation_id) id: vec3u) {
    if (any(id.xy >= textureDimensions(reflection_out))) {
        return;
    }
    let o = reflected(vec2i(id.xy));
    textureStore(reflection_out, id.xy, o.reflection);
    textureStore(hdr_out, id.xy, o.hdr);
}
