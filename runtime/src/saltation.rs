//! The saltation matrix of a collision: how a perturbation of the state
//! just before a collision maps to one just after it, the shift of the
//! collision instant included. With the state x = (q, v), the collision map
//! x⁺ = (q, v⁺(q, v⁻)) on the wall f(q) = 0 and the vector field
//! F(x) = (v, q̈(q, v)),
//!
//! S = R + (F⁺ − R F⁻) ∇fᵀ / (∇f · F⁻),  R = ∂x⁺/∂x⁻,
//!
//! with F∓ at the states before and after and ∇f = (df(q), 0), so that
//! ∇f · F⁻ = df(q)·v⁻, the normal velocity. A perturbation δx⁻ of the state
//! at the collision moves the collision instant by
//! δt* = −∇f · δx⁻ / (∇f · F⁻), and the state just after it by S δx⁻. The
//! flow's sensitivity through a collision is Φ⁺ = S Φ⁻.
//!
//! A grazing contact (df·v⁻ → 0) has no saltation matrix (the instant moves
//! without bound); it is an error, as is a model whose collision map has no
//! derivative ([`Walls::collide_tangent`]).

use crate::dynamics::{DynamicsError, qdd};
use crate::linalg;
use crate::{Surfaces, Walls};

/// A 2N×2N matrix over the state (q, v), as its four N×N blocks.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StateMatrix<const N: usize> {
    /// ∂q/∂q.
    pub qq: [[f64; N]; N],
    /// ∂q/∂v.
    pub qv: [[f64; N]; N],
    /// ∂v/∂q.
    pub vq: [[f64; N]; N],
    /// ∂v/∂v.
    pub vv: [[f64; N]; N],
}

impl<const N: usize> StateMatrix<N> {
    /// The identity.
    pub fn identity() -> Self {
        let mut m = Self {
            qq: [[0.0; N]; N],
            qv: [[0.0; N]; N],
            vq: [[0.0; N]; N],
            vv: [[0.0; N]; N],
        };
        for i in 0..N {
            m.qq[i][i] = 1.0;
            m.vv[i][i] = 1.0;
        }
        m
    }

    /// The matrix applied to (δq, δv).
    pub fn apply(&self, dq: &[f64; N], dv: &[f64; N]) -> ([f64; N], [f64; N]) {
        let (a, b) = (linalg::mat_vec(&self.qq, dq), linalg::mat_vec(&self.qv, dv));
        let (c, d) = (linalg::mat_vec(&self.vq, dq), linalg::mat_vec(&self.vv, dv));
        (
            core::array::from_fn(|i| a[i] + b[i]),
            core::array::from_fn(|i| c[i] + d[i]),
        )
    }

    /// The product `self · other`.
    pub fn mul(&self, other: &Self) -> Self {
        let block = |a: &[[f64; N]; N], b: &[[f64; N]; N], c: &[[f64; N]; N], d: &[[f64; N]; N]| {
            let (x, y) = (linalg::mat_mul(a, b), linalg::mat_mul(c, d));
            core::array::from_fn(|i| core::array::from_fn(|j| x[i][j] + y[i][j]))
        };
        Self {
            qq: block(&self.qq, &other.qq, &self.qv, &other.vq),
            qv: block(&self.qq, &other.qv, &self.qv, &other.vv),
            vq: block(&self.vq, &other.qq, &self.vv, &other.vq),
            vv: block(&self.vq, &other.qv, &self.vv, &other.vv),
        }
    }
}

/// What a direction δp of the parameters adds at a collision: with the
/// state x(t₀) held fixed, the derivative of the run along δp jumps as
/// δx⁺ = S δx⁻ + `dx`, and the collision instant moves by
/// `dt_dq · δq⁻ + dt`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ParameterJump<const N: usize> {
    /// The jump's part from δp over (q, v): (0, ∂v⁺/∂p δp) for the map's
    /// own change, plus (F⁺ − R F⁻) (∂f/∂p δp)/(df·v⁻) for the instant's.
    pub dx: ([f64; N], [f64; N]),
    /// The instant's shift from δp: −(∂f/∂p δp)/(df·v⁻).
    pub dt: f64,
}

/// A collision's saltation matrix and the sensitivity of its instant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Saltation<const N: usize> {
    /// S: δx⁺ = S δx⁻.
    pub matrix: StateMatrix<N>,
    /// ∂t*/∂q: the collision instant moves by `dt_dq · δq` (its derivative
    /// by v is zero: f depends on q alone).
    pub dt_dq: [f64; N],
    /// The velocity after the collision, v⁺.
    pub v_plus: [f64; N],
}

/// Why a collision has no saltation matrix.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SaltationError {
    /// The motion meets the wall tangentially: |df·v⁻| is at most `1e-9`
    /// of |df| |v⁻| (the collision instant's derivative is unbounded).
    Grazing {
        /// df·v⁻.
        normal_velocity: f64,
    },
    /// The model has no derivative of this wall's collision map
    /// ([`Walls::collide_tangent`] is `None`), or, for a direction of the
    /// parameters ([`parameter_jump`]), none of the map or of the wall's f
    /// along it.
    NoDerivative,
    /// q̈ before or after the collision could not be computed.
    Dynamics(DynamicsError),
}

