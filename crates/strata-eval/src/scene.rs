//! Scene loading and camera resolution for the benchmarks and evaluations: a scene by name or
//! path, the frame along its camera path, the image size and optional camera overrides.
//!
//! Error messages name the command-line flags the fields come from (`--scene`, `--width`, ...).

use anyhow::{bail, Result};
use glam::Vec3;
use strata_render::frame::FrameCameras;
use strata_scene::{Camera, Scene};

/// Which scene, frame, image size and camera.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneSpec {
    /// Built-in scene name or path to a .gltf/.glb/.obj/.toml file.
    pub scene: String,
    /// Frame index along the scene's camera path / animation.
    pub frame: f32,
    pub width: u32,
    pub height: u32,
    /// Camera position (overrides the scene camera and its path).
    pub eye: Option<Vec3>,
    /// Camera look-at point.
    pub target: Option<Vec3>,
    /// Camera up vector.
    pub up: Option<Vec3>,
    /// Vertical field of view in degrees.
    pub fov: Option<f32>,
    /// Which of the scene file's cameras (`Scene::cameras`) to start from.
    pub camera: Option<usize>,
}

impl SceneSpec {
    /// A spec with no camera overrides.
    pub fn new(scene: impl Into<String>, frame: f32, width: u32, height: u32) -> Self {
        Self {
            scene: scene.into(),
            frame,
            width,
            height,
            eye: None,
            target: None,
            up: None,
            fov: None,
            camera: None,
        }
    }

    /// Loads the scene and resolves the cameras of frames `frame − 1`, `frame` and `frame + 1`
    /// (the scene's path, then the overrides), checking the frame, camera and image size.
    pub fn load(&self) -> Result<(Scene, FrameCameras)> {
        let mut scene = strata_scene::load_scene(&self.scene).map_err(|e| anyhow::anyhow!("--scene: {e}"))?;
        if let Some(n) = self.camera {
            let k = scene.cameras.len();
            match scene.cameras.get(n) {
                Some(c) => {
                    scene.camera = *c;
                    scene.camera_path = None;
                }
                None if k == 0 => bail!("--camera {n} is out of range: the scene file defines no cameras"),
                None => bail!(
                    "--camera {n} is out of range: the scene file defines {k} camera(s), 0..={}",
                    k - 1
                ),
            }
        }
        if !self.frame.is_finite() || self.frame < 0.0 {
            bail!("--frame {} is out of range: must be a finite number >= 0", self.frame);
        }
        let cams = self.cameras_at(&scene, self.frame);
        cams.current
            .validate()
            .map_err(|e| anyhow::anyhow!("--eye/--target/--up/--fov: {e}"))?;
        for (name, v) in [("--width", self.width), ("--height", self.height)] {
            if !(strata_render::renderer::MIN_SIZE..=strata_render::renderer::MAX_SIZE).contains(&v) {
                bail!(
                    "{name} {v} is out of range: must be in {}..={}",
                    strata_render::renderer::MIN_SIZE,
                    strata_render::renderer::MAX_SIZE
                );
            }
        }
        Ok((scene, cams))
    }

    /// The cameras of frames `f − 1`, `f`, `f + 1` with the overrides applied.
    pub fn cameras_at(&self, scene: &Scene, f: f32) -> FrameCameras {
        let apply = |mut c: Camera| {
            if let Some(e) = self.eye {
                c.eye = e;
            }
            if let Some(t) = self.target {
                c.target = t;
            }
            if let Some(u) = self.up {
                c.up = u;
            }
            if let Some(fov) = self.fov {
                c.fov_y_deg = fov;
            }
            c
        };
        FrameCameras {
            previous: apply(scene.camera_at(f - 1.0)),
            current: apply(scene.camera_at(f)),
            next_view: apply(scene.camera_at(f + 1.0)).view(),
        }
    }
}
