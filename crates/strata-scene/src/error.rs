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
    /// An error about `path`. The message is made one line (line breaks and
    /// other control characters become "; " or spaces).
    pub fn file(path: impl Into<PathBuf>, message: impl std::fmt::Display) -> Self {
        SceneError::File {
            path: path.into(),
            message: one_line(&message.to_string()),
        }
    }
}

/// `s` on one line: non-empty lines joined with "; ", other control
/// characters replaced by spaces.
pub fn one_line(s: &str) -> String {
    s.lines()
        .map(str::trim)
        .filter(|l| !l.is_empty())
        .collect::<Vec<_>>()
        .join("; ")
        .chars()
        .map(|c| if c.is_control() { ' ' } else { c })
        .collect()
}

/// At most 80 characters of `s` (for messages).
pub(crate) fn short(s: &str) -> String {
    if s.chars().count() <= 80 {
        s.to_string()
    } else {
        let t: String = s.chars().take(77).collect();
        format!("{t}...")
    }
}
