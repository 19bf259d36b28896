//! Light probes for `--technique full` (DGB Fig. 9's static fallback): baked
//! once per scene with the CPU path tracer and cached next to the reference
//! images.

use anyhow::Result;
use glam::Vec3;
use strata_reference::gi::GiSettings;
use strata_reference::Reference;
use strata_scene::probes::{IrradianceProbes, DEPTH_TEXELS};
use strata_scene::{ImageBuf, Scene};

use super::{scene_fingerprint, RefCache};

/// Probes per axis (the default grid).
pub const GRID: [u32; 3] = [16, 8, 16];
/// Paths per probe (the default). 4096 left the warehouse's probes with 2 % noise (the
/// mean over probes and axis normals; 4.4 % at the 90th percentile), enough to draw
/// bands along a flat wall between neighbouring probes; 16384 halves it
/// (docs/radiosity.md § "Rays per probe").
pub const RAYS: u32 = 16384;
/// The range `--probe-rays` accepts.
pub const RAYS_RANGE: std::ops::RangeInclusive<u32> = 64..=1_048_576;
/// Bounces of each path after its first hit: with the receiver's own bounce, the
/// path tracer's 4.
pub const BOUNCES: u32 = 3;

/// How the light probes are baked: probes per axis and paths per probe.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ProbeBake {
    pub grid: [u32; 3],
    pub rays: u32,
}

impl Default for ProbeBake {
    fn default() -> Self {
        Self { grid: GRID, rays: RAYS }
    }
}

/// The scene's probes at animation frame 0 (static lighting) baked as `bake` says
/// ([`ProbeBake::default`] unless the user chose), from the cache or baked (with a notice
/// on stderr unless `quiet`).
pub fn scene_probes(scene: &Scene, bake: ProbeBake, cache: &RefCache, quiet: bool) -> Result<IrradianceProbes> {
    let ProbeBake { grid, rays } = bake;
    let description = format!(
        "v8 probes {} grid={grid:?} rays={rays} bounces={BOUNCES} relocate=plane×{}+inside depth={}² sharpness={} cutoff={:e} range={}",
        scene_fingerprint(scene, 0.0),
        strata_reference::probes::RELOCATE,
        strata_scene::probes::DEPTH_OCT,
        strata_reference::probes::DEPTH_SHARPNESS,
        strata_reference::probes::LOBE_CUTOFF,
        strata_reference::probes::DEPTH_RANGE
    );
    // the scene's own probe volume (keys without one stay as they were)
    let description = match scene.settings.probe_bounds {
        Some(b) => format!("{description} bounds={b:?}"),
        None => description,
    };
    let key = RefCache::key(&description);
    if let Some(img) = cache.load(&key) {
        if let Some(p) = decode(&img) {
            return Ok(p);
        }
    }
    if !quiet {
        eprintln!(
            "baking {} light probes ({}×{}×{}, {rays} paths each)…",
            grid.iter().product::<u32>(),
            grid[0],
            grid[1],
            grid[2]
        );
    }
    let settings = GiSettings {
        bounces: BOUNCES,
        ..Default::default()
    };
    // a large scene spends minutes in the BVH build before the first path: say so
    let triangles = scene.triangle_count();
    let step = Step::start(quiet, format!("building the BVH of {triangles} triangles"));
    let reference = Reference::new(scene, 0.0);
    step.finish();
    let step = Step::start(
        quiet,
        format!("tracing {} probes × {rays} paths", grid.iter().product::<u32>()),
    );
    let probes = match scene.settings.probe_bounds {
        Some([lo, hi]) => reference.bake_grid(IrradianceProbes::grid(lo.into(), hi.into(), grid), rays, &settings),
        None => reference.bake_probes(grid, rays, &settings),
    };
    step.finish();
    if let Err(e) = cache.store(&key, &encode(&probes), &description) {
        tracing::warn!("could not cache the light probes: {e:#}");
    }
    Ok(probes)
}

/// One step of a bake shown while it runs: a spinner with the elapsed time on a terminal;
/// elsewhere (logs, pipes) one line when it ends, if it took 5 s or more.
struct Step {
    bar: indicatif::ProgressBar,
    what: String,
    start: std::time::Instant,
    quiet: bool,
}

