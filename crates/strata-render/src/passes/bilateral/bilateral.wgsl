// Separable bilateral reconstruction (DGB §3.1: "normal and plane weights"):
// each tap's weight = spatial Gaussian × plane weight (distance of the tap's
// surface from X's tangent plane, relative to X's depth) × normal weight
// (× a world-distance weight when `inv_radius2` > 0: not in the paper).
#import "common/fullscreen.wgsl"
#import "common/frame.wgsl"
#import "common/camera.wgsl"
#import "common/packing.wgsl"

// 0 = horizontal, 1 = vertical
override DIRECTION: u32 = 0u;

// Matches `bilateral::BilateralUniforms`.
struct Bilateral {
    radius: i32,
    step: i32,
    plane_sharpness: f32,
    // integer exponent of the normal weight
    normal_power: u32,
    // Gaussian weight of tap |k| in gauss[k / 4][k % 4]
    gauss: array<vec4f, 9>,
    // 1/R²: taps whose surface lies R or more from X get no weight (0: off;
    // `bilateral::distance_weight`)
    inv_radius2: f32,
    // > 0: the history-aware radius R_fresh (`BilateralSettings::fresh_radius`), read
    // from the temporal filter's count in `frames`
    fresh_radius: i32,
    pad0: f32,
    pad1: f32,
}

@group(0) @binding(0) var<uniform> frame: Frame;
@group(1) @binding(0) var<uniform> blur: Bilateral;
@group(1) @binding(1) var src: texture_2d<f32>;
@group(1) @binding(2) var zpack: texture_2d<f32>;
@group(1) @binding(3) var npack: texture_2d<f32>;
// the temporal filter's count of accepted history frames (read when fresh_radius > 0)
@group(1) @binding(4) var frames: texture_2d<f32>;

// Taps of a pixel whose history holds n frames: max(radius, round(R_fresh / √(n + 1)))
// (2-D taps grow as r², the history's variance falls as 1/(n + 1)). Rust twin:
// bilateral::history_radius.
fn history_radius(n: f32) -> i32 {
    return max(blur.radius, i32(floor(f32(blur.fresh_radius) / sqrt(max(n, 0.0) + 1.0) + 0.5)));
}

// Gaussian weight of tap |k| = a for a filter of `radius` taps (bilateral::gauss_weight).
fn gauss_weight(a: u32, radius: i32) -> f32 {
    if (radius == blur.radius) {
        return blur.gauss[a / 4u][a % 4u];
    }
    let sigma = max(0.75 * f32(radius), 0.5);
    return exp(-f32(a * a) / (2.0 * sigma * sigma));
}

// The filtered value at pixel p.
fn filtered(p: vec2i) -> vec4f {
    let centre = textureLoad(src, p, 0);
    let z = textureLoad(zpack, p, 0).r;
    var radius = blur.radius;
    if (blur.fresh_radius > 0) {
        radius = history_radius(textureLoad(frames, p, 0).r);
    }
    if (z <= 0.0 || radius == 0) {
        return centre;
    }
    let x = world_from_csz(frame, vec2f(p) + 0.5, z);
    let n = oct_decode(textureLoad(npack, p, 0).rg);
    let size = vec2i(textureDimensions(src));
    var axis = vec2i(1, 0);
    if (DIRECTION == 1u) {
        axis = vec2i(0, 1);
    }
    var sum = centre;
    var weight = 1.0;
    for (var k = -radius; k <= radius; k++) {
        if (k == 0) {
            continue;
        }
        let q = p + axis * (k * blur.step);
        if (any(q < vec2i(0)) || any(q >= size)) {
            continue;
        }
        let zq = textureLoad(zpack, q, 0).r;
        if (zq <= 0.0) {
            continue;
        }
        let y = world_from_csz(frame, vec2f(q) + 0.5, zq);
        let nq = oct_decode(textureLoad(npack, q, 0).rg);
        let plane = max(0.0, 1.0 - blur.plane_sharpness * abs(dot(n, y - x)) / z);
        var normal = 1.0;
        let c = max(0.0, dot(n, nq));
        for (var e = 0u; e < blur.normal_power; e++) {
            normal *= c;
        }
        let a = u32(abs(k));
        var w = gauss_weight(a, radius) * plane * normal;
        if (blur.inv_radius2 > 0.0) {
            let d = y - x;
            w *= max(0.0, 1.0 - dot(d, d) * blur.inv_radius2);
        }
        sum += w * textureLoad(src, q, 0);
        weight += w;
    }
    return sum / weight;
}

@fragment
fn fs_main(@builtin(position) pos: vec4f) -> @location(0) vec4f {
    return filtered(vec2i(pos.xy));
}

// The same pass as compute (`Kernel`), 8×8 pixels per workgroup.
@group(1) @binding(5) var out: texture_storage_2d<STORAGE_FORMAT_0, write>;

@compute @workgroup_size(8, 8)
fn cs_main(@builtin(global_invocation_id) id: vec3u) {
    if (any(id.xy >= textureDimensions(out))) {
        return;
    }
    textureStore(out, id.xy, filtered(vec2i(id.xy)));
}
