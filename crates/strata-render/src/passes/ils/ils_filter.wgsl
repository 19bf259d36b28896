// ILS §4.5 filtering (F): the discontinuity buffer (DB) and the separable
// Gaussian blur (B) of the gathered irradiance that stops at discontinuities,
// in the texel-centre form (Fig. 4 a) and the bilinear-tap form (Fig. 4 b).
#import "common/fullscreen.wgsl"
#import "common/frame.wgsl"
#import "common/camera.wgsl"

struct Filter {
    // DB: a neighbour differs when its distance to the pixel's tangent plane
    // exceeds depth_threshold · z, or the normals' cosine is below normal_cos
    depth_threshold: f32,
    normal_cos: f32,
    // B: taps on each side along `dir`, Gaussian σ in pixels, 1 = bilinear taps
    radius: u32,
    sigma: f32,
    dir: vec2i,
    bilinear: u32,
    // B: the DB channel that stops the blur: 3 = §4.5's flag (three positive
    // neighbours), 0 / 1 = differs from the +x / +y neighbour (per-axis option)
    channel: u32,
    // B: > 1 = the interleave period along `dir` (equal sub-buffer weights)
    period: u32,
    // B: the interleave pattern's size along `dir` (n or m), for the coverage
    pattern: u32,
    // B: the tap weight at offset ±k is weights[k / 4][k % 4], k in 0..=radius
    // (`ils::blur_weights`: the Gaussian, or with a period divided by the window's sum
    // over the tap's sub-buffer)
    weights: array<vec4f, 9>,
}

@group(0) @binding(0) var<uniform> frame: Frame;
@group(1) @binding(0) var<uniform> filt: Filter;

// binding 1: DB reads the packed G-buffer (normal xyz, csz w), B the irradiance
@group(1) @binding(1) var src: texture_2d<f32>;
// B only: the discontinuity buffer and a linear, clamp-to-edge sampler
@group(1) @binding(2) var discontinuity: texture_2d<f32>;
@group(1) @binding(3) var bilinear_sampler: sampler;

// ---- DB ----

fn differs(p: vec2i, q: vec2i) -> bool {
    let a = textureLoad(src, p, 0);
    let b = textureLoad(src, q, 0);
    if (b.w <= 0.0) {
        return true;
    }
    if (dot(a.xyz, b.xyz) < filt.normal_cos) {
        return true;
    }
    let xa = world_from_csz(frame, vec2f(p) + 0.5, a.w);
    let xb = world_from_csz(frame, vec2f(q) + 0.5, b.w);
    // distance to the other's tangent plane, both ways (robust at grazing angles)
    let d = max(abs(dot(a.xyz, xb - xa)), abs(dot(b.xyz, xa - xb)));
    return d > filt.depth_threshold * min(a.w, b.w);
}

// a = §4.5's flag: 1 where the pixel is not similar to one of its three
// "positive" neighbours (x+1, y), (x, y+1), (x+1, y+1), or has no surface;
// r, g = the same against (x+1, y) and (x, y+1) alone (the per-axis option).
// Neighbours outside the image do not count (the blur stops at the border).
@fragment
fn fs_discontinuity(@builtin(position) pos: vec4f) -> @location(0) vec4f {
    let p = vec2i(pos.xy);
    let size = vec2i(textureDimensions(src));
    if (textureLoad(src, p, 0).w <= 0.0) {
        return vec4f(1.0);
    }
    var d = vec3f(0.0);
    for (var k = 0; k < 3; k++) {
        let o = array<vec2i, 3>(vec2i(1, 0), vec2i(0, 1), vec2i(1, 1))[k];
        let q = p + o;
        if (all(q < size) && differs(p, q)) {
            d[k] = 1.0;
        }
    }
    return vec4f(d.x, d.y, 0.0, max(d.x, max(d.y, d.z)));
}

// ---- B ----

// The weight of the tap at offset k in [−radius, radius] (symmetric in k).
fn weight(k: i32) -> f32 {
    let a = u32(abs(k));
    return filt.weights[a / 4u][a % 4u];
}

fn flag(p: vec2i) -> bool {
    return textureLoad(discontinuity, p, 0)[filt.channel] > 0.0;
}

