//! dalembert: nonholonomic mechanical systems with elastic collisions.
//!
//! This crate holds the models built from `models/*.toml` at build time (see
//! `build.rs`), each a type implementing [`runtime::Model`]. It is
//! `#![no_std]`: generated code needs neither `std` nor a heap.
#![no_std]
#![forbid(unsafe_code)]

pub use dalembert_runtime as runtime;

/// The built-in models, one module per model file.
pub mod models {
    include!(concat!(env!("OUT_DIR"), "/models.rs"));
}
