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
// 16 KiB of RGBA32Uint texels, WebGPU's guaranteed maxComputeWorkgroupStorageSize.
const SHARED_TEXELS: u32 = 1024u;

// The staged tile: (TILE + 2·apron)² pixels × `staged_texels()` texels,
// row-major, each texel four compressed node words (z16 << 16 | α16, 0 =
// empty) as in the node texture, so a tap reads 4 nodes per load.
var<workgroup> staged: array<vec4u, SHARED_TEXELS>;
// The farthest step (pixels along an axis) of the tile's receivers, and the
// apron staged: min(that, `ao.apron`, what fits).
var<workgroup> tile_reach: atomic<u32>;
var<workgroup> tile_apron: u32;
// Top-left pixel of the staged region and its side, set per invocation.
var<private> stage_origin: vec2i;
var<private> stage_side: i32;

// Node words per pixel that occlude: all M with Algorithm 1, the nearest otherwise.
fn occluder_words() -> u32 {
    if (ao.multilayer == 1u) {
        return params.compress;
    }
    return 1u;
}

// Texels staged per pixel: ⌈M/4⌉, or one holding the nearest node.
fn staged_texels() -> u32 {
    return (occluder_words() + 3u) / 4u;
}

// The nearest node with α > 0 of pixel q (single layer), 0 if none.
fn nearest_node(q: vec2i) -> u32 {
    for (var l = 0u; l < (params.compress + 3u) / 4u; l++) {
        let v = textureLoad(nodes_m, q, i32(l), 0);
        for (var e = 0u; e < 4u; e++) {
            if (4u * l + e < params.compress && (v[e] & 0xffffu) != 0u) {
                return v[e];
            }
        }
    }
    return 0u;
}

// Texel l of pixel q as the taps see it: the node texture's, or (single
// layer) the nearest node alone.
fn tap_texel_nodes(q: vec2i, l: u32) -> vec4u {
    if (ao.multilayer == 1u) {
        return textureLoad(nodes_m, q, i32(l), 0);
    }
    return vec4u(nearest_node(q), 0u, 0u, 0u);
}

// Algorithm 1's inner loop at tap pixel q: max over its (staged) node words
// of α · getAO(x, node); outside the staged region the node texture.
fn tap_occlusion(q: vec2i, x: vec3f, n: vec3f) -> f32 {
    let centre = vec2f(q) + 0.5;
    let t = q - stage_origin;
    let texels = staged_texels();
    let words = occluder_words();
    let inside = all(t >= vec2i(0)) && all(t < vec2i(stage_side));
    var a = 0.0;
    for (var l = 0u; l < texels; l++) {
        var v: vec4u;
        if (inside) {
            v = staged[u32(t.y * stage_side + t.x) * texels + l];
        } else {
            // the apron is exceeded (r_p > apron): global reads
            v = tap_texel_nodes(q, l);
        }
        for (var e = 0u; e < 4u; e++) {
            if (4u * l + e < words && (v[e] & 0xffffu) != 0u) {
                a = max(a, node_occlusion(v[e], centre, x, n));
            }
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
    let texels = staged_texels();
    // stage the tile + apron (the host keeps side² · texels ≤ SHARED_TEXELS)
    let count = u32(stage_side * stage_side);
    for (var i = li; i < count; i += TILE * TILE) {
        let q = stage_origin + vec2i(i32(i % u32(stage_side)), i32(i / u32(stage_side)));
        let inside = all(q >= vec2i(0)) && all(q < size);
        for (var l = 0u; l < texels; l++) {
            var v = vec4u(0u);
            if (inside) {
                v = tap_texel_nodes(q, l);
            }
            staged[i * texels + l] = v;
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