impl Step {
    fn start(quiet: bool, what: String) -> Self {
        use std::io::IsTerminal;
        let bar = if quiet || !std::io::stderr().is_terminal() {
            indicatif::ProgressBar::hidden()
        } else {
            let bar = indicatif::ProgressBar::new_spinner();
            if let Ok(style) = indicatif::ProgressStyle::with_template("{spinner} {msg}… {elapsed}") {
                bar.set_style(style);
            }
            bar.set_message(what.clone());
            bar.enable_steady_tick(std::time::Duration::from_millis(200));
            bar
        };
        Self {
            bar,
            what,
            start: std::time::Instant::now(),
            quiet,
        }
    }

    fn finish(self) {
        self.bar.finish_and_clear();
        let s = self.start.elapsed().as_secs_f64();
        if !self.quiet && self.bar.is_hidden() && s >= 5.0 {
            eprintln!("{}: {s:.0} s", self.what);
        }
    }
}

/// Floats per row: 27 coefficients, the validity, the distance map's moments, the
/// relocation offset.
const ROW: usize = 28 + 2 * DEPTH_TEXELS + 3;
const OFFSET: usize = 28 + 2 * DEPTH_TEXELS;

/// Row 0: origin, spacing, dims; row 1 + i: probe i's 27 coefficients, its validity
/// and its distance map (mean, mean square per texel).
fn encode(p: &IrradianceProbes) -> ImageBuf {
    let mut img = ImageBuf::new(ROW as u32, p.count() as u32 + 1, 1);
    let head = [p.origin.to_array(), p.spacing.to_array(), p.dims.map(|d| d as f32)].concat();
    img.data[..9].copy_from_slice(&head);
    for (i, c) in p.coeffs.iter().enumerate() {
        let row = ROW * (i + 1);
        img.data[row..row + 27].copy_from_slice(&c.concat());
        img.data[row + 27] = p.valid[i] as u32 as f32;
        if let Some(d) = p.depth.get(i) {
            img.data[row + 28..row + OFFSET].copy_from_slice(&d.concat());
        }
        if let Some(o) = p.offsets.get(i) {
            img.data[row + OFFSET..row + ROW].copy_from_slice(o);
        }
    }
    img
}

fn decode(img: &ImageBuf) -> Option<IrradianceProbes> {
    if img.width as usize != ROW || img.channels != 1 || img.height < 2 {
        return None;
    }
    let d = &img.data;
    let dims = [d[6] as u32, d[7] as u32, d[8] as u32];
    let count = (dims[0] * dims[1] * dims[2]) as usize;
    if count + 1 != img.height as usize {
        return None;
    }
    let coeffs = (0..count)
        .map(|i| std::array::from_fn(|k| std::array::from_fn(|c| d[ROW * (i + 1) + 3 * k + c])))
        .collect();
    let valid = (0..count).map(|i| d[ROW * (i + 1) + 27] > 0.5).collect();
    let depth = (0..count)
        .map(|i| std::array::from_fn(|t| std::array::from_fn(|c| d[ROW * (i + 1) + 28 + 2 * t + c])))
        .collect();
    let offsets = (0..count)
        .map(|i| std::array::from_fn(|c| d[ROW * (i + 1) + OFFSET + c]))
        .collect();
    Some(IrradianceProbes {
        origin: Vec3::new(d[0], d[1], d[2]),
        spacing: Vec3::new(d[3], d[4], d[5]),
        dims,
        coeffs,
        valid,
        depth,
        offsets,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cache_encoding_round_trips() {
        let mut p = IrradianceProbes::grid(Vec3::new(-1.0, 0.0, 2.0), Vec3::new(3.0, 2.0, 5.0), [3, 2, 2]);
        for (i, c) in p.coeffs.iter_mut().enumerate() {
            for (k, rgb) in c.iter_mut().enumerate() {
                *rgb = [i as f32, k as f32, 0.5 * (i + k) as f32];
            }
        }
        p.valid[3] = false;
        p.depth = (0..p.count())
            .map(|i| std::array::from_fn(|t| [i as f32 + t as f32, 0.25 * t as f32]))
            .collect();
        p.offsets = (0..p.count()).map(|i| [0.1 * i as f32, -0.2, 0.05]).collect();
        assert_eq!(decode(&encode(&p)), Some(p));
    }
}
