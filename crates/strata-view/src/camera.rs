//! Fly and orbit camera control. Real winit events and scripted events both become
//! [`Input`]s, which [`CameraControl::apply`] and [`CameraControl::step`] consume: the
//! scripted tests exercise the same code as a person at the keyboard.

use glam::Vec3;
use strata_scene::Camera;

/// Keys the camera reacts to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Key {
    W,
    A,
    S,
    D,
    Q,
    E,
    Shift,
}

impl Key {
    pub const ALL: [Key; 7] = [Key::W, Key::A, Key::S, Key::D, Key::Q, Key::E, Key::Shift];

    pub fn parse(s: &str) -> Option<Key> {
        Some(match s.to_ascii_uppercase().as_str() {
            "W" => Key::W,
            "A" => Key::A,
            "S" => Key::S,
            "D" => Key::D,
            "Q" => Key::Q,
            "E" => Key::E,
            "SHIFT" => Key::Shift,
            _ => return None,
        })
    }
}

/// One input event for the camera.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Input {
    Key(Key, bool),
    /// Pointer moved by (dx, dy) physical pixels with the right button held.
    Drag(f32, f32),
    /// Wheel notches (positive: away from the user).
    Wheel(f32),
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    Fly,
    Orbit,
}

/// Radians per pixel of drag.
const LOOK_SENSITIVITY: f32 = 0.004;
const MAX_PITCH: f32 = 1.55;

pub struct CameraControl {
    pub mode: Mode,
    pub eye: Vec3,
    /// The world's up: the scene camera's up vector (+Y for Y-up scenes, +Z for Z-up
    /// ones); yaw turns around it and pitch rises towards it.
    pub up: Vec3,
    /// Around `up` from the horizon's reference direction (+Z for a Y-up world,
    /// [`horizon`]) (radians); pitch above the horizon.
    pub yaw: f32,
    pub pitch: f32,
    /// Distance to the look-at point (the orbit centre).
    pub distance: f32,
    pub fov_y_deg: f32,
    pub near: f32,
    /// Fly speed, scene units per second.
    pub speed: f32,
    /// Smallest orbit radius (a scene camera may look at a point 1 mm ahead).
    min_orbit: f32,
    held: [bool; 7],
    /// Pressed since the last step: a tap shorter than a frame still moves one step.
    tapped: [bool; 7],
    drag: (f32, f32),
    wheel: f32,
    /// The camera as given (scene or path) until the first move: shown exactly, with
    /// no round trip through yaw/pitch.
    exact: Option<Camera>,
}

/// The horizon's axes (a, b) of a world whose up is `up` (unit): yaw 0 looks along b,
/// yaw π/2 along a. For +Y they are +X and +Z, so a Y-up world keeps its old angles.
fn horizon(up: Vec3) -> (Vec3, Vec3) {
    let reference = if up.z.abs() < 0.9 { Vec3::Z } else { Vec3::X };
    let b = (reference - reference.dot(up) * up).normalize();
    (up.cross(b), b)
}

/// The view direction at `yaw`, `pitch` in a world whose up is `up`.
fn dir(up: Vec3, yaw: f32, pitch: f32) -> Vec3 {
    let (a, b) = horizon(up);
    pitch.cos() * (yaw.sin() * a + yaw.cos() * b) + pitch.sin() * up
}

/// `v` as a world up: normalised, or +Y when it is zero or not finite.
fn world_up(v: Vec3) -> Vec3 {
    let n = v.normalize_or_zero();
    if n == Vec3::ZERO || !n.is_finite() {
        Vec3::Y
    } else {
        n
    }
}

impl CameraControl {
    /// Starts at `cam`; `scale` (scene size) sets the initial fly speed.
    pub fn new(cam: Camera, scale: f32) -> Self {
        let mut c = Self {
            mode: Mode::Fly,
            eye: cam.eye,
            up: Vec3::Y,
            yaw: 0.0,
            pitch: 0.0,
            distance: 1.0,
            fov_y_deg: cam.fov_y_deg,
            near: cam.near,
            speed: (scale * 0.25).max(1e-3),
            min_orbit: scale * 0.25,
            held: [false; 7],
            tapped: [false; 7],
            drag: (0.0, 0.0),
            wheel: 0.0,
            exact: None,
        };
        c.set(cam);
        c
    }

