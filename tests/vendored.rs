//! The vendored copy in `examples/vendored/` is exactly what the generator
//! writes today (uses the symbolic engine: `RUST_TEST_THREADS=1`).

use std::path::Path;

#[test]
fn vendored_file_is_current() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let fresh = dalembert_codegen::generate(&root.join("models/ball_floor.toml")).unwrap();
    let vendored =
        std::fs::read_to_string(root.join("examples/vendored/src/ball_floor.rs")).unwrap();
    assert!(
        fresh == vendored,
        "examples/vendored/src/ball_floor.rs is stale: regenerate it with\n  cargo run --release -- generate models/ball_floor.toml -o examples/vendored/src/ball_floor.rs"
    );
}
