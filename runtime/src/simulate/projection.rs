//! Back onto the constraints: q onto h(q) = 0 and q̇ onto ker A(q), in the
//! metric of G; residuals and admissible velocities for callers.

use super::integrator::Engine;
use super::phase::{Phase, norm};
use super::thresholds::{ADMISSIBLE, HOLONOMIC_DONE_ULPS, HOLONOMIC_FAILED, HOLONOMIC_STEPS};
use super::{Residual, SimError, Simulator};
use crate::linalg::{self, ProjectorError};
use crate::{Dynamics, Surfaces};

impl<M: Surfaces<N>, const N: usize> Simulator<'_, M, N> {
    /// q onto h(q) = 0 (Gauss–Newton in the metric of G), then q̇ onto
    /// ker A(q) (G-orthogonally). Recomputes (q̇, q̈) when anything moved.
    pub(super) fn project(&mut self) -> Result<(), SimError<M::Wall>> {
        if !self.settings.project {
            return Ok(());
        }
        let m = self.model;
        let t = self.state.t;
        let fail = |error| SimError::Projection { t, error };
        // (h's rows are A's first: where q moves, A is not empty.)
        self.state.q = onto_holonomic(m, &self.state.q).map_err(fail)?;
        let a = m.constraints(&self.state.q);
        let moved = !a.is_empty();
        if moved {
            let g = m.mass_matrix(&self.state.q);
            let r = a.apply(&self.state.v);
            let d = linalg::correction(&g, a.as_slice(), r.as_slice()).map_err(fail)?;
            for (vi, di) in self.state.v.iter_mut().zip(d) {
                *vi -= di;
            }
        }
        // Taylor's method starts every step from the state itself.
        if moved && matches!(self.engine, Engine::RungeKutta(_)) {
            let y = Phase {
                q: self.state.q,
                v: self.state.v,
            };
            self.f0 = self.rhs(t, &y)?;
        }
        Ok(())
    }
}

/// q moved onto h(q) = 0 by Gauss–Newton in the metric of G (each step the
/// G-smallest correction that zeroes the linearised residual): the nearest
/// point of the constraint manifold to a q near it. q itself, to rounding,
/// where it is on h = 0 or the model has no holonomic constraint. An error
/// where the rows are dependent or the iteration leaves h far from zero.
pub fn onto_holonomic<M: Dynamics<N>, const N: usize>(
    m: &M,
    q: &[f64; N],
) -> Result<[f64; N], ProjectorError> {
    let mut q = *q;
    let mut r = m.holonomic(&q);
    if r.as_slice().is_empty() {
        return Ok(q);
    }
    for _ in 0..HOLONOMIC_STEPS {
        if r.max_abs() <= HOLONOMIC_DONE_ULPS * f64::EPSILON * (1.0 + norm(&q)) {
            return Ok(q);
        }
        let g = m.mass_matrix(&q);
        let a = m.constraints(&q);
        let rows = &a.as_slice()[..r.as_slice().len()];
        let d = linalg::correction(&g, rows, r.as_slice())?;
        for (qi, di) in q.iter_mut().zip(d) {
            *qi -= di;
        }
        r = m.holonomic(&q);
    }
    if r.max_abs() > HOLONOMIC_FAILED * (1.0 + norm(&q)) {
        return Err(ProjectorError::DependentRows);
    }
    Ok(q)
}

/// Constraint residuals of model `m` at (q, v).
pub fn residual<M: Dynamics<N>, const N: usize>(m: &M, q: &[f64; N], v: &[f64; N]) -> Residual {
    Residual {
        velocity: m.constraints(q).apply(v).max_abs(),
        position: m.holonomic(q).max_abs(),
    }
}

