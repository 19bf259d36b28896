// Per-frame constants shared by every pass (matches `frame::FrameUniforms`).
struct Frame {
    view: mat4x4f,
    proj: mat4x4f,
    view_proj: mat4x4f,
    inv_view_proj: mat4x4f,
    prev_view_proj: mat4x4f,
    // frame t + 1 (exact for Delay, extrapolated for Predict)
    next_view_proj: mat4x4f,
    // xyz = eye, w = near plane
    eye: vec4f,
    // xyz = camera right * tan(fov_y/2) * aspect
    cam_right: vec4f,
    // xyz = camera up * tan(fov_y/2)
    cam_up: vec4f,
    // xyz = unit forward
    cam_forward: vec4f,
    // width, height, 1/width, 1/height
    size: vec4f,
    // rgb = sky radiance, w = exposure
    sky: vec4f,
    // rgb = ambient radiance, w = frame index
    ambient: vec4f,
}
