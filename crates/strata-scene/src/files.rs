//! Where loaders read the files a scene file refers to (OBJ material
//! libraries, textures, glTF buffers and images).
//!
//! [`DiskFiles`] reads regular files only (never devices, FIFOs or folders, so
//! a reference to `/dev/zero` is an error, not an endless read) of at most
//! [`MAX_FILE_BYTES`]. [`MemFiles`] serves files from memory (tests, fuzzing).
//!
//! Texture decoding with bounded memory ([`decode_texture`] and its limits)
//! lives in the loader (`load/texture.rs`) and is re-exported here.

use std::collections::HashMap;
use std::io::Read;
use std::path::{Path, PathBuf};

pub use crate::load::texture::{
    check_exr_header, decode_texture, texture_budget, EXR_TILE_SLACK, MAX_TEXTURE_SIDE, TEXTURE_BUDGET_CAP,
    TEXTURE_BUDGET_FLOOR, TEXTURE_BUDGET_RATIO,
};

/// Largest file a loader reads (2 GiB).
pub const MAX_FILE_BYTES: u64 = 2 << 30;

/// A source of files for the loaders. Errors are a short reason (the caller
/// names the file).
pub trait FileSource {
    fn read(&self, path: &Path) -> Result<Vec<u8>, String>;
}

/// Regular files on disk, at most [`MAX_FILE_BYTES`] each.
#[derive(Clone, Copy, Debug, Default)]
pub struct DiskFiles;

impl FileSource for DiskFiles {
    fn read(&self, path: &Path) -> Result<Vec<u8>, String> {
        let meta = std::fs::metadata(path).map_err(|e| match e.kind() {
            std::io::ErrorKind::NotFound => "file not found".to_string(),
            _ => format!("cannot read it: {e}"),
        })?;
        if !meta.is_file() {
            return Err("not a regular file".into());
        }
        if meta.len() > MAX_FILE_BYTES {
            return Err(format!(
                "file is too large: {} bytes (at most {MAX_FILE_BYTES})",
                meta.len()
            ));
        }
        let f = std::fs::File::open(path).map_err(|e| format!("cannot open it: {e}"))?;
        let mut bytes = Vec::with_capacity(meta.len() as usize);
        // Never more than the limit, even if the file grows meanwhile.
        f.take(MAX_FILE_BYTES + 1)
            .read_to_end(&mut bytes)
            .map_err(|e| format!("cannot read it: {e}"))?;
        if bytes.len() as u64 > MAX_FILE_BYTES {
            return Err(format!("file is too large (more than {MAX_FILE_BYTES} bytes)"));
        }
        Ok(bytes)
    }
}

/// Files held in memory, looked up by exact path.
#[derive(Clone, Debug, Default)]
pub struct MemFiles {
    files: HashMap<PathBuf, Vec<u8>>,
}

impl MemFiles {
    pub fn new() -> Self {
        Self::default()
    }

    pub fn insert(&mut self, path: impl Into<PathBuf>, bytes: impl Into<Vec<u8>>) -> &mut Self {
        self.files.insert(path.into(), bytes.into());
        self
    }
}

impl FileSource for MemFiles {
    fn read(&self, path: &Path) -> Result<Vec<u8>, String> {
        self.files
            .get(path)
            .cloned()
            .ok_or_else(|| "file not found".to_string())
    }
}
