//! Camera paths: interpolation through keyframes, continuity and clamping.

use glam::Vec3;
use strata_scene::{Camera, CameraPath, Keyframe};

fn path() -> CameraPath {
    let k = |frame: f32, eye: [f32; 3], target: [f32; 3]| Keyframe {
        frame,
        eye: eye.into(),
        target: target.into(),
    };
    CameraPath::new(vec![
        k(30.0, [4.0, 1.0, 0.0], [4.0, 1.0, -5.0]),
        k(0.0, [0.0, 1.0, 0.0], [0.0, 1.0, -5.0]),
        k(10.0, [1.0, 2.0, 0.5], [1.0, 0.0, -5.0]),
        k(55.0, [2.0, 1.5, 3.0], [0.0, 1.0, 0.0]),
    ])
    .expect("valid path")
}

#[test]
fn hits_every_keyframe_exactly() {
    let p = path();
    assert_eq!(
        p.keyframes.iter().map(|k| k.frame).collect::<Vec<_>>(),
        vec![0.0, 10.0, 30.0, 55.0]
    );
    for k in &p.keyframes {
        let (eye, target) = p.sample(k.frame);
        assert!(
            eye.abs_diff_eq(k.eye, 1e-5) && target.abs_diff_eq(k.target, 1e-5),
            "frame {}",
            k.frame
        );
    }
}

#[test]
fn is_continuous() {
    let p = path();
    let step = 0.01;
    let mut max_step = 0.0f32;
    let mut prev = p.sample(-1.0);
    let mut f = -1.0;
    while f <= 60.0 {
        f += step;
        let cur = p.sample(f);
        max_step = max_step.max((cur.0 - prev.0).length()).max((cur.1 - prev.1).length());
        prev = cur;
    }
    // The fastest segment moves ~5 m in 20 frames; a 0.01-frame step must stay tiny.
    assert!(max_step < 0.01, "discontinuity: max step {max_step}");
    // Velocity is continuous across an interior keyframe (C¹).
    let v = |f: f32| (p.sample(f + 1e-2).0 - p.sample(f - 1e-2).0) / 2e-2;
    let (a, b) = (v(10.0 - 0.05), v(10.0 + 0.05));
    assert!(
        (a - b).length() < 0.05 * a.length().max(1.0),
        "velocity jump {a} vs {b}"
    );
}

#[test]
fn clamps_outside_the_range() {
    let p = path();
    assert_eq!(p.sample(-100.0), p.sample(0.0));
    assert_eq!(p.sample(1e6), p.sample(55.0));
    assert_eq!(p.sample(f32::NEG_INFINITY), (p.keyframes[0].eye, p.keyframes[0].target));
    let base = Camera {
        fov_y_deg: 33.0,
        near: 0.2,
        up: Vec3::Y,
        ..Default::default()
    };
    let c = p.camera_at(70.0, &base);
    assert_eq!((c.eye, c.fov_y_deg, c.near), (Vec3::new(2.0, 1.5, 3.0), 33.0, 0.2));
}

#[test]
fn single_keyframe_and_invalid_paths() {
    let k = Keyframe {
        frame: 5.0,
        eye: Vec3::ONE,
        target: Vec3::ZERO,
    };
    let p = CameraPath::new(vec![k]).unwrap();
    assert_eq!(p.sample(0.0), (Vec3::ONE, Vec3::ZERO));
    assert_eq!(p.sample(9.0), (Vec3::ONE, Vec3::ZERO));
    assert!(CameraPath::new(vec![]).is_err());
    assert!(CameraPath::new(vec![k, k]).is_err());
    assert!(CameraPath::new(vec![Keyframe { frame: f32::NAN, ..k }]).is_err());
    assert!(CameraPath::new(vec![Keyframe {
        eye: Vec3::INFINITY,
        ..k
    }])
    .is_err());
}

#[test]
fn atrium_path_is_smooth() {
    let s = strata_scene::procedural::atrium();
    let p = s.camera_path.as_ref().unwrap();
    let mut max_step = 0.0f32;
    for i in 0..1200 {
        let f = i as f32 * 0.1;
        let d = (s.camera_at(f + 0.1).eye - s.camera_at(f).eye).length();
        max_step = max_step.max(d);
        assert!(s.camera_at(f).validate().is_ok());
    }
    assert!(max_step < 0.05, "{max_step}");
    for k in &p.keyframes {
        assert!(s.camera_at(k.frame).eye.abs_diff_eq(k.eye, 1e-5));
    }
}

#[test]
fn nan_frame_gives_first_keyframe() {
    let p = path();
    assert_eq!(p.sample(f32::NAN), (p.keyframes[0].eye, p.keyframes[0].target));
}

#[test]
fn evenly_spaced_keys_give_uniform_catmull_rom() {
    let pts = [
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(1.0, 2.0, 0.0),
        Vec3::new(3.0, 2.0, 1.0),
        Vec3::new(4.0, 0.0, 3.0),
    ];
    let keys = pts
        .iter()
        .enumerate()
        .map(|(i, &p)| Keyframe {
            frame: 10.0 * i as f32,
            eye: p,
            target: p + Vec3::X,
        })
        .collect();
    let path = CameraPath::new(keys).unwrap();
    // Middle segment, t = 0.3: 0.5 * (2 p1 + (−p0 + p2) t + (2 p0 − 5 p1 + 4 p2 − p3) t² + (−p0 + 3 p1 − 3 p2 + p3) t³).
    let [p0, p1, p2, p3] = pts;
    let t = 0.3f32;
    let want = 0.5
        * (2.0 * p1
            + (p2 - p0) * t
            + (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3) * t * t
            + (3.0 * p1 - p0 - 3.0 * p2 + p3) * t * t * t);
    assert!(
        path.sample(13.0).0.abs_diff_eq(want, 1e-5),
        "{} vs {want}",
        path.sample(13.0).0
    );
}

#[test]
fn guard_band_camera_reproduces_the_cropped_pixel_centres() {
    let cam = strata_scene::Camera::new(
        glam::Vec3::new(1.0, 2.0, 3.0),
        glam::Vec3::new(-2.0, 0.5, -4.0),
        glam::Vec3::Y,
        55.0,
        0.1,
    );
    let (w, h, g) = (64u32, 40u32, 7u32);
    let wide = cam.with_guard_band(h, g);
    for (x, y) in [(0, 0), (63, 0), (0, 39), (63, 39), (31, 17)] {
        let a = cam.pixel_dir(x, y, w, h);
        let b = wide.pixel_dir(x + g, y + g, w + 2 * g, h + 2 * g);
        assert!((a - b).length() < 1e-5, "pixel ({x}, {y}): {a} vs {b}");
    }
    assert_eq!(cam.with_guard_band(h, 0).fov_y_deg, cam.fov_y_deg);
}
