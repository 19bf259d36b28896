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
    // rgb = emitted radiance
    emission: vec4f,
    // roughness, metallic, has_texture (0/1), alpha cutoff
    params: vec4f,
}
