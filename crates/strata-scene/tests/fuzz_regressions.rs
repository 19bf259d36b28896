//! Every input under `<repo>/tests/fuzz-regressions/<format>/` (inputs that
//! crashed, hung or over-allocated in the loaders before they were fixed; see
//! `docs/reliability.md`) loads without a panic, within 1 s and 256 MiB of
//! peak allocation, to a valid scene or a one-line error naming the file.

use std::alloc::{GlobalAlloc, Layout, System};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant};

use strata_scene::load::{self, MemFiles};

/// Counts live bytes and their peak (this test binary only).
struct Counting;
static LIVE: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);
/// Allocations beyond this fail (the test aborts) instead of exhausting the machine.
const HARD_CAP: usize = 4 << 30;

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        let live = LIVE.fetch_add(l.size(), Ordering::Relaxed) + l.size();
        if live > HARD_CAP {
            LIVE.fetch_sub(l.size(), Ordering::Relaxed);
            return std::ptr::null_mut();
        }
        PEAK.fetch_max(live, Ordering::Relaxed);
        // SAFETY: forwarded to the system allocator.
        unsafe { System.alloc(l) }
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        // SAFETY: `p` came from `alloc` with this layout.
        unsafe { System.dealloc(p, l) };
        LIVE.fetch_sub(l.size(), Ordering::Relaxed);
    }
}

#[global_allocator]
static A: Counting = Counting;

const MAX_TIME: Duration = Duration::from_secs(1);
const MAX_ALLOC: usize = 256 << 20;

fn regressions_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../tests/fuzz-regressions")
}

/// Loads one regression input: `Ok(description)` or `Err(message)`; a panic
/// propagates to `catch_unwind` in the caller.
fn load(format: &str, file: &Path) -> Result<String, String> {
    match format {
        "gltf" | "glb" | "obj" | "path" | "toml" => load::load_path(file).map_err(|e| e.to_string()).and_then(|s| {
            s.validate().map_err(|e| format!("INVALID SCENE: {e}"))?;
            Ok(format!("{} triangles", s.triangle_count()))
        }),
        "mtl" => {
            // An OBJ using material 'red' of this MTL, both served from memory
            // under the regression file's folder.
            let dir = file.parent().unwrap();
            let obj = dir.join("mtl-host.obj");
            let name = file.file_name().unwrap().to_string_lossy().into_owned();
            let mut files = MemFiles::new();
            files.insert(dir.join(&name), std::fs::read(file).unwrap());
            let text = format!("mtllib {name}\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\n");
            load::load_slice(text.as_bytes(), &obj, &files)
                .map(|s| format!("{} triangles", s.triangle_count()))
                .map_err(|e| e.to_string())
        }
        "png" | "jpeg" | "exr" => {
            let name = file.file_name().unwrap().to_string_lossy().into_owned();
            load::load_texture(file)
                .map(|t| format!("{}×{}", t.width, t.height))
                .map_err(|e| format!("{name}: {e}"))
        }
        other => panic!("unknown regression folder '{other}'"),
    }
}

#[test]
fn every_regression_input_loads_or_errors_cleanly() {
    let root = regressions_dir();
    let mut dirs: Vec<PathBuf> = std::fs::read_dir(&root)
        .unwrap_or_else(|e| panic!("{}: {e}", root.display()))
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_dir())
        .collect();
    dirs.sort();
    let mut n = 0;
    let mut failures = Vec::new();
    for dir in dirs {
        let format = dir.file_name().unwrap().to_string_lossy().into_owned();
        let mut files: Vec<PathBuf> = std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().path()).collect();
        files.sort();
        for file in files {
            n += 1;
            let name = file.file_name().unwrap().to_string_lossy().into_owned();
            let base = LIVE.load(Ordering::Relaxed);
            PEAK.store(base, Ordering::Relaxed);
            let t0 = Instant::now();
            let r = std::panic::catch_unwind(|| load(&format, &file));
            let (elapsed, peak) = (t0.elapsed(), PEAK.load(Ordering::Relaxed) - base);
            let what = format!("{format}/{name}");
            match &r {
                Err(_) => failures.push(format!("{what}: panicked")),
                Ok(Err(e)) if e.starts_with("INVALID SCENE") => failures.push(format!("{what}: {e}")),
                Ok(Err(e)) if e.contains('\n') || !e.contains(&name) => {
                    failures.push(format!("{what}: error is not one line naming the file: {e:?}"))
                }
                _ => {}
            }
            if elapsed > MAX_TIME {
                failures.push(format!("{what}: took {elapsed:?}"));
            }
            if peak > MAX_ALLOC {
                failures.push(format!("{what}: peak allocation {} MiB", peak >> 20));
            }
            eprintln!("{what}: {:?} in {elapsed:?}, peak {} KiB", r.ok(), peak >> 10);
        }
    }
    assert!(n >= 20, "only {n} regression inputs found under {}", root.display());
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
