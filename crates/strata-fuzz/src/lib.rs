//! strata-fuzz: a deterministic mutation fuzzer for strata's scene loaders on
//! the stable toolchain (no libFuzzer).
//!
//! Every input must end in `Ok` or a one-line `Err` naming the file within
//! [`Limits::max_time`] and with a peak allocation below
//! [`Limits::max_alloc`]; an `Ok` scene must pass `Scene::validate` (and a
//! camera path must sample finite cameras). See `docs/reliability.md`.
//!
//! - [`seeds`]: seed inputs per [`Format`];
//! - [`mutate`]: the mutators and the per-index input generator;
//! - [`alloc`]: the counting global allocator (opt-in per binary/test);
//! - [`run_input`] / [`Campaign`]: the in-process runner.

pub mod alloc;
pub mod mutate;
pub mod seeds;

use std::panic::AssertUnwindSafe;
use std::path::{Path, PathBuf};
use std::sync::{Mutex, Once};
use std::time::{Duration, Instant};

use strata_scene::load::{self, MemFiles};

/// The input formats (targets).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Format {
    Gltf = 0,
    Glb = 1,
    Obj = 2,
    Mtl = 3,
    Toml = 4,
    Preset = 5,
    Path = 6,
    Png = 7,
    Jpeg = 8,
    Exr = 9,
}

impl Format {
    pub const ALL: [Format; 10] = [
        Format::Gltf,
        Format::Glb,
        Format::Obj,
        Format::Mtl,
        Format::Toml,
        Format::Preset,
        Format::Path,
        Format::Png,
        Format::Jpeg,
        Format::Exr,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Format::Gltf => "gltf",
            Format::Glb => "glb",
            Format::Obj => "obj",
            Format::Mtl => "mtl",
            Format::Toml => "toml",
            Format::Preset => "preset",
            Format::Path => "path",
            Format::Png => "png",
            Format::Jpeg => "jpeg",
            Format::Exr => "exr",
        }
    }

    /// File extension of saved inputs.
    pub fn ext(self) -> &'static str {
        match self {
            Format::Gltf => "gltf",
            Format::Glb => "glb",
            Format::Obj => "obj",
            Format::Mtl => "mtl",
            Format::Toml | Format::Preset | Format::Path => "toml",
            Format::Png => "png",
            Format::Jpeg => "jpg",
            Format::Exr => "exr",
        }
    }

    pub fn parse(s: &str) -> Option<Format> {
        Format::ALL
            .into_iter()
            .find(|f| f.name() == s || (s == "jpg" && *f == Format::Jpeg))
    }

    pub fn is_text(self) -> bool {
        matches!(
            self,
            Format::Obj | Format::Mtl | Format::Toml | Format::Preset | Format::Path | Format::Gltf
        )
    }
}

/// Per-input limits.
#[derive(Clone, Copy, Debug)]
pub struct Limits {
    /// Longer is a hang finding.
    pub max_time: Duration,
    /// A higher peak of live bytes (above the baseline) is an allocation finding.
    pub max_alloc: usize,
}

impl Default for Limits {
    fn default() -> Self {
        Limits {
            max_time: Duration::from_secs(1),
            max_alloc: 256 << 20,
        }
    }
}

/// What one input did.
#[derive(Clone, Debug, PartialEq)]
pub enum Verdict {
    Ok,
    Err(String),
    /// A panic (message).
    Crash(String),
    /// Finished, but over the time limit.
    Hang(Duration),
    /// Finished, but the peak allocation was over the limit (bytes).
    Alloc(usize),
    /// `Ok` but the result breaks an invariant, or a malformed error (message).
    Invariant(String),
}

impl Verdict {
    pub fn is_finding(&self) -> bool {
        !matches!(self, Verdict::Ok | Verdict::Err(_))
    }