impl core::fmt::Display for SaltationError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::Grazing { normal_velocity } => write!(
                f,
                "the motion grazes the wall (normal velocity {normal_velocity:e}): the collision instant has no derivative"
            ),
            Self::NoDerivative => write!(f, "the model has no derivative of this collision map"),
            Self::Dynamics(e) => write!(f, "q̈ at the collision: {e:?}"),
        }
    }
}

/// The saltation matrix of a collision with `wall` at (q, v⁻), q on the
/// wall and v⁻ admissible and approaching. See the module doc.
pub fn saltation<M: Surfaces<N>, const N: usize>(
    m: &M,
    wall: <M as Walls<N, N>>::Wall,
    q: &[f64; N],
    v_minus: &[f64; N],
) -> Result<Saltation<N>, SaltationError> {
    let (df, sigma) = crossing(m, wall, q, v_minus)?;
    let (cq, cv) = m
        .collide_jacobian(wall, q, v_minus)
        .ok_or(SaltationError::NoDerivative)?;
    let v_plus = m.collide(wall, q, v_minus);
    let a_minus = qdd(m, q, v_minus).map_err(SaltationError::Dynamics)?;
    let a_plus = qdd(m, q, &v_plus).map_err(SaltationError::Dynamics)?;
    // w = F⁺ − R F⁻, R = [[I, 0], [Cq, Cv]], F = (v, q̈).
    let (cq_v, cv_a) = (
        linalg::mat_vec(&cq, v_minus),
        linalg::mat_vec(&cv, &a_minus),
    );
    let w_q: [f64; N] = core::array::from_fn(|i| v_plus[i] - v_minus[i]);
    let w_v: [f64; N] = core::array::from_fn(|i| a_plus[i] - cq_v[i] - cv_a[i]);
    let mut matrix = StateMatrix::identity();
    matrix.vq = cq;
    matrix.vv = cv;
    for (i, (qq, vq)) in matrix.qq.iter_mut().zip(&mut matrix.vq).enumerate() {
        for (j, d) in df.iter().enumerate() {
            qq[j] += w_q[i] * d / sigma;
            vq[j] += w_v[i] * d / sigma;
        }
    }
    Ok(Saltation {
        matrix,
        dt_dq: core::array::from_fn(|j| -df[j] / sigma),
        v_plus,
    })
}

/// What a direction δp of the parameters (one entry each, in
/// [`crate::Model::parameter_names`] order) adds at a collision with
/// `wall` at (q, v⁻), the state before the collision held fixed. From
/// f(q(t*), p) = 0, the instant moves by δt* = −(df·δq⁻ + ∂f/∂p δp)/σ,
/// σ = df·v⁻, and the state after it at the unperturbed instant by
/// S δx⁻ + (0, ∂v⁺/∂p δp) + (F⁺ − R F⁻)(∂f/∂p δp)/σ; R F⁻ is one tangent
/// of the map, along F⁻ = (v⁻, q̈⁻). Errors as [`saltation`]'s.
pub fn parameter_jump<M: Surfaces<N>, const N: usize>(
    m: &M,
    wall: <M as Walls<N, N>>::Wall,
    q: &[f64; N],
    v_minus: &[f64; N],
    dp: &[f64],
) -> Result<ParameterJump<N>, SaltationError> {
    let (_, sigma) = crossing(m, wall, q, v_minus)?;
    let (_, f_p) = m
        .surface_parameter_tangent(wall, q, dp)
        .ok_or(SaltationError::NoDerivative)?;
    let (v_plus, by_p) = m
        .collide_parameter_tangent(wall, q, v_minus, dp)
        .ok_or(SaltationError::NoDerivative)?;
    let a_minus = qdd(m, q, v_minus).map_err(SaltationError::Dynamics)?;
    let a_plus = qdd(m, q, &v_plus).map_err(SaltationError::Dynamics)?;
    let (_, r_f) = m
        .collide_tangent(wall, q, v_minus, v_minus, &a_minus)
        .ok_or(SaltationError::NoDerivative)?;
    let shift = f_p / sigma;
    Ok(ParameterJump {
        dx: (
            core::array::from_fn(|i| (v_plus[i] - v_minus[i]) * shift),
            core::array::from_fn(|i| by_p[i] + (a_plus[i] - r_f[i]) * shift),
        ),
        dt: -shift,
    })
}

/// The wall's normal df(q) and the normal velocity σ = df·v⁻, or the
/// grazing error where |σ| is at most 1e-9 of |df| |v⁻| (or not finite).
fn crossing<M: Surfaces<N>, const N: usize>(
    m: &M,
    wall: <M as Walls<N, N>>::Wall,
    q: &[f64; N],
    v_minus: &[f64; N],
) -> Result<([f64; N], f64), SaltationError> {
    let df = m.normal(wall, q);
    let sigma = linalg::dot(&df, v_minus);
    let size2 = linalg::dot(&df, &df) * linalg::dot(v_minus, v_minus);
    let clear = sigma * sigma > 1e-18 * size2; // false for NaN too
    if clear {
        Ok((df, sigma))
    } else {
        Err(SaltationError::Grazing {
            normal_velocity: sigma,
        })
    }
}
