// Index maths of interleaved deferred shading (Segovia et al. 2006, "ILS"),
// shared by every buffer splitting (BS) and buffer gathering (BG) pass.
// The CPU twin is `passes::interleave::InterleaveGeometry` (keep both in step).
//
// Terms (§3.2): the W×H interleaved image G is split into n×m sub-buffers G_ij;
// texel p goes to sub-buffer (i, j) = p mod (n, m) at local texel p div (n, m).
// The sub-buffers are tiled in one buffer: G_ij occupies the tile at
// (i, j)·tile, tile = ceil((W, H) / (n, m)). Tiled texels whose image texel
// lies outside W×H are padding and hold `padding` (never gathered back).
//
// Two-pass variant (§3.3, Fig. 2): blocks of block = (n, m)·sub_block texels
// are split into n×m sub-blocks of sub_block texels each (block splitting),
// then the sub-blocks are moved to their sub-buffers (block translation).

struct Interleave {
    size: vec2u,       // W, H of the interleaved image
    pattern: vec2u,    // n, m
    tile: vec2u,       // sub-buffer size ceil(W / n), ceil(H / m)
    sub_block: vec2u,  // sub-block size (Blocks)
    block: vec2u,      // block size = pattern * sub_block (Blocks)
    group: vec2u,      // per-sub-buffer texels of one compute workgroup (Compute)
    padding: vec4f,    // value written to padding texels
}

// Image texel p -> its texel in the tiled buffer (§3.2).
fn ils_split_index(p: vec2u, g: Interleave) -> vec2u {
    return (p % g.pattern) * g.tile + p / g.pattern;
}

// Sub-buffer (i, j) of tiled texel t (>= pattern when t lies right of / below the tiles).
fn ils_sub_buffer(t: vec2u, g: Interleave) -> vec2u {
    return t / g.tile;
}

// Tiled texel t -> image texel (the inverse of ils_split_index); out of the
// image (any component >= size) for padding texels.
fn ils_gather_index(t: vec2u, g: Interleave) -> vec2u {
    return (t % g.tile) * g.pattern + t / g.tile;
}

// Whether tiled texel t is padding (no image texel maps to it).
fn ils_is_padding(t: vec2u, g: Interleave) -> bool {
    return any(t / g.tile >= g.pattern) || any(ils_gather_index(t, g) >= g.size);
}

// Block splitting (§3.3, Fig. 2 b→c): image texel p -> its texel in the
// block-split buffer. Block b = p div block keeps its place; inside it texel
// u = p mod block goes to sub-block u mod pattern at u div pattern.
fn ils_block_split_index(p: vec2u, g: Interleave) -> vec2u {
    let u = p % g.block;
    return p - u + (u % g.pattern) * g.sub_block + u / g.pattern;
}

// Inverse of ils_block_split_index: block-split texel q -> image texel
// (out of the image for padding).
fn ils_block_gather_index(q: vec2u, g: Interleave) -> vec2u {
    let u = q % g.block;
    return q - u + (u % g.sub_block) * g.pattern + u / g.sub_block;
}

// Block translation (§3.3, Fig. 2 c→d): block-split texel q (sub-block s of
// block b, offset k) -> tiled texel s·tile + b·sub_block + k.
fn ils_block_translate_index(q: vec2u, g: Interleave) -> vec2u {
    let b = q / g.block;
    let u = q % g.block;
    return (u / g.sub_block) * g.tile + b * g.sub_block + u % g.sub_block;
}

// Inverse block translation: tiled texel t -> block-split texel.
fn ils_block_untranslate_index(t: vec2u, g: Interleave) -> vec2u {
    let s = t / g.tile;
    let l = t % g.tile;
    return (l / g.sub_block) * g.block + s * g.sub_block + l % g.sub_block;
}

// Whether texel p of the image plane (possibly past W×H, i.e. padding) has a
// texel in the tiles (false right of / below the last sub-buffer column / row).
fn ils_in_tiles(p: vec2u, g: Interleave) -> bool {
    return all(p / g.pattern < g.tile);
}
