// Issue 13 item 4 / BZB Table 3's "MIP map": min/max camera depth of the
// receivers (texels with a sample in sub-image 0 of `origins`) over square
// tiles of ZMINMAX_TILES sizes; one invocation per (level, tile). A tile with no
// receiver holds (+big, −big), so every splat over it is culled.

const BIG: f32 = 3.0e38;

@group(0) @binding(0) var<uniform> frame: Frame;
@group(1) @binding(0) var origins: texture_2d<f32>;
@group(1) @binding(1) var<storage, read_write> tiles: array<vec2f>;

@compute @workgroup_size(64)
fn cs_main(@builtin(global_invocation_id) gid: vec3u) {
    let size = vec2u(frame.size.xy);
    var i = gid.x;
    var offset = 0u;
    for (var level = 0u; level < ZMINMAX_LEVELS; level++) {
        let t = zminmax_tile(level);
        let n = (size + vec2u(t - 1u)) / t;
        if (i < n.x * n.y) {
            let tile = vec2u(i % n.x, i / n.x);
            var r = vec2f(BIG, -BIG);
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
            tiles[offset + i] = r;
            return;
        }
        i -= n.x * n.y;
        offset += n.x * n.y;
    }
}
