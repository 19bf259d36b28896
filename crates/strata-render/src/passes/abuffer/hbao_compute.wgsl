// Compute-shader multilayer HBAO (ABA §V-B, Table III; after Bavoil's DX11
// compute HBAO): a workgroup shades a TILE × TILE tile of pixels; first it
// stages the compressed nodes (Eq. 5) of the tile plus an apron of `ao.apron`
// pixels on every side in workgroup memory, then every pixel runs the HBAO of
// `ao_common.wgsl` with the four axis directions +x, +y, −x, −y (the existing
// HBAO with D = 4 and φ = 0; S steps each, the paper's "8 samples along x and
// y"), taking at each step the strongest horizon over every staged layer
// (Algorithm 1). The apron is what the tile's taps reach (its nearest
// receivers' farthest step), capped by what fits in workgroup memory
// (`ao.apron`); taps beyond the cap read the node texture in global memory:
// the result does not depend on the tile, only the speed does. Receivers are the pixel's compressed nodes (Eq. 3–4 blend, so
// transparent nodes work too; ABA uses it for opaque scenes). The CPU twin is
// `passes::abuffer::ao::ambient_visibility_cpu` with kernel 2.
#import "abuffer/ao_common.wgsl"

@group(2) @binding(2) var av_out: texture_storage_2d<r32float, write>;

const TILE: u32 = 8u;
// 16 KiB, WebGPU's guaranteed maxComputeWorkgroupStorageSize.
const SHARED_WORDS: u32 = 4096u;

// The staged tile: (TILE + 2·apron)² pixels × `words` node words, row-major;
// a word is a compressed node (z16 << 16 | α16), 0 = empty.
var<workgroup> staged: array<u32, SHARED_WORDS>;
// The farthest step (pixels along an axis) of the tile's receivers, and the
// apron staged: min(that, `ao.apron`, what fits).
var<workgroup> tile_reach: atomic<u32>;
var<workgroup> tile_apron: u32;
// Top-left pixel of the staged region and its side, set per invocation.
var<private> stage_origin: vec2i;
var<private> stage_side: i32;

// Node words staged per pixel: all M with Algorithm 1, the nearest otherwise.
fn staged_words() -> u32 {
    if (ao.multilayer == 1u) {
        return params.compress;
    }
    return 1u;
}

// Node j of pixel q from the node texture (global memory).
fn global_node(q: vec2i, j: u32) -> u32 {
    return textureLoad(nodes_m, q, i32(j / 4u), 0)[j % 4u];
}

// The nearest node with α > 0 of pixel q (single layer), 0 if none.
fn nearest_node(q: vec2i) -> u32 {
    for (var j = 0u; j < params.compress; j++) {
        let w = global_node(q, j);
        if ((w & 0xffffu) != 0u) {
            return w;
        }
    }
    return 0u;
}

// Algorithm 1's inner loop at tap pixel q: max over its (staged) node words
// of α · getAO(x, node); outside the staged region the node texture.
fn tap_occlusion(q: vec2i, x: vec3f, n: vec3f) -> f32 {
    let centre = vec2f(q) + 0.5;
    let t = q - stage_origin;
    let words = staged_words();
    var a = 0.0;
    if (all(t >= vec2i(0)) && all(t < vec2i(stage_side))) {
        let base = u32(t.y * stage_side + t.x) * words;
        for (var j = 0u; j < words; j++) {
            let w = staged[base + j];
            if ((w & 0xffffu) != 0u) {
                a = max(a, node_occlusion(w, centre, x, n));
            }
        }
        return a;
    }
    // the apron is exceeded (r_p > apron): global reads
    if (ao.multilayer == 0u) {
        let w = nearest_node(q);
        if ((w & 0xffffu) != 0u) {
            a = node_occlusion(w, centre, x, n);
        }
        return max(a, 0.0);
    }
    for (var j = 0u; j < params.compress; j++) {
        let w = global_node(q, j);
        if ((w & 0xffffu) != 0u) {
            a = max(a, node_occlusion(w, centre, x, n));
        }
    }
    return a;
}

@compute @workgroup_size(8, 8, 1)
fn cs_main(
    @builtin(workgroup_id) wg: vec3u,
    @builtin(local_invocation_index) li: u32,
    @builtin(local_invocation_id) lid: vec3u,
) {
    let size = vec2i(i32(params.width), i32(params.height));
    let p = vec2i(wg.xy * TILE + lid.xy);
    // the apron this tile needs: the farthest step r_p (S − ½)/S of its
    // nearest receivers (deeper nodes have smaller r_p), capped by what fits
    if (li == 0u) {
        atomicStore(&tile_reach, 0u);
    }
    workgroupBarrier();
    if (all(p < size)) {
        let w0 = nearest_node(p);
        if ((w0 & 0xffffu) != 0u) {
            let z = (f32(w0 >> 16u) + 0.5) / params.depth_scale;
            let r_p = ao.proj_scale * ao.radius / z;
            let h = r_p * (f32(ao.steps) - 0.5) / f32(ao.steps);
            atomicMax(&tile_reach, u32(min(floor(h + 0.5), 65535.0)));
        }
    }
    workgroupBarrier();
    if (li == 0u) {
        tile_apron = min(atomicLoad(&tile_reach), ao.apron);
    }
    let apron = i32(workgroupUniformLoad(&tile_apron));
    stage_side = i32(TILE) + 2 * apron;
    stage_origin = vec2i(wg.xy * TILE) - vec2i(apron);
    let words = staged_words();
    // stage the tile + apron (the host keeps side² · words ≤ SHARED_WORDS)
    let count = u32(stage_side * stage_side);
    for (var i = li; i < count; i += TILE * TILE) {
        let q = stage_origin + vec2i(i32(i % u32(stage_side)), i32(i / u32(stage_side)));
        let inside = all(q >= vec2i(0)) && all(q < size);
        if (ao.multilayer == 1u) {
            for (var j = 0u; j < words; j++) {
                var w = 0u;
                if (inside) {
                    w = global_node(q, j);
                }
                staged[i * words + j] = w;
            }
        } else {
            var w = 0u;
            if (inside) {
                w = nearest_node(q);
            }
            staged[i] = w;
        }
    }
    workgroupBarrier();
    if (any(p >= size)) {
        return;
    }
    // φ = 0: the axis directions (the host sets rotate = 0, D = 4)
    var av = 0.0;
    var t = 1.0;
    compressed_receivers(p, 0.0, &av, &t);
    if (t >= T_MIN) {
        av += t;
    }
    textureStore(av_out, p, vec4f(av));
}
