//! Camera paths: keyframes at frame indices, interpolated with a centripetal-free
//! uniform Catmull–Rom spline (C¹-continuous, passes through every keyframe).

use glam::Vec3;
use serde::{Deserialize, Serialize};

use crate::camera::Camera;

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Keyframe {
    pub frame: f32,
    pub eye: Vec3,
    pub target: Vec3,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CameraPath {
    /// Keyframes sorted by strictly increasing `frame`.
    pub keyframes: Vec<Keyframe>,
}

impl CameraPath {
    pub fn new(mut keyframes: Vec<Keyframe>) -> Result<Self, String> {
        if keyframes.is_empty() {
            return Err("camera path needs at least one keyframe".into());
        }
        keyframes.sort_by(|a, b| a.frame.total_cmp(&b.frame));
        if keyframes.windows(2).any(|w| w[1].frame <= w[0].frame) {
            return Err("camera path keyframes must have distinct frame indices".into());
        }
        Ok(Self { keyframes })
    }

    pub fn first_frame(&self) -> f32 {
        self.keyframes[0].frame
    }
    pub fn last_frame(&self) -> f32 {
        self.keyframes[self.keyframes.len() - 1].frame
    }

    /// Camera at a fractional frame (clamped to the path's range); fov, near and up come from `base`.
    pub fn camera_at(&self, frame: f32, base: &Camera) -> Camera {
        let (eye, target) = self.sample(frame);
        Camera { eye, target, ..*base }
    }

    /// (eye, target) at `frame`.
    pub fn sample(&self, frame: f32) -> (Vec3, Vec3) {
        let k = &self.keyframes;
        if k.len() == 1 || frame <= k[0].frame {
            return (k[0].eye, k[0].target);
        }
        if frame >= self.last_frame() {
            let l = k[k.len() - 1];
            return (l.eye, l.target);
        }
        let i = k.partition_point(|kf| kf.frame <= frame) - 1;
        let (f0, f1) = (k[i].frame, k[i + 1].frame);
        let t = (frame - f0) / (f1 - f0);
        // Neighbours, mirrored at the ends.
        let prev = |sel: fn(&Keyframe) -> Vec3| {
            if i > 0 {
                sel(&k[i - 1])
            } else {
                2.0 * sel(&k[i]) - sel(&k[i + 1])
            }
        };
        let next = |sel: fn(&Keyframe) -> Vec3| {
            if i + 2 < k.len() {
                sel(&k[i + 2])
            } else {
                2.0 * sel(&k[i + 1]) - sel(&k[i])
            }
        };
        let eye = catmull_rom(prev(|k| k.eye), k[i].eye, k[i + 1].eye, next(|k| k.eye), t);
        let target = catmull_rom(prev(|k| k.target), k[i].target, k[i + 1].target, next(|k| k.target), t);
        (eye, target)
    }
}

/// Uniform Catmull–Rom between p1 (t = 0) and p2 (t = 1).
fn catmull_rom(p0: Vec3, p1: Vec3, p2: Vec3, p3: Vec3, t: f32) -> Vec3 {
    let t2 = t * t;
    let t3 = t2 * t;
    0.5 * ((2.0 * p1)
        + (-p0 + p2) * t
        + (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3) * t2
        + (-p0 + 3.0 * p1 - 3.0 * p2 + p3) * t3)
}
