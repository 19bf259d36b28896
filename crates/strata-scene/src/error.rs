use std::path::PathBuf;

/// Errors from loading scenes. Each names the file (and what is wrong / valid).
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    #[error("{path}: {message}")]
    File { path: PathBuf, message: String },
    #[error("unknown scene '{0}': use a built-in name ({names}) or a path to a .gltf, .glb, .obj or .toml file", names = crate::procedural::BUILTIN_NAMES.join(", "))]
    Unknown(String),
    #[error("{0}")]
    Invalid(String),
}

impl SceneError {
    pub fn file(path: impl Into<PathBuf>, message: impl std::fmt::Display) -> Self {
        SceneError::File {
            path: path.into(),
            message: message.to_string(),
        }
    }
}
