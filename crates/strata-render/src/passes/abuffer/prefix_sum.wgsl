// Linear lists (ABA §IV-B), pass 2: exclusive prefix sum of the per-pixel
// fragment counts, offsets[i] = Σ_{j<i} counts[j] (the first node of pixel i).
// One workgroup of 256 invocations: each sums a contiguous chunk of
// ceil(n / 256) counts, the 256 chunk sums are scanned in workgroup memory
// (Hillis–Steele), then each invocation writes its chunk's offsets. Simple and
// bounded (no inter-workgroup synchronisation); not work-efficient for very
// large images (docs/abuffer.md).

struct ScanParams {
    // number of pixels
    n: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

const GROUP: u32 = 256u;

@group(0) @binding(0) var<uniform> params: ScanParams;
@group(0) @binding(1) var<storage, read> counts: array<u32>;
@group(0) @binding(2) var<storage, read_write> offsets: array<u32>;

var<workgroup> sums: array<u32, 256>;

@compute @workgroup_size(256)
fn cs_main(@builtin(local_invocation_index) t: u32) {
    let chunk = (params.n + GROUP - 1u) / GROUP;
    let begin = min(t * chunk, params.n);
    let end = min(begin + chunk, params.n);
    var s = 0u;
    for (var i = begin; i < end; i++) {
        s += counts[i];
    }
    sums[t] = s;
    workgroupBarrier();
    // inclusive scan of the chunk sums
    for (var d = 1u; d < GROUP; d <<= 1u) {
        var add = 0u;
        if (t >= d) {
            add = sums[t - d];
        }
        workgroupBarrier();
        sums[t] += add;
        workgroupBarrier();
    }
    var run = sums[t] - s;
    for (var i = begin; i < end; i++) {
        offsets[i] = run;
        run += counts[i];
    }
}
