// Buffer splitting (BS) and gathering (BG) of interleaved deferred shading
// (Segovia et al. 2006) as one compute pass each: the GPU-compute analogue of
// §3.3's coherent block moves. A workgroup owns an image region of
// (n·a)×(m·b) texels, which is exactly an a×b rectangle of every sub-buffer
// (a, b = ils.group): it reads the region row by row into workgroup memory and
// writes each sub-buffer's rectangle row by row (BS), or the reverse (BG).
// `STORAGE_FORMAT` is replaced by the texture format's WGSL name.
#import "common/interleave.wgsl"

@group(0) @binding(0) var<uniform> ils: Interleave;
@group(0) @binding(1) var src: texture_2d<f32>;
@group(0) @binding(2) var dst: texture_storage_2d<STORAGE_FORMAT, write>;

const THREADS: u32 = 256u;
// 1024 vec4f = 16 KiB, WebGPU's default workgroup-storage limit; n·a, m·b <= 32.
var<workgroup> region: array<vec4f, 1024>;

// Region texel of the k-th texel in sub-buffer-major order (sub-buffer
// (i, j) = (s mod n, s div n), then its rectangle's rows): consecutive k walk
// one sub-buffer row, i.e. contiguous texels of the tiled buffer.
fn sub_buffer_order(k: u32) -> vec2u {
    let per = ils.group.x * ils.group.y;
    let s = k / per;
    let r = k % per;
    let sub = vec2u(s % ils.pattern.x, s / ils.pattern.x);
    let local = vec2u(r % ils.group.x, r / ils.group.x);
    return local * ils.pattern + sub;
}

@compute @workgroup_size(256)
fn cs_split(@builtin(workgroup_id) wg: vec3u, @builtin(local_invocation_index) li: u32) {
    let extent = ils.pattern * ils.group;
    let origin = wg.xy * extent;
    let count = extent.x * extent.y;
    // coherent read of the image region, row-major (texels outside the image: padding)
    for (var k = li; k < count; k += THREADS) {
        let p = origin + vec2u(k % extent.x, k / extent.x);
        var v = ils.padding;
        if all(p < ils.size) {
            v = textureLoad(src, p, 0);
        }
        region[k] = v;
    }
    workgroupBarrier();
    // contiguous writes, one sub-buffer rectangle after the other
    for (var k = li; k < count; k += THREADS) {
        let r = sub_buffer_order(k);
        let p = origin + r;
        if ils_in_tiles(p, ils) {
            textureStore(dst, ils_split_index(p, ils), region[r.y * extent.x + r.x]);
        }
    }
}

@compute @workgroup_size(256)
fn cs_gather(@builtin(workgroup_id) wg: vec3u, @builtin(local_invocation_index) li: u32) {
    let extent = ils.pattern * ils.group;
    let origin = wg.xy * extent;
    let count = extent.x * extent.y;
    // contiguous reads of every sub-buffer's rectangle
    for (var k = li; k < count; k += THREADS) {
        let r = sub_buffer_order(k);
        let p = origin + r;
        if all(p < ils.size) {
            region[r.y * extent.x + r.x] = textureLoad(src, ils_split_index(p, ils), 0);
        }
    }
    workgroupBarrier();
    // coherent write of the image region, row-major
    for (var k = li; k < count; k += THREADS) {
        let p = origin + vec2u(k % extent.x, k / extent.x);
        if all(p < ils.size) {
            textureStore(dst, p, region[k]);
        }
    }
}
