//! The runtime is `#![no_std]` and keeps its dependencies free of `std`: a
//! change that drops the attribute or turns on nalgebra's default (std)
//! features fails here. (Inside the crate, `#![no_std]` itself makes any use
//! of `std` a compile error.)

#[test]
fn runtime_is_no_std() {
    let lib = include_str!("../src/lib.rs");
    assert!(lib.lines().any(|l| l.trim() == "#![no_std]"));
    assert!(lib.lines().any(|l| l.trim() == "#![forbid(unsafe_code)]"));
    let manifest = include_str!("../Cargo.toml");
    let nalgebra = manifest
        .lines()
        .find(|l| l.starts_with("nalgebra"))
        .expect("nalgebra dependency");
    assert!(nalgebra.contains("default-features = false"), "{nalgebra}");
    assert!(!manifest.contains("symbolica"));
}

#[test]
fn generated_models_are_no_std() {
    let lib = include_str!("../../src/lib.rs");
    assert!(lib.lines().any(|l| l.trim() == "#![no_std]"));
}
