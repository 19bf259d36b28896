//! Camera paths: keyframes at frame indices, interpolated with a Catmull–Rom
//! spline whose tangents are measured per frame (C¹-continuous in frame time,
//! passes through every keyframe; uniform Catmull–Rom for evenly spaced keys).

use glam::{DVec3, Vec3};
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
    /// Sorts the keyframes by frame; errors when there are none, when two share
    /// a frame index, or when a frame, eye or target is not finite (or a
    /// coordinate is beyond ±[`crate::model::MAX_COORDINATE`]).
    pub fn new(mut keyframes: Vec<Keyframe>) -> Result<Self, String> {
        if keyframes.is_empty() {
            return Err("camera path needs at least one keyframe".into());
        }
        let m = crate::model::MAX_COORDINATE;
        if let Some(k) = keyframes
            .iter()
            .find(|k| !(k.frame.is_finite() && k.eye.abs().max_element() <= m && k.target.abs().max_element() <= m))
        {
            return Err(format!(
                "camera path keyframe at frame {} is out of range: frame, eye and target must be finite, coordinates within ±{m:e}",
                k.frame
            ));
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

    /// (eye, target) at `frame`, clamped to the path's frame range (a NaN frame
    /// gives the first keyframe).
    ///
    /// Catmull–Rom with tangents measured per frame, `m_i = (p_{i+1} − p_{i−1}) /
    /// (f_{i+1} − f_{i−1})`, so the motion is C¹ in frame time even when the
    /// keyframes are unevenly spaced (for even spacing this is the uniform
    /// Catmull–Rom spline). The ends use mirrored neighbours.
    pub fn sample(&self, frame: f32) -> (Vec3, Vec3) {
        let k = &self.keyframes;
        if k.len() == 1 || frame.is_nan() || frame <= k[0].frame {
            return (k[0].eye, k[0].target);
        }
        if frame >= self.last_frame() {
            let l = k[k.len() - 1];
            return (l.eye, l.target);
        }
        let i = k
            .partition_point(|kf| kf.frame <= frame)
            .saturating_sub(1)
            .min(k.len() - 2);
        let (f0, f1) = (k[i].frame as f64, k[i + 1].frame as f64);
        let t = ((frame as f64 - f0) / (f1 - f0)).clamp(0.0, 1.0);
        let eye = self.hermite(i, t, |k| k.eye);
        let target = self.hermite(i, t, |k| k.target);
        (eye, target)
    }

    /// Per-frame tangent of the selected quantity at keyframe `i` (f64: the
    /// difference of two far-apart f32 positions, divided by a tiny frame
    /// spacing, can overflow f32).
    fn tangent(&self, i: usize, sel: fn(&Keyframe) -> Vec3) -> DVec3 {
        let k = &self.keyframes;
        let n = k.len();
        let (a, b) = if i == 0 {
            // Mirrored neighbour before the start: m = (p1 − p0) / (f1 − f0).
            (0, 1)
        } else if i == n - 1 {
            (n - 2, n - 1)
        } else {
            (i - 1, i + 1)
        };
        (sel(&k[b]).as_dvec3() - sel(&k[a]).as_dvec3()) / (k[b].frame as f64 - k[a].frame as f64)
    }

    /// Cubic Hermite between keyframes `i` and `i + 1` at `t` ∈ [0, 1],
    /// evaluated in f64. The result stays within the keyframes' coordinate
    /// range widened by a bounded overshoot; where that leaves the f32 range it
    /// is clamped to ±`f32::MAX`, so a sample of finite keyframes is finite.
    fn hermite(&self, i: usize, t: f64, sel: fn(&Keyframe) -> Vec3) -> Vec3 {
        let k = &self.keyframes;
        let len = k[i + 1].frame as f64 - k[i].frame as f64;
        let (p0, p1) = (sel(&k[i]).as_dvec3(), sel(&k[i + 1]).as_dvec3());
        let (m0, m1) = (self.tangent(i, sel) * len, self.tangent(i + 1, sel) * len);
        let t2 = t * t;
        let t3 = t2 * t;
        let p =
            p0 * (2.0 * t3 - 3.0 * t2 + 1.0) + m0 * (t3 - 2.0 * t2 + t) + p1 * (-2.0 * t3 + 3.0 * t2) + m1 * (t3 - t2);
        let m = f32::MAX as f64;
        p.clamp(DVec3::splat(-m), DVec3::splat(m)).as_vec3()
    }
}
