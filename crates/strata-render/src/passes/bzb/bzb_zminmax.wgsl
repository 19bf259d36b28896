// Issue 13 item 4 / BZB Table 3's "MIP map": min/max camera depth of the
// receivers (texels with a sample in sub-image 0 of `origins`) over square
// tiles of ZMINMAX_TILES sizes, one dispatch per level, one invocation per
// tile: level 0 reads its ≤ 8×8 texels, every coarser level the 4×4 tiles (the
// whole-image level: all tiles) of the level below, written by the previous
// dispatch. A tile with no receiver holds (+big, −big), so every splat over it
// is culled. (One invocation per tile reading texels at every level took 45 ms
// at 768×512 on an H100: the whole-image tile was 393k serial loads.)

#import "common/zminmax.wgsl"

const BIG: f32 = 3.0e38;

override LEVEL: u32 = 0u;

@group(0) @binding(0) var<uniform> frame: Frame;
@group(1) @binding(0) var origins: texture_2d<f32>;
@group(1) @binding(1) var<storage, read_write> tiles: array<vec2f>;

fn tiles_of(level: u32, size: vec2u) -> vec2u {
    let t = zminmax_tile(level);
    return (size + vec2u(t - 1u)) / t;
}

@compute @workgroup_size(64)
fn cs_main(@builtin(global_invocation_id) gid: vec3u) {
    let size = vec2u(frame.size.xy);
    var offset = 0u;
    var below = 0u;
    for (var level = 0u; level < LEVEL; level++) {
        let m = tiles_of(level, size);
        below = offset;
        offset += m.x * m.y;
    }
    let n = tiles_of(LEVEL, size);
    let i = gid.x;
    if (i >= n.x * n.y) {
        return;
    }
    let tile = vec2u(i % n.x, i / n.x);
    let t = zminmax_tile(LEVEL);
    var r = vec2f(BIG, -BIG);
    if (LEVEL == 0u) {
        let end = min((tile + 1u) * t, size);
        for (var y = tile.y * t; y < end.y; y++) {
            for (var x = tile.x * t; x < end.x; x++) {
                let o = textureLoad(origins, vec2i(vec2u(x, y)), 0);
                if (o.w > 0.0) {
                    let z = dot(o.xyz - frame.eye.xyz, frame.cam_forward.xyz);
                    r = vec2f(min(r.x, z), max(r.y, z));
                }
            }
        }
    } else {
        // the tiles of the level below inside this one (tile sizes divide)
        let tc = zminmax_tile(LEVEL - 1u);
        let nc = tiles_of(LEVEL - 1u, size);
        let first = tile * (t / tc);
        let end = min((tile + 1u) * (t / tc), nc);
        for (var y = first.y; y < end.y; y++) {
            for (var x = first.x; x < end.x; x++) {
                let c = tiles[below + y * nc.x + x];
                r = vec2f(min(r.x, c.x), max(r.y, c.y));
            }
        }
    }
    tiles[offset + i] = r;
}
