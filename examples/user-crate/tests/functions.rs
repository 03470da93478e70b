//! A model whose q̈ has a square root and a logarithm (`models/bead.toml`):
//! its generated Taylor series, which runs their recurrences, against the
//! derivatives of the closed-form acceleration.

use dalembert_example_user::models::Bead;
use dalembert_example_user::models::bead::SeriesScratch;
use dalembert_runtime::taylor::Series;

/// V'(x) for V = x√(1 + x²) + x ln(2 + x²).
fn force(x: f64) -> f64 {
    let r = (1.0 + x * x).sqrt();
    r + x * x / r + (2.0 + x * x).ln() + 2.0 * x * x / (2.0 + x * x)
}

#[test]
fn series_of_sqrt_and_log() {
    let bead = Bead::default();
    let m = bead.params().m;
    let mut scratch = SeriesScratch::default();
    for (x, v) in [(0.7, -0.3), (-1.2, 0.8), (2.5, 1.5)] {
        let mut s = Series::<1>::at(&[x], &[v]);
        bead.motion_series(&mut s, &mut scratch, 6);
        // ẍ = −V'/m, x⃛ = −V''v/m, x⁗ = −(V'''v² + V''ẍ)/m: the
        // normalised coefficients times k!.
        let h = 1e-4;
        let d1 = force(x);
        let d2 = (force(x + h) - force(x - h)) / (2.0 * h);
        let d3 = (force(x + h) - 2.0 * d1 + force(x - h)) / (h * h);
        let acc = -d1 / m;
        let jerk = -d2 * v / m;
        let snap = -(d3 * v * v + d2 * acc) / m;
        for (k, want, tol) in [(2, acc, 1e-12), (3, jerk, 1e-7), (4, snap, 1e-5)] {
            let factorial: f64 = (1..=k).map(|i| i as f64).product();
            let got = factorial * s.q[0][k];
            assert!(
                (got - want).abs() <= tol * (1.0 + want.abs()),
                "x = {x}, order {k}: {got} against {want}"
            );
        }
    }
}
