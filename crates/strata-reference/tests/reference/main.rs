//! Property tests of the CPU reference against brute force and analytic results.
//! One test binary (faster to link); one module per oracle.

mod ao;
mod builtin_scenes;
mod bvh;
mod converge;
mod gi;
mod glossy;
mod layers;
mod oit;
mod oracle;
mod scenes;
mod tracer;
mod vpl;
