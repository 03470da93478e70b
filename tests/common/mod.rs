//! Helpers shared by the integration tests.

use dalembert::runtime::Rows;
use nalgebra::DMatrix;

/// v projected onto ker A (Euclidean; membership in ker A does not depend on
/// the metric). A must have full row rank.
pub fn onto_kernel<const N: usize>(a: &Rows<N>, v: [f64; N]) -> [f64; N] {
    let k = a.len();
    if k == 0 {
        return v;
    }
    let am = DMatrix::from_fn(k, N, |i, j| a.as_slice()[i][j]);
    let vv = DMatrix::from_fn(N, 1, |i, _| v[i]);
    let lam = (&am * am.transpose())
        .lu()
        .solve(&(&am * &vv))
        .expect("A has full row rank");
    let w = vv - am.transpose() * lam;
    std::array::from_fn(|i| w[(i, 0)])
}
