//! The CI slice of the fuzz campaign: a few thousand mutated inputs per format
//! with a fixed seed, in process, with zero crashes, hangs (> 1 s),
//! over-allocations (> 256 MiB peak) or invariant violations. Run it in
//! release mode (`cargo test --release -p strata-fuzz`); it takes a few seconds.

use std::time::{Duration, Instant};

use strata_fuzz::{alloc, Campaign, Format};

#[global_allocator]
static ALLOC: alloc::Counting = alloc::Counting;

/// The counting allocator sees every thread of the process: the tests of this
/// binary run one at a time, so one test's allocations never count against the
/// other's limits (they ran in parallel before and could fail at random).
static SERIAL: std::sync::Mutex<()> = std::sync::Mutex::new(());

fn serial() -> std::sync::MutexGuard<'static, ()> {
    SERIAL.lock().unwrap_or_else(|p| p.into_inner())
}

const INPUTS_PER_FORMAT: u64 = 4_000;
const SEED: u64 = 20261123;

#[test]
fn fixed_seed_slice_has_no_findings() {
    let _serial = serial();
    let t0 = Instant::now();
    let mut report = Vec::new();
    let mut findings = Vec::new();
    for format in Format::ALL {
        let c = Campaign::new(format, SEED);
        assert!(!c.seeds.is_empty(), "{}: no seeds", format.name());
        let stats = c.run(
            0..INPUTS_PER_FORMAT,
            |_| {},
            |f| {
                findings.push(format!(
                    "{} #{} {}: {}",
                    format.name(),
                    f.index,
                    f.verdict.kind(),
                    f.verdict.detail()
                ))
            },
        );
        assert_eq!(stats.inputs, INPUTS_PER_FORMAT);
        // The slice must exercise both outcomes (a harness whose inputs all fail
        // to parse, or all load, tests little).
        assert!(
            stats.ok > 0 && stats.err > 0,
            "{}: ok {} err {}",
            format.name(),
            stats.ok,
            stats.err
        );
        report.push(format!(
            "{}: ok {} err {} max {:.2} ms peak {:.1} MiB",
            format.name(),
            stats.ok,
            stats.err,
            stats.max_time.as_secs_f64() * 1e3,
            stats.max_peak_bytes as f64 / (1 << 20) as f64
        ));
    }
    eprintln!("{}", report.join("\n"));
    assert!(alloc::installed(), "the counting allocator is not active");
    assert!(findings.is_empty(), "findings:\n{}", findings.join("\n"));
    assert!(t0.elapsed() < Duration::from_secs(60), "slice took {:?}", t0.elapsed());
}

#[test]
fn the_oracle_catches_a_panic_and_an_over_allocation() {
    let _serial = serial();
    // The runner itself must turn a panic into a finding and see a big allocation.
    let target = strata_fuzz::Target::new();
    let limits = strata_fuzz::Limits {
        max_time: Duration::from_secs(1),
        max_alloc: 1 << 20,
    };
    // A 4×4 PNG decodes within 1 MiB: no finding.
    let png = &strata_fuzz::seeds::png_seeds()[0];
    assert_eq!(
        strata_fuzz::run_input(&target, Format::Png, png, &limits)
            .verdict
            .kind(),
        "ok"
    );
    // A valid glTF seed with a tiny limit: the scene's allocations exceed 1 KiB.
    let tiny = strata_fuzz::Limits {
        max_alloc: 1 << 10,
        ..limits
    };
    let gltf = &strata_fuzz::seeds::seeds(Format::Gltf).0[0];
    assert_eq!(
        strata_fuzz::run_input(&target, Format::Gltf, gltf, &tiny)
            .verdict
            .kind(),
        "alloc"
    );
}