    pub fn kind(&self) -> &'static str {
        match self {
            Verdict::Ok => "ok",
            Verdict::Err(_) => "err",
            Verdict::Crash(_) => "crash",
            Verdict::Hang(_) => "hang",
            Verdict::Alloc(_) => "alloc",
            Verdict::Invariant(_) => "invariant",
        }
    }

    pub fn detail(&self) -> String {
        match self {
            Verdict::Ok => String::new(),
            Verdict::Err(e) | Verdict::Crash(e) | Verdict::Invariant(e) => e.clone(),
            Verdict::Hang(d) => format!("took {:.3} s", d.as_secs_f64()),
            Verdict::Alloc(b) => format!("peak allocation {:.1} MiB", *b as f64 / (1 << 20) as f64),
        }
    }
}

/// The result of one input.
#[derive(Clone, Debug)]
pub struct Outcome {
    pub verdict: Verdict,
    pub elapsed: Duration,
    /// Peak live bytes above the baseline (0 when the counting allocator is not installed).
    pub peak_bytes: usize,
}

/// The fixed context inputs run in: the in-memory companion files.
pub struct Target {
    files: MemFiles,
    obj_for_mtl: Vec<u8>,
}

impl Default for Target {
    fn default() -> Self {
        Self::new()
    }
}

impl Target {
    pub fn new() -> Self {
        let dir = seeds::input_dir();
        let mut files = MemFiles::new();
        for (name, bytes) in seeds::companion_files() {
            files.insert(dir.join(name), bytes);
        }
        if let Some(shared) = seeds::shared_scenes() {
            if let Ok(b) = std::fs::read(shared.join("cornell_box/cornell_box.mtl")) {
                files.insert(dir.join("cornell_box.mtl"), b);
            }
        }
        Target {
            files,
            obj_for_mtl: seeds::TINY_OBJ.as_bytes().to_vec(),
        }
    }

    /// The path an input of `format` is loaded as (it names the file in errors).
    pub fn input_path(format: Format) -> PathBuf {
        seeds::input_dir().join(format!("in.{}", format.ext()))
    }

    /// Loads `input` as `format`: `Ok(())`, `Err(message)`, or
    /// `Err("INVARIANT: …")` for an `Ok` result that breaks an invariant.
    pub fn load(&self, format: Format, input: &[u8]) -> Result<(), String> {
        let path = Self::input_path(format);
        let file_name = path.file_name().unwrap().to_string_lossy().into_owned();
        let check_err = |e: String, name: &str| -> String {
            if e.contains('\n') || !e.contains(name) {
                format!("INVARIANT: error is not one line naming {name}: {e:?}")
            } else {
                e
            }
        };
        match format {
            Format::Gltf | Format::Glb | Format::Obj | Format::Toml | Format::Path => {
                let scene =
                    load::load_slice(input, &path, &self.files).map_err(|e| check_err(e.to_string(), &file_name))?;
                scene
                    .validate()
                    .map_err(|e| format!("INVARIANT: loaded scene is invalid: {e}"))?;
                if let Some(p) = &scene.camera_path {
                    let (a, b) = (p.first_frame(), p.last_frame());
                    for f in [
                        a,
                        b,
                        0.5 * (a + b),
                        a + 0.25 * (b - a),
                        a + 1e-3,
                        b - 1e-3,
                        f32::NAN,
                        f32::INFINITY,
                        -1e30,
                    ] {
                        let c = scene.camera_at(f);
                        if !(c.eye.is_finite() && c.target.is_finite()) {
                            return Err(format!(
                                "INVARIANT: camera path gives a non-finite camera at frame {f}: {c:?}"
                            ));
                        }
                    }
                }
                Ok(())
            }
            Format::Mtl => {
                let mut files = self.files.clone();
                files.insert(seeds::input_dir().join("in.mtl"), input.to_vec());
                let obj_path = seeds::input_dir().join("in.obj");
                let scene = load::load_slice(&self.obj_for_mtl, &obj_path, &files)
                    .map_err(|e| check_err(e.to_string(), "in.obj"))?;
                scene
                    .validate()
                    .map_err(|e| format!("INVARIANT: loaded scene is invalid: {e}"))
            }
            #[cfg(feature = "preset")]
            Format::Preset => {
                let text = std::str::from_utf8(input).map_err(|e| e.to_string())?;
                strata_render::passes::radiosity::Preset::parse(text).map(|_| ())
            }
            #[cfg(not(feature = "preset"))]
            Format::Preset => Err("preset target not built (feature `preset`)".into()),
            Format::Png | Format::Jpeg | Format::Exr => {
                let t = load::decode_texture(input, &file_name)?;
                if t.rgba8.len() as u64 != t.width as u64 * t.height as u64 * 4 || t.width == 0 || t.height == 0 {
                    return Err(format!(
                        "INVARIANT: texture {}×{} with {} bytes",
                        t.width,
                        t.height,
                        t.rgba8.len()
                    ));
                }
                Ok(())
            }
        }
    }
}

