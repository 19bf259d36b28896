//! The one camera model shared by the GPU path and the CPU reference.
//!
//! Conventions (both paths use exactly these):
//! - right-handed world, +Y up; camera looks down its local −Z;
//! - pixel (x, y) has its centre at `(x + 0.5, y + 0.5)`; y grows downwards;
//! - *camera-space depth* `z` is the positive distance along the view axis
//!   (`dot(p − eye, forward)`), the quantity the deep G-buffer stores;
//! - projection is reversed-Z with an infinite far plane: NDC depth = `near / z`.

use glam::{Mat4, Vec3, Vec4};
use serde::{Deserialize, Serialize};

/// A pinhole perspective camera. `fov_y_deg` is the vertical field of view.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Camera {
    pub eye: Vec3,
    pub target: Vec3,
    pub up: Vec3,
    /// Vertical field of view in degrees, in (0, 180).
    pub fov_y_deg: f32,
    /// Near plane distance (scene units), > 0.
    pub near: f32,
}

impl Default for Camera {
    fn default() -> Self {
        Self {
            eye: Vec3::new(0.0, 1.0, 5.0),
            target: Vec3::ZERO,
            up: Vec3::Y,
            fov_y_deg: 60.0,
            near: 0.05,
        }
    }
}

impl Camera {
    pub fn new(eye: Vec3, target: Vec3, up: Vec3, fov_y_deg: f32, near: f32) -> Self {
        Self {
            eye,
            target,
            up,
            fov_y_deg,
            near,
        }
    }

    /// Unit view direction.
    pub fn forward(&self) -> Vec3 {
        (self.target - self.eye).normalize()
    }

    /// Orthonormal camera basis (right, true up, forward).
    pub fn basis(&self) -> (Vec3, Vec3, Vec3) {
        let f = self.forward();
        let r = f.cross(self.up).normalize();
        let u = r.cross(f);
        (r, u, f)
    }

    /// World → camera transform (camera looks down −Z).
    pub fn view(&self) -> Mat4 {
        glam::camera::rh::view::look_at_mat4(self.eye, self.target, self.up)
    }

    /// Reversed-Z infinite perspective projection for wgpu (NDC y up, depth in [0, 1]).
    pub fn projection(&self, aspect: f32) -> Mat4 {
        let f = 1.0 / (0.5 * self.fov_y_deg.to_radians()).tan();
        Mat4::from_cols(
            Vec4::new(f / aspect, 0.0, 0.0, 0.0),
            Vec4::new(0.0, f, 0.0, 0.0),
            Vec4::new(0.0, 0.0, 0.0, -1.0),
            Vec4::new(0.0, 0.0, self.near, 0.0),
        )
    }

    pub fn view_projection(&self, aspect: f32) -> Mat4 {
        self.projection(aspect) * self.view()
    }

    /// Unnormalised world-space direction through the centre of pixel (x, y) of a
    /// `width`×`height` image, scaled so that its component along `forward` is 1:
    /// `eye + z * dir` is the point at camera-space depth `z`.
    pub fn pixel_dir(&self, x: u32, y: u32, width: u32, height: u32) -> Vec3 {
        self.pixel_dir_f(x as f32 + 0.5, y as f32 + 0.5, width, height)
    }

    /// As [`Camera::pixel_dir`] for a continuous image position (pixel units, y down).
    pub fn pixel_dir_f(&self, px: f32, py: f32, width: u32, height: u32) -> Vec3 {
        let (r, u, f) = self.basis();
        let t = (0.5 * self.fov_y_deg.to_radians()).tan();
        let aspect = width as f32 / height as f32;
        let ndc_x = px / width as f32 * 2.0 - 1.0;
        let ndc_y = 1.0 - py / height as f32 * 2.0;
        f + r * (ndc_x * t * aspect) + u * (ndc_y * t)
    }

    /// The camera for a `width`×`height` image widened by a guard band of `g`
    /// pixels on every side: rendering `(width + 2g)`×`(height + 2g)` pixels with
    /// it and cropping `g` pixels from each edge gives exactly the pixel centres
    /// of `self` at `width`×`height` (the vertical and horizontal half-angle
    /// tangents grow by `(height + 2g)/height` and `(width + 2g)/width`).
    pub fn with_guard_band(&self, height: u32, g: u32) -> Camera {
        if g == 0 {
            return *self;
        }
        let t = (0.5 * self.fov_y_deg.to_radians()).tan() * (height + 2 * g) as f32 / height as f32;
        // The wider aspect of the widened image carries the horizontal growth.
        Camera {
            fov_y_deg: 2.0 * t.atan().to_degrees(),
            ..*self
        }
    }

    /// Camera-space depth of a world point.
    pub fn depth_of(&self, p: Vec3) -> f32 {
        (p - self.eye).dot(self.forward())
    }

    /// Checks the parameters; the error names the parameter and its valid range.
    pub fn validate(&self) -> Result<(), String> {
        if !(self.fov_y_deg > 0.0 && self.fov_y_deg < 180.0) {
            return Err(format!(
                "camera fov {} is out of range: vertical field of view must be in (0, 180) degrees",
                self.fov_y_deg
            ));
        }
        if self.near <= 0.0 || !self.near.is_finite() {
            return Err(format!("camera near {} is out of range: must be > 0", self.near));
        }
        let m = crate::model::MAX_COORDINATE;
        if !(self.eye.abs().max_element() <= m && self.target.abs().max_element() <= m) {
            return Err(format!(
                "camera eye {} or target {} is out of range: coordinates must be finite and within ±{m:e}",
                self.eye, self.target
            ));
        }
        let f = self.target - self.eye;
        if !f.is_finite() || f.length() < 1e-6 {
            return Err("camera eye and target must be finite and distinct".into());
        }
        if !self.up.is_finite() || self.up.length() < 1e-12 {
            return Err(format!(
                "camera up vector {} is out of range: must be finite and non-zero",
                self.up
            ));
        }
        if f.normalize().cross(self.up.normalize()).length() < 1e-4 {
            return Err(format!(
                "camera up vector {} is parallel to the view direction {}: it must make an angle of at least 0.006 degrees with it",
                self.up,
                f.normalize()
            ));
        }
        Ok(())
    }
}
