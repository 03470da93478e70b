//! Generated code, vendored: `ball_floor.rs` was written by
//!
//! ```sh
//! cargo run --release -p dalembert-cli -- generate models/ball_floor.toml -o examples/vendored/src/ball_floor.rs
//! ```
//!
//! and is compiled here with `dalembert-runtime` as the only dalembert
//! dependency: no build script, no generator, no symbolica. The workspace's
//! test `tests/vendored.rs` fails when the file is no longer what the
//! generator writes. The generated files are left as the generator formats
//! them (`rustfmt::skip`), so that `cargo fmt` keeps them current.
#![no_std]

#[rustfmt::skip]
pub mod ball_floor;
pub use ball_floor::BallFloor;

/// Single-precision versions for microcontrollers without double-precision
/// hardware, written by
///
/// ```sh
/// cargo run --release -p dalembert-cli -- generate models/ball_floor.toml --f32 -o examples/vendored/src/single/ball_floor.rs
/// cargo run --release -p dalembert-cli -- generate models/ball_wall_euler.toml --f32 -o examples/vendored/src/single/ball_wall_euler.rs
/// ```
///
/// the models' inherent functions in f32 (accuracy against f64:
/// docs/performance.md, checked by the workspace's `tests/vendored.rs`).
#[rustfmt::skip]
pub mod single {
    pub mod ball_floor;
    pub mod ball_wall_euler;
}