    /// Jumps to `cam` (path playback, a new scene).
    pub fn set(&mut self, cam: Camera) {
        let f = cam.target - cam.eye;
        let d = f.length().max(1e-6);
        let n = f / d;
        self.up = world_up(cam.up);
        let (a, b) = horizon(self.up);
        self.eye = cam.eye;
        self.distance = d;
        self.pitch = n.dot(self.up).clamp(-1.0, 1.0).asin();
        self.yaw = n.dot(a).atan2(n.dot(b));
        self.fov_y_deg = cam.fov_y_deg;
        self.near = cam.near;
        self.exact = Some(cam);
    }

    pub fn camera(&self) -> Camera {
        if let Some(c) = self.exact {
            return c;
        }
        let f = dir(self.up, self.yaw, self.pitch);
        Camera {
            eye: self.eye,
            target: self.eye + f * self.distance,
            up: self.up,
            fov_y_deg: self.fov_y_deg,
            near: self.near,
        }
    }

    /// Records an event; motion happens in [`CameraControl::step`].
    pub fn apply(&mut self, e: Input) {
        match e {
            Input::Key(k, down) => {
                let i = Key::ALL.iter().position(|x| *x == k).unwrap_or(0);
                self.held[i] = down;
                self.tapped[i] |= down;
            }
            Input::Drag(dx, dy) => {
                self.drag.0 += dx;
                self.drag.1 += dy;
            }
            Input::Wheel(n) => self.wheel += n,
        }
    }

    /// A key is held or tapped, or a drag or wheel turn waits for the next step: the
    /// camera will move.
    pub fn active(&self) -> bool {
        self.held.iter().chain(&self.tapped).any(|&k| k) || self.drag != (0.0, 0.0) || self.wheel != 0.0
    }

    pub fn release_all(&mut self) {
        self.held = [false; 7];
        self.tapped = [false; 7];
    }

    fn down(&self, k: Key) -> bool {
        let i = Key::ALL.iter().position(|x| *x == k).unwrap_or(0);
        self.held[i] || self.tapped[i]
    }

