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
    // B: 1 = windows an edge cuts are re-weighted and slide (`slide_window`; not in the paper)
    slide: u32,
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

// A blurred value and the number of texels its window held (2r + 1 when uncut).
struct Blurred {
    v: vec4f,
    texels: f32,
}

// §4.5: from a pixel not on a discontinuity, both directions are explored; a
// neighbour is blended while the pixel before it (towards the centre) is
// similar to it, i.e. texel c + k·d needs DB(c + (k − 1)·d) = 0 going +d and
// DB(c − k·d) = 0 going −d (the flag of a texel says it differs from its +x/+y
// neighbours). From a pixel on a discontinuity only −d is explored. Colours of
// objects are never filtered (albedo is applied after, in compose).
fn blur_texels(c: vec2i, size: vec2i) -> Blurred {
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
    return Blurred(vec4f(sum / wsum, coverage(texels, alpha)), texels);
}

// Fig. 4 b: texels k and k + 1 in one bilinear tap at k + w_{k+1}/(w_k + w_{k+1})
// weighted w_k + w_{k+1}; the discontinuity buffer is read bilinearly at the
// same place and the tap (and the rest of the direction) is dropped as soon as
// it is > 0. Going −d this tests exactly the two texels' flags; going +d it
// tests flags k, k + 1 instead of k − 1, k (k − 1's was tested by the previous
// tap, or is the centre's): never more permissive than the texel form.
fn blur_bilinear(c: vec2i, size: vec2i) -> Blurred {
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
    return Blurred(vec4f(sum / wsum, coverage(texels, alpha)), texels);
}

// Not in the paper (`slide_window`). The last tap k in first..=last reachable from c along
// s·dir under blur_texels' rules: going +d, texel k + 1 needs the flag of texel k clear
// (its predecessor towards the centre); going −d, its own flag clear; both inside.
fn reach(c: vec2i, size: vec2i, s: i32, first: i32, last: i32) -> i32 {
    var k = first;
    while (k < last) {
        let q = c + (k + 1) * s * filt.dir;
        if (any(q < vec2i(0)) || any(q >= size)) {
            break;
        }
        if (select(flag(q), flag(c + k * filt.dir), s > 0)) {
            break;
        }
        k++;
    }
    return k;
}

// Not in the paper (`slide_window`): the window [−a, b] along dir of a pixel whose
// blur_texels (or blur_bilinear) window an edge or the border cuts on a side; (−1, −1)
// when neither side is cut. When it holds fewer than L = min(2r + 1, pattern) texels
// and one side is open, that side goes past r until the window holds L texels (or
// meets a cut).
fn cut_window(c: vec2i, size: vec2i) -> vec2i {
    let r = i32(filt.radius);
    let l = min(2 * r + 1, i32(max(filt.pattern, 1u)));
    var a = reach(c, size, -1, 0, r);
    var b = reach(c, size, 1, 0, r);
    if (a == r && b == r) {
        // the bilinear form also drops the last +d tap when texel r is flagged (its
        // tap reads the DB at r); the texel rule keeps it: sum it here, exactly
        if (filt.bilinear != 0u && r > 0 && flag(c + r * filt.dir)) {
            return vec2i(r);
        }
        return vec2i(-1);
    }
    if (a + b + 1 < l) {
        if (b == r) {
            b = reach(c, size, 1, r, l - 1 - a);
        } else if (a == r) {
            a = reach(c, size, -1, r, l - 1 - b);
        }
    }
    return vec2i(a, b);
}

fn gauss(k: i32) -> f32 {
    return exp(-0.5 * f32(k * k) / (filt.sigma * filt.sigma));
}

// The cut window's sum over its texels −a..=b. With equal sub-buffer weights each
// tap's Gaussian is divided by the Gaussian's sum over the window's taps of the same
// sub-buffer (offsets ≡ k mod period in [−a, b]), as `blur_weights` does for the whole
// window, so every sub-buffer the window holds weighs 1 (a window of ≤ n texels: each
// weighs 1); without them, the Gaussian.
fn blur_cut(c: vec2i, ab: vec2i) -> vec4f {
    let p = i32(filt.period);
    var sum = vec3f(0.0);
    var wsum = 0.0;
    var alpha = 0.0;
    // equal sub-buffer weights over ≤ period texels: each sub-buffer once, weight 1
    let boxed = p > 1 && ab.x + ab.y + 1 <= p;
    for (var k = -ab.x; k <= ab.y; k++) {
        var w = select(gauss(k), 1.0, boxed);
        if (p > 1 && !boxed) {
            var same = 0.0;
            for (var t = k - p * ((k + ab.x) / p); t <= ab.y; t += p) {
                same += gauss(t);
            }
            w /= same;
        }
        let t = textureLoad(src, c + k * filt.dir, 0);
        sum += w * t.rgb;
        wsum += w;
        alpha += t.a;
    }
    let texels = f32(ab.x + ab.y + 1);
    return vec4f(sum / wsum, coverage(texels, alpha));
}

@fragment
fn fs_blur(@builtin(position) pos: vec4f) -> @location(0) vec4f {
    let c = vec2i(pos.xy);
    let size = vec2i(textureDimensions(src));
    var b: Blurred;
    if (filt.bilinear != 0u) {
        b = blur_bilinear(c, size);
    } else {
        b = blur_texels(c, size);
    }
    // only a window cut on a side pays for the slide
    if (filt.slide != 0u && b.texels < f32(2u * filt.radius + 1u)) {
        let ab = cut_window(c, size);
        if (ab.x >= 0) {
            return blur_cut(c, ab);
        }
    }
    return b.v;
}