static PANIC_MSG: Mutex<Option<String>> = Mutex::new(None);
static HOOK: Once = Once::new();

/// Installs a quiet panic hook that records the message and location (once per process).
pub fn install_quiet_panic_hook() {
    HOOK.call_once(|| {
        std::panic::set_hook(Box::new(|info| {
            let msg = if let Some(s) = info.payload().downcast_ref::<&str>() {
                s.to_string()
            } else if let Some(s) = info.payload().downcast_ref::<String>() {
                s.clone()
            } else {
                "panic".into()
            };
            let loc = info
                .location()
                .map(|l| format!(" at {}:{}", l.file(), l.line()))
                .unwrap_or_default();
            if let Ok(mut m) = PANIC_MSG.lock() {
                *m = Some(format!("{msg}{loc}"));
            }
        }));
    });
}

/// Runs one input: catches panics, measures time and peak allocation.
pub fn run_input(target: &Target, format: Format, input: &[u8], limits: &Limits) -> Outcome {
    install_quiet_panic_hook();
    let base = alloc::reset_peak();
    let t0 = Instant::now();
    let r = std::panic::catch_unwind(AssertUnwindSafe(|| target.load(format, input)));
    let elapsed = t0.elapsed();
    let peak_bytes = alloc::peak().saturating_sub(base);
    let verdict = match r {
        Err(_) => Verdict::Crash(
            PANIC_MSG
                .lock()
                .ok()
                .and_then(|mut m| m.take())
                .unwrap_or_else(|| "panic".into()),
        ),
        Ok(_) if elapsed > limits.max_time => Verdict::Hang(elapsed),
        Ok(_) if peak_bytes > limits.max_alloc => Verdict::Alloc(peak_bytes),
        Ok(Err(e)) if e.starts_with("INVARIANT: ") => Verdict::Invariant(e["INVARIANT: ".len()..].to_string()),
        Ok(Err(e)) => Verdict::Err(e),
        Ok(Ok(())) => Verdict::Ok,
    };
    Outcome {
        verdict,
        elapsed,
        peak_bytes,
    }
}

/// A finding: the input index (or file), its verdict and the input.
#[derive(Clone, Debug)]
pub struct Finding {
    pub format: Format,
    pub index: u64,
    pub verdict: Verdict,
    pub input: Vec<u8>,
}

/// Counts for one format.
#[derive(Clone, Debug, Default)]
pub struct Stats {
    pub inputs: u64,
    pub ok: u64,
    pub err: u64,
    pub crash: u64,
    pub hang: u64,
    pub alloc: u64,
    pub invariant: u64,
    /// Worker deaths (abort, stack overflow, out of memory) and kills after a stall.
    pub abort: u64,
    pub max_time: Duration,
    pub max_peak_bytes: usize,
    pub total_time: Duration,
}

impl Stats {
    pub fn add(&mut self, o: &Outcome) {
        self.inputs += 1;
        match o.verdict {
            Verdict::Ok => self.ok += 1,
            Verdict::Err(_) => self.err += 1,
            Verdict::Crash(_) => self.crash += 1,
            Verdict::Hang(_) => self.hang += 1,
            Verdict::Alloc(_) => self.alloc += 1,
            Verdict::Invariant(_) => self.invariant += 1,
        }
        self.max_time = self.max_time.max(o.elapsed);
        self.max_peak_bytes = self.max_peak_bytes.max(o.peak_bytes);
        self.total_time += o.elapsed;
    }

