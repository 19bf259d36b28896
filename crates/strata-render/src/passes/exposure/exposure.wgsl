// Auto-exposure (not in the four papers): the exposure that maps the image's typical
// luminance to a key value, key / L̄ (Reinhard et al. 2002, "Photographic tone
// reproduction", Eq. 2), adapted over frames in log space. L̄ = 2^(mean log2 L) over the
// non-black pixels between two percentiles of a log2-luminance histogram (as game
// engines' eye adaptation does): with the plain log-average of Eq. 1, an image that is
// half black background or deep shadow was metered as if it were dark all over. `cs_histogram`
// counts each 16×16 tile's pixels per bin; `cs_exposure` reads the histogram and writes
// the exposure. CPU twin: `exposure::metered_exposure`.

struct Meter {
    key: f32,
    // the new exposure's weight in log space per frame (1: at once)
    adaptation: f32,
    // the percentile window metered (fractions of the pixels, darkest first)
    low: f32,
    high: f32,
    // 0: no exposure from an earlier frame (the first frame, a cut): the new one at once
    has_history: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
    // the image inside the guard band: origin (xy) and size (zw) in texels
    image: vec4u,
}

@group(0) @binding(0) var<uniform> meter: Meter;
@group(0) @binding(1) var hdr: texture_2d<f32>;
// pixels per bin (cleared before each frame)
@group(0) @binding(2) var<storage, read_write> histogram: array<atomic<u32>, BINS>;
// [0] the exposure, [1] L̄
@group(0) @binding(3) var<storage, read_write> metered: array<f32>;

// bin b holds log2 L in [MIN_LOG2 + b / BINS_PER_STOP, … + 1 / BINS_PER_STOP); black and
// darker pixels fall in bin 0, which is not metered (black carries no exposure: a
// background without sky, unlit shadows), brighter ones than the range in the last
const BINS: u32 = 128u;
const BINS_PER_STOP: f32 = 4.0;
const MIN_LOG2: f32 = -16.0;
// the exposure stays within these bounds
const MIN_EXPOSURE: f32 = 1e-6;
const MAX_EXPOSURE: f32 = 1e6;

// The bin of a linear rgb pixel: Rec. 709 luminance; NaN and negative values count as
// black.
fn bin_of(c: vec3f) -> u32 {
    let l = dot(c, vec3f(0.2126, 0.7152, 0.0722));
    if (!(l > 0.0)) {
        return 0u;
    }
    let b = floor((log2(l) - MIN_LOG2) * BINS_PER_STOP);
    return u32(clamp(b, 0.0, f32(BINS - 1u)));
}

// One invocation per 16×16 tile of the image (not the guard band): a private histogram,
// then one atomic add per bin it holds (few atomics and no workgroup barriers, which a
// CPU adapter runs slowly).
@compute @workgroup_size(8, 8)
fn cs_histogram(@builtin(global_invocation_id) id: vec3u) {
    let size = meter.image.zw;
    let tiles = (size + vec2u(15u)) / 16u;
    if (any(id.xy >= tiles)) {
        return;
    }
    var local: array<u32, BINS>;
    let origin = meter.image.xy + id.xy * 16u;
    let end = min(origin + vec2u(16u), meter.image.xy + size);
    for (var y = origin.y; y < end.y; y++) {
        for (var x = origin.x; x < end.x; x++) {
            local[bin_of(textureLoad(hdr, vec2u(x, y), 0).rgb)] += 1u;
        }
    }
    for (var b = 0u; b < BINS; b++) {
        if (local[b] > 0u) {
            atomicAdd(&histogram[b], local[b]);
        }
    }
}

// The mean log2 L (bin centres) of the pixels between the `low` and `high` percentiles
// of those brighter than bin 0.
@compute @workgroup_size(1)
fn cs_exposure() {
    var total = 0.0;
    for (var b = 1u; b < BINS; b++) {
        total += f32(atomicLoad(&histogram[b]));
    }
    let lo = meter.low * total;
    let hi = meter.high * total;
    var below = 0.0;
    var weight = 0.0;
    var sum = 0.0;
    for (var b = 1u; b < BINS; b++) {
        let n = f32(atomicLoad(&histogram[b]));
        // the part of this bin's pixels inside [lo, hi]
        let w = max(0.0, min(below + n, hi) - max(below, lo));
        sum += w * (MIN_LOG2 + (f32(b) + 0.5) / BINS_PER_STOP);
        weight += w;
        below += n;
    }
    // an all-black image: L̄ = 1
    let mean = select(0.0, sum / weight, weight > 0.0);
    // log2(key / L̄)
    var e = clamp(log2(meter.key) - mean, log2(MIN_EXPOSURE), log2(MAX_EXPOSURE));
    if (meter.has_history != 0u) {
        e = mix(log2(metered[0]), e, meter.adaptation);
    }
    metered[0] = exp2(e);
    metered[1] = exp2(mean);
}
