//! Scene/camera resolution from arguments and safe output writing (the work is done by
//! `strata_eval::scene` and `strata_eval::files`).

use anyhow::Result;
use strata_eval::scene::SceneSpec;
use strata_render::frame::FrameCameras;
use strata_scene::Scene;

pub use strata_eval::files::{check_output, save};

use crate::args::SceneArgs;

/// Loads the scene and resolves the cameras of frames --frame − 1, --frame and
/// --frame + 1 (the scene's path, then flag overrides).
pub fn scene_and_camera(a: &SceneArgs) -> Result<(Scene, FrameCameras)> {
    SceneSpec::from(a).load()
}

/// The cameras of frames `f − 1`, `f`, `f + 1` with the flag overrides applied.
pub fn cameras_at(scene: &Scene, a: &SceneArgs, f: f32) -> FrameCameras {
    SceneSpec::from(a).cameras_at(scene, f)
}