    /// Advances by `dt` seconds; true when the camera moved.
    pub fn step(&mut self, dt: f32) -> bool {
        let before = self.camera();
        let (dx, dy) = std::mem::take(&mut self.drag);
        let wheel = std::mem::take(&mut self.wheel);
        let axis = |p: Key, n: Key| (self.down(p) as i32 - self.down(n) as i32) as f32;
        let (fwd, side, lift) = (axis(Key::W, Key::S), axis(Key::D, Key::A), axis(Key::E, Key::Q));
        let boost = if self.down(Key::Shift) { 4.0 } else { 1.0 };
        self.tapped = [false; 7];
        let any = dx != 0.0 || dy != 0.0 || wheel != 0.0 || fwd != 0.0 || side != 0.0 || lift != 0.0;
        if !any {
            return false;
        }
        // leave the exact camera: from here on the yaw/pitch state is the camera
        self.exact = None;
        match self.mode {
            Mode::Fly => {
                self.yaw -= dx * LOOK_SENSITIVITY;
                self.pitch = (self.pitch - dy * LOOK_SENSITIVITY).clamp(-MAX_PITCH, MAX_PITCH);
                if wheel != 0.0 {
                    self.speed = (self.speed * 1.25f32.powf(wheel)).clamp(1e-4, 1e4);
                }
                let f = dir(self.up, self.yaw, self.pitch);
                let r = f.cross(self.up).normalize_or_zero();
                let v = self.speed * boost * dt;
                self.eye += (f * fwd + r * side + self.up * lift) * v;
            }
            Mode::Orbit => {
                self.distance = self.distance.max(self.min_orbit);
                let centre = self.eye + dir(self.up, self.yaw, self.pitch) * self.distance;
                self.yaw -= dx * LOOK_SENSITIVITY + side * 1.5 * dt;
                self.pitch = (self.pitch - dy * LOOK_SENSITIVITY + lift * 1.5 * dt).clamp(-MAX_PITCH, MAX_PITCH);
                let zoom = 0.9f32.powf(wheel) * (1.0 - fwd * dt * boost).max(0.05);
                self.distance = (self.distance * zoom).clamp(1e-3, 1e5);
                self.eye = centre - dir(self.up, self.yaw, self.pitch) * self.distance;
            }
        }
        self.camera() != before
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unmoved_camera_is_exact_and_w_moves_forward() {
        let cam = Camera::new(Vec3::new(0.1, 0.2, 3.0), Vec3::new(0.3, 0.1, -1.0), Vec3::Y, 40.0, 0.01);
        let mut c = CameraControl::new(cam, 4.0);
        assert!(!c.step(0.1));
        assert_eq!(c.camera(), cam);
        c.apply(Input::Key(Key::W, true));
        assert!(c.step(0.1));
        let moved = c.camera();
        let f = (cam.target - cam.eye).normalize();
        let d = moved.eye - cam.eye;
        assert!((d.normalize() - f).length() < 1e-4, "moved along the view direction");
        assert!((d.length() - c.speed * 0.1).abs() < 1e-5);
        assert!((moved.forward() - f).length() < 1e-4);
    }

    #[test]
    fn a_tap_within_one_frame_still_moves_one_step() {
        let cam = Camera::new(Vec3::new(0.0, 1.0, 5.0), Vec3::new(0.0, 1.0, 0.0), Vec3::Y, 60.0, 0.05);
        let mut c = CameraControl::new(cam, 4.0);
        c.apply(Input::Key(Key::W, true));
        c.apply(Input::Key(Key::W, false));
        assert!(c.step(0.1));
        assert!(!c.step(0.1), "released: no more motion");
    }

    /// A Z-up scene camera (glTF/OBJ exports of CAD and architecture scenes) keeps +Z as
    /// the world's up once the camera moves: a small drag turns the view a little instead
    /// of snapping it to a +Y horizon, E lifts along +Z, D strafes in the XY plane, and
    /// the camera handed to the renderer keeps up = +Z.
    #[test]
    fn a_z_up_scene_keeps_its_up_after_the_first_move() {
        let cam = Camera::new(Vec3::new(5.0, -3.0, 1.5), Vec3::new(0.0, 0.0, 1.0), Vec3::Z, 50.0, 0.05);
        let f0 = (cam.target - cam.eye).normalize();
        let mut c = CameraControl::new(cam, 4.0);
        assert_eq!(c.up, Vec3::Z);
        c.apply(Input::Drag(1.0, 0.0));
        assert!(c.step(1.0 / 60.0));
        let m = c.camera();
        assert_eq!(m.up, Vec3::Z);
        let turned = m.forward().angle_between(f0);
        assert!(
            turned > 0.5 * LOOK_SENSITIVITY && turned < 2.0 * LOOK_SENSITIVITY,
            "turned {turned} rad"
        );
        // a yaw turns around +Z: the height of the view direction is kept
        assert!((m.forward().z - f0.z).abs() < 1e-5);
        let e0 = m.eye;
        c.apply(Input::Key(Key::E, true));
        assert!(c.step(0.1));
        c.apply(Input::Key(Key::E, false));
        let d = c.camera().eye - e0;
        assert!((d.normalize() - Vec3::Z).length() < 1e-5, "lift {d}");
        c.apply(Input::Key(Key::D, true));
        assert!(c.step(0.1));
        c.apply(Input::Key(Key::D, false));
        let d = c.camera().eye - e0 - Vec3::Z * c.speed * 0.1;
        assert!(d.z.abs() < 1e-5 && d.length() > 0.0, "strafe {d}");
        // a Y-up camera keeps the old angles: yaw 0 looks along +Z
        let y = CameraControl::new(Camera::new(Vec3::ZERO, Vec3::Z, Vec3::Y, 60.0, 0.05), 1.0);
        assert!(y.yaw.abs() < 1e-6 && y.pitch.abs() < 1e-6 && y.up == Vec3::Y);
        // a degenerate up falls back to +Y
        let mut z = CameraControl::new(cam, 1.0);
        z.set(Camera { up: Vec3::ZERO, ..cam });
        assert_eq!(z.up, Vec3::Y);
    }

    #[test]
    fn orbit_keeps_the_centre() {
        let cam = Camera::new(Vec3::new(0.0, 1.0, 5.0), Vec3::new(0.0, 1.0, 0.0), Vec3::Y, 60.0, 0.05);
        let mut c = CameraControl::new(cam, 4.0);
        c.mode = Mode::Orbit;
        c.apply(Input::Drag(100.0, 20.0));
        assert!(c.step(1.0 / 30.0));
        let m = c.camera();
        assert!((m.target - cam.target).length() < 1e-4);
        assert!(((m.eye - m.target).length() - 5.0).abs() < 1e-4);
        assert!((m.eye - cam.eye).length() > 0.1);
    }
}
