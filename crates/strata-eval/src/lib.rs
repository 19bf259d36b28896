//! Evaluation and benchmarks for strata: image metrics (ꟻLIP, RMSE, MAE, flicker), the on-disk
//! cache of CPU references and light probes, GPU timestamp benchmarks, the evaluation flows
//! that compare a GPU technique with the CPU ground truth, and readable HTML reports (tables and
//! SVG plots).
//!
//! Functions take plain settings structs and return serde-serialisable results (or
//! `anyhow::Result`); they print nothing on stdout. Progress goes to stderr (progress bars of the
//! CPU reference, the light-probe bake notice) and can be turned off in the settings.
//!
//! Module tree (no sibling flow imports another):
//! - [`metrics`], [`stats`]: image errors; medians, quantiles and spreads of timings
//! - [`scene`], [`files`]: scene + camera resolution; output files that refuse to overwrite
//! - [`cache`]: reference cache ([`cache::RefCache`]) and light probes ([`cache::probes`])
//! - [`results`]: what the flows return (the JSON the CLI prints; read back by [`report`])
//! - [`report`]: HTML pages with tables and plotters SVG plots; [`report::stitch`] builds one
//!   page from a folder of result JSON files
//! - [`bench`]: `gbuffer`, `deep`, `stage` (shared driver) with `ao`, `radiosity`, `reflections`,
//!   and `reference` (CPU ray throughput)
//! - [`eval`]: `ao` and `gi`, sharing [`eval::EvalSettings`] and [`eval::flicker`]

pub mod bench;
pub mod cache;
pub mod eval;
pub mod files;
pub mod metrics;
pub mod report;
pub mod results;
pub mod scene;
pub mod stats;
pub mod vpls;
