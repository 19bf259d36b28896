// The min/max depth tiles of the receivers (bzb_zminmax.wgsl writes them): ZMINMAX_LEVELS
// levels of square tiles, 8, 32, 128 pixels, then one tile over the whole image; and the
// splat culling that reads them (issue 13 item 4; BZB §4.3's "Min/Max MIP-map for splat
// culling"), shared by the AOV splats and DSS's shells.

const ZMINMAX_LEVELS: u32 = 4u;

fn zminmax_tile(level: u32) -> u32 {
    return select(8u << (2u * level), 0x40000000u, level == ZMINMAX_LEVELS - 1u);
}

// Whether some receiver under the pixel rectangle [rmin, rmax) of a `size` image has a
// camera depth in [zlo, zhi]: the tiles of the finest level on which the rectangle spans
// at most 3 × 3 of them. `tiles` is the importing shader's binding of the tiles
// (array<vec2f>, level after level).
fn receivers_in_range(size: vec2u, rmin: vec2f, rmax: vec2f, zlo: f32, zhi: f32) -> bool {
    let extent = max(rmax.x - rmin.x, rmax.y - rmin.y);
    var offset = 0u;
    for (var level = 0u; level < ZMINMAX_LEVELS; level++) {
        let t = zminmax_tile(level);
        let n = (size + vec2u(t - 1u)) / t;
        if (extent <= 2.0 * f32(t) || level == ZMINMAX_LEVELS - 1u) {
            let t0 = min(vec2u(rmin) / t, n - 1u);
            let t1 = min(vec2u(max(rmax - 1.0, rmin)) / t, n - 1u);
            for (var y = t0.y; y <= t1.y; y++) {
                for (var x = t0.x; x <= t1.x; x++) {
                    let r = tiles[offset + y * n.x + x];
                    if (r.x <= zhi && r.y >= zlo) {
                        return true;
                    }
                }
            }
            return false;
        }
        offset += n.x * n.y;
    }
    return true;
}
