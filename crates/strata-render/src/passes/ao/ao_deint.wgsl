// Deinterleaved DGB §3.1 ambient visibility (issue 11 item 8; the HBAO+ /
// "deinterleaved texturing" idea on strata's ILS split, Segovia et al. §3.2).
// One full-screen pass over the tiled buffer: the fragment at tiled texel t
// belongs to sub-buffer (i, j) = t div tile and stands for full-resolution
// pixel p = (t mod tile)·(n, m) + (i, j). It evaluates Eq. 1–2 with the spiral
// taps k ≡ i + n·j (mod n·m) of the N-tap §3.4 spiral, each snapped to the
// pixels of its own sub-buffer, so level-0 depth reads stay inside one
// ⌈W/n⌉×⌈H/m⌉ tile. CPU twin: `ao::deinterleaved_visibility_cpu`.
#import "common/fullscreen.wgsl"
#import "common/frame.wgsl"
#import "common/camera.wgsl"
#import "common/packing.wgsl"
#import "common/spiral.wgsl"
#import "common/interleave.wgsl"
#import "common/obscurance.wgsl"

override LAYERS: u32 = 2u;

#import "ao/uniforms.wgsl"

// Matches `ao::DeintUniforms`.
struct DeintAo {
    ao: Ao,
    ils: Interleave,
}

@group(0) @binding(0) var<uniform> frame: Frame;
@group(1) @binding(0) var<uniform> u: DeintAo;
// the split zmip level 0 and npack (ILS §3.2 tiled layout)
@group(1) @binding(1) var zsplit: texture_2d<f32>;
@group(1) @binding(2) var nsplit: texture_2d<f32>;
// the full-resolution MIP chain, for taps at level >= 1 (DGB §3.4)
@group(1) @binding(3) var zmip: texture_2d<f32>;

// Eq. 2: obscurance at X (normal n) due to a surface point at v = Y − X.
fn obscurance(v: vec3f, n: vec3f) -> f32 {
    return eq2_obscurance(v, n, u.ao.radius, u.ao.bias, u.ao.epsilon);
}

// ⌊a / b⌋ for b > 0 (WGSL's `/` truncates towards zero).
fn floor_div(a: i32, b: i32) -> i32 {
    let q = a / b;
    return select(q, q - 1, (a % b != 0) && (a < 0));
}

@fragment
fn fs_main(@builtin(position) pos: vec4f) -> @location(0) vec4f {
    let t = vec2u(pos.xy);
    if (ils_is_padding(t, u.ils)) {
        // no image pixel (never gathered)
        return vec4f(f32(u.ao.output_obscurance == 0u));
    }
    let sub = t / u.ils.tile;
    let origin = vec2i(sub * u.ils.tile);
    let pat = vec2i(u.ils.pattern);
    let local = vec2i(t) - origin;
    // the full-resolution pixel this texel stands for (ILS §3.2 inverse)
    let p = local * pat + vec2i(sub);
    let z = textureLoad(zsplit, t, 0).r;
    if (z <= 0.0) {
        // no surface: unoccluded (AV 1, S 0)
        return vec4f(f32(u.ao.output_obscurance == 0u));
    }
    // everything below is in full-resolution pixels: the frame's projection applies as is
    let x = world_from_csz(frame, vec2f(p) + 0.5, z);
    let n = oct_decode(textureLoad(nsplit, t, 0).rg);
    let r_p = u.ao.proj_scale * u.ao.radius / z;
    var phi = 0.0;
    if (u.ao.rotate != 0u) {
        phi = pixel_angle(vec2u(p), u.ao.seed);
    }
    let size = vec2i(u.ils.size);
    // sub-buffer s = i + n·j takes taps s, s + n·m, s + 2·n·m, … of the N-tap spiral
    let count = u.ils.pattern.x * u.ils.pattern.y;
    let s = sub.x + u.ils.pattern.x * sub.y;
    let taps_here = (u.ao.samples - s + count - 1u) / count;
    var sum = 0.0;
    for (var k = s; k < u.ao.samples; k += count) {
        let tap = spiral_tap(k, u.ao.samples, u.ao.tau, r_p, phi);
        let d = tap_texel(tap.offset);
        // snapped to the sub-buffer's lattice: ⌊d/n + ½⌋ sub-buffer texels
        let dl = vec2i(floor_div(2 * d.x + pat.x, 2 * pat.x), floor_div(2 * d.y + pat.y, 2 * pat.y));
        let q = p + dl * pat;
        if (any(q < vec2i(0)) || any(q >= size)) {
            continue;
        }
        let m = spiral_mip(tap.radius, u.ao.q, u.ao.max_mip);
        var zs: vec4f;
        var src: vec2i;
        if (m == 0u) {
            // the same texel, read from the sub-buffer's own tile
            zs = textureLoad(zsplit, origin + local + dl, 0);
            src = q;
        } else {
            let tm = mip_texel(zmip, q, m);
            zs = textureLoad(zmip, tm, i32(m));
            src = mip_source_pixel(zmip, tm, m);
        }
        var a = 0.0;
        for (var j = 0u; j < LAYERS; j++) {
            if (zs[j] > 0.0) {
                let y = world_from_csz(frame, vec2f(src) + 0.5, zs[j]);
                a = max(a, obscurance(y - x, n));
            }
        }
        sum += a;
    }
    let s_mean = u.ao.intensity * 3.14159265358979 / f32(taps_here) * sum;
    if (u.ao.output_obscurance != 0u) {
        return vec4f(s_mean);
    }
    let av = max(0.0, 1.0 - sqrt(s_mean));
    return vec4f(av);
}