// Not in the paper: the share of the n·m sub-buffers (VPL subsets) a blurred pixel
// averaged, in alpha. Taps along `dir` are contiguous, so `texels` of them cover
// min(texels, pattern) of the pattern's columns (rows); the vertical pass multiplies
// by the mean coverage of the rows it took (the source's alpha: 1 before the
// horizontal pass). `ils-refine` shades the pixels below a threshold again.
fn coverage(texels: f32, alpha_sum: f32) -> f32 {
    let p = f32(max(filt.pattern, 1u));
    return min(texels, p) / p * (alpha_sum / texels);
}

// §4.5: from a pixel not on a discontinuity, both directions are explored; a
// neighbour is blended while the pixel before it (towards the centre) is
// similar to it, i.e. texel c + k·d needs DB(c + (k − 1)·d) = 0 going +d and
// DB(c − k·d) = 0 going −d (the flag of a texel says it differs from its +x/+y
// neighbours). From a pixel on a discontinuity only −d is explored. Colours of
// objects are never filtered (albedo is applied after, in compose).
fn blur_texels(c: vec2i, size: vec2i) -> vec4f {
    let d = filt.dir;
    let r = i32(filt.radius);
    let w0 = weight(0);
    let s0 = textureLoad(src, c, 0);
    var sum = w0 * s0.rgb;
    var wsum = w0;
    var texels = 1.0;
    var alpha = s0.a;
    var prev_similar = !flag(c);
    for (var k = 1; k <= r; k++) {
        let q = c + k * d;
        if (!prev_similar || any(q >= size)) {
            break;
        }
        let w = weight(k);
        let t = textureLoad(src, q, 0);
        sum += w * t.rgb;
        wsum += w;
        texels += 1.0;
        alpha += t.a;
        prev_similar = !flag(q);
    }
    for (var k = 1; k <= r; k++) {
        let q = c - k * d;
        if (any(q < vec2i(0)) || flag(q)) {
            break;
        }
        let w = weight(-k);
        let t = textureLoad(src, q, 0);
        sum += w * t.rgb;
        wsum += w;
        texels += 1.0;
        alpha += t.a;
    }
    return vec4f(sum / wsum, coverage(texels, alpha));
}

// Fig. 4 b: texels k and k + 1 in one bilinear tap at k + w_{k+1}/(w_k + w_{k+1})
// weighted w_k + w_{k+1}; the discontinuity buffer is read bilinearly at the
// same place and the tap (and the rest of the direction) is dropped as soon as
// it is > 0. Going −d this tests exactly the two texels' flags; going +d it
// tests flags k, k + 1 instead of k − 1, k (k − 1's was tested by the previous
// tap, or is the centre's): never more permissive than the texel form.
fn blur_bilinear(c: vec2i, size: vec2i) -> vec4f {
    let d = filt.dir;
    let r = i32(filt.radius);
    let inv = 1.0 / vec2f(size);
    let centre = vec2f(c) + 0.5;
    let w0 = weight(0);
    let s0 = textureLoad(src, c, 0);
    var sum = w0 * s0.rgb;
    var wsum = w0;
    var texels = 1.0;
    var alpha = s0.a;
    for (var side = 0; side < 2; side++) {
        let s = select(-1, 1, side == 0);
        if (s > 0 && flag(c)) {
            continue;
        }
        for (var k = 1; k <= r; k += 2) {
            let wa = weight(s * k);
            let wb = select(0.0, weight(s * (k + 1)), k + 1 <= r);
            let last = c + s * select(k, k + 1, k + 1 <= r) * d;
            if (any(last < vec2i(0)) || any(last >= size)) {
                break;
            }
            let off = f32(k) + wb / (wa + wb);
            let uv = (centre + f32(s) * off * vec2f(d)) * inv;
            if (textureSampleLevel(discontinuity, bilinear_sampler, uv, 0.0)[filt.channel] > 0.0) {
                break;
            }
            let t = textureSampleLevel(src, bilinear_sampler, uv, 0.0);
            sum += (wa + wb) * t.rgb;
            wsum += wa + wb;
            // one texel in the last tap of an odd radius (wb = 0), else two
            let n = select(1.0, 2.0, k + 1 <= r);
            texels += n;
            alpha += n * t.a;
        }
    }
    return vec4f(sum / wsum, coverage(texels, alpha));
}

@fragment
fn fs_blur(@builtin(position) pos: vec4f) -> @location(0) vec4f {
    let c = vec2i(pos.xy);
    let size = vec2i(textureDimensions(src));
    if (filt.bilinear != 0u) {
        return blur_bilinear(c, size);
    }
    return blur_texels(c, size);
}
