// Per-object and per-material constants (match `scene_gpu::ObjectUniforms` and
// `scene_gpu::MaterialUniforms`).

struct ObjectUniforms {
    model: mat4x4f,
    // inverse-transpose of `model` (upper 3x3 used)
    normal_matrix: mat4x4f,
    // transform at frame t - 1 (reverse reprojection)
    prev_model: mat4x4f,
    // transform at frame t + 1 (exact for Delay, extrapolated for Predict)
    next_model: mat4x4f,
}

struct MaterialUniforms {
    // rgb = linear base colour, a = opacity
    base_color: vec4f,
    // rgb = emitted radiance, w = 1 when the texture's alpha multiplies the opacity
    emission: vec4f,
    // roughness, metallic, has_texture (0/1), alpha cutoff (< 0: none, not MASK)
    params: vec4f,
    // x = 1 for a glossy material (`Material::glossy`: ILS's GGX receivers)
    flags: vec4f,
}

// A fragment's alpha from the material and its texture sample `tex`, the rule
// of `strata_scene::Material::fragment_alpha` (CPU twin): a = opacity × (texture
// alpha if the material says so); MASK (cutoff ≥ 0): kept iff a ≥ cutoff, then
// opaque; otherwise kept with alpha a. Returns −1 for a cut fragment.
fn fragment_alpha(m: MaterialUniforms, tex: vec4f) -> f32 {
    var a = m.base_color.a;
    if (m.params.z > 0.5 && m.emission.w > 0.5) {
        a = a * tex.a;
    }
    if (m.params.w >= 0.0) {
        return select(-1.0, 1.0, a >= m.params.w);
    }
    return a;
}
