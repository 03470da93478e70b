//! The runtime's fixed-size linear algebra. (That the runtime and the
//! generated models need no `std` is checked by building
//! `nostd-check/` as a static library without it: see `.ci/run`.)

/// Numbers in [−1/2, 1/2) from a linear congruential generator.
fn numbers(mut seed: u64) -> impl FnMut() -> f64 {
    move || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    }
}

/// A random symmetric positive definite matrix MᵀM + I.
fn spd<const N: usize>(next: &mut impl FnMut() -> f64) -> [[f64; N]; N] {
    let m: [[f64; N]; N] = core::array::from_fn(|_| core::array::from_fn(|_| next()));
    core::array::from_fn(|i| {
        core::array::from_fn(|j| {
            (0..N).map(|k| m[k][i] * m[k][j]).sum::<f64>() + if i == j { 1.0 } else { 0.0 }
        })
    })
}

/// The fixed-size Cholesky solves SPD systems (A = MᵀM + I) to rounding,
/// on a leading block too, and rejects indefinite or NaN matrices.
#[test]
fn cholesky_solves_and_rejects() {
    use dalembert_runtime::linalg::{Cholesky, mat_vec};
    let mut next = numbers(7);
    for _ in 0..100 {
        let a: [[f64; 5]; 5] = spd(&mut next);
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
    // Singular blocks whose last pivot comes out of the rounding a few ulps
    // above zero (0.125 − (0.125/√0.125)² = 2.8e-17, 0.7's 1.1e-16): the
    // coin lying flat, whose φ and ψ both turn it about its axis
    // (moment 1/8), has this block. Singular to working precision.
    for c in [0.125, 0.7, 0.3] {
        assert!(Cholesky::new(&[[c, c], [c, c]], 2).is_none(), "{c}");
    }
    // Nearly singular but not to working precision: factored.
    let near = 1.0 - 1e-10;
    assert!(Cholesky::new(&[[1.0, near], [near, 1.0]], 2).is_some());
}

/// The generic projector agrees with the constrained solve: P v equals the
/// correction that removes B v, P is idempotent and G-symmetric, and a row
/// that depends on earlier ones is ignored.
#[test]
fn projector_agrees_with_the_correction() {
    use dalembert_runtime::linalg::{correction, mat_mul, mat_vec, projector};
    let mut next = numbers(11);
    for _ in 0..100 {
        let g: [[f64; 4]; 4] = spd(&mut next);
        let b0: [f64; 4] = core::array::from_fn(|_| next());
        let b1: [f64; 4] = core::array::from_fn(|_| next());
        let dependent: [f64; 4] = core::array::from_fn(|i| 2.0 * b0[i] - b1[i]);
        let p = projector(&g, &[b0, b1, dependent]).unwrap();
        let v: [f64; 4] = core::array::from_fn(|_| next());
        let bv = [b0, b1].map(|r| (0..4).map(|i| r[i] * v[i]).sum::<f64>());
        let d = correction(&g, &[b0, b1], &bv).unwrap();
        let pv = mat_vec(&p, &v);
        let pp = mat_mul(&p, &p);
        let gp = mat_mul(&g, &p);
        for i in 0..4 {
            assert!((pv[i] - d[i]).abs() < 1e-10, "{pv:?} vs {d:?}");
            for j in 0..4 {
                assert!((pp[i][j] - p[i][j]).abs() < 1e-10);
                assert!((gp[i][j] - gp[j][i]).abs() < 1e-10);
            }
        }
    }
}
