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

/// The fixed-size Cholesky solves SPD systems (A = MᵀM + I) to rounding,
/// on a leading block too, and rejects indefinite or NaN matrices.
#[test]
fn cholesky_solves_and_rejects() {
    use dalembert_runtime::linalg::{Cholesky, mat_vec};
    let mut seed = 7u64;
    let mut next = || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    for _ in 0..100 {
        let m: [[f64; 5]; 5] = core::array::from_fn(|_| core::array::from_fn(|_| next()));
        let a: [[f64; 5]; 5] = core::array::from_fn(|i| {
            core::array::from_fn(|j| {
                (0..5).map(|k| m[k][i] * m[k][j]).sum::<f64>() + if i == j { 1.0 } else { 0.0 }
            })
        });
        let x: [f64; 5] = core::array::from_fn(|_| next());
        let b = mat_vec(&a, &x);
        let got = Cholesky::new(&a, 5).unwrap().solve(&b);
        for i in 0..5 {
            assert!((got[i] - x[i]).abs() < 1e-12);
        }
        // The leading 3×3 block alone.
        let mut b3 = [0.0; 5];
        for i in 0..3 {
            b3[i] = (0..3).map(|j| a[i][j] * x[j]).sum();
        }
        let got = Cholesky::new(&a, 3).unwrap().solve(&b3);
        for i in 0..3 {
            assert!((got[i] - x[i]).abs() < 1e-12);
        }
        assert_eq!(&got[3..], &[0.0, 0.0]);
    }
    let indefinite = [[1.0, 2.0], [2.0, 1.0]];
    assert!(Cholesky::new(&indefinite, 2).is_none());
    assert!(Cholesky::new(&[[f64::NAN, 0.0], [0.0, 1.0]], 2).is_none());
}