/// The admissible velocity nearest to `v` in the metric of G(q): v minus its
/// G-orthogonal component off ker A(q). Use it to build initial states.
pub fn admissible<M: Dynamics<N>, const N: usize>(
    m: &M,
    q: &[f64; N],
    v: &[f64; N],
) -> Result<[f64; N], ProjectorError> {
    let a = m.constraints(q);
    if a.is_empty() {
        return Ok(*v);
    }
    let d = linalg::correction(&m.mass_matrix(q), a.as_slice(), a.apply(v).as_slice())?;
    Ok(core::array::from_fn(|i| v[i] - d[i]))
}

/// A perturbation (δq, δv) of the state (q, v) moved onto the directions a
/// motion can take, tangent to the constraint manifold: δq onto the kernel
/// of the holonomic rows of A(q) (its first rows), then δv so that
/// A(q) δv + (∂A/∂q δq) v = 0, both the smallest change in the metric of
/// G(q); ∂A/∂q δq by a central difference of A along δq. A perturbation
/// of a start along such a direction stays admissible to first order, so
/// [`crate::simulate::Variational`]'s Φ applied to it is the simulation's
/// derivative.
pub fn tangent_direction<M: Dynamics<N>, const N: usize>(
    m: &M,
    q: &[f64; N],
    v: &[f64; N],
    dq: &[f64; N],
    dv: &[f64; N],
) -> Result<([f64; N], [f64; N]), ProjectorError> {
    let a = m.constraints(q);
    if a.is_empty() {
        return Ok((*dq, *dv));
    }
    let g = m.mass_matrix(q);
    let holonomic = &a.as_slice()[..m.holonomic(q).as_slice().len()];
    let mut dq = *dq;
    if !holonomic.is_empty() {
        let r: [f64; N] =
            core::array::from_fn(|k| holonomic.get(k).map_or(0.0, |row| linalg::dot(row, &dq)));
        let d = linalg::correction(&g, holonomic, &r[..holonomic.len()])?;
        dq = core::array::from_fn(|i| dq[i] - d[i]);
    }
    // (∂A/∂q δq) v, zero where δq is.
    let size = norm(&dq);
    let mut moved = [0.0; N];
    if size > 0.0 {
        let eps = 1e-6 * (1.0 + norm(q)) / size;
        let along = |s: f64| {
            let q: [f64; N] = core::array::from_fn(|i| q[i] + s * dq[i]);
            m.constraints(&q).apply(v)
        };
        let (plus, minus) = (along(eps), along(-eps));
        for (k, x) in moved.iter_mut().enumerate().take(a.len()) {
            *x = (plus.as_slice()[k] - minus.as_slice()[k]) / (2.0 * eps);
        }
    }
    let av = a.apply(dv);
    let r: [f64; N] = core::array::from_fn(|k| av.as_slice().get(k).map_or(0.0, |x| x + moved[k]));
    let d = linalg::correction(&g, a.as_slice(), &r[..a.len()])?;
    Ok((dq, core::array::from_fn(|i| dv[i] - d[i])))
}

/// How [`starting_velocity`] found the start's velocity.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StartRule {
    /// The given entries are kept and the others follow from the
    /// constraints (and the rates given).
    Completed,
    /// The given entries cannot be completed to an admissible velocity: the
    /// given velocity (zero elsewhere) projected G-orthogonally onto ker A,
    /// as [`admissible`], and onto the rates given where there are.
    Projected,
}

/// The starting velocity at q from the entries of `v` marked in `given`
/// (the others of `v` are ignored) and the model's start rates
/// ([`Dynamics::start_rows`] with [`Dynamics::start_values`]), as a user
/// states a start: the given entries and rates are kept and the other
/// entries follow from A(q) q̇ = 0. Where the constraints leave a choice,
/// the others have the least kinetic energy of their own, ½ uᵀ G_uu u over
/// the entries u not given: nothing is added to what the constraints and
/// rates force (a ball started by its centre's velocity rolls without
/// spin), and they are all zero when the given entries are admissible by
/// themselves and no rate is given. When no choice of the others makes
/// the velocity admissible, the given velocity with zeros elsewhere is
/// projected G-orthogonally onto ker A and the rates
/// ([`StartRule::Projected`]). Rates that no admissible velocity has are
/// [`ProjectorError::Inconsistent`].
pub fn starting_velocity<M: Dynamics<N>, const N: usize>(
    m: &M,
    q: &[f64; N],
    v: &[f64; N],
    given: &[bool; N],
) -> Result<([f64; N], StartRule), ProjectorError> {
    starting_velocity_with(m, q, v, given, m.start_values().as_slice())
}

