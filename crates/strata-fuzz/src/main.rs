//! `strata-fuzz`: runs a deterministic fuzz campaign over strata's scene
//! loaders. Each format's inputs run in a worker process (this binary with
//! `--worker`) watched by a supervisor, so that an abort (stack overflow, a
//! failed allocation) or an endless loop is recorded with its input instead
//! of ending the campaign.
//!
//! ```text
//! strata-fuzz --format all --inputs 100000 --seed 1 --corpus target/fuzz --json
//! strata-fuzz --format gltf --replay crash.gltf [--minimise]
//! ```

use std::io::{BufRead, BufReader, Write};
use std::os::unix::fs::FileExt;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use strata_fuzz::{
    alloc, minimise, run_input, save_finding, Campaign, Finding, Format, Limits, Stats, Target, Verdict,
};

#[global_allocator]
static ALLOC: alloc::Counting = alloc::Counting;

const USAGE: &str = "usage: strata-fuzz [--format gltf|glb|obj|mtl|toml|preset|path|png|jpeg|exr|all[,…]] [--inputs N (per format, default 10000)]
                   [--seed S (default 1)] [--start K] [--corpus DIR (findings saved here, default target/fuzz)]
                   [--workers W (processes per format, default 1)] [--max-ms MS (default 1000)]
                   [--max-alloc-mib MIB (default 256)] [--stall-secs S (default 10)] [--no-fork] [--json]
                   [--dump-seeds DIR]
       strata-fuzz --format F --replay FILE [--minimise]";

#[derive(Clone)]
struct Args {
    formats: Vec<Format>,
    inputs: u64,
    seed: u64,
    start: u64,
    corpus: PathBuf,
    workers: u64,
    limits: Limits,
    stall: Duration,
    no_fork: bool,
    json: bool,
    replay: Option<PathBuf>,
    minimise: bool,
    dump_seeds: Option<PathBuf>,
    worker: Option<(u64, u64, PathBuf)>,
}

fn parse_args() -> Result<Args, String> {
    let mut a = Args {
        formats: Format::ALL.to_vec(),
        inputs: 10_000,
        seed: 1,
        start: 0,
        corpus: PathBuf::from("target/fuzz"),
        workers: 1,
        limits: Limits::default(),
        stall: Duration::from_secs(10),
        no_fork: false,
        json: false,
        replay: None,
        minimise: false,
        dump_seeds: None,
        worker: None,
    };
    let mut it = std::env::args().skip(1);
    let (mut wstart, mut wend, mut wprog) = (None, None, None);
    while let Some(arg) = it.next() {
        let mut val = |name: &str| it.next().ok_or_else(|| format!("{name} needs a value"));
        let num = |s: String, name: &str| {
            s.parse::<u64>()
                .map_err(|_| format!("{name}: '{s}' is not a non-negative integer"))
        };
        match arg.as_str() {
            "--format" => {
                let v = val("--format")?;
                a.formats = if v == "all" {
                    Format::ALL.to_vec()
                } else {
                    v.split(',')
                        .map(|f| Format::parse(f).ok_or_else(|| format!("unknown format '{f}'\n{USAGE}")))
                        .collect::<Result<_, _>>()?
                };
            }
            "--inputs" => a.inputs = num(val("--inputs")?, "--inputs")?,
            "--seed" => a.seed = num(val("--seed")?, "--seed")?,
            "--start" => a.start = num(val("--start")?, "--start")?,
            "--corpus" => a.corpus = PathBuf::from(val("--corpus")?),
            "--workers" => a.workers = num(val("--workers")?, "--workers")?.clamp(1, 64),
            "--max-ms" => a.limits.max_time = Duration::from_millis(num(val("--max-ms")?, "--max-ms")?),
            "--max-alloc-mib" => a.limits.max_alloc = (num(val("--max-alloc-mib")?, "--max-alloc-mib")? as usize) << 20,
            "--stall-secs" => a.stall = Duration::from_secs(num(val("--stall-secs")?, "--stall-secs")?.max(1)),
            "--no-fork" => a.no_fork = true,
            "--json" => a.json = true,
            "--replay" => a.replay = Some(PathBuf::from(val("--replay")?)),
            "--minimise" | "--minimize" => a.minimise = true,
            "--dump-seeds" => a.dump_seeds = Some(PathBuf::from(val("--dump-seeds")?)),
            "--worker" => {}
            "--worker-start" => wstart = Some(num(val("--worker-start")?, "--worker-start")?),
            "--worker-end" => wend = Some(num(val("--worker-end")?, "--worker-end")?),
            "--worker-progress" => wprog = Some(PathBuf::from(val("--worker-progress")?)),
            "-h" | "--help" => return Err(USAGE.into()),
            other => return Err(format!("unknown argument '{other}'\n{USAGE}")),
        }
    }
    if let (Some(s), Some(e), Some(p)) = (wstart, wend, wprog) {
        a.worker = Some((s, e, p));
    }
    Ok(a)
}

