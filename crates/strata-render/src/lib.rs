//! strata-render: the wgpu side of strata.
//!
//! A frame is an ordered list of passes ([`frame::Pass`]), each declaring the
//! targets it reads and writes; every target can be read back as a debug view.
//! Passes live in [`passes`], one module per technique with its WGSL beside it;
//! shared WGSL lives in `shaders/common/` and is imported with `#import`.

pub mod display;
pub mod embed;
pub mod frame;
pub mod gpu;
pub mod lights;
pub mod packing;
pub mod passes;
pub mod profiler;
pub mod renderer;
pub mod scene_gpu;
pub mod shader;
pub mod spiral;
pub mod technique;

pub use gpu::{GpuContext, GpuOptions};
pub use profiler::PassTimings;
pub use renderer::{RenderSettings, Renderer, ACCUMULATION_WARMUP};

/// Errors from the GPU side; each names what is wrong and what is valid.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    #[error("{0}")]
    NoAdapter(String),
    #[error("the adapter lacks feature {feature}, which pass '{pass}' needs")]
    MissingFeature { feature: String, pass: String },
    #[error("wgpu validation error:\n{0}")]
    Validation(String),
    #[error("{0}")]
    Parameter(String),
    #[error("{0}")]
    Other(String),
}
