//! Motion between collisions: the Lagrange–d'Alembert equations
//!
//! G(q) q̈ + h(q, q̇) = A(q)ᵀλ,   A(q) q̇ = 0,
//!
//! solved for q̈ and the constraint reaction λ at a state, without heap
//! allocation. Differentiating A q̇ = 0 gives A q̈ = −Ȧq̇, so with
//! z = −G⁻¹h and Y = G⁻¹Aᵀ, λ solves (A Y) λ = −Ȧq̇ − A z and q̈ = z + Y λ
//! (both systems by Cholesky factorisation on fixed-size matrices).

use nalgebra::{SMatrix, SVector};

use crate::Model;

/// Why the accelerations could not be computed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DynamicsError {
    /// A coordinate or velocity is NaN or infinite, or the model's functions
    /// returned a non-finite value there.
    NonFinite,
    /// G(q) is not positive definite (e.g. a coordinate singularity).
    SingularMassMatrix,
    /// A G⁻¹Aᵀ is singular: the constraint rows are dependent at q.
    DependentConstraints,
}

/// The solution at one state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Accelerations<const N: usize> {
    /// q̈.
    pub qdd: [f64; N],
    /// λ, one entry per row of A (the rest zero).
    pub lambda: [f64; N],
    /// Number of rows of A.
    pub constraints: usize,
}

fn finite<const N: usize>(x: &[f64; N]) -> bool {
    x.iter().all(|v| v.is_finite())
}

/// q̈ and λ of model `m` at (q, q̇). `q̇` should satisfy A q̇ = 0.
pub fn accelerations<M: Model<N, N>, const N: usize>(
    m: &M,
    q: &[f64; N],
    qd: &[f64; N],
) -> Result<Accelerations<N>, DynamicsError> {
    if !finite(q) || !finite(qd) {
        return Err(DynamicsError::NonFinite);
    }
    let g = m.mass_matrix(q);
    let h = m.forcing(q, qd);
    let a = m.constraints(q);
    let c = m.constraint_drift(q, qd);
    if !g.iter().all(finite) || !finite(&h) || !a.as_slice().iter().all(finite) || !finite(&c) {
        return Err(DynamicsError::NonFinite);
    }
    let chol = SMatrix::<f64, N, N>::from_fn(|i, j| g[i][j])
        .cholesky()
        .ok_or(DynamicsError::SingularMassMatrix)?;
    let z = chol.solve(&SVector::<f64, N>::from_fn(|i, _| -h[i]));
    let k = a.len();
    // Y's columns G⁻¹aᵣᵀ; the k×k system padded to N×N with the identity.
    let mut y = SMatrix::<f64, N, N>::zeros();
    for (r, row) in a.as_slice().iter().enumerate() {
        let col = chol.solve(&SVector::<f64, N>::from_fn(|i, _| row[i]));
        y.set_column(r, &col);
    }
    let mut s = SMatrix::<f64, N, N>::identity();
    let mut rhs = SVector::<f64, N>::zeros();
    for (r, row) in a.as_slice().iter().enumerate() {
        let ar = SVector::<f64, N>::from_fn(|i, _| row[i]);
        for t in 0..k {
            s[(r, t)] = ar.dot(&y.column(t));
        }
        rhs[r] = -c[r] - ar.dot(&z);
    }
    // A G⁻¹Aᵀ is symmetric, and positive definite exactly when A's rows
    // are independent.
    let lambda = s
        .cholesky()
        .ok_or(DynamicsError::DependentConstraints)?
        .solve(&rhs);
    let qdd = z + y * lambda;
    let out = Accelerations {
        qdd: core::array::from_fn(|i| qdd[i]),
        lambda: core::array::from_fn(|i| if i < k { lambda[i] } else { 0.0 }),
        constraints: k,
    };
    if !finite(&out.qdd) || !finite(&out.lambda) {
        return Err(DynamicsError::DependentConstraints);
    }
    Ok(out)
}
