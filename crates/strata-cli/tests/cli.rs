//! End-to-end tests of the `strata` binary: exit codes, one-line errors that
//! name the bad flag or file, the no-overwrite rule, and real outputs (on
//! lavapipe when no GPU is present).

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn strata(args: &[&str]) -> Output {
    strata_cmd(args).output().expect("failed to start strata")
}

/// `strata ARGS` with `$STRATA_CACHE` = `cache` (probe bakes and references land there).
fn strata_cached(args: &[&str], cache: &Path) -> Output {
    strata_cmd(args)
        .env("STRATA_CACHE", cache)
        .output()
        .expect("failed to start strata")
}

fn strata_cmd(args: &[&str]) -> Command {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_strata"));
    cmd.args(args);
    if std::env::var_os("XDG_RUNTIME_DIR").is_none() {
        let dir = std::env::temp_dir().join("strata-xdg-cli-tests");
        std::fs::create_dir_all(&dir).unwrap();
        cmd.env("XDG_RUNTIME_DIR", dir);
    }
    cmd
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// The one JSON object a successful run printed.
fn json_of(o: &Output) -> serde_json::Value {
    assert!(o.status.success(), "{}", stderr(o));
    serde_json::from_str(stdout(o).trim()).expect("one JSON object on stdout")
}

/// The flag warnings (`strata: warning: --…`) of a successful run, one per line.
fn flag_warnings(o: &Output) -> Vec<String> {
    assert!(o.status.success(), "{}", stderr(o));
    stderr(o)
        .lines()
        .filter(|l| l.starts_with("strata: warning: --"))
        .map(String::from)
        .collect()
}

/// Pass names of a `bench` JSON object.
fn pass_names(v: &serde_json::Value) -> Vec<&str> {
    v["passes"]
        .as_array()
        .expect("passes")
        .iter()
        .map(|p| p["name"].as_str().unwrap())
        .collect()
}

fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("cli");
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join(name);
    let _ = std::fs::remove_file(&p);
    p
}

/// A failing run: exit code ≠ 0 and exactly one line on stderr that contains
/// every one of `needles`.
fn assert_one_line_error(o: &Output, needles: &[&str]) {
    assert!(
        !o.status.success(),
        "expected failure, got success; stderr: {}",
        stderr(o)
    );
    let err = stderr(o);
    let lines: Vec<&str> = err.lines().filter(|l| !l.trim().is_empty()).collect();
    assert_eq!(lines.len(), 1, "expected a one-line error, got:\n{err}");
    for n in needles {
        assert!(lines[0].contains(n), "error line {:?} does not mention {n:?}", lines[0]);
    }
}

