//! An example of a user's crate: its build script runs dalembert's generator
//! on `models/`, and the generated models are included here.
#![no_std]

/// The models generated from `models/*.toml`.
pub mod models {
    include!(concat!(env!("OUT_DIR"), "/models.rs"));
}
