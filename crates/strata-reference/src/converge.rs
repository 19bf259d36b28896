//! References converged to a measured noise target instead of a fixed sample count.
//!
//! Every estimator of this crate is a per-pixel mean of independent samples, so
//! its noise can be *measured*: the samples are split into two independent
//! halves (two sample streams with different seeds, each with the same number
//! of samples per pixel), and the difference between the two half images is
//! pure estimator noise. [`Reference::converge`] adds samples to both halves in
//! rounds until a caller-supplied noise measure of the two half images (e.g.
//! ꟻLIP between them) is at or below a target, or a sample cap is reached.
//!
//! The noise between the halves is a conservative figure for the combined image:
//! each half has twice the combined image's variance, so for an RMSE-like
//! measure the combined image's own error is about half of RMSE(A − B)
//! (Var(A − B) = 2σ²/n per half of n samples; Var((A + B)/2) = σ²/(2n)).
//!
//! The next round's sample count assumes noise ∝ n^(−b), with b measured from
//! the last two rounds (0.5, Monte Carlo, before that); the prediction only sets
//! how far to go in one step, the stopping rule always measures.

use std::ops::Range;
use std::time::Instant;

use strata_scene::{Camera, ImageBuf};

use crate::ao::{obscurance_visibility, pixel_key, AoBinarySettings, ObscuranceSettings};
use crate::gi::GiSettings;
use crate::sampling::hash;
use crate::Reference;

/// What to integrate. The settings' own `spp` is ignored here: the sample
/// counts come from the [`ConvergeRule`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Estimator {
    /// Binary ambient visibility (1 channel: AV).
    AoBinary(AoBinarySettings),
    /// DGB obscurance (1 channel: AV, from the mean obscurance of Eq. 2).
    Obscurance(ObscuranceSettings),
    /// Path-traced diffuse GI (6 channels: direct RGB, then indirect RGB).
    Gi(GiSettings),
    /// The screen-space oracle's split of the path tracer's indirect light
    /// ([`crate::oracle`], [`crate::oracle::ORACLE_CHANNELS`] channels).
    ScreenOracle(crate::oracle::ScreenOracleSettings),
}

impl Estimator {
    /// Channels of the per-pixel means (and of [`Estimator::finish`]'s image).
    pub fn channels(&self) -> u32 {
        match self {
            Estimator::AoBinary(_) | Estimator::Obscurance(_) => 1,
            Estimator::Gi(_) => 6,
            Estimator::ScreenOracle(_) => crate::oracle::ORACLE_CHANNELS,
        }
    }

    fn seed(&self) -> u64 {
        match self {
            Estimator::AoBinary(s) => s.seed,
            Estimator::Obscurance(s) => s.seed,
            Estimator::Gi(s) => s.seed,
            Estimator::ScreenOracle(s) => s.gi.seed,
        }
    }

    /// The estimator with its seed replaced (each half has its own stream).
    fn with_seed(&self, seed: u64) -> Self {
        let mut e = *self;
        match &mut e {
            Estimator::AoBinary(s) => s.seed = seed,
            Estimator::Obscurance(s) => s.seed = seed,
            Estimator::Gi(s) => s.seed = seed,
            Estimator::ScreenOracle(s) => s.gi.seed = seed,
        }
        e
    }

    /// The image an estimator's per-pixel sample means stand for: binary AV and
    /// GI radiance are the means themselves; the obscurance's AV is DGB Eq. 1
    /// applied to the mean of the Eq. 2 terms.
    pub fn finish(&self, means: &ImageBuf) -> ImageBuf {
        let mut out = means.clone();
        if let Estimator::Obscurance(_) = self {
            out.data.iter_mut().for_each(|v| *v = obscurance_visibility(*v));
        }
        out
    }
}

/// When to stop adding samples.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ConvergeRule {
    /// Stop when the noise measure of the two half images is at or below this
    /// (0: run to `max_spp`).
    pub target: f64,
    /// Samples per pixel *per half* of the first round (≥ 1).
    pub first_spp: u32,
    /// Cap on the total samples per pixel (both halves together; ≥ 2).
    pub max_spp: u32,
}

