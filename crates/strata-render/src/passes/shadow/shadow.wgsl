// Depth-only shadow map rendering for one light (light matrix at a dynamic offset).
#import "common/scene.wgsl"

struct ShadowView {
    view_proj: mat4x4f,
}


@group(0) @binding(0) var<uniform> light: ShadowView;
@group(1) @binding(0) var<uniform> object: ObjectUniforms;

@vertex
fn vs_main(@location(0) position: vec3f) -> @builtin(position) vec4f {
    return light.view_proj * object.model * vec4f(position, 1.0);
}
