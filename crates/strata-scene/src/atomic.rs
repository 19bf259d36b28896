//! Output files that are never half-written: each is written to a temporary file
//! beside its destination and renamed into place (a rename within one directory is
//! atomic on POSIX file systems). Temporary files of writes in flight are
//! registered so an interrupt handler can remove them ([`remove_in_flight`]).

use std::path::{Path, PathBuf};
use std::sync::Mutex;

static IN_FLIGHT: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

fn in_flight() -> std::sync::MutexGuard<'static, Vec<PathBuf>> {
    IN_FLIGHT.lock().unwrap_or_else(|p| p.into_inner())
}

/// The temporary name for `path`: hidden, in the same directory, tagged with the
/// process id, and keeping the extension (encoders choose the format by it).
pub fn temp_path(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let tmp_name = match path.extension() {
        Some(ext) => {
            let stem = path
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default();
            format!(".{stem}.tmp{}.{}", std::process::id(), ext.to_string_lossy())
        }
        None => format!(".{name}.tmp{}", std::process::id()),
    };
    path.with_file_name(tmp_name)
}

/// Writes `path` through `write`, which receives the temporary path to write to;
/// on success the temporary file is renamed to `path`, on failure it is removed
/// and `path` is untouched.
pub fn write_with(path: &Path, write: impl FnOnce(&Path) -> Result<(), String>) -> Result<(), String> {
    let tmp = temp_path(path);
    in_flight().push(tmp.clone());
    let result = write(&tmp).and_then(|()| {
        std::fs::rename(&tmp, path)
            .map_err(|e| format!("{}: cannot move the finished file into place: {e}", path.display()))
    });
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    in_flight().retain(|p| p != &tmp);
    result
}

/// Writes `bytes` to `path` atomically.
pub fn write(path: &Path, bytes: &[u8]) -> Result<(), String> {
    write_with(path, |tmp| {
        std::fs::write(tmp, bytes).map_err(|e| format!("{}: cannot write: {e}", path.display()))
    })
}

/// Removes the temporary files of every write in flight (for an interrupt
/// handler: the destinations were never touched). Returns how many it removed.
pub fn remove_in_flight() -> usize {
    let paths: Vec<PathBuf> = in_flight().drain(..).collect();
    paths.iter().filter(|p| std::fs::remove_file(p).is_ok()).count()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `remove_in_flight` is process-wide: these tests must not interleave.
    static SERIAL: Mutex<()> = Mutex::new(());

    fn serial() -> std::sync::MutexGuard<'static, ()> {
        SERIAL.lock().unwrap_or_else(|p| p.into_inner())
    }

    fn dir(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("strata-atomic-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    #[test]
    fn temp_names_keep_the_extension_and_stay_beside() {
        let t = temp_path(Path::new("/a/b/out.png"));
        assert_eq!(t.parent(), Some(Path::new("/a/b")));
        assert_eq!(t.extension().unwrap(), "png");
        assert!(t.file_name().unwrap().to_string_lossy().starts_with(".out.tmp"));
        assert!(temp_path(Path::new("x")).to_string_lossy().starts_with(".x.tmp"));
    }

    #[test]
    fn success_replaces_and_leaves_no_temporary() {
        let _serial = serial();
        let d = dir("ok");
        let p = d.join("f.txt");
        std::fs::write(&p, b"old").unwrap();
        write(&p, b"new").unwrap();
        assert_eq!(std::fs::read(&p).unwrap(), b"new");
        assert_eq!(std::fs::read_dir(&d).unwrap().count(), 1);
    }

    #[test]
    fn failure_keeps_the_old_file_and_removes_the_temporary() {
        let _serial = serial();
        let d = dir("fail");
        let p = d.join("f.txt");
        std::fs::write(&p, b"old").unwrap();
        let r = write_with(&p, |tmp| {
            std::fs::write(tmp, b"half").unwrap();
            Err("encoder failed".into())
        });
        assert!(r.is_err());
        assert_eq!(std::fs::read(&p).unwrap(), b"old");
        assert_eq!(std::fs::read_dir(&d).unwrap().count(), 1);
    }

    #[test]
    fn in_flight_temporaries_can_be_removed() {
        let _serial = serial();
        let d = dir("flight");
        let p = d.join("f.bin");
        let r = write_with(&p, |tmp| {
            std::fs::write(tmp, b"partial").unwrap();
            // an interrupt arriving now removes the temporary; the rename then fails
            assert!(remove_in_flight() >= 1);
            Ok(())
        });
        assert!(r.is_err());
        assert!(!p.exists());
        assert_eq!(std::fs::read_dir(&d).unwrap().count(), 0);
    }
}