impl Default for ConvergeRule {
    /// Target 0.02 (the ꟻLIP at which strata calls a reference converged), first
    /// round 16 samples per half, at most 16,384 samples per pixel.
    fn default() -> Self {
        Self {
            target: 0.02,
            first_spp: 16,
            max_spp: 16_384,
        }
    }
}

/// One round of [`Reference::converge`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Round {
    /// Total samples per pixel after the round (both halves).
    pub spp: u32,
    /// The noise measure between the halves after the round.
    pub noise: f64,
    /// Wall-clock seconds of the round.
    pub seconds: f64,
}

/// The result of [`Reference::converge`].
#[derive(Clone, Debug, PartialEq)]
pub struct Converged {
    pub estimator: Estimator,
    /// Per-pixel sample means of each half (`estimator.channels()` channels).
    pub halves: [ImageBuf; 2],
    /// Samples per pixel of each half.
    pub spp_per_half: u32,
    /// The noise measure of the last round.
    pub noise: f64,
    /// Whether the target was met (false: the cap stopped it).
    pub converged: bool,
    pub rounds: Vec<Round>,
}

impl Converged {
    /// Total samples per pixel.
    pub fn spp(&self) -> u32 {
        self.spp_per_half * 2
    }

    /// The reference: both halves' samples together, finished.
    pub fn image(&self) -> ImageBuf {
        let mut mean = self.halves[0].clone();
        for (m, b) in mean.data.iter_mut().zip(&self.halves[1].data) {
            *m = 0.5 * (*m + *b);
        }
        self.estimator.finish(&mean)
    }

    /// Each half alone, finished (for noise measures).
    pub fn half_images(&self) -> [ImageBuf; 2] {
        [
            self.estimator.finish(&self.halves[0]),
            self.estimator.finish(&self.halves[1]),
        ]
    }
}

/// Running per-pixel sums of one half.
struct Sums {
    data: Vec<f64>,
    spp: u32,
}

impl Sums {
    fn means(&self, width: u32, height: u32, channels: u32) -> ImageBuf {
        let k = 1.0 / self.spp.max(1) as f64;
        ImageBuf {
            width,
            height,
            channels,
            data: self.data.iter().map(|s| (s * k) as f32).collect(),
        }
    }
}