#[test]
fn out_of_range_width_names_flag_and_range() {
    let out = scratch("tiny.png");
    let o = strata(&[
        "render",
        "--scene",
        "plane",
        "--width",
        "4",
        "--height",
        "64",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_one_line_error(&o, &["--width", "8"]);
    assert!(!out.exists());
}

/// Flags the chosen technique does not read are named in a one-line warning, not ignored in
/// silence (the CLI sweep of 2026-11-29 found `render` accepting them without a word); the
/// frame still renders, as the command `strata view` prints for it must. The same flags
/// with a technique that reads them give no warning.
#[test]
fn render_warns_of_flags_its_technique_does_not_read() {
    let out = scratch("unread.png");
    let o = out.to_str().unwrap();
    let base = [
        "render", "--scene", "plane", "--width", "32", "--height", "18", "--out", o, "--force",
    ];
    let warnings = |extra: &[&str]| {
        let args: Vec<&str> = base.iter().chain(extra).copied().collect();
        let r = strata(&args);
        assert!(r.status.success(), "{extra:?}: {}", stderr(&r));
        assert!(out.exists(), "{extra:?} wrote no image");
        stderr(&r)
            .lines()
            .filter(|l| l.contains("warning"))
            .map(str::to_string)
            .collect::<Vec<_>>()
    };
    for (extra, needles) in [
        (
            &["--technique", "direct", "--samples", "5"][..],
            &["--samples", "direct", "AO"][..],
        ),
        (
            &["--technique", "ao", "--indirect-samples", "5"][..],
            &["--indirect-samples", "ao", "radiosity"][..],
        ),
        (
            &["--technique", "direct", "--no-probes"][..],
            &["--no-probes", "direct"][..],
        ),
        (
            &["--technique", "ao", "--variant", "peel"][..],
            &["--variant", "ao"][..],
        ),
        (
            &["--technique", "ao", "--layer-scale", "2"][..],
            &["--layer-scale", "second"][..],
        ),
        (
            &["--technique", "ils", "--layers", "2"][..],
            &["--layers", "ils", "second"][..],
        ),
    ] {
        let w = warnings(extra);
        assert_eq!(w.len(), 1, "{extra:?}: {w:?}");
        for n in needles {
            assert!(w[0].contains(n), "{:?} does not mention {n:?}", w[0]);
        }
    }
    let w = warnings(&[
        "--technique",
        "ao",
        "--samples",
        "5",
        "--layers",
        "2",
        "--variant",
        "peel",
        "--layer-scale",
        "2",
    ]);
    assert!(w.is_empty(), "{w:?}");
}

/// clap's own errors keep, on their one line, the flags they miss and the values they accept;
/// a folder where the output file goes is refused before anything is rendered.
#[test]
fn argument_errors_name_flags_values_and_folders_on_one_line() {
    let o = strata(&["reference", "--scene", "plane"]);
    assert_one_line_error(&o, &["--kind", "--out"]);
    let o = strata(&["reference", "--scene", "plane", "--kind", "foo", "--out", "x.exr"]);
    assert_one_line_error(&o, &["--kind", "obscurance"]);
    let o = strata(&[
        "reference",
        "--scene",
        "plane",
        "--kind",
        "ao",
        "--spp",
        "99999999999",
        "--out",
        "x.exr",
    ]);
    assert_one_line_error(&o, &["--spp", "1..=65536"]);
    let o = strata(&["render", "--scene", "plane", "--layers", "2", "--layer-scale", "5"]);
    assert_one_line_error(&o, &["--layer-scale", "1..=4"]);
    let dir = scratch("a-folder.png");
    std::fs::create_dir_all(&dir).unwrap();
    let o = strata(&[
        "render",
        "--scene",
        "plane",
        "--width",
        "32",
        "--height",
        "18",
        "--out",
        dir.to_str().unwrap(),
        "--force",
    ]);
    assert_one_line_error(&o, &["--out", "folder"]);
    assert!(dir.is_dir());
}

#[test]
fn out_of_range_fov_names_flag_and_range() {
    let out = scratch("fov.png");
    let o = strata(&[
        "render",
        "--scene",
        "plane",
        "--fov",
        "190",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_one_line_error(&o, &["fov", "180"]);
}

#[test]
fn unknown_scene_lists_valid_names() {
    let out = scratch("unknown.png");
    let o = strata(&["render", "--scene", "no-such-scene", "--out", out.to_str().unwrap()]);
    assert_one_line_error(&o, &["no-such-scene", "cornell", "atrium"]);
}

#[test]
fn malformed_toml_scene_names_the_file() {
    let bad = scratch("bad_scene.toml");
    std::fs::write(&bad, "[camera\neye = [0, 1, 2]\n").unwrap();
    let out = scratch("bad_scene.png");
    let o = strata(&[
        "render",
        "--scene",
        bad.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_one_line_error(&o, &["bad_scene.toml"]);
    assert!(!out.exists());
}

#[test]
fn unsupported_output_extension_is_refused() {
    let out = scratch("image.bmp");
    let o = strata(&[
        "render",
        "--scene",
        "plane",
        "--width",
        "16",
        "--height",
        "16",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_one_line_error(&o, &["--out"]);
    assert!(!out.exists());
}

#[test]
fn existing_output_is_not_overwritten_without_force() {
    let out = scratch("keep.png");
    std::fs::write(&out, b"precious").unwrap();
    let o = strata(&[
        "render",
        "--scene",
        "plane",
        "--width",
        "16",
        "--height",
        "16",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_one_line_error(&o, &["keep.png", "--force"]);
    assert_eq!(std::fs::read(&out).unwrap(), b"precious");

    let o = strata(&[
        "render",
        "--scene",
        "plane",
        "--width",
        "16",
        "--height",
        "16",
        "--force",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_ne!(std::fs::read(&out).unwrap(), b"precious");
}

#[test]
fn info_lists_multiview_and_timestamps_present() {
    let o = strata(&["info"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = stdout(&o);
    for feature in ["MULTIVIEW", "TIMESTAMP_QUERY"] {
        let line = text
            .lines()
            .find(|l| l.split_whitespace().next() == Some(feature))
            .unwrap_or_else(|| panic!("{feature} missing from strata info:\n{text}"));
        assert_eq!(
            line.split_whitespace().nth(1),
            Some("yes"),
            "{feature} not present: {line}"
        );
    }
    // the storage formats of the compute passes: WebGPU guarantees RGBA16F and R32F
    let v = json_of(&strata(&["info", "--json"]));
    for format in ["Rgba16Float", "R32Float"] {
        assert_eq!(v["storage_formats"][format], true, "{v}");
    }
}

#[test]
fn render_atrium_writes_a_non_uniform_png() {
    let out = scratch("atrium.png");
    let o = strata(&[
        "render",
        "--scene",
        "atrium",
        "--width",
        "160",
        "--height",
        "90",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let img = image::open(&out).unwrap().to_rgb8();
    assert_eq!(img.dimensions(), (160, 90));
    let lum: Vec<f32> = img
        .pixels()
        .map(|p| p.0.iter().map(|&c| c as f32).sum::<f32>() / 3.0)
        .collect();
    let mean = lum.iter().sum::<f32>() / lum.len() as f32;
    let sd = (lum.iter().map(|l| (l - mean) * (l - mean)).sum::<f32>() / lum.len() as f32).sqrt();
    assert!(
        mean > 20.0 && mean < 235.0,
        "mean grey {mean}: image is nearly black or white"
    );
    assert!(sd > 15.0, "standard deviation {sd}: image is nearly uniform");
}

#[test]
fn reference_ao_of_cornell_is_a_visibility_image() {
    let out = scratch("cornell_ao.exr");
    let o = strata(&[
        "reference",
        "--scene",
        "cornell",
        "--kind",
        "ao",
        "--spp",
        "16",
        "--width",
        "24",
        "--height",
        "24",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let img = image::open(&out).unwrap().to_rgb32f();
    let v: Vec<f32> = img.pixels().map(|p| p.0[0]).collect();
    assert!(
        v.iter().all(|&a| (0.0..=1.0).contains(&a)),
        "ambient visibility outside [0, 1]"
    );
    // The box has corners and two blocks: some pixels are occluded, some open.
    assert!(v.iter().any(|&a| a < 0.8) && v.iter().any(|&a| a > 0.95));
}

#[test]
fn reference_ao_png_holds_raw_visibility_like_render_ao() {
    // `render --technique ao` writes byte = 255·AV; the reference's AO PNGs must
    // be the same encoding (not sRGB) for the two to compare
    for kind in ["ao", "obscurance", "ao-opacity"] {
        let (png, exr) = (scratch(&format!("raw-{kind}.png")), scratch(&format!("raw-{kind}.exr")));
        for out in [&png, &exr] {
            let o = strata(&[
                "reference",
                "--scene",
                "cornell",
                "--kind",
                kind,
                "--spp",
                "8",
                "--width",
                "16",
                "--height",
                "16",
                "--quiet",
                "--force",
                "--out",
                out.to_str().unwrap(),
            ]);
            assert!(o.status.success(), "{}", stderr(&o));
        }
        let bytes = image::open(&png).unwrap().to_luma8();
        let av = image::open(&exr).unwrap().to_rgb32f();
        let mut mid = 0;
        for (b, a) in bytes.pixels().zip(av.pixels()) {
            let want = (a.0[0].clamp(0.0, 1.0) * 255.0).round();
            assert!(
                (b.0[0] as f32 - want).abs() <= 1.0,
                "{kind}: byte {} vs 255·AV {want}",
                b.0[0]
            );
            mid += (want > 20.0 && want < 200.0) as u32;
        }
        assert!(
            mid > 0,
            "{kind}: some pixels are partly occluded (sRGB would move them)"
        );
    }
}

#[test]
fn bench_gbuffer_json_has_per_pass_times() {
    let o = strata(&[
        "bench", "gbuffer", "--scene", "plane", "--width", "32", "--height", "32", "--frames", "2", "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_str(stdout(&o).trim()).expect("bench output is not JSON");
    let passes = v["passes"].as_array().expect("passes array");
    let names: Vec<&str> = passes.iter().filter_map(|p| p["name"].as_str()).collect();
    assert!(names.contains(&"gbuffer") && names.contains(&"lighting"), "{names:?}");
    for p in passes {
        let (med, min) = (p["median_ms"].as_f64().unwrap(), p["min_ms"].as_f64().unwrap());
        assert!(med > 0.0 && min > 0.0 && min <= med, "bad timing {p}");
    }
}

/// `bench display` times both ways of getting the frame onto a window, for a technique's own
/// display target, and names a bad technique in one line.
#[test]
fn bench_display_json_times_both_paths() {
    for (technique, target) in [("direct", "ldr"), ("ao", "ao")] {
        let o = strata(&[
            "bench",
            "display",
            "--scene",
            "cornell",
            "--technique",
            technique,
            "--width",
            "48",
            "--height",
            "32",
            "--frames",
            "2",
            "--json",
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        let v: serde_json::Value = serde_json::from_str(stdout(&o).trim()).expect("bench output is not JSON");
        assert_eq!(v["bench"], "display");
        assert_eq!(v["target"], target);
        assert_eq!((v["width"].as_u64(), v["frames"].as_u64()), (Some(48), Some(2)));
        for k in ["readback", "gpu"] {
            let (med, min) = (
                v[format!("{k}_median_ms")].as_f64().unwrap(),
                v[format!("{k}_min_ms")].as_f64().unwrap(),
            );
            assert!(med > 0.0 && min > 0.0 && min <= med, "{technique}: bad {k} timing {v}");
        }
        let ratio = v["readback_median_ms"].as_f64().unwrap() / v["gpu_median_ms"].as_f64().unwrap();
        assert!((v["speedup"].as_f64().unwrap() - ratio).abs() < 1e-9, "{v}");
    }
    let o = strata(&["bench", "display", "--technique", "nope"]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("nope"), "{}", stderr(&o));
}

#[test]
fn render_ao_writes_visibility_in_unit_range_darker_in_corners() {
    let out = scratch("ao-cornell.exr");
    let o = strata(&[
        "render",
        "--scene",
        "cornell",
        "--technique",
        "ao",
        "--layers",
        "2",
        "--width",
        "64",
        "--height",
        "64",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let img = strata_scene::ImageBuf::load(&out).unwrap();
    let av: Vec<f32> = img.data.chunks_exact(4).map(|p| p[0]).collect();
    assert!(av.iter().all(|v| (0.0..=1.0).contains(v)), "AV outside [0, 1]");
    let min = av.iter().cloned().fold(1.0f32, f32::min);
    let max = av.iter().cloned().fold(0.0f32, f32::max);
    assert!(max > 0.95 && min < 0.6, "AV range {min}..{max} is not an AO image");
}

/// `render` without `--warmup` warms a frame that builds up over frames (AO's temporal
/// filter) up by `ACCUMULATION_WARMUP` frames, and a frame that does not (direct light) by
/// none; the warmed-up AO is closer to the ray-traced obscurance than the first frame after a
/// cut (issue 14: the demo's single-frame `atrium-ao.png` showed one frame's sampling pattern).
#[test]
fn render_warms_up_accumulating_frames_by_default() {
    let render = |technique: &str, warmup: Option<&str>, name: &str| -> strata_scene::ImageBuf {
        let out = scratch(name);
        let mut args = vec![
            "render",
            "--scene",
            "cornell",
            "--technique",
            technique,
            "--layers",
            "2",
            "--width",
            "96",
            "--height",
            "96",
            "--force",
            "--out",
        ];
        args.push(out.to_str().unwrap());
        if let Some(w) = warmup {
            args.extend(["--warmup", w]);
        }
        let o = strata(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        strata_scene::ImageBuf::load(&out).unwrap()
    };
    let auto = render("ao", None, "warmup-auto.exr");
    let eight = render(
        "ao",
        Some(&strata_render::ACCUMULATION_WARMUP.to_string()),
        "warmup-8.exr",
    );
    let first = render("ao", Some("0"), "warmup-0.exr");
    assert_eq!(auto.data, eight.data, "the default is ACCUMULATION_WARMUP frames");
    assert_ne!(auto.data, first.data, "AO accumulates: the warm-up changes the frame");
    assert_eq!(
        render("direct", None, "warmup-direct-auto.exr").data,
        render("direct", Some("0"), "warmup-direct-0.exr").data,
        "direct light does not accumulate: no warm-up by default"
    );
    let reference = scratch("warmup-obscurance.exr");
    let o = strata(&[
        "reference",
        "--scene",
        "cornell",
        "--kind",
        "obscurance",
        "--spp",
        "512",
        "--width",
        "96",
        "--height",
        "96",
        "--quiet",
        "--out",
        reference.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let reference = strata_scene::ImageBuf::load(&reference).unwrap();
    let rmse = |img: &strata_scene::ImageBuf| {
        let sq: f64 = (img.data.chunks_exact(img.channels as usize))
            .zip(reference.data.chunks_exact(reference.channels as usize))
            .map(|(a, b)| (a[0] as f64 - b[0] as f64).powi(2))
            .sum();
        (sq / (96.0 * 96.0)).sqrt()
    };
    let (warm, cut) = (rmse(&auto), rmse(&first));
    eprintln!("AV RMSE vs the 512-spp obscurance: default {warm:.5}, --warmup 0 {cut:.5}");
    assert!(
        warm < cut,
        "the warmed-up AO ({warm}) is no closer to the reference than the first frame ({cut})"
    );
}

#[test]
fn eval_ao_prints_errors_and_caches_the_reference() {
    let cache = scratch("ref-cache");
    let _ = std::fs::remove_dir_all(&cache);
    let report = scratch("ao-report");
    let _ = std::fs::remove_dir_all(&report);
    let args = [
        "eval",
        "--scene",
        "column-wall",
        "--technique",
        "ao",
        "--layers",
        "2",
        "--width",
        "48",
        "--height",
        "32",
        "--ref-spp",
        "16",
        "--json",
        "--quiet",
        "--frames",
        "3",
        "--cache",
        cache.to_str().unwrap(),
        "--report",
        report.to_str().unwrap(),
    ];
    let o = strata(&args);
    let v = json_of(&o);
    assert_eq!(v["technique"], "ao");
    assert_eq!(v["layers"], 2);
    assert_eq!(v["ref_spp"], 16);
    // issue 10: the reference's own noise and the speckles of both images beside the errors
    assert_eq!(v["ref_noise"]["spp"], 16);
    assert!(v["ref_noise"]["flip"].as_f64().is_some_and(|f| f > 0.0), "{v}");
    assert!(v["outliers"].as_u64().is_some() && v["binary"]["ref_outliers"].as_u64().is_some());
    // 16 spp cannot reach the default ꟻLIP 0.02 between the halves: the run says so
    assert_eq!(v["ref_noise"]["converged"], false);
    let warnings = v["warnings"].as_array().expect("warnings");
    assert!(
        warnings.iter().any(|w| w.as_str().unwrap().contains("--ref-spp cap")),
        "{warnings:?}"
    );
    for key in ["flip", "rmse", "mae", "flicker"] {
        let x = v[key].as_f64().unwrap_or_else(|| panic!("{key} missing: {v}"));
        assert!((0.0..1.0).contains(&x), "{key} = {x}");
    }
    assert!(v["rmse"].as_f64().unwrap() >= v["mae"].as_f64().unwrap());
    assert!(
        v["layers_1"]["flip"].as_f64().is_some(),
        "report run compares with 1 layer"
    );
    let html = std::fs::read_to_string(report.join("index.html")).unwrap();
    for f in ["gpu-k2.png", "gpu-k1.png", "reference-obscurance.png", "flip-k2.png"] {
        assert!(
            html.contains(f) && report.join(f).exists(),
            "{f} missing from the report"
        );
    }
    let cached = std::fs::read_dir(&cache).unwrap().count();
    assert!(cached >= 2, "references not cached ({cached} files)");
    // the second run reads the cache and gives the same reference, so the same
    // numbers; the report is not overwritten without --force
    let again = strata(&args);
    assert_one_line_error(&again, &["--report", "--force"]);
    let o2 = strata(&args[..args.len() - 2]);
    let v2: serde_json::Value = serde_json::from_str(stdout(&o2).trim()).unwrap();
    assert_eq!(v["flip"], v2["flip"]);
}

#[test]
fn eval_rejects_out_of_range_parameters() {
    let o = strata(&[
        "eval",
        "--scene",
        "plane",
        "--samples",
        "0",
        "--width",
        "16",
        "--height",
        "16",
    ]);
    assert_one_line_error(&o, &["samples", "1..=256"]);
    let o = strata(&[
        "eval", "--scene", "plane", "--alpha", "1.5", "--width", "16", "--height", "16",
    ]);
    assert_one_line_error(&o, &["alpha", "[0, 1)"]);
    let o = strata(&[
        "eval",
        "--scene",
        "plane",
        "--ref-noise",
        "1.5",
        "--width",
        "16",
        "--height",
        "16",
    ]);
    assert_one_line_error(&o, &["--ref-noise", "[0, 1)"]);
    let o = strata(&[
        "eval",
        "--scene",
        "plane",
        "--ref-spp",
        "1",
        "--width",
        "16",
        "--height",
        "16",
    ]);
    assert_one_line_error(&o, &["--ref-spp", "2..=65536"]);
}

/// `eval --layer-scale` where no compared configuration builds a second layer (one layer, ILS,
/// the OIT composite) is an error naming the flag, not a number measured without it.
#[test]
fn eval_refuses_a_layer_scale_without_a_second_layer() {
    for technique in ["ao", "gi", "ils", "oit"] {
        let o = strata(&[
            "eval",
            "--scene",
            "plane",
            "--technique",
            technique,
            "--layer-scale",
            "2",
            "--width",
            "16",
            "--height",
            "16",
        ]);
        let hint = if ["ils", "oit"].contains(&technique) {
            "must be 1"
        } else {
            "--layers 2..=4"
        };
        // `gi` is the alias of `full`, which the message names
        let name = if technique == "gi" { "full" } else { technique };
        assert_one_line_error(&o, &["--layer-scale 2", name, hint]);
    }
}

/// `bench ao` splits the first layer from the increment; the benches report the form
/// (fragment or compute) each pass with two forms ran in: AO, radiosity, lighting,
/// reflections and BZB's splats.
#[test]
fn bench_ao_splits_first_layer_and_increment() {
    let o = strata(&[
        "bench",
        "ao",
        "--scene",
        "column-wall",
        "--width",
        "64",
        "--height",
        "48",
        "--layers",
        "2",
        "--frames",
        "2",
        "--json",
    ]);
    let v = json_of(&o);
    let names = pass_names(&v);
    // the filters average the obscurance S by default; `ao-resolve` turns it into AV
    assert_eq!(
        names,
        ["depth-mip", "ao", "ao-temporal", "ao-blur-h", "ao-blur-v", "ao-resolve"]
    );
    let total = v["total_median_ms"].as_f64().unwrap();
    let (first, inc) = (v["layer1_ms"].as_f64().unwrap(), v["increment_ms"].as_f64().unwrap());
    assert!(total > 0.0 && first > 0.0);
    assert!((first + inc - total).abs() < 1e-6, "{first} + {inc} != {total}");
    // the form `ao-kernel=auto` resolved to: fragment on CPU adapters, compute on GPUs
    let cpu = v["device"].as_str().is_some_and(|d| d.contains("llvmpipe"));
    assert_eq!(v["ao_kernel"], if cpu { "fragment" } else { "compute" }, "{v}");
    assert!(v.get("indirect_kernel").is_none(), "no radiosity in bench ao: {v}");
    assert_eq!(v["ao_scale"], 1, "{v}");
    // and what --set chooses
    let bench_with = |set: &str| {
        json_of(&strata(&[
            "bench",
            "technique",
            "--technique",
            "ao",
            "--scene",
            "column-wall",
            "--width",
            "64",
            "--height",
            "48",
            "--frames",
            "1",
            "--set",
            set,
            "--json",
        ]))
    };
    assert_eq!(bench_with("ao-kernel=compute")["ao_kernel"], "compute");
    // the lighting's and the reflections' forms, in `full`
    let v = json_of(&strata(&[
        "bench",
        "technique",
        "--technique",
        "full",
        "--scene",
        "mirror",
        "--width",
        "48",
        "--height",
        "32",
        "--frames",
        "1",
        "--set",
        "lighting-kernel=compute",
        "--set",
        "reflection-kernel=compute",
        "--json",
    ]));
    assert_eq!(
        (&v["lighting_kernel"], &v["reflection_kernel"]),
        (&"compute".into(), &"compute".into()),
        "{v}"
    );
    assert_eq!(v["indirect_kernel"], if cpu { "fragment" } else { "compute" }, "{v}");
    // BZB's splats: `auto` as the other kernels, and what --set chooses
    let bzb = |set: &[&str]| {
        let mut args = vec![
            "bench",
            "technique",
            "--technique",
            "bzb-ao",
            "--scene",
            "column-wall",
            "--width",
            "32",
            "--height",
            "24",
            "--frames",
            "1",
            "--json",
        ];
        args.extend(set);
        json_of(&strata(&args))
    };
    let auto = if cpu { "fragment" } else { "compute" };
    assert_eq!(bzb(&[])["splat_kernel"], auto);
    assert_eq!(bzb(&["--set", "splat-kernel=fragment"])["splat_kernel"], "fragment");
    // the additive baseline blends in fragments whatever the kernel
    assert_eq!(
        bzb(&["--set", "visibility=off", "--set", "splat-kernel=compute"])["splat_kernel"],
        "fragment"
    );
    // a reduced AO pass: its upsampling is timed right after it, and the scale is reported
    let v = bench_with("ao-scale=2");
    assert_eq!(v["ao_scale"], 2, "{v}");
    let names = pass_names(&v);
    let at = names.iter().position(|&n| n == "ao").expect("ao timed");
    assert_eq!(names[at + 1], "ao-upsample", "{names:?}");
}

/// `--deinterleave 2x2 --filter-obscurance`: the copy, both splits, `ao-deint`,
/// the gather and `ao-resolve` replace `ao` in the timed passes; a bad pattern
/// is a one-line error naming the flag or the setting and its range.
#[test]
fn bench_ao_deinterleaved_times_split_gather_and_resolve() {
    let args = |extra: &[&'static str]| {
        let mut a: Vec<&str> = "bench ao --scene column-wall --width 64 --height 48 --layers 2 --frames 2 --json"
            .split(' ')
            .collect();
        a.extend_from_slice(extra);
        a
    };
    let v = json_of(&strata(&args(&["--deinterleave", "2x2", "--filter-obscurance"])));
    assert_eq!(
        pass_names(&v),
        [
            "depth-mip",
            "ao-deint-copy",
            "ao-deint-split-z",
            "ao-deint-split-n",
            "ao-deint",
            "ao-deint-gather",
            "ao-temporal",
            "ao-blur-h",
            "ao-blur-v",
            "ao-resolve"
        ]
    );
    assert_eq!(v["deinterleave"], "2x2");
    assert_eq!(v["filter_obscurance"], true);
    let bad = strata(&args(&["--deinterleave", "5x5"]));
    assert_one_line_error(&bad, &["deinterleave", "5x5", "1..=4"]);
    assert_one_line_error(&strata(&args(&["--deinterleave", "2by2"])), &["deinterleave", "2by2"]);
}

#[test]
fn render_full_is_brighter_than_direct_in_shadow_and_lists_its_passes() {
    let cache = scratch("probe-cache");
    let _ = std::fs::remove_dir_all(&cache);
    let run = |technique: &str, out: &Path| {
        strata_cached(
            &[
                "render",
                "--scene",
                "mirror",
                "--technique",
                technique,
                "--layers",
                "2",
                "--width",
                "64",
                "--height",
                "48",
                "--warmup",
                "2",
                "--force",
                "--out",
                out.to_str().unwrap(),
            ],
            &cache,
        )
    };
    let (direct, full) = (scratch("mirror-direct.exr"), scratch("mirror-full.exr"));
    let o = run("direct", &direct);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = run("full", &full);
    assert!(o.status.success(), "{}", stderr(&o));
    let (d, f) = (
        strata_scene::ImageBuf::load(&direct).unwrap(),
        strata_scene::ImageBuf::load(&full).unwrap(),
    );
    let sum = |img: &strata_scene::ImageBuf| img.data.chunks_exact(4).map(|p| p[0] + p[1] + p[2]).sum::<f32>();
    assert!(
        sum(&f) > 1.05 * sum(&d),
        "indirect light, probes and reflections add light"
    );
    assert!(
        std::fs::read_dir(&cache).unwrap().count() >= 1,
        "the probes were not cached"
    );
    let o = strata(&[
        "render",
        "--scene",
        "mirror",
        "--technique",
        "full",
        "--layers",
        "2",
        "--list-passes",
    ]);
    let text = stdout(&o);
    for p in [
        "depth-mip",
        "ao",
        "propagate",
        "radiosity",
        "compose",
        "reflections",
        "tonemap",
    ] {
        assert!(text.contains(&format!("  {p} ")), "pass {p} missing:\n{text}");
    }
}

#[test]
fn unknown_preset_lists_the_valid_ones() {
    let o = strata(&[
        "render",
        "--scene",
        "plane",
        "--technique",
        "full",
        "--preset",
        "ultra",
        "--out",
        "x.png",
    ]);
    assert_one_line_error(&o, &["--preset", "high-performance, balanced, high-quality"]);
    // a technique without presets refuses one instead of ignoring it
    for cmd in [&["render", "--out", "x.png"][..], &["eval"][..]] {
        let mut a = cmd.to_vec();
        a.extend(["--scene", "plane", "--technique", "ao", "--preset", "balanced"]);
        let o = strata(&a);
        assert_one_line_error(&o, &["--preset", "technique 'ao' has no presets"]);
    }
}

/// `eval --technique full --views` (issue 14): what `render --technique full` shows, measured —
/// the final image and the Fig. 9 views' clipping, |blended − probe-only|, the frame's ꟻLIP
/// against the path tracer and the regions' chroma; and its settings' one-line errors.
#[test]
fn eval_full_views_reports_clipping_blend_and_region_chroma() {
    let cache = scratch("views-cache");
    let _ = std::fs::remove_dir_all(&cache);
    let args = vec![
        "eval",
        "--scene",
        "mirror",
        "--technique",
        "full",
        "--views",
        "--layers",
        "2",
        "--width",
        "48",
        "--height",
        "32",
        "--ref-spp",
        "4",
        "--warmup",
        "2",
        "--json",
        "--quiet",
        "--cache",
        cache.to_str().unwrap(),
    ];
    let v = json_of(&strata(&args));
    let views = v["views"].as_array().expect("views");
    let names: Vec<&str> = views.iter().map(|x| x["view"].as_str().unwrap()).collect();
    assert_eq!(
        names,
        ["final", "probe-only", "blended", "gbuffer-only", "final-specular"]
    );
    // the frame compared with the (Lambertian) path tracer has no GGX lobe; the frame as
    // `render` shows it adds that lobe's light and nothing else
    let mean = |i: usize| views[i]["mean"].as_f64().unwrap();
    assert!(
        mean(0) <= mean(4) + 1e-9,
        "final {} > final-specular {}",
        mean(0),
        mean(4)
    );
    for x in views {
        let c = x["clip_fraction"].as_f64().unwrap();
        assert!((0.0..=0.01).contains(&c), "{}: {c} of the pixels clipped", x["view"]);
    }
    for key in [
        "flip_blended",
        "flip_probe_only",
        "flip_gbuffer_only",
        "blended_vs_probe_only",
        "mean_confidence",
    ] {
        assert!(v[key].as_f64().is_some_and(|x| x >= 0.0), "{key}: {v}");
    }
    let regions = v["regions"].as_array().expect("regions");
    assert_eq!(regions.len(), 3);
    for r in regions {
        assert!(r["chroma_reference"].as_f64().is_some_and(|x| x >= 0.0), "{r}");
    }
    assert!(v.get("probes_from").is_none(), "{v}");
    // probes baked from another scene (stale probes): read, and said in the JSON; the same
    // scene by name gives the same bake, so the same numbers; another scene's probes change
    // the probe-only composite
    let mut named = args.clone();
    named.extend(["--probes-from", "mirror"]);
    let same = json_of(&strata(&named));
    assert_eq!(same["probes_from"], "mirror");
    assert_eq!(same["flip_blended"], v["flip_blended"]);
    let mut other = args.clone();
    other.extend(["--probes-from", "plane"]);
    let stale = json_of(&strata(&other));
    assert_ne!(stale["flip_probe_only"], v["flip_probe_only"], "{stale}");
    let mut bad = args.clone();
    bad.extend(["--probes-from", "no-such-scene"]);
    assert_one_line_error(&strata(&bad), &["--probes-from", "no-such-scene"]);
    let o = strata(&["eval", "--scene", "plane", "--technique", "ao", "--views"]);
    assert_one_line_error(&o, &["--views", "full"]);
    let o = strata(&[
        "eval",
        "--scene",
        "plane",
        "--technique",
        "full",
        "--views",
        "--set",
        "coverage-confidence=2",
    ]);
    assert_one_line_error(&o, &["coverage-confidence", "0..=1"]);
}

/// Issue 14's radiosity switches reject unknown values with one line naming the flag and the choices.
#[test]
fn radiosity_estimator_switches_are_range_checked() {
    for (flag, value, choices) in [
        ("--indirect-weights", "uniform", "paper or solid-angle"),
        ("--indirect-temporal-noise", "sometimes", "on or off"),
    ] {
        let o = strata(&["eval", "--scene", "cornell", "--technique", "gi", flag, value, "--json"]);
        assert_one_line_error(&o, &[flag, choices]);
    }
}

/// `eval --technique gi` runs no AO: an AO setting (or how AO darkens the probes) given with
/// `--set` is an error naming it, not a number measured without it.
#[test]
fn eval_gi_refuses_ao_settings_it_would_ignore() {
    for set in ["samples=5", "blur-distance=0", "probe-ao=1"] {
        let o = strata(&[
            "eval",
            "--scene",
            "cornell",
            "--technique",
            "gi",
            "--set",
            set,
            "--json",
        ]);
        let name = set.split('=').next().unwrap();
        assert_one_line_error(&o, &[name, "without AO", "--views"]);
    }
    // the AO flags themselves: a one-line warning each, and the comparison runs; the
    // radiosity flags given to the AO comparison likewise
    for (technique, flags, warned_flag) in [
        ("gi", &["--samples", "5"][..], "--samples"),
        (
            "ao",
            &["--indirect-samples", "5", "--bounces", "2"][..],
            "--indirect-samples",
        ),
    ] {
        let mut args = vec![
            "eval",
            "--scene",
            "cornell",
            "--technique",
            technique,
            "--width",
            "16",
            "--height",
            "16",
            "--ref-spp",
            "4",
            "--quiet",
            "--no-cache",
        ];
        args.extend_from_slice(flags);
        let o = strata(&args);
        let warned = flag_warnings(&o);
        assert_eq!(warned.len(), flags.len() / 2, "{technique}: {warned:?}");
        assert!(
            warned
                .iter()
                .any(|l| l.contains(warned_flag) && l.contains("not read by eval")),
            "{technique}: {warned:?}"
        );
    }
}

/// `eval --technique gi` blends with light probes by default (what `render --technique full`
/// shows) and evaluates the screen-space radiosity alone with `--no-probes`; both report the
/// indirect and full errors; `--set` reaches the radiosity's registry settings.
#[test]
fn eval_gi_reports_indirect_and_full_errors() {
    let cache = scratch("gi-cache");
    let _ = std::fs::remove_dir_all(&cache);
    let gi = |extra: &[&str]| {
        let mut args = vec![
            "eval",
            "--scene",
            "cornell",
            "--technique",
            "gi",
            "--layers",
            "2",
            "--width",
            "32",
            "--height",
            "32",
            "--ref-spp",
            "4",
            "--bounces",
            "2",
            "--warmup",
            "2",
            "--json",
            "--quiet",
            "--cache",
            cache.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        strata(&args)
    };
    let run = |extra: &[&str]| json_of(&gi(extra));
    let blended = run(&[]);
    let alone = run(&["--no-probes", "--set", "hidden-taps=black"]);
    for v in [&blended, &alone] {
        assert_eq!(v["technique"], "gi");
        for key in ["flip", "rmse", "mae"] {
            assert!(v[key].as_f64().is_some_and(|x| x >= 0.0), "{key}: {v}");
            assert!(v["full"][key].as_f64().is_some_and(|x| x >= 0.0), "full.{key}: {v}");
        }
        assert_eq!(v["ref_spp"], 4);
    }
    assert_eq!(blended["probes"], true);
    assert_eq!(alone["probes"], false);
    assert_ne!(blended["rmse"], alone["rmse"], "the probes change the indirect light");
    // probes baked from a named scene: the same scene gives the same (cached) probes and
    // the same errors; an unknown scene is a one-line error naming the flag
    let same = run(&["--probes-from", "cornell"]);
    assert_eq!(same["probes_from"], "cornell");
    assert_eq!(same["rmse"], blended["rmse"]);
    assert!(blended.get("probes_from").is_none(), "{blended}");
    // --moving warms up along the camera path; Cornell has none, so it is the still warm-up
    let moving = run(&["--moving"]);
    assert_eq!(moving["moving"], true);
    assert_eq!(moving["rmse"], blended["rmse"]);
    assert!(blended.get("moving").is_none(), "{blended}");
    let o = gi(&["--probes-from", "no-such-scene"]);
    assert_one_line_error(&o, &["--probes-from", "no-such-scene"]);
    // --moving is read by the deep-G-buffer AO too: Cornell stands still, so the path's
    // warm-up renders what the still one does; bzb-ao has no temporal filter to warm up
    let ao = |extra: &[&str]| {
        let mut a = vec![
            "eval",
            "--scene",
            "cornell",
            "--technique",
            "ao",
            "--width",
            "32",
            "--height",
            "18",
            "--ref-spp",
            "4",
            "--json",
            "--quiet",
        ];
        a.extend(extra);
        a.extend(["--cache", cache.to_str().unwrap()]);
        json_of(&strata(&a))
    };
    let (still, path) = (ao(&[]), ao(&["--moving"]));
    assert_eq!(path["moving"], true);
    assert!(still.get("moving").is_none(), "{still}");
    assert_eq!(path["flip"], still["flip"]);
    let o = strata(&[
        "eval",
        "--scene",
        "cornell",
        "--technique",
        "aba-ao",
        "--moving",
        "--json",
    ]);
    assert_one_line_error(&o, &["--moving", "bzb-ao", "bzb-gi"]);
    // the GI comparison's own flags are errors where nothing reads them
    let o = strata(&[
        "eval",
        "--scene",
        "cornell",
        "--technique",
        "gi",
        "--set",
        "open-sky=cloud",
        "--json",
    ]);
    assert_one_line_error(&o, &["open-sky", "fill", "sky"]);
}

/// `eval --technique gi --oracle`: DGB's blend with a perfect gather beside the GPU's, for
/// k = 1 and 2 (the report evaluates both). The second layer holds at least what the first
/// does, every blend of the rule is reported against the same reference, the CPU twin of the
/// probe field the control variate reads follows the GPU's, and the report shows the images.
/// `--oracle` splits the light by 1 or 2 layers only, and only `eval --technique gi` reads it.
#[test]
fn eval_gi_oracle_reports_a_perfect_gather_beside_the_gpu() {
    let cache = scratch("gi-oracle-cache");
    let report = scratch("gi-oracle-report");
    let _ = std::fs::remove_dir_all(&cache);
    let _ = std::fs::remove_dir_all(&report);
    let args = |extra: &[&str]| -> Vec<String> {
        let mut a: Vec<String> = [
            "eval",
            "--scene",
            "cornell",
            "--technique",
            "gi",
            "--width",
            "40",
            "--height",
            "30",
            "--ref-spp",
            "64",
            "--bounces",
            "2",
            "--warmup",
            "2",
            "--json",
            "--quiet",
            "--cache",
        ]
        .iter()
        .map(|s| s.to_string())
        .collect();
        a.push(cache.to_str().unwrap().into());
        a.extend(extra.iter().map(|s| s.to_string()));
        a
    };
    let run = |extra: &[&str]| strata(&args(extra).iter().map(String::as_str).collect::<Vec<_>>());
    let v = json_of(&run(&[
        "--layers",
        "2",
        "--oracle",
        "--report",
        report.to_str().unwrap(),
    ]));
    let o = &v["oracle"];
    assert!(o["noise"]["spp"].as_u64().unwrap() >= 2, "{o}");
    assert!(o["probe_twin_error"].as_f64().unwrap() < 0.01, "{o}");
    let rows = o["by_layers"].as_array().expect("by_layers");
    assert_eq!(
        rows.iter().map(|r| r["layers"].as_u64().unwrap()).collect::<Vec<_>>(),
        [1, 2]
    );
    let c = |r: &serde_json::Value, key: &str| r[key].as_f64().unwrap();
    // the renderer's rule on the GPU's own gathered pair is the GPU's image
    let recomposed = |v: &serde_json::Value| {
        for r in v["oracle"]["by_layers"].as_array().unwrap() {
            let gpu = r["entries"]
                .as_array()
                .unwrap()
                .iter()
                .find(|e| e["blend"] == "gpu")
                .expect("gpu entry");
            let own = match r["layers"].as_u64() {
                Some(2) => v,
                _ => &v["layers_1"],
            };
            let (a, b) = (gpu["errors"]["rmse"].as_f64().unwrap(), own["rmse"].as_f64().unwrap());
            assert!((a - b).abs() <= 0.02 * b, "recomposed RMSE {a} against the GPU's {b}");
        }
    };
    recomposed(&v);
    for r in rows {
        assert!(c(r, "confidence") > 0.0 && c(r, "confidence") <= 1.0, "{r}");
        // the GPU's gather against the perfect one over the receivers both see
        let g = &r["gather"];
        assert!(c(g, "confidence") > 0.0 && c(g, "confidence") <= 1.0, "{g}");
        assert!(g["pixels"].as_u64().unwrap() > 0, "{g}");
        for x in g["irradiance_ratio"].as_array().unwrap() {
            assert!(x.as_f64().unwrap() > 0.0 && x.as_f64().unwrap().is_finite(), "{g}");
        }
        assert!(c(r, "confidence_within_radius") <= c(r, "confidence"), "{r}");
        let names: Vec<(&str, bool)> = r["entries"]
            .as_array()
            .unwrap()
            .iter()
            .map(|e| (e["blend"].as_str().unwrap(), e["within_radius"].as_bool().unwrap()))
            .collect();
        for blend in ["paper", "renderer", "detail", "alone"] {
            for within in [false, true] {
                assert!(names.contains(&(blend, within)), "{blend} {within}: {names:?}");
            }
        }
        assert!(names.contains(&("probes", false)), "{names:?}");
        for blend in ["gpu-gather-oracle-c", "oracle-gather-gpu-c"] {
            assert!(names.contains(&(blend, true)), "{blend}: {names:?}");
        }
        for e in r["entries"].as_array().unwrap() {
            let flip = e["errors"]["flip"].as_f64().unwrap();
            assert!(flip > 0.0 && flip < 1.0, "{e}");
            assert!(
                e["rmse_denoised"].as_f64().unwrap() <= e["errors"]["rmse"].as_f64().unwrap(),
                "{e}"
            );
        }
    }
    assert!(c(&rows[1], "confidence") >= c(&rows[0], "confidence"), "{rows:?}");
    for f in [
        "oracle-paper-k2.png",
        "oracle-detail-k1.png",
        "oracle-confidence-k2.png",
        "oracle-probes-k2.png",
    ] {
        assert!(report.join(f).exists(), "{f} in the report");
    }
    // with the probes' control variate compose runs another rule, and the `gpu` rows follow
    // it (the gathered term is no irradiance then: no `gather`)
    let d = json_of(&run(&["--layers", "2", "--oracle", "--set", "probe-detail=on"]));
    recomposed(&d);
    for r in d["oracle"]["by_layers"].as_array().unwrap() {
        assert!(r.get("gather").is_none(), "{r}");
    }
    // without probes the oracle converges on the seen light: its own cache entry (two
    // halves), not the one converged on the blends; the reference's is shared
    let bins = || {
        std::fs::read_dir(&cache)
            .unwrap()
            .filter(|e| e.as_ref().unwrap().path().extension().is_some_and(|x| x == "bin"))
            .count()
    };
    let before = bins();
    let n = json_of(&run(&["--layers", "2", "--oracle", "--no-probes"]));
    assert!(n["oracle"].get("probe_twin_error").is_none(), "{}", n["oracle"]);
    assert_eq!(bins(), before + 2, "a new oracle entry for the seen-light criterion");
    assert_one_line_error(
        &run(&["--layers", "3", "--oracle"]),
        &["--layers 3", "--oracle", "1..=2"],
    );
    let o = strata(&["eval", "--scene", "cornell", "--technique", "ao", "--oracle", "--json"]);
    assert_one_line_error(&o, &["--oracle", "gi"]);
}

#[test]
fn bench_radiosity_and_reflections_time_their_passes() {
    let o = strata(&[
        "bench",
        "radiosity",
        "--scene",
        "cornell",
        "--width",
        "48",
        "--height",
        "48",
        "--frames",
        "2",
        "--preset",
        "high-performance",
        "--json",
    ]);
    let v = json_of(&o);
    let names = pass_names(&v);
    assert!(
        names.contains(&"radiosity") && names.contains(&"propagate"),
        "{names:?}"
    );
    assert_eq!(v["samples"], 13, "high-performance preset: N = 13");
    let o = strata(&[
        "bench",
        "reflections",
        "--scene",
        "mirror",
        "--width",
        "48",
        "--height",
        "32",
        "--frames",
        "2",
        "--json",
    ]);
    let v = json_of(&o);
    assert!(v["total_median_ms"].as_f64().unwrap() > 0.0);
}

/// Issue 16: memory stays flat over a long run with two deep-G-buffer layers
/// (Debian 12's lavapipe leaked ~5 MB per frame here; scripts/setup.sh installs
/// a Mesa without the leak). 500 frames of the full technique along atrium's
/// camera path, resident memory sampled every 100 frames: growth ≤ 1 % after
/// the first sample.
#[test]
fn soak_500_frames_keeps_memory_flat() {
    let cache = scratch("soak-cache");
    let v = json_of(&strata_cached(
        &[
            "soak",
            "--scene",
            "atrium",
            "--technique",
            "full",
            "--layers",
            "2",
            "--width",
            "128",
            "--height",
            "72",
            "--frames",
            "500",
            "--sample-every",
            "100",
            "--json",
        ],
        &cache,
    ));
    let samples = v["samples"].as_array().expect("samples");
    assert_eq!(samples.len(), 5, "{v}");
    assert_eq!(samples[4]["frame"], 500);
    let rss: Vec<u64> = samples
        .iter()
        .map(|s| s["rss_bytes"].as_u64().expect("rss on Linux"))
        .collect();
    let growth = v["rss_growth_percent"].as_f64().unwrap();
    assert!(
        growth <= 1.0,
        "resident memory grew {growth:.2} % over 400 frames: {rss:?}"
    );
    assert_eq!(v["layers"], 2);
}

/// Every other registered technique soaks flat too (`full` has the 500-frame test above):
/// 160 frames of `glasshouse` (transparent and opaque surfaces, so the A-buffer
/// techniques have lists to build) with 2 layers, sampled every 40 frames. wgpu's
/// allocations stay the same. Resident memory grows ≤ 2 % after the first sample, and not
/// in every interval: a leak grows each interval, while the process's allocator takes a
/// one-time step now and then (measured 2026-11-29: 0 % for each at 64×36; at 128×72 for
/// 300 frames, one-time steps of 0.35–0.67 % before frame 150; and one clean-clone CI run
/// failed the earlier "≤ 1 % over 120 frames" rule on `ao` with a single 1.1 MiB step,
/// 1.004 %, at frame 120).
#[test]
fn every_technique_soaks_flat() {
    let cache = scratch("soak-every-cache");
    for t in strata_render::technique::registry().iter().filter(|t| t.name != "full") {
        let v = json_of(&strata_cached(
            &[
                "soak",
                "--scene",
                "glasshouse",
                "--technique",
                t.name,
                "--layers",
                "2",
                "--width",
                "64",
                "--height",
                "36",
                "--frames",
                "160",
                "--sample-every",
                "40",
                "--json",
            ],
            &cache,
        ));
        let samples = v["samples"].as_array().expect("samples");
        assert_eq!(samples.len(), 4, "{} {v}", t.name);
        let gpu: Vec<u64> = samples
            .iter()
            .map(|s| s["gpu_allocated_bytes"].as_u64().expect("wgpu's allocator report"))
            .collect();
        assert!(gpu.iter().all(|&b| b == gpu[0]), "{}: wgpu allocations {gpu:?}", t.name);
        let growth = v["rss_growth_percent"].as_f64().unwrap();
        assert!(growth <= 2.0, "{}: resident memory grew {growth:.2} %: {v}", t.name);
        let rss: Vec<u64> = samples
            .iter()
            .map(|s| s["rss_bytes"].as_u64().expect("VmRSS"))
            .collect();
        // a leak of 1.6 KB a frame or more grows each 40-frame interval by 64 KiB or more
        let flat = rss.windows(2).any(|w| w[1] <= w[0] + 64 * 1024);
        assert!(flat, "{}: resident memory grew in every interval {rss:?}: {v}", t.name);
    }
}

#[test]
fn soak_rejects_out_of_range_parameters() {
    let o = strata(&["soak", "--scene", "cornell", "--frames", "0"]);
    assert_one_line_error(&o, &["--frames", "0"]);
    let o = strata(&[
        "soak",
        "--scene",
        "cornell",
        "--frames",
        "2",
        "--max-growth-percent",
        "-5",
    ]);
    assert_one_line_error(&o, &["--max-growth-percent", "0..=1000"]);
    // a flag its technique does not read: the same one-line warning as `render`, and it runs
    let o = strata(&[
        "soak",
        "--scene",
        "cornell",
        "--frames",
        "2",
        "--sample-every",
        "1",
        "--width",
        "16",
        "--height",
        "16",
        "--samples",
        "5",
        "--json",
    ]);
    let warned = flag_warnings(&o);
    assert!(
        warned.len() == 1 && warned[0].contains("--samples is not read by --technique direct"),
        "{warned:?}"
    );
}

/// Issue 9's CLI fix, needed by anyone typing a camera: negative vector values in
/// the plain `--eye -3,2,5` form.
#[test]
fn negative_vector_arguments_work_in_the_plain_form() {
    let out = scratch("negative-eye.png");
    let o = strata(&[
        "render",
        "--scene",
        "atrium",
        "--eye",
        "-3,2,5",
        "--target",
        "0,1,0",
        "--width",
        "64",
        "--height",
        "64",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(out.exists());
}

/// Issue 16: a truncated cache entry is detected, reported, recomputed and
/// rewritten; the run still succeeds with the same numbers.
#[test]
fn truncated_cache_entry_is_reported_and_recomputed() {
    let cache = scratch("truncated-cache");
    let _ = std::fs::remove_dir_all(&cache);
    let args = [
        "eval",
        "--scene",
        "cornell",
        "--technique",
        "ao",
        "--width",
        "32",
        "--height",
        "32",
        "--ref-spp",
        "8",
        "--json",
        "--quiet",
        "--cache",
        cache.to_str().unwrap(),
    ];
    let v = json_of(&strata(&args));
    let bins: Vec<PathBuf> = std::fs::read_dir(&cache)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "bin"))
        .collect();
    assert!(!bins.is_empty(), "nothing cached");
    let sizes: Vec<u64> = bins.iter().map(|p| std::fs::metadata(p).unwrap().len()).collect();
    for p in &bins {
        let bytes = std::fs::read(p).unwrap();
        std::fs::write(p, &bytes[..bytes.len() / 2]).unwrap();
    }
    let o = strata(&args);
    let v2 = json_of(&o);
    assert!(
        stderr(&o).contains("corrupt"),
        "the truncated entry is reported: {}",
        stderr(&o)
    );
    assert_eq!(v["flip"], v2["flip"], "recomputed reference gives the same numbers");
    for (p, size) in bins.iter().zip(sizes) {
        assert_eq!(
            std::fs::metadata(p).unwrap().len(),
            size,
            "{} rewritten whole",
            p.display()
        );
    }
}

/// Issue 16: Ctrl-C (SIGINT) during `strata reference` leaves neither the output
/// nor a temporary file, and exits non-zero; the same command then completes.
#[test]
fn interrupted_reference_leaves_no_partial_file() {
    let dir = scratch("interrupted");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("gi.exr");
    let run = |spp: &str| {
        let mut cmd = Command::new(env!("CARGO_BIN_EXE_strata"));
        cmd.args([
            "reference",
            "--scene",
            "cornell",
            "--kind",
            "gi",
            "--width",
            "64",
            "--height",
            "64",
            "--spp",
            spp,
            "--out",
            out.to_str().unwrap(),
        ]);
        cmd.stderr(std::process::Stdio::piped())
            .stdout(std::process::Stdio::piped());
        cmd.spawn().unwrap()
    };
    let child = run("65536");
    std::thread::sleep(std::time::Duration::from_millis(1500));
    let killed = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(killed.success());
    let o = child.wait_with_output().unwrap();
    assert!(!o.status.success(), "an interrupted run must not report success");
    let left: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert!(left.is_empty(), "interrupted run left {left:?}");
    let o = run("1").wait_with_output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let left: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(left, vec![std::ffi::OsString::from("gi.exr")]);
}

/// Issue 16: a frame over the memory budget is a one-line error before anything
/// is allocated, and no output is written.
#[test]
fn frame_over_the_memory_budget_is_refused() {
    let out = scratch("huge.png");
    let o = strata(&[
        "render",
        "--scene",
        "atrium",
        "--technique",
        "ao",
        "--layers",
        "4",
        "--width",
        "8192",
        "--height",
        "8192",
        // the AO default (10 %) would already exceed the largest texture
        "--guard-band",
        "0",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_one_line_error(&o, &["width 8192", "layers 4", "STRATA_MEMORY_BUDGET_MB"]);
    assert!(!out.exists());
}

/// `bzb-gi` with AOV splats and d_max spanning the scene (the defaults) tests every
/// triangle at every texel of every sub-image: above 10¹⁰ tests a frame `render` warns in
/// one line with the count and the DSS alternative (atrium at 1280×720: 7,866 × 4 ×
/// 921,600 = 2.9·10¹⁰), and not with DSS surfels, a shorter d_max, the additive
/// baseline's single sub-image (7.2·10⁹) or at 640×360 (7.2·10⁹).
#[test]
fn render_warns_of_a_full_screen_bzb_gi_splat() {
    let warned = |extra: &[&str]| -> Vec<String> {
        let args = [
            &["render", "--scene", "atrium", "--technique", "bzb-gi", "--list-passes"][..],
            extra,
        ]
        .concat();
        let o = strata(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        stderr(&o)
            .lines()
            .filter(|l| l.starts_with("strata: warning: bzb-gi:"))
            .map(String::from)
            .collect()
    };
    let big = ["--width", "1280", "--height", "720"];
    let w = warned(&big);
    assert!(
        w.len() == 1
            && w[0].contains("7866 triangles × 4 directions × 1280x720 = 2.9e10")
            && w[0].contains("splat=dss"),
        "{w:?}"
    );
    for extra in [
        &["--set", "splat=dss"][..],
        &["--set", "dmax=5"],
        &["--set", "visibility=off"],
    ] {
        assert!(warned(&[&big[..], extra].concat()).is_empty(), "{extra:?}");
    }
    assert!(warned(&["--width", "640", "--height", "360"]).is_empty());
}

/// `strata techniques NAME` lists that technique alone, naming its settings as `--set`
/// takes them (not as flags: `--refine-peak` is no flag of `render`) and two-valued ones by
/// their value names; an unknown name is one line listing the valid ones.
#[test]
fn techniques_lists_one_technique_with_set_names() {
    let o = strata(&["techniques", "ils"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = String::from_utf8_lossy(&o.stdout).to_string();
    assert!(out.starts_with("ils  —"), "{out}");
    assert!(
        !out.contains("\nao  —") && !out.contains("\nbzb-gi  —"),
        "other techniques listed: {out}"
    );
    assert!(out.contains("--set NAME=VALUE"), "{out}");
    let row = |name: &str| {
        out.lines()
            .find(|l| l.split_whitespace().next() == Some(name))
            .unwrap_or_else(|| panic!("no row {name}: {out}"))
            .to_string()
    };
    assert!(!out.contains("--refine-peak"), "{out}");
    assert!(
        row("shadows").contains(" none ") && row("shadows").contains("none|vpl"),
        "{}",
        row("shadows")
    );
    assert!(row("refine-peak").contains("0..=1"), "{}", row("refine-peak"));
    let v = json_of(&strata(&["techniques", "ao", "--json"]));
    let names: Vec<&str> = v["techniques"]
        .as_array()
        .unwrap()
        .iter()
        .map(|t| t["name"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["ao"]);
    assert_one_line_error(&strata(&["techniques", "foo"]), &["unknown technique 'foo'", "ils"]);
}

/// Issue 9: `strata techniques --json` lists every registered technique with its
/// settings, defaults and ranges; every listed setting is settable with `--set`
/// and its range is enforced there with a one-line error.
#[test]
fn techniques_json_lists_settings_defaults_and_ranges() {
    let v = json_of(&strata(&["techniques", "--json"]));
    let ts = v["techniques"].as_array().expect("techniques");
    let names: Vec<&str> = ts.iter().map(|t| t["name"].as_str().unwrap()).collect();
    assert_eq!(
        names,
        ["direct", "ao", "full", "ils", "oit", "aba-ao", "bzb-ao", "bzb-gi"]
    );
    let full = &ts[2];
    assert_eq!(
        full["presets"],
        serde_json::json!(["balanced", "high-performance", "high-quality"])
    );
    for t in ts {
        let settings = t["settings"].as_array().unwrap();
        assert!(!settings.is_empty(), "{} lists no settings", t["name"]);
        for s in settings {
            assert!(s["doc"].as_str().is_some_and(|d| !d.is_empty()), "{s}");
            assert!(s["range"]["text"].as_str().is_some(), "{s}");
            assert!(s["default"].is_number() || s["default"].is_null(), "{s}");
            if let (Some(d), Some(min)) = (s["default"].as_f64(), s["range"]["min"].as_f64()) {
                assert!(d >= min, "default below range: {s}");
            }
        }
    }
    let ao = &ts[1]["settings"];
    let samples = ao.as_array().unwrap().iter().find(|s| s["name"] == "samples").unwrap();
    assert_eq!(samples["default"], 19.0);
    assert_eq!(samples["range"]["text"], "1..=256");
    // --set applies a registered setting, and enforces its range in one line
    let out = scratch("set-samples.png");
    let o = strata(&[
        "render",
        "--scene",
        "cornell",
        "--technique",
        "ao",
        "--set",
        "samples=8",
        "--width",
        "32",
        "--height",
        "32",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = strata(&[
        "render",
        "--scene",
        "cornell",
        "--technique",
        "full",
        "--set",
        "reflection-steps=0",
        "--out",
        "x.png",
    ]);
    assert_one_line_error(&o, &["reflection-steps", "1..=1024"]);
    let o = strata(&[
        "render",
        "--scene",
        "cornell",
        "--technique",
        "direct",
        "--set",
        "samples=8",
        "--out",
        "x.png",
    ]);
    assert_one_line_error(&o, &["samples", "valid settings are"]);
}

/// Issue 9: `bench technique` times any registered technique's declared passes
/// (k = 1 and k = 2, increment with its spread); bad presets and settings are
/// one-line errors before any GPU work.
#[test]
fn bench_technique_times_the_registered_passes() {
    let v = json_of(&strata(&[
        "bench",
        "technique",
        "--technique",
        "ao",
        "--scene",
        "cornell",
        "--width",
        "64",
        "--height",
        "48",
        "--frames",
        "2",
        "--set",
        "samples=12",
        "--json",
    ]));
    assert_eq!(v["bench"], "technique");
    assert_eq!(v["technique"], "ao");
    assert_eq!(v["set"]["samples"], 12.0);
    assert_eq!(
        pass_names(&v),
        ["depth-mip", "ao", "ao-temporal", "ao-blur-h", "ao-blur-v"]
    );
    assert!(v["increment_spread"]["frames"].as_u64() == Some(2), "{v}");
    // bzb-gi with DSS surfels: its surfelization, surfel shading and splat passes are timed
    let v = json_of(&strata(&[
        "bench",
        "technique",
        "--technique",
        "bzb-gi",
        "--scene",
        "still-life",
        "--width",
        "32",
        "--height",
        "24",
        "--frames",
        "1",
        "--layers",
        "1",
        "--set",
        "splat=dss",
        "--json",
    ]));
    let names = pass_names(&v);
    for p in [
        "bzb-directions",
        "dss-fine",
        "dss-gi-shade",
        "dss-splat",
        "dss-reduce",
        "bzb-reconstruct",
    ] {
        assert!(names.contains(&p), "{p} in {names:?}");
    }
    assert!(!names.contains(&"bzb-splat"), "{names:?}");
    let o = strata(&[
        "bench",
        "technique",
        "--technique",
        "ao",
        "--set",
        "samples=999",
        "--frames",
        "1",
    ]);
    assert_one_line_error(&o, &["--set samples=999", "1..=256"]);
    let o = strata(&[
        "bench",
        "technique",
        "--technique",
        "full",
        "--preset",
        "ultra",
        "--frames",
        "1",
    ]);
    assert_one_line_error(&o, &["--preset", "valid presets are"]);
}

/// Issue 17: `--list-lights` prints the scene's lights in strata's units; `--camera N` is
/// range-checked against the file's cameras.
#[test]
fn render_lists_lights_and_checks_the_camera_index() {
    let o = strata(&["render", "--scene", "warehouse", "--list-lights"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = stdout(&o);
    assert!(out.contains("lights of 'warehouse': 2"), "{out}");
    assert!(
        out.contains("spot ")
            && out.contains("cone 15.00°..19.00°")
            && out.contains("point position (4.000, 3.200, 2.500)"),
        "{out}"
    );
    let o = strata(&["render", "--scene", "warehouse", "--camera", "0", "--list-lights"]);
    assert_one_line_error(&o, &["--camera 0", "no cameras"]);
}

/// Issue 11: `strata render --technique ils` generates the VPLs on the CPU and
/// renders interleaved deferred shading; its debug views and `--set` work, bad
/// settings are one-line errors; `strata bench ils` reports IS, brute force and
/// the speed-up.
#[test]
fn ils_renders_benches_and_refuses_bad_settings() {
    let out = scratch("ils.png");
    let args = |extra: &[&'static str]| {
        let mut v = vec![
            "render",
            "--scene",
            "cornell",
            "--technique",
            "ils",
            "--width",
            "48",
            "--height",
            "40",
        ];
        v.extend_from_slice(extra);
        v.extend(["--out", out.to_str().unwrap(), "--force"]);
        v.iter().map(|s| s.to_string()).collect::<Vec<_>>()
    };
    for extra in [
        &[][..],
        &[
            "--set",
            "vpls=96",
            "--set",
            "interleave-n=4",
            "--set",
            "interleave-m=4",
            "--set",
            "split-block=16",
        ][..],
        &["--debug-view", "ils-irradiance-tiled"][..],
        &["--debug-view", "ils-discontinuity", "--set", "bilinear=0"][..],
        &["--set", "brute-force=1", "--set", "blur=0"][..],
        &["--preset", "clean-edges"][..],
        &["--preset", "refined", "--set", "refine=0.25"][..],
    ] {
        let a = args(extra);
        let o = strata(&a.iter().map(String::as_str).collect::<Vec<_>>());
        assert!(o.status.success(), "{extra:?}: {}", stderr(&o));
        assert!(out.exists());
    }
    for (extra, needles) in [
        (&["--set", "interleave-m=0"][..], &["interleave-m", "1..=16"][..]),
        (&["--set", "split-block=12"][..], &["block size 12", "8..=1024"][..]),
        (&["--set", "vpls=70000"][..], &["vpls", "1..=65536"][..]),
        (&["--set", "blur=9"][..], &["blur", "0..=4"][..]),
        (
            &["--preset", "balanced"][..],
            &["--preset", "standard, clean-edges, refined"][..],
        ),
    ] {
        let a = args(extra);
        let o = strata(&a.iter().map(String::as_str).collect::<Vec<_>>());
        assert_one_line_error(&o, needles);
    }
    let v = json_of(&strata(&[
        "bench",
        "ils",
        "--scene",
        "cornell",
        "--width",
        "64",
        "--height",
        "48",
        "--frames",
        "2",
        "--layers",
        "1",
        "--set",
        "vpls=96",
        "--preset",
        "clean-edges",
        "--json",
    ]));
    assert_eq!(v["bench"], "ils", "{v}");
    assert_eq!(v["interleaved"]["preset"], "clean-edges", "{v}");
    assert!(v["speedup"].as_f64().is_some_and(|x| x > 0.0), "{v}");
    let names: Vec<&str> = v["brute_force"]["passes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["name"].as_str().unwrap())
        .collect();
    assert!(names.contains(&"ils-brute-force"), "{names:?}");
}

/// `strata bench bzb` times both bounced z-buffer techniques (BZB Table 1: AO and the
/// indirect-light columns) with and without visibility, DSS included; GI's layered
/// framebuffer holds radiance, so it is larger than AO's (Table 3: 18 against 6 MB);
/// another technique is a one-line error.
#[test]
fn bench_bzb_times_ao_and_gi_with_and_without_visibility() {
    let run = |technique: &str, extra: &[&str]| {
        let mut a = vec![
            "bench",
            "bzb",
            "--technique",
            technique,
            "--scene",
            "cornell",
            "--width",
            "64",
            "--height",
            "48",
            "--frames",
            "1",
            "--json",
        ];
        a.extend(extra);
        json_of(&strata(&a))
    };
    let mut layered = Vec::new();
    for (technique, extra, splat) in [
        ("bzb-ao", &[][..], "bzb-splat"),
        ("bzb-gi", &[][..], "bzb-splat"),
        ("bzb-ao", &["--set", "splat=dss"][..], "dss-splat"),
        ("bzb-gi", &["--set", "splat=dss"][..], "dss-splat"),
    ] {
        let v = run(technique, extra);
        assert_eq!(
            (v["bench"].as_str(), v["technique"].as_str()),
            (Some("bzb"), Some(technique)),
            "{v}"
        );
        for run in ["visibility", "no_visibility"] {
            let names: Vec<&str> = v[run]["passes"]
                .as_array()
                .unwrap()
                .iter()
                .map(|p| p["name"].as_str().unwrap())
                .collect();
            assert!(names.contains(&splat), "{technique} {extra:?} {run}: {names:?}");
            if technique == "bzb-gi" {
                assert!(names.contains(&"bzb-gi-blur-h"), "{names:?}");
            }
        }
        assert!(
            v["splat_ratio"].as_f64().is_some_and(|x| x.is_finite() && x > 0.0),
            "{v}"
        );
        assert!(v["memory_bytes"].as_u64().is_some_and(|b| b > 0), "{v}");
        if let Some(d) = v.get("dss") {
            assert!(d["counts"]["surfels"].as_u64().is_some_and(|n| n > 0), "{d}");
            let shade = d["stages"]["shade_ms"].as_f64().unwrap();
            assert_eq!(shade > 0.0, technique == "bzb-gi", "only GI shades its surfels: {d}");
            layered.push(d["memory"]["layered_framebuffer"].as_u64().unwrap());
        }
    }
    assert!(
        layered[1] > 2 * layered[0],
        "GI's layered framebuffer {} vs AO's {}",
        layered[1],
        layered[0]
    );
    let o = strata(&[
        "bench",
        "bzb",
        "--technique",
        "ao",
        "--scene",
        "cornell",
        "--frames",
        "1",
    ]);
    assert_one_line_error(&o, &["--technique", "bzb-ao or bzb-gi"]);
}

/// Issue 11: `strata eval --technique ils` compares the interleaved image with
/// the brute force of the same VPLs and with the one-bounce path tracer (low
/// `--ref-spp` cap: the numbers are only checked to exist and be sane); `eval
/// ao` and `eval gi` keep refusing `--set`; bad settings are one-line errors.
#[test]
fn eval_ils_reports_errors_vs_brute_force_and_path_tracer() {
    let cache = scratch("ils-cache");
    let _ = std::fs::remove_dir_all(&cache);
    let base = [
        "eval",
        "--scene",
        "cornell",
        "--technique",
        "ils",
        "--width",
        "32",
        "--height",
        "24",
        "--ref-spp",
        "4",
        "--json",
        "--quiet",
        "--cache",
    ];
    let run = |extra: &[&str]| {
        let mut a: Vec<&str> = base.to_vec();
        a.push(cache.to_str().unwrap());
        a.extend_from_slice(extra);
        strata(&a)
    };
    let v = json_of(&run(&["--set", "vpls=96"]));
    assert_eq!(v["technique"], "ils", "{v}");
    assert_eq!(v["shadows"], "none");
    assert_eq!(v["pattern"], "8x6");
    for key in [
        "flip_vs_brute",
        "rmse_vs_brute",
        "indirect_flip_vs_brute",
        "indirect_rmse_vs_brute",
    ] {
        assert!(v[key].as_f64().is_some_and(|x| (0.0..1.0).contains(&x)), "{key}: {v}");
    }
    for key in ["flip", "rmse", "mae"] {
        assert!(v[key].as_f64().is_some_and(|x| x >= 0.0), "{key}: {v}");
        assert!(v["full"][key].as_f64().is_some_and(|x| x >= 0.0), "full.{key}: {v}");
        assert!(
            v["brute_force"][key].as_f64().is_some_and(|x| x >= 0.0),
            "brute_force.{key}: {v}"
        );
    }
    assert!(
        v["reference"].as_str().unwrap().contains("SNSM ignores VPL visibility"),
        "{v}"
    );
    assert_eq!(v["ref_spp"], 4);
    assert_eq!(v["preset"], "standard", "{v}");
    assert!(v.get("refined_share").is_none(), "no ils-refine without refine: {v}");
    // --report: the path tracer, the interleaved frame and the brute force beside their
    // ꟻLIP maps, and the interleaved frame's ꟻLIP against the brute force
    let report = scratch("ils-report");
    let _ = std::fs::remove_dir_all(&report);
    let v = json_of(&run(&["--set", "vpls=96", "--report", report.to_str().unwrap()]));
    let html = std::fs::read_to_string(report.join("index.html")).unwrap();
    for f in [
        "reference-indirect.png",
        "reference-full.png",
        "flip-indirect-vs-brute-force.png",
    ] {
        assert!(
            html.contains(f) && report.join(f).exists(),
            "{f} missing from the report"
        );
    }
    let indirect: Vec<_> = std::fs::read_dir(&report)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .filter(|n| n.starts_with("indirect-") && html.contains(n.as_str()))
        .collect();
    assert_eq!(
        indirect.len(),
        2,
        "the interleaved frame and the brute force: {indirect:?}"
    );
    let (a, b) = (
        std::fs::read(report.join(&indirect[0])).unwrap(),
        std::fs::read(report.join(&indirect[1])).unwrap(),
    );
    assert_ne!(a, b, "the interleaved frame and the brute force wrote the same image");
    let flip = format!("{:.4}", v["indirect_flip_vs_brute"].as_f64().unwrap());
    assert!(html.contains(&flip), "ꟻLIP vs the brute force {flip} not on the page");
    // --bounces without --progressive and an AO flag are not read: a warning each;
    // --preset is read (the ILS presets)
    let o = run(&[
        "--set",
        "vpls=96",
        "--bounces",
        "2",
        "--samples",
        "5",
        "--preset",
        "refined",
    ]);
    let warned = flag_warnings(&o);
    assert_eq!(warned.len(), 2, "{warned:?}");
    assert!(
        warned
            .iter()
            .any(|l| l.contains("--bounces") && l.contains("--progressive")),
        "{warned:?}"
    );
    assert!(warned.iter().any(|l| l.contains("--samples")), "{warned:?}");
    // §4.3 SSM: per-VPL shadow maps, named value on --set; the refined preset's
    // ils-refine with them, and the share of the pixels it shaded
    let v = json_of(&run(&[
        "--set",
        "vpls=48",
        "--set",
        "shadows=vpl",
        "--set",
        "vpl-shadow-resolution=16",
        "--preset",
        "refined",
    ]));
    assert_eq!(v["shadows"], "vpl", "{v}");
    assert!(v["reference"].as_str().unwrap().contains("SSM"), "{v}");
    assert_eq!(
        (&v["preset"], &v["refine"], &v["blur_slide"]),
        (
            &serde_json::json!("refined"),
            &serde_json::json!(0.5),
            &serde_json::json!(true)
        )
    );
    assert!(
        v["refined_share"].as_f64().is_some_and(|x| (0.0..=1.0).contains(&x)),
        "{v}"
    );
    // a 1x1 pattern is the brute force
    let v = json_of(&run(&[
        "--set",
        "vpls=96",
        "--set",
        "interleave-n=1",
        "--set",
        "interleave-m=1",
        "--set",
        "blur=0",
    ]));
    assert!(v["flip_vs_brute"].as_f64().unwrap() < 0.01, "{v}");
    for (extra, needles) in [
        (&["--set", "interleave-n=20"][..], &["interleave-n", "1..=16"][..]),
        (&["--set", "shadows=maybe"][..], &["shadows", "maybe"][..]),
        (
            &["--set", "vpl-shadow-resolution=4"][..],
            &["vpl-shadow-resolution", "8..=512"][..],
        ),
        (&["--layers", "2"][..], &["--layers", "must be 1"][..]),
    ] {
        assert_one_line_error(&run(extra), needles);
    }
    let o = strata(&[
        "eval",
        "--scene",
        "plane",
        "--technique",
        "ao",
        "--width",
        "16",
        "--height",
        "16",
        "--set",
        "vpls=3",
    ]);
    // an ILS setting given to AO: the error names it, the technique and AO's own settings
    assert_one_line_error(&o, &["--set vpls=3", "'ao'", "temporal-clamp"]);
}

/// Issue 10: `export-scene` writes every world-space triangle (per material, unshared
/// vertices in scene order) and the camera; a second run refuses to overwrite.
#[test]
fn export_scene_writes_the_triangles_and_camera_of_the_frame() {
    let dir = scratch("export-cornell");
    let _ = std::fs::remove_dir_all(&dir);
    let args = [
        "export-scene",
        "--scene",
        "cornell",
        "--width",
        "40",
        "--height",
        "30",
        "--fov",
        "50",
        "--out",
        dir.to_str().unwrap(),
        "--json",
    ];
    let v = json_of(&strata(&args));
    let scene = strata_scene::load_scene("cornell").unwrap();
    let tris = scene.world_triangles(0.0);
    assert_eq!(v["triangles"].as_u64(), Some(tris.len() as u64));

    let doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("scene.json")).unwrap()).unwrap();
    assert_eq!(doc["triangles"].as_u64(), Some(tris.len() as u64));
    assert_eq!(doc["camera"]["width"], 40);
    assert_eq!(doc["camera"]["height"], 30);
    assert_eq!(doc["camera"]["fov_y_deg"].as_f64(), Some(50.0));
    let eye: Vec<f32> = doc["camera"]["eye"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap() as f32)
        .collect();
    assert_eq!(eye, scene.camera.eye.to_array());

    // Every material's PLY: header counts, and its triangles are the scene's, in order.
    let mut total = 0;
    for m in doc["materials"].as_array().unwrap() {
        let Some(name) = m["mesh"].as_str() else { continue };
        let index = m["index"].as_u64().unwrap() as u32;
        let bytes = std::fs::read(dir.join(name)).unwrap();
        let end = b"end_header\n";
        let at = bytes.windows(end.len()).position(|w| w == end).unwrap() + end.len();
        let header = String::from_utf8_lossy(&bytes[..at]);
        let mine: Vec<_> = tris.iter().filter(|t| t.material == index).collect();
        assert!(
            header.contains(&format!("element vertex {}\n", 3 * mine.len())),
            "{header}"
        );
        assert!(header.contains(&format!("element face {}\n", mine.len())), "{header}");
        let f = |i: usize| f32::from_le_bytes(bytes[at + 4 * i..at + 4 * i + 4].try_into().unwrap());
        // Vertex 3i + k = corner k of triangle i: 8 floats (position, normal, uv).
        for (i, t) in mine.iter().enumerate() {
            for k in 0..3 {
                let base = (3 * i + k) * 8;
                assert_eq!(
                    [f(base), f(base + 1), f(base + 2)],
                    t.p[k].to_array(),
                    "{name} triangle {i}"
                );
            }
        }
        let faces = at + 3 * mine.len() * 32;
        assert_eq!(bytes.len(), faces + mine.len() * 13, "{name}: face list size");
        assert_eq!(bytes[faces], 3);
        total += mine.len();
    }
    assert_eq!(total, tris.len());

    let o = strata(&args);
    assert_one_line_error(&o, &["exists", "--force"]);
}

/// `reference` warns in one line of each given flag its `--kind` does not read (it used to
/// accept `--kind ao --bounces 3` or `--kind layers --spp 64` without a word), still writes
/// the image, and says nothing of the flags the kind reads.
#[test]
fn reference_warns_of_flags_its_kind_does_not_read() {
    let out = scratch("reference-unread.exr");
    let warned = |args: &[&str]| -> Vec<String> {
        let base = [
            "reference",
            "--scene",
            "cornell",
            "--width",
            "8",
            "--height",
            "8",
            "--quiet",
            "--force",
            "--out",
            out.to_str().unwrap(),
        ];
        let o = strata(&[&base[..], args].concat());
        assert!(o.status.success(), "{}", stderr(&o));
        assert!(out.exists());
        stderr(&o)
            .lines()
            .filter(|l| l.starts_with("strata: warning: --"))
            .map(String::from)
            .collect()
    };
    let w = warned(&[
        "--kind",
        "ao",
        "--bounces",
        "3",
        "--layers",
        "3",
        "--spp",
        "4",
        "--ao-radius",
        "0.1",
    ]);
    assert_eq!(w.len(), 2, "{w:?}");
    assert!(
        w.iter()
            .any(|l| l.contains("--bounces is not read by reference --kind ao: it reads --ao-radius, --spp, --seed")),
        "{w:?}"
    );
    assert!(w.iter().any(|l| l.contains("--layers is not read")), "{w:?}");
    let w = warned(&["--kind", "layers", "--spp", "64", "--layers", "3"]);
    assert!(
        w.len() == 1 && w[0].contains("--spp is not read by reference --kind layers"),
        "{w:?}"
    );
    let w = warned(&["--kind", "composite", "--seed", "3"]);
    assert!(
        w.len() == 1 && w[0].contains("it takes none of the sampling flags"),
        "{w:?}"
    );
    assert!(warned(&["--kind", "indirect", "--bounces", "1", "--spp", "4", "--seed", "2"]).is_empty());
}

/// Writes cornell's ray-traced AO (4 spp) at `width`×16 to `out` (overwriting it).
fn ao_reference(out: &Path, width: &str) {
    let o = strata(&[
        "reference",
        "--scene",
        "cornell",
        "--kind",
        "ao",
        "--spp",
        "4",
        "--width",
        width,
        "--height",
        "16",
        "--quiet",
        "--force",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
}

/// `compare` of an image with itself is zero error; different sizes are one line.
#[test]
fn compare_reports_zero_for_identical_images_and_refuses_size_mismatch() {
    let a = scratch("compare-a.exr");
    let b = scratch("compare-b.exr");
    for (p, w) in [(&a, "24"), (&b, "16")] {
        ao_reference(p, w);
    }
    let v = json_of(&strata(&[
        "compare",
        a.to_str().unwrap(),
        a.to_str().unwrap(),
        "--json",
    ]));
    assert_eq!(v["flip"].as_f64(), Some(0.0));
    assert_eq!(v["rmse"].as_f64(), Some(0.0));
    assert_eq!(v["mean_difference"].as_f64(), Some(0.0));
    let o = strata(&["compare", a.to_str().unwrap(), b.to_str().unwrap(), "--exposure", "1"]);
    assert_one_line_error(&o, &["same size"]);
}

/// `compare` reads a PNG's stored bytes, as `eval` hands them to ꟻLIP: an AO reference
/// written as EXR and as PNG (raw 255·AV bytes) compares with ꟻLIP 0 and RMSE within the
/// bytes' rounding (it read the PNG sRGB-decoded before: ꟻLIP 0.15 at this size).
/// `--exposure` (linear radiance) refuses a PNG in one line, and a radiance EXR against a
/// PNG warns.
#[test]
fn compare_reads_png_bytes_as_eval_does() {
    let (exr, png) = (scratch("compare-ao.exr"), scratch("compare-ao.png"));
    for p in [&exr, &png] {
        ao_reference(p, "24");
    }
    let v = json_of(&strata(&[
        "compare",
        exr.to_str().unwrap(),
        png.to_str().unwrap(),
        "--json",
    ]));
    assert_eq!(v["flip"].as_f64(), Some(0.0), "{v}");
    let rmse = v["rmse"].as_f64().unwrap();
    assert!(rmse <= 0.5 / 255.0 + 1e-6, "rmse {rmse}");
    assert!(v["mean_difference"].as_f64().unwrap().abs() <= 0.5 / 255.0, "{v}");

    let o = strata(&[
        "compare",
        exr.to_str().unwrap(),
        png.to_str().unwrap(),
        "--exposure",
        "1",
    ]);
    assert_one_line_error(&o, &["--exposure", "compare-ao.png", "display values"]);

    let (hdr, ldr) = (scratch("compare-render.exr"), scratch("compare-render.png"));
    for p in [&hdr, &ldr] {
        let o = strata(&[
            "render",
            "--scene",
            "cornell",
            "--width",
            "24",
            "--height",
            "16",
            "--force",
            "--out",
            p.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
    }
    let o = strata(&["compare", hdr.to_str().unwrap(), ldr.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let err = stderr(&o);
    let warned: Vec<&str> = err
        .lines()
        .filter(|l| l.starts_with("strata: warning: compare:"))
        .collect();
    assert!(
        warned.len() == 1 && warned[0].contains("compare-render.exr") && warned[0].contains("linear radiance"),
        "{}",
        stderr(&o)
    );
    // two PNGs, or an AO EXR beside its PNG, do not warn
    let o = strata(&["compare", ldr.to_str().unwrap(), ldr.to_str().unwrap()]);
    assert!(o.status.success() && !stderr(&o).contains("warning"), "{}", stderr(&o));
    let o = strata(&["compare", exr.to_str().unwrap(), png.to_str().unwrap()]);
    assert!(o.status.success() && !stderr(&o).contains("warning"), "{}", stderr(&o));
}

/// Writes a glTF (JSON + external .bin) of a 4 × 4 floor quad at y = 0 (normal
/// +Y) seen from above by a camera node; `extension` is inserted at the top
/// level and `light_nodes` appended to the nodes (the scene lists nodes 0.. all).
fn floor_gltf(name: &str, extension: &str, light_nodes: &[&str]) -> PathBuf {
    let floats: [f32; 24] = [
        -2.0, 0.0, -2.0, 0.0, 1.0, 0.0, //
        -2.0, 0.0, 2.0, 0.0, 1.0, 0.0, //
        2.0, 0.0, 2.0, 0.0, 1.0, 0.0, //
        2.0, 0.0, -2.0, 0.0, 1.0, 0.0,
    ];
    let mut bin: Vec<u8> = floats.iter().flat_map(|f| f.to_le_bytes()).collect();
    bin.extend([0u16, 1, 2, 0, 2, 3].iter().flat_map(|i| i.to_le_bytes()));
    let bin_path = scratch(&format!("{name}.bin"));
    std::fs::write(&bin_path, &bin).unwrap();
    let mut nodes = vec![
        r#"{"mesh": 0}"#.to_string(),
        // camera 3 m above, looking straight down (−Z rotated onto −Y)
        r#"{"camera": 0, "translation": [0, 3, 0], "rotation": [-0.70710677, 0, 0, 0.70710677]}"#.to_string(),
    ];
    nodes.extend(light_nodes.iter().map(|s| s.to_string()));
    let all: Vec<String> = (0..nodes.len()).map(|i| i.to_string()).collect();
    let json = format!(
        r#"{{"asset": {{"version": "2.0"}}, {extension}
  "scene": 0, "scenes": [{{"nodes": [{all}]}}],
  "nodes": [{nodes}],
  "cameras": [{{"type": "perspective", "perspective": {{"yfov": 0.9, "znear": 0.05}}}}],
  "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0, "NORMAL": 1}}, "indices": 2, "material": 0}}]}}],
  "materials": [{{"pbrMetallicRoughness": {{"baseColorFactor": [0.8, 0.8, 0.8, 1.0], "metallicFactor": 0.0}}}}],
  "buffers": [{{"uri": "{name}.bin", "byteLength": {len}}}],
  "bufferViews": [{{"buffer": 0, "byteOffset": 0, "byteLength": 96, "byteStride": 24}}, {{"buffer": 0, "byteOffset": 96, "byteLength": 12}}],
  "accessors": [
    {{"bufferView": 0, "byteOffset": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-2, 0, -2], "max": [2, 0, 2]}},
    {{"bufferView": 0, "byteOffset": 12, "componentType": 5126, "count": 4, "type": "VEC3"}},
    {{"bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR"}}
  ]}}"#,
        all = all.join(", "),
        nodes = nodes.join(",\n    "),
        len = bin.len()
    );
    let p = scratch(&format!("{name}.gltf"));
    std::fs::write(&p, json).unwrap();
    p
}

/// Mean linear-ish RGB of the central quarter of a PNG.
fn centre_rgb(path: &Path) -> [f64; 3] {
    let img = image::open(path).unwrap().to_rgb8();
    let (w, h) = img.dimensions();
    let mut sum = [0.0; 3];
    let mut n = 0.0;
    for y in h * 3 / 8..h * 5 / 8 {
        for x in w * 3 / 8..w * 5 / 8 {
            let p = img.get_pixel(x, y);
            for c in 0..3 {
                sum[c] += p[c] as f64;
            }
            n += 1.0;
        }
    }
    sum.map(|s| s / n)
}

/// Issue 17's must-show: `strata render` of a glTF carrying `KHR_lights_punctual`
/// lights it with those lights (a red point light above the floor makes the floor
/// red; the same file without the extension gets the default white sun), and
/// `--list-lights` lists them in strata's units (candela ÷ 683).
#[test]
fn gltf_punctual_lights_light_the_render() {
    let lit = floor_gltf(
        "red-bulb",
        r#""extensionsUsed": ["KHR_lights_punctual"], "extensions": {"KHR_lights_punctual": {"lights": [{"type": "point", "color": [1.0, 0.1, 0.1], "intensity": 1366.0}]}},"#,
        &[r#"{"translation": [0, 1.5, 0], "extensions": {"KHR_lights_punctual": {"light": 0}}}"#],
    );
    let plain = floor_gltf("no-lights", "", &[]);
    let o = strata(&["render", "--scene", lit.to_str().unwrap(), "--list-lights"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = stdout(&o);
    assert!(
        out.contains("lights of")
            && out.contains("point position (0.000, 1.500, 0.000)")
            && out.contains("intensity 2"),
        "{out}"
    );
    let mut rgb = Vec::new();
    for (scene, png) in [(&lit, "red-bulb.png"), (&plain, "no-lights.png")] {
        let out = scratch(png);
        let o = strata(&[
            "render",
            "--scene",
            scene.to_str().unwrap(),
            "--width",
            "64",
            "--height",
            "48",
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        rgb.push(centre_rgb(&out));
    }
    eprintln!("centre RGB: red bulb {:?}, default sun {:?}", rgb[0], rgb[1]);
    assert!(
        rgb[0][0] > 1.5 * rgb[0][1] + 10.0,
        "the red bulb lights the floor red: {:?}",
        rgb[0]
    );
    assert!(
        (rgb[1][0] - rgb[1][1]).abs() < 0.25 * rgb[1][0] + 5.0,
        "the default sun is near white: {:?}",
        rgb[1]
    );
}

/// Issue 13: `bzb-ao` renders through the registry, its baseline by a named
/// value (`--set visibility=off`), and out-of-range settings are one line.
#[test]
fn bzb_ao_renders_with_and_without_visibility() {
    for (set, name) in [("visibility=on", "bzb-on.png"), ("visibility=off", "bzb-off.png")] {
        let out = scratch(name);
        let o = strata(&[
            "render",
            "--scene",
            "cornell",
            "--technique",
            "bzb-ao",
            "--set",
            set,
            "--width",
            "32",
            "--height",
            "24",
            "--out",
            out.to_str().unwrap(),
            "--force",
        ]);
        assert!(o.status.success(), "{set}: {}", stderr(&o));
        assert!(out.exists());
    }
    let out = scratch("bzb-bad.png");
    let o = strata(&[
        "render",
        "--scene",
        "cornell",
        "--technique",
        "bzb-ao",
        "--set",
        "directions=17",
        "--width",
        "32",
        "--height",
        "24",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(!o.status.success());
    let e = stderr(&o);
    assert!(e.contains("directions") && e.contains("1..=16"), "{e}");
    assert_eq!(e.trim().lines().count(), 1, "{e}");
}

/// Issue 13 (GI): `bzb-gi` renders through the registry in both modes, and a
/// bad `dmax` is a one-line error naming the setting and its range.
#[test]
fn bzb_gi_renders_with_and_without_visibility() {
    for (set, name) in [("visibility=on", "bzb-gi-on.png"), ("visibility=off", "bzb-gi-off.png")] {
        let out = scratch(name);
        let o = strata(&[
            "render",
            "--scene",
            "cornell",
            "--technique",
            "bzb-gi",
            "--set",
            set,
            "--width",
            "32",
            "--height",
            "24",
            "--out",
            out.to_str().unwrap(),
            "--force",
        ]);
        assert!(o.status.success(), "{set}: {}", stderr(&o));
        assert!(out.exists());
    }
    let out = scratch("bzb-gi-bad.png");
    let o = strata(&[
        "render",
        "--scene",
        "cornell",
        "--technique",
        "bzb-gi",
        "--set",
        "dmax=0",
        "--width",
        "32",
        "--height",
        "24",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(!o.status.success());
    let e = stderr(&o);
    assert!(e.contains("dmax") && e.contains("> 0"), "{e}");
    assert_eq!(e.trim().lines().count(), 1, "{e}");
}

/// `eval --technique bzb-gi --set alpha=0.85` renders `--warmup` frames on the still camera
/// (or along the camera path with `--moving`) before the evaluated one, so its temporal filter averages new directions: the indirect
/// RMSE against the path tracer falls below the single frame's (cornell 64×64, 1024 spp:
/// 0.0039 → 0.0028 with 8 frames). It rendered one frame before, and the two were equal.
/// The JSON records α and the frames; without the filter a frame stands alone (0).
/// `--set exposure` sets the exposure ꟻLIP displays both images at (the scene's before,
/// silently): the RMSE stays, ꟻLIP moves, and the JSON records `display_exposure`.
#[test]
fn eval_bzb_gi_warms_up_its_temporal_filter() {
    let cache = scratch("bzb-gi-temporal-cache");
    let eval = |extra: &[&str]| cornell_eval("bzb-gi", &cache, extra);
    let single = json_of(&eval(&[]));
    let filtered = json_of(&eval(&["--set", "alpha=0.85", "--warmup", "8"]));
    // --set exposure: ꟻLIP displays both images at it (RMSE compares linear values), and
    // the JSON records it
    let exposed = json_of(&eval(&["--set", "exposure=4"]));
    assert_eq!(exposed["display_exposure"], 4.0, "{exposed}");
    assert!(single["display_exposure"].is_null(), "{single}");
    assert_eq!(
        exposed["rmse"], single["rmse"],
        "linear values are compared as they were"
    );
    assert!(
        exposed["flip"].as_f64().unwrap() > single["flip"].as_f64().unwrap() * 1.2,
        "a brighter display shows the noise: {} vs {}",
        exposed["flip"],
        single["flip"]
    );
    assert!(
        single["temporal_alpha"].is_null() && single["warmup_frames"] == 0,
        "{single}"
    );
    assert!(
        (filtered["temporal_alpha"].as_f64().unwrap() - 0.85).abs() < 1e-6 && filtered["warmup_frames"] == 8,
        "{filtered}"
    );
    let (a, b) = (single["rmse"].as_f64().unwrap(), filtered["rmse"].as_f64().unwrap());
    assert!(
        b < 0.85 * a,
        "indirect RMSE {a} one frame vs {b} after 8 frames of the filter"
    );
    // --moving: Cornell has no camera path, so the warm-up along it is the still one
    let moving = json_of(&eval(&["--set", "alpha=0.85", "--warmup", "8", "--moving"]));
    assert_eq!(moving["moving"], true, "{moving}");
    assert_eq!(moving["warmup_frames"], 8, "{moving}");
    assert_eq!(moving["rmse"], filtered["rmse"], "{moving}");
    // --frames: Cornell has no camera path, so a frame with fixed directions repeats
    // exactly (no flicker but the reprojection's rounding), while the filter's new
    // directions every frame move it
    let still = json_of(&eval(&["--frames", "3"]));
    assert_eq!(still["flicker_frames"], 3, "{still}");
    let f = |j: &serde_json::Value| j["flicker"].as_f64().unwrap();
    assert!(f(&still) < 1e-6, "{still}");
    let renewed = json_of(&eval(&["--frames", "3", "--set", "alpha=0.85"]));
    eprintln!(
        "bzb-gi flicker on a still camera: {} fixed directions, {} renewed",
        f(&still),
        f(&renewed)
    );
    assert!(f(&renewed) > 1e-4, "{renewed}");
}

/// `strata eval --technique T` on the Cornell box at 64×64 against a 1024-spp reference
/// cached in `cache`, with `extra` flags, as JSON on stdout.
fn cornell_eval(technique: &str, cache: &std::path::Path, extra: &[&str]) -> std::process::Output {
    let base = [
        "eval",
        "--scene",
        "cornell",
        "--technique",
        technique,
        "--width",
        "64",
        "--height",
        "64",
        "--ref-spp",
        "1024",
        "--json",
        "--quiet",
        "--cache",
        cache.to_str().unwrap(),
    ];
    strata(&[&base[..], extra].concat())
}

/// `eval --technique bzb-ao --set alpha` warms the temporal filter up on the still camera
/// (or along the path with `--moving`), records α and the warm-up in its JSON, and ends
/// closer to the ray-traced binary AO than one frame (no bilateral filter in either, so the
/// comparison isolates the temporal one); along the atrium's path (`--frames`) it flickers
/// less.
#[test]
fn eval_bzb_ao_warms_up_its_temporal_filter() {
    let cache = scratch("bzb-ao-temporal-cache");
    let eval = |extra: &[&str]| {
        json_of(&cornell_eval(
            "bzb-ao",
            &cache,
            &[&["--set", "filter-radius=0"], extra].concat(),
        ))
    };
    let single = eval(&[]);
    let filtered = eval(&["--set", "alpha=0.85", "--warmup", "8"]);
    assert!(
        single["temporal_alpha"].is_null() && single["warmup_frames"].is_null(),
        "{single}"
    );
    assert!(
        (filtered["temporal_alpha"].as_f64().unwrap() - 0.85).abs() < 1e-6 && filtered["warmup_frames"] == 8,
        "{filtered}"
    );
    let rmse = |j: &serde_json::Value| j["binary"]["rmse"].as_f64().unwrap();
    let (a, b) = (rmse(&single), rmse(&filtered));
    assert!(
        b < 0.6 * a,
        "binary-AO RMSE {a} one frame vs {b} after 8 frames of the filter"
    );
    // --moving: Cornell has no camera path, so the warm-up is the still one
    let moving = eval(&["--set", "alpha=0.85", "--warmup", "8", "--moving"]);
    assert_eq!(moving["moving"], true, "{moving}");
    assert_eq!(rmse(&moving), b);
    // BZB §6's reason for the re-projection: flicker along the atrium's camera path
    let flicker = |alpha: &str| {
        let j = json_of(&strata(&[
            "eval",
            "--scene",
            "atrium",
            "--technique",
            "bzb-ao",
            "--width",
            "160",
            "--height",
            "90",
            "--frames",
            "10",
            "--ref-spp",
            "64",
            "--set",
            alpha,
            "--json",
            "--quiet",
            "--cache",
            cache.to_str().unwrap(),
        ]));
        assert_eq!(j["flicker_frames"], 10, "{j}");
        j["flicker"].as_f64().unwrap()
    };
    let (none, filtered) = (flicker("alpha=0"), flicker("alpha=0.85"));
    assert!(
        filtered < 0.8 * none,
        "flicker {none} one frame at a time vs {filtered} with the temporal filter"
    );
}

/// The side-by-side evaluations (`bzb-ao`, `aba-ao`, `bzb-gi`) write a JSON with every
/// configuration's errors and, with `--report`, a page with one error row per configuration
/// (the JSON's numbers) and each configuration's image and ꟻLIP maps beside the references:
/// every file on disk, distinct images for distinct configurations.
#[test]
fn side_by_side_evals_write_json_and_report_pages() {
    let cache = scratch("side-by-side-cache");
    for (technique, images) in [
        (
            "bzb-ao",
            &[
                "reference-binary.png",
                "bzb-ao.png",
                "bzb-ao-visibility-off-additive.png",
                "ao-2-layers.png",
                "flip-binary-bzb-ao.png",
            ][..],
        ),
        (
            "aba-ao",
            &[
                "reference-obscurance.png",
                "aba-ao.png",
                "aba-ao-multilayer-off.png",
                "flip-obscurance-aba-ao.png",
            ][..],
        ),
        (
            "bzb-gi",
            &[
                "reference-indirect.png",
                "indirect-bzb-gi.png",
                "indirect-bzb-gi-visibility-off-additive.png",
                "full-dgb-radiosity-2-layers-one-bounce.png",
                "flip-indirect-bzb-gi.png",
            ][..],
        ),
    ] {
        let report = scratch(&format!("side-by-side-{technique}"));
        let _ = std::fs::remove_dir_all(&report);
        let v = json_of(&strata(&[
            "eval",
            "--scene",
            "cornell",
            "--technique",
            technique,
            "--width",
            "32",
            "--height",
            "24",
            "--ref-spp",
            "16",
            "--json",
            "--quiet",
            "--cache",
            cache.to_str().unwrap(),
            "--report",
            report.to_str().unwrap(),
        ]));
        assert_eq!(v["technique"], technique, "{v}");
        let others = if technique == "aba-ao" {
            ["layers_1", "dgb_2_layers"]
        } else {
            ["no_visibility", "dgb_2_layers"]
        };
        for x in [&v, &v[others[0]], &v[others[1]]] {
            let flip = x["flip"]
                .as_f64()
                .unwrap_or_else(|| panic!("{technique}: no flip in {x}"));
            assert!(flip > 0.0 && flip < 1.0, "{technique}: FLIP {flip}");
        }
        let html = std::fs::read_to_string(report.join("index.html")).unwrap();
        // one error row per configuration, with the JSON's numbers
        assert!(
            html.contains("Errors by configuration"),
            "{technique}: no configuration table"
        );
        for x in [&v, &v[others[0]], &v[others[1]]] {
            let flip = format!("{:.4}", x["flip"].as_f64().unwrap());
            assert!(html.contains(&flip), "{technique}: FLIP {flip} not on the page");
        }
        for f in images {
            assert!(
                html.contains(f) && report.join(f).exists(),
                "{technique}: {f} missing from the report"
            );
        }
        let (a, b) = (
            std::fs::read(report.join(images[1])).unwrap(),
            std::fs::read(report.join(images[2])).unwrap(),
        );
        assert_ne!(a, b, "{technique}: two configurations wrote the same image");
    }
}

/// Issue 13 (DSS): `--set splat=dss` renders in both modes with the surfel
/// counts printed by `--timings`, and bad DSS settings are one-line errors naming the setting.
#[test]
fn bzb_ao_dss_renders_and_range_checks_its_settings() {
    for (set, name) in [("visibility=on", "dss-on.png"), ("visibility=off", "dss-off.png")] {
        let out = scratch(name);
        let o = strata(&[
            "render",
            "--scene",
            "cornell",
            "--technique",
            "bzb-ao",
            "--set",
            "splat=dss",
            "--set",
            set,
            "--set",
            "levels=2",
            "--width",
            "32",
            "--height",
            "24",
            "--timings",
            "--out",
            out.to_str().unwrap(),
            "--force",
        ]);
        assert!(o.status.success(), "{set}: {}", stderr(&o));
        assert!(out.exists());
        assert!(stderr(&o).contains("dss surfelization:"), "{}", stderr(&o));
        assert!(stderr(&o).contains("dss-splat"), "{}", stderr(&o));
    }
    for (set, needle) in [("levels=7", "1..=6"), ("surfel-size=0.1", "16"), ("splat=gpu", "splat")] {
        let out = scratch("dss-bad.png");
        let o = strata(&[
            "render",
            "--scene",
            "cornell",
            "--technique",
            "bzb-ao",
            "--set",
            set,
            "--width",
            "32",
            "--height",
            "24",
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(!o.status.success(), "{set}");
        let e = stderr(&o);
        let name = set.split('=').next().unwrap();
        assert!(e.contains(name) && e.contains(needle), "{set}: {e}");
        assert_eq!(e.trim().lines().count(), 1, "{e}");
    }
}

/// Issue 12: `strata eval --technique oit` compares the A-buffer's composite with the CPU
/// compositing of every crossing (glasshouse: ≤ 0.02 ꟻLIP, the issue's bound) for every
/// construction; a pool too small for the fragments drops some, says how many in the JSON and
/// warns; `render --technique oit` writes the image.
#[test]
fn eval_oit_matches_the_cpu_compositing_and_reports_overflow() {
    // eval --technique oit on glasshouse at `size`, then `extra`
    let oit = |size: [&str; 2], extra: &[&str]| {
        let mut a = vec![
            "eval",
            "--scene",
            "glasshouse",
            "--technique",
            "oit",
            "--width",
            size[0],
            "--height",
            size[1],
        ];
        a.extend_from_slice(extra);
        strata(&a)
    };
    for method in ["linked-list", "linear", "fixed-array", "dual-peel"] {
        let set = format!("abuffer={method}");
        let v = json_of(&oit(["96", "54"], &["--json", "--set", &set]));
        let flip = v["flip"].as_f64().unwrap();
        assert!(flip <= 0.02, "{method}: ꟻLIP {flip}");
        assert!(v["fragments"].as_u64().unwrap() > 96 * 54, "{method}: {v}");
        assert!(
            v["max_fragments_per_pixel"].as_u64().unwrap() >= 8,
            "glasshouse has ≥ 8 layers somewhere: {v}"
        );
    }
    let o = oit(["96", "54"], &["--json", "--set", "pool=500"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let (total, dropped) = (v["fragments"].as_u64().unwrap(), v["dropped"].as_u64().unwrap());
    assert_eq!(dropped, total - 500, "{v}");
    assert!(stderr(&o).contains("dropped"), "{}", stderr(&o));
    // --report: the page and its images exist (it had printed "wrote" and written nothing)
    let report = scratch("oit-report");
    let _ = std::fs::remove_dir_all(&report);
    let report_arg = report.to_str().unwrap();
    let v = json_of(&oit(["96", "54"], &["--json", "--report", report_arg]));
    let html = std::fs::read_to_string(report.join("index.html")).expect("the report page");
    for f in ["reference.png", "oit.png", "flip-oit.png"] {
        assert!(
            html.contains(f) && report.join(f).exists(),
            "{f} missing from the report"
        );
    }
    let flip = format!("{:.4}", v["flip"].as_f64().unwrap());
    assert!(html.contains(&flip), "ꟻLIP {flip} not on the page");
    assert_one_line_error(&oit(["96", "54"], &["--report", report_arg]), &["--report", "--force"]);
    // flags the exact composite does not read: one warning line each, and it still runs;
    // --guard-band is read (a wider frame), so no warning names it
    let o = oit(
        ["32", "24"],
        &["--warmup", "5", "--samples", "5", "--ref-spp", "4", "--guard-band", "8"],
    );
    let warned = flag_warnings(&o);
    for flag in ["--warmup", "--samples", "--ref-spp"] {
        assert!(
            warned
                .iter()
                .any(|l| l.contains(flag) && l.contains("not read by eval --technique oit")),
            "{flag}: {warned:?}"
        );
    }
    assert_eq!(warned.len(), 3, "{warned:?}");
    let out = scratch("oit.png");
    let o = strata(&[
        "render",
        "--scene",
        "glasshouse",
        "--technique",
        "oit",
        "--width",
        "64",
        "--height",
        "36",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(out.exists());
    let o = strata(&[
        "render",
        "--scene",
        "glasshouse",
        "--technique",
        "oit",
        "--width",
        "64",
        "--height",
        "36",
        "--set",
        "pool=100",
        "--force",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("A-buffer: dropped") && stderr(&o).contains("(pool 100 nodes"),
        "{}",
        stderr(&o)
    );
}

/// Issue 12: `strata bench abuffer --json` carries ABA Table I's stages for the four
/// constructions and the compressed path, with memory and overflow per method; only
/// `linear` has count and prefix-sum passes; every method stores the same fragments.
#[test]
fn bench_abuffer_reports_table_one_per_method() {
    let v = json_of(&strata(&[
        "bench",
        "abuffer",
        "--scene",
        "glasshouse",
        "--width",
        "64",
        "--height",
        "36",
        "--frames",
        "1",
        "--json",
    ]));
    let m = &v["methods"];
    let fragments = m["linked-list"]["fragments"].as_u64().unwrap();
    assert!(fragments > 64 * 36, "{v}");
    for key in ["linked-list", "linear", "fixed-array", "dual-peel", "compressed"] {
        let x = &m[key];
        assert!(x["total_ms"].as_f64().unwrap() > 0.0, "{key}: {x}");
        assert!(
            x["draw_ms"].as_f64().unwrap() > 0.0 && x["resolve_ms"].as_f64().unwrap() > 0.0,
            "{key}"
        );
        assert!(x["memory_bytes"].as_u64().unwrap() > 0, "{key}");
        assert_eq!(x["fragments"].as_u64().unwrap(), fragments, "{key}: the same geometry");
        assert_eq!(x["count_ms"].is_null(), key != "linear", "{key}: {x}");
        assert_eq!(x["prefix_sum_ms"].is_null(), key != "linear", "{key}");
    }
}

/// Issue 12, Table II: `--set multires=4` runs every construction's AO on 4
/// resolution levels (the rows say so); `multires=5` is a one-line range error.
#[test]
fn bench_abuffer_table_two_with_multires() {
    let v = json_of(&strata(&[
        "bench",
        "abuffer",
        "--scene",
        "glasshouse",
        "--width",
        "64",
        "--height",
        "36",
        "--frames",
        "1",
        "--set",
        "multires=4",
        "--json",
    ]));
    let m = &v["methods"];
    for key in ["linked-list", "linear", "fixed-array", "dual-peel", "compressed"] {
        let x = &m[key];
        assert!(
            x["ao_ms"].as_f64().unwrap() > 0.0 && x["total_ms"].as_f64().unwrap() > 0.0,
            "{key}: {x}"
        );
        assert_eq!(x["stage"]["multires"].as_u64(), Some(4), "{key}: {x}");
    }
    let o = strata(&[
        "bench",
        "abuffer",
        "--scene",
        "glasshouse",
        "--width",
        "32",
        "--height",
        "18",
        "--frames",
        "1",
        "--set",
        "multires=5",
    ]);
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("multires") && err.trim().lines().count() == 1, "{err}");
}

/// Issue 12 item 6: `--set kernel=hbao-compute` turns `bench abuffer` into ABA Table
/// III: the list columns run the fragment HBAO with the compute kernel's axis taps, the
/// compressed column the compute HBAO (§V-B), plus `compressed-fragment` and
/// `single-layer` rows; the compute kernel without compression is a one-line error.
#[test]
fn bench_abuffer_table_three_with_the_compute_hbao() {
    let v = json_of(&strata(&[
        "bench",
        "abuffer",
        "--scene",
        "atrium",
        "--width",
        "64",
        "--height",
        "36",
        "--frames",
        "1",
        "--set",
        "kernel=hbao-compute",
        "--json",
    ]));
    let m = &v["methods"];
    for (key, kernel, multilayer) in [
        ("linked-list", "Hbao", true),
        ("dual-peel", "Hbao", true),
        ("compressed", "HbaoCompute", true),
        ("compressed-fragment", "Hbao", true),
        ("single-layer", "HbaoCompute", false),
    ] {
        let x = &m[key];
        assert!(x["ao_ms"].as_f64().unwrap() > 0.0, "{key}: {x}");
        let st = &x["stage"];
        assert_eq!(st["kernel"].as_str(), Some(kernel), "{key}: {st}");
        assert_eq!(st["multilayer"].as_bool(), Some(multilayer), "{key}: {st}");
    }
    // the same axis taps over lists and over M = 6 nodes of an opaque scene
    let flip = v["ao_flip_compressed_vs_brute"].as_f64().unwrap();
    assert!(flip < 0.02, "FLIP {flip}");
    let o = strata(&[
        "render",
        "--scene",
        "atrium",
        "--technique",
        "aba-ao",
        "--width",
        "32",
        "--height",
        "18",
        "--set",
        "kernel=hbao-compute",
        "--set",
        "compress=0",
        "--out",
        scratch("hbao-compute-nocompress.png").to_str().unwrap(),
    ]);
    assert!(!o.status.success());
    let e = stderr(&o);
    assert!(e.contains("hbao-compute") && e.contains("compress"), "{e}");
    assert_eq!(e.trim().lines().count(), 1, "one line: {e}");
}

#[test]
fn ils_progressive_mode_converges_and_approaches_the_path_tracer() {
    // ILS §6.3: fresh VPL sets per frame (2 bounces, VPL shadow maps); the running
    // mean reaches 1 % RMS of the converged image of the same estimator, and its
    // distance to the path tracer falls with the frames down to the clamp bias
    let cache = scratch("ils-progressive-cache");
    let v = json_of(&strata(&[
        "eval",
        "--scene",
        "cornell",
        "--technique",
        "ils",
        "--width",
        "48",
        "--height",
        "48",
        "--set",
        "vpls=24",
        "--progressive",
        "16",
        "--bounces",
        "2",
        "--ref-noise",
        "0.03",
        "--cache",
        cache.to_str().unwrap(),
        "--json",
    ]));
    let p = &v["progressive"];
    assert_eq!(p["bounces"].as_u64(), Some(2));
    let patterns = p["patterns"].as_array().expect("patterns");
    assert_eq!(patterns.len(), 2, "1x1 and 2x2");
    for q in patterns {
        let curve: Vec<f64> = q["rms_curve"]
            .as_array()
            .unwrap()
            .iter()
            .map(|e| e[1].as_f64().unwrap())
            .collect();
        assert!(
            curve.first().unwrap() > curve.last().unwrap(),
            "{}: {curve:?}",
            q["pattern"]
        );
    }
    let one = &patterns[0];
    assert_eq!(one["pattern"], "1x1");
    // the per-set deviation σ₁ predicts when the running mean crosses 1 % of the K-set
    // converged image: ‖mean_N − converged_K‖ ≈ σ₁·√(1/N + 1/K) (independent sets)
    let (sigma, k) = (one["per_set_rel_rms"].as_f64().unwrap(), p["sets"].as_f64().unwrap());
    let slack = (0.01 / sigma).powi(2) - 1.0 / k;
    assert!(slack > 0.0, "σ₁ {sigma}: 1 % unreachable against {k} sets");
    let predicted = (1.0 / slack).ceil();
    let measured = one["frames_to_target"].as_f64().expect("cornell reaches 1 %");
    assert!(
        measured >= predicted / 2.0 && measured <= predicted * 2.0,
        "crossing after {measured} frames, σ₁ {sigma} predicts {predicted}"
    );
    assert_eq!(
        one["predicted_frames_to_target"].as_f64().unwrap(),
        (sigma / 0.01).powi(2).ceil().max(1.0)
    );
    // the VPL-dependent passes (shadow maps, SSM) are part of every frame, and a static
    // view pays the rest once
    for q in patterns {
        let (dep, all) = (
            q["vpl_dependent_ms_per_frame"].as_f64().unwrap(),
            q["gpu_ms_per_frame"].as_f64().unwrap(),
        );
        assert!(dep > 0.0 && dep < all, "{}: {dep} of {all} ms", q["pattern"]);
        let frames = q["predicted_frames_to_target"].as_f64().unwrap();
        let fixed = q["predicted_static_view_gpu_ms_to_target"].as_f64().unwrap();
        assert!(
            (fixed - (all - dep + frames * dep)).abs() < 1e-6 * all.max(1.0),
            "{fixed}"
        );
    }
    let pt: Vec<(u64, f64)> = one["rms_vs_path_tracer"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| (e[0].as_u64().unwrap(), e[1].as_f64().unwrap()))
        .collect();
    assert_eq!(pt.iter().map(|e| e.0).collect::<Vec<_>>(), vec![1, 2, 4, 8, 16]);
    // monotone within noise (each count at most 10 % above the previous) and falling overall
    for w in pt.windows(2) {
        assert!(w[1].1 <= 1.1 * w[0].1, "{pt:?}");
    }
    assert!(pt[4].1 < 0.8 * pt[0].1, "{pt:?}");
    // what remains is the bias of the converged image (clamp, singularities)
    let bias = p["converged_vs_path_tracer"]["rmse"].as_f64().unwrap();
    assert!(bias > 0.0);
}

/// `--probe-grid` and `--probe-rays` reach the bake (the notice names the count, shape
/// and paths; each bake is cached apart, a repeated one is not baked again) and a
/// malformed or out-of-range value is one line naming the flag and the range.
#[test]
fn probe_grid_and_rays_reach_the_bake_and_are_range_checked() {
    let out = scratch("probe-grid.png");
    let bad_run = |flag: &str, bad: &str| {
        strata(&[
            "render",
            "--scene",
            "cornell",
            "--technique",
            "full",
            flag,
            bad,
            "--out",
            out.to_str().unwrap(),
        ])
    };
    for bad in ["0,8,16", "16,8", "64,64,64", "a,b,c"] {
        assert_one_line_error(&bad_run("--probe-grid", bad), &["--probe-grid", "1..=64", "32768"]);
    }
    for bad in ["0", "63", "1048577", "x"] {
        assert_one_line_error(&bad_run("--probe-rays", bad), &["--probe-rays", "64..=1048576"]);
    }
    let cache = scratch("probe-grid-cache");
    let _ = std::fs::remove_dir_all(&cache);
    let run = |grid: &str, rays: &str| full_at_32x24(&cache, "cornell", grid, rays, &out, &[]);
    let e = run("2,3,2", "256");
    assert!(e.contains("baking 12 light probes (2×3×2, 256 paths each)"), "{e}");
    let e = run("2,3,2", "256");
    assert!(!e.contains("baking"), "a cached bake is baked again: {e}");
    let e = run("3,2,2", "256");
    assert!(e.contains("baking 12 light probes (3×2×2,"), "{e}");
    let e = run("3,2,2", "512");
    assert!(e.contains("baking 12 light probes (3×2×2, 512 paths each)"), "{e}");
}

/// `bench ils`, `abuffer` and `bzb` time no second layer: `--layers` and `--variant` given to
/// them get a one-line warning each and the bench runs; not given, no warning.
#[test]
fn benches_without_a_second_layer_warn_of_layer_flags() {
    for bench in ["ils", "abuffer", "bzb"] {
        let args = |extra: &[&'static str]| {
            let mut a = vec![
                "bench", bench, "--scene", "cornell", "--frames", "1", "--width", "32", "--height", "32", "--json",
            ];
            a.extend_from_slice(extra);
            strata(&a)
        };
        let o = args(&["--layers", "3", "--variant", "peel"]);
        let warned = flag_warnings(&o);
        assert_eq!(warned.len(), 2, "{bench}: {warned:?}");
        for flag in ["--layers", "--variant"] {
            let needle = format!("{flag} is not read by bench {bench}");
            assert!(warned.iter().any(|l| l.contains(&needle)), "{bench}: {warned:?}");
        }
        let o = args(&[]);
        assert!(o.status.success(), "{bench}: {}", stderr(&o));
        assert!(!stderr(&o).contains("strata: warning: --"), "{bench}: {}", stderr(&o));
    }
}

/// `bench deep-gbuffer` (DGB Table 5, Fig. 3) and, with `--layer-scale`, Fig. 11: every method
/// builds its layers one submission per layer, the upsampling is part of layer 2's time, and
/// the JSON and the report say the scale.
#[test]
fn bench_deep_gbuffer_with_a_reduced_second_layer() {
    let bench = |scale: &str| {
        json_of(&strata(&[
            "bench",
            "deep-gbuffer",
            "--scene",
            "atrium",
            "--width",
            "48",
            "--height",
            "32",
            "--frames",
            "2",
            "--layer-scale",
            scale,
            "--json",
        ]))
    };
    let full = bench("1");
    let reduced = bench("2");
    assert_eq!(full["layer_scale"].as_u64(), Some(1), "{full}");
    assert_eq!(reduced["layer_scale"].as_u64(), Some(2), "{reduced}");
    let rows = |v: &serde_json::Value| v["rows"].as_array().unwrap().clone();
    assert_eq!(rows(&full).len(), 6, "single layer and the five variants");
    for r in rows(&reduced) {
        let method = r["method"].as_str().unwrap();
        assert_eq!(r["submission"], "per-layer", "{r}");
        assert!(r["multiview_total_ms"].is_null(), "{r}");
        if method == "single-layer" {
            assert!(r["upsample_ms"].is_null(), "{r}");
            continue;
        }
        let up = r["upsample_ms"]
            .as_f64()
            .unwrap_or_else(|| panic!("{method}: no upsampling time: {r}"));
        assert!(up > 0.0 && up.is_finite(), "{r}");
        // the peel times its second layer inside each frame, upsampling included, so its
        // median lies above the upsampling's; the single-pass methods' layer 2 is their
        // frame minus the single-layer frame of other runs, which timing noise can push
        // below it (a test of timings would be flaky)
        if method == "peel" {
            assert!(up <= r["layer2_ms"].as_f64().unwrap(), "{r}");
        }
    }
    // at full resolution there is no upsampling
    assert!(rows(&full).iter().all(|r| r["upsample_ms"].is_null()), "{full}");
    // the report names the scale
    let dir = scratch("deep-report");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("bench-deep.json"), reduced.to_string()).unwrap();
    let page = dir.join("report.html");
    let o = strata(&[
        "report",
        "--from",
        dir.to_str().unwrap(),
        "--out",
        page.to_str().unwrap(),
        "--force",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let html = std::fs::read_to_string(&page).unwrap();
    assert!(html.contains("layers ≥ 1 at 1/2 resolution") && html.contains("of which upsampling"));
}

/// The main job (`scripts/demo.sh`, the README's first command) renders every registered
/// technique, evaluates every one with an eval kind against its reference, and times
/// every one: a technique added to the registry and not to the main job fails here.
#[test]
fn the_main_job_renders_evaluates_and_times_every_registered_technique() {
    use std::collections::BTreeSet;
    use strata_render::technique::{find, registry, EvalKind};
    let demo = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scripts/demo.sh");
    let text = std::fs::read_to_string(&demo).unwrap();
    let (mut rendered, mut evaluated, mut timed) = (BTreeSet::new(), BTreeSet::new(), BTreeSet::new());
    // commands continued over lines with a backslash are one command
    for line in text.replace("\\\n", " ").lines() {
        let words: Vec<&str> = line.split_whitespace().collect();
        let Some(at) = words.iter().position(|w| *w == "$S") else {
            continue;
        };
        // `eval` takes `gi` for `full`
        let given = words
            .windows(2)
            .find(|w| w[0] == "--technique")
            .map(|w| if w[1] == "gi" { "full" } else { w[1] });
        let name = |default: &str| find(given.unwrap_or(default)).unwrap().name;
        match (words.get(at + 1).copied(), words.get(at + 2).copied()) {
            (Some("render"), _) => rendered.insert(name("direct")),
            (Some("eval"), _) => evaluated.insert(name("ao")),
            // what each bench subcommand times (`strata bench --help`)
            (Some("bench"), Some(sub)) => match sub {
                "gbuffer" => timed.insert("direct"),
                "ao" => timed.insert("ao"),
                "radiosity" | "reflections" => timed.insert("full"),
                "ils" => timed.insert("ils"),
                "abuffer" => timed.insert("oit") | timed.insert("aba-ao"),
                "bzb" => timed.insert(name("bzb-ao")),
                "technique" => timed.insert(name("")),
                "deep-gbuffer" | "reference" => false,
                other => panic!("bench {other}: say here which techniques it times"),
            },
            _ => false,
        };
    }
    for t in registry() {
        assert!(rendered.contains(t.name), "scripts/demo.sh renders no '{}'", t.name);
        assert!(timed.contains(t.name), "scripts/demo.sh times no '{}'", t.name);
        if t.eval != EvalKind::None {
            assert!(evaluated.contains(t.name), "scripts/demo.sh evaluates no '{}'", t.name);
        }
    }
}

/// `render --technique full` bakes the reflections' environment map (DGB §3.6's fallback)
/// for a scene with a mirror material, once (then from the cache), never for a scene
/// without one, and not with `--no-probes`.
#[test]
fn full_bakes_an_environment_map_for_scenes_with_mirrors() {
    let cache = scratch("environment-cache");
    let _ = std::fs::remove_dir_all(&cache);
    let out = scratch("environment.png");
    let run = |scene: &str, extra: &[&str]| full_at_32x24(&cache, scene, "2,2,2", "64", &out, extra);
    let baking = "baking the reflections' environment map";
    assert!(
        !run("mirror", &["--no-probes"]).contains(baking),
        "--no-probes bakes no fallback"
    );
    assert!(run("mirror", &[]).contains(baking));
    assert!(
        !run("mirror", &[]).contains(baking),
        "a cached environment map is baked again"
    );
    assert!(!run("cornell", &[]).contains(baking), "cornell has no mirror");
}

/// `render --technique full` of `scene` at 32×24 with a `grid` of probes, `rays` paths
/// each, and `extra` flags, with `$STRATA_CACHE` = `cache`; it succeeds; its stderr.
fn full_at_32x24(cache: &Path, scene: &str, grid: &str, rays: &str, out: &Path, extra: &[&str]) -> String {
    let mut args = vec![
        "render",
        "--scene",
        scene,
        "--technique",
        "full",
        "--probe-grid",
        grid,
        "--probe-rays",
        rays,
        "--width",
        "32",
        "--height",
        "24",
        "--force",
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    let o = strata_cached(&args, cache);
    assert!(o.status.success(), "{}", stderr(&o));
    stderr(&o)
}

/// `--exposure auto` meters the frame (the metered value is printed and differs from the
/// scene's), `auto:KEY` scales it by KEY, and bad values are one-line errors naming the
/// flag and the range.
#[test]
fn exposure_auto_meters_the_frame() {
    let out = scratch("exposure-auto.png");
    let metered = |mode: &str| {
        let o = strata(&[
            "render",
            "--scene",
            "cornell",
            "--width",
            "64",
            "--height",
            "64",
            "--exposure",
            mode,
            "--out",
            out.to_str().unwrap(),
            "--force",
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        let err = stderr(&o);
        let line = err.lines().find(|l| l.starts_with("exposure (metered): ")).expect(&err);
        line["exposure (metered): ".len()..].trim().parse::<f32>().unwrap()
    };
    let e = metered("auto");
    // the Cornell box's scene exposure is 1; its lit walls meter brighter than that needs
    assert!(e > 1.5, "{e}");
    let half = metered("auto:0.09");
    assert!((half / e - 0.5).abs() < 1e-3, "key 0.09 against 0.18: {half} vs {e}");
    assert_eq!(metered("auto:key=0.09"), half, "the named key");
    // the darker half of the non-black pixels needs more exposure than the brighter half
    let dark = metered("auto:low=0,high=0.5");
    assert!(dark > 1.5 * e, "window 0..0.5: {dark} against 0.5..0.95: {e}");
    for (args, needles) in [
        (&["--exposure", "auto:0"][..], &["--exposure", "(0, 10]"][..]),
        (&["--exposure", "auto:x"], &["--exposure", "auto:KEY"]),
        (
            &["--exposure", "auto:adapt=0"],
            &["--exposure", "adaptation 0", "(0, 1]"],
        ),
        (
            &["--exposure", "auto:speed=1"],
            &["--exposure", "'speed'", "key, adapt, low and high"],
        ),
        (
            &["--exposure", "auto:low=0.9,high=0.5"],
            &["--exposure", "0 <= low < high <= 1"],
        ),
        (&["--exposure", "-2"], &["--exposure", "must be > 0"]),
        // the technique setting `exposure` is the fixed exposure: not beside auto
        (
            &["--exposure", "auto", "--set", "exposure=2"],
            &["exposure 2", "auto-exposure", "both"],
        ),
    ] {
        let o = strata(
            &[
                &["render", "--scene", "cornell", "--out", out.to_str().unwrap()][..],
                args,
            ]
            .concat(),
        );
        assert_one_line_error(&o, needles);
    }
}

/// `--exposure auto:adapt=A` weighs each frame's metering by A in log space: `render`
/// then warms the frame up along the camera path like a temporal filter's, so the
/// exposure lags towards the earlier frames' meterings; after a cut (`--warmup 0`) the
/// first frame takes its metering at once.
#[test]
fn exposure_auto_adapts_along_the_camera_path() {
    let out = scratch("exposure-adapt.png");
    let metered = |mode: &str, frame: &str, warmup: Option<&str>| {
        let mut args = vec![
            "render",
            "--scene",
            "atrium",
            "--width",
            "64",
            "--height",
            "64",
            "--frame",
            frame,
            "--exposure",
            mode,
            "--out",
        ];
        args.push(out.to_str().unwrap());
        args.push("--force");
        if let Some(w) = warmup {
            args.extend(["--warmup", w]);
        }
        let o = strata(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        let err = stderr(&o);
        let line = err.lines().find(|l| l.starts_with("exposure (metered): ")).expect(&err);
        line["exposure (metered): ".len()..].trim().parse::<f32>().unwrap()
    };
    let (early, now) = (metered("auto", "2", Some("0")), metered("auto", "10", Some("0")));
    assert!(
        (early - now).abs() > 1e-3,
        "the metering changes along the path: {early} {now}"
    );
    assert_eq!(
        metered("auto:adapt=0.25", "10", Some("0")),
        now,
        "a cut takes the metering at once"
    );
    // the default warm-up (8 frames, 2..=9) applies because the exposure adapts
    let lagged = metered("auto:adapt=0.25", "10", None);
    eprintln!("metered: frame 2 {early}, frame 10 {now}, adapted over frames 2..=10 {lagged}");
    assert!(
        (lagged - now).abs() > 1e-4 && (lagged - early).abs() < (now - early).abs(),
        "adapted {lagged} lies between frame 2's {early} and frame 10's {now}"
    );
}
