// One pixel's A-buffer list, for every construction (ABA §IV): the stored
// fragment, the pass uniforms shared by the resolve and the multilayer AO
// (group 1, bindings 0–4), a walk over a pixel's fragments in storage order,
// and the bounded insertion sort that visits them in depth order.
struct Fragment {
    depth: f32,
    rg: u32,
    ba: u32,
    normal_facing: u32,
}

struct ResolveParams {
    width: u32,
    height: u32,
    pool: u32,
    slots: u32,
    // 0 linked list, 1 linear, 2 fixed array, 3 dual peel
    method: u32,
    // M (0 = no compression)
    compress: u32,
    // 1 = Eq. 5 searches only the back half
    back_half: u32,
    _pad: u32,
    // normalised depth z = min(csz · depth_scale, 65535) / 65535
    depth_scale: f32,
    _pad1: f32,
    _pad2: f32,
    _pad3: f32,
}

const SORT_BOUND: u32 = 16u;
const MAX_M: u32 = 16u;
const ONE16: u32 = 65535u;
const T_MIN: f32 = 1e-4;

@group(1) @binding(0) var<uniform> params: ResolveParams;
@group(1) @binding(1) var<storage, read> nodes: array<Fragment>;
@group(1) @binding(2) var<storage, read> links: array<u32>;
@group(1) @binding(3) var<storage, read> counts: array<u32>;
@group(1) @binding(4) var<storage, read> offsets: array<u32>;

// A walk over one pixel's stored fragments (any method), in storage order.
struct Walk {
    // linked list: next node + 1 (0 = end); others: next position k
    next: u32,
    // stored fragments (array methods) / steps taken (linked list)
    n: u32,
    base: u32,
    // dual peel: stored front layers
    fronts: u32,
}

fn walk_begin(p: u32) -> Walk {
    var w: Walk;
    switch params.method {
        case 0u: {
            w.next = counts[p];
        }
        case 1u: {
            let o = offsets[p];
            w.base = o;
            w.n = min(counts[p], params.pool - min(o, params.pool));
        }
        case 2u: {
            w.base = p * params.slots;
            w.n = min(counts[p], params.slots);
        }
        default: {
            w.base = p * params.slots;
            w.fronts = countOneBits(counts[2u * p]);
            w.n = w.fronts + countOneBits(counts[2u * p + 1u]);
        }
    }
    return w;
}

// The next node index, or 0xffffffff at the end (a linked list is cut after
// `pool` steps or at an index outside the pool: never a hang, never out of bounds).
fn walk_next(w: ptr<function, Walk>) -> u32 {
    if (params.method == 0u) {
        let nx = (*w).next;
        if (nx == 0u || nx > params.pool || (*w).n >= params.pool) {
            return 0xffffffffu;
        }
        (*w).n += 1u;
        (*w).next = links[nx - 1u];
        return nx - 1u;
    }
    let k = (*w).next;
    if (k >= (*w).n) {
        return 0xffffffffu;
    }
    (*w).next = k + 1u;
    if (params.method == 3u && k >= (*w).fronts) {
        return (*w).base + params.slots - 1u - (k - (*w).fronts);
    }
    return (*w).base + k;
}

fn key_less(d0: u32, i0: u32, d1: u32, i1: u32) -> bool {
    return d0 < d1 || (d0 == d1 && i0 < i1);
}

// One round of the bounded insertion sort: the (up to SORT_BOUND) smallest
// keys (depth bits, node) of pixel p's list greater than (last_d, last_i)
// (all keys when !started), sorted into kd/ki; returns how many. A list of
// n ≤ SORT_BOUND fragments takes one round, longer ones ⌈n / SORT_BOUND⌉.
fn sorted_batch(
    p: u32,
    started: bool,
    last_d: u32,
    last_i: u32,
    kd: ptr<function, array<u32, SORT_BOUND>>,
    ki: ptr<function, array<u32, SORT_BOUND>>,
) -> u32 {
    var k = 0u;
    var w = walk_begin(p);
    loop {
        let i = walk_next(&w);
        if (i == 0xffffffffu) {
            break;
        }
        let d = bitcast<u32>(nodes[i].depth);
        if (started && !key_less(last_d, last_i, d, i)) {
            continue;
        }
        if (k == SORT_BOUND && !key_less(d, i, (*kd)[k - 1u], (*ki)[k - 1u])) {
            continue;
        }
        // insertion into the sorted bounded array
        var j = min(k, SORT_BOUND - 1u);
        while (j > 0u && key_less(d, i, (*kd)[j - 1u], (*ki)[j - 1u])) {
            (*kd)[j] = (*kd)[j - 1u];
            (*ki)[j] = (*ki)[j - 1u];
            j--;
        }
        (*kd)[j] = d;
        (*ki)[j] = i;
        k = min(k + 1u, SORT_BOUND);
    }
    return k;
}