fn main() {
    let args = match parse_args() {
        Ok(a) => a,
        Err(e) => {
            eprintln!("{e}");
            std::process::exit(2);
        }
    };
    // A 2 MiB stack, like test threads: deep recursion shows up here first.
    let handle = std::thread::Builder::new()
        .stack_size(2 << 20)
        .spawn(move || real_main(args))
        .expect("spawn main thread");
    let code = handle.join().unwrap_or(101);
    std::process::exit(code);
}

fn real_main(args: Args) -> i32 {
    if let Some((start, end, progress)) = &args.worker {
        return worker(&args, *start, *end, progress);
    }
    if let Some(dir) = &args.dump_seeds {
        for f in &args.formats {
            let (seeds, notes) = strata_fuzz::seeds::seeds(*f);
            notes.iter().for_each(|n| eprintln!("{n}"));
            let d = dir.join(f.name());
            std::fs::create_dir_all(&d).expect("create seed dir");
            for (i, s) in seeds.iter().enumerate() {
                std::fs::write(d.join(format!("seed-{i}.{}", f.ext())), s).expect("write seed");
            }
        }
        return 0;
    }
    if let Some(file) = &args.replay {
        return replay(&args, file);
    }
    campaign(&args)
}

/// Worker: runs `start..end` of the single format, writing the index about to
/// run to `progress` (8 bytes) and findings/stats lines to stdout.
fn worker(args: &Args, start: u64, end: u64, progress: &Path) -> i32 {
    let format = args.formats[0];
    let mut c = Campaign::new(format, args.seed);
    c.limits = args.limits;
    let pf = std::fs::OpenOptions::new()
        .write(true)
        .open(progress)
        .expect("open progress file");
    let stdout = std::io::stdout();
    let mut total = Stats::default();
    let mut i = start;
    while i < end {
        let chunk_end = (i + 5_000).min(end);
        let stats = c.run(
            i..chunk_end,
            |k| {
                let _ = pf.write_at(&k.to_le_bytes(), 0);
            },
            |f| {
                let mut out = stdout.lock();
                let _ = writeln!(
                    out,
                    "FINDING {} {} {}",
                    f.index,
                    f.verdict.kind(),
                    serde_json::to_string(&f.verdict.detail()).unwrap_or_default()
                );
                let _ = out.flush();
            },
        );
        total.merge(&stats);
        let mut out = stdout.lock();
        let _ = writeln!(out, "STATS {} {}", chunk_end, stats_line(&total));
        let _ = out.flush();
        i = chunk_end;
    }
    0
}

fn stats_line(s: &Stats) -> String {
    format!(
        "{} {} {} {} {} {} {} {} {} {}",
        s.inputs,
        s.ok,
        s.err,
        s.crash,
        s.hang,
        s.alloc,
        s.invariant,
        s.max_time.as_nanos(),
        s.max_peak_bytes,
        s.total_time.as_nanos()
    )
}

fn parse_stats(words: &[&str]) -> Option<Stats> {
    let n: Vec<u128> = words.iter().map(|w| w.parse().ok()).collect::<Option<_>>()?;
    if n.len() != 10 {
        return None;
    }
    Some(Stats {
        inputs: n[0] as u64,
        ok: n[1] as u64,
        err: n[2] as u64,
        crash: n[3] as u64,
        hang: n[4] as u64,
        alloc: n[5] as u64,
        invariant: n[6] as u64,
        abort: 0,
        max_time: Duration::from_nanos(n[7] as u64),
        max_peak_bytes: n[8] as usize,
        total_time: Duration::from_nanos(n[9] as u64),
    })
}

/// A finding as recorded by the supervisor.
#[derive(Clone, Debug)]
struct Record {
    format: Format,
    index: u64,
    kind: String,
    detail: String,
    file: Option<PathBuf>,
}

