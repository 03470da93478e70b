//! The variational flow along a simulation: Φ(t) = ∂x(t)/∂x(t₀) for the
//! state x = (q, q̇), through collisions.
//!
//! [`Variational::follow`] takes each step the simulator has just made, with
//! any integrator: between collisions it integrates the variational
//! equation Φ̇ = J(x(t)) Φ, J = [[0, I], [∂q̈/∂q, ∂q̈/∂q̇]], column by column
//! along the step's own motion ([`Simulator::state_at`]: the Runge–Kutta
//! dense output, or Taylor's polynomial), by Dormand–Prince 5(4) with its
//! own error control, each column's derivative one tangent of q̈
//! ([`Dynamics::accelerations_tangent`]); at a collision it applies the
//! saltation matrix ([`saltation`]), Φ⁺ = S Φ⁻.
//!
//! The simulator projects each step's end onto the constraints; Φ is not
//! projected. A perturbation tangent to the constraint manifold (h(q) = 0,
//! A(q) q̇ = 0) stays tangent to it along the flow and through collisions,
//! and on those the projection acts as the identity, so Φ δx₀ is the
//! simulation's derivative along every admissible δx₀; other columns of Φ
//! describe the flow of the equations extended off the manifold.

use super::integrator::{DormandPrince, Method};
use super::phase::Phase;
use super::{Simulator, Step};
use crate::Surfaces;
use crate::saltation::{SaltationError, StateMatrix, saltation};

/// Φ along a simulation (see the module doc). Start it at the simulator's
/// start and call [`Variational::follow`] after every step:
///
/// ```ignore
/// let mut phi = Variational::new(1e-10);
/// while sim.state().t < t_end {
///     let step = sim.step(t_end)?;
///     phi.follow(&sim, &step)?;
/// }
/// let m = phi.matrix(); // ∂x(t)/∂x(t₀)
/// ```
#[derive(Clone, Copy, Debug)]
pub struct Variational<const N: usize> {
    phi: StateMatrix<N>,
    /// Φ at the end of the last step's flight: before its collision.
    before: StateMatrix<N>,
    method: DormandPrince,
    /// The last accepted length of a step of Φ's integration.
    h: f64,
}

/// Why Φ could not follow a step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum VariationalError<W> {
    /// The model has no tangent of q̈ ([`Dynamics::accelerations_tangent`]
    /// is `None`).
    ///
    /// [`Dynamics::accelerations_tangent`]: crate::Dynamics::accelerations_tangent
    NoDerivative,
    /// The step is not the simulator's last (its motion is gone).
    NotTheLastStep,
    /// Φ's integration failed at time `t` (a non-finite derivative, or
    /// steps shrinking without end).
    Integration {
        /// Where.
        t: f64,
    },
    /// The collision with `wall` has no saltation matrix.
    Saltation {
        /// The wall met.
        wall: W,
        /// Why.
        error: SaltationError,
    },
}

impl<const N: usize> Variational<N> {
    /// Φ = I, integrated with relative tolerance `rtol` (absolute
    /// `rtol`·1e-2 on entries that start at one).
    pub fn new(rtol: f64) -> Self {
        Self {
            phi: StateMatrix::identity(),
            before: StateMatrix::identity(),
            method: DormandPrince {
                rtol,
                atol: rtol * 1e-2,
                max_step: f64::INFINITY,
            },
            h: f64::INFINITY,
        }
    }

    /// Φ so far: ∂x/∂x₀ over (q, q̇) as four N×N blocks.
    pub fn matrix(&self) -> &StateMatrix<N> {
        &self.phi
    }

    /// Φ just before the last step's collision, Φ⁻ (the saltation gives
    /// [`Variational::matrix`] = S Φ⁻); [`Variational::matrix`] itself
    /// when the step met no wall.
    pub fn before_collision(&self) -> &StateMatrix<N> {
        &self.before
    }

    /// Advances Φ over `step`, the step `sim` has just made: along its
    /// motion, then through its collision if it ended at one.
    pub fn follow<M: Surfaces<N>>(
        &mut self,
        sim: &Simulator<'_, M, N>,
        step: &Step<M::Wall, N>,
    ) -> Result<(), VariationalError<M::Wall>> {
        let t1 = step.collision.as_ref().map_or(step.state.t, |c| c.t);
        if t1 > step.t0 {
            for j in 0..2 * N {
                let column = self.column(j);
                let column = self.integrate(sim, step.t0, t1, column)?;
                self.set_column(j, &column);
            }
        }
        self.before = self.phi;
        if let Some(c) = &step.collision {
            let s = saltation(sim.model(), c.wall, &c.q, &c.v_minus).map_err(|error| {
                VariationalError::Saltation {
                    wall: c.wall,
                    error,
                }
            })?;
            self.phi = s.matrix.mul(&self.phi);
        }
        Ok(())
    }

    fn column(&self, j: usize) -> Phase<N> {
        let (q, v) = if j < N {
            (&self.phi.qq, &self.phi.vq)
        } else {
            (&self.phi.qv, &self.phi.vv)
        };
        let k = j % N;
        Phase {
            q: core::array::from_fn(|i| q[i][k]),
            v: core::array::from_fn(|i| v[i][k]),
        }
    }

    fn set_column(&mut self, j: usize, c: &Phase<N>) {
        let (q, v) = if j < N {
            (&mut self.phi.qq, &mut self.phi.vq)
        } else {
            (&mut self.phi.qv, &mut self.phi.vv)
        };
        let k = j % N;
        for i in 0..N {
            q[i][k] = c.q[i];
            v[i][k] = c.v[i];
        }
    }

    /// One column of Φ from t0 to t1 along the simulator's last step.
    fn integrate<M: Surfaces<N>>(
        &mut self,
        sim: &Simulator<'_, M, N>,
        t0: f64,
        t1: f64,
        mut y: Phase<N>,
    ) -> Result<Phase<N>, VariationalError<M::Wall>> {
        let model = sim.model();
        let mut rhs = |t: f64, d: &Phase<N>| -> Result<Phase<N>, VariationalError<M::Wall>> {
            let x = sim
                .state_at(t.clamp(t0, t1))
                .ok_or(VariationalError::NotTheLastStep)?;
            let (_, dqdd) = model
                .accelerations_tangent(&x.q, &x.v, &d.q, &d.v)
                .ok_or(VariationalError::NoDerivative)?;
            Ok(Phase { q: d.v, v: dqdd })
        };
        let span = t1 - t0;
        let mut t = t0;
        let mut h = self.h.min(span);
        let mut tries = 0;
        while t < t1 {
            let last = t + h >= t1 - 1e-12 * span;
            let h_now = if last { t1 - t } else { h };
            let f0 = rhs(t, &y)?;
            let trial = self.method.trial(&mut rhs, &y, &f0, t, h_now)?;
            let factor = self.method.factor(trial.error);
            if trial.error <= 1.0 && trial.y1.finite() {
                y = trial.y1;
                t = if last { t1 } else { t + h_now };
                self.h = h_now;
                tries = 0;
            } else {
                tries += 1;
                if tries > 50 || !trial.error.is_finite() {
                    return Err(VariationalError::Integration { t });
                }
            }
            h = h_now * factor;
        }
        Ok(y)
    }
}
