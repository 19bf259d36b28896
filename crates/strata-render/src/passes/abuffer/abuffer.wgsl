// A-buffer construction (Bauer et al. 2013, "ABA" §IV): every rasterised
// fragment of every object (opaque included; no depth test, no culling) is
// shaded once and stored in a per-pixel fragment list. One fragment entry per
// construction method:
//   fs_linked_list  PPLL (§IV-A): global atomic counter, head pointer per pixel, node pool
//   fs_count        linear lists (§IV-B), pass 1: per-pixel fragment count
//   fs_linear       linear lists, pass 3: fill the pixel's contiguous range (after the prefix sum)
//   fs_fixed_array  Texture3D (§IV-C): K slots per pixel + per-pixel counter
//   fs_dual_init    dual depth peeling baseline: nearest and farthest depth of every pixel
//   fs_dual_peel    one dual peel: stores the front and the back layer, narrows the interval
// Overflow never writes out of bounds: the fragment is dropped and counted
// (stats[STAT_OVERFLOW]); see docs/abuffer.md for which fragments are dropped.
#import "common/camera.wgsl"
#import "common/packing.wgsl"
#import "common/scene.wgsl"
#import "common/lights.wgsl"

// One stored fragment (16 bytes; `abuffer::GpuFragment` on the CPU).
struct Fragment {
    // camera-space depth csz (as the deep G-buffer stores it), > 0
    depth: f32,
    // pack2x16float(radiance.r, radiance.g)
    rg: u32,
    // pack2x16float(radiance.b, alpha)
    ba: u32,
    // bits 0-15: Oct16 normal (toward the camera), bit 16: front facing
    normal_facing: u32,
}

struct DrawParams {
    width: u32,
    height: u32,
    // nodes in the pool (linked list, linear)
    pool: u32,
    // slots per pixel (fixed array: K; dual peel: 2·ceil(L/2))
    slots: u32,
    light_count: u32,
    // dual peel: index of this peel and of the last one
    peel: u32,
    last_peel: u32,
    _pad: u32,
}

const STAT_COUNTER: u32 = 0u;
const STAT_OVERFLOW: u32 = 1u;
const STAT_TOTAL: u32 = 2u;

@group(0) @binding(0) var<uniform> frame: Frame;
@group(1) @binding(0) var<uniform> object: ObjectUniforms;
@group(2) @binding(0) var<uniform> material: MaterialUniforms;
@group(2) @binding(1) var base_tex: texture_2d<f32>;
@group(2) @binding(2) var base_sampler: sampler;
@group(3) @binding(0) var<uniform> params: DrawParams;
@group(3) @binding(1) var<storage, read> lights: array<GpuLight>;
@group(3) @binding(2) var<storage, read_write> nodes: array<Fragment>;
// linked list: next pointer per node (node index + 1, 0 = end of list)
@group(3) @binding(3) var<storage, read_write> links: array<u32>;
// linked list: head pointer per pixel (node index + 1, 0 = empty);
// linear / fixed array: fragments per pixel; dual peel: 2 words per pixel,
// bit p set = the front (word 0) / back (word 1) layer of peel p is stored
@group(3) @binding(4) var<storage, read_write> counts: array<atomic<u32>>;
// linear: exclusive prefix sum of `counts` (first node of the pixel)
@group(3) @binding(5) var<storage, read_write> offsets: array<u32>;
// linear: fill cursor per pixel; dual peel: the next peel's interval (2 words per pixel)
@group(3) @binding(6) var<storage, read_write> cursor: array<atomic<u32>>;
// counter, overflow, total fragments, 0
@group(3) @binding(7) var<storage, read_write> stats: array<atomic<u32>>;
// dual peel: this peel's interval, 2 words per pixel: ~bits(nearest), bits(farthest)
@group(3) @binding(8) var<storage, read_write> interval: array<u32>;

struct VsOut {
    @builtin(position) clip: vec4f,
    @location(0) world: vec3f,
    @location(1) normal: vec3f,
    @location(2) uv: vec2f,
    // camera-space depth (clip w of the reversed-Z projection)
    @location(3) csz: f32,
}

@vertex
fn vs_main(@location(0) position: vec3f, @location(1) normal: vec3f, @location(2) uv: vec2f) -> VsOut {
    let w = object.model * vec4f(position, 1.0);
    var o: VsOut;
    o.clip = frame.view_proj * w;
    o.world = w.xyz;
    o.normal = (object.normal_matrix * vec4f(normal, 0.0)).xyz;
    o.uv = uv;
    o.csz = o.clip.w;
    return o;
}

const INV_PI: f32 = 0.31830988618379067;

// The fragment's material α (opacity × base-colour texture alpha) and shaded
// radiance L = emission + albedo·ambient + albedo/π · Σ_l E_l(x, n_c), n_c the
// shading normal flipped toward the camera, E_l unshadowed (no shadows in the
// A-buffer; emissive triangles light nothing). CPU twin: strata_reference::oit::shade.
struct Shaded {
    frag: Fragment,
    // below the material's alpha cutoff (MASK): not a fragment at all
    cut: bool,
}

