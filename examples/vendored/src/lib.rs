//! Generated code, vendored: `ball_floor.rs` was written by
//!
//! ```sh
//! cargo run --release -- generate models/ball_floor.toml -o examples/vendored/src/ball_floor.rs
//! ```
//!
//! and is compiled here with `dalembert-runtime` as the only dalembert
//! dependency: no build script, no generator, no symbolica. The workspace's
//! test `tests/vendored.rs` fails when the file is no longer what the
//! generator writes.
#![no_std]

pub mod ball_floor;
pub use ball_floor::BallFloor;