impl Reference<'_> {
    /// Per-pixel sums of `estimator` over the sample indices `samples`
    /// (`estimator.channels()` values per pixel, row-major). Sample i of a pixel
    /// is the same whichever range it is computed in, so sums of consecutive
    /// ranges add up to the sum of their union.
    pub fn sample_sums(
        &self,
        camera: &Camera,
        width: u32,
        height: u32,
        estimator: &Estimator,
        samples: Range<u32>,
    ) -> Vec<f64> {
        let n = samples.len() as u64;
        match estimator {
            Estimator::AoBinary(s) => self.for_each_pixel("AO binary", width, height, |x, y, rays| {
                let dir = camera.pixel_dir(x, y, width, height);
                *rays += 1;
                let Some(h) = self.bvh.intersect(camera.eye, dir, camera.near, f32::INFINITY) else {
                    return n as f64;
                };
                let hit = self.bvh.surface(&h, dir);
                let (ns, ng) = hit.facing_normals(dir);
                *rays += n;
                let key = pixel_key(s.seed, x, y, width);
                self.ao_binary_unoccluded(hit.position, ns, ng, s.radius, key, samples.clone()) as f64
            }),
            Estimator::Obscurance(s) => self.for_each_pixel("AO DGB", width, height, |x, y, rays| {
                let dir = camera.pixel_dir(x, y, width, height);
                *rays += 1;
                let Some(h) = self.bvh.intersect(camera.eye, dir, camera.near, f32::INFINITY) else {
                    return 0.0;
                };
                let hit = self.bvh.surface(&h, dir);
                let (ns, _) = hit.facing_normals(dir);
                *rays += n;
                let key = pixel_key(s.seed, x, y, width);
                self.obscurance_sum(camera, hit.position, ns, s, key, samples.clone())
            }),
            Estimator::Gi(s) => {
                let px = self.for_each_pixel("GI", width, height, |x, y, rays| {
                    let [d, i] = self.gi_pixel_sum(camera, x, y, width, height, s, samples.clone(), rays);
                    [d.x, d.y, d.z, i.x, i.y, i.z].map(f64::from)
                });
                px.into_iter().flatten().collect()
            }
            Estimator::ScreenOracle(s) => {
                let px = self.for_each_pixel("screen-space oracle", width, height, |x, y, rays| {
                    self.oracle_pixel_sum(camera, x, y, (width, height), s, samples.clone(), rays)
                });
                px.into_iter().flatten().collect()
            }
        }
    }

    /// Integrates `estimator` in two independent halves until
    /// `noise(half A, half B)` (on the finished half images, see
    /// [`Estimator::finish`]) is at most `rule.target`, or `rule.max_spp` total
    /// samples per pixel are reached. Each round brings both halves to the
    /// predicted sample count (at least double, at most 8× the previous one).
    pub fn converge(
        &self,
        camera: &Camera,
        width: u32,
        height: u32,
        estimator: &Estimator,
        rule: &ConvergeRule,
        mut noise: impl FnMut(&ImageBuf, &ImageBuf) -> f64,
    ) -> Converged {
        let channels = estimator.channels();
        let cap = (rule.max_spp / 2).max(1);
        let streams = [0u64, 1].map(|h| estimator.with_seed(hash(&[estimator.seed(), 0x4a1f, h])));
        let len = (width as usize) * (height as usize) * channels as usize;
        let mut sums = [0, 1].map(|_| Sums {
            data: vec![0.0; len],
            spp: 0,
        });
        let mut next = rule.first_spp.clamp(1, cap);
        let mut rounds = Vec::new();
        loop {
            let start = Instant::now();
            for (acc, stream) in sums.iter_mut().zip(&streams) {
                let add = self.sample_sums(camera, width, height, stream, acc.spp..next);
                acc.data.iter_mut().zip(add).for_each(|(a, b)| *a += b);
                acc.spp = next;
            }
            let halves = sums
                .each_ref()
                .map(|s| estimator.finish(&s.means(width, height, channels)));
            let measured = noise(&halves[0], &halves[1]);
            rounds.push(Round {
                spp: 2 * next,
                noise: measured,
                seconds: start.elapsed().as_secs_f64(),
            });
            let converged = measured <= rule.target;
            if converged || next >= cap {
                return Converged {
                    estimator: *estimator,
                    halves: sums.each_ref().map(|s| s.means(width, height, channels)),
                    spp_per_half: next,
                    noise: measured,
                    converged,
                    rounds,
                };
            }
            next = next_round_spp(next, measured, rule.target, decay_exponent(&rounds)).min(cap);
        }
    }
}

/// The exponent b of noise ∝ n^(−b) measured between the last two rounds, clamped to
/// [0.2, 1]; 0.5 (Monte Carlo RMSE) before there are two rounds. ꟻLIP, which raises colour
/// differences to the power 0.7, falls with b ≈ 0.35.
pub fn decay_exponent(rounds: &[Round]) -> f64 {
    match rounds {
        [.., a, b] if a.noise > 0.0 && b.noise > 0.0 && b.spp > a.spp => {
            let slope = (a.noise / b.noise).ln() / (b.spp as f64 / a.spp as f64).ln();
            if slope.is_finite() {
                slope.clamp(0.2, 1.0)
            } else {
                0.5
            }
        }
        _ => 0.5,
    }
}

/// Samples per half for the next round: the count at which noise ∝ n^(−b)
/// (b = `exponent`) would reach `target` with 20 % to spare, but at least 2× and
/// at most 8× `n`.
pub fn next_round_spp(n: u32, noise: f64, target: f64, exponent: f64) -> u32 {
    let n = n.max(1) as f64;
    let want = if target > 0.0 && noise.is_finite() && exponent > 0.0 {
        n * (noise / target).powf(1.0 / exponent) * 1.2
    } else {
        f64::INFINITY
    };
    want.clamp(2.0 * n, 8.0 * n).min(u32::MAX as f64 / 4.0).ceil() as u32
}
