// OIT resolve (ABA §III, §IV) and list compression (§III-B, Eq. 5) in one
// full-screen pass: per pixel, the fragment list is visited in depth order and
// blended front to back, C += T·α·L, T *= 1 − α, while T ≥ 1e-4; the
// background (sky) gets the remaining T (none once T < 1e-4). With compression on, every fragment
// (in the same order) is also inserted into an M-node array of (depth, α),
// written packed into `compressed` (layers 0…⌈M/4⌉−1: depth and α words;
// the next ⌈M/4⌉ layers: each node's normal and facing word).
//
// Sort: keys (depth bits, node index) — positive floats order as their bits,
// the index breaks ties. Rounds of a bounded insertion sort: each round walks
// the whole list and keeps the SORT_BOUND smallest keys greater than the last
// key blended; a list of n ≤ SORT_BOUND fragments takes one round, longer ones
// ceil(n / SORT_BOUND) rounds (O(n²/SORT_BOUND) reads, O(SORT_BOUND) memory).
#import "common/frame.wgsl"
#import "common/fullscreen.wgsl"

#import "abuffer/lists.wgsl"

@group(0) @binding(0) var<uniform> frame: Frame;
@group(1) @binding(5) var compressed: texture_storage_2d_array<rgba32uint, write>;

// Eq. 5 state: M nodes sorted by depth, 16-bit depth and α each.
var<private> cz: array<u32, 17>;
// each node's Oct16 normal and facing (the fragment's `normal_facing`), moved with it
var<private> cn: array<u32, 17>;
var<private> ca: array<u32, 17>;

// Inserts (z, a) after the nodes of depth ≤ z, then removes node
// i = argmin_j a_j·(1 − z_j) over the M + 1 nodes (integer: a_j·(65535 − z_j);
// ties: the largest j), searching j ≥ ⌊(M + 1)/2⌋ only with `back_half`.
// CPU twin: passes::abuffer::compress::insert.
fn compress_insert(z: u32, a: u32, nf: u32) {
    let m = params.compress;
    var pos = m;
    for (var j = 0u; j < m; j++) {
        if (cz[j] > z) {
            pos = j;
            break;
        }
    }
    for (var j = m; j > pos; j--) {
        cz[j] = cz[j - 1u];
        ca[j] = ca[j - 1u];
        cn[j] = cn[j - 1u];
    }
    cz[pos] = z;
    ca[pos] = a;
    cn[pos] = nf;
    var lo = 0u;
    if (params.back_half == 1u) {
        lo = (m + 1u) / 2u;
    }
    var evict = lo;
    var best = 0xffffffffu;
    for (var j = lo; j <= m; j++) {
        let metric = ca[j] * (ONE16 - cz[j]);
        if (metric <= best) {
            best = metric;
            evict = j;
        }
    }
    for (var j = evict; j < m; j++) {
        cz[j] = cz[j + 1u];
        ca[j] = ca[j + 1u];
        cn[j] = cn[j + 1u];
    }
}

struct ResolveOut {
    @location(0) color: vec4f,
    // fragments stored for this pixel (the `abuffer-count` debug view)
    @location(1) count: f32,
}

@fragment
fn fs_main(@builtin(position) frag: vec4f) -> ResolveOut {
    let px = vec2u(frag.xy);
    let p = px.y * params.width + px.x;
    var stored = 0u;
    var cw = walk_begin(p);
    while (walk_next(&cw) != 0xffffffffu) {
        stored += 1u;
    }
    let m = params.compress;
    for (var j = 0u; j < MAX_M; j++) {
        cz[j] = ONE16;
        ca[j] = 0u;
        cn[j] = 0u;
    }
    var c = vec3f(0.0);
    var t = 1.0;
    // last key blended (none yet)
    var last_d = 0u;
    var last_i = 0u;
    var started = false;
    loop {
        var kd: array<u32, SORT_BOUND>;
        var ki: array<u32, SORT_BOUND>;
        let k = sorted_batch(p, started, last_d, last_i, &kd, &ki);
        for (var j = 0u; j < k; j++) {
            let f = nodes[ki[j]];
            let rg = unpack2x16float(f.rg);
            let ba = unpack2x16float(f.ba);
            let a = ba.y;
            if (t >= T_MIN) {
                c += t * a * vec3f(rg, ba.x);
                t *= 1.0 - a;
            }
            if (m > 0u) {
                let z = u32(min(f.depth * params.depth_scale, 65535.0));
                let qa = u32(min(a * 65535.0, 65535.0));
                compress_insert(z, qa, f.normal_facing);
            }
        }
        if (k < SORT_BOUND || (m == 0u && t < T_MIN)) {
            break;
        }
        last_d = kd[k - 1u];
        last_i = ki[k - 1u];
        started = true;
    }
    if (t < T_MIN) {
        t = 0.0;
    }
    if (m > 0u) {
        let layers = (m + 3u) / 4u;
        for (var l = 0u; l < layers; l++) {
            var v = vec4u(0u);
            for (var e = 0u; e < 4u; e++) {
                let j = 4u * l + e;
                var word = ONE16 << 16u;
                if (j < m) {
                    word = (cz[j] << 16u) | ca[j];
                }
                v[e] = word;
            }
            textureStore(compressed, vec2i(px), i32(l), v);
            // layers ⌈M/4⌉…: the nodes' normal and facing words (the AO's receivers)
            var nv = vec4u(0u);
            for (var e = 0u; e < 4u; e++) {
                let j = 4u * l + e;
                if (j < m) {
                    nv[e] = cn[j];
                }
            }
            textureStore(compressed, vec2i(px), i32(l + layers), nv);
        }
    }
    var out: ResolveOut;
    out.color = vec4f(c + t * frame.sky.rgb, 1.0);
    out.count = f32(stored);
    return out;
}
