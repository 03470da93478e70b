//! Motion between collisions: the Lagrange–d'Alembert equations
//!
//! G(q) q̈ + h(q, q̇) = A(q)ᵀλ,   A(q) q̇ = 0,
//!
//! solved for q̈ and the constraint reaction λ at a state, without heap
//! allocation. Differentiating A q̇ = 0 gives A q̈ = −Ȧq̇, so with
//! z = −G⁻¹h and Y = G⁻¹Aᵀ, λ solves (A Y) λ = −Ȧq̇ − A z and q̈ = z + Y λ
//! (both systems by Cholesky factorisation on fixed-size arrays).

use crate::Dynamics;
use crate::linalg::{Cholesky, constrained_solve, dot};

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

/// q̈ of model `m` at (q, q̇): the generated closed form
/// ([`Dynamics::closed_form_accelerations`]) where the model has one and it is
/// finite there, else the numeric solve of [`accelerations`] (which also
/// tells why a state has none). `q̇` should satisfy A q̇ = 0.
pub fn qdd<M: Dynamics<N>, const N: usize>(
    m: &M,
    q: &[f64; N],
    qd: &[f64; N],
) -> Result<[f64; N], DynamicsError> {
    match m.closed_form_accelerations(q, qd) {
        Some(x) if finite(&x) => Ok(x),
        _ => accelerations(m, q, qd).map(|a| a.qdd),
    }
}

/// q̈ and λ of model `m` at (q, q̇) by solving the equations numerically
/// (Cholesky factorisations of G and A G⁻¹Aᵀ). `q̇` should satisfy A q̇ = 0.
pub fn accelerations<M: Dynamics<N>, const N: usize>(
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
    let chol = Cholesky::new(&g, N).ok_or(DynamicsError::SingularMassMatrix)?;
    let z = chol.solve(&h.map(|x| -x));
    let k = a.len();
    if k == 0 {
        return Ok(Accelerations {
            qdd: z,
            lambda: [0.0; N],
            constraints: 0,
        });
    }
    // The k×k system (A G⁻¹Aᵀ) λ = −Ȧq̇ − A z, then q̈ = z + G⁻¹Aᵀλ.
    let rows = a.as_slice();
    let mut rhs = [0.0; N];
    for (r, row) in rows.iter().enumerate() {
        rhs[r] = -c[r] - dot(row, &z);
    }
    let (qdd, lambda) =
        constrained_solve(&chol, rows, &rhs[..k], z).ok_or(DynamicsError::DependentConstraints)?;
    let out = Accelerations {
        qdd,
        lambda,
        constraints: k,
    };
    if !finite(&out.qdd) || !finite(&out.lambda) {
        return Err(DynamicsError::DependentConstraints);
    }
    Ok(out)
}