/// Supervises workers over `start..end` of `format`, restarting after a
/// worker death or stall.
fn supervise(args: &Args, format: Format, start: u64, end: u64, records: &Mutex<Vec<Record>>) -> Stats {
    let campaign = Campaign::new(format, args.seed);
    let exe = std::env::current_exe().expect("current exe");
    let mut total = Stats::default();
    let mut cur = start;
    let progress = std::env::temp_dir().join(format!(
        "strata-fuzz-{}-{}-{start}.progress",
        std::process::id(),
        format.name()
    ));
    while cur < end {
        std::fs::write(&progress, cur.to_le_bytes()).expect("progress file");
        let mut child = Command::new(&exe)
            .args(["--worker", "--format", format.name()])
            .args(["--seed", &args.seed.to_string()])
            .args(["--worker-start", &cur.to_string(), "--worker-end", &end.to_string()])
            .arg("--worker-progress")
            .arg(&progress)
            .args(["--max-ms", &args.limits.max_time.as_millis().to_string()])
            .args(["--max-alloc-mib", &(args.limits.max_alloc >> 20).to_string()])
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .expect("spawn worker");
        let stdout = child.stdout.take().expect("worker stdout");
        let last_stats: Arc<Mutex<Option<Stats>>> = Arc::new(Mutex::new(None));
        let found: Arc<Mutex<Vec<(u64, String, String)>>> = Arc::new(Mutex::new(Vec::new()));
        let reader = {
            let (last_stats, found) = (last_stats.clone(), found.clone());
            std::thread::spawn(move || {
                for line in BufReader::new(stdout).lines().map_while(Result::ok) {
                    let w: Vec<&str> = line.splitn(4, ' ').collect();
                    match w.first().copied() {
                        Some("STATS") => {
                            let words: Vec<&str> = line.split(' ').skip(2).collect();
                            if let Some(s) = parse_stats(&words) {
                                *last_stats.lock().unwrap() = Some(s);
                            }
                        }
                        Some("FINDING") if w.len() == 4 => {
                            let detail: String = serde_json::from_str(w[3]).unwrap_or_else(|_| w[3].to_string());
                            found
                                .lock()
                                .unwrap()
                                .push((w[1].parse().unwrap_or(0), w[2].to_string(), detail));
                        }
                        _ => {}
                    }
                }
            })
        };
        let read_progress = || {
            let mut b = [0u8; 8];
            std::fs::File::open(&progress)
                .and_then(|f| f.read_exact_at(&mut b, 0))
                .map(|_| u64::from_le_bytes(b))
                .unwrap_or(cur)
        };
        let mut last = (read_progress(), Instant::now());
        let status = loop {
            if let Some(st) = child.try_wait().expect("wait worker") {
                break Some(st);
            }
            std::thread::sleep(Duration::from_millis(50));
            let p = read_progress();
            if p != last.0 {
                last = (p, Instant::now());
            } else if last.1.elapsed() > args.stall {
                let _ = child.kill();
                let _ = child.wait();
                break None;
            }
        };
        let _ = reader.join();
        let stats = last_stats.lock().unwrap().clone().unwrap_or_default();
        let mut findings = found.lock().unwrap().clone();
        let done_ok = matches!(status, Some(s) if s.success());
        let mut next = end;
        if !done_ok {
            let p = read_progress();
            let (kind, detail) = match status {
                Some(s) => ("abort", format!("worker died ({s}) on this input")),
                None => ("hang", format!("no progress for {} s: killed", args.stall.as_secs())),
            };
            findings.push((p, kind.to_string(), detail));
            // Inputs after the last stats line but before `p` finished without findings
            // being lost (findings are flushed at once); count them as run.
            let mut s = stats.clone();
            let counted = s.inputs;
            let ran = p - cur;
            s.inputs = ran + 1;
            s.err += ran.saturating_sub(counted);
            s.abort = 1;
            total.merge(&s);
            next = p + 1;
        } else {
            total.merge(&stats);
        }
        for (index, kind, detail) in findings {
            let input = campaign.input(index);
            let verdict = Verdict::Invariant(kind.clone()); // for the file name only
            let f = Finding {
                format,
                index,
                verdict: match kind.as_str() {
                    "crash" => Verdict::Crash(detail.clone()),
                    "hang" => Verdict::Hang(Duration::ZERO),
                    "alloc" => Verdict::Alloc(0),
                    _ => verdict,
                },
                input,
            };
            let file = save_finding(&args.corpus, &f).ok().map(|p| {
                if kind == "abort" {
                    let q = p.with_file_name(format!("abort-{index}.{}", format.ext()));
                    let _ = std::fs::rename(&p, &q);
                    q
                } else {
                    p
                }
            });
            if !args.json {
                eprintln!(
                    "finding: {} #{index} {kind}: {detail} ({})",
                    format.name(),
                    file.as_ref().map(|p| p.display().to_string()).unwrap_or_default()
                );
            }
            records.lock().unwrap().push(Record {
                format,
                index,
                kind,
                detail,
                file,
            });
        }
        cur = next;
    }
    let _ = std::fs::remove_file(&progress);
    total
}