    pub fn findings(&self) -> u64 {
        self.crash + self.hang + self.alloc + self.invariant + self.abort
    }

    pub fn merge(&mut self, o: &Stats) {
        self.inputs += o.inputs;
        self.ok += o.ok;
        self.err += o.err;
        self.crash += o.crash;
        self.hang += o.hang;
        self.alloc += o.alloc;
        self.invariant += o.invariant;
        self.abort += o.abort;
        self.max_time = self.max_time.max(o.max_time);
        self.max_peak_bytes = self.max_peak_bytes.max(o.max_peak_bytes);
        self.total_time += o.total_time;
    }

    pub fn json(&self) -> serde_json::Value {
        serde_json::json!({
            "inputs": self.inputs, "ok": self.ok, "err": self.err, "crash": self.crash, "hang": self.hang,
            "alloc": self.alloc, "invariant": self.invariant, "abort": self.abort,
            "max_ms": self.max_time.as_secs_f64() * 1e3,
            "max_peak_mib": self.max_peak_bytes as f64 / (1 << 20) as f64,
            "cpu_s": self.total_time.as_secs_f64(),
        })
    }
}

/// A deterministic in-process campaign over one format.
pub struct Campaign {
    pub format: Format,
    pub seed: u64,
    pub seeds: Vec<Vec<u8>>,
    pub notes: Vec<String>,
    pub target: Target,
    pub limits: Limits,
}

impl Campaign {
    pub fn new(format: Format, seed: u64) -> Self {
        let (seeds, notes) = seeds::seeds(format);
        Campaign {
            format,
            seed,
            seeds,
            notes,
            target: Target::new(),
            limits: Limits::default(),
        }
    }

    /// Input `index` of this campaign.
    pub fn input(&self, index: u64) -> Vec<u8> {
        // The first inputs are the seeds themselves.
        if (index as usize) < self.seeds.len() {
            return self.seeds[index as usize].clone();
        }
        mutate::generate(self.format, &self.seeds, self.seed, index)
    }

    /// Runs inputs `range`, calling `progress(index)` before each and
    /// `on_finding` for each finding.
    pub fn run(
        &self,
        range: std::ops::Range<u64>,
        mut progress: impl FnMut(u64),
        mut on_finding: impl FnMut(Finding),
    ) -> Stats {
        let mut stats = Stats::default();
        for i in range {
            progress(i);
            let input = self.input(i);
            let o = run_input(&self.target, self.format, &input, &self.limits);
            stats.add(&o);
            if o.verdict.is_finding() {
                on_finding(Finding {
                    format: self.format,
                    index: i,
                    verdict: o.verdict,
                    input,
                });
            }
        }
        stats
    }
}

/// Shrinks `input` while `still(input)` holds (chunk deletion, halving chunk
/// sizes down to single bytes), within `budget` attempts.
pub fn minimise(mut input: Vec<u8>, mut still: impl FnMut(&[u8]) -> bool, budget: usize) -> Vec<u8> {
    let mut tries = 0;
    let mut size = (input.len() / 2).max(1);
    while size >= 1 && tries < budget {
        let mut i = 0;
        let mut changed = false;
        while i < input.len() && tries < budget {
            let end = (i + size).min(input.len());
            let mut cand = input.clone();
            cand.drain(i..end);
            tries += 1;
            if still(&cand) {
                input = cand;
                changed = true;
            } else {
                i += size;
            }
        }
        if !changed {
            if size == 1 {
                break;
            }
            size /= 2;
        }
    }
    input
}

/// Saves a finding's input under `dir/<format>/<kind>-<index>.<ext>`; returns the path.
pub fn save_finding(dir: &Path, f: &Finding) -> std::io::Result<PathBuf> {
    let d = dir.join(f.format.name());
    std::fs::create_dir_all(&d)?;
    let p = d.join(format!("{}-{}.{}", f.verdict.kind(), f.index, f.format.ext()));
    std::fs::write(&p, &f.input)?;
    Ok(p)
}
