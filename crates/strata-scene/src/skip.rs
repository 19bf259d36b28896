//! Tests that cannot run here (e.g. `../shared` is absent) say so: the reason goes
//! to stderr and, when `STRATA_SKIP_LOG` names a file, is appended to it, so the
//! test command can print how many tests skipped instead of letting a skip pass
//! for a success (`scripts/test.sh`).

use std::io::Write;

/// Records that the calling test skipped, and why.
pub fn note_skip(test: &str, reason: &str) {
    eprintln!("skipping {test}: {reason}");
    if let Some(path) = std::env::var_os("STRATA_SKIP_LOG") {
        if let Ok(mut f) = std::fs::OpenOptions::new().create(true).append(true).open(path) {
            // one write per line: tests run in parallel, and a single append is atomic
            let _ = f.write_all(format!("{test}: {reason}\n").as_bytes());
        }
    }
}
