//! Convergence by a noise target: sample ranges add up, halves are independent,
//! the rule stops where it should, and the result is the estimator's image.

use strata_reference::converge::{decay_exponent, next_round_spp, Round};
use strata_reference::{AoBinarySettings, ConvergeRule, Estimator, GiSettings, ObscuranceSettings, Reference};
use strata_scene::ImageBuf;

fn rmse(a: &ImageBuf, b: &ImageBuf) -> f64 {
    let se: f64 = a.data.iter().zip(&b.data).map(|(x, y)| ((x - y) as f64).powi(2)).sum();
    (se / a.data.len().max(1) as f64).sqrt()
}

fn cornell() -> strata_scene::Scene {
    strata_scene::procedural::builtin("cornell").unwrap()
}

/// Sums over [0, a) and [a, b) add up to the sum over [0, b): exactly for the
/// binary AO's hit counts, to f32 rounding for the path tracer's radiance.
#[test]
fn sample_ranges_add_up() {
    let scene = cornell();
    let r = Reference::new(&scene, 0.0);
    let cam = r.camera();
    let ao = Estimator::AoBinary(AoBinarySettings::new(0.5));
    let whole = r.sample_sums(&cam, 12, 10, &ao, 0..24);
    let (a, b) = (
        r.sample_sums(&cam, 12, 10, &ao, 0..7),
        r.sample_sums(&cam, 12, 10, &ao, 7..24),
    );
    for ((w, x), y) in whole.iter().zip(&a).zip(&b) {
        assert_eq!(*w, x + y);
    }
    let gi = Estimator::Gi(GiSettings::default());
    let whole = r.sample_sums(&cam, 8, 6, &gi, 0..6);
    assert_eq!(whole.len(), 8 * 6 * 6);
    let (a, b) = (
        r.sample_sums(&cam, 8, 6, &gi, 0..2),
        r.sample_sums(&cam, 8, 6, &gi, 2..6),
    );
    for ((w, x), y) in whole.iter().zip(&a).zip(&b) {
        assert!((w - (x + y)).abs() <= 1e-5 * w.abs().max(1.0), "{w} vs {x} + {y}");
    }
}

/// The first range of a seed's samples is what the one-shot estimators compute.
#[test]
fn sample_sums_match_the_one_shot_estimators() {
    let scene = cornell();
    let r = Reference::new(&scene, 0.0);
    let cam = r.camera();
    let s = AoBinarySettings {
        spp: 32,
        ..AoBinarySettings::new(0.4)
    };
    let one_shot = r.ao_binary(&cam, 10, 10, &s);
    let sums = r.sample_sums(&cam, 10, 10, &Estimator::AoBinary(s), 0..32);
    for (v, sum) in one_shot.data.iter().zip(&sums) {
        assert_eq!(*v, 1.0 - (32.0 - *sum as f32) / 32.0);
    }
    let o = ObscuranceSettings {
        spp: 16,
        ..ObscuranceSettings::new(0.4)
    };
    let one_shot = r.ao_obscurance(&cam, 10, 10, &o);
    let e = Estimator::Obscurance(o);
    let mean = ImageBuf {
        width: 10,
        height: 10,
        channels: 1,
        data: r
            .sample_sums(&cam, 10, 10, &e, 0..16)
            .iter()
            .map(|s| (s / 16.0) as f32)
            .collect(),
    };
    let finished = e.finish(&mean);
    for (a, b) in one_shot.data.iter().zip(&finished.data) {
        assert!((a - b).abs() < 1e-6, "{a} vs {b}");
    }
}

/// Where the estimator has no variance (an unoccluded view: AO is exactly 1
/// everywhere) the halves agree at once and the first round is the last.
#[test]
fn a_noiseless_image_stops_after_one_round() {
    let scene = strata_scene::procedural::builtin("plane").unwrap();
    let r = Reference::new(&scene, 0.0);
    let cam = r.camera();
    let est = Estimator::AoBinary(AoBinarySettings::new(1e-3));
    let c = r.converge(&cam, 16, 16, &est, &ConvergeRule::default(), rmse);
    assert_eq!(c.rounds.len(), 1);
    assert!(c.converged);
    assert_eq!(c.noise, 0.0);
    assert_eq!(c.spp(), 2 * ConvergeRule::default().first_spp);
}