fn shade(in: VsOut, front: bool) -> Shaded {
    // sample first: uniform control flow for the derivatives
    let tex = textureSample(base_tex, base_sampler, in.uv);
    var base = material.base_color;
    if (material.params.z > 0.5) {
        base = base * tex;
    }
    // α by `Material::fragment_alpha`'s rule (MASK cut or opaque, else blended)
    let alpha = fragment_alpha(material, tex);
    var n = normalize(in.normal);
    if (dot(n, frame.eye.xyz - in.world) < 0.0) {
        n = -n;
    }
    var e = vec3f(0.0);
    for (var i = 0u; i < params.light_count; i++) {
        e += light_irradiance(lights[i], in.world, n);
    }
    let radiance = material.emission.rgb + base.rgb * frame.ambient.rgb + base.rgb * INV_PI * e;
    let o = oct_encode(n);
    let q = vec2u(round(clamp(o, vec2f(0.0), vec2f(1.0)) * 255.0));
    var s: Shaded;
    s.frag.depth = in.csz;
    s.frag.rg = pack2x16float(radiance.rg);
    s.frag.ba = pack2x16float(vec2f(radiance.b, max(alpha, 0.0)));
    s.frag.normal_facing = q.x | (q.y << 8u) | (select(0u, 1u, front) << 16u);
    s.cut = alpha < 0.0;
    return s;
}

fn pixel(in: VsOut) -> u32 {
    let p = vec2u(in.clip.xy);
    return p.y * params.width + p.x;
}

// PPLL (§IV-A): node = atomicAdd(counter); beyond the pool the fragment is
// dropped (counted), so only in-pool nodes are ever linked.
@fragment
fn fs_linked_list(in: VsOut, @builtin(front_facing) front: bool) -> @location(0) vec4f {
    let s = shade(in, front);
    if (s.cut) {
        discard;
    }
    atomicAdd(&stats[STAT_TOTAL], 1u);
    let idx = atomicAdd(&stats[STAT_COUNTER], 1u);
    if (idx >= params.pool) {
        atomicAdd(&stats[STAT_OVERFLOW], 1u);
        return vec4f(0.0);
    }
    nodes[idx] = s.frag;
    links[idx] = atomicExchange(&counts[pixel(in)], idx + 1u);
    return vec4f(0.0);
}

// Linear lists (§IV-B), pass 1: count.
@fragment
fn fs_count(in: VsOut, @builtin(front_facing) front: bool) -> @location(0) vec4f {
    let s = shade(in, front);
    if (s.cut) {
        discard;
    }
    atomicAdd(&stats[STAT_TOTAL], 1u);
    atomicAdd(&counts[pixel(in)], 1u);
    return vec4f(0.0);
}

// Linear lists, pass 3: fill offsets[p] + slot; slots past the pool are dropped.
@fragment
fn fs_linear(in: VsOut, @builtin(front_facing) front: bool) -> @location(0) vec4f {
    let s = shade(in, front);
    if (s.cut) {
        discard;
    }
    let p = pixel(in);
    let slot = atomicAdd(&cursor[p], 1u);
    let idx = offsets[p] + slot;
    if (idx >= params.pool) {
        atomicAdd(&stats[STAT_OVERFLOW], 1u);
        return vec4f(0.0);
    }
    nodes[idx] = s.frag;
    return vec4f(0.0);
}

// Texture3D (§IV-C): slot = atomicAdd(count); slots ≥ K are dropped.
@fragment
fn fs_fixed_array(in: VsOut, @builtin(front_facing) front: bool) -> @location(0) vec4f {
    let s = shade(in, front);
    if (s.cut) {
        discard;
    }
    atomicAdd(&stats[STAT_TOTAL], 1u);
    let p = pixel(in);
    let slot = atomicAdd(&counts[p], 1u);
    if (slot >= params.slots) {
        atomicAdd(&stats[STAT_OVERFLOW], 1u);
        return vec4f(0.0);
    }
    nodes[p * params.slots + slot] = s.frag;
    return vec4f(0.0);
}

// Dual depth peeling: the interval [nearest, farthest] of the pixel's
// fragments as two atomic maxima of the depth's bits (positive floats order as
// their bits): word 0 = max(~bits) = ~bits(min depth), word 1 = max(bits).
fn widen_interval(p: u32, depth: f32) {
    let b = bitcast<u32>(depth);
    atomicMax(&cursor[2u * p], ~b);
    atomicMax(&cursor[2u * p + 1u], b);
}

@fragment
fn fs_dual_init(in: VsOut, @builtin(front_facing) front: bool) -> @location(0) vec4f {
    let s = shade(in, front);
    if (s.cut) {
        discard;
    }
    atomicAdd(&stats[STAT_TOTAL], 1u);
    widen_interval(pixel(in), s.frag.depth);
    return vec4f(0.0);
}

// Peel p: the fragment at the interval's near end is front layer p, the one at
// its far end back layer p; fragments strictly inside widen the next interval
// (or, in the last peel, overflow). Two fragments at the same depth cannot be
// told apart by peeling: the second is dropped and counted.
@fragment
fn fs_dual_peel(in: VsOut, @builtin(front_facing) front: bool) -> @location(0) vec4f {
    let s = shade(in, front);
    if (s.cut) {
        discard;
    }
    let p = pixel(in);
    let b = bitcast<u32>(s.frag.depth);
    let near = ~interval[2u * p];
    let far = interval[2u * p + 1u];
    if (b < near || b > far) {
        return vec4f(0.0);
    }
    let bit = 1u << params.peel;
    if (b == near || b == far) {
        let back = b != near;
        let word = 2u * p + select(0u, 1u, back);
        let old = atomicOr(&counts[word], bit);
        if ((old & bit) != 0u) {
            atomicAdd(&stats[STAT_OVERFLOW], 1u);
            return vec4f(0.0);
        }
        var slot = params.peel;
        if (back) {
            slot = params.slots - 1u - params.peel;
        }
        nodes[p * params.slots + slot] = s.frag;
        return vec4f(0.0);
    }
    if (params.peel == params.last_peel) {
        atomicAdd(&stats[STAT_OVERFLOW], 1u);
    } else {
        widen_interval(p, s.frag.depth);
    }
    return vec4f(0.0);
}