fn campaign(args: &Args) -> i32 {
    let t0 = Instant::now();
    let records = Mutex::new(Vec::new());
    let mut per_format = Vec::new();
    for &format in &args.formats {
        let tf = Instant::now();
        let (_, notes) = strata_fuzz::seeds::seeds(format);
        notes.iter().for_each(|n| eprintln!("{}: {n}", format.name()));
        let (start, end) = (args.start, args.start + args.inputs);
        let stats = if args.no_fork {
            let mut c = Campaign::new(format, args.seed);
            c.limits = args.limits;
            c.run(
                start..end,
                |_| {},
                |f| {
                    let file = save_finding(&args.corpus, &f).ok();
                    if !args.json {
                        eprintln!(
                            "finding: {} #{} {}: {}",
                            format.name(),
                            f.index,
                            f.verdict.kind(),
                            f.verdict.detail()
                        );
                    }
                    records.lock().unwrap().push(Record {
                        format,
                        index: f.index,
                        kind: f.verdict.kind().into(),
                        detail: f.verdict.detail(),
                        file,
                    });
                },
            )
        } else {
            let w = args.workers.min(args.inputs.max(1));
            let per = args.inputs.div_ceil(w);
            let mut total = Stats::default();
            std::thread::scope(|s| {
                let hs: Vec<_> = (0..w)
                    .map(|k| {
                        let (a, b) = (start + k * per, (start + (k + 1) * per).min(end));
                        let records = &records;
                        s.spawn(move || supervise(args, format, a, b, records))
                    })
                    .collect();
                for h in hs {
                    total.merge(&h.join().expect("supervisor"));
                }
            });
            total
        };
        let wall = tf.elapsed();
        if !args.json {
            println!(
                "{:7} {:>9} inputs  ok {:>8}  err {:>8}  findings {:>4}  max {:>8.2} ms  peak {:>7.1} MiB  wall {:>7.1} s",
                format.name(),
                stats.inputs,
                stats.ok,
                stats.err,
                stats.findings(),
                stats.max_time.as_secs_f64() * 1e3,
                stats.max_peak_bytes as f64 / (1 << 20) as f64,
                wall.as_secs_f64()
            );
        }
        per_format.push((format, stats, wall));
    }
    let records = records.into_inner().unwrap();
    let total_inputs: u64 = per_format.iter().map(|(_, s, _)| s.inputs).sum();
    let total_findings: u64 = per_format.iter().map(|(_, s, _)| s.findings()).sum();
    if args.json {
        let formats: serde_json::Map<String, serde_json::Value> = per_format
            .iter()
            .map(|(f, s, w)| {
                let mut j = s.json();
                j["wall_s"] = serde_json::json!(w.as_secs_f64());
                (f.name().to_string(), j)
            })
            .collect();
        let findings: Vec<serde_json::Value> = records
            .iter()
            .map(|r| {
                serde_json::json!({"format": r.format.name(), "index": r.index, "kind": r.kind, "detail": r.detail,
                    "file": r.file.as_ref().map(|p| p.display().to_string())})
            })
            .collect();
        let j = serde_json::json!({
            "seed": args.seed, "start": args.start, "inputs_per_format": args.inputs, "workers": args.workers,
            "max_ms": args.limits.max_time.as_millis() as u64, "max_alloc_mib": args.limits.max_alloc >> 20,
            "alloc_counting": alloc::installed(),
            "total_inputs": total_inputs, "total_findings": total_findings, "wall_s": t0.elapsed().as_secs_f64(),
            "formats": formats, "findings": findings,
        });
        println!("{}", serde_json::to_string_pretty(&j).unwrap());
    } else {
        println!(
            "total   {total_inputs:>9} inputs  findings {total_findings}  wall {:.1} s",
            t0.elapsed().as_secs_f64()
        );
    }
    if total_findings > 0 {
        1
    } else {
        0
    }
}

fn replay(args: &Args, file: &Path) -> i32 {
    let format = args.formats[0];
    let input = match std::fs::read(file) {
        Ok(b) => b,
        Err(e) => {
            eprintln!("{}: {e}", file.display());
            return 2;
        }
    };
    let target = Target::new();
    let o = run_input(&target, format, &input, &args.limits);
    println!(
        "{}: {} ({:.3} ms, peak {:.1} MiB): {}",
        file.display(),
        o.verdict.kind(),
        o.elapsed.as_secs_f64() * 1e3,
        o.peak_bytes as f64 / (1 << 20) as f64,
        o.verdict.detail()
    );
    if args.minimise && o.verdict.is_finding() {
        let kind = o.verdict.kind();
        let small = minimise(
            input,
            |c| run_input(&target, format, c, &args.limits).verdict.kind() == kind,
            20_000,
        );
        let out = file.with_extension(format!("min.{}", format.ext()));
        std::fs::write(&out, &small).expect("write minimised input");
        println!("minimised to {} bytes: {}", small.len(), out.display());
    }
    if o.verdict.is_finding() {
        1
    } else {
        0
    }
}