/// On a noisy image the rounds add samples until the measured noise is at the
/// target; noise falls as samples grow; the halves are independent (they
/// differ) and the combined image is closer to a high-sample render than either half.
#[test]
fn converges_to_the_target_and_improves_on_each_half() {
    let scene = cornell();
    let r = Reference::new(&scene, 0.0);
    let cam = r.camera();
    let (w, h) = (24, 24);
    let settings = AoBinarySettings::new(0.3);
    let est = Estimator::AoBinary(settings);
    let rule = ConvergeRule {
        target: 0.01,
        first_spp: 4,
        max_spp: 4096,
    };
    let c = r.converge(&cam, w, h, &est, &rule, rmse);
    assert!(c.converged, "rounds {:?}", c.rounds);
    assert!(c.noise <= rule.target);
    assert!(
        c.rounds.len() >= 2,
        "4 spp per half cannot reach RMSE 0.01: {:?}",
        c.rounds
    );
    assert!(c.rounds[0].noise > rule.target);
    for pair in c.rounds.windows(2) {
        assert!(pair[1].spp >= 2 * pair[0].spp && pair[1].spp <= 8 * pair[0].spp);
    }
    let [a, b] = c.half_images();
    assert!(rmse(&a, &b) > 0.0);
    let truth = r.ao_binary(
        &cam,
        w,
        h,
        &AoBinarySettings {
            spp: 8192,
            seed: 99,
            ..settings
        },
    );
    let combined = rmse(&c.image(), &truth);
    assert!(combined < rmse(&a, &truth) && combined < rmse(&b, &truth));
    // the halves' difference bounds the combined image's error (≈ half of it)
    assert!(
        combined < c.noise,
        "combined error {combined} vs half-to-half {}",
        c.noise
    );
}

/// The cap wins over an unreachable target, and the result says so.
#[test]
fn the_cap_stops_an_unreachable_target() {
    let scene = cornell();
    let r = Reference::new(&scene, 0.0);
    let cam = r.camera();
    let rule = ConvergeRule {
        target: 0.0,
        first_spp: 2,
        max_spp: 40,
    };
    let c = r.converge(&cam, 8, 8, &Estimator::Gi(GiSettings::default()), &rule, rmse);
    assert!(!c.converged);
    assert_eq!(c.spp(), 40);
    assert_eq!(c.rounds.iter().map(|r| r.spp).collect::<Vec<_>>(), vec![4, 32, 40]);
}

#[test]
fn next_round_follows_the_measured_decay_within_bounds() {
    // noise twice the target at b = 0.5: 4× the samples, +20 %
    assert_eq!(next_round_spp(100, 0.04, 0.02, 0.5), 480);
    assert_eq!(next_round_spp(100, 0.021, 0.02, 0.5), 200); // at least 2×
    assert_eq!(next_round_spp(100, 1.0, 0.02, 0.5), 800); // at most 8×
                                                          // ꟻLIP-like decay (b = 0.35) asks for more than b = 0.5 would
    assert!(next_round_spp(100, 0.024, 0.02, 0.35) > next_round_spp(100, 0.024, 0.02, 0.5));
    // target 0 (run to the cap), unusable noise: 8× per round
    assert_eq!(next_round_spp(10, f64::NAN, 0.02, 0.5), 80);
    assert_eq!(next_round_spp(0, 1.0, 0.0, 0.5), 8);
    let round = |spp, noise| Round {
        spp,
        noise,
        seconds: 0.0,
    };
    assert_eq!(decay_exponent(&[round(16, 0.2)]), 0.5);
    let b = decay_exponent(&[round(16, 0.2), round(64, 0.1)]);
    assert!((b - 0.5).abs() < 1e-12, "{b}");
    assert_eq!(decay_exponent(&[round(16, 0.2), round(64, 0.2)]), 0.2); // clamped
    assert_eq!(decay_exponent(&[round(16, 0.0), round(64, 0.0)]), 0.5);
}
