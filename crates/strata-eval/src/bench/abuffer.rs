//! `strata bench abuffer`: ABA Table I's stages (clear, count, prefix sum, draw,
//! resolve, AO) per A-buffer construction — `linked-list`, `linear`,
//! `fixed-array`, `dual-peel` — and the `compressed` path (the linked list
//! resolved with Eq. 5 compression, AO taps reading the M nodes), each with the
//! memory of its structure at the bench size and the fragments it stored and
//! dropped (overflow). The frame is the `aba-ao` technique's (OIT + multilayer
//! AO); the AO speed-up of compression and the ꟻLIP between the two AO images
//! come last (ABA §V's heavy-workload comparison).
//!
//! With `--set kernel=hbao-compute` the bench is ABA Table III (opaque
//! multilayer HBAO, §V-B): the list columns run the fragment-shader HBAO with
//! the compute kernel's taps (D = 4 axis directions, φ = 0: brute-force list
//! walk per tap), `compressed` the compute HBAO over the M nodes staged in
//! workgroup memory, plus [`TABLE3_KEYS`]: `compressed-fragment` (the same
//! taps over the compressed nodes in the fragment shader, one texel fetch per
//! tap: what the staging alone buys) and `single-layer` (compute HBAO over
//! each pixel's nearest node: Table III's "default").
//!
//! With `--set multires=4` every column's AO is the multi-resolution AO over
//! 4 levels (ABA Table II; each row's `stage.multires` says so).

use std::collections::BTreeMap;

use anyhow::Result;
use serde_json::json;
use strata_render::frame::FrameCameras;
use strata_render::passes::abuffer::ao::AoKernel;
use strata_render::passes::abuffer::{ABufferMethod, ABufferSettings};
use strata_render::technique;
use strata_render::{RenderSettings, Renderer};

use super::stage::{self, Stage, StageSettings};
use super::timing_gpu;
use crate::results::{AbufferBench, AbufferMethodBench};

/// The bench keys in Table I's column order.
pub const KEYS: [&str; 5] = ["dual-peel", "linked-list", "linear", "fixed-array", "compressed"];

/// The columns Table III (`kernel=hbao-compute`) adds after [`KEYS`].
pub const TABLE3_KEYS: [&str; 2] = ["compressed-fragment", "single-layer"];

/// `set`: the `oit` technique's settings (`pool`, `max-layers`, `compress`, …), applied
/// last and range-checked; `abuffer` and (for the compressed run) `compress` are the bench's.
pub fn run(stage: &StageSettings, set: &[(String, f64)]) -> Result<AbufferBench> {
    let t = technique::find("aba-ao")?;
    let (scene, cams) = stage.scene.load()?;
    let stage1 = StageSettings {
        layers: 1,
        ..stage.clone()
    };
    let configure = |key: &str| -> Result<RenderSettings> {
        let mut s = t.settings(&stage1.render_settings(1), None)?;
        for (name, value) in set {
            t.set(&mut s, name, *value)
                .map_err(|e| anyhow::anyhow!("--set {name}={value}: {e}"))?;
        }
        let a = s.abuffer.get_or_insert_with(ABufferSettings::default);
        let table3 = a.ao.as_ref().is_some_and(|o| o.kernel == AoKernel::HbaoCompute);
        if key == "compressed" || TABLE3_KEYS.contains(&key) {
            a.method = ABufferMethod::LinkedList;
            a.compress = a.compress.or(ABufferSettings::default().compress).or(Some(6));
        } else {
            a.method = key.parse().map_err(|e: String| anyhow::anyhow!(e))?;
            a.compress = None;
        }
        if let (true, Some(o)) = (table3, a.ao.as_mut()) {
            match key {
                "compressed" => {}
                "single-layer" => o.multilayer = false,
                // the compute kernel's taps (D = 4, φ = 0) in the fragment shader
                _ => {
                    o.kernel = AoKernel::Hbao;
                    o.directions = 4;
                    o.rotate = false;
                }
            }
        }
        s.validate()?;
        Ok(s)
    };
    let gpu = timing_gpu(&stage.adapter)?;
    let (w, h) = (stage.scene.width, stage.scene.height);
    let mut methods = BTreeMap::new();
    let mut ao_images = BTreeMap::new();
    let table3 = configure("compressed")?
        .abuffer
        .and_then(|a| a.ao)
        .is_some_and(|o| o.kernel == AoKernel::HbaoCompute);
    let keys: Vec<&str> = if table3 {
        KEYS.iter().chain(&TABLE3_KEYS).copied().collect()
    } else {
        KEYS.to_vec()
    };
    for key in keys {
        let settings = configure(key)?;
        let a = settings.abuffer.clone().expect("oit has an A-buffer");
        // fragments stored and dropped, from one frame's lists
        let (fragments, dropped, pool) = {
            let mut r = Renderer::new(&gpu, &scene, settings.clone())?;
            r.render(&gpu, &scene, &FrameCameras::fixed(cams.current), stage.scene.frame)?;
            let abuffer = r.abuffer().expect("A-buffer");
            let (lists, pool) = (abuffer.read_lists(&gpu)?, abuffer.pool());
            if key == "linked-list" || key == "compressed" {
                ao_images.insert(key, r.read_target(&gpu, "ao")?);
            }
            gpu.check_errors()?;
            (lists.total, lists.overflow, pool)
        };
        let mut passes = a.method.passes().to_vec();
        passes.extend(["aba-ao", "ao-blur-h", "ao-blur-v"]);
        let extra = json!({
            "technique": "aba-ao",
            "abuffer": a.method.name(),
            // the nodes the stage allocated (the default pool fits the adapter)
            "pool": pool,
            "max_layers": a.max_layers,
            "compress": a.compress,
            "compress_back_half": a.compress_back_half,
            "kernel": a.ao.as_ref().map(|o| format!("{:?}", o.kernel)),
            "multilayer": a.ao.as_ref().map(|o| o.multilayer),
            "multires": a.ao.as_ref().map(|o| o.levels),
        });
        let s2 = settings.clone();
        let bench = stage::run(Stage {
            stage: &stage1,
            passes: &passes,
            settings: Box::new(move |_| s2.clone()),
            extra,
        })?;
        let ms = |name: &str| bench.passes.iter().find(|p| p.name == name).map(|p| p.median_ms);
        methods.insert(
            key.to_string(),
            AbufferMethodBench {
                clear_ms: ms("abuffer-clear"),
                count_ms: ms("abuffer-count"),
                prefix_sum_ms: ms("abuffer-prefix-sum"),
                draw_ms: ms("abuffer-draw"),
                resolve_ms: ms("abuffer-resolve"),
                ao_ms: ms("aba-ao"),
                ao_blur_ms: ms("ao-blur-h").zip(ms("ao-blur-v")).map(|(a, b)| a + b),
                total_ms: bench.total_median_ms,
                memory_bytes: a.memory_bytes(w, h) + a.compressed_bytes(w, h),
                fragments,
                dropped,
                stage: bench,
            },
        );
    }
    let ao = |k: &str| methods.get(k).and_then(|m: &AbufferMethodBench| m.ao_ms);
    let ao_speedup = ao("linked-list").zip(ao("compressed")).map(|(b, c)| b / c);
    let ao_flip = match (ao_images.get("compressed"), ao_images.get("linked-list")) {
        (Some(c), Some(b)) => Some(crate::metrics::compare(b, c)?.0.flip),
        _ => None,
    };
    Ok(AbufferBench {
        methods,
        ao_speedup,
        ao_flip_compressed_vs_brute: ao_flip,
    })
}
