//! Issue 14: the AO spiral's rotation changes every frame by default, so at a still camera the
//! temporal filter averages different tap patterns; with the paper's fixed rotation every frame
//! is the same image and its noise stays (the blotches along concave edges, docs/ao.md).

mod common;

use strata_render::frame::FrameCameras;
use strata_render::passes::ao::AoSettings;
use strata_render::{RenderSettings, Renderer};
use strata_scene::{procedural, ImageBuf};

#[test]
fn per_frame_rotation_averages_tap_patterns_at_a_still_camera() {
    assert!(
        AoSettings::default().temporal_noise,
        "per-frame rotation is the default"
    );
    let gpu = common::gpu();
    let mut scene = procedural::builtin("atrium").unwrap();
    scene.camera_path = None;
    for o in &mut scene.objects {
        o.animation = None;
    }
    let (w, h) = (160, 90);
    let av = |ao: AoSettings, frames: u32| -> ImageBuf {
        let mut r = Renderer::new(
            &gpu,
            &scene,
            RenderSettings {
                ao: Some(ao),
                ..common::two_peeled_layers(&scene, w, h)
            },
        )
        .unwrap();
        for _ in 0..frames {
            r.render(&gpu, &scene, &FrameCameras::fixed(scene.camera), 0.0)
                .expect("frame renders without validation errors");
        }
        r.read_target(&gpu, "ao").unwrap()
    };
    let rmse = |a: &ImageBuf, b: &ImageBuf| {
        let n = a.data.len() as f64;
        (a.data
            .iter()
            .zip(&b.data)
            .map(|(x, y)| ((x - y) as f64).powi(2))
            .sum::<f64>()
            / n)
            .sqrt()
    };
    let fixed = AoSettings {
        temporal_noise: false,
        ..Default::default()
    };
    // the estimate the frames should approach: 8× the taps in one frame
    let dense = av(
        AoSettings {
            samples: 152,
            ..fixed.clone()
        },
        1,
    );
    let (fixed_1, fixed_9) = (av(fixed.clone(), 1), av(fixed, 9));
    let rotated_9 = av(AoSettings::default(), 9);
    let (e_fixed1, e_fixed, e_rotated) = (rmse(&fixed_1, &dense), rmse(&fixed_9, &dense), rmse(&rotated_9, &dense));
    eprintln!(
        "RMSE vs 152 taps: fixed 1 frame {e_fixed1:.4}, fixed 9 frames {e_fixed:.4}, rotated 9 frames {e_rotated:.4}"
    );
    // a still camera with a fixed pattern: the temporal filter averages identical frames
    assert!((e_fixed - e_fixed1).abs() < 1e-3, "fixed rotation: 9 frames = 1 frame");
    assert!(e_rotated < 0.8 * e_fixed, "rotated {e_rotated} vs fixed {e_fixed}");
}
