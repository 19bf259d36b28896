// Buffer splitting (BS) and buffer gathering (BG) of interleaved deferred
// shading (Segovia et al. 2006, §3.2–3.4) as full-screen fragment programs:
// every output texel reads its input texel through the shared index maths
// (common/interleave.wgsl). One entry point per pass; all share one layout.
#import "common/fullscreen.wgsl"
#import "common/interleave.wgsl"

@group(0) @binding(0) var<uniform> ils: Interleave;
@group(0) @binding(1) var src: texture_2d<f32>;

fn fetch(p: vec2u) -> vec4f {
    return textureLoad(src, p, 0);
}

// BS, one pass (§3.2, Table 1's baseline): tiled texel t <- image texel.
@fragment
fn fs_naive_split(@builtin(position) pos: vec4f) -> @location(0) vec4f {
    let t = vec2u(pos.xy);
    if ils_is_padding(t, ils) {
        return ils.padding;
    }
    return fetch(ils_gather_index(t, ils));
}

// BG, one pass: image texel p <- tiled texel.
@fragment
fn fs_naive_gather(@builtin(position) pos: vec4f) -> @location(0) vec4f {
    return fetch(ils_split_index(vec2u(pos.xy), ils));
}

// BS pass 1, block splitting (§3.3, Fig. 2 b→c): block-split texel q <- image texel.
@fragment
fn fs_block_splitting(@builtin(position) pos: vec4f) -> @location(0) vec4f {
    let p = ils_block_gather_index(vec2u(pos.xy), ils);
    if any(p >= ils.size) {
        return ils.padding;
    }
    return fetch(p);
}

// BS pass 2, block translation (§3.3, Fig. 2 c→d): tiled texel t <- block-split texel.
@fragment
fn fs_block_translation(@builtin(position) pos: vec4f) -> @location(0) vec4f {
    let t = vec2u(pos.xy);
    if ils_is_padding(t, ils) {
        return ils.padding;
    }
    return fetch(ils_block_untranslate_index(t, ils));
}

// BG pass 1, block translation back (§3.4): block-split texel q <- tiled texel.
@fragment
fn fs_block_untranslation(@builtin(position) pos: vec4f) -> @location(0) vec4f {
    let q = vec2u(pos.xy);
    if any(ils_block_gather_index(q, ils) >= ils.size) {
        return ils.padding;
    }
    return fetch(ils_block_translate_index(q, ils));
}

// BG pass 2, block gathering (§3.4): image texel p <- block-split texel.
@fragment
fn fs_block_gathering(@builtin(position) pos: vec4f) -> @location(0) vec4f {
    return fetch(ils_block_split_index(vec2u(pos.xy), ils));
}
