// Camera reconstruction (same model as strata_scene::Camera): pixel centres at
// (x + 0.5, y + 0.5), y down; camera-space depth z along the forward axis.
#import "common/frame.wgsl"

// World-space direction through a pixel position, scaled so its forward component is 1.
fn pixel_dir(f: Frame, pix: vec2f) -> vec3f {
    let ndc = vec2f(pix.x * f.size.z * 2.0 - 1.0, 1.0 - pix.y * f.size.w * 2.0);
    return f.cam_forward.xyz + f.cam_right.xyz * ndc.x + f.cam_up.xyz * ndc.y;
}

// World position of the surface at pixel position `pix` with camera-space depth `z`.
fn world_from_csz(f: Frame, pix: vec2f, z: f32) -> vec3f {
    return f.eye.xyz + z * pixel_dir(f, pix);
}

// Camera-space depth of a world point.
fn csz_of(f: Frame, p: vec3f) -> f32 {
    return dot(p - f.eye.xyz, f.cam_forward.xyz);
}
