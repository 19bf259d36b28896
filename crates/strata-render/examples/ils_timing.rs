//! Times buffer splitting (BS) and gathering (BG) of interleaved deferred
//! shading per method, pattern and block size (ILS §5.1, Fig. 5) with GPU
//! timestamp queries.
//!
//! ```sh
//! cargo run --release -p strata-render --example ils_timing            # 1024×1024, Fig. 5's set
//! cargo run --release -p strata-render --example ils_timing -- 256 5   # size, repeats
//! ```
//!
//! On lavapipe (software Vulkan) the times are CPU times of the rasteriser
//! threads, not GPU memory behaviour: compare methods on one machine only.

use strata_render::passes::interleave::bench::{time_interleave, TimingConfig};
use strata_render::{GpuContext, GpuOptions};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut cfg = TimingConfig::default();
    let parse = |i: usize, name: &str| -> Option<u32> {
        args.get(i).map(|a| {
            a.parse().unwrap_or_else(|_| {
                eprintln!("ils_timing: {name} '{a}' is not a positive integer");
                std::process::exit(2)
            })
        })
    };
    if let Some(s) = parse(0, "size") {
        cfg.width = s;
        cfg.height = s;
    }
    if let Some(r) = parse(1, "repeats") {
        cfg.repeats = r.max(1);
    }
    let gpu = GpuContext::new(&GpuOptions::default()).unwrap_or_else(|e| {
        eprintln!("ils_timing: {e}");
        std::process::exit(1)
    });
    println!(
        "# ILS BS/BG timings, {}x{} {:?}, median of {} (GPU timestamps, ms) on {}",
        cfg.width,
        cfg.height,
        cfg.format,
        cfg.repeats,
        gpu.describe()
    );
    let rows = time_interleave(&gpu, &cfg).unwrap_or_else(|e| {
        eprintln!("ils_timing: {e}");
        std::process::exit(1)
    });
    println!(
        "{:<8} {:<11} {:>9} {:>9} {:>9}  per pass",
        "pattern", "method", "BS ms", "BG ms", "wall ms"
    );
    for r in rows {
        let passes: Vec<String> = r
            .split
            .iter()
            .chain(&r.gather)
            .map(|(l, t)| format!("{}={t:.2}", l.trim_start_matches("ils-")))
            .collect();
        println!(
            "{:<8} {:<11} {:>9.2} {:>9.2} {:>9.2}  {}",
            format!("{}x{}", r.n, r.m),
            r.method.name(),
            r.split_ms(),
            r.gather_ms(),
            r.wall_ms,
            passes.join(" ")
        );
    }
}