/// [`starting_velocity`] with `rates` in place of the model's
/// [`Dynamics::start_values`], one per [`Dynamics::start_rate_names`] (a
/// front end's `--set ball_wz=5`); rows past the values given are not
/// imposed.
pub fn starting_velocity_with<M: Dynamics<N>, const N: usize>(
    m: &M,
    q: &[f64; N],
    v: &[f64; N],
    given: &[bool; N],
    rates: &[f64],
) -> Result<([f64; N], StartRule), ProjectorError> {
    let v: [f64; N] = core::array::from_fn(|i| if given[i] { v[i] } else { 0.0 });
    let a = m.constraints(q);
    let l = m.start_rows(q);
    // (row, value) of each rate given.
    let rate_rows = || l.as_slice().iter().copied().zip(rates.iter().copied());
    if a.is_empty() && rate_rows().next().is_none() {
        return Ok((v, StartRule::Completed));
    }
    let scale = 1.0 + norm(q) + norm(&v) + rate_rows().map(|(_, c)| c.abs()).fold(0.0, f64::max);
    // Off the constraints and off the rates given, at most.
    let off = |x: &[f64; N]| {
        let rate_off = rate_rows()
            .map(|(row, c)| (linalg::dot(&row, x) - c).abs())
            .fold(0.0, f64::max);
        a.apply(x).max_abs().max(rate_off)
    };
    // The metric: G on the entries not given, the identity on the given
    // ones (fixed by their rows, so it only has to be positive there).
    let g = m.mass_matrix(q);
    let h: [[f64; N]; N] = core::array::from_fn(|i| {
        core::array::from_fn(|j| match (given[i], given[j]) {
            (false, false) => g[i][j],
            (true, true) if i == j => 1.0,
            _ => 0.0,
        })
    });
    let unit = |i: usize| core::array::from_fn(|j| if i == j { 1.0 } else { 0.0 });
    let conditions = a.as_slice().iter().map(|row| (*row, 0.0));
    let fixed = (0..N).filter(|i| given[*i]).map(|i| (unit(i), v[i]));
    let completed = linalg::least_solution(&h, conditions.chain(fixed).chain(rate_rows()))?;
    let moved = (0..N)
        .filter(|i| given[*i])
        .map(|i| (completed[i] - v[i]).abs())
        .fold(0.0, f64::max);
    if off(&completed) <= ADMISSIBLE * scale && moved <= ADMISSIBLE * scale {
        // The given entries exactly as given (the solve rounds them).
        let kept = core::array::from_fn(|i| if given[i] { v[i] } else { completed[i] });
        return Ok((kept, StartRule::Completed));
    }
    if rate_rows().next().is_none() {
        return Ok((admissible(m, q, &v)?, StartRule::Projected));
    }
    // v plus its G-smallest change d with A(v + d) = 0 and L(v + d) = c.
    let conditions = (a.as_slice().iter()).map(|row| (*row, -linalg::dot(row, &v)));
    let to_rates = rate_rows().map(|(row, c)| (row, c - linalg::dot(&row, &v)));
    let d = linalg::least_solution(&g, conditions.chain(to_rates))?;
    let projected = core::array::from_fn(|i| v[i] + d[i]);
    if off(&projected) <= ADMISSIBLE * scale {
        Ok((projected, StartRule::Projected))
    } else {
        Err(ProjectorError::Inconsistent)
    }
}
